"""An independent reading of the glTF 2.0 specification, for checking the program's 3D import.

Nothing here comes from ``qtanimator``: the file is parsed with pygltflib (the JSON and the GLB
container) and every number is worked out again with numpy from the specification's text
(https://registry.khronos.org/glTF/specs/2.0/glTF-2.0.html), so that a test comparing the
program's output with this module compares two separate implementations.

Public functions (all take the path of a ``.gltf`` or ``.glb`` file):

* :func:`mesh_instances` -- every (node, mesh, primitive) that draws vertices, in a fixed order:
  nodes by increasing index that have a ``mesh``, and for each node its primitives in order.
* :func:`world_positions` -- the world-space vertex positions of every instance at a time of an
  animation (``None``: the rest pose, i.e. the nodes' own TRS / matrix).
* :func:`node_matrices` -- every node's global matrix at such a time.
* :func:`stored_positions` -- each instance's POSITION values as the file stores them.
* :func:`key_times`, :func:`animation_names`, :func:`animation_range`, :func:`model_size`.

What the specification says, and how it is read here:

* Node local transform (§ 3.5.3): ``matrix`` when present, else ``T · R · S`` (missing parts
  are identity). A node targeted by an animation must not have a ``matrix``; such a file is
  refused (``ValueError``) rather than guessed at.
* Global transform: ``global(parent) · local``, up to a node with no parent. Every node counts,
  whether or not a scene lists it.
* Animation samplers (§ 3.11 and Appendix C): before the first key the first value holds, after
  the last key the last value holds (clamping). Inside, with ``td = t[k+1] - t[k]`` and
  ``u = (t - t[k]) / td``:

  - ``STEP``: ``v[k]``;
  - ``LINEAR``: ``lerp`` for translation and scale; spherical linear interpolation for
    rotation, along the shorter arc (when ``dot(q[k], q[k+1]) < 0`` the second key is negated);
  - ``CUBICSPLINE``: every key holds (in-tangent ``a``, value ``v``, out-tangent ``b``) and
    ``p(u) = (2u³-3u²+1) v[k] + td (u³-2u²+u) b[k] + (-2u³+3u²) v[k+1] + td (u³-u²) a[k+1]``.

  Rotations are normalized after interpolation, for every interpolation (the specification
  asks for it after CUBICSPLINE; for STEP and LINEAR it only removes the float32 rounding of
  stored unit quaternions). Channels on ``weights`` (morph targets) are ignored, and meshes
  with morph targets are refused (``NotImplementedError``): nothing checked here has them.
* Skinning (§ 3.7.3): for a node with ``skin`` and a primitive with ``JOINTS_n`` /
  ``WEIGHTS_n``, ``v' = Σ_k w_k · global(joint_k) · inverseBind_k · v``; the mesh node's own
  transform is ignored (only the joints place the mesh). A missing ``inverseBindMatrices``
  means identity matrices. All weight sets are summed together.
* Weights: the specification requires each vertex's weights to sum to 1. Older exporters
  (the 2017 CesiumMan and RiggedFigure) do not, so -- like the program -- each vertex's
  weights are divided by their sum when that sum is positive (a vertex with no weight keeps
  zero weights and collapses to the origin, which no checked file has).
* An unskinned primitive is moved by its node's global matrix.
* Accessors (§ 3.6.2): ``byteStride`` of the buffer view, matrix columns padded to 4 bytes,
  normalized integers (unsigned: ``c / (2ⁿ - 1)``; signed: ``max(c / (2ⁿ⁻¹ - 1), -1)``), sparse
  substitution, and accessors without a buffer view (zeros). Buffers may be the GLB binary
  chunk, ``data:`` URIs of any media type, or files next to the ``.gltf``.

Everything is computed in float64 from the stored values; files are read once per path and
modification time.
"""

from __future__ import annotations

import base64
import functools
import math
import os
import urllib.parse
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pygltflib

__all__ = [
    "Instance", "animation_names", "animation_range", "key_times", "mesh_instances", "model_size",
    "node_matrices", "stored_positions", "world_positions",
]

