"""2D IK (core/ik.py): the handout gradient on a straight chain in closed form, the
tolerance stop, the limits of the DLS solver and the stats' defaults."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.ik import IKStats, handout_gradient, planar_chain, solve_ik


def test_stats_start_empty():
    s = IKStats()
    assert s.iterations == 0
    assert math.isnan(s.error) and s.method == ""


@pytest.mark.parametrize("dy", [10.0, -7.0])
def test_handout_gradient_of_a_straight_chain(dy):
    # planar_chain(3, 50): pivots at x = 0, 50, 100, zero angles; the point is x = 150 on
    # the last link. With e = q - p = (0, dy) and r_j = p - pivot_j = (150 - x_j, 0), the
    # handout's D_j = <e, (r.y, -r.x)> = -dy·(150 - x_j); the root's D is 0.
    ch = planar_chain(3, 50.0)
    p = np.array([150.0, 0.0])
    d = handout_gradient(ch, np.zeros(3), 2, p, p + [0.0, dy])
    np.testing.assert_allclose(d, [0.0, -dy * 100.0, -dy * 50.0], rtol=0, atol=1e-9)


def test_handout_gradient_with_a_translated_chain():
    # The whole character moved by (30, -20): pivots and the point move together, r_j does not.
    ch = planar_chain(3, 50.0)
    t = np.array([30.0, -20.0])
    d = handout_gradient(ch, np.zeros(3), 2, [150.0, 0.0], np.array([150.0, 4.0]) + t, t)
    np.testing.assert_allclose(d, [0.0, -400.0, -200.0], rtol=0, atol=1e-9)


def test_a_target_exactly_tolerance_away_is_reached():
    # |q - tip| = tolerance exactly (0 in x, 1e-4 in y, both exact in floats): "within
    # tolerance" holds, so nothing moves and no iteration runs.
    ch = planar_chain(3, 50.0)
    a0 = np.array([0.0, 0.0, 0.0])
    stats = IKStats()
    out = solve_ik(ch, a0, (0.0, 0.0), 2, [150.0, 0.0], [150.0, 1e-4], tolerance=1e-4,
                   freeze_root=False, stats=stats)
    np.testing.assert_array_equal(out, a0)
    assert stats.iterations == 0
    assert stats.error == 1e-4


def test_dls_limits_clamp_at_the_upper_bound():
    # Target (0, -150), out of reach from pivot 1: joint 1 wants a large positive angle;
    # it may turn at most 0.1 rad, joint 2 is free. Root frozen.
    ch = planar_chain(3, 50.0)
    limits = [None, (-1.0, 0.1), None]
    out = solve_ik(ch, np.zeros(3), (0.0, 0.0), 2, [150.0, 0.0], [0.0, -150.0], limits,
                   max_iterations=200)
    assert out[0] == 0.0
    assert out[1] == pytest.approx(0.1, abs=1e-12)
    # without the limit joint 1 turns further than 0.1
    free = solve_ik(ch, np.zeros(3), (0.0, 0.0), 2, [150.0, 0.0], [0.0, -150.0], max_iterations=200)
    assert free[1] > 0.1
