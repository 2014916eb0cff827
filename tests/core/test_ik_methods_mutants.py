"""2D CCD / FABRIK helpers (core/ik_methods.py): the pattern move's parabola vertex, and
the iteration count of a solve that has nothing to do."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.ik import IKStats, planar_chain
from qtanimator.core.ik_methods import _extrapolate, solve_ccd, solve_fabrik, solve_two_bone, two_bone_closed_form


class _LineChain:
    """A stand-in chain whose tip is (delta[0], 0): the error at factor f along a step is
    |target - f·step| exactly, so the squared error is a parabola in f."""

    def evaluate(self, delta):
        d = np.asarray(delta, dtype=np.float64)
        return None, np.zeros((1, 2)), np.array([d[0], 0.0])


def test_pattern_move_lands_on_the_parabola_vertex():
    # Target x = 3, sweep from 0 to 1: factors 1, 2, 4 give errors 2, 1, 1 (4 is no better
    # than 2, so doubling stops). The squared errors 4, 1, 1 at f = 1, 2, 4 lie on
    # (f - 3)², whose vertex f = 3 hits the target exactly.
    inf = np.full(1, math.inf)
    cand, _piv, tip, err = _extrapolate(_LineChain(), np.zeros(1), np.ones(1), 2.0,
                                        np.array([3.0, 0.0]), -inf, inf, np.zeros(1))
    assert cand[0] == pytest.approx(3.0, abs=1e-12)
    assert err == pytest.approx(0.0, abs=1e-12)
    np.testing.assert_allclose(tip, [3.0, 0.0], atol=1e-12)


def test_pattern_move_vertex_off_centre():
    # Target x = 2.5: errors at f = 1, 2, 4 are 1.5, 0.5, 1.5; squared 2.25, 0.25, 2.25
    # lie on (f - 2.5)², vertex 2.5.
    inf = np.full(1, math.inf)
    cand, _piv, _tip, err = _extrapolate(_LineChain(), np.zeros(1), np.ones(1), 1.5,
                                         np.array([2.5, 0.0]), -inf, inf, np.zeros(1))
    assert cand[0] == pytest.approx(2.5, abs=1e-12)
    assert err == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("accelerate", [True, False])
def test_fabrik_at_the_target_runs_no_iteration(accelerate):
    ch = planar_chain(3, 50.0)
    a0 = np.array([0.0, 0.2, -0.1])
    stats = IKStats()
    # the point's own position at a0: x along the links, found by forward kinematics
    tip = ch.pose(a0, (0.0, 0.0)).to_world(2, [150.0, 0.0])
    out = solve_fabrik(ch, a0, (0.0, 0.0), 2, [150.0, 0.0], tip, stats=stats, accelerate=accelerate)
    assert stats.iterations == 0
    np.testing.assert_array_equal(out, a0)


def test_fabrik_counts_its_iterations():
    ch = planar_chain(3, 50.0)
    stats = IKStats()
    solve_fabrik(ch, np.zeros(3), (0.0, 0.0), 2, [150.0, 0.0], [60.0, 80.0], stats=stats,
                 max_iterations=1, accelerate=False, tolerance=1e-12)
    assert stats.iterations == 1


@pytest.mark.parametrize("target, limit", [([0.0, -150.0], 1.0), ([0.0, 150.0], -1.0)])
def test_ccd_turns_a_joint_exactly_to_its_limit(target, limit):
    """Joint 1 would have to turn about 1.9 rad to point the end at the target; limited to
    [-1, 1] (joint 2 pinned at 0) it stops exactly at the limit, turning by exactly ±1."""
    ch = planar_chain(3, 50.0)
    stats = IKStats()
    out = solve_ccd(ch, np.zeros(3), (0.0, 0.0), 2, [150.0, 0.0], target, [None, (-1.0, 1.0), (0.0, 0.0)],
                    stats=stats)
    assert out.tolist() == [0.0, limit, 0.0]
    # the end 100 from pivot 1 (50, 0) at angle 1 rad towards the target's side
    end = np.array([50.0 + 100.0 * math.cos(1.0), -math.copysign(100.0 * math.sin(1.0), limit)])
    assert stats.error == pytest.approx(float(np.linalg.norm(np.asarray(target) - end)), rel=1e-12)


def test_two_bone_with_the_target_on_the_first_pivot_and_a_limited_middle():
    """Target on the first pivot (50, 0): the bones would fold completely, but the middle
    joint may bend only 0.5 rad. The closest pose bends it to a limit; the end is then
    2·50·cos(0.25) from the pivot, whatever the first joint's angle (no direction to aim)."""
    ch = planar_chain(3, 50.0)
    stats = IKStats()
    out = solve_two_bone(ch, np.zeros(3), (0.0, 0.0), 2, [150.0, 0.0], [50.0, 0.0], [None, None, (-0.5, 0.5)],
                         stats=stats)
    assert np.all(np.isfinite(out))
    assert abs(out[2]) == 0.5
    assert stats.error == pytest.approx(100.0 * math.cos(0.25), rel=1e-12)