_COMPONENT = {  # componentType -> (numpy dtype, bytes)
    5120: (np.dtype("i1"), 1), 5121: (np.dtype("u1"), 1), 5122: (np.dtype("<i2"), 2),
    5123: (np.dtype("<u2"), 2), 5125: (np.dtype("<u4"), 4), 5126: (np.dtype("<f4"), 4),
}
_SHAPE = {  # type -> (columns, rows)
    "SCALAR": (1, 1), "VEC2": (1, 2), "VEC3": (1, 3), "VEC4": (1, 4), "MAT2": (2, 2), "MAT3": (3, 3), "MAT4": (4, 4),
}


@dataclass(frozen=True)
class Instance:
    """One primitive of one mesh as a node draws it."""

    node: int
    mesh: int
    primitive: int
    skinned: bool
    vertex_count: int


# --------------------------------------------------------------------------- math
def _quat_matrix(q: np.ndarray) -> np.ndarray:
    """3×3 rotation of a unit quaternion ``(x, y, z, w)``, written out from the definition
    ``R v = q v q*`` (each column is the image of a basis vector)."""
    x, y, z, w = (float(c) for c in q)
    vec = np.array([x, y, z])

    def rotate(v: np.ndarray) -> np.ndarray:
        # q v q* = v + 2w (u × v) + 2 u × (u × v), u the vector part
        c = np.cross(vec, v)
        return v + 2.0 * w * c + 2.0 * np.cross(vec, c)

    return np.column_stack([rotate(e) for e in np.eye(3)])


def _trs(t: np.ndarray, r: np.ndarray, s: np.ndarray) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3] = _quat_matrix(r) @ np.diag(s)
    m[:3, 3] = t
    return m


def _unit(q: np.ndarray) -> np.ndarray:
    n = float(np.linalg.norm(q))
    return q / n if n > 0 else q


def _slerp(a: np.ndarray, b: np.ndarray, u: float) -> np.ndarray:
    """Spherical linear interpolation along the shorter arc. The angle comes from
    ``2 atan2(|a - b|, |a + b|)``, accurate for small and large angles alike."""
    a, b = _unit(a), _unit(b)
    if float(np.dot(a, b)) < 0.0:
        b = -b
    omega = 2.0 * math.atan2(float(np.linalg.norm(a - b)), float(np.linalg.norm(a + b)))  # angle between
    if omega < 1e-12:
        return a.copy()
    s = math.sin(omega)
    return (math.sin((1.0 - u) * omega) / s) * a + (math.sin(u * omega) / s) * b


# --------------------------------------------------------------------------- the file
class _Sampler:
    def __init__(self, times: np.ndarray, values: np.ndarray, interpolation: str) -> None:
        self.times = times
        self.interpolation = interpolation
        if interpolation == "CUBICSPLINE":
            if len(values) != 3 * len(times):
                raise ValueError(f"CUBICSPLINE sampler with {len(times)} keys has {len(values)} outputs")
            values = values.reshape(len(times), 3, -1)  # (in-tangent, value, out-tangent)
        elif len(values) != len(times):
            raise ValueError(f"{interpolation} sampler with {len(times)} keys has {len(values)} outputs")
        self.values = values

    def value(self, t: float, rotation: bool) -> np.ndarray:
        times, n = self.times, len(self.times)
        cubic = self.interpolation == "CUBICSPLINE"
        v = self.values[:, 1] if cubic else self.values
        if n == 1 or t <= times[0]:
            out = v[0].copy()
        elif t >= times[-1]:
            out = v[-1].copy()
        else:
            k = int(np.searchsorted(times, t, side="right")) - 1  # times[k] <= t < times[k + 1]
            td = float(times[k + 1] - times[k])
            u = (t - float(times[k])) / td
            if self.interpolation == "STEP":
                out = v[k].copy()
            elif cubic:
                b_k, a_k1 = self.values[k, 2], self.values[k + 1, 0]
                out = ((2 * u**3 - 3 * u**2 + 1) * v[k] + td * (u**3 - 2 * u**2 + u) * b_k
                       + (-2 * u**3 + 3 * u**2) * v[k + 1] + td * (u**3 - u**2) * a_k1)
            elif rotation:
                out = _slerp(v[k], v[k + 1], u)
            else:
                out = (1.0 - u) * v[k] + u * v[k + 1]
        return _unit(out) if rotation else out


