"""glTF 2.0: import ``.gltf`` / ``.glb`` scenes and export skinned, animated characters as ``.glb``.

Import (:func:`import_gltf`) reads nodes (``matrix`` or TRS), meshes (POSITION, NORMAL,
TEXCOORD_0, JOINTS_n / WEIGHTS_n, indices), skins (joints, inverse bind matrices),
animations (LINEAR, STEP and CUBICSPLINE samplers on translation, rotation and scale),
materials, textures and embedded images, into a :class:`GltfScene`. Weights that do not
sum to 1 are renormalised (older exports such as the 2017 CesiumMan need it).
:meth:`GltfScene.skinned_positions` evaluates a mesh at any time: per the specification
the skinned mesh node's own transform is ignored and joint j moves vertices by
``global(joint_j) · inverseBind_j``.

Export: :func:`export_glb` writes a :class:`GltfScene` (one buffer, one buffer view per
accessor, 4-byte aligned, min / max on every accessor, the JSON chunk padded with spaces
and the BIN chunk with zeros). A whole character (every mesh and clip, keys as they are) is
turned into such a scene by :mod:`qtanimator.document.gltf_export`, and one skeleton + skin +
``.anim`` channels without a document by :mod:`qtanimator.document.gltf_skeleton_export`
(character export belongs to the document layer; this package reads and writes scenes).

Every malformed file raises :class:`~qtanimator.formats.FormatError`.

The package, one idea a module: :mod:`~qtanimator.formats.gltf.model` (the scene's
dataclasses and pose evaluation), :mod:`~qtanimator.formats.gltf.reader` (import),
:mod:`~qtanimator.formats.gltf.accessors` and :mod:`~qtanimator.formats.gltf.buffers`
(validated JSON access, accessor and buffer data), :mod:`~qtanimator.formats.gltf.writer`
(export), :mod:`~qtanimator.formats.gltf.sampling` (export sample times),
:mod:`~qtanimator.formats.gltf.constants`. Every public name is importable from here too.
"""

from __future__ import annotations

from qtanimator.core.rotation import quaternion_to_matrix
from qtanimator.formats.gltf.buffers import contained_path
from qtanimator.formats.gltf.constants import (
    ARRAY_BUFFER,
    BYTE,
    ELEMENT_ARRAY_BUFFER,
    FLOAT,
    INTERPOLATIONS,
    MAX_ZERO_ELEMENTS,
    PATHS,
    SHORT,
    TRIANGLE_FAN,
    TRIANGLE_STRIP,
    TRIANGLES,
    UNSIGNED_BYTE,
    UNSIGNED_INT,
    UNSIGNED_SHORT,
    WEIGHT_SUM_TOLERANCE,
)
from qtanimator.formats.gltf.model import (
    FloatArray,
    GltfAnimation,
    GltfAnimationChannel,
    GltfImage,
    GltfMesh,
    GltfNode,
    GltfPrimitive,
    GltfSampler,
    GltfScene,
    GltfSkin,
    IntArray,
)
from qtanimator.formats.gltf.reader import import_gltf, parse_gltf, summarize
from qtanimator.formats.gltf.sampling import sample_times
from qtanimator.formats.gltf.writer import export_glb, glb_bytes, scene_to_gltf

__all__ = [
    "ARRAY_BUFFER", "BYTE", "ELEMENT_ARRAY_BUFFER", "FLOAT", "INTERPOLATIONS", "MAX_ZERO_ELEMENTS", "PATHS",
    "SHORT", "TRIANGLES", "TRIANGLE_FAN", "TRIANGLE_STRIP", "UNSIGNED_BYTE", "UNSIGNED_INT", "UNSIGNED_SHORT",
    "WEIGHT_SUM_TOLERANCE",
    "FloatArray", "GltfAnimation", "GltfAnimationChannel", "GltfImage",
    "GltfMesh", "GltfNode", "GltfPrimitive", "GltfSampler", "GltfScene", "GltfSkin", "IntArray",
    "contained_path", "export_glb", "glb_bytes", "import_gltf",
    "parse_gltf", "quaternion_to_matrix", "sample_times", "scene_to_gltf", "summarize",
]
