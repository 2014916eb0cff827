"""Linear blend skinning with any number of influences per vertex.

* :class:`SkinBinding` holds the influences as sparse ``(vertex, joint, weight)`` triples
  and derives a padded ``(V, K)`` layout (K = the most influences any vertex has; MIT
  meshes reach 13) and CSR arrays from them.
* :class:`Skin` is a bind-pose mesh plus a binding plus the joints' bind matrices
  (``.skin`` files store the bind world matrices B; glTF stores B⁻¹; both are kept).
* :func:`skin_positions`: ``v' = Σ_k w_k · (W_j · B_j⁻¹) · v``. Weights are used as given
  (the MIT reference does not renormalise). Each vertex's blended 3×4 matrix is built
  with one gather-multiply-add per influence slot; vertices are sorted by influence
  count so slot k only touches the vertices that have k + 1 influences, and the work
  runs in cache-sized blocks. O(total influences), vectorised, float64 or float32.
* :func:`skin_normals`: the inverse transpose of each vertex's blended 3×3, applied as the
  cofactor matrix (``det·A⁻ᵀ``, sign-corrected) and renormalised.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.intp]


class SkinBinding:
    """Sparse per-vertex joint weights: parallel arrays ``vertex``, ``joint``, ``weight``.

    Entries are sorted by vertex (stable, so the per-vertex order of the file is kept).
    Zero weights are kept: they are harmless and some files list them explicitly.
    """

    def __init__(self, vertex: npt.ArrayLike, joint: npt.ArrayLike, weight: npt.ArrayLike,
                 num_vertices: int, num_joints: int) -> None:
        v = np.asarray(vertex, dtype=np.intp).reshape(-1)
        j = np.asarray(joint, dtype=np.intp).reshape(-1)
        w = np.asarray(weight, dtype=np.float64).reshape(-1)
        if not (len(v) == len(j) == len(w)):
            raise ValueError("vertex, joint and weight arrays must have the same length")
        if len(v):
            if v.min() < 0 or v.max() >= num_vertices:
                raise ValueError("a weight refers to a vertex that does not exist")
            if j.min() < 0 or j.max() >= num_joints:
                raise ValueError("a weight refers to a joint that does not exist")
            if not np.all(np.isfinite(w)):
                raise ValueError("weights must be finite numbers")
        order = np.argsort(v, kind="stable")
        self.vertex: IntArray = v[order]
        self.joint: IntArray = j[order]
        self.weight: FloatArray = w[order]
        self.num_vertices = int(num_vertices)
        self.num_joints = int(num_joints)
        #: one more than the highest joint index any weight uses
        self.joints_used = int(self.joint.max()) + 1 if len(self.joint) else 0
        self._padded: dict[Any, tuple[npt.NDArray[np.int32], npt.NDArray[Any]]] = {}

    # ----------------------------------------------------------- constructors
    @classmethod
    def from_dense(cls, weights: npt.ArrayLike, drop_zeros: bool = True) -> SkinBinding:
        """From a (V, J) weight matrix; zero entries are dropped."""
        w = np.asarray(weights, dtype=np.float64)
        if w.ndim != 2:
            raise ValueError("dense weights must be a (V, J) array")
        if drop_zeros:
            v, j = np.nonzero(w)
        else:
            v, j = np.indices(w.shape).reshape(2, -1)
        return cls(v, j, w[v, j], w.shape[0], w.shape[1])

    @classmethod
    def from_padded(cls, joints: npt.ArrayLike, weights: npt.ArrayLike, num_joints: int) -> SkinBinding:
        """From (V, K) joint indices and weights (glTF JOINTS_0 / WEIGHTS_0); zero weights dropped."""
        jj = np.asarray(joints, dtype=np.intp)
        ww = np.asarray(weights, dtype=np.float64)
        if jj.shape != ww.shape or jj.ndim != 2:
            raise ValueError("padded joints and weights must be (V, K) arrays of the same shape")
        v = np.repeat(np.arange(jj.shape[0]), jj.shape[1])
        keep = ww.reshape(-1) != 0.0
        return cls(v[keep], jj.reshape(-1)[keep], ww.reshape(-1)[keep], jj.shape[0], num_joints)

    # ---------------------------------------------------------------- layouts
    def __len__(self) -> int:
        return len(self.vertex)

    def counts(self) -> IntArray:
        """Number of influences of every vertex."""
        c: IntArray = np.bincount(self.vertex, minlength=self.num_vertices).astype(np.intp)
        return c

    @property
    def max_influences(self) -> int:
        return int(self.counts().max()) if self.num_vertices and len(self.vertex) else 0

    def csr(self) -> tuple[IntArray, IntArray, FloatArray]:
        """``(indptr, joint_indices, weights)``: vertex v's influences are ``indptr[v]:indptr[v+1]``."""
        indptr = np.zeros(self.num_vertices + 1, dtype=np.intp)
        np.cumsum(self.counts(), out=indptr[1:])
        return indptr, self.joint.copy(), self.weight.copy()

    def dense(self) -> FloatArray:
        """(V, J) weight matrix (duplicate entries add up)."""
        out = np.zeros((self.num_vertices, self.num_joints))
        np.add.at(out, (self.vertex, self.joint), self.weight)
        return out

    def weight_sums(self) -> FloatArray:
        s = np.bincount(self.vertex, weights=self.weight, minlength=self.num_vertices)
        return np.asarray(s, dtype=np.float64)

    def padded(self, dtype: npt.DTypeLike = np.float64) -> tuple[npt.NDArray[np.int32], npt.NDArray[Any]]:
        """(V, K) joint indices and weights; unused slots have joint 0 and weight 0."""
        key = np.dtype(dtype)
        cached = self._padded.get(key)
        if cached is not None:
            return cached
        counts = self.counts()
        k = max(int(counts.max()) if len(counts) else 0, 1)
        idx = np.zeros((self.num_vertices, k), dtype=np.int32)
        w = np.zeros((self.num_vertices, k), dtype=key)
        starts = np.zeros(self.num_vertices, dtype=np.intp)
        if self.num_vertices > 1:
            np.cumsum(counts[:-1], out=starts[1:])
        slot = np.arange(len(self.vertex)) - starts[self.vertex]
        idx[self.vertex, slot] = self.joint
        w[self.vertex, slot] = self.weight
        # Slot-major copies make each influence slot one contiguous column.
        result = (np.ascontiguousarray(idx.T).T, np.ascontiguousarray(w.T).T)
        self._padded[key] = result
        return result

    def renormalized(self) -> SkinBinding:
        """Weights divided by each vertex's sum (vertices whose weights sum to 0 are kept)."""
        sums = self.weight_sums()
        scale = np.where(sums[self.vertex] != 0.0, sums[self.vertex], 1.0)
        return SkinBinding(self.vertex, self.joint, self.weight / scale, self.num_vertices, self.num_joints)


