"""Small glTF 2.0 characters written from scratch, one per case that issue 21 names.

Each generator takes a folder, writes one file there and returns its path. The files are
built by hand -- JSON plus one binary buffer packed with numpy -- and nothing here uses
``qtanimator``, so a bug in the program's glTF code cannot leak into its test data.

Conventions shared by all files:

* The skinned meshes are authored in the rest pose, and every inverse bind matrix is the
  inverse of its joint's rest global matrix (times the placement above the skeleton for
  :func:`parent_above_skeleton`), so the rest pose shows the mesh exactly as authored.
* Vertices are weighted to the 2-4 nearest joints (by inverse squared distance), quantized so
  that each vertex's weights sum to exactly 1 (float weights in 1/256ths, normalized
  ``UNSIGNED_BYTE`` weights summing to 255, ``UNSIGNED_SHORT`` ones to 65535).
* Accessors have min / max where the specification asks for them; buffer views are 4-byte
  aligned; the GLB chunks are padded (JSON with spaces, BIN with zeros).
* Storage differs between files on purpose: ``.glb`` (most), ``.gltf`` with a base64 data URI
  (:func:`two_moving_roots`), ``.gltf`` with an external ``.bin`` (:func:`parent_above_skeleton`);
  interleaved POSITION / NORMAL with a ``byteStride`` (:func:`translating_hip`); a sparse
  accessor (the hat in :func:`three_meshes_and_rigid`); joint indices as ``UNSIGNED_BYTE`` or
  ``UNSIGNED_SHORT``.

The rows: :func:`translating_hip`, :func:`two_moving_roots`, :func:`gimbal_path`,
:func:`three_meshes_and_rigid`, :func:`three_animations`, :func:`cubic_and_step`,
:func:`scale_keys`, :func:`parent_above_skeleton`, :func:`unnamed_joints`; and
:func:`big_clip`, a large character for benchmarks. :data:`ROWS` lists the nine rows.
"""

from __future__ import annotations

import base64
import json
import math
import os
import struct
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "GIMBAL_MIDPOINTS", "PARENT_ABOVE_PLACEMENT", "ROWS", "Builder", "big_clip", "column", "quat", "qmul",
    "rotation_matrix", "cubic_and_step", "gimbal_path",
    "parent_above_skeleton", "scale_keys", "three_animations", "three_meshes_and_rigid", "translating_hip",
    "two_moving_roots", "unnamed_joints",
]

BYTE_U, SHORT_U, FLOAT = 5121, 5123, 5126
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
_DTYPES = {BYTE_U: np.dtype("u1"), SHORT_U: np.dtype("<u2"), 5125: np.dtype("<u4"), FLOAT: np.dtype("<f4")}
_KINDS = {1: "SCALAR", 2: "VEC2", 3: "VEC3", 4: "VEC4", 16: "MAT4"}


# --------------------------------------------------------------------------- small math
def quat(axis: Sequence[float], degrees: float) -> np.ndarray:
    """Unit quaternion ``(x, y, z, w)`` of a rotation by ``degrees`` about ``axis``."""
    a = np.asarray(axis, dtype=np.float64)
    a = a / np.linalg.norm(a)
    h = math.radians(degrees) / 2.0
    return np.array([*(a * math.sin(h)), math.cos(h)])


