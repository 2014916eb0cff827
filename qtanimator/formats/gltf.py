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
turned into such a scene by :mod:`qtanimator.document.gltf_export`.
:func:`export_character_glb` is the older path for one skeleton, one skin and ``.anim``-layout
channels: joints become nodes, each vertex keeps its strongest four influences (renormalised,
with a :class:`GltfExportWarning` when that visibly changes the animated shape), and the
animation is sampled at ``fps`` with LINEAR or CUBICSPLINE interpolation, time 0 at
``start``; a channel with weighted tangents (issue 13) is sampled and named in a warning.

Every malformed file raises :class:`~qtanimator.formats.FormatError`.
"""

from __future__ import annotations

import base64
import binascii
import math
import os
import urllib.parse
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.core.channel import Channel
from qtanimator.core.rotation import normalize as _normalize
from qtanimator.core.rotation import quaternion_multiply, quaternion_to_matrix, trs_matrix
from qtanimator.core.rotation import slerp as _slerp
from qtanimator.core.skeleton import ROTATION_ORDERS, Skeleton
from qtanimator.core.skinning import Skin, SkinBinding
from qtanimator.formats._tokens import read_bytes
from qtanimator.formats.atomic import write_atomic
from qtanimator.formats.errors import FormatError
from qtanimator.formats.glb import build_glb, is_glb, parse_json_text, read_glb
from qtanimator.formats.limits import (
    MAX_DATA_URI_BYTES,
    MAX_JOINTS,
    MAX_NODES,
    MAX_VERTICES,
    decoded_budget,
    exceeded,
)

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

__all__ = [
    "CharacterExport", "GltfAnimation", "GltfAnimationChannel", "GltfExportWarning", "GltfImage",
    "GltfMesh", "GltfNode", "GltfPrimitive", "GltfSampler", "GltfScene", "GltfSkin",
    "build_character_scene", "export_character_glb", "export_glb", "glb_bytes", "import_gltf",
    "parse_gltf", "quaternion_to_matrix", "summarize",
]

# --------------------------------------------------------------------------- constants
BYTE, UNSIGNED_BYTE, SHORT, UNSIGNED_SHORT, UNSIGNED_INT, FLOAT = 5120, 5121, 5122, 5123, 5125, 5126
_COMPONENTS: dict[int, tuple[str, int]] = {
    BYTE: ("i1", 1), UNSIGNED_BYTE: ("u1", 1), SHORT: ("<i2", 2), UNSIGNED_SHORT: ("<u2", 2),
    UNSIGNED_INT: ("<u4", 4), FLOAT: ("<f4", 4),
}
_TYPES: dict[str, tuple[int, int]] = {  # type -> (columns, rows)
    "SCALAR": (1, 1), "VEC2": (1, 2), "VEC3": (1, 3), "VEC4": (1, 4),
    "MAT2": (2, 2), "MAT3": (3, 3), "MAT4": (4, 4),
}
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN = 4, 5, 6
INTERPOLATIONS = ("LINEAR", "STEP", "CUBICSPLINE")
PATHS = {"translation": 3, "rotation": 4, "scale": 3, "weights": 0}
#: Largest accessor without a buffer view (all zeros) we build; guards hostile counts.
MAX_ZERO_ELEMENTS = 1 << 26
WEIGHT_SUM_TOLERANCE = 1e-6


class GltfExportWarning(UserWarning):
    """An export had to change the character (e.g. dropping influences beyond four)."""


# --------------------------------------------------------------------------- scene model
@dataclass(eq=False)
class GltfNode:
    """A node. ``matrix`` (4×4, column vectors) when the file gave one, else TRS."""

    name: str = ""
    children: list[int] = field(default_factory=list)
    parent: int | None = None
    translation: FloatArray = field(default_factory=lambda: np.zeros(3))
    rotation: FloatArray = field(default_factory=lambda: np.array([0.0, 0.0, 0.0, 1.0]))
    scale: FloatArray = field(default_factory=lambda: np.ones(3))
    matrix: FloatArray | None = None
    mesh: int | None = None
    skin: int | None = None

    def local_matrix(self) -> FloatArray:
        if self.matrix is not None:
            return self.matrix.copy()
        return trs_matrix(self.translation, self.rotation, self.scale)


@dataclass(eq=False)
class GltfSkin:
    """``joints`` are node indices; ``inverse_bind_matrices`` (J, 4, 4)."""

    joints: list[int]
    inverse_bind_matrices: FloatArray
    skeleton: int | None = None
    name: str = ""


@dataclass(eq=False)
class GltfPrimitive:
    """One primitive. ``joints`` / ``weights`` are (V, K) with K a multiple of 4 (or 0)."""

    positions: FloatArray
    triangles: IntArray
    normals: FloatArray | None = None
    texcoords: FloatArray | None = None
    joints: IntArray | None = None
    weights: FloatArray | None = None
    material: int | None = None
    mode: int = TRIANGLES
    #: vertices whose weights were divided by their sum on import
    renormalized_vertices: int = 0

    @property
    def num_vertices(self) -> int:
        return int(len(self.positions))


@dataclass(eq=False)
class GltfMesh:
    primitives: list[GltfPrimitive]
    name: str = ""

    @property
    def num_vertices(self) -> int:
        return sum(p.num_vertices for p in self.primitives)

    @property
    def num_triangles(self) -> int:
        return sum(len(p.triangles) for p in self.primitives)


@dataclass(eq=False)
class GltfSampler:
    """Key times (K,) and values: (K, n) for LINEAR / STEP, (K, 3, n) (in-tangent, value,
    out-tangent) for CUBICSPLINE."""

    times: FloatArray
    values: FloatArray
    interpolation: str = "LINEAR"

    def evaluate(self, t: float, rotation: bool = False) -> FloatArray:
        times = self.times
        cubic = self.interpolation == "CUBICSPLINE"
        vals = self.values[:, 1] if cubic else self.values
        n = len(times)
        if t <= times[0] or n == 1:
            out = vals[0].copy()
        elif t >= times[-1]:
            out = vals[-1].copy()
        else:
            i = int(np.searchsorted(times, t, side="right")) - 1
            i = min(max(i, 0), n - 2)
            dt = float(times[i + 1] - times[i])
            u = (t - float(times[i])) / dt if dt > 0 else 0.0
            if self.interpolation == "STEP":
                out = vals[i].copy()
            elif cubic:
                p0, p1 = self.values[i, 1], self.values[i + 1, 1]
                m0, m1 = self.values[i, 2] * dt, self.values[i + 1, 0] * dt
                u2, u3 = u * u, u * u * u
                out = ((2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * m0
                       + (-2 * u3 + 3 * u2) * p1 + (u3 - u2) * m1)
            elif rotation:
                out = _slerp(vals[i], vals[i + 1], u)
            else:
                out = vals[i] * (1 - u) + vals[i + 1] * u
        if rotation:
            out = _normalize(out)
        return out


@dataclass(eq=False)
class GltfAnimationChannel:
    sampler: int
    node: int
    path: str


@dataclass(eq=False)
class GltfAnimation:
    samplers: list[GltfSampler]
    channels: list[GltfAnimationChannel]
    name: str = ""

    @property
    def start(self) -> float:
        return min((float(s.times[0]) for s in self.samplers), default=0.0)

    @property
    def end(self) -> float:
        return max((float(s.times[-1]) for s in self.samplers), default=0.0)


@dataclass(eq=False)
class GltfImage:
    """An image: embedded bytes (from a buffer view or a data URI) or an external ``uri``."""

    data: bytes | None = None
    mime_type: str | None = None
    uri: str | None = None
    name: str = ""


@dataclass(eq=False)
class GltfScene:
    """Everything :func:`import_gltf` reads; :func:`export_glb` writes it back."""

    nodes: list[GltfNode] = field(default_factory=list)
    meshes: list[GltfMesh] = field(default_factory=list)
    skins: list[GltfSkin] = field(default_factory=list)
    animations: list[GltfAnimation] = field(default_factory=list)
    roots: list[int] = field(default_factory=list)
    materials: list[dict[str, Any]] = field(default_factory=list)
    textures: list[dict[str, Any]] = field(default_factory=list)
    samplers: list[dict[str, Any]] = field(default_factory=list)
    images: list[GltfImage] = field(default_factory=list)
    generator: str = ""
    path: str | None = None

    # ------------------------------------------------------------------ structure
    def _order(self) -> list[int]:
        """Node indices with every parent before its children."""
        order: list[int] = []
        for i, n in enumerate(self.nodes):
            if n.parent is None:
                stack = [i]
                while stack:
                    k = stack.pop()
                    order.append(k)
                    stack.extend(reversed(self.nodes[k].children))
        return order

    def mesh_node(self, mesh_index: int) -> int | None:
        """The node that instantiates mesh ``mesh_index`` (one with a skin preferred)."""
        found = None
        for i, n in enumerate(self.nodes):
            if n.mesh == mesh_index:
                if n.skin is not None:
                    return i
                if found is None:
                    found = i
        return found

    # ------------------------------------------------------------------ pose
    def local_matrices(self, time: float | None = None, animation: int | None = 0) -> FloatArray:
        """(N, 4, 4) node local matrices at ``time`` seconds of ``animation`` (rest pose
        when ``time`` is None or there is no such animation)."""
        n = len(self.nodes)
        t = np.array([node.translation for node in self.nodes], dtype=np.float64).reshape(n, 3)
        r = np.array([node.rotation for node in self.nodes], dtype=np.float64).reshape(n, 4)
        s = np.array([node.scale for node in self.nodes], dtype=np.float64).reshape(n, 3)
        animated = np.zeros(n, dtype=bool)
        if time is not None and animation is not None and 0 <= animation < len(self.animations):
            anim = self.animations[animation]
            for ch in anim.channels:
                if ch.path == "weights":
                    continue
                value = anim.samplers[ch.sampler].evaluate(float(time), rotation=ch.path == "rotation")
                {"translation": t, "rotation": r, "scale": s}[ch.path][ch.node] = value
                animated[ch.node] = True
        out = trs_matrix(t, r, s) if n else np.zeros((0, 4, 4))
        for i, node in enumerate(self.nodes):
            if node.matrix is not None and not animated[i]:
                out[i] = node.matrix
        return out

    def world_matrices(self, time: float | None = None, animation: int | None = 0) -> FloatArray:
        """(N, 4, 4) node world matrices."""
        local = self.local_matrices(time, animation)
        world = np.empty_like(local)
        for i in self._order():
            p = self.nodes[i].parent
            world[i] = local[i] if p is None else world[p] @ local[i]
        return world

    def joint_world_matrices(self, skin_index: int, time: float | None = None,
                             animation: int | None = 0) -> FloatArray:
        """(J, 4, 4) world matrices of a skin's joints (what :mod:`core.skinning` expects)."""
        return self.world_matrices(time, animation)[self.skins[skin_index].joints]

    def joint_matrices(self, skin_index: int, time: float | None = None, animation: int | None = 0) -> FloatArray:
        """(J, 4, 4) skinning matrices ``global(joint) · inverseBind``."""
        skin = self.skins[skin_index]
        result: FloatArray = self.joint_world_matrices(skin_index, time, animation) @ skin.inverse_bind_matrices
        return result

    def skinned_positions(self, mesh_index: int, time: float | None = None, animation: int | None = 0,
                          primitive: int | None = None) -> FloatArray:
        """World-space positions of a mesh at ``time`` (all primitives stacked, or one).

        A skinned mesh uses linear blend skinning with the renormalised weights; an unskinned
        one is moved by its node's world matrix.
        """
        mesh = self.meshes[mesh_index]
        prims = mesh.primitives if primitive is None else [mesh.primitives[primitive]]
        node_index = self.mesh_node(mesh_index)
        node = self.nodes[node_index] if node_index is not None else None
        world = self.world_matrices(time, animation)
        out = []
        for prim in prims:
            p = prim.positions
            if node is not None and node.skin is not None and prim.joints is not None and prim.weights is not None:
                skin = self.skins[node.skin]
                mats = world[skin.joints] @ skin.inverse_bind_matrices  # (J, 4, 4)
                blended = np.einsum("vk,vkij->vij", prim.weights, mats[prim.joints][:, :, :3, :])
                out.append(np.einsum("vij,vj->vi", blended[:, :, :3], p) + blended[:, :, 3])
            else:
                m = world[node_index] if node_index is not None else np.eye(4)
                out.append(p @ m[:3, :3].T + m[:3, 3])
        return np.concatenate(out, axis=0) if out else np.zeros((0, 3))

    def to_skin(self, mesh_index: int, primitive: int = 0) -> Skin:
        """One primitive as a :class:`~qtanimator.core.skinning.Skin` over its node's skin.

        Pose it with ``core.skinning.skin_positions(skin, scene.joint_world_matrices(s, t))``.
        """
        node_index = self.mesh_node(mesh_index)
        if node_index is None or self.nodes[node_index].skin is None:
            raise ValueError(f"mesh {mesh_index} is not skinned")
        sk = self.skins[self.nodes[node_index].skin or 0]
        prim = self.meshes[mesh_index].primitives[primitive]
        if prim.joints is None or prim.weights is None:
            raise ValueError(f"mesh {mesh_index} primitive {primitive} has no JOINTS_0 / WEIGHTS_0")
        binding = SkinBinding.from_padded(prim.joints, prim.weights, len(sk.joints))
        return Skin(prim.positions.copy(), prim.triangles.copy(), binding, sk.inverse_bind_matrices.copy(),
                    normals=None if prim.normals is None else prim.normals.copy(),
                    texcoords=None if prim.texcoords is None else prim.texcoords.copy())

    def summary(self) -> dict[str, Any]:
        return {
            "kind": "glTF 2.0 scene",
            "generator": self.generator,
            "nodes": len(self.nodes),
            "meshes": [{"name": m.name, "primitives": len(m.primitives), "vertices": m.num_vertices,
                        "triangles": m.num_triangles,
                        "renormalized_vertices": sum(p.renormalized_vertices for p in m.primitives)}
                       for m in self.meshes],
            "skins": [{"name": s.name, "joints": len(s.joints)} for s in self.skins],
            "animations": [{"name": a.name, "channels": len(a.channels), "start": a.start, "end": a.end,
                            "interpolations": sorted({s.interpolation for s in a.samplers}),
                            "keys": int(sum(len(a.samplers[c.sampler].times) for c in a.channels))}
                           for a in self.animations],
            "materials": len(self.materials),
            "images": len(self.images),
        }