@dataclass(eq=False)
class Skin:
    """A bind-pose mesh bound to a skeleton.

    ``inverse_bind_matrices[j]`` maps world space at bind time into joint j's space.
    ``bind_matrices`` (their inverses) are what a ``.skin`` file stores.
    """

    positions: FloatArray
    triangles: npt.NDArray[np.int64]
    binding: SkinBinding
    inverse_bind_matrices: FloatArray
    normals: FloatArray | None = None
    texcoords: FloatArray | None = None
    material: Mapping[str, Any] | None = None
    bind_matrices: FloatArray | None = None
    extras: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.positions = np.asarray(self.positions, dtype=np.float64).reshape(-1, 3)
        self.triangles = np.asarray(self.triangles, dtype=np.int64).reshape(-1, 3)
        self.inverse_bind_matrices = np.asarray(self.inverse_bind_matrices, dtype=np.float64).reshape(-1, 4, 4)
        if self.normals is not None:
            self.normals = np.asarray(self.normals, dtype=np.float64).reshape(-1, 3)
        if self.texcoords is not None:
            self.texcoords = np.asarray(self.texcoords, dtype=np.float64).reshape(len(self.positions), -1)
        if self.bind_matrices is None:
            self.bind_matrices = np.asarray(np.linalg.inv(self.inverse_bind_matrices), dtype=np.float64)
        if self.binding.num_vertices != len(self.positions):
            raise ValueError("the binding and the mesh have different vertex counts")
        if self.binding.num_joints > len(self.inverse_bind_matrices):
            raise ValueError("the binding refers to more joints than there are bind matrices")

    @classmethod
    def from_bind_matrices(cls, positions: npt.ArrayLike, triangles: npt.ArrayLike, binding: SkinBinding,
                           bind_matrices: npt.ArrayLike, **kw: Any) -> Skin:
        b = np.asarray(bind_matrices, dtype=np.float64).reshape(-1, 4, 4)
        return cls(np.asarray(positions, dtype=np.float64), np.asarray(triangles), binding,
                   np.asarray(np.linalg.inv(b), dtype=np.float64), bind_matrices=b, **kw)

    @property
    def num_vertices(self) -> int:
        return len(self.positions)

    def invalidate_caches(self) -> None:
        """Call after changing ``positions`` or ``binding`` arrays in place (replacing them is noticed)."""
        self.extras = {k: v for k, v in self.extras.items() if not k.startswith("_")}

    @property
    def num_joints(self) -> int:
        return len(self.inverse_bind_matrices)

    @property
    def weights(self) -> SkinBinding:
        return self.binding


