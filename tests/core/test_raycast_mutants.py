"""Ray/triangle hits on edges and vertices (u + v = 1, v = 0 exactly), with barycentric
coordinates worked out by hand: the cases the straddling pre-filter must not drop."""

from __future__ import annotations

import numpy as np
import pytest

from qtanimator.core.raycast import ray_triangles

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