@pytest.mark.parametrize("target", [[148.0, 0.0], [50.0 + 98.0 * 0.6, 98.0 * 0.8]])
@pytest.mark.parametrize("limits, sign", [((-0.5, 2.7), 1.0), ((-2.7, 0.5), -1.0)])
def test_two_bone_straight_chain_bends_to_the_side_its_limits_lean_to(target, limits, sign):
    """A straight chain with "keep" has no current side; the middle's limits (midpoint
    ±1.1 rad) choose the side, even though the other one fits too. Target 98 from the
    first pivot: bend pi - acos((50² + 50² - 98²) / (2·50·50))."""
    ch = planar_chain(3, 50.0)
    stats = IKStats()
    out = solve_two_bone(ch, np.zeros(3), (0.0, 0.0), 2, [150.0, 0.0], target, [None, None, limits],
                         stats=stats)
    assert out[2] == pytest.approx(sign * (math.pi - math.acos((5000.0 - 98.0 ** 2) / 5000.0)), abs=1e-12)
    assert stats.error < 1e-9


def _ccd_sweep_by_hand(pivots, end, goal, joints):
    """One CCD sweep in plain geometry: each pivot (last first) turns the end towards the
    goal; pivots above a joint do not move when it turns."""
    end = np.asarray(end, dtype=np.float64)
    goal = np.asarray(goal, dtype=np.float64)
    for k in joints:
        p = np.asarray(pivots[k], dtype=np.float64)
        u, w = end - p, goal - p
        a = math.atan2(u[0] * w[1] - u[1] * w[0], u @ w)
        c, s = math.cos(a), math.sin(a)
        end = p + np.array([c * u[0] - s * u[1], s * u[0] + c * u[1]])
    return end


@pytest.mark.parametrize("point, target", [([3.0, 0.0], [2.0, 1.0]), ([2.0, 1.0], [3.0, 0.0]),
                                           ([3.0, 0.0], [1.5, 2.0]), ([2.0, 1.0], [0.5, -1.5])])
def test_one_ccd_sweep_by_hand(point, target):
    """Links of length 1 (pivots (0, 0), (1, 0), (2, 0)), root frozen: one sweep without the
    pattern move puts the end where the hand-written sweep does. The first joint turned
    sees the end and the target at whole-unit offsets such as (1, 0) and (0, 1)."""
    ch = planar_chain(3, 1.0)
    stats = IKStats()
    out = solve_ccd(ch, np.zeros(3), (0.0, 0.0), 2, point, target, max_iterations=1, accelerate=False,
                    tolerance=1e-12, stats=stats)
    expected = _ccd_sweep_by_hand([(0.0, 0.0), (1.0, 0.0), (2.0, 0.0)], point, target, (2, 1))
    assert stats.iterations == 1
    assert out[0] == 0.0
    np.testing.assert_allclose(ch.pose(out, (0.0, 0.0)).to_world(2, point), expected, atol=1e-12)
    assert stats.error == pytest.approx(float(np.linalg.norm(np.asarray(target) - expected)), abs=1e-12)


@pytest.mark.parametrize("solver", [solve_ccd, solve_fabrik, solve_two_bone])
def test_a_target_exactly_tolerance_away_needs_no_iteration(solver):
    """|q - tip| = tolerance exactly (1e-4 in y): within tolerance, as for the DLS solver."""
    ch = planar_chain(3, 50.0)
    stats = IKStats()
    out = solver(ch, np.zeros(3), (0.0, 0.0), 2, [150.0, 0.0], [150.0, 1e-4], tolerance=1e-4, stats=stats)
    if solver is not solve_two_bone:
        assert stats.iterations == 0
        np.testing.assert_array_equal(out, np.zeros(3))
    assert stats.error <= 1e-4


def test_two_bone_with_an_off_axis_point_reports_the_true_error():
    """The dragged point is off the bone's line ((150, 10) on joint 2): the analytic pose
    puts it on the target, and the error reported is that of the pose returned."""
    ch = planar_chain(3, 50.0)
    point = [150.0, 10.0]
    for target in ([120.0, 40.0], [90.0, -50.0]):
        stats = IKStats()
        out = solve_two_bone(ch, np.zeros(3), (0.0, 0.0), 2, point, target, stats=stats)
        end = ch.pose(out, (0.0, 0.0)).to_world(2, point)
        np.testing.assert_allclose(end, target, atol=1e-9)
        assert stats.error < 1e-9