def skinning_matrices(skin: Skin, world_matrices: npt.ArrayLike) -> FloatArray:
    """(J, 4, 4): ``W_j · B_j⁻¹``."""
    w = np.asarray(world_matrices, dtype=np.float64).reshape(-1, 4, 4)
    used = skin.binding.joints_used
    if len(w) < used:
        raise ValueError(f"the skin's weights refer to {used} joints, but {len(w)} joint matrices were given")
    n = min(len(w), len(skin.inverse_bind_matrices))
    result: FloatArray = w[:n] @ skin.inverse_bind_matrices[:n]
    return result


#: Vertices blended per block: the block's matrices stay in the CPU cache.
CHUNK = 8192


class _Layout:
    """Influences arranged for fast blending, for one float dtype.

    Vertices are permuted so that influence counts decrease (``order``); slot k then
    covers a prefix of ``sizes[k]`` vertices, so a mesh where most vertices have few
    influences (MIT: mean 5.6, max 13) does no work for empty slots. Each slot's joint
    rows are gathered as one 3×4 block per vertex (a ``void`` item, one memcpy each).
    For float32 the weights are stored repeated 12 times so the multiply is a flat,
    contiguous loop; for float64 they broadcast.
    """

    def __init__(self, binding: SkinBinding, positions: FloatArray, dtype: np.dtype[Any]) -> None:
        nv = binding.num_vertices
        counts = binding.counts()
        order = np.argsort(-counts, kind="stable")
        self.identity = bool(np.all(order == np.arange(nv)))
        self.order = order
        self.inverse = np.argsort(order)
        idx, w = binding.padded(np.float64)
        idx_p = idx[order]
        w_p = w[order]
        sorted_counts = counts[order]
        k = idx.shape[1] if nv else 0
        self.sizes = [int(np.count_nonzero(sorted_counts > slot)) for slot in range(k)]
        self.dtype = dtype
        self.joints = [np.ascontiguousarray(idx_p[: n, slot], dtype=np.intp) for slot, n in enumerate(self.sizes)]
        if dtype == np.float32:
            self.weights = [np.repeat(w_p[: n, slot].astype(dtype), 12).reshape(n, 12)
                            for slot, n in enumerate(self.sizes)]
        else:
            self.weights = [np.ascontiguousarray(w_p[: n, slot, None], dtype=dtype)
                            for slot, n in enumerate(self.sizes)]
        p = positions[order]
        self.xyz = np.ascontiguousarray(p.T, dtype=dtype)  # (3, V)
        self.num_vertices = nv
        self.source = (binding, positions)
        self.item = np.dtype((np.void, 12 * dtype.itemsize))

    def _gather(self, m: FloatArray) -> npt.NDArray[Any]:
        return np.ascontiguousarray(m[:, :3, :].reshape(-1, 12), dtype=self.dtype).view(self.item).reshape(-1)

    def blend_chunk(self, mv: npt.NDArray[Any], s: int, e: int, acc: npt.NDArray[Any],
                    tmp: npt.NDArray[Any]) -> npt.NDArray[Any]:
        """Blended (e − s, 12) matrices of permuted vertices s…e into ``acc``'s first rows."""
        n = e - s
        a = acc[:n]
        empty = True
        for slot, size in enumerate(self.sizes):
            stop = min(e, size)
            if stop <= s:
                break
            k = stop - s
            if empty and k == n:
                # First slot covering the whole block: gather straight into the result.
                np.take(mv, self.joints[slot][s:stop], out=a.view(self.item).reshape(n))
                a *= self.weights[slot][s:stop]
                empty = False
                continue
            if empty:
                a[:] = 0
                empty = False
            t = tmp[:k]
            np.take(mv, self.joints[slot][s:stop], out=t.view(self.item).reshape(k))
            t *= self.weights[slot][s:stop]
            a[:k] += t
        if empty:
            a[:] = 0
        return a

    def blend(self, m: FloatArray) -> npt.NDArray[Any]:
        """(V, 12) blended top-3-row matrices, permuted order."""
        nv = self.num_vertices
        mv = self._gather(m)
        acc = np.empty((nv, 12), dtype=self.dtype)
        tmp = np.empty((min(nv, CHUNK), 12), dtype=self.dtype)
        for s in range(0, nv, CHUNK):
            e = min(nv, s + CHUNK)
            self.blend_chunk(mv, s, e, acc[s:e], tmp)
        return acc

    def positions(self, m: FloatArray) -> npt.NDArray[Any]:
        """(V, 3) skinned positions (original order), blended and applied chunk by chunk
        so the intermediate matrices stay in cache."""
        nv = self.num_vertices
        mv = self._gather(m)
        out = np.empty((nv, 3), dtype=self.dtype)
        size = min(nv, CHUNK)
        acc = np.empty((size, 12), dtype=self.dtype)
        tmp = np.empty((size, 12), dtype=self.dtype)
        col = np.empty(size, dtype=self.dtype)
        for s in range(0, nv, CHUNK):
            e = min(nv, s + CHUNK)
            a = self.blend_chunk(mv, s, e, acc, tmp)
            x, y, z = self.xyz[:, s:e]
            c = col[: e - s]
            for r in range(3):
                o = out[s:e, r]
                np.multiply(a[:, 4 * r], x, out=o)
                np.multiply(a[:, 4 * r + 1], y, out=c)
                o += c
                np.multiply(a[:, 4 * r + 2], z, out=c)
                o += c
                o += a[:, 4 * r + 3]
        return self.unpermute(out)

    def unpermute(self, rows: npt.NDArray[Any]) -> npt.NDArray[Any]:
        if self.identity:
            return np.ascontiguousarray(rows)
        result: npt.NDArray[Any] = np.take(rows, self.inverse, axis=0)
        return result


