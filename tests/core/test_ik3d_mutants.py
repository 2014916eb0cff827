"""3D IK (core/ik3d.py, ik3d_methods.py): one damped least-squares step against its closed
form, starting values passed as an array, and the CCD iteration cap."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.ik3d import chain_dofs, chain_joints, end_position, jacobian, solve_ik
from qtanimator.core.ik3d_methods import solve_ccd
from qtanimator.core.skeleton import Dof, Joint, Skeleton


def arm() -> Skeleton:
    def dofs():
        return (Dof(0, -100000.0, 100000.0), Dof(0, -100000.0, 100000.0), Dof(0, -100000.0, 100000.0))
    return Skeleton([
        Joint("root", None, (0, 0, 0), dofs()),
        Joint("shoulder", 0, (0, 1, 0), dofs()),
        Joint("elbow", 1, (1, 0, 0), dofs()),
        Joint("wrist", 2, (0.8, 0, 0), dofs()),
        Joint("hand", 3, (0.3, 0, 0), dofs()),
    ], rotation_order="zyx")


def test_one_dls_step_is_the_closed_form():
    # Only the shoulder's z DOF: the hand is 2.1 from the shoulder (0, 1, 0) along +x, so at
    # angle 0 the Jacobian column is J = (0, 2.1, 0) and reach = 2.1. For one column the DLS
    # step J^T (J J^T + λ² I)^-1 e is (J·e) / (|J|² + λ²), λ = damping · reach. The goal is
    # the hand turned by 0.3 rad; one step gets most of the way and is kept whole.
    sk = arm()
    r, damping = 2.1, 0.05
    goal = np.array([r * math.cos(0.3), 1.0 + r * math.sin(0.3), 0.0])
    e = goal - np.array([r, 1.0, 0.0])
    step = (r * e[1]) / (r * r + (damping * r) ** 2)
    res = solve_ik(sk, 4, goal, dofs=[(1, 2)], damping=damping, iterations=1, max_step=1.0)
    assert res.iterations == 1
    assert res.values[(1, 2)] == pytest.approx(step, rel=1e-12)
    expected_tip = np.array([r * math.cos(step), 1.0 + r * math.sin(step), 0.0])
    np.testing.assert_allclose(res.position, expected_tip, atol=1e-12)
    assert res.error == pytest.approx(float(np.linalg.norm(goal - expected_tip)), rel=1e-9)


def test_start_values_given_as_an_array_are_used():
    # Starting from values (J, 3) must be the same as starting from a skeleton posed there;
    # the pose is reshaped from any (3J,) layout.
    sk = arm()
    rng = np.random.default_rng(11)
    start = np.zeros((5, 3))
    start[1:4] = rng.uniform(-0.4, 0.4, (3, 3))
    target = np.array([1.2, 1.9, 0.4])
    posed = arm()
    posed.set_dof_values(start)
    expected = solve_ik(posed, 4, target, iterations=5)
    for values in (start, start.reshape(-1), start.tolist()):
        res = solve_ik(sk, 4, target, iterations=5, values=values)
        assert res.values == pytest.approx(expected.values, abs=1e-14)
    # with iterations=0 the effector is where the start values put it
    res0 = solve_ik(sk, 4, target, iterations=0, values=start.reshape(-1))
    np.testing.assert_allclose(res0.position, end_position(sk, start, 4), atol=1e-14)


def test_ccd_stops_after_the_given_number_of_iterations():
    sk = arm()
    target = np.array([0.5, 2.6, 0.7])  # reachable, not in one sweep
    for n in (1, 2):
        res = solve_ccd(sk, 4, target, iterations=n, accelerate=False, tolerance=1e-12)
        assert res.iterations == n
        assert res.error > 1e-12


def test_default_chain_is_the_three_nearest_ancestors():
    """Without ``dofs`` the solver moves the three joints above the end, no more."""
    sk = Skeleton([Joint("root", None, (0, 0, 0))] + [Joint(f"j{i}", i, (1, 0, 0)) for i in range(5)],
                  rotation_order="zyx")
    res = solve_ik(sk, 5, [2.0, 2.5, 0.5], iterations=2)
    assert res.dofs == [(j, a) for j in (4, 3, 2) for a in range(3)]
    assert res.by_axis_name()[(4, "y")] == res.values[(4, 1)]
    assert set(res.by_axis_name()) == {(j, ax) for j in (4, 3, 2) for ax in "xyz"}


def test_chain_dofs_leave_out_pinned_dofs():
    sk = arm()
    sk.joints[2].dofs[1].set_limits(0.2, 0.2)
    sk.joints[3].dofs[0].set_limits(-1e-13, 1e-13)   # pinned within 1e-12
    assert chain_dofs(sk, 4, 2) == [(3, 1), (3, 2), (2, 0), (2, 2)]
    assert chain_dofs(sk, 4, 1, include_root=True) == [(3, 1), (3, 2)]
    assert (0, 0) in chain_dofs(sk, 4, 5, include_root=True)


def test_jacobian_under_placement_root_translation_and_scale():
    """The columns are axis × (end - pivot) with unit world axes, also when the frame above
    is a placement, the root is translated, a parent is scaled, and a joint has its own
    rotation order and a translation; compared with central differences. (A uniform
    scale: under a non-uniform one a turn of the child is not a rotation in world space.)"""
    sk = arm()
    sk.placement = np.array([[0.0, 0.0, 2.0, 1.0], [2.0, 0.0, 0.0, -0.5], [0.0, 2.0, 0.0, 0.3], [0, 0, 0, 1.0]])
    sk.set_root_translation([0.4, -0.2, 0.1])
    sk.joints[1].scale = np.array([2.0, 2.0, 2.0])
    sk.joints[2].rotation_order = "yzx"
    sk.joints[2].translation = np.array([0.1, 0.2, 0.0])
    rng = np.random.default_rng(4)
    values = rng.uniform(-1, 1, (5, 3))
    dofs = [(j, a) for j in (0, 1, 2, 3) for a in range(3)]
    p, jac = jacobian(sk, values, dofs, 4)
    np.testing.assert_allclose(p, end_position(sk, values, 4), atol=1e-14)
    h = 1e-6
    for col, (j, a) in enumerate(dofs):
        plus, minus = values.copy(), values.copy()
        plus[j, a] += h
        minus[j, a] -= h
        numeric = (end_position(sk, plus, 4) - end_position(sk, minus, 4)) / (2 * h)
        np.testing.assert_allclose(jac[:, col], numeric, atol=1e-6)


def test_max_step_caps_one_iteration():
    """One DOF, a target 1 rad round: the DLS step (about 1 rad) is cut to max_step."""
    sk = arm()
    r = 2.1
    goal = np.array([r * math.cos(1.0), 1.0 + r * math.sin(1.0), 0.0])
    res = solve_ik(sk, 4, goal, dofs=[(1, 2)], iterations=1, max_step=0.25)
    assert res.values[(1, 2)] == pytest.approx(0.25, abs=1e-15)
    np.testing.assert_allclose(res.position, [r * math.cos(0.25), 1.0 + r * math.sin(0.25), 0.0], atol=1e-12)
    res = solve_ik(sk, 4, goal, dofs=[(1, 2)], iterations=200, max_step=0.25, tolerance=1e-10)
    assert res.values[(1, 2)] == pytest.approx(1.0, abs=1e-9)
    assert res.iterations > 4


@pytest.mark.parametrize("limits, turn", [((-1.0, 0.0), 0.5), ((0.0, 1.0), -0.5)])
def test_a_dof_at_its_limit_is_locked_and_the_others_take_over(limits, turn):
    """The shoulder's z DOF starts at a limit (0) and the target needs it to turn past it:
    it stays exactly there and the elbow's z DOF turns instead (the full step, not one
    shared with a locked column)."""
    sk = arm()
    sk.joints[1].dofs[2].set_limits(*limits)
    # elbow at (1, 1, 0), hand 1.1 beyond it along x; target: the hand turned about the elbow
    goal = np.array([1.0 + 1.1 * math.cos(turn), 1.0 + 1.1 * math.sin(turn), 0.0])
    res = solve_ik(sk, 4, goal, dofs=[(1, 2), (2, 2)], iterations=100, tolerance=1e-10)
    assert limits[0] <= res.values[(1, 2)] <= limits[1]
    assert abs(res.values[(1, 2)]) <= 1e-6
    assert res.values[(2, 2)] == pytest.approx(turn, abs=1e-5)
    assert res.error < 1e-9
    # one iteration: the elbow's step is the one-column DLS step (J·e) / (|J|² + λ²), as
    # if the shoulder were not there; reach λ/damping = 2.1 (shoulder to hand)
    one = solve_ik(sk, 4, goal, dofs=[(1, 2), (2, 2)], iterations=1, max_step=10.0)
    jcol = np.array([0.0, 1.1, 0.0])
    e = goal - np.array([2.1, 1.0, 0.0])
    lam2 = (0.05 * 2.1) ** 2
    assert one.values[(2, 2)] == pytest.approx(float(jcol @ e) / (1.1 ** 2 + lam2), rel=1e-12)
    assert one.values[(1, 2)] == 0.0


def test_an_overshooting_step_is_halved_once():
    """One DOF (shoulder z, the hand r = 2.1 out along x) and a target 3r straight up from
    the hand: the DLS step (J·e) / (|J|² + λ²) = 3r² / (r² (1 + 0.05²)) ≈ 2.99 rad swings
    the hand past the target (error 3.47r > 3r); half of it (≈ 1.5 rad, error ≈ 2.2r) is
    taken instead."""
    sk = arm()
    r = 2.1
    goal = np.array([r, 1.0 + 3.0 * r, 0.0])
    step = 3.0 / (1.0 + 0.05 ** 2)
    full = np.array([r * math.cos(step), 1.0 + r * math.sin(step), 0.0])
    assert np.linalg.norm(goal - full) > 3.0 * r
    res = solve_ik(sk, 4, goal, dofs=[(1, 2)], iterations=1, max_step=10.0)
    assert res.values[(1, 2)] == pytest.approx(step / 2, rel=1e-12)
    np.testing.assert_allclose(res.position, [r * math.cos(step / 2), 1.0 + r * math.sin(step / 2), 0.0],
                               atol=1e-12)
    assert res.iterations == 1


@pytest.mark.parametrize("limits, turn", [((0.0, 1.0), 0.5), ((-1.0, 0.0), -0.5)])
def test_a_dof_at_its_limit_moves_away_from_it_freely(limits, turn):
    """At a limit but stepping back inside: not locked, the DOF takes its share of the
    step (one iteration: the full two-column DLS step, clipped to nothing)."""
    sk = arm()
    sk.joints[1].dofs[2].set_limits(*limits)
    goal = np.array([1.0 + 1.1 * math.cos(turn), 1.0 + 1.1 * math.sin(turn), 0.0])
    one = solve_ik(sk, 4, goal, dofs=[(1, 2), (2, 2)], iterations=1, max_step=10.0)
    # columns: shoulder z about (0, 1, 0): z × (2.1, 0, 0) = (0, 2.1, 0); elbow z about
    # (1, 1, 0): (0, 1.1, 0). dq = Jᵀ (J Jᵀ + λ² I)⁻¹ e, λ = 0.05 · 2.1
    jac = np.array([[0.0, 0.0], [2.1, 1.1], [0.0, 0.0]])
    e = goal - np.array([2.1, 1.0, 0.0])
    dq = jac.T @ np.linalg.solve(jac @ jac.T + (0.05 * 2.1) ** 2 * np.eye(3), e)
    assert np.sign(dq[0]) == np.sign(turn)
    assert [one.values[(1, 2)], one.values[(2, 2)]] == pytest.approx(dq.tolist(), rel=1e-12)


def test_chain_joints_default_length_is_three():
    sk = Skeleton([Joint("root", None, (0, 0, 0))] + [Joint(f"j{i}", i, (1, 0, 0)) for i in range(5)],
                  rotation_order="zyx")
    assert chain_joints(sk, 5) == [4, 3, 2]
    assert chain_dofs(sk, 5) == [(j, a) for j in (4, 3, 2) for a in range(3)]
    assert chain_joints(sk, 5, include_root=True) == [4, 3, 2]
    assert chain_joints(sk, 3, 10, include_root=True) == [2, 1, 0]


def test_iterations_count_the_steps_taken():
    """A solve that reaches the tolerance after k steps reports k: with k - 1 allowed
    steps it is not there yet, with k it is, and more allowed steps change nothing."""
    sk = arm()
    target = np.array([0.9, 2.2, 0.6])
    res = solve_ik(sk, 4, target, iterations=100, tolerance=1e-6)
    k = res.iterations
    assert 1 < k < 100 and res.error < 1e-6
    assert solve_ik(sk, 4, target, iterations=k - 1, tolerance=1e-6).error >= 1e-6
    exact = solve_ik(sk, 4, target, iterations=k, tolerance=1e-6)
    assert exact.iterations == k and exact.values == res.values