class _File:
    """A parsed file: buffers decoded, accessors read on demand."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.gltf = pygltflib.GLTF2().load(str(path))
        if self.gltf is None:
            raise ValueError(f"{path}: pygltflib could not read it")
        self.buffers = [self._buffer(i, b) for i, b in enumerate(self.gltf.buffers)]
        self._accessors: dict[int, np.ndarray] = {}
        nodes = self.gltf.nodes
        self.parent: list[int | None] = [None] * len(nodes)
        for i, node in enumerate(nodes):
            for c in node.children or []:
                if self.parent[c] is not None:
                    raise ValueError(f"{path}: node {c} has two parents")
                self.parent[c] = i
        self.animations = [self._animation(a) for a in self.gltf.animations]
        self.instances: list[Instance] = []
        self.primitive_data: list[tuple[np.ndarray, np.ndarray | None, np.ndarray | None]] = []
        for ni, node in enumerate(nodes):
            if node.mesh is None:
                continue
            mesh = self.gltf.meshes[node.mesh]
            for pi, prim in enumerate(mesh.primitives):
                if prim.targets:
                    raise NotImplementedError(f"{path}: mesh {node.mesh} has morph targets")
                positions = self.accessor(prim.attributes.POSITION)
                joints, weights = self._influences(prim.attributes, len(positions))
                skinned = node.skin is not None and joints is not None
                self.instances.append(Instance(ni, node.mesh, pi, skinned, len(positions)))
                self.primitive_data.append((positions, joints if skinned else None, weights if skinned else None))

    # ------------------------------------------------------------------ binary data
    def _buffer(self, index: int, buffer: pygltflib.Buffer) -> bytes:
        uri = buffer.uri
        if uri is None:  # the GLB binary chunk
            if index != 0 or self.gltf.binary_blob() is None:
                raise ValueError(f"{self.path}: buffer {index} has no uri and there is no GLB binary chunk")
            data = bytes(self.gltf.binary_blob())
        elif uri.startswith("data:"):
            header, _, payload = uri.partition(",")
            if not header.endswith(";base64"):
                raise ValueError(f"{self.path}: buffer {index} is a data URI that is not base64")
            data = base64.b64decode(payload)
        else:
            data = (self.path.parent / urllib.parse.unquote(uri)).read_bytes()
        if len(data) < buffer.byteLength:
            raise ValueError(f"{self.path}: buffer {index} holds {len(data)} bytes, not {buffer.byteLength}")
        return data

    def _view(self, index: int) -> tuple[bytes, int, int, int | None]:
        view = self.gltf.bufferViews[index]
        return self.buffers[view.buffer], view.byteOffset or 0, view.byteLength, view.byteStride

    def accessor(self, index: int) -> np.ndarray:
        """Accessor ``index`` as a float64 (count, components) array (matrices column-major)."""
        if index in self._accessors:
            return self._accessors[index]
        acc = self.gltf.accessors[index]
        dtype, size = _COMPONENT[acc.componentType]
        cols, rows = _SHAPE[acc.type]
        # a matrix column starts on a 4-byte boundary (§ 3.6.2.4)
        column = rows * size if cols == 1 else -(-rows * size // 4) * 4
        element = column * cols
        if acc.bufferView is None:
            raw = np.zeros((acc.count, cols * rows), dtype=dtype)
        else:
            data, start, length, stride = self._view(acc.bufferView)
            stride = stride or element
            first = start + (acc.byteOffset or 0)
            if (acc.byteOffset or 0) + stride * (acc.count - 1) + element > length:
                raise ValueError(f"{self.path}: accessor {index} runs past its buffer view")
            # byte address of every component of every element, then the bytes reinterpreted
            component = np.array([c * column + r * size for c in range(cols) for r in range(rows)])
            address = first + np.arange(acc.count)[:, None, None] * stride + component[None, :, None]
            address = address + np.arange(size)[None, None, :]
            raw_bytes = np.frombuffer(data, dtype=np.uint8)[address]  # (count, components, size)
            raw = np.ascontiguousarray(raw_bytes).view(dtype).reshape(acc.count, cols * rows)
        if acc.sparse is not None:
            raw = raw.copy()
            sp = acc.sparse
            idt, isize = _COMPONENT[sp.indices.componentType]
            data, start, _, _ = self._view(sp.indices.bufferView)
            where = np.frombuffer(data, dtype=idt, count=sp.count, offset=start + (sp.indices.byteOffset or 0))
            data, start, _, _ = self._view(sp.values.bufferView)
            vals = np.frombuffer(data, dtype=dtype, count=sp.count * cols * rows,
                                 offset=start + (sp.values.byteOffset or 0))
            raw[where.astype(np.int64)] = vals.reshape(sp.count, cols * rows)
        out = raw.astype(np.float64)
        if acc.normalized:
            bits = 8 * size
            if dtype.kind == "u":
                out = out / (2.0**bits - 1.0)
            else:
                out = np.maximum(out / (2.0 ** (bits - 1) - 1.0), -1.0)
        self._accessors[index] = out
        return out

    def _influences(self, attributes: pygltflib.Attributes, n: int) -> tuple[np.ndarray | None, np.ndarray | None]:
        joint_sets, weight_sets = [], []
        k = 0
        while getattr(attributes, f"JOINTS_{k}", None) is not None:
            joint_sets.append(self.accessor(getattr(attributes, f"JOINTS_{k}")).astype(np.int64))
            weight_sets.append(self.accessor(getattr(attributes, f"WEIGHTS_{k}")))
            k += 1
        if not joint_sets:
            return None, None
        joints = np.concatenate(joint_sets, axis=1)
        weights = np.concatenate(weight_sets, axis=1)
        if joints.shape != (n, 4 * k) or weights.shape != (n, 4 * k):
            raise ValueError(f"{self.path}: JOINTS / WEIGHTS do not match {n} vertices")
        total = weights.sum(axis=1, keepdims=True)
        weights = np.where(total > 0, weights / np.where(total > 0, total, 1.0), 0.0)  # renormalized
        return joints, weights

    def _animation(self, anim: pygltflib.Animation) -> tuple[list[_Sampler], list[tuple[int, int, str]]]:
        samplers = [
            _Sampler(self.accessor(s.input).reshape(-1), self.accessor(s.output), s.interpolation or "LINEAR")
            for s in anim.samplers
        ]
        channels = []
        for ch in anim.channels:
            node, path = ch.target.node, ch.target.path
            if node is None or path == "weights":
                continue
            if self.gltf.nodes[node].matrix is not None:
                raise ValueError(f"{self.path}: animated node {node} has a matrix, which the spec forbids")
            channels.append((ch.sampler, node, path))
        return samplers, channels

    # ------------------------------------------------------------------ evaluation
    def globals(self, animation: int | None, t: float) -> list[np.ndarray]:
        """Every node's global 4×4 matrix."""
        nodes = self.gltf.nodes
        trs = [[np.array(n.translation or [0.0, 0.0, 0.0], dtype=np.float64),
                np.array(n.rotation or [0.0, 0.0, 0.0, 1.0], dtype=np.float64),
                np.array(n.scale or [1.0, 1.0, 1.0], dtype=np.float64)] for n in nodes]
        if animation is not None:
            samplers, channels = self.animations[animation]
            for si, node, path in channels:
                slot = {"translation": 0, "rotation": 1, "scale": 2}[path]
                trs[node][slot] = samplers[si].value(float(t), rotation=path == "rotation")
        local = []
        for i, n in enumerate(nodes):
            if n.matrix is not None:
                local.append(np.array(n.matrix, dtype=np.float64).reshape(4, 4).T)  # column-major
            else:
                local.append(_trs(*trs[i]))
        result: list[np.ndarray | None] = [None] * len(nodes)

        def global_of(i: int) -> np.ndarray:
            chain = []
            k: int | None = i
            while k is not None and result[k] is None:
                chain.append(k)
                k = self.parent[k]
            above = np.eye(4) if k is None else result[k]
            for j in reversed(chain):
                above = above @ local[j]
                result[j] = above
            return result[i]

        return [global_of(i) for i in range(len(nodes))]

    def positions(self, animation: int | None, t: float) -> list[np.ndarray]:
        world = self.globals(animation, t)
        out = []
        for inst, (pos, joints, weights) in zip(self.instances, self.primitive_data):
            homogeneous = np.column_stack([pos, np.ones(len(pos))])
            if inst.skinned:
                skin = self.gltf.skins[self.gltf.nodes[inst.node].skin]
                if skin.inverseBindMatrices is None:
                    ibm = np.tile(np.eye(4), (len(skin.joints), 1, 1))
                else:
                    ibm = self.accessor(skin.inverseBindMatrices).reshape(-1, 4, 4).transpose(0, 2, 1)
                joint_matrices = np.stack([world[j] @ ibm[k] for k, j in enumerate(skin.joints)])
                result = np.zeros((len(pos), 4))
                for slot in range(joints.shape[1]):
                    moved = np.einsum("vij,vj->vi", joint_matrices[joints[:, slot]], homogeneous)
                    result += weights[:, slot, None] * moved
                out.append(result[:, :3])
            else:
                out.append((homogeneous @ world[inst.node].T)[:, :3])
        return out


