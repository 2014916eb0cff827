"""Damped least-squares IK on 3D skeletons (Qt-free)."""

from __future__ import annotations

import numpy as np
import pytest

from qtanimator.core.ik3d import chain_dofs, chain_joints, end_position, jacobian, solve_ik
from qtanimator.core.skeleton import Dof, Joint, Skeleton


def arm(order: str = "zyx", limits: tuple[float, float] = (-100000.0, 100000.0)) -> Skeleton:
    def dofs():
        return (Dof(0, *limits), Dof(0, *limits), Dof(0, *limits))
    return Skeleton([
        Joint("root", None, (0, 0, 0), dofs()),
        Joint("shoulder", 0, (0, 1, 0), dofs()),
        Joint("elbow", 1, (1, 0, 0), dofs()),
        Joint("wrist", 2, (0.8, 0, 0), dofs()),
        Joint("hand", 3, (0.3, 0, 0), dofs()),
    ], rotation_order=order)


@pytest.mark.parametrize("order", ["zyx", "xyz", "yxz"])
def test_analytic_jacobian_matches_finite_differences(order):
    sk = arm(order)
    rng = np.random.default_rng(3)
    values = rng.uniform(-1, 1, (5, 3))
    dofs = chain_dofs(sk, 4, chain_length=3)
    p, jac = jacobian(sk, values, dofs, 4)
    h = 1e-6
    for col, (j, a) in enumerate(dofs):
        plus, minus = values.copy(), values.copy()
        plus[j, a] += h
        minus[j, a] -= h
        numeric = (end_position(sk, plus, 4) - end_position(sk, minus, 4)) / (2 * h)
        np.testing.assert_allclose(jac[:, col], numeric, atol=1e-6)
    np.testing.assert_allclose(p, end_position(sk, values, 4))


def test_chain_starts_at_the_parent_and_leaves_the_root_out():
    sk = arm()
    assert chain_joints(sk, 4, 3) == [3, 2, 1]
    assert chain_joints(sk, 4, 10) == [3, 2, 1]
    assert chain_joints(sk, 4, 10, include_root=True) == [3, 2, 1, 0]
    assert chain_joints(sk, 1, 3) == []


@pytest.mark.parametrize("order", ["zyx", "xyz"])
def test_reaches_a_reachable_target_and_leaves_the_skeleton_alone(order):
    sk = arm(order)
    rng = np.random.default_rng(7)
    goal_pose = np.zeros((5, 3))
    goal_pose[1:4] = rng.uniform(-0.6, 0.6, (3, 3))
    target = end_position(sk, goal_pose, 4)
    before = sk.dof_values().copy()
    res = solve_ik(sk, 4, target, chain_length=3, iterations=100)
    assert res.error < 1e-3
    np.testing.assert_array_equal(sk.dof_values(), before)
    v = sk.dof_values()
    for (j, a), x in res.values.items():
        v[j, a] = x
    np.testing.assert_allclose(end_position(sk, v, 4), target, atol=1e-3)


def test_unreachable_target_stretches_towards_it_without_blowing_up():
    sk = arm()
    res = solve_ik(sk, 4, [10.0, 1.0, 0.0], iterations=60)
    assert np.all(np.isfinite(list(res.values.values())))
    # the arm points straight at the target: distance = 10 - 1 - 0.8 - 0.3
    assert res.error == pytest.approx(10.0 - 2.1, abs=0.05)


def test_limits_are_respected_and_other_joints_make_up_for_a_locked_one():
    sk = arm(limits=(-0.3, 0.3))
    target = end_position(sk, np.array([[0, 0, 0], [0, 0, 0.25], [0, 0, 0.25], [0, 0, 0.25], [0, 0, 0]]), 4)
    far = target + np.array([0.0, 0.5, 0.0])   # needs more than the limits allow
    res = solve_ik(sk, 4, far, iterations=80)
    for x in res.values.values():
        assert -0.3 - 1e-12 <= x <= 0.3 + 1e-12
    start_err = float(np.linalg.norm(end_position(sk, sk.dof_values(), 4) - far))
    assert res.error < start_err
    # pinned DOFs (min == max) are never part of the chain
    sk.joints[2].dofs[2].set_limits(0.1, 0.1)
    assert (2, 2) not in chain_dofs(sk, 4)