# =========================================================================== import
class _Reader:
    """Validating access to the JSON with errors that name where the problem is."""

    def __init__(self, doc: dict[str, Any], buffers: list[bytes], path: str | None,
                 input_bytes: int = 0) -> None:
        self.doc = doc
        self.buffers = buffers
        self.path = path
        self._accessors: dict[int, Any] = {}
        #: Bytes of decoded accessor data allowed (proportional to the input, capped).
        self.budget = decoded_budget(input_bytes + sum(len(b) for b in buffers))
        self.decoded = 0
        self.vertices = 0

    def spend(self, nbytes: int, where: str) -> None:
        """Count ``nbytes`` of decoded data against the budget before allocating them."""
        self.decoded += nbytes
        if self.decoded > self.budget:
            raise exceeded(f"{where}: the decoded data ({self.decoded} bytes so far)",
                           f"{self.budget} bytes for a file of this size", self.path)

    def error(self, message: str) -> FormatError:
        return FormatError(message, self.path)

    # ---------------------------------------------------------------- JSON access
    def array(self, obj: Mapping[str, Any], key: str, where: str) -> list[Any]:
        value = obj.get(key, [])
        if not isinstance(value, list):
            raise self.error(f"{where}.{key} must be an array.")
        return value

    def obj(self, value: Any, where: str) -> dict[str, Any]:
        if not isinstance(value, dict):
            raise self.error(f"{where} must be an object.")
        return value

    def integer(self, obj: Mapping[str, Any], key: str, where: str, *, required: bool = False,
                default: int | None = None, minimum: int = 0, count: int | None = None) -> int | None:
        value = obj.get(key)
        if value is None:
            if required:
                raise self.error(f"{where} has no '{key}'.")
            return default
        return self.whole(value, f"{where}.{key}", minimum, count)

    def whole(self, value: Any, label: str, minimum: int = 0, count: int | None = None) -> int:
        if (isinstance(value, bool) or not isinstance(value, int | float)
                or (isinstance(value, float) and not (math.isfinite(value) and value == int(value)))):
            raise self.error(f"{label} must be a whole number, found {_short(value)}.")
        v = int(value)
        if v < minimum:
            raise self.error(f"{label} must be at least {minimum}, found {v}.")
        if count is not None and v >= count:
            raise self.error(f"{label} is {v}, but there are only {count}.")
        return v

    def item(self, value: Any, where: str, count: int) -> int:
        """An array element that must be an index below ``count``."""
        return self.whole(value, where, 0, count)

    def index(self, obj: Mapping[str, Any], key: str, where: str, collection: str,
              required: bool = False) -> int | None:
        count = len(self.doc.get(collection, []) or [])
        return self.integer(obj, key, where, required=required, count=count)

    def numbers(self, obj: Mapping[str, Any], key: str, where: str, length: int) -> FloatArray | None:
        value = obj.get(key)
        if value is None:
            return None
        if (not isinstance(value, list) or len(value) != length
                or not all(isinstance(x, int | float) and not isinstance(x, bool) for x in value)):
            raise self.error(f"{where}.{key} must be an array of {length} numbers.")
        arr = np.array(value, dtype=np.float64)
        if not np.isfinite(arr).all():
            raise self.error(f"{where}.{key} holds a number that is too large.")
        return arr

    def string(self, obj: Mapping[str, Any], key: str, where: str, default: str = "") -> str:
        value = obj.get(key, default)
        if not isinstance(value, str):
            raise self.error(f"{where}.{key} must be a string.")
        return value

    def collection(self, key: str) -> list[dict[str, Any]]:
        items = self.array(self.doc, key, "the glTF")
        return [self.obj(item, f"{key}[{i}]") for i, item in enumerate(items)]

    # ---------------------------------------------------------------- binary data
    def buffer_view(self, index: int, where: str) -> tuple[bytes, int, int, int | None]:
        """``(buffer bytes, start, length, byteStride)`` of buffer view ``index``."""
        views = self.collection("bufferViews")
        if not 0 <= index < len(views):
            raise self.error(f"{where} refers to buffer view {index}, but there are {len(views)}.")
        view = views[index]
        vw = f"bufferViews[{index}]"
        b = self.integer(view, "buffer", vw, required=True, count=len(self.buffers))
        offset = self.integer(view, "byteOffset", vw, default=0) or 0
        length = self.integer(view, "byteLength", vw, required=True, minimum=1) or 0
        stride = self.integer(view, "byteStride", vw, minimum=4)
        data = self.buffers[b or 0]
        if offset + length > len(data):
            raise self.error(f"{vw} covers bytes {offset}..{offset + length} of buffer {b}, "
                             f"which has only {len(data)}.")
        return data, offset, length, stride

    def accessor(self, index: int, where: str) -> npt.NDArray[Any]:
        """Accessor ``index`` as a (count, components) array: float64 for FLOAT and
        normalized types, int64 otherwise. Matrices come out column-major, flattened."""
        if index in self._accessors:
            result: npt.NDArray[Any] = self._accessors[index]
            return result
        accessors = self.collection("accessors")
        if not 0 <= index < len(accessors):
            raise self.error(f"{where} refers to accessor {index}, but there are {len(accessors)}.")
        acc = accessors[index]
        aw = f"accessors[{index}]"
        ctype = self.integer(acc, "componentType", aw, required=True)
        if ctype not in _COMPONENTS:
            raise self.error(f"{aw}.componentType {ctype} is not a glTF component type.")
        kind = acc.get("type")
        if kind not in _TYPES:
            raise self.error(f"{aw}.type must be SCALAR, VEC2, VEC3, VEC4, MAT2, MAT3 or MAT4, "
                             f"found {_short(kind)}.")
        count = self.integer(acc, "count", aw, required=True, minimum=1) or 0
        normalized = acc.get("normalized", False)
        if not isinstance(normalized, bool):
            raise self.error(f"{aw}.normalized must be true or false.")
        dtype_code, csize = _COMPONENTS[ctype]
        cols, rows = _TYPES[kind]
        ncomp = cols * rows
        col_bytes = rows * csize
        col_stride = col_bytes + ((-col_bytes) % 4 if cols > 1 else 0)
        elem = col_stride * cols
        view_index = self.integer(acc, "bufferView", aw)
        # What this accessor will hold, decoded (8-byte numbers), counted before allocation:
        # many accessors sharing one small view must not expand without bound.
        self.spend(count * ncomp * 8 * (2 if acc.get("sparse") is not None else 1), aw)
        if view_index is None:
            if count * ncomp > MAX_ZERO_ELEMENTS:
                raise self.error(f"{aw} has no buffer view and {count} elements; that is too many.")
            raw = np.zeros((count, ncomp), dtype=dtype_code)
        else:
            data, start, length, stride = self.buffer_view(view_index, aw)
            offset = self.integer(acc, "byteOffset", aw, default=0) or 0
            stride = stride or elem
            if stride < elem:
                raise self.error(f"bufferViews[{view_index}].byteStride {stride} is smaller than an "
                                 f"element of {aw} ({elem} bytes).")
            need = offset + stride * (count - 1) + elem
            if need > length:
                raise self.error(f"{aw} needs {need} bytes of buffer view {view_index}, which has {length}.")
            dt = np.dtype(dtype_code)
            strided = np.ndarray((count, cols, rows), dtype=dt, buffer=data, offset=start + offset,
                                 strides=(stride, col_stride, csize))
            raw = strided.reshape(count, ncomp).copy()
        sparse = acc.get("sparse")
        if sparse is not None:
            raw = self.apply_sparse(raw, self.obj(sparse, f"{aw}.sparse"), aw, dtype_code, count, cols, rows)
        if ctype == FLOAT:
            with np.errstate(invalid="ignore"):  # a signalling NaN warns when cast; refused below
                out: npt.NDArray[Any] = raw.astype(np.float64)
            if not np.isfinite(out).all():
                raise self.error(f"{aw} holds values that are not finite numbers.")
        elif normalized:
            if ctype == UNSIGNED_INT:
                raise self.error(f"{aw} cannot be normalized with unsigned int components.")
            info = np.iinfo(np.dtype(dtype_code))
            out = np.maximum(raw.astype(np.float64) / info.max, -1.0)
        else:
            out = raw.astype(np.int64)
        self._accessors[index] = out
        return out

    def apply_sparse(self, raw: npt.NDArray[Any], sparse: dict[str, Any], aw: str, dtype_code: str,
                     count: int, cols: int, rows: int) -> npt.NDArray[Any]:
        sw = f"{aw}.sparse"
        n = self.integer(sparse, "count", sw, required=True, minimum=1) or 0
        if n > count:
            raise self.error(f"{sw}.count {n} is more than the accessor's {count} elements.")
        idx_obj = self.obj(sparse.get("indices"), f"{sw}.indices")
        val_obj = self.obj(sparse.get("values"), f"{sw}.values")
        ictype = self.integer(idx_obj, "componentType", f"{sw}.indices", required=True)
        if ictype not in (UNSIGNED_BYTE, UNSIGNED_SHORT, UNSIGNED_INT):
            raise self.error(f"{sw}.indices.componentType must be an unsigned integer type.")
        icode, isize = _COMPONENTS[ictype or UNSIGNED_INT]
        indices = self._sparse_block(idx_obj, f"{sw}.indices", np.dtype(icode), n, 1).reshape(n).astype(np.int64)
        if indices.max() >= count:
            raise self.error(f"{sw}.indices refers to element {int(indices.max())} of {count}.")
        if np.any(np.diff(indices) <= 0):
            raise self.error(f"{sw}.indices must increase strictly.")
        values = self._sparse_block(val_obj, f"{sw}.values", np.dtype(dtype_code), n, cols * rows)
        raw = raw.copy()
        raw[indices] = values.reshape(n, cols * rows)
        return raw

    def _sparse_block(self, obj: dict[str, Any], where: str, dt: np.dtype[Any], n: int, ncomp: int) -> npt.NDArray[Any]:
        view = self.integer(obj, "bufferView", where, required=True) or 0
        data, start, length, _ = self.buffer_view(view, where)
        offset = self.integer(obj, "byteOffset", where, default=0) or 0
        need = offset + n * ncomp * dt.itemsize
        if need > length:
            raise self.error(f"{where} needs {need} bytes of buffer view {view}, which has {length}.")
        return np.frombuffer(data, dtype=dt, count=n * ncomp, offset=start + offset).copy()