@functools.lru_cache(maxsize=32)
def _load(path: str, _mtime_ns: int) -> _File:
    return _File(Path(path))


def _file(path: str | os.PathLike[str]) -> _File:
    p = Path(path).resolve()
    return _load(str(p), p.stat().st_mtime_ns)


# --------------------------------------------------------------------------- public
def mesh_instances(path: str | os.PathLike[str]) -> list[Instance]:
    """Every drawn primitive: nodes with a mesh by increasing node index, primitives in order."""
    return list(_file(path).instances)


def world_positions(path: str | os.PathLike[str], animation_index: int | None, t: float) -> list[np.ndarray]:
    """(V, 3) world positions of each :func:`mesh_instances` entry at time ``t`` (seconds, the
    file's own times) of animation ``animation_index``; ``None`` gives the rest pose."""
    return _file(path).positions(animation_index, t)


def node_matrices(path: str | os.PathLike[str], animation_index: int | None, t: float) -> np.ndarray:
    """(N, 4, 4) global matrices of all nodes at time ``t`` of the animation (``None``: rest)."""
    return np.array(_file(path).globals(animation_index, t))


def stored_positions(path: str | os.PathLike[str]) -> list[np.ndarray]:
    """(V, 3) POSITION values of each :func:`mesh_instances` entry, sparse substitution applied."""
    return [pos.copy() for pos, _, _ in _file(path).primitive_data]


def key_times(path: str | os.PathLike[str], animation_index: int) -> np.ndarray:
    """Sorted unique input times of all the animation's samplers."""
    samplers, _ = _file(path).animations[animation_index]
    return np.unique(np.concatenate([s.times for s in samplers])) if samplers else np.zeros(0)


def animation_names(path: str | os.PathLike[str]) -> list[str]:
    """Each animation's ``name`` as the file gives it (``""`` when it has none)."""
    return [a.name or "" for a in _file(path).gltf.animations]


def animation_range(path: str | os.PathLike[str], animation_index: int) -> tuple[float, float]:
    """(first, last) key time of the animation."""
    times = key_times(path, animation_index)
    return float(times[0]), float(times[-1])


def model_size(path: str | os.PathLike[str]) -> float:
    """Diagonal of the bounding box of every instance's rest-pose world positions."""
    every = np.concatenate(world_positions(path, None, 0.0))
    return float(np.linalg.norm(every.max(axis=0) - every.min(axis=0)))