def _layout(skin: Skin, dtype: npt.DTypeLike) -> _Layout:
    dt = np.dtype(dtype)
    if dt not in (np.dtype(np.float32), np.dtype(np.float64)):
        raise ValueError("skinning runs in float32 or float64")
    key = f"_layout:{dt.str}"
    lay = skin.extras.get(key)
    if lay is None or lay.source[0] is not skin.binding or lay.source[1] is not skin.positions:
        lay = _Layout(skin.binding, skin.positions, dt)
        skin.extras[key] = lay
    assert isinstance(lay, _Layout)
    return lay


def blended_matrices(skin: Skin, world_matrices: npt.ArrayLike,
                     dtype: npt.DTypeLike = np.float64) -> npt.NDArray[Any]:
    """(V, 3, 4): every vertex's weighted sum of its joints' skinning matrices (top 3 rows)."""
    lay = _layout(skin, dtype)
    acc = lay.blend(skinning_matrices(skin, world_matrices))
    return lay.unpermute(acc).reshape(skin.num_vertices, 3, 4)


def skin_positions(skin: Skin, world_matrices: npt.ArrayLike, dtype: npt.DTypeLike = np.float64) -> npt.NDArray[Any]:
    """(V, 3) skinned positions ``Σ_k w_k·(W_j·B_j⁻¹)·v`` (weights used as given).

    Pass ``dtype=np.float32`` for speed where exactness is not needed (drawing).
    """
    return _layout(skin, dtype).positions(skinning_matrices(skin, world_matrices))


def skin_normals(skin: Skin, world_matrices: npt.ArrayLike, normals: npt.ArrayLike | None = None,
                 dtype: npt.DTypeLike = np.float64) -> npt.NDArray[Any]:
    """(V, 3) unit normals: inverse transpose of each blended matrix, renormalised.

    Uses the skin's normals, or ``normals`` when given (e.g. smooth normals computed for a
    mesh that has none). Zero-length results stay zero.
    """
    base = skin.normals if normals is None else np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    if base is None:
        base = vertex_normals(skin.positions, skin.triangles)
    lay = _layout(skin, dtype)
    a = lay.blend(skinning_matrices(skin, world_matrices))
    n = np.ascontiguousarray(base[lay.order].T, dtype=lay.dtype)
    out = _cofactor_apply(a, n)
    return lay.unpermute(out.T)


def skin_positions_and_normals(skin: Skin, world_matrices: npt.ArrayLike, dtype: npt.DTypeLike = np.float64
                               ) -> tuple[npt.NDArray[Any], npt.NDArray[Any]]:
    """Both at once, blending the matrices only once (what a viewport needs per frame)."""
    base = skin.normals if skin.normals is not None else vertex_normals(skin.positions, skin.triangles)
    lay = _layout(skin, dtype)
    a = lay.blend(skinning_matrices(skin, world_matrices))
    x, y, z = lay.xyz
    pos = np.empty((3, skin.num_vertices), dtype=lay.dtype)
    for r in range(3):
        pos[r] = a[:, 4 * r] * x + a[:, 4 * r + 1] * y + a[:, 4 * r + 2] * z + a[:, 4 * r + 3]
    n = np.ascontiguousarray(base[lay.order].T, dtype=lay.dtype)
    return lay.unpermute(pos.T), lay.unpermute(_cofactor_apply(a, n).T)