def _short(value: Any, limit: int = 40) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[:limit] + "…"


def _load_buffers(doc: dict[str, Any], bin_chunk: bytes | None, base: Path | None,
                  path: str | None) -> list[bytes]:
    reader = _Reader(doc, [], path)
    out: list[bytes] = []
    for i, buf in enumerate(reader.collection("buffers")):
        where = f"buffers[{i}]"
        length = reader.integer(buf, "byteLength", where, required=True, minimum=1) or 0
        uri = buf.get("uri")
        if uri is None:
            if i != 0 or bin_chunk is None:
                raise FormatError(f"{where} has no uri and there is no GLB binary chunk for it.", path)
            data = bin_chunk
        elif not isinstance(uri, str):
            raise FormatError(f"{where}.uri must be a string.", path)
        else:
            data = _read_uri(uri, base, where, path)
        if len(data) < length:
            raise FormatError(f"{where} should hold {length} bytes but has only {len(data)}.", path)
        out.append(data[:length])
    return out


def _read_uri(uri: str, base: Path | None, where: str, path: str | None) -> bytes:
    if uri.startswith("data:"):
        head, sep, payload = uri.partition(",")
        if not sep or not head.endswith(";base64"):
            raise FormatError(f"{where}.uri is a data URI that is not base64 encoded.", path)
        if len(payload) // 4 * 3 > MAX_DATA_URI_BYTES:
            raise exceeded(f"{where}.uri, a data URI of {len(payload) // 4 * 3:,} bytes",
                           f"{MAX_DATA_URI_BYTES:,} bytes (MAX_DATA_URI_BYTES)", path)
        try:
            return base64.b64decode(payload, validate=True)
        except (binascii.Error, ValueError) as exc:
            raise FormatError(f"{where}.uri holds invalid base64 data.", path) from exc
    if base is None:
        raise FormatError(f"{where} refers to an external file {_short(uri)} but the glTF has no folder.", path)
    parsed = urllib.parse.urlparse(uri)
    if parsed.scheme and len(parsed.scheme) > 1:
        raise FormatError(f"{where}.uri {_short(uri)} is not a local file.", path)
    target = contained_path(base, uri, where, path)
    try:
        return read_bytes(target)
    except (OSError, ValueError) as exc:  # FormatError too: a folder, a device, a missing file
        raise FormatError(f"{where} refers to {_short(uri)}, which cannot be read.", path) from exc