@pytest.mark.parametrize("limits", [(0.1, 0.2), (-0.2, -0.1)])
def test_two_bone_projection_aims_the_chain_at_an_unbendable_target(limits):
    """Target 60 from the first pivot would need a bend of about 2.1 rad; the middle may
    bend only 0.1 to 0.2 rad (one side), so the closest pose bends it 0.2 and points the chain at
    the target: the end is then 2·50·cos(0.1) from the pivot, on the line to the target."""
    ch = planar_chain(3, 50.0)
    stats = IKStats()
    a = np.array([50.0, 0.0])
    target = a + 60.0 * np.array([0.6, -0.8])
    out = solve_two_bone(ch, np.zeros(3), (0.0, 0.0), 2, [150.0, 0.0], target, [None, None, limits], stats=stats)
    assert abs(out[2]) == pytest.approx(0.2)
    end = ch.pose(out, (0.0, 0.0)).to_world(2, [150.0, 0.0])
    reach = 100.0 * math.cos(0.1)
    np.testing.assert_allclose(end, a + reach * np.array([0.6, -0.8]), atol=1e-9)
    assert stats.error == pytest.approx(reach - 60.0, abs=1e-9)


@pytest.mark.parametrize("target", [[120.0, 80.0], [60.0, -100.0], [150.0, 20.0]])
def test_plain_fabrik_converges_on_a_reachable_target(target):
    """Without limits or the pattern move, FABRIK's passes converge on any reachable target
    (Aristidou & Lasenby): each pass starts from the positions the last one laid out."""
    ch = planar_chain(4, 50.0)
    stats = IKStats()
    out = solve_fabrik(ch, np.zeros(4), (0.0, 0.0), 3, [200.0, 0.0], target, max_iterations=100,
                       accelerate=False, tolerance=1e-9, stats=stats)
    assert stats.error < 1e-9
    np.testing.assert_allclose(ch.pose(out, (0.0, 0.0)).to_world(3, [200.0, 0.0]), target, atol=1e-8)


def test_ccd_with_the_target_on_an_off_axis_tip_runs_no_sweep():
    """The chain translated by (0, 30): the tip (150, 0) of the straight chain is at
    (150, 30), and so is the target. The error is 0 from the start (both coordinates
    count), so no sweep runs and nothing moves."""
    ch = planar_chain(3, 50.0)
    stats = IKStats()
    out = solve_ccd(ch, np.zeros(3), (0.0, 30.0), 2, [150.0, 0.0], [150.0, 30.0], tolerance=1e-4, stats=stats)
    assert stats.iterations == 0
    assert stats.error <= 1e-12
    np.testing.assert_array_equal(out, np.zeros(3))


@pytest.mark.parametrize("upper, lower", [(0.1, 0.3), (0.1, 1.1), (0.1, 2.9)])
def test_two_bone_closed_form_fully_folded(upper, lower):
    """A target on the first pivot with a longer lower bone: the reach is clamped to
    lower - upper and the chain folds flat. The inner angle is 0, so the lower bone turns
    by pi; the upper bone points away from the target (its angle from the line to the
    target is pi). (For these lengths the law of cosines rounds to just above 1.)"""
    first, turn = two_bone_closed_form(upper, lower, 0.0)
    assert abs(first) == pytest.approx(math.pi, abs=1e-7)
    assert turn == pytest.approx(math.pi, abs=1e-7)


@pytest.mark.parametrize("upper, lower", [(0.0, 1.0), (1.0, 0.0), (0.0, 0.0)])
def test_two_bone_closed_form_with_a_zero_length_bone_returns_two_finite_angles(upper, lower):
    """A bone of no length determines no angle; the function must still return its
    documented pair of angles (no division by zero, no NaN)."""
    first, turn = two_bone_closed_form(upper, lower, 0.5)
    assert math.isfinite(first) and math.isfinite(turn)


# ---- surv4: StallCheck's default window is three sweeps


def test_stall_check_default_window_is_three_sweeps():
    # STALL_FRACTION's doc: "Three sweeps or passes that together gain less than three times
    # this fraction of the tolerance end the solve". No gain at all: the third repeat stops it.
    from qtanimator.core.ik_methods import STALL_FRACTION, StallCheck

    check = StallCheck(1.0, 1.0)
    assert check.window == 3
    assert check.limit == pytest.approx(3 * STALL_FRACTION)
    assert [check(1.0) for _ in range(3)] == [False, False, True]