def _cofactor_apply(a: npt.NDArray[Any], n: npt.NDArray[Any]) -> npt.NDArray[Any]:
    """(3, V) normalised ``sign(det A)·cof(A)·n`` for the 3×3 blocks of (V, 12) matrices."""
    m = [[np.ascontiguousarray(a[:, 4 * r + c]) for c in range(3)] for r in range(3)]
    # cofactor matrix C with C[r][c] = cofactor of A[r][c]; det(A)·A⁻ᵀ = C.
    c = [[m[(r + 1) % 3][(k + 1) % 3] * m[(r + 2) % 3][(k + 2) % 3]
          - m[(r + 1) % 3][(k + 2) % 3] * m[(r + 2) % 3][(k + 1) % 3] for k in range(3)] for r in range(3)]
    det = m[0][0] * c[0][0] + m[0][1] * c[0][1] + m[0][2] * c[0][2]
    out = np.empty_like(n)
    for r in range(3):
        out[r] = c[r][0] * n[0] + c[r][1] * n[1] + c[r][2] * n[2]
    out *= np.where(det < 0, -1.0, 1.0).astype(out.dtype)
    length = np.sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2])
    out /= np.where(length > 0, length, 1.0)
    return out


def transform_normals(matrices: npt.ArrayLike, normals: npt.ArrayLike) -> npt.NDArray[Any]:
    """Apply each (3, 3) matrix's inverse transpose to each normal and renormalise."""
    a = np.asarray(matrices)
    n = np.asarray(normals)
    c0, c1, c2 = a[:, :, 0], a[:, :, 1], a[:, :, 2]
    # det(A)·A⁻ᵀ has columns c1×c2, c2×c0, c0×c1 (the cofactor matrix).
    out = (np.cross(c1, c2) * n[:, 0, None] + np.cross(c2, c0) * n[:, 1, None]
           + np.cross(c0, c1) * n[:, 2, None])
    det = np.einsum("ij,ij->i", c0, np.cross(c1, c2))
    out *= np.where(det < 0, -1.0, 1.0).astype(out.dtype)[:, None]
    return _normalize_rows(out)


def _normalize_rows(v: npt.NDArray[Any]) -> npt.NDArray[Any]:
    length = np.sqrt(np.einsum("ij,ij->i", v, v))
    safe = np.where(length > 0, length, 1.0)
    result: npt.NDArray[Any] = v / safe[:, None]
    return result


def faceted_normals(positions: npt.ArrayLike, triangles: npt.ArrayLike) -> FloatArray:
    """(T, 3) unit face normals ``normalize((p1 − p0) × (p2 − p0))``; zero-area faces give 0."""
    p = np.asarray(positions, dtype=np.float64)
    t = np.asarray(triangles, dtype=np.intp).reshape(-1, 3)
    n = np.cross(p[t[:, 1]] - p[t[:, 0]], p[t[:, 2]] - p[t[:, 0]])
    result: FloatArray = _normalize_rows(n)
    return result


def vertex_normals(positions: npt.ArrayLike, triangles: npt.ArrayLike) -> FloatArray:
    """(V, 3) smooth normals: area-weighted average of the adjacent faces' normals."""
    p = np.asarray(positions, dtype=np.float64)
    t = np.asarray(triangles, dtype=np.intp).reshape(-1, 3)
    face = np.cross(p[t[:, 1]] - p[t[:, 0]], p[t[:, 2]] - p[t[:, 0]])  # length = 2·area
    acc = np.zeros_like(p)
    for c in range(3):
        for axis in range(3):
            acc[:, axis] += np.bincount(t[:, c], weights=face[:, axis], minlength=len(p))
    result: FloatArray = _normalize_rows(acc)
    return result


def bind_to_skeleton(positions: npt.ArrayLike, triangles: npt.ArrayLike, binding: SkinBinding,
                     bind_world_matrices: npt.ArrayLike, **kw: Any) -> Skin:
    """A skin whose bind matrices are the given joint world matrices (e.g. the MIT rest pose:
    ``skeleton.bind_world_matrices()``)."""
    return Skin.from_bind_matrices(positions, triangles, binding, bind_world_matrices, **kw)