def contained_path(base: Path, uri: str, where: str, path: str | None) -> Path:
    """The file a relative ``uri`` names inside ``base`` (the glTF's folder), after
    percent-escapes, ``..`` and symbolic links are resolved; FormatError when it lies
    outside that folder (an absolute path, ``../``, a link pointing out)."""
    try:
        folder = base.resolve(strict=False)
        target = (folder / urllib.parse.unquote(uri)).resolve(strict=False)
    except (OSError, ValueError, RuntimeError) as exc:  # a NUL byte, a symlink loop
        raise FormatError(f"{where}.uri {_short(uri)} is not a usable file name.", path) from exc
    if not target.is_relative_to(folder):
        raise FormatError(f"{where}.uri {_short(uri)} points outside the glTF's folder; qtanimator "
                          "reads only files beside the glTF or in folders below it.", path)
    return target


def import_gltf(path: str | os.PathLike[str]) -> GltfScene:
    """Read a ``.gltf`` (embedded or external buffers) or ``.glb`` file.

    Raises :class:`FormatError` and nothing else on bad input.
    """
    p = Path(path)
    return parse_gltf(read_bytes(p), path, base=p.parent)


def parse_gltf(data: bytes, path: str | os.PathLike[str] | None = None, base: Path | None = None) -> GltfScene:
    """Parse glTF JSON or GLB bytes. ``base`` is the folder for external buffers."""
    spath = os.fspath(path) if path is not None else None
    if is_glb(data):
        doc, bin_chunk = read_glb(data, spath)
    else:
        doc, bin_chunk = parse_json_text(data, spath), None
    try:
        return _build_scene(doc, bin_chunk, base, spath, len(data))
    except FormatError:
        raise
    except (ValueError, TypeError, KeyError, IndexError, OverflowError, MemoryError, RecursionError) as exc:
        # A safety net: the validation above should have caught every bad input.
        raise FormatError(f"the glTF data is inconsistent ({type(exc).__name__}: {_short(str(exc), 80)}).",
                          spath) from exc


def _build_scene(doc: dict[str, Any], bin_chunk: bytes | None, base: Path | None, path: str | None,
                 input_bytes: int = 0) -> GltfScene:
    asset = doc.get("asset")
    if not isinstance(asset, dict) or not isinstance(asset.get("version"), str):
        raise FormatError("the glTF has no asset.version; is this a glTF 2.0 file?", path)
    version = asset["version"]
    min_version = asset.get("minVersion")
    if not version.startswith("2.") or (isinstance(min_version, str) and not min_version.startswith("2.")):
        raise FormatError(f"glTF version {_short(version)} is not supported; qtanimator reads glTF 2.0.", path)
    required = doc.get("extensionsRequired", [])
    if isinstance(required, list) and required:
        raise FormatError(f"the file requires extensions qtanimator does not support: "
                          f"{', '.join(_short(x) for x in required)}.", path)
    buffers = _load_buffers(doc, bin_chunk, base, path)
    r = _Reader(doc, buffers, path, input_bytes)
    scene = GltfScene(path=path, generator=str(asset.get("generator", "")))
    scene.nodes = _read_nodes(r)
    scene.skins = _read_skins(r, len(scene.nodes))
    scene.meshes = [_read_mesh(r, i, m) for i, m in enumerate(r.collection("meshes"))]
    for i, node in enumerate(scene.nodes):
        if node.mesh is not None and node.mesh >= len(scene.meshes):
            raise r.error(f"nodes[{i}].mesh refers to mesh {node.mesh}, but there are {len(scene.meshes)}.")
        if node.skin is not None:
            if node.mesh is None:
                continue
            joints = len(scene.skins[node.skin].joints)
            for k, prim in enumerate(scene.meshes[node.mesh].primitives):
                if prim.joints is not None and prim.weights is not None:
                    used = prim.joints[prim.weights != 0]
                    if used.size and int(used.max()) >= joints:
                        raise r.error(f"meshes[{node.mesh}].primitives[{k}] uses joint {int(used.max())}, "
                                      f"but skins[{node.skin}] has {joints}.")
                    prim.joints = np.where(prim.weights != 0, prim.joints, 0)
    scene.animations = [_read_animation(r, i, a, len(scene.nodes)) for i, a in enumerate(r.collection("animations"))]
    scene.roots = _read_roots(r, scene.nodes)
    scene.materials = r.collection("materials")
    scene.textures = r.collection("textures")
    scene.samplers = r.collection("samplers")
    scene.images = [_read_image(r, i, im, base) for i, im in enumerate(r.collection("images"))]
    return scene


def _read_nodes(r: _Reader) -> list[GltfNode]:
    raw = r.collection("nodes")
    if len(raw) > MAX_NODES:
        raise exceeded(f"the scene's {len(raw)} nodes", f"{MAX_NODES} nodes", r.path)
    nodes: list[GltfNode] = []
    for i, nd in enumerate(raw):
        w = f"nodes[{i}]"
        node = GltfNode(name=r.string(nd, "name", w))
        children = r.array(nd, "children", w)
        for ck in range(len(children)):
            node.children.append(r.item(children[ck], f"{w}.children[{ck}]", len(raw)))
        m = r.numbers(nd, "matrix", w, 16)
        if m is not None:
            node.matrix = m.reshape(4, 4).T.copy()  # column-major in the file
        t = r.numbers(nd, "translation", w, 3)
        q = r.numbers(nd, "rotation", w, 4)
        s = r.numbers(nd, "scale", w, 3)
        if t is not None:
            node.translation = t
        if q is not None:
            big = float(np.abs(q).max())
            if big == 0.0:
                raise r.error(f"{w}.rotation is the zero quaternion.")
            q = q / big
            node.rotation = q / float(np.linalg.norm(q))
        if s is not None:
            node.scale = s
        node.mesh = r.integer(nd, "mesh", w)
        node.skin = r.index(nd, "skin", w, "skins")
        nodes.append(node)
    for i, node in enumerate(nodes):
        for c in node.children:
            if nodes[c].parent is not None or c == i:
                raise r.error(f"node {c} has more than one parent (or is its own child).")
            nodes[c].parent = i
    # Every node must reach a root by walking up; a cycle never does.
    state = [0] * len(nodes)  # 0 unknown, 1 visiting, 2 fine
    for i in range(len(nodes)):
        chain = []
        k: int | None = i
        while k is not None and state[k] == 0:
            state[k] = 1
            chain.append(k)
            k = nodes[k].parent
        if k is not None and state[k] == 1:
            raise r.error(f"the node hierarchy has a cycle through node {k}.")
        for c in chain:
            state[c] = 2
    return nodes


def _read_roots(r: _Reader, nodes: list[GltfNode]) -> list[int]:
    scenes = r.collection("scenes")
    default = r.integer(r.doc, "scene", "the glTF", count=len(scenes))
    if scenes:
        sc = scenes[default or 0]
        roots = []
        for k, value in enumerate(r.array(sc, "nodes", f"scenes[{default or 0}]")):
            idx = r.item(value, f"scenes[{default or 0}].nodes[{k}]", len(nodes))
            if nodes[idx].parent is not None:
                raise r.error(f"scene root node {idx} has a parent.")
            roots.append(idx)
        return roots
    return [i for i, n in enumerate(nodes) if n.parent is None]


def _read_skins(r: _Reader, num_nodes: int) -> list[GltfSkin]:
    skins = []
    for i, sk in enumerate(r.collection("skins")):
        w = f"skins[{i}]"
        joints_raw = r.array(sk, "joints", w)
        if not joints_raw:
            raise r.error(f"{w} has no joints.")
        if len(joints_raw) > MAX_JOINTS:
            raise exceeded(f"{w} with {len(joints_raw)} joints", f"{MAX_JOINTS} joints per skin", r.path)
        joints = []
        for k, j in enumerate(joints_raw):
            joints.append(r.item(j, f"{w}.joints[{k}]", num_nodes))
        ibm_index = r.integer(sk, "inverseBindMatrices", w)
        if ibm_index is None:
            ibm = np.broadcast_to(np.eye(4), (len(joints), 4, 4)).copy()
        else:
            data = r.accessor(ibm_index, f"{w}.inverseBindMatrices")
            if data.shape[1] != 16:
                raise r.error(f"{w}.inverseBindMatrices must be a MAT4 accessor.")
            if len(data) < len(joints):
                raise r.error(f"{w} has {len(joints)} joints but only {len(data)} inverse bind matrices.")
            ibm = np.asarray(data[: len(joints)], dtype=np.float64).reshape(-1, 4, 4).transpose(0, 2, 1).copy()
        skins.append(GltfSkin(joints, ibm, r.integer(sk, "skeleton", w, count=num_nodes), r.string(sk, "name", w)))
    return skins


