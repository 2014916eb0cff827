"""What a 3D character asset loads (:class:`Character3D`: skeleton, skin, meshes, clips), its
parts and clips, the DOF names and asset properties of 3D characters, and :func:`character`,
the loaded character of an asset.

The data only: :mod:`qtanimator.document.character3d` loads characters and works with them in
the document; the glTF modules (:mod:`~qtanimator.document.gltf_character`,
:mod:`~qtanimator.document.gltf_export`) build and read them without it.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import numpy.typing as npt

from qtanimator.core.channel import Channel
from qtanimator.core.clip import AnimationClip
from qtanimator.core.quaternion_channels import QUATERNION_DOFS
from qtanimator.core.rotation import euler_to_quaternions
from qtanimator.core.skeleton import Skeleton
from qtanimator.core.skinning import Skin
from qtanimator.document.document import Document
from qtanimator.formats.obj import Mesh

FloatArray = npt.NDArray[np.float64]

ASSET_KIND = "character3d"
ROOT_DOFS = ("tx", "ty", "tz")
JOINT_DOFS = ("rx", "ry", "rz")
QUAT_DOFS = QUATERNION_DOFS
TRANSLATE_DOFS = ("tx", "ty", "tz")
SCALE_DOFS = ("sx", "sy", "sz")
#: The asset properties of the active clip's name and of the clips edited and left.
CLIP = "clip"
CLIP_STORE = "clip_store"
#: The asset property saying how rotations are keyed: "quaternion" or "euler" (absent: as
#: the file has them; glTF quaternion, the others Euler).
ROTATION_MODE = "rotation_mode"
ROTATION_MODES = ("quaternion", "euler")


@dataclass(eq=False)
class TextureImage:
    """An image a mesh is drawn with, as the file gave it: its bytes (a glTF embedded image)
    or a ``path`` (a ``.skin`` material's texture beside the skin, a glTF ``uri``). The render
    layer decodes it; undecodable or missing, it draws a checkerboard. ``wrap`` is
    ``"repeat"`` or ``"clamp"`` (to the edge)."""

    data: bytes | None = None
    path: str | None = None
    mime_type: str | None = None
    name: str = ""
    wrap: str = "repeat"

    def read(self) -> bytes | None:
        """The image's bytes (None when the file is missing or unreadable)."""
        if self.data is not None:
            return self.data
        if self.path is None:
            return None
        try:
            return Path(self.path).read_bytes()
        except OSError:
            return None


def skin_texture(skin: Skin | None, skin_path: str | os.PathLike[str] | None) -> TextureImage | None:
    """The image of a ``.skin``'s ``material { texture FILE }`` block: FILE beside the skin
    (matched without regard to case when the exact name is absent). None without a block."""
    material = getattr(skin, "material", None)
    name = material.get("texture") if material else None
    if not name or skin_path is None:
        return None
    folder = Path(skin_path).parent
    path = folder / str(name)
    if not path.is_file() and folder.is_dir():
        path = next((p for p in sorted(folder.iterdir()) if p.name.lower() == Path(str(name)).name.lower()), path)
    return TextureImage(path=str(path), name=str(name), wrap="clamp")


@dataclass
class MeshPart:
    """One mesh of a character: vertices ``start … start + count`` and triangles
    ``triangle_start …`` of the merged skin. ``node`` / ``mesh`` / ``primitive`` say where
    it came from in a glTF file (None for course files)."""

    name: str
    start: int
    count: int
    triangle_start: int = 0
    triangle_count: int = 0
    skinned: bool = True
    node: int | None = None
    mesh: int | None = None
    primitive: int = 0
    #: base colour (RGBA, linear) of the part's material
    color: tuple[float, float, float, float] = (0.8, 0.8, 0.8, 1.0)
    #: the image of the material's base colour (drawn with the skin's texture coordinates)
    texture: TextureImage | None = None


@dataclass
class ClipSource:
    """An animation the character's file brought: its name, where it lies in the file's
    time, and its channels keyed by the asset-relative id (``"<joint key>/<dof>"``,
    ``"/tx"`` for the root translation)."""

    name: str
    start: float
    end: float
    channels: dict[str, Channel] = field(default_factory=dict)
    #: the animation's index in the file (None: not from a file)
    index: int | None = None


@dataclass(eq=False)
class Character3D:
    """What a 3D character asset loads: skeleton (rest pose from the file), skin, clip."""

    skeleton: Skeleton
    skin: Skin | None = None
    mesh: Mesh | None = None
    clip: AnimationClip | None = None
    #: MIT meshes are drawn with per-face normals by default.
    faceted: bool = False
    #: The meshes of the merged skin (empty: the skin is one mesh).
    parts: list[MeshPart] = field(default_factory=list)
    #: The animations of the file (glTF); the document's channels hold the active one.
    clips: list[ClipSource] = field(default_factory=list)
    #: Skin joint slot → skeleton joint (None: slot i is joint i). Several glTF skins (each
    #: with its own inverse bind matrices) and rigid parts share one merged skin this way.
    palette: npt.NDArray[np.intp] | None = None
    #: Notes for the user from reading the file.
    notes: list[str] = field(default_factory=list)
    #: The whole skin's image when it has no parts (a ``.skin`` material's texture).
    texture: TextureImage | None = None
    _rest_quaternions: FloatArray | None = field(default=None, repr=False)

    @property
    def joint_keys(self) -> list[str]:
        return self.skeleton.joint_keys()

    def skinning_world(self, world: FloatArray) -> FloatArray:
        """The world matrices of the skin's joint slots from the skeleton's (J, 4, 4)."""
        return world if self.palette is None else world[self.palette]

    def clip_named(self, name: str) -> ClipSource | None:
        return next((c for c in self.clips if c.name == name), None)

    def rest_quaternions(self) -> FloatArray:
        """(J, 4) the rest pose's rotations as quaternions (what a quaternion joint holds
        where a component has no channel)."""
        if self._rest_quaternions is None:
            sk = self.skeleton
            out = np.tile(np.array([0.0, 0.0, 0.0, 1.0]), (len(sk.joints), 1))
            for i, j in enumerate(sk.joints):
                if j.quaternion:
                    out[i] = euler_to_quaternions(j.pose, j.rotation_order or sk.rotation_order)[0]
            self._rest_quaternions = out
        return self._rest_quaternions


def character(doc: Document, asset_id: str) -> Character3D:
    rt = doc.runtime.get(asset_id)
    if not isinstance(rt, Character3D):
        raise KeyError(f"{asset_id!r} is not a loaded 3D character")
    return rt
