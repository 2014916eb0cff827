"""Rays against triangle meshes: the nearest hit, for picking a point of a skinned surface.

Qt-free and numpy only. :func:`ray_triangles` is Möller–Trumbore (1997) over every
triangle the ray's line passes near (no acceleration structure, which would have to be
rebuilt for every pose of a skinned mesh): the vertices are projected on two axes across the
ray and only triangles whose corners lie on both sides of the line on both axes are
tested. Triangles are two-sided (the camera may be inside a sleeve).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class RayHit:
    """Where a ray first meets a mesh: ``point = origin + t·direction``, on triangle
    ``triangle`` at barycentric ``(1 − u − v, u, v)`` of its three corners."""

    t: float
    triangle: int
    u: float
    v: float
    point: FloatArray

    @property
    def barycentric(self) -> FloatArray:
        return np.array([1.0 - self.u - self.v, self.u, self.v])


def ray_triangles(origin: npt.ArrayLike, direction: npt.ArrayLike, positions: npt.ArrayLike,
                  triangles: npt.ArrayLike, epsilon: float = 1e-12) -> RayHit | None:
    """The nearest hit (``t > 0``) of the ray ``origin + t·direction`` on the triangles
    (T, 3) of the vertices ``positions`` (V, 3), or None. ``direction`` need not be unit
    (``t`` is in its units). Degenerate triangles and rays in a triangle's plane miss."""
    o = np.asarray(origin, dtype=np.float64).reshape(3)
    d = np.asarray(direction, dtype=np.float64).reshape(3)
    pos = np.asarray(positions, dtype=np.float64)
    tri = np.asarray(triangles, dtype=np.intp).reshape(-1, 3)
    if len(tri) == 0:
        return None
    index = _straddling(o, d, pos, tri)
    tri = tri[index]
    if len(tri) == 0:
        return None
    p0 = pos[tri[:, 0]]
    e1 = pos[tri[:, 1]] - p0
    e2 = pos[tri[:, 2]] - p0
    pvec = np.cross(d, e2)
    det = np.einsum("ij,ij->i", e1, pvec)
    # the determinant's scale: |d|·|e1|·|e2| (a relative test for a ray in the plane)
    scale = np.sqrt(float(d @ d)) * np.sqrt(np.einsum("ij,ij->i", e1, e1) * np.einsum("ij,ij->i", e2, e2))
    ok = np.abs(det) > epsilon * np.maximum(scale, 1e-300)
    inv = np.zeros_like(det)
    inv[ok] = 1.0 / det[ok]
    tvec = o - p0
    u = np.einsum("ij,ij->i", tvec, pvec) * inv
    ok &= (u >= 0.0) & (u <= 1.0)
    qvec = np.cross(tvec, e1)
    v = (qvec @ d) * inv
    ok &= (v >= 0.0) & (u + v <= 1.0)
    t = np.einsum("ij,ij->i", e2, qvec) * inv
    ok &= t > 0.0
    if not ok.any():
        return None
    candidates = np.flatnonzero(ok)
    k = int(candidates[np.argmin(t[candidates])])
    tk = float(t[k])
    return RayHit(tk, int(index[k]), float(u[k]), float(v[k]), o + tk * d)


def _straddling(o: FloatArray, d: FloatArray, pos: FloatArray, tri: npt.NDArray[np.intp]) -> npt.NDArray[np.intp]:
    """Indices of the triangles whose corners straddle the ray's line in both directions
    across it (a triangle the line crosses does; most others do not). One projection per
    vertex, then sign tests per corner: the exact test runs on a few candidates only."""
    n = float(np.linalg.norm(d))
    if not n > 0.0:
        return np.arange(len(tri))
    unit = d / n
    helper = np.eye(3)[int(np.argmin(np.abs(unit)))]
    a = np.cross(unit, helper)
    a /= np.linalg.norm(a)
    b = np.cross(unit, a)
    rel = pos - o
    index = np.arange(len(tri))
    for axis in (a, b):
        q = rel @ axis
        corners = tri[index]
        above, below = (q > 0.0)[corners], (q < 0.0)[corners]
        index = index[~above.all(axis=1) & ~below.all(axis=1)]
    return index


__all__ = ["RayHit", "ray_triangles"]
