"""3D IK (core/ik3d.py, ik3d_methods.py): one damped least-squares step against its closed
form, starting values passed as an array, and the CCD iteration cap."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.ik3d import end_position, solve_ik
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
