"""The cloth's grid: particles, pins, spring families and triangles, and geometry on them.

* Particle ``(r, c)`` has index ``r·cols + c``; row 0 is the top edge. In the cloth's own
  frame the top edge is centred on the origin and the cloth hangs down along −y, spanning x;
  ``ClothParams.orientation`` (a rotation vector, radians) and ``origin`` place it.
* Springs: structural (right and down neighbours), shear (both diagonals of every quad) and
  bend (skip one particle, horizontally and vertically). On a regular grid every spring
  family is a pair of slices of the flat particle array (offset 1, cols, cols ± 1, 2,
  2·cols): :class:`SpringFamily` records them, and :attr:`ClothGrid.springs` lists the same
  springs explicitly (for the implicit solver and for drawing).
* Triangles: per quad (a, c, d) and (a, d, b), with a = (r, c), b its right neighbour, c the
  one below and d below-right.

:func:`build_grid` builds it all from :class:`~qtanimator.core.cloth_params.ClothParams`;
:class:`qtanimator.core.cloth.Cloth` simulates on it.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.core.cloth_params import ClothParams

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]
BoolArray = npt.NDArray[np.bool_]

__all__ = ["BoolArray", "ClothGrid", "FloatArray", "IntArray", "SpringFamily", "build_grid", "grid_index",
           "nearest_particle", "pins_from_cells", "rotation_matrix", "vertex_normals"]


def rotation_matrix(rotation: Any) -> FloatArray:
    """A 3×3 rotation from a rotation vector (axis·angle, radians) or a 3×3 matrix."""
    r = np.asarray(rotation, dtype=np.float64)
    if r.shape == (3, 3):
        return r.copy()
    if r.shape != (3,):
        raise ValueError("a rotation is an axis-angle vector (3,) or a 3×3 matrix")
    angle = float(np.linalg.norm(r))
    if angle < 1e-15:
        return np.eye(3)
    k = r / angle
    kx = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + math.sin(angle) * kx + (1.0 - math.cos(angle)) * (kx @ kx)


@dataclass(frozen=True)
class SpringFamily:
    """Springs ``(i, i + offset)`` for ``i`` in ``[0, n − offset)``; segment ``[start, stop)`` of the buffers."""

    offset: int
    start: int
    stop: int


@dataclass(frozen=True)
class ClothGrid:
    """A cloth's structure: everything that depends on the grid, its size, placement and pins.

    ``fam_valid`` / ``fam_kind`` / ``fam_rest`` run over the families' segments end to end
    (a spring slot is invalid where the slice pairs particles that are not neighbours, across
    a row end); ``springs`` / ``spring_kinds`` / ``rest_lengths`` hold the valid ones only,
    ``si`` / ``sj`` their two columns (contiguous)."""

    rows: int
    cols: int
    n: int
    rotation: FloatArray
    rest_positions: FloatArray
    uvs: FloatArray
    pinned: BoolArray
    pin_index: IntArray
    families: list[SpringFamily]
    fam_valid: BoolArray
    fam_kind: npt.NDArray[np.int8]
    fam_rest: FloatArray
    springs: IntArray
    spring_kinds: npt.NDArray[np.int8]
    rest_lengths: FloatArray
    si: IntArray
    sj: IntArray
    triangles: IntArray


def build_grid(p: ClothParams) -> ClothGrid:
    """The grid of ``p``: rest positions, UVs, pins, springs and triangles."""
    R, C = p.rows, p.cols
    n = R * C
    dx, dy = p.width / (C - 1), p.height / (R - 1)
    r, c = np.divmod(np.arange(n), C)
    local = np.stack([c * dx - p.width / 2.0, -r * dy, np.zeros(n)], axis=1)
    rot = rotation_matrix(p.orientation)
    rest_positions: FloatArray = local @ rot.T + np.asarray(p.origin, dtype=np.float64)
    uvs: FloatArray = np.stack([c / (C - 1), 1.0 - r / (R - 1)], axis=1).astype(np.float64)

    pinned = np.zeros(n, dtype=bool)
    if p.pin_mode == "top_corners":
        pinned[[0, C - 1]] = True
    elif p.pin_mode == "top_edge":
        pinned[:C] = True
    elif p.pin_mode == "custom":
        pinned[np.asarray(p.custom_pins, dtype=np.int64)] = True

    # Spring families: (offset, kind, valid mask over i in [0, n - offset), rest length).
    diag = math.hypot(dx, dy)
    spec = [
        (1, 0, c < C - 1, dx), (C, 0, r < R - 1, dy),
        (C + 1, 1, (c < C - 1) & (r < R - 1), diag), (C - 1, 1, (c > 0) & (r < R - 1), diag),
        (2, 2, c < C - 2, 2 * dx), (2 * C, 2, r < R - 2, 2 * dy),
    ]
    families: list[SpringFamily] = []
    masks, kinds, rests = [], [], []
    start = 0
    for offset, kind, valid, rest in spec:
        if offset <= 0 or offset >= n:
            continue
        v = valid[: n - offset]
        if not v.any():
            continue
        families.append(SpringFamily(offset, start, start + n - offset))
        start += n - offset
        masks.append(v)
        kinds.append(np.full(n - offset, kind, dtype=np.int8))
        rests.append(np.full(n - offset, rest))
    fam_valid = np.concatenate(masks)
    fam_kind = np.concatenate(kinds)
    fam_rest = np.concatenate(rests)

    # The same springs as an explicit list (for the implicit solver and for drawing).
    seg_i = [np.arange(f.stop - f.start) for f in families]
    idx_i = np.concatenate(seg_i)
    idx_j = np.concatenate([s + f.offset for s, f in zip(seg_i, families)])
    springs: IntArray = np.stack([idx_i[fam_valid], idx_j[fam_valid]], axis=1).astype(np.int64)

    # Triangles: per quad (a, c, d) and (a, d, b) with a = (r, c), b = right, c = below, d = below-right.
    qa = (r * C + c)[(r < R - 1) & (c < C - 1)]
    tris = np.empty((2 * len(qa), 3), dtype=np.int64)
    tris[0::2] = np.stack([qa, qa + C, qa + C + 1], axis=1)
    tris[1::2] = np.stack([qa, qa + C + 1, qa + 1], axis=1)

    return ClothGrid(R, C, n, rot, rest_positions, uvs, pinned, np.flatnonzero(pinned), families, fam_valid, fam_kind,
                     fam_rest, springs, fam_kind[fam_valid], np.ascontiguousarray(fam_rest[fam_valid]),
                     np.ascontiguousarray(springs[:, 0]), np.ascontiguousarray(springs[:, 1]), tris)


def vertex_normals(positions: FloatArray, triangles: IntArray, fallback: Any = (0.0, 0.0, 1.0)) -> FloatArray:
    """Smooth unit normals per vertex: the sum of the adjacent triangles' area-weighted normals.

    Vertices with no area around them get ``fallback``.
    """
    x = np.asarray(positions, dtype=np.float64)
    t = np.asarray(triangles, dtype=np.int64)
    n = len(x)
    fn = np.cross(x[t[:, 1]] - x[t[:, 0]], x[t[:, 2]] - x[t[:, 0]])
    vn = np.zeros((n, 3))
    for k in range(3):
        vn[:, k] = (np.bincount(t[:, 0], fn[:, k], n) + np.bincount(t[:, 1], fn[:, k], n)
                    + np.bincount(t[:, 2], fn[:, k], n))
    length = np.sqrt(np.einsum("ij,ij->i", vn, vn))
    ok = length > 1e-300
    vn[ok] /= length[ok, None]
    vn[~ok] = np.asarray(fallback, dtype=np.float64)
    return vn


def nearest_particle(positions: FloatArray, ray_origin: Any, ray_dir: Any,
                     max_distance: float | None = None) -> int | None:
    """The particle nearest to a ray (in front of its origin), or None.

    With ``max_distance`` only particles that close to the ray count. :meth:`Cloth.grab`
    uses it; a viewer holding a snapshot of the positions can pick with it too.
    """
    o = np.asarray(ray_origin, dtype=np.float64).reshape(3)
    d = np.asarray(ray_dir, dtype=np.float64).reshape(3)
    norm = float(np.linalg.norm(d))
    if not norm > 0 or len(positions) == 0:
        return None
    d = d / norm
    w = np.asarray(positions, dtype=np.float64) - o
    along = w @ d
    dist2 = np.einsum("ij,ij->i", w, w) - along * along
    dist2[along < 0] = np.inf
    i = int(np.argmin(dist2))
    if not np.isfinite(dist2[i]):
        return None
    if max_distance is not None and dist2[i] > max_distance * max_distance:
        return None
    return i


def grid_index(cols: int, row: int, col: int) -> int:
    """Flat particle index of ``(row, col)`` in a cloth with ``cols`` columns."""
    return row * cols + col


def pins_from_cells(cols: int, cells: Iterable[Sequence[int]]) -> list[int]:
    """Flat indices for ``custom_pins`` from ``(row, col)`` pairs."""
    return [grid_index(cols, int(r), int(c)) for r, c in cells]
