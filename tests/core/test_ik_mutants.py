"""2D IK (core/ik.py): the handout gradient on a straight chain in closed form, the
tolerance stop, the limits of the DLS solver and the stats' defaults."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from qtanimator.core.ik import IKStats, end_effector, handout_gradient, limit_bounds, planar_chain, solve_ik


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


def _solve_scaled(s: float, target, **kw):
    ch = planar_chain(3, 50.0 * s)
    stats = IKStats()
    out = solve_ik(ch, np.array([0.0, 0.3, -0.2]), (0.0, 0.0), 2, [150.0 * s, 0.0], np.asarray(target) * s,
                   tolerance=1e-9 * s, stats=stats, **kw)
    return out, stats


@pytest.mark.parametrize("target", [[90.0, 120.0], [0.0, -150.0]])
def test_dls_is_scale_invariant(target):
    """Every threshold of the solver (damping, its floor, tolerance) scales with the chain:
    the same problem drawn 4096 times smaller or larger gives the same angles and the same
    iteration count. A power-of-two scale is exact in floating point, so the results must
    be identical. The targets are at full stretch (150 from the root pivot), where the
    damping shrinks to its floor."""
    ref, ref_stats = _solve_scaled(1.0, target, freeze_root=False, max_iterations=300)
    assert ref_stats.error < 1e-9
    for s in (2.0 ** -12, 2.0 ** 12):
        out, stats = _solve_scaled(s, target, freeze_root=False, max_iterations=300)
        np.testing.assert_array_equal(out, ref)
        assert stats.iterations == ref_stats.iterations
        assert stats.error == ref_stats.error * s


def test_undamped_singular_jacobian_does_not_blow_up():
    """damping=0 on a straight chain: J Jᵀ is singular (every pivot on the x axis, so the
    x row of J is zero); the step is skipped rather than divided by a zero determinant, and
    the start, the best pose found, is returned."""
    ch = planar_chain(3, 50.0)
    stats = IKStats()
    with warnings.catch_warnings():
        warnings.simplefilter("error")   # no division by zero (numpy warns on it)
        out = solve_ik(ch, np.zeros(3), (0.0, 0.0), 2, [150.0, 0.0], [140.0, 10.0], damping=0.0,
                       freeze_root=False, stats=stats)
    np.testing.assert_array_equal(out, np.zeros(3))
    assert stats.error == pytest.approx(math.hypot(10.0, 10.0))


def test_one_sided_limits_are_limits():
    """Only minima (maxima +inf), or only maxima, still limit the joints; all-free or NaN
    limits are no limits at all."""
    inf = math.inf
    lo, hi = limit_bounds([(0.0, inf), None, (-inf, inf)], 3)
    np.testing.assert_array_equal(lo, [0.0, -inf, -inf])
    np.testing.assert_array_equal(hi, [inf, inf, inf])
    lo, hi = limit_bounds(np.array([[-inf, inf], [-inf, 0.25], [math.nan, math.nan]]), 3)
    np.testing.assert_array_equal(lo, [-inf, -inf, -inf])
    np.testing.assert_array_equal(hi, [inf, 0.25, inf])
    assert limit_bounds([None, None, None], 3) is None
    assert limit_bounds(np.full((3, 2), math.nan), 3) is None
    assert limit_bounds(None, 3) is None
    # a minimum alone stops joint 1 turning negative towards (150, 60) (below: +y)
    ch = planar_chain(3, 50.0)
    free = solve_ik(ch, np.zeros(3), (0.0, 0.0), 2, [150.0, 0.0], [140.0, 60.0])
    assert free[1] < 0.0
    out = solve_ik(ch, np.zeros(3), (0.0, 0.0), 2, [150.0, 0.0], [140.0, 60.0], [None, (0.0, inf), None])
    assert out[1] == 0.0


def test_handout_gradient_is_minus_the_gradient_of_half_the_squared_distance():
    """D_j = -∂f/∂θ_j for f = ½|p - q|² (the handout), checked by central differences on a
    bent chain at the default translation, the root's D being 0."""
    ch = planar_chain(3, 50.0)
    angles = np.array([0.3, -0.4, 0.7])
    local = np.array([150.0, 5.0])
    q = np.array([60.0, 95.0])

    def f(a):
        p = end_effector(ch, a, (0.0, 0.0), 2, local)
        return 0.5 * float((p - q) @ (p - q))

    d = handout_gradient(ch, angles, 2, local, q)
    h = 1e-6
    for j in (1, 2):
        plus, minus = angles.copy(), angles.copy()
        plus[j] += h
        minus[j] -= h
        assert d[j] == pytest.approx(-(f(plus) - f(minus)) / (2 * h), rel=1e-6)
    assert d[0] == 0.0


def test_one_iteration_is_one_damped_step():
    """max_iterations=1 takes exactly one step. planar_chain(2, 50), root frozen, point
    (100, 0) on joint 1, target (100, -20): the tip is 50 from joint 1's pivot, so
    J = [[0, 0], [0, -50]] (the frozen root's column is 0) and e = (0, -20); the damping is
    1e-3 · scale² with scale = 100 (the root pivot to the tip), λ² = 10. The step
    Jᵀ (J Jᵀ + λ² I)⁻¹ e for joint 1 is (-50)(-20) / (2500 + 10)."""
    ch = planar_chain(2, 50.0)
    stats = IKStats()
    out = solve_ik(ch, np.zeros(2), (0.0, 0.0), 1, [100.0, 0.0], [100.0, -20.0], max_iterations=1, stats=stats)
    assert stats.iterations == 1
    assert out[0] == 0.0
    assert out[1] == pytest.approx(1000.0 / 2510.0, rel=1e-12)


def test_planar_chain_links_are_thin_rectangles_along_x():
    """Each link is a closed rectangle from its pivot to the next, symmetric about the x
    axis, filled with a valid RGBA colour."""
    ch = planar_chain(3, 10.0)
    assert [j.parent for j in ch.joints] == [None, 0, 1]
    for i, joint in enumerate(ch.joints):
        (shape,) = joint.shapes
        pts = np.asarray(shape.points)
        assert shape.closed
        assert pts[:, 0].min() == 10.0 * i and pts[:, 0].max() == 10.0 * (i + 1)
        assert pts[:, 1].min() == -pts[:, 1].max() > -10.0
        assert sorted(map(tuple, pts)) == sorted({(x, y) for x in (pts[:, 0].min(), pts[:, 0].max())
                                                  for y in (pts[:, 1].min(), pts[:, 1].max())})
        assert all(0.0 <= c <= 1.0 for c in shape.fill)