def _read_mesh(r: _Reader, mi: int, mesh: dict[str, Any]) -> GltfMesh:
    w = f"meshes[{mi}]"
    prims = r.array(mesh, "primitives", w)
    if not prims:
        raise r.error(f"{w} has no primitives.")
    out = []
    for pi, praw in enumerate(prims):
        pw = f"{w}.primitives[{pi}]"
        prim = r.obj(praw, pw)
        attrs = r.obj(prim.get("attributes"), f"{pw}.attributes")
        pos_index = r.integer(attrs, "POSITION", f"{pw}.attributes", required=True)
        positions = _float_attr(r, pos_index or 0, f"{pw}.attributes.POSITION", 3)
        r.vertices += len(positions)
        if r.vertices > MAX_VERTICES:
            raise exceeded(f"the meshes' {r.vertices} vertices", f"{MAX_VERTICES} vertices per file", r.path)
        nv = len(positions)

        normals = _optional_attr(r, attrs, pw, "NORMAL", 3, nv)
        texcoords = _optional_attr(r, attrs, pw, "TEXCOORD_0", 2, nv)
        joint_sets, weight_sets = [], []
        k = 0
        while f"JOINTS_{k}" in attrs or f"WEIGHTS_{k}" in attrs:
            ji = r.integer(attrs, f"JOINTS_{k}", f"{pw}.attributes", required=True) or 0
            wi = r.integer(attrs, f"WEIGHTS_{k}", f"{pw}.attributes", required=True) or 0
            jarr = r.accessor(ji, f"{pw}.attributes.JOINTS_{k}")
            warr = r.accessor(wi, f"{pw}.attributes.WEIGHTS_{k}")
            if jarr.dtype.kind == "f" or jarr.shape[1] != 4:
                raise r.error(f"{pw}.attributes.JOINTS_{k} must be a VEC4 of unsigned integers.")
            if warr.dtype.kind != "f" or warr.shape[1] != 4:
                raise r.error(f"{pw}.attributes.WEIGHTS_{k} must be a VEC4 of floats or normalized integers.")
            if len(jarr) != nv or len(warr) != nv:
                raise r.error(f"{pw}.attributes.JOINTS_{k} / WEIGHTS_{k} do not match the {nv} vertices.")
            if (jarr < 0).any():
                raise r.error(f"{pw}.attributes.JOINTS_{k} holds a negative joint index.")
            joint_sets.append(jarr)
            weight_sets.append(warr)
            k += 1
            if k > 64:
                break
        joints = weights = None
        renormalized = 0
        if joint_sets:
            joints = np.concatenate(joint_sets, axis=1).astype(np.int64)
            weights = np.concatenate(weight_sets, axis=1).astype(np.float64)
            if (weights < 0).any():
                raise r.error(f"{pw} has negative skin weights.")
            sums = weights.sum(axis=1)
            fix = (np.abs(sums - 1.0) > WEIGHT_SUM_TOLERANCE) & (sums > 0)
            renormalized = int(fix.sum())
            weights[fix] /= sums[fix, None]
        mode = r.integer(prim, "mode", pw, default=TRIANGLES) or 0
        if mode > 6:
            raise r.error(f"{pw}.mode {mode} is not a glTF primitive mode.")
        idx_index = r.integer(prim, "indices", pw)
        if idx_index is None:
            indices = np.arange(nv, dtype=np.int64)
        else:
            ia = r.accessor(idx_index, f"{pw}.indices")
            if ia.dtype.kind == "f" or ia.shape[1] != 1:
                raise r.error(f"{pw}.indices must be a SCALAR accessor of unsigned integers.")
            indices = ia.reshape(-1)
            if indices.size and (indices.min() < 0 or indices.max() >= nv):
                raise r.error(f"{pw}.indices refers to vertex {int(indices.max())} of {nv}.")
        triangles = _triangles(indices, mode)
        material = r.index(prim, "material", pw, "materials")
        out.append(GltfPrimitive(positions, triangles, normals, texcoords, joints, weights, material, mode,
                                 renormalized))
    return GltfMesh(out, r.string(mesh, "name", w))


def _optional_attr(r: _Reader, attrs: dict[str, Any], pw: str, name: str, width: int, nv: int) -> FloatArray | None:
    idx = r.integer(attrs, name, f"{pw}.attributes")
    if idx is None:
        return None
    arr = _float_attr(r, idx, f"{pw}.attributes.{name}", width)
    if len(arr) != nv:
        raise r.error(f"{pw}.attributes.{name} has {len(arr)} elements for {nv} vertices.")
    return arr


def _float_attr(r: _Reader, index: int, where: str, width: int) -> FloatArray:
    arr = r.accessor(index, where)
    if arr.shape[1] != width:
        raise r.error(f"{where} must have {width} components per element, found {arr.shape[1]}.")
    return np.asarray(arr, dtype=np.float64)


def _triangles(indices: IntArray, mode: int) -> IntArray:
    if mode == TRIANGLES:
        n = len(indices) // 3 * 3
        return indices[:n].reshape(-1, 3).copy()
    if mode == TRIANGLE_STRIP and len(indices) >= 3:
        i = np.arange(len(indices) - 2)
        even = (i % 2) == 0
        a = indices[i]
        b = np.where(even, indices[i + 1], indices[i + 2])
        c = np.where(even, indices[i + 2], indices[i + 1])
        return np.stack([a, b, c], axis=1)
    if mode == TRIANGLE_FAN and len(indices) >= 3:
        i = np.arange(1, len(indices) - 1)
        return np.stack([np.full(len(i), indices[0]), indices[i], indices[i + 1]], axis=1)
    return np.zeros((0, 3), dtype=np.int64)


def _read_animation(r: _Reader, ai: int, anim: dict[str, Any], num_nodes: int) -> GltfAnimation:
    w = f"animations[{ai}]"
    samplers = []
    for si, sraw in enumerate(r.array(anim, "samplers", w)):
        sw = f"{w}.samplers[{si}]"
        s = r.obj(sraw, sw)
        interp = s.get("interpolation", "LINEAR")
        if interp not in INTERPOLATIONS:
            raise r.error(f"{sw}.interpolation must be LINEAR, STEP or CUBICSPLINE, found {_short(interp)}.")
        times = r.accessor(r.integer(s, "input", sw, required=True) or 0, f"{sw}.input")
        if times.dtype.kind != "f" or times.shape[1] != 1:
            raise r.error(f"{sw}.input must be a SCALAR float accessor.")
        times = times.reshape(-1).astype(np.float64)
        if np.any(np.diff(times) < 0):
            raise r.error(f"{sw}.input times must increase.")
        values = r.accessor(r.integer(s, "output", sw, required=True) or 0, f"{sw}.output")
        values = np.asarray(values, dtype=np.float64)
        per_key = 3 if interp == "CUBICSPLINE" else 1
        if len(values) % (len(times) * per_key):
            raise r.error(f"{sw} has {len(times)} key times but {len(values)} output values.")
        width = len(values) // (len(times) * per_key) * values.shape[1]
        shaped = values.reshape(len(times), per_key, width) if per_key == 3 else values.reshape(len(times), width)
        samplers.append(GltfSampler(times, shaped, interp))
    channels = []
    for ci, craw in enumerate(r.array(anim, "channels", w)):
        cw = f"{w}.channels[{ci}]"
        c = r.obj(craw, cw)
        si = r.integer(c, "sampler", cw, required=True, count=len(samplers)) or 0
        target = r.obj(c.get("target"), f"{cw}.target")
        node = r.integer(target, "node", f"{cw}.target", count=num_nodes)
        path = target.get("path")
        if path not in PATHS:
            raise r.error(f"{cw}.target.path must be translation, rotation, scale or weights, found {_short(path)}.")
        if node is None:
            continue  # targets an extension; nothing to animate here
        width = PATHS[path]
        sampler = samplers[si]
        got = sampler.values.shape[-1]
        if width and got != width:
            raise r.error(f"{cw} animates {path} with {got} numbers per key instead of {width}.")
        if path == "rotation":  # keys must be unit quaternions; tangents are left alone
            if sampler.interpolation == "CUBICSPLINE":
                sampler.values[:, 1] = _normalize(sampler.values[:, 1])
            else:
                sampler.values = _normalize(sampler.values)
        channels.append(GltfAnimationChannel(si, node, path))
    return GltfAnimation(samplers, channels, r.string(anim, "name", w))


def _read_image(r: _Reader, i: int, im: dict[str, Any], base: Path | None) -> GltfImage:
    w = f"images[{i}]"
    name = r.string(im, "name", w)
    mime = im.get("mimeType")
    mime = mime if isinstance(mime, str) else None
    view = r.integer(im, "bufferView", w)
    if view is not None:
        data, start, length, _ = r.buffer_view(view, w)
        return GltfImage(bytes(data[start:start + length]), mime, None, name)
    uri = im.get("uri")
    if isinstance(uri, str) and uri.startswith("data:"):
        return GltfImage(_read_uri(uri, base, w, r.path), mime or uri[5:].split(";")[0], None, name)
    return GltfImage(None, mime, uri if isinstance(uri, str) else None, name)


