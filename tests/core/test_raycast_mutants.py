"""Ray/triangle hits on edges and vertices (u + v = 1, v = 0 exactly), with barycentric
coordinates worked out by hand: the cases the straddling pre-filter must not drop."""

from __future__ import annotations

import numpy as np
import pytest

from qtanimator.core.raycast import _straddling, ray_triangles

# p0, p1, p2 with e1 = p1 - p0 = (2, 0, 0), e2 = p2 - p0 = (1, ±1, 0): a point
# p0 + u·e1 + v·e2 of the plane z = 0 has v = ±(y - 0) and u = (x + 1 - v) / 2.
ABOVE = np.array([[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])   # y >= 0
BELOW = np.array([[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])  # y <= 0


@pytest.mark.parametrize("positions", [ABOVE, BELOW], ids=["above", "below"])
def test_a_ray_through_an_edge_hits_either_triangle(positions):
    # The edge p0-p1 lies on the line y = 0: the ray down x = 0.25, y = 0 meets it at
    # v = 0, u = 1.25 / 2. Every corner of the triangle is on one side of the ray's line
    # or on it; the pre-filter must keep the triangle (a corner on the line is not "below").
    hit = ray_triangles([0.25, 0.0, 5.0], [0.0, 0.0, -1.0], positions, [[0, 1, 2]])
    assert hit is not None
    assert hit.t == 5.0
    assert hit.v == 0.0
    assert hit.u == 0.625
    np.testing.assert_array_equal(hit.point, [0.25, 0.0, 0.0])


@pytest.mark.parametrize("positions", [ABOVE, BELOW], ids=["above", "below"])
@pytest.mark.parametrize("direction", [[0.0, 0.0, -1.0], [0.0, 0.0, -2.0]])
def test_a_ray_through_the_edge_opposite_the_first_corner_has_u_plus_v_one(positions, direction):
    # Midpoint of p1-p2: (0.5, ±0.5, 0) = p0 + 0.5·e1 + 0.5·e2. t is in the direction's units.
    y = positions[2, 1] * 0.5
    hit = ray_triangles([0.5, y, 3.0], direction, positions, [[0, 1, 2]])
    assert hit is not None
    assert (hit.u, hit.v) == (0.5, 0.5)
    assert hit.u + hit.v == 1.0
    assert hit.t == pytest.approx(3.0 / -direction[2], abs=1e-15)


@pytest.mark.parametrize("corner, uv", [(0, (0.0, 0.0)), (1, (1.0, 0.0)), (2, (0.0, 1.0))])
def test_a_ray_through_a_vertex_hits_it(corner, uv):
    p = ABOVE[corner]
    hit = ray_triangles(p + [0.0, 0.0, 2.0], [0.0, 0.0, -1.0], ABOVE, [[0, 1, 2]])
    assert hit is not None
    assert (hit.u, hit.v) == uv
    assert hit.t == 2.0
    np.testing.assert_allclose(hit.barycentric, np.eye(3)[corner], atol=0)


def test_just_outside_the_edge_misses_and_the_nearest_of_two_is_taken():
    assert ray_triangles([0.25, -1e-9, 5.0], [0.0, 0.0, -1.0], ABOVE, [[0, 1, 2]]) is None
    # two parallel copies at z = 0 and z = 1: from above, the upper one (index 1) is first
    pos = np.vstack([ABOVE, ABOVE + [0.0, 0.0, 1.0]])
    hit = ray_triangles([0.25, 0.0, 5.0], [0.0, 0.0, -1.0], pos, [[0, 1, 2], [3, 4, 5]])
    assert hit is not None and (hit.triangle, hit.t) == (1, 4.0)


def test_a_tiny_triangle_is_hit():
    """The "ray in the triangle's plane" test is relative to |d|·|e1|·|e2|: a triangle a
    few 1e-7 across (its determinant ~1e-14) is an ordinary triangle."""
    h = 1e-7
    pos = ABOVE * h + [0.0, 0.0, 2.0]
    hit = ray_triangles([0.25 * h, 0.25 * h, 5.0], [0.0, 0.0, -1.0], pos, [[0, 1, 2]])
    assert hit is not None
    assert hit.t == pytest.approx(3.0)
    # v = y / h, u = (x / h + 1 - v) / 2 (see ABOVE)
    assert (hit.u, hit.v) == (pytest.approx(0.5), pytest.approx(0.25))


def test_the_direction_may_be_tiny():
    """Only the direction's line matters for which triangles are tested: a direction of
    length 1e-160 (whose square underflows) finds the same triangle, t in its units."""
    # the ray from the origin along (1, 1e-10, 0) meets the plane x = 1e12 at y = 100,
    # inside the triangle (1e12; 99, -1), (1e12; 101, -1), (1e12; 100, 1) at its centre line
    pos = np.array([[1e12, 99.0, -1.0], [1e12, 101.0, -1.0], [1e12, 100.0, 1.0]])
    unit_hit = ray_triangles([0.0, 0.0, 0.0], [1.0, 1e-10, 0.0], pos, [[0, 1, 2]])
    assert unit_hit is not None
    np.testing.assert_allclose(unit_hit.point, [1e12, 100.0, 0.0], rtol=1e-9)
    tiny = ray_triangles([0.0, 0.0, 0.0], [1e-160, 1e-170, 0.0], pos, [[0, 1, 2]])
    assert tiny is not None
    assert tiny.t == pytest.approx(unit_hit.t * 1e160, rel=1e-9)
    np.testing.assert_allclose(tiny.point, unit_hit.point, rtol=1e-9)


@pytest.mark.parametrize("direction", [[0.0, 0.0, -1.0], [0.0, 0.0, -0.5], [0.6, 0.0, -0.8], [1.0, 2.0, 2.0]])
def test_the_prefilter_keeps_only_triangles_around_the_line(direction):
    """A triangle off the ray's line by more than its size, in any direction across it, lies
    on one side of it along at least one of any two perpendicular axes: dropped (whether
    the gap is 5 or 0.6). Triangles around the line are kept."""
    d = np.asarray(direction, dtype=np.float64)
    d /= np.linalg.norm(d)
    helper = np.array([1.0, 0.0, 0.0]) if abs(d[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(d, helper)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(d, e1)
    o = np.array([0.5, -0.25, 2.0])
    shape = np.array([[-1.0, -0.6], [1.0, -0.6], [0.0, 1.2]])   # around (0, 0)

    def triangle(cx, cy, size, along):
        return [o + along * d + (cx + size * x) * e1 + (cy + size * y) * e2 for x, y in shape]

    far = [(5.0, 0.0), (0.0, -5.0), (3.5, 3.5), (-3.5, 3.6)]
    near = [(0.6, 0.0), (0.0, 0.6), (-0.6, 0.0), (0.0, -0.6)]
    tris = ([triangle(0.0, 0.0, 0.15, 1.0), triangle(0.05, -0.05, 0.15, 2.0)]
            + [triangle(cx, cy, 0.15, 3.0 + k) for k, (cx, cy) in enumerate(far)]
            + [triangle(cx, cy, 0.02, 7.0 + k) for k, (cx, cy) in enumerate(near)])
    pos = np.array([p for t in tris for p in t])
    tri = np.arange(len(pos)).reshape(-1, 3)
    kept = _straddling(o, np.asarray(direction, dtype=np.float64), pos, tri)
    assert kept.tolist() == [0, 1]


def test_just_outside_the_edge_opposite_the_first_corner_misses():
    """Past the edge p1-p2 (u + v > 1) is outside: at (0.5 + 1e-9, 0.5 + 1e-9) u + v is
    just above 1; a point 0.3 further out has u + v = 1.3 and misses as well."""
    for x, y in ((0.5 + 1e-9, 0.5 + 1e-9), (0.65, 0.65)):
        assert ray_triangles([x, y, 5.0], [0.0, 0.0, -1.0], ABOVE, [[0, 1, 2]]) is None
    assert ray_triangles([0.5 - 1e-9, 0.5 - 1e-9, 5.0], [0.0, 0.0, -1.0], ABOVE, [[0, 1, 2]]) is not None
