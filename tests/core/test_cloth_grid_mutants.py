"""The cloth grid (cloth_grid.py) against a second, loop-by-loop enumeration written here:
springs by kind and rest length, triangles, pins, rest positions and UVs, plus Rodrigues'
rotation formula applied to vectors, small-area vertex normals and the ray pick."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.cloth_grid import build_grid, nearest_particle, pins_from_cells, rotation_matrix, vertex_normals
from qtanimator.core.cloth_params import ClothParams


def _hand_springs(rows: int, cols: int, dx: float, dy: float) -> set[tuple[int, int, int, float]]:
    """(i, j, kind, rest) of every spring, by walking the grid: structural right/down, shear
    both diagonals of each quad, bend two to the right / two down."""
    out = set()
    diag = math.hypot(dx, dy)
    for r in range(rows):
        for c in range(cols):
            i = r * cols + c
            if c + 1 < cols:
                out.add((i, i + 1, 0, round(dx, 12)))
            if r + 1 < rows:
                out.add((i, i + cols, 0, round(dy, 12)))
            if r + 1 < rows and c + 1 < cols:
                out.add((i, i + cols + 1, 1, round(diag, 12)))
            if r + 1 < rows and c - 1 >= 0:
                out.add((i, i + cols - 1, 1, round(diag, 12)))
            if c + 2 < cols:
                out.add((i, i + 2, 2, round(2 * dx, 12)))
            if r + 2 < rows:
                out.add((i, i + 2 * cols, 2, round(2 * dy, 12)))
    return out


@pytest.mark.parametrize("rows,cols", [(3, 4), (4, 3), (2, 2), (2, 5), (5, 2)])
def test_springs_match_a_walk_over_the_grid(rows: int, cols: int) -> None:
    p = ClothParams(rows=rows, cols=cols, width=1.2, height=0.9)
    g = build_grid(p)
    dx, dy = 1.2 / (cols - 1), 0.9 / (rows - 1)
    got = {(int(i), int(j), int(k), round(float(L), 12))
           for (i, j), k, L in zip(g.springs, g.spring_kinds, g.rest_lengths)}
    assert len(got) == len(g.springs)
    assert got == _hand_springs(rows, cols, dx, dy)
    np.testing.assert_array_equal(g.si, g.springs[:, 0])
    np.testing.assert_array_equal(g.sj, g.springs[:, 1])
    # Every rest length is the distance between the two rest positions.
    d = g.rest_positions[g.sj] - g.rest_positions[g.si]
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), g.rest_lengths, rtol=1e-12)
    # The families cover exactly the valid springs.
    assert int(g.fam_valid.sum()) == len(g.springs)
    assert sum(f.stop - f.start for f in g.families) == len(g.fam_valid)


def test_triangles_are_two_per_quad_in_the_documented_order() -> None:
    """Per quad (a, c, d), (a, d, b): a = (r, c), b right, c below, d below-right."""
    rows, cols = 3, 4
    g = build_grid(ClothParams(rows=rows, cols=cols))
    want = []
    for r in range(rows - 1):
        for c in range(cols - 1):
            a = r * cols + c
            want += [[a, a + cols, a + cols + 1], [a, a + cols + 1, a + 1]]
    assert g.triangles.tolist() == want


def test_rest_positions_uvs_and_placement() -> None:
    """A 3 × 2 grid, 2 m wide and 1 m high, turned 90° about y and moved to (1, 2, 3): the top
    edge is centred on the origin and spans x (then −z after the turn), rows hang down along −y."""
    p = ClothParams(rows=3, cols=2, width=2.0, height=1.0, origin=(1.0, 2.0, 3.0), orientation=(0.0, math.pi / 2, 0.0))
    g = build_grid(p)
    local = np.array([[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [-1.0, -0.5, 0.0], [1.0, -0.5, 0.0],
                      [-1.0, -1.0, 0.0], [1.0, -1.0, 0.0]])
    # 90° about y: (x, y, z) → (z, y, −x).
    world = np.stack([local[:, 2], local[:, 1], -local[:, 0]], axis=1) + [1.0, 2.0, 3.0]
    np.testing.assert_allclose(g.rest_positions, world, atol=1e-12)
    np.testing.assert_allclose(g.uvs, [[0, 1], [1, 1], [0, 0.5], [1, 0.5], [0, 0], [1, 0]], atol=1e-15)
    assert g.n == 6 and g.rows == 3 and g.cols == 2


@pytest.mark.parametrize("mode,want", [("top_corners", [0, 3]), ("top_edge", [0, 1, 2, 3]), ("none", []),
                                       ("custom", [5, 9])])
def test_pin_modes(mode: str, want: list[int]) -> None:
    g = build_grid(ClothParams(rows=3, cols=4, pin_mode=mode, custom_pins=[9, 5] if mode == "custom" else []))
    assert g.pin_index.tolist() == want
    assert np.flatnonzero(g.pinned).tolist() == want


def test_pins_from_cells() -> None:
    assert pins_from_cells(5, [(0, 0), (1, 2), (3, 4)]) == [0, 7, 19]


# ------------------------------------------------------------------ rotations
@pytest.mark.parametrize("rv", [(0.3, -0.5, 0.2), (0.0, 0.0, 2.0), (1.0, 0.0, 0.0), (-0.4, 0.9, 1.3)])
def test_rotation_matrix_is_rodrigues(rv: tuple[float, float, float]) -> None:
    """R·v = v·cosθ + (k × v)·sinθ + k·(k·v)·(1 − cosθ) for a few vectors v."""
    r = np.array(rv)
    theta = float(np.linalg.norm(r))
    k = r / theta
    rot = rotation_matrix(r)
    for v in np.random.default_rng(2).normal(size=(4, 3)):
        want = v * math.cos(theta) + np.cross(k, v) * math.sin(theta) + k * np.dot(k, v) * (1 - math.cos(theta))
        np.testing.assert_allclose(rot @ v, want, rtol=1e-12, atol=1e-14)


def test_rotation_matrix_of_zero_and_of_a_matrix() -> None:
    np.testing.assert_array_equal(rotation_matrix((0.0, 0.0, 0.0)), np.eye(3))
    m = rotation_matrix((0.1, 0.2, 0.3))
    assert rotation_matrix(m) is not m
    np.testing.assert_array_equal(rotation_matrix(m), m)
    with pytest.raises(ValueError):
        rotation_matrix((1.0, 2.0))


# ------------------------------------------------------------------ normals and picking
def test_vertex_normals_of_a_small_tilted_triangle() -> None:
    """A triangle of area 0.005 in the x-z plane, (0,0,0), (0,0,0.1), (0.1,0,0): normal
    (0,0,0.1) × (0.1,0,0) = (0, 0.01, 0) → +y at its corners; a vertex with no triangle gets
    the fallback."""
    x = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.1], [0.1, 0.0, 0.0], [3.0, 3.0, 3.0]])
    nrm = vertex_normals(x, np.array([[0, 1, 2]]), fallback=(1.0, 0.0, 0.0))
    np.testing.assert_allclose(nrm, [[0.0, 1.0, 0.0]] * 3 + [[1.0, 0.0, 0.0]], atol=1e-15)


def test_a_particle_at_the_ray_origin_is_on_the_ray() -> None:
    """The ray starts at its origin: a particle there is at distance 0 (it is not behind)."""
    pts = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [5.0, 0.5, 0.0]])
    assert nearest_particle(pts, (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)) == 1


def test_nearest_particle_ignores_particles_behind_and_far() -> None:
    pts = np.array([[0.0, 0.0, -1.0], [0.3, 0.0, 2.0], [0.0, 0.2, 5.0]])
    assert nearest_particle(pts, (0.0, 0.0, 0.0), (0.0, 0.0, 2.0)) == 2
    assert nearest_particle(pts, (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), max_distance=0.1) is None
    assert nearest_particle(pts, (0.0, 0.0, 0.0), (0.0, 0.0, -1.0)) == 0
    assert nearest_particle(pts, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)) is None
    assert nearest_particle(pts[:1], (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)) is None


def test_the_ray_direction_length_does_not_matter() -> None:
    """The distance to a ray is |w|² − (w·d̂)² with d̂ the unit direction: (0.1, 0, 1) is 0.1
    from the z axis and (0.5, 0, 10) 0.5, whatever the length of the direction given (a
    direction left unnormalised would weigh the far particle's (w·d)² more and pick it)."""
    pts = np.array([[0.5, 0.0, 10.0], [0.1, 0.0, 1.0]])
    for length in (0.25, 1.0, 2.0, 40.0):
        assert nearest_particle(pts, (0.0, 0.0, 0.0), (0.0, 0.0, length)) == 1
        assert nearest_particle(pts, (0.0, 0.0, 0.0), (0.0, 0.0, length), max_distance=0.11) == 1
        assert nearest_particle(pts, (0.0, 0.0, 0.0), (0.0, 0.0, length), max_distance=0.09) is None


def test_a_particle_exactly_max_distance_from_the_ray_counts() -> None:
    """"Only particles that close to the ray count": (0.5, 0, 1) is |w|² − (w·d̂)² =
    1.25 − 1 = 0.25 = 0.5² (every number exact in binary) from the z axis, so with
    max_distance 0.5 it is picked; with 0.4999 it is not."""
    pts = np.array([[0.5, 0.0, 1.0]])
    assert nearest_particle(pts, (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), max_distance=0.5) == 0
    assert nearest_particle(pts, (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), max_distance=0.4999) is None