def summarize(path: Path) -> dict[str, Any]:
    scene = import_gltf(path)
    out: dict[str, Any] = {"file": str(path)}
    out.update(scene.summary())
    return out


# =========================================================================== export
class _Writer:
    """Collects accessors and buffer views into one binary buffer."""

    def __init__(self) -> None:
        self.chunks: list[bytes] = []
        self.size = 0
        self.views: list[dict[str, Any]] = []
        self.accessors: list[dict[str, Any]] = []
        self._dedup: dict[tuple[bytes, int, str, int | None, bool], int] = {}

    def view(self, data: bytes, target: int | None = None) -> int:
        pad = (-self.size) % 4
        if pad:
            self.chunks.append(b"\0" * pad)
            self.size += pad
        v: dict[str, Any] = {"buffer": 0, "byteOffset": self.size, "byteLength": len(data)}
        if target is not None:
            v["target"] = target
        self.chunks.append(data)
        self.size += len(data)
        self.views.append(v)
        return len(self.views) - 1

    def accessor(self, array: npt.ArrayLike, ctype: int, kind: str, target: int | None = None,
                 normalized: bool = False) -> int:
        dtype_code, _ = _COMPONENTS[ctype]
        cols, rows = _TYPES[kind]
        a = np.ascontiguousarray(np.asarray(array).reshape(-1, cols * rows), dtype=np.dtype(dtype_code))
        if ctype == FLOAT and not np.isfinite(a).all():
            raise ValueError(f"cannot export non-finite values to a {kind} accessor")
        if len(a) == 0:
            raise ValueError("cannot export an empty accessor")
        data = a.tobytes()
        key = (data, ctype, kind, target, normalized)
        if key in self._dedup:
            return self._dedup[key]
        acc: dict[str, Any] = {"bufferView": self.view(data, target), "componentType": ctype,
                               "count": int(len(a)), "type": kind}
        if normalized:
            acc["normalized"] = True
        if ctype == FLOAT:
            acc["min"] = [float(x) for x in a.min(axis=0)]
            acc["max"] = [float(x) for x in a.max(axis=0)]
        else:
            acc["min"] = [int(x) for x in a.min(axis=0)]
            acc["max"] = [int(x) for x in a.max(axis=0)]
        self.accessors.append(acc)
        self._dedup[key] = len(self.accessors) - 1
        return len(self.accessors) - 1

    def binary(self) -> bytes:
        return b"".join(self.chunks)


def _index_type(count: int) -> int:
    if count <= 255:
        return UNSIGNED_BYTE
    return UNSIGNED_SHORT if count <= 65535 else UNSIGNED_INT


def scene_to_gltf(scene: GltfScene) -> tuple[dict[str, Any], bytes]:
    """The glTF JSON object and the binary buffer of ``scene``."""
    w = _Writer()
    doc: dict[str, Any] = {"asset": {"version": "2.0", "generator": "qtanimator"}}
    nodes_json = []
    for node in scene.nodes:
        nj: dict[str, Any] = {}
        if node.name:
            nj["name"] = node.name
        if node.children:
            nj["children"] = [int(c) for c in node.children]
        if node.matrix is not None:
            nj["matrix"] = [float(x) for x in np.asarray(node.matrix, dtype=np.float64).T.reshape(16)]
        else:
            if np.any(node.translation != 0):
                nj["translation"] = [float(x) for x in node.translation]
            if not np.array_equal(node.rotation, [0.0, 0.0, 0.0, 1.0]):
                nj["rotation"] = [float(x) for x in _normalize(np.asarray(node.rotation, dtype=np.float64))]
            if np.any(node.scale != 1):
                nj["scale"] = [float(x) for x in node.scale]
        if node.mesh is not None:
            nj["mesh"] = int(node.mesh)
        if node.skin is not None:
            nj["skin"] = int(node.skin)
        nodes_json.append(nj)
    doc["nodes"] = nodes_json
    doc["scene"] = 0
    doc["scenes"] = [{"nodes": [int(i) for i in scene.roots]}]
    meshes_json = []
    for mesh in scene.meshes:
        prims = []
        for prim in mesh.primitives:
            nv = prim.num_vertices
            attrs: dict[str, int] = {"POSITION": w.accessor(prim.positions, FLOAT, "VEC3", ARRAY_BUFFER)}
            if prim.normals is not None:
                n = np.asarray(prim.normals, dtype=np.float64)
                length = np.linalg.norm(n, axis=1, keepdims=True)
                n = np.where(length > 0, n / np.where(length > 0, length, 1.0), [0.0, 0.0, 1.0])
                attrs["NORMAL"] = w.accessor(n, FLOAT, "VEC3", ARRAY_BUFFER)
            if prim.texcoords is not None:
                attrs["TEXCOORD_0"] = w.accessor(prim.texcoords, FLOAT, "VEC2", ARRAY_BUFFER)
            if prim.joints is not None and prim.weights is not None and prim.joints.shape[1]:
                k = prim.joints.shape[1]
                sets = (k + 3) // 4
                jj = np.zeros((nv, sets * 4), dtype=np.int64)
                ww = np.zeros((nv, sets * 4))
                jj[:, :k] = prim.joints
                ww[:, :k] = prim.weights
                jt = UNSIGNED_BYTE if int(jj.max()) <= 255 else UNSIGNED_SHORT
                for si in range(sets):
                    attrs[f"JOINTS_{si}"] = w.accessor(jj[:, 4 * si:4 * si + 4], jt, "VEC4", ARRAY_BUFFER)
                    attrs[f"WEIGHTS_{si}"] = w.accessor(ww[:, 4 * si:4 * si + 4], FLOAT, "VEC4", ARRAY_BUFFER)
            pj: dict[str, Any] = {"attributes": attrs, "mode": TRIANGLES}
            if len(prim.triangles):
                pj["indices"] = w.accessor(prim.triangles.reshape(-1), _index_type(nv - 1), "SCALAR",
                                           ELEMENT_ARRAY_BUFFER)
            if prim.material is not None:
                pj["material"] = int(prim.material)
            prims.append(pj)
        mj: dict[str, Any] = {"primitives": prims}
        if mesh.name:
            mj["name"] = mesh.name
        meshes_json.append(mj)
    if meshes_json:
        doc["meshes"] = meshes_json
    skins_json = []
    for skin in scene.skins:
        ibm = np.asarray(skin.inverse_bind_matrices, dtype=np.float64).transpose(0, 2, 1)
        sj: dict[str, Any] = {"joints": [int(j) for j in skin.joints],
                              "inverseBindMatrices": w.accessor(ibm, FLOAT, "MAT4")}
        if skin.skeleton is not None:
            sj["skeleton"] = int(skin.skeleton)
        if skin.name:
            sj["name"] = skin.name
        skins_json.append(sj)
    if skins_json:
        doc["skins"] = skins_json
    anims_json = []
    for anim in scene.animations:
        samplers = []
        for s in anim.samplers:
            values = np.asarray(s.values, dtype=np.float64)
            width = values.shape[-1]
            kind = {1: "SCALAR", 3: "VEC3", 4: "VEC4"}.get(width, "SCALAR")
            flat = values.reshape(-1, width) if kind != "SCALAR" else values.reshape(-1, 1)
            samplers.append({"input": w.accessor(s.times, FLOAT, "SCALAR"),
                             "output": w.accessor(flat, FLOAT, kind),
                             "interpolation": s.interpolation})
        channels = [{"sampler": int(c.sampler), "target": {"node": int(c.node), "path": c.path}}
                    for c in anim.channels]
        aj: dict[str, Any] = {"samplers": samplers, "channels": channels}
        if anim.name:
            aj["name"] = anim.name
        anims_json.append(aj)
    if anims_json:
        doc["animations"] = anims_json
    images_json = []
    for im in scene.images:
        ij: dict[str, Any] = {}
        if im.name:
            ij["name"] = im.name
        if im.data is not None:
            ij["bufferView"] = w.view(im.data)
            ij["mimeType"] = im.mime_type or "image/png"
        elif im.uri is not None:
            ij["uri"] = im.uri
        images_json.append(ij)
    for key, items in (("materials", scene.materials), ("textures", scene.textures), ("samplers", scene.samplers),
                       ("images", images_json)):
        if items:
            doc[key] = items
    binary = w.binary()
    if binary:
        doc["buffers"] = [{"byteLength": len(binary)}]
        doc["bufferViews"] = w.views
    if w.accessors:
        doc["accessors"] = w.accessors
    return doc, binary


def glb_bytes(scene: GltfScene) -> bytes:
    """``scene`` as the bytes of a ``.glb`` file."""
    doc, binary = scene_to_gltf(scene)
    return build_glb(doc, binary if binary else None)


def export_glb(path: str | os.PathLike[str], scene: GltfScene) -> None:
    """Write ``scene`` to a ``.glb`` file atomically."""
    write_atomic(path, glb_bytes(scene))