def qmul(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Hamilton product ``p q`` (the rotation ``q`` first, then ``p``)."""
    x1, y1, z1, w1 = p
    x2, y2, z2, w2 = q
    return np.array([
        w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
        w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
        w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
        w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
    ])


def qinv(q: np.ndarray) -> np.ndarray:
    return np.array([-q[0], -q[1], -q[2], q[3]])


def rotation_matrix(q: np.ndarray) -> np.ndarray:
    """3×3 rotation matrix of a quaternion ``(x, y, z, w)``."""
    x, y, z, w = q / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def _local(node: dict[str, Any]) -> np.ndarray:
    if "matrix" in node:
        return np.array(node["matrix"], dtype=np.float64).reshape(4, 4).T
    m = np.eye(4)
    m[:3, :3] = rotation_matrix(np.array(node.get("rotation", [0, 0, 0, 1.0]))) @ np.diag(node.get("scale", [1.0] * 3))
    m[:3, 3] = node.get("translation", [0.0, 0.0, 0.0])
    return m


# --------------------------------------------------------------------------- geometry
def column(bottom: Sequence[float], top: Sequence[float], width: float, rings: int = 4,
           depth: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """A square tube from ``bottom`` to ``top`` with ``rings`` rings of 4 vertices and capped
    ends: (rings·4, 3) positions and (T, 3) triangles."""
    b, t = np.asarray(bottom, dtype=np.float64), np.asarray(top, dtype=np.float64)
    axis = t - b
    length = np.linalg.norm(axis)
    d = axis / length
    helper = np.array([0.0, 0.0, 1.0]) if abs(d[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    s1 = np.cross(d, helper)
    s1 /= np.linalg.norm(s1)
    s2 = np.cross(d, s1)
    hw, hd = width / 2.0, (depth if depth is not None else width) / 2.0
    corners = [s1 * hw + s2 * hd, -s1 * hw + s2 * hd, -s1 * hw - s2 * hd, s1 * hw - s2 * hd]
    pos = np.array([b + axis * (r / (rings - 1)) + c for r in range(rings) for c in corners])
    tris = []
    for r in range(rings - 1):
        for c in range(4):
            a0, a1 = r * 4 + c, r * 4 + (c + 1) % 4
            tris += [(a0, a1, a1 + 4), (a0, a1 + 4, a0 + 4)]
    last = (rings - 1) * 4
    tris += [(0, 2, 1), (0, 3, 2), (last, last + 1, last + 2), (last, last + 2, last + 3)]
    return pos, np.array(tris, dtype=np.int64)


def merge(*parts: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Several (positions, triangles) pieces as one."""
    positions, triangles, base = [], [], 0
    for p, t in parts:
        positions.append(p)
        triangles.append(t + base)
        base += len(p)
    return np.concatenate(positions), np.concatenate(triangles)


def vertex_normals(positions: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    n = np.zeros_like(positions)
    face = np.cross(positions[triangles[:, 1]] - positions[triangles[:, 0]],
                    positions[triangles[:, 2]] - positions[triangles[:, 0]])
    for k in range(3):
        np.add.at(n, triangles[:, k], face)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return n / np.where(length > 0, length, 1.0)


def nearest_weights(positions: np.ndarray, anchors: np.ndarray, influences: int,
                    total: int) -> tuple[np.ndarray, np.ndarray]:
    """(V, 4) joint slots and integer weights summing to ``total``: each vertex is bound to its
    ``influences`` nearest anchors (inverse squared distance); unused slots (and any whose
    weight rounds to zero) hold joint 0 and weight 0."""
    influences = min(influences, len(anchors))
    d2 = ((positions[:, None, :] - anchors[None, :, :]) ** 2).sum(axis=2) + 1e-3
    order = np.argsort(d2, axis=1, kind="stable")[:, :influences]
    raw = 1.0 / np.take_along_axis(d2, order, axis=1)
    raw /= raw.sum(axis=1, keepdims=True)
    ints = np.floor(raw * total).astype(np.int64)
    remainder = raw * total - ints
    for v in range(len(ints)):  # largest remainders get the units left over
        short = total - int(ints[v].sum())
        for k in np.argsort(-remainder[v], kind="stable")[:short]:
            ints[v, k] += 1
    joints = np.zeros((len(positions), 4), dtype=np.int64)
    weights = np.zeros((len(positions), 4), dtype=np.int64)
    joints[:, :influences] = order
    weights[:, :influences] = ints
    joints[weights == 0] = 0  # a slot whose weight rounded to zero names no joint
    return joints, weights


# --------------------------------------------------------------------------- the builder
class Builder:
    """A glTF document and its single binary buffer, built up piece by piece."""

    def __init__(self, name: str) -> None:
        self.doc: dict[str, Any] = {
            "asset": {"version": "2.0", "generator": f"qtanimator tests/gltf_gen.py ({name})"},
            "scene": 0, "scenes": [{"nodes": []}], "nodes": [], "meshes": [], "materials": [], "skins": [],
            "animations": [], "accessors": [], "bufferViews": [], "buffers": [],
        }
        self.blob = bytearray()
        self._inputs: dict[bytes, int] = {}

    # ------------------------------------------------------------------ binary
    def view(self, data: bytes, target: int | None = None, stride: int | None = None) -> int:
        self.blob += b"\0" * (-len(self.blob) % 4)
        view: dict[str, Any] = {"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data)}
        if target is not None:
            view["target"] = target
        if stride is not None:
            view["byteStride"] = stride
        self.blob += data
        self.doc["bufferViews"].append(view)
        return len(self.doc["bufferViews"]) - 1

    def accessor(self, array: Any, ctype: int = FLOAT, *, target: int | None = None, normalized: bool = False,
                 minmax: bool = False, view: int | None = None, offset: int = 0) -> int:
        a = np.asarray(array)
        flat = a.reshape(len(a), -1)
        acc: dict[str, Any] = {"componentType": ctype, "count": len(a), "type": _KINDS[flat.shape[1]]}
        if view is None:
            acc["bufferView"] = self.view(flat.astype(_DTYPES[ctype]).tobytes(), target)
        else:
            acc["bufferView"], acc["byteOffset"] = view, offset
        if normalized:
            acc["normalized"] = True
        if minmax:
            stored = flat.astype(_DTYPES[ctype]).astype(np.float64)
            acc["min"] = [float(x) for x in stored.min(axis=0)]
            acc["max"] = [float(x) for x in stored.max(axis=0)]
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def interleaved(self, *arrays: np.ndarray) -> list[int]:
        """Float VEC3 arrays of one length in one vertex buffer view with a ``byteStride``."""
        block = np.concatenate([a.astype("<f4") for a in arrays], axis=1)
        stride = block.shape[1] * 4
        v = self.view(block.tobytes(), ARRAY_BUFFER, stride)
        out, offset = [], 0
        for a in arrays:
            out.append(self.accessor(a, view=v, offset=offset))
            stored = a.astype("<f4").astype(np.float64)
            self.doc["accessors"][-1]["min"] = [float(x) for x in stored.min(axis=0)]
            self.doc["accessors"][-1]["max"] = [float(x) for x in stored.max(axis=0)]
            offset += a.shape[1] * 4
        return out

    def sparse_positions(self, base: np.ndarray, changed: dict[int, Sequence[float]]) -> int:
        """A POSITION accessor: ``base`` with the vertices in ``changed`` replaced sparsely."""
        index = self.accessor(base, target=ARRAY_BUFFER)
        final = base.astype("<f4").astype(np.float64).copy()
        rows = sorted(changed)
        final[rows] = np.array([changed[r] for r in rows], dtype="<f4")
        acc = self.doc["accessors"][index]
        acc["sparse"] = {
            "count": len(rows),
            "indices": {"bufferView": self.view(np.array(rows, dtype="<u2").tobytes()), "componentType": SHORT_U},
            "values": {"bufferView": self.view(np.array([changed[r] for r in rows], dtype="<f4").tobytes())},
        }
        acc["min"] = [float(x) for x in final.min(axis=0)]
        acc["max"] = [float(x) for x in final.max(axis=0)]
        return index

    # ------------------------------------------------------------------ structure
    def node(self, name: str | None = None, parent: int | None = None, **props: Any) -> int:
        node: dict[str, Any] = {} if name is None else {"name": name}
        for key, value in props.items():
            node[key] = [float(x) for x in np.asarray(value).reshape(-1)] if key in (
                "translation", "rotation", "scale", "matrix") else value
        self.doc["nodes"].append(node)
        index = len(self.doc["nodes"]) - 1
        if parent is None:
            self.doc["scenes"][0]["nodes"].append(index)
        else:
            self.doc["nodes"][parent].setdefault("children", []).append(index)
        return index

    def parent_of(self, index: int) -> int | None:
        for i, n in enumerate(self.doc["nodes"]):
            if index in n.get("children", []):
                return i
        return None

    def rest_global(self, index: int | None) -> np.ndarray:
        m = np.eye(4)
        while index is not None:
            m = _local(self.doc["nodes"][index]) @ m
            index = self.parent_of(index)
        return m

    def material(self, name: str, color: Sequence[float]) -> int:
        self.doc["materials"].append({"name": name, "pbrMetallicRoughness": {
            "baseColorFactor": [float(c) for c in color], "metallicFactor": 0.0, "roughnessFactor": 0.8}})
        return len(self.doc["materials"]) - 1

    def skin(self, joints: Sequence[int], placement: np.ndarray | None = None, skeleton: int | None = None,
             name: str | None = None) -> int:
        """A skin whose inverse bind matrices make the rest pose show the authored mesh
        (``placement`` · vertex when the mesh is authored below a placement node)."""
        place = np.eye(4) if placement is None else placement
        ibm = np.array([np.linalg.inv(self.rest_global(j)) @ place for j in joints])
        skin: dict[str, Any] = {"joints": list(joints),
                                "inverseBindMatrices": self.accessor(ibm.transpose(0, 2, 1).reshape(-1, 16))}
        if skeleton is not None:
            skin["skeleton"] = skeleton
        if name is not None:
            skin["name"] = name
        self.doc["skins"].append(skin)
        return len(self.doc["skins"]) - 1

    def primitive(self, positions: np.ndarray, triangles: np.ndarray, *, material: int | None = None,
                  anchors: np.ndarray | None = None, influences: int = 4, weight_type: int = FLOAT,
                  joint_type: int = BYTE_U, interleave: bool = False, position_accessor: int | None = None,
                  joint_ids: Sequence[int] | None = None) -> dict[str, Any]:
        """A triangle primitive; with ``anchors`` (rest positions of the skin's joints, in the
        skin's joint order, or of the joints ``joint_ids`` names by skin index) it gets
        JOINTS_0 / WEIGHTS_0."""
        normals = vertex_normals(positions, triangles)
        if position_accessor is not None:
            attrs = {"POSITION": position_accessor, "NORMAL": self.accessor(normals, target=ARRAY_BUFFER)}
        elif interleave:
            p, n = self.interleaved(positions, normals)
            attrs = {"POSITION": p, "NORMAL": n}
        else:
            attrs = {"POSITION": self.accessor(positions, target=ARRAY_BUFFER, minmax=True),
                     "NORMAL": self.accessor(normals, target=ARRAY_BUFFER)}
        if anchors is not None:
            total = {FLOAT: 256, BYTE_U: 255, SHORT_U: 65535}[weight_type]
            joints, ints = nearest_weights(positions, anchors, influences, total)
            if joint_ids is not None:
                joints = np.where(ints > 0, np.asarray(joint_ids)[joints], 0)
            weights = ints / total if weight_type == FLOAT else ints
            attrs["JOINTS_0"] = self.accessor(joints, joint_type, target=ARRAY_BUFFER)
            attrs["WEIGHTS_0"] = self.accessor(weights, weight_type, target=ARRAY_BUFFER,
                                               normalized=weight_type != FLOAT)
        index_type = BYTE_U if len(positions) < 256 else SHORT_U if len(positions) < 65536 else 5125
        prim: dict[str, Any] = {"attributes": attrs, "mode": 4,
                                "indices": self.accessor(triangles.reshape(-1), index_type,
                                                         target=ELEMENT_ARRAY_BUFFER)}
        if material is not None:
            prim["material"] = material
        return prim

    def mesh(self, primitives: list[dict[str, Any]], name: str | None = None) -> int:
        mesh: dict[str, Any] = {"primitives": primitives}
        if name is not None:
            mesh["name"] = name
        self.doc["meshes"].append(mesh)
        return len(self.doc["meshes"]) - 1

    def animation(self, name: str | None,
                  channels: Sequence[tuple[int, str, Sequence[float], Any, str]]) -> int:
        """channels: (node, path, times, values, interpolation). CUBICSPLINE values are
        (K, 3, n): in-tangent, value, out-tangent per key. Identical time lists share one
        input accessor."""
        anim: dict[str, Any] = {"samplers": [], "channels": []}
        if name is not None:
            anim["name"] = name
        for node, path, times, values, interpolation in channels:
            t = np.asarray(times, dtype="<f4")
            key = t.tobytes()
            if key not in self._inputs:
                self._inputs[key] = self.accessor(t, minmax=True)
            v = np.asarray(values, dtype=np.float64)
            v = v.reshape(-1, v.shape[-1])
            anim["samplers"].append({"input": self._inputs[key], "output": self.accessor(v),
                                     "interpolation": interpolation})
            anim["channels"].append({"sampler": len(anim["samplers"]) - 1, "target": {"node": node, "path": path}})
        self.doc["animations"].append(anim)
        return len(self.doc["animations"]) - 1

    # ------------------------------------------------------------------ output
    def save(self, path: Path, external: bool = False) -> Path:
        """``.glb``; or ``.gltf`` with the buffer as a base64 data URI, or (``external``) as a
        ``.bin`` file of the same stem beside it."""
        doc = {k: v for k, v in self.doc.items() if v != []}
        self.blob += b"\0" * (-len(self.blob) % 4)
        buffer: dict[str, Any] = {"byteLength": len(self.blob)}
        if path.suffix == ".glb":
            doc["buffers"] = [buffer]
            text = json.dumps(doc, separators=(",", ":")).encode()
            text += b" " * (-len(text) % 4)
            body = (struct.pack("<II", len(text), 0x4E4F534A) + text
                    + struct.pack("<II", len(self.blob), 0x004E4942) + bytes(self.blob))
            path.write_bytes(struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body)
            return path
        if external:
            path.with_suffix(".bin").write_bytes(bytes(self.blob))
            buffer["uri"] = path.with_suffix(".bin").name
        else:
            buffer["uri"] = "data:application/octet-stream;base64," + base64.b64encode(bytes(self.blob)).decode()
        doc["buffers"] = [buffer]
        path.write_text(json.dumps(doc, indent=1))
        return path


def _anchors(b: Builder, joints: Sequence[int], placement: np.ndarray | None = None) -> np.ndarray:
    """Rest positions of joints, in the space the mesh is authored in."""
    inv = np.eye(4) if placement is None else np.linalg.inv(placement)
    return np.array([(inv @ b.rest_global(j))[:3, 3] for j in joints])


def _folder(folder: str | os.PathLike[str]) -> Path:
    p = Path(folder)
    p.mkdir(parents=True, exist_ok=True)
    return p


def _rotations(axis: Sequence[float], degrees: Sequence[float]) -> np.ndarray:
    return np.array([quat(axis, d) for d in degrees])


# =========================================================================== the rows
def translating_hip(folder: str | os.PathLike[str]) -> Path:
    """(a) A fixed root joint "root" (never animated) and below it "hips", whose translation
    bobs up and down (and sways) while it turns about Y; "spine" above, two legs
    ("leg_l" → "knee_l", "leg_r" → "knee_r") below. One skinned mesh "body" (6 tubes, 88
    vertices, 4 influences, float weights, u8 joints, POSITION / NORMAL interleaved).

    Animation "bounce", LINEAR, 0-1 s: hips translation at 0, 0.25, 0.5, 0.75, 1; hips
    rotation at 0, 0.5, 1; leg_l / leg_r rotation at 0, 0.5, 1; knee_l at 0, 0.3, 0.6, 1."""
    b = Builder("translating_hip")
    root = b.node("root", translation=[0.3, 0.0, 0.0])
    hips = b.node("hips", root, translation=[0.0, 1.0, 0.0])
    spine = b.node("spine", hips, translation=[0.0, 0.5, 0.0])
    leg_l = b.node("leg_l", hips, translation=[0.2, -0.1, 0.0])
    knee_l = b.node("knee_l", leg_l, translation=[0.0, -0.45, 0.0])
    leg_r = b.node("leg_r", hips, translation=[-0.2, -0.1, 0.0])
    knee_r = b.node("knee_r", leg_r, translation=[0.0, -0.45, 0.0])
    joints = [root, hips, spine, leg_l, knee_l, leg_r, knee_r]
    anchors = _anchors(b, joints)
    o = np.array([0.3, 0.0, 0.0])
    pos, tris = merge(
        column(o + [0, 0.85, 0], o + [0, 1.1, 0], 0.5, rings=4, depth=0.3),     # pelvis
        column(o + [0, 1.1, 0], o + [0, 1.8, 0], 0.45, rings=4, depth=0.25),    # torso
        column(o + [0.2, 0.9, 0], o + [0.2, 0.45, 0], 0.14, rings=3),           # thighs
        column(o + [-0.2, 0.9, 0], o + [-0.2, 0.45, 0], 0.14, rings=3),
        column(o + [0.2, 0.45, 0], o + [0.2, 0.0, 0], 0.12, rings=4),           # shins
        column(o + [-0.2, 0.45, 0], o + [-0.2, 0.0, 0], 0.12, rings=4),
    )
    mesh = b.mesh([b.primitive(pos, tris, anchors=anchors, influences=4, interleave=True)], "body")
    b.node("body", mesh=mesh, skin=0)
    b.skin(joints, skeleton=root, name="skeleton")
    t5 = [0.0, 0.25, 0.5, 0.75, 1.0]
    b.animation("bounce", [
        (hips, "translation", t5, [[0, 1.0, 0], [0.1, 0.8, 0.05], [0, 1.0, 0], [-0.1, 0.8, -0.05], [0, 1.0, 0]],
         "LINEAR"),
        (hips, "rotation", [0.0, 0.5, 1.0], _rotations([0, 1, 0], [-25, 25, -25]), "LINEAR"),
        (leg_l, "rotation", [0.0, 0.5, 1.0], _rotations([1, 0, 0], [30, -30, 30]), "LINEAR"),
        (leg_r, "rotation", [0.0, 0.5, 1.0], _rotations([1, 0, 0], [-30, 30, -30]), "LINEAR"),
        (knee_l, "rotation", [0.0, 0.3, 0.6, 1.0], _rotations([1, 0, 0], [0, 60, 10, 0]), "LINEAR"),
    ])
    return b.save(_folder(folder) / "translating_hip.glb")


def two_moving_roots(folder: str | os.PathLike[str]) -> Path:
    """(b) One skin over two separate hierarchies: scene roots "left_root" (→ "left_tip") and
    "right_root" (→ "right_tip"), no common parent and no ``skin.skeleton``. Both roots have
    animated translation and rotation. Mesh "pair": a tube on each side and a bridge between
    them whose vertices mix joints of both roots (72 vertices, 3 influences, normalized u8
    weights, u16 joints). Stored as ``.gltf`` with a base64 data URI.

    Animation "drift", LINEAR, 0-1.2 s: left_root translation at 0, 0.4, 1.2 and rotation at
    0, 0.6, 1.2; right_root translation at 0, 0.3, 0.6, 0.9, 1.2 and rotation at 0, 1.2;
    left_tip rotation at 0, 0.6, 1.2."""
    b = Builder("two_moving_roots")
    left = b.node("left_root", translation=[-1.0, 0.0, 0.0])
    left_tip = b.node("left_tip", left, translation=[0.0, 1.5, 0.0])
    right = b.node("right_root", translation=[1.0, 0.0, 0.0], rotation=quat([0, 0, 1], 10))
    right_tip = b.node("right_tip", right, translation=[0.0, 1.2, 0.0])
    joints = [left, left_tip, right, right_tip]
    anchors = _anchors(b, joints)
    pos, tris = merge(
        column(anchors[0], anchors[1] + [0, 0.3, 0], 0.3, rings=6),
        column(anchors[2], anchors[3] + (anchors[3] - anchors[2]) * 0.25, 0.3, rings=6),
        column([-0.8, 0.6, 0.0], [0.8, 0.6, 0.0], 0.2, rings=6),
    )
    mesh = b.mesh([b.primitive(pos, tris, anchors=anchors, influences=3, weight_type=BYTE_U,
                               joint_type=SHORT_U)], "pair")
    b.node("pair", mesh=mesh, skin=0)
    b.skin(joints)
    b.animation("drift", [
        (left, "translation", [0.0, 0.4, 1.2], [[-1, 0, 0], [-1.3, 0.4, 0.2], [-0.8, -0.2, 0]], "LINEAR"),
        (left, "rotation", [0.0, 0.6, 1.2], _rotations([0, 0, 1], [0, -40, 15]), "LINEAR"),
        (right, "translation", [0.0, 0.3, 0.6, 0.9, 1.2],
         [[1, 0, 0], [1.2, 0.3, 0], [1.0, 0.6, 0.3], [0.8, 0.3, 0], [1, 0, 0]], "LINEAR"),
        (right, "rotation", [0.0, 1.2], [quat([0, 0, 1], 10), qmul(quat([1, 0, 0], 50), quat([0, 0, 1], -30))],
         "LINEAR"),
        (left_tip, "rotation", [0.0, 0.6, 1.2], _rotations([1, 0, 1], [0, 70, -20]), "LINEAR"),
    ])
    return b.save(_folder(folder) / "two_moving_roots.gltf")


def _gimbal_keys() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """q0, q1, q2 and the two gimbal-locked midpoints m1, m2: the shortest slerp from q0 to
    q1 passes m1 = Rz(30°)·Ry(90°)·Rx(20°) at u = 0.5 (Z-Y-X Euler angles with pitch 90°), and
    the one from q1 to q2 passes m2 = Rx(-160°)·Ry(90°)·Rz(-170°) (X-Y-Z angles, pitch 90°)."""
    m1 = qmul(qmul(quat([0, 0, 1], 30), quat([0, 1, 0], 90)), quat([1, 0, 0], 20))
    q0 = qmul(m1, quat([1, 1, 0], -35))
    q1 = qmul(m1, quat([1, 1, 0], 35))
    m2 = qmul(qmul(quat([1, 0, 0], -160), quat([0, 1, 0], 90)), quat([0, 0, 1], -170))
    q2 = qmul(m2, qinv(qmul(qinv(m2), q1)))  # q1 mirrored through m2 along the great circle
    assert float(np.dot(q1, q2)) > 0.1, "the mirrored key must lie on the shorter arc"
    return q0, q1, q2, m1, m2


#: (time, unit quaternion) pairs where the "arm" joint of :func:`gimbal_path` is exactly in
#: gimbal lock (the midpoints between its keys).
GIMBAL_MIDPOINTS = ((0.5, _gimbal_keys()[3]), (1.5, _gimbal_keys()[4]))


def gimbal_path(folder: str | os.PathLike[str]) -> Path:
    """(c) "base" (rotating slowly about Y) → "arm" → "tip" 4 units further (a long bone so an
    angle error shows). The arm's rotation keys at 0, 1, 2 s are placed so that the shortest
    slerp between them passes exactly through gimbal lock half-way (see
    :data:`GIMBAL_MIDPOINTS`). Mesh "limb": a short tube, a long tube along the arm and a fin
    at its end, 64 vertices, 2 influences.

    Animation "through_lock", LINEAR, 0-2 s: arm rotation at 0, 1, 2; base rotation at 0, 2."""
    b = Builder("gimbal_path")
    base = b.node("base")
    arm = b.node("arm", base, translation=[0.0, 1.0, 0.0])
    tip = b.node("tip", arm, translation=[0.0, 4.0, 0.0])
    joints = [base, arm, tip]
    anchors = _anchors(b, joints)
    pos, tris = merge(
        column([0, 0, 0], [0, 1, 0], 0.3, rings=3),
        column([0, 1, 0], [0, 5, 0], 0.2, rings=10),
        column([0, 4.8, 0], [1.0, 4.8, 0], 0.1, rings=3),
    )
    mesh = b.mesh([b.primitive(pos, tris, anchors=anchors, influences=2)], "limb")
    b.node("limb", mesh=mesh, skin=0)
    b.skin(joints, skeleton=base)
    q0, q1, q2, _, _ = _gimbal_keys()
    b.animation("through_lock", [
        (arm, "rotation", [0.0, 1.0, 2.0], [q0, q1, q2], "LINEAR"),
        (base, "rotation", [0.0, 2.0], _rotations([0, 1, 0], [0, 40]), "LINEAR"),
    ])
    return b.save(_folder(folder) / "gimbal_path.glb")


def three_meshes_and_rigid(folder: str | os.PathLike[str]) -> Path:
    """(d) Three skinned meshes on one skin and a rigid (unskinned) hat below a joint.

    Nodes in index order: 0 "hands" (mesh 2 "hands": primitives left / right hand), 1 "body"
    (mesh 0 "body": primitives torso / arms), 2 "head_mesh" (mesh 1 "head"), then joints
    "pelvis" (root) → "chest" → "neck" → "head", "chest" → "arm_l" → "hand_l", "chest" →
    "arm_r" → "hand_r", and "hat" (mesh 3 "hat", no skin) as a child of the "head" joint with
    its own translation and tilt; the hat's POSITION is a sparse accessor (2 raised vertices).
    Vertices: body 20 + 40, head 16, hands 12 + 12, hat 12.
    Node order therefore differs from mesh order. Five materials with different
    baseColorFactor. Normalized u16 weights, 2-4 influences, u8 joints.

    Animation "wave", LINEAR, 0-1.5 s: arm_l rotation at 0, 0.5, 1, 1.5; hand_l rotation at
    0, 0.25, 0.5, 0.75, 1, 1.25, 1.5; head rotation at 0, 0.75, 1.5; chest rotation at 0, 1.5;
    pelvis translation at 0, 0.75, 1.5."""
    b = Builder("three_meshes_and_rigid")
    hands_node = b.node("hands")
    body_node = b.node("body")
    head_node = b.node("head_mesh")
    pelvis = b.node("pelvis", translation=[0.0, 1.0, 0.0])
    chest = b.node("chest", pelvis, translation=[0.0, 0.6, 0.0])
    neck = b.node("neck", chest, translation=[0.0, 0.5, 0.0])
    head = b.node("head", neck, translation=[0.0, 0.2, 0.0])
    arm_l = b.node("arm_l", chest, translation=[0.3, 0.4, 0.0])
    hand_l = b.node("hand_l", arm_l, translation=[0.6, 0.0, 0.0])
    arm_r = b.node("arm_r", chest, translation=[-0.3, 0.4, 0.0], rotation=quat([0, 0, 1], 20))
    hand_r = b.node("hand_r", arm_r, translation=[-0.6, 0.0, 0.0])
    joints = [pelvis, chest, neck, head, arm_l, hand_l, arm_r, hand_r]
    anchors = _anchors(b, joints)
    a = {j: anchors[k] for k, j in enumerate(joints)}
    shirt = b.material("shirt", [0.2, 0.4, 0.9, 1.0])
    sleeves = b.material("sleeves", [0.1, 0.3, 0.7, 1.0])
    skin_color = b.material("skin", [0.9, 0.7, 0.6, 1.0])
    gloves = b.material("gloves", [0.2, 0.2, 0.2, 1.0])
    hat_color = b.material("hat", [0.8, 0.1, 0.1, 1.0])
    w = {"anchors": anchors, "weight_type": SHORT_U}
    torso = column(a[pelvis] - [0, 0.1, 0], a[neck], 0.45, rings=5, depth=0.25)
    arms = merge(column(a[arm_l] - [0.1, 0, 0], a[hand_l], 0.12, rings=5),
                 column(a[arm_r] + [0.1, 0, 0], a[hand_r], 0.12, rings=5))
    b.mesh([b.primitive(*torso, material=shirt, influences=3, **w),
            b.primitive(*arms, material=sleeves, influences=2, **w)], "body")
    head_geo = column(a[neck], a[head] + [0, 0.35, 0], 0.3, rings=4)
    b.mesh([b.primitive(*head_geo, material=skin_color, influences=2, **w)], "head")
    left_hand = column(a[hand_l], a[hand_l] + [0.2, -0.05, 0], 0.1, rings=3)
    right_hand = column(a[hand_r], a[hand_r] + [-0.2, -0.05, 0], 0.1, rings=3)
    b.mesh([b.primitive(*left_hand, material=gloves, influences=4, **w),
            b.primitive(*right_hand, material=gloves, influences=4, **w)], "hands")
    hat_pos, hat_tris = column([0, 0, 0], [0, 0.2, 0], 0.35, rings=3)
    hat_accessor = b.sparse_positions(hat_pos, {9: [0.05, 0.3, 0.05], 11: [-0.05, 0.32, -0.05]})
    b.mesh([b.primitive(hat_pos, hat_tris, material=hat_color, position_accessor=hat_accessor)], "hat")
    b.node("hat", head, translation=[0.0, 0.35, 0.0], rotation=quat([0, 0, 1], 15), mesh=3)
    b.doc["nodes"][hands_node].update(mesh=2, skin=0)
    b.doc["nodes"][body_node].update(mesh=0, skin=0)
    b.doc["nodes"][head_node].update(mesh=1, skin=0)
    b.skin(joints, skeleton=pelvis)
    t4 = [0.0, 0.5, 1.0, 1.5]
    b.animation("wave", [
        (arm_l, "rotation", t4, _rotations([0, 0, 1], [0, 70, 20, 70]), "LINEAR"),
        (hand_l, "rotation", np.linspace(0, 1.5, 7), _rotations([0, 1, 1], [0, 40, -40, 40, -40, 40, 0]), "LINEAR"),
        (head, "rotation", [0.0, 0.75, 1.5], _rotations([1, 0, 0], [0, 25, 0]), "LINEAR"),
        (chest, "rotation", [0.0, 1.5], _rotations([0, 1, 0], [-20, 20]), "LINEAR"),
        (pelvis, "translation", [0.0, 0.75, 1.5], [[0, 1, 0], [0.2, 0.9, 0.1], [0, 1, 0]], "LINEAR"),
    ])
    return b.save(_folder(folder) / "three_meshes_and_rigid.glb")


def three_animations(folder: str | os.PathLike[str]) -> Path:
    """(e) "root" → "spine" → "arm", "root" → "leg"; mesh "figure" (3 tubes, 60 vertices,
    3 influences). Three animations with different lengths and different joints:

    * "idle", 0-1 s: spine rotation at 0, 0.5, 1;
    * "walk", 0-2 s: leg rotation at 0, 0.5, 1, 1.5, 2; root translation at 0, 2;
    * "run", 0.25-0.75 s (it starts late): arm rotation at 0.25, 0.375, 0.5, 0.75; leg rotation
      at 0.25, 0.5, 0.75; root translation at 0.25, 0.75."""
    b = Builder("three_animations")
    root = b.node("root")
    spine = b.node("spine", root, translation=[0.0, 1.0, 0.0])
    arm = b.node("arm", spine, translation=[0.3, 0.5, 0.0])
    leg = b.node("leg", root, translation=[0.2, 0.0, 0.0])
    joints = [root, spine, arm, leg]
    anchors = _anchors(b, joints)
    pos, tris = merge(
        column([0, 0.0, 0], [0, 1.6, 0], 0.3, rings=7),
        column([0.3, 1.5, 0], [1.2, 1.5, 0], 0.1, rings=4),
        column([0.2, 0.0, 0], [0.2, -1.0, 0], 0.12, rings=4),
    )
    mesh = b.mesh([b.primitive(pos, tris, anchors=anchors, influences=3)], "figure")
    b.node("figure", mesh=mesh, skin=0)
    b.skin(joints, skeleton=root)
    b.animation("idle", [(spine, "rotation", [0.0, 0.5, 1.0], _rotations([0, 0, 1], [0, 8, 0]), "LINEAR")])
    b.animation("walk", [
        (leg, "rotation", [0.0, 0.5, 1.0, 1.5, 2.0], _rotations([1, 0, 0], [0, 35, 0, -35, 0]), "LINEAR"),
        (root, "translation", [0.0, 2.0], [[0, 0, 0], [0, 0, 2.0]], "LINEAR"),
    ])
    b.animation("run", [
        (arm, "rotation", [0.25, 0.375, 0.5, 0.75], _rotations([0, 1, 0], [0, 60, -60, 0]), "LINEAR"),
        (leg, "rotation", [0.25, 0.5, 0.75], _rotations([1, 0, 0], [50, -50, 50]), "LINEAR"),
        (root, "translation", [0.25, 0.75], [[0, 0, 0], [0, 0.2, 1.5]], "LINEAR"),
    ])
    return b.save(_folder(folder) / "three_animations.glb")


def cubic_and_step(folder: str | os.PathLike[str]) -> Path:
    """(f) "root" → "upper" → "lower" → "tip"; mesh "chain" (3 tubes, 56 vertices, 2-3
    influences). Animation "spline", 0-2 s:

    * root translation, CUBICSPLINE at 0, 0.7, 2 (uneven intervals, so the tangents' scaling by
      the key interval matters);
    * upper rotation, CUBICSPLINE at 0, 0.8, 1.2, 2: tangents not tangent to the sphere (each
      has a component along its key's quaternion as well as across it);
    * lower rotation, STEP at 0, 0.5, 1, 1.5 (big jumps: 0°, 70°, -50°, 20° about X);
    * tip rotation, CUBICSPLINE with two keys at 0.3, 1.7 (zero and non-zero tangents)."""
    b = Builder("cubic_and_step")
    root = b.node("root")
    upper = b.node("upper", root, translation=[0.0, 1.0, 0.0])
    lower = b.node("lower", upper, translation=[0.0, 1.5, 0.0])
    tip = b.node("tip", lower, translation=[0.0, 1.5, 0.0])
    joints = [root, upper, lower, tip]
    anchors = _anchors(b, joints)
    pos, tris = merge(
        column([0, 0, 0], [0, 1.0, 0], 0.4, rings=3),
        column([0, 1.0, 0], [0, 2.5, 0], 0.3, rings=6),
        column([0, 2.5, 0], [0, 4.3, 0], 0.2, rings=5),
    )
    mesh = b.mesh([b.primitive(pos, tris, anchors=anchors, influences=3)], "chain")
    b.node("chain", mesh=mesh, skin=0)
    b.skin(joints, skeleton=root)
    translation = np.array([
        [[0, 0, 0], [0, 0, 0], [1.0, 0.5, 0]],
        [[0.5, -1.0, 0.3], [0.6, 0.2, 0.1], [-0.4, 0.8, 0.2]],
        [[2.0, 0, -1.0], [0.0, 0.4, 0.5], [0, 0, 0]],
    ])
    values = [quat([0, 0, 1], 0), quat([0, 0, 1], 60), quat([1, 0, 1], -45),
              quat([0, 1, 0], 80)]
    rng = np.random.default_rng(21)
    rotation = []
    for q in values:
        across = rng.normal(size=(2, 4)) * 0.6
        rotation.append([across[0] + 0.4 * q, q, across[1] - 0.3 * q])  # in-tangent, value, out-tangent
    tip_keys = [[[0, 0, 0, 0], quat([0, 0, 1], -30), [0.3, 0.0, 0.2, 0.1]],
                [[0.0, 0.5, 0.0, -0.2], quat([1, 1, 0], 60), [0, 0, 0, 0]]]
    b.animation("spline", [
        (root, "translation", [0.0, 0.7, 2.0], translation, "CUBICSPLINE"),
        (upper, "rotation", [0.0, 0.8, 1.2, 2.0], np.array(rotation), "CUBICSPLINE"),
        (lower, "rotation", [0.0, 0.5, 1.0, 1.5], _rotations([1, 0, 0], [0, 70, -50, 20]), "STEP"),
        (tip, "rotation", [0.3, 1.7], np.array(tip_keys), "CUBICSPLINE"),
    ])
    return b.save(_folder(folder) / "cubic_and_step.glb")


def scale_keys(folder: str | os.PathLike[str]) -> Path:
    """(g) "root" → "stretch" → "child" (rest rotation 30° about Z) → "squash"; mesh "stack"
    (3 tubes, 64 vertices, 3 influences). Animation "breathe", 0-1.5 s:

    * stretch scale, LINEAR non-uniform at 0, 0.5, 1, 1.5: (1,1,1), (1.5,0.6,1), (0.7,1.8,1.3), (1,1,1);
    * squash scale, STEP at 0, 0.6, 1.2;
    * child scale, CUBICSPLINE at 0, 1.5;
    * root translation, LINEAR at 0, 1.5."""
    b = Builder("scale_keys")
    root = b.node("root")
    stretch = b.node("stretch", root, translation=[0.0, 1.0, 0.0])
    child = b.node("child", stretch, translation=[0.0, 1.0, 0.0], rotation=quat([0, 0, 1], 30))
    squash = b.node("squash", child, translation=[0.0, 0.8, 0.0])
    joints = [root, stretch, child, squash]
    anchors = _anchors(b, joints)
    pos, tris = merge(
        column(anchors[0], anchors[1], 0.4, rings=4),
        column(anchors[1], anchors[2], 0.35, rings=6),
        column(anchors[2], anchors[3] + (anchors[3] - anchors[2]) * 0.6, 0.25, rings=6),
    )
    mesh = b.mesh([b.primitive(pos, tris, anchors=anchors, influences=3)], "stack")
    b.node("stack", mesh=mesh, skin=0)
    b.skin(joints, skeleton=root)
    b.animation("breathe", [
        (stretch, "scale", [0.0, 0.5, 1.0, 1.5], [[1, 1, 1], [1.5, 0.6, 1], [0.7, 1.8, 1.3], [1, 1, 1]], "LINEAR"),
        (squash, "scale", [0.0, 0.6, 1.2], [[1, 1, 1], [2.0, 0.5, 1.0], [0.6, 1.0, 2.2]], "STEP"),
        (child, "scale", [0.0, 1.5], [[[0, 0, 0], [1, 1, 1], [0.8, -0.5, 0.2]],
                                      [[-0.6, 0.9, 0.0], [1.2, 0.7, 1.0], [0, 0, 0]]], "CUBICSPLINE"),
        (root, "translation", [0.0, 1.5], [[0, 0, 0], [0.5, 0.0, -0.5]], "LINEAR"),
    ])
    return b.save(_folder(folder) / "scale_keys.glb")


#: The rest placement of the skeleton in :func:`parent_above_skeleton`: the "Z_UP" node
#: (translation (0.5, 0, -2), -90° about X) times the "Armature" node (a ``matrix``: uniform
#: scale 0.5, translation (0, 0.1, 0)). The mesh is authored in Armature space, so its rest
#: world positions are this matrix times the POSITION values.
PARENT_ABOVE_PLACEMENT = np.array([
    [1.0, 0.0, 0.0, 0.5], [0.0, 0.0, 1.0, 0.0], [0.0, -1.0, 0.0, -2.0], [0.0, 0.0, 0.0, 1.0],
]) @ np.array([[0.5, 0, 0, 0.0], [0, 0.5, 0, 0.1], [0, 0, 0.5, 0.0], [0, 0, 0, 1.0]])


def parent_above_skeleton(folder: str | os.PathLike[str]) -> Path:
    """(h) The skeleton hangs below two non-joint nodes that place it: "Z_UP" (TRS: translation
    (0.5, 0, -2), rotation -90° about X, Z-up to Y-up) → "Armature" (a ``matrix``: scale 0.5,
    translation (0, 0.1, 0)) → joints "root" → "spine" → "head" built along +Z, and the
    skinned mesh node "body_mesh", also below "Armature" and with a translation of its own that
    the specification says to ignore. Mesh "body" (3 tubes, 56 vertices, 4 influences). Stored
    as ``.gltf`` with an external ``parent_above_skeleton.bin``.

    Animation "sway", LINEAR, 0-2 s: root translation at 0, 1, 2; spine rotation at 0, 1, 2;
    head rotation at 0, 0.5, 1.5, 2."""
    b = Builder("parent_above_skeleton")
    z_up = b.node("Z_UP", translation=[0.5, 0.0, -2.0], rotation=quat([1, 0, 0], -90))
    armature_matrix = np.array([[0.5, 0, 0, 0.0], [0, 0.5, 0, 0.1], [0, 0, 0.5, 0.0], [0, 0, 0, 1.0]])
    armature = b.node("Armature", z_up, matrix=armature_matrix.T)
    body_node = b.node("body_mesh", armature, translation=[3.0, 3.0, 3.0])
    root = b.node("root", armature, translation=[0.0, 0.0, 1.0])
    spine = b.node("spine", root, translation=[0.0, 0.0, 1.0])
    head = b.node("head", spine, translation=[0.0, 0.0, 0.8])
    joints = [root, spine, head]
    placement = b.rest_global(armature)
    assert np.allclose(placement, PARENT_ABOVE_PLACEMENT)
    anchors = _anchors(b, joints, placement)
    pos, tris = merge(
        column([0, 0, 0.0], [0, 0, 1.0], 0.5, rings=4),
        column([0, 0, 1.0], [0, 0, 1.8], 0.45, rings=6),
        column([0, 0, 1.8], [0, 0, 2.4], 0.3, rings=4),
    )
    mesh = b.mesh([b.primitive(pos, tris, anchors=anchors, influences=3)], "body")
    b.doc["nodes"][body_node].update(mesh=mesh, skin=0)
    b.skin(joints, placement=placement, skeleton=root)
    b.animation("sway", [
        (root, "translation", [0.0, 1.0, 2.0], [[0, 0, 1], [0.4, 0.3, 1.2], [0, 0, 1]], "LINEAR"),
        (spine, "rotation", [0.0, 1.0, 2.0], _rotations([1, 1, 0], [0, 45, 0]), "LINEAR"),
        (head, "rotation", [0.0, 0.5, 1.5, 2.0], _rotations([0, 0, 1], [0, 90, -90, 0]), "LINEAR"),
    ])
    return b.save(_folder(folder) / "parent_above_skeleton.gltf", external=True)


def unnamed_joints(folder: str | os.PathLike[str]) -> Path:
    """(i) No node, mesh, skin or animation has a name: joints 0 → 1 → 2 and 0 → 3, mesh node
    4 (2 tubes, 48 vertices, 2 influences). Two unnamed animations (the program calls them
    "Animation 0" and "Animation 1"):

    * animation 0, 0-1 s: node 1 rotation at 0, 0.5, 1; node 0 translation at 0, 1;
    * animation 1, 0-0.6 s: node 3 rotation at 0, 0.2, 0.4, 0.6; node 2 rotation at 0, 0.6."""
    b = Builder("unnamed_joints")
    j0 = b.node()
    j1 = b.node(None, j0, translation=[0.0, 1.0, 0.0])
    j2 = b.node(None, j1, translation=[0.0, 1.0, 0.0])
    j3 = b.node(None, j0, translation=[0.8, 0.0, 0.0])
    joints = [j0, j1, j2, j3]
    anchors = _anchors(b, joints)
    pos, tris = merge(column([0, 0, 0], [0, 2.3, 0], 0.3, rings=8), column([0.1, 0, 0], [1.2, 0, 0], 0.2, rings=4))
    mesh = b.mesh([b.primitive(pos, tris, anchors=anchors, influences=2)])
    b.node(None, mesh=mesh, skin=0)
    b.skin(joints)
    b.animation(None, [
        (j1, "rotation", [0.0, 0.5, 1.0], _rotations([0, 0, 1], [0, 50, 0]), "LINEAR"),
        (j0, "translation", [0.0, 1.0], [[0, 0, 0], [0.5, 0.2, 0]], "LINEAR"),
    ])
    b.animation(None, [
        (j3, "rotation", [0.0, 0.2, 0.4, 0.6], _rotations([0, 1, 0], [0, 60, -60, 0]), "LINEAR"),
        (j2, "rotation", [0.0, 0.6], _rotations([1, 0, 0], [0, -80]), "LINEAR"),
    ])
    return b.save(_folder(folder) / "unnamed_joints.glb")


#: The nine rows of issue 21, in order.
ROWS: tuple[Callable[[str | os.PathLike[str]], Path], ...] = (
    translating_hip, two_moving_roots, gimbal_path, three_meshes_and_rigid, three_animations, cubic_and_step,
    scale_keys, parent_above_skeleton, unnamed_joints,
)


# =========================================================================== benchmark
def big_clip(folder: str | os.PathLike[str], meshes: int = 59, seconds: float = 35.0, joints: int = 60,
             fps: float = 30) -> Path:
    """(j) A larger character for benchmarks: ``joints`` joints "j00".."jNN" in a binary tree
    (joint i's parent is (i-1)//2), one skin, ``meshes`` meshes "part00".. (one node each, one
    tube of 16 vertices on a joint and its parent, 2 influences), and one LINEAR animation
    "long" of ``seconds`` seconds with a rotation key on every joint at every 1/``fps`` s
    (plus the root's translation). Written as ``big_clip.glb``."""
    b = Builder("big_clip")
    ids: list[int] = []
    for i in range(joints):
        parent = None if i == 0 else ids[(i - 1) // 2]
        side = -1.0 if i % 2 else 1.0
        offset = [0.0, 1.0, 0.0] if i == 0 else [0.35 * side, 0.6, 0.1 * side]
        ids.append(b.node(f"j{i:02d}", parent, translation=offset))
    anchors = _anchors(b, ids)
    for m in range(meshes):
        j = (m + 1) % joints
        p = 0 if j == 0 else (j - 1) // 2
        start, end = anchors[p], anchors[j]
        if np.allclose(start, end):
            end = start + [0.0, 0.5, 0.0]
        pos, tris = column(start, end, 0.12, rings=4)
        mesh = b.mesh([b.primitive(pos, tris, anchors=anchors[[p, j]], joint_ids=[p, j], influences=2)],
                      f"part{m:02d}")
        b.node(f"part{m:02d}", mesh=mesh, skin=0)
    b.skin(ids, skeleton=ids[0])
    times = np.arange(int(round(seconds * fps)) + 1) / fps
    channels: list[tuple[int, str, Sequence[float], Any, str]] = []
    for i, j in enumerate(ids):
        axis = [math.sin(i), 1.0, math.cos(i)]
        angles = 25.0 * np.sin(2 * math.pi * times * (0.3 + 0.02 * i) + i)
        channels.append((j, "rotation", times, _rotations(axis, angles), "LINEAR"))
    channels.append((ids[0], "translation", times,
                     np.column_stack([0.5 * np.sin(times), 1.0 + 0.1 * np.sin(3 * times), 0.2 * times]), "LINEAR"))
    b.animation("long", channels)
    return b.save(_folder(folder) / "big_clip.glb")