# ------------------------------------------------------------------ characters
@dataclass
class CharacterExport:
    """What :func:`export_character_glb` (or :func:`qtanimator.document.gltf_export.character_scene`,
    which keeps every influence) wrote and what it had to change."""

    scene: GltfScene
    #: the sample times (the whole-character export: every time of its first animation)
    times: FloatArray
    #: vertices that had more influences than the export keeps
    dropped_vertices: IntArray
    #: largest vertex displacement that dropping (the whole-character export: dividing the
    #: weights by their sums) caused, relative to the mesh's bounding-box diagonal
    max_relative_error: float
    joint_nodes: list[int]
    mesh_node: int


def _axis_quaternions(angles: FloatArray, axis: int) -> FloatArray:
    q = np.zeros(angles.shape + (4,))
    q[..., axis] = np.sin(angles / 2)
    q[..., 3] = np.cos(angles / 2)
    return q


def _euler_quaternions(angles: FloatArray, rates: FloatArray | None,
                       order: str) -> tuple[FloatArray, FloatArray | None]:
    """Quaternions (and their time derivatives) of ``R_a(θa)·R_b(θb)·R_c(θc)`` for ``order``
    ``"abc"``; ``angles`` and ``rates`` are (..., 3) in x, y, z order."""
    axes = ["xyz".index(c) for c in order]
    qs = [_axis_quaternions(angles[..., a], a) for a in axes]
    q = quaternion_multiply(quaternion_multiply(qs[0], qs[1]), qs[2])
    if rates is None:
        return q, None
    dqs = []
    for a in axes:
        half = angles[..., a] / 2
        d = np.zeros(angles.shape[:-1] + (4,))
        d[..., a] = 0.5 * np.cos(half) * rates[..., a]
        d[..., 3] = -0.5 * np.sin(half) * rates[..., a]
        dqs.append(d)
    dq = (quaternion_multiply(quaternion_multiply(dqs[0], qs[1]), qs[2])
          + quaternion_multiply(quaternion_multiply(qs[0], dqs[1]), qs[2])
          + quaternion_multiply(quaternion_multiply(qs[0], qs[1]), dqs[2]))
    return q, dq


def _sample_times(start: float, end: float, fps: float) -> FloatArray:
    if not (math.isfinite(start) and math.isfinite(end) and math.isfinite(fps)) or fps <= 0 or end < start:
        raise ValueError(f"need finite start <= end and fps > 0, got start={start}, end={end}, fps={fps}")
    n = int(math.floor((end - start) * fps + 1e-9)) + 1
    times = start + np.arange(n, dtype=np.float64) / fps
    if end - times[-1] > 1e-9:
        times = np.append(times, end)
    return times


def _with_key_times(grid: FloatArray, channels: Sequence[Channel], start: float, end: float,
                    tolerance: float = 1e-6, limit: int = 100_000) -> FloatArray:
    """The sample grid plus every key time (cycled keys included) inside [start, end]; a
    grid time within ``tolerance`` of a key time gives way to it."""
    from qtanimator.core.channel import Extrapolation

    periodic = (Extrapolation.CYCLE, Extrapolation.CYCLE_OFFSET, Extrapolation.BOUNCE)
    found: list[FloatArray] = []
    total = 0
    for ch in channels:
        if len(ch.keys) < 2:
            continue
        kt = ch.times
        t0, t1 = float(kt[0]), float(kt[-1])
        d = t1 - t0
        found.append(kt[(kt >= start) & (kt <= end)])
        for mode, lo, hi in ((ch.pre, start, t0), (ch.post, t1, end)):
            if mode not in periodic or hi <= lo:
                continue
            m0 = math.floor((lo - t0) / d) - 1
            m1 = math.ceil((hi - t0) / d) + 1
            base = np.concatenate([kt, t0 + t1 - kt]) if mode is Extrapolation.BOUNCE else kt
            total += (m1 - m0 + 1) * len(base)
            if total > limit:
                break
            shifted = (base[None, :] + d * np.arange(m0, m1 + 1, dtype=np.float64)[:, None]).reshape(-1)
            found.append(shifted[(shifted >= lo) & (shifted <= hi)])
    if not found:
        return grid
    keys = np.unique(np.concatenate(found))
    if len(keys) == 0:
        return grid
    # Merge keys closer than the tolerance, then drop grid times next to a key.
    keys = keys[np.concatenate([[True], np.diff(keys) > tolerance])]
    i = np.clip(np.searchsorted(keys, grid), 1, len(keys) - 1) if len(keys) > 1 else np.zeros(len(grid), int)
    near = np.abs(keys[i] - grid) <= tolerance
    if len(keys) > 1:
        near |= np.abs(keys[i - 1] - grid) <= tolerance
    merged: FloatArray = np.union1d(grid[~near], keys)
    return merged


def sample_times(start: float, end: float, fps: float, channels: Sequence[Channel] = ()) -> FloatArray:
    """Times from ``start`` to ``end`` (both included) every ``1 / fps`` seconds, plus every
    key time of ``channels`` (cycled keys included) inside that range; what the exports sample."""
    return _with_key_times(_sample_times(start, end, fps), channels, start, end)


def _channel_values(skeleton: Skeleton, channels: Sequence[Channel | None], times: FloatArray,
                    derivative: int) -> FloatArray:
    """(T, 3 + 3J) channel values (root translation, then x, y, z per joint) at ``times``;
    missing channels hold the skeleton's current value (derivative 0)."""
    nj = len(skeleton.joints)
    if derivative == 0:
        base = np.concatenate([skeleton.root_translation, skeleton.dof_values().reshape(-1)])
    else:
        base = np.zeros(3 + 3 * nj)
    out = np.broadcast_to(base, (len(times), 3 + 3 * nj)).copy()
    for i, ch in enumerate(list(channels)[: 3 + 3 * nj]):
        if ch is not None:
            out[:, i] = ch.evaluate(times, derivative)
    return out


def _channel_label(skeleton: Skeleton, index: int) -> str:
    """``root translation x`` or ``<joint> x rotation`` for an ``.anim``-layout channel."""
    if index < 3:
        return f"root translation {'xyz'[index]}"
    joint, axis = divmod(index - 3, 3)
    return f"{skeleton.joints[joint].name} {'xyz'[axis]} rotation"


def _top_influences(binding: SkinBinding, k: int) -> tuple[IntArray, FloatArray, IntArray]:
    """(V, k) strongest joints and renormalised weights, and the vertices that lost some."""
    pidx, pw = binding.padded(np.float64)
    idx: IntArray = np.asarray(pidx, dtype=np.int64)
    w: FloatArray = np.asarray(pw, dtype=np.float64)
    nonzero = (w != 0).sum(axis=1)
    order = np.argsort(-w, axis=1, kind="stable")[:, :k]
    top_j: IntArray = np.take_along_axis(idx, order, axis=1)
    top_w: FloatArray = np.take_along_axis(w, order, axis=1)
    if top_j.shape[1] < k:
        pad = k - top_j.shape[1]
        top_j = np.pad(top_j, ((0, 0), (0, pad)))
        top_w = np.pad(top_w, ((0, 0), (0, pad)))
    sums = top_w.sum(axis=1)
    top_w = np.where(sums[:, None] > 0, top_w / np.where(sums > 0, sums, 1.0)[:, None], top_w)
    top_j = np.where(top_w != 0, top_j, 0)
    dropped = np.flatnonzero(nonzero > k).astype(np.int64)
    return top_j, top_w, dropped


def _as_skin(skeleton: Skeleton, skin_or_mesh: Any) -> Skin:
    if isinstance(skin_or_mesh, Skin):
        return skin_or_mesh
    if isinstance(skin_or_mesh, tuple) and len(skin_or_mesh) == 2:
        mesh, weights = skin_or_mesh
        positions = np.asarray(getattr(mesh, "positions", getattr(mesh, "vertices", None)), dtype=np.float64)
        triangles = np.asarray(getattr(mesh, "triangles", getattr(mesh, "faces", None)), dtype=np.int64)
        if isinstance(weights, SkinBinding):
            binding = weights
        else:
            dense = np.asarray(weights, dtype=np.float64)
            if dense.shape[1] == len(skeleton.joints) - 1:  # MIT .attach: no root column
                dense = np.concatenate([np.zeros((len(dense), 1)), dense], axis=1)
            binding = SkinBinding.from_dense(dense)
        normals = getattr(mesh, "normals", None)
        if normals is not None and np.shape(normals) != positions.shape:
            normals = None  # per-corner OBJ normals, not one per vertex
        return Skin.from_bind_matrices(positions, triangles, binding, skeleton.bind_world_matrices(),
                                       normals=normals)
    raise TypeError("expected a core.skinning.Skin or a (mesh, weights) pair")


def build_character_scene(skeleton: Skeleton, skin_or_mesh_with_weights: Any,
                          channels: Sequence[Channel | None] | Any, start: float, end: float, fps: float,
                          *, interpolation: str = "LINEAR", max_influences: int = 4,
                          weight_tolerance: float = 1e-4, name: str = "character",
                          key_times: bool = True) -> CharacterExport:
    """The glTF scene :func:`export_character_glb` writes (see there)."""
    if interpolation not in ("LINEAR", "CUBICSPLINE"):
        raise ValueError("interpolation must be LINEAR or CUBICSPLINE")
    if not 1 <= max_influences <= 4:
        raise ValueError("max_influences must be 1 to 4")
    skin = _as_skin(skeleton, skin_or_mesh_with_weights)
    chans: list[Channel | None] = list(getattr(channels, "channels", channels))
    nj = len(skeleton.joints)
    if skin.num_joints < nj and skin.binding.num_joints > skin.num_joints:
        raise ValueError("the skin has fewer bind matrices than the skeleton has joints")
    times = _sample_times(start, end, fps)
    for i, chan in enumerate(chans[: 3 + 3 * nj]):
        if chan is not None and chan.is_weighted:
            warnings.warn(f"{name}: channel {i} ({_channel_label(skeleton, i)}) has weighted tangents, which glTF "
                          f"cannot hold: sampled at {fps:g} fps ({interpolation}).", GltfExportWarning, stacklevel=3)
    if key_times:
        times = _with_key_times(times, [c for c in chans[: 3 + 3 * nj] if c is not None], start, end)
    lo, hi = skeleton.dof_limits()
    raw = _channel_values(skeleton, chans, times, 0)
    root_t = raw[:, :3]
    dofs = raw[:, 3:].reshape(len(times), nj, 3)
    clamped = np.clip(dofs, lo, hi)
    free = clamped == dofs
    cubic = interpolation == "CUBICSPLINE"
    rates_in = rates_out = root_in = root_out = None
    if cubic:
        # One-sided derivatives, so a key with different in and out slopes (a kink) that
        # falls on a sample keeps both.
        delta = 1e-7 * max(1.0, abs(start), abs(end))
        d_in = _channel_values(skeleton, chans, times - delta, 1)
        d_out = _channel_values(skeleton, chans, times + delta, 1)
        root_in, root_out = d_in[:, :3], d_out[:, :3]
        rates_in = np.where(free, d_in[:, 3:].reshape(len(times), nj, 3), 0.0)
        rates_out = np.where(free, d_out[:, 3:].reshape(len(times), nj, 3), 0.0)

    scene = GltfScene(generator="qtanimator")
    offsets = np.array([j.offset for j in skeleton.joints], dtype=np.float64).reshape(nj, 3)
    samplers: list[GltfSampler] = []
    anim_channels: list[GltfAnimationChannel] = []
    out_times = times - start
    for ji, joint in enumerate(skeleton.joints):
        order = joint.rotation_order or skeleton.rotation_order
        if order not in ROTATION_ORDERS:
            raise ValueError(f"unknown rotation order {order!r}")
        q, dq_in = _euler_quaternions(clamped[:, ji], None if rates_in is None else rates_in[:, ji], order)
        _, dq_out = _euler_quaternions(clamped[:, ji], None if rates_out is None else rates_out[:, ji], order)
        # Keep consecutive keys in one hemisphere so slerp takes the short way.
        sign = np.ones(len(q))
        for k in range(1, len(q)):
            sign[k] = sign[k - 1] * (-1.0 if np.dot(q[k], q[k - 1]) * sign[k - 1] < 0 else 1.0)
        q = q * sign[:, None]
        translation = offsets[ji] + (root_t if joint.parent is None else np.zeros_like(root_t))
        node = GltfNode(name=joint.name, translation=translation[0].copy(), rotation=q[0].copy())
        if joint.parent is not None:
            scene.nodes[joint.parent].children.append(ji)
            node.parent = joint.parent
        scene.nodes.append(node)
        if cubic:
            assert dq_in is not None and dq_out is not None
            rot_vals = np.stack([dq_in * sign[:, None], q, dq_out * sign[:, None]], axis=1)
        else:
            rot_vals = q
        samplers.append(GltfSampler(out_times, rot_vals, interpolation))
        anim_channels.append(GltfAnimationChannel(len(samplers) - 1, ji, "rotation"))
        if joint.parent is None:
            if cubic:
                assert root_in is not None and root_out is not None
                t_vals = np.stack([root_in, translation, root_out], axis=1)
            else:
                t_vals = translation
            samplers.append(GltfSampler(out_times, t_vals, interpolation))
            anim_channels.append(GltfAnimationChannel(len(samplers) - 1, ji, "translation"))

    top_j, top_w, dropped = _top_influences(skin.binding, max_influences)
    max_rel = 0.0
    if len(dropped):
        # How much does dropping influences move the animated mesh? Compare with all the
        # influences (renormalised, so unnormalised source weights do not count as a change).
        from qtanimator.core.skinning import skin_positions

        full = Skin(skin.positions, skin.triangles, skin.binding.renormalized(), skin.inverse_bind_matrices)
        reduced = Skin(skin.positions, skin.triangles, SkinBinding.from_padded(top_j, top_w, skin.binding.num_joints),
                       skin.inverse_bind_matrices)
        diag = float(np.linalg.norm(np.ptp(skin.positions, axis=0))) or 1.0
        step = max(1, len(times) // 64)
        for k in range(0, len(times), step):
            world = skeleton.world_matrices(clamped[k], root_t[k])
            err = np.linalg.norm(skin_positions(full, world) - skin_positions(reduced, world), axis=1)
            max_rel = max(max_rel, float(err.max()) / diag)
        if max_rel > weight_tolerance:
            warnings.warn(f"{name}: {len(dropped)} vertices have more than {max_influences} influences; keeping "
                          f"the strongest {max_influences} moves the animated mesh by up to {max_rel:.2e} of its "
                          f"size.", GltfExportWarning, stacklevel=3)
    normals = None if skin.normals is None else np.asarray(skin.normals, dtype=np.float64)
    texcoords = None
    if skin.texcoords is not None and np.shape(skin.texcoords)[1] >= 2:
        # Our texture coordinates follow OpenGL (v up from the bottom of the image);
        # glTF puts the origin at the top left.
        texcoords = np.asarray(skin.texcoords, dtype=np.float64)[:, :2].copy()
        texcoords[:, 1] = 1.0 - texcoords[:, 1]
    prim = GltfPrimitive(np.asarray(skin.positions, dtype=np.float64), np.asarray(skin.triangles, dtype=np.int64),
                         normals, texcoords, top_j, top_w)
    scene.meshes.append(GltfMesh([prim], name))
    roots = [i for i, j in enumerate(skeleton.joints) if j.parent is None]
    scene.skins.append(GltfSkin(list(range(nj)), np.asarray(skin.inverse_bind_matrices[:nj], dtype=np.float64),
                                roots[0] if roots else None, name))
    mesh_node = len(scene.nodes)
    scene.nodes.append(GltfNode(name=name, mesh=0, skin=0))
    scene.roots = roots + [mesh_node]
    scene.animations.append(GltfAnimation(samplers, anim_channels, name))
    return CharacterExport(scene, times, dropped, max_rel, list(range(nj)), mesh_node)


def export_character_glb(path: str | os.PathLike[str], skeleton: Skeleton, skin_or_mesh_with_weights: Any,
                         channels: Sequence[Channel | None] | Any, start: float, end: float, fps: float,
                         *, interpolation: str = "LINEAR", max_influences: int = 4,
                         weight_tolerance: float = 1e-4, name: str = "character",
                         key_times: bool = True) -> CharacterExport:
    """Write a skinned, animated character to ``.glb``.

    ``skin_or_mesh_with_weights`` is a :class:`~qtanimator.core.skinning.Skin`, or a pair
    ``(mesh, weights)`` with a mesh that has ``positions`` / ``triangles`` (or ``vertices`` /
    ``faces``) and weights as a :class:`SkinBinding` or a dense (V, J) or MIT (V, J − 1)
    array; such a mesh is bound in the skeleton's zero pose. ``channels`` use the ``.anim``
    layout (root translation x, y, z, then x, y, z per joint; an :class:`AnimationClip`
    works too); missing channels hold the skeleton's current values and DOFs are clamped to
    their limits. The clip is sampled at ``fps`` from ``start`` to ``end`` (both included);
    exported time 0 is ``start``. With ``key_times`` the channels' key times (cycled ones
    too) are sampled as well, so keys and kinks are not cut off by the grid.
    ``interpolation="CUBICSPLINE"`` stores the channels' one-sided derivatives as in / out
    tangents, so the curve between samples follows the channels closely.

    Vertices keep their ``max_influences`` strongest joints, renormalised; when that moves the
    animated mesh by more than ``weight_tolerance`` × its bounding-box diagonal, a
    :class:`GltfExportWarning` is issued.
    """
    result = build_character_scene(skeleton, skin_or_mesh_with_weights, channels, start, end, fps,
                                   interpolation=interpolation, max_influences=max_influences,
                                   weight_tolerance=weight_tolerance, name=name, key_times=key_times)
    export_glb(path, result.scene)
    return result
