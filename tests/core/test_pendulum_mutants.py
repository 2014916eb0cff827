"""A limited pendulum stepped with a pivot acceleration given as a function (the form the
simulation cache passes) against one hand-written symplectic Euler step of the equation of
motion (targets a mutation-test survivor in the bounded step's callable path)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.mass import MassProperties
from qtanimator.core.pendulum import PendulumParams, PendulumSystem
from qtanimator.core.rig2d import Character, Joint, rotation

MASS, INERTIA, Y0 = 2.0, 5000.0, np.array([3.0, 40.0])


def base_and_bob() -> Character:
    pivot = np.array([0.0, 10.0])
    mp = MassProperties(MASS, pivot + Y0, INERTIA, pivot)
    return Character("c", [Joint("base", None, np.zeros(2)),
                           Joint("bob", 0, pivot, is_dynamic=True, mass_properties=mp)])


def expected_step(theta: float, omega: float, acc: np.ndarray, g: float, damping: float,
                  tau: float) -> tuple[float, float]:
    """I θ'' = m (g_vec − a)·∂r/∂θ, r = R(θ) y0, ∂r/∂θ = R(θ + π/2) y0, g_vec = (0, g)
    (y down; the pivot frame's pseudo-force −m a); symplectic Euler, then e^(−aτ)."""
    dr = rotation(theta + math.pi / 2) @ Y0
    acc_theta = MASS * float((np.array([0.0, g]) - acc) @ dr) / INERTIA
    w = omega + tau * acc_theta
    return theta + tau * w, w * math.exp(-damping * tau)


@pytest.mark.parametrize("limits", [None, [None, (-3.0, 3.0)], [None, (-0.5, 0.5)]])
@pytest.mark.parametrize("as_function", [True, False])
def test_a_pendulum_step_with_a_moving_pivot(limits: list[tuple[float, float] | None] | None,
                                             as_function: bool) -> None:
    params = PendulumParams(g=1000.0, damping=0.3, integrator="symplectic_euler")
    system = PendulumSystem(base_and_bob(), params, limits)
    acc = np.array([40.0, -25.0])
    theta, omega = np.array([0.0, 0.2]), np.array([0.0, 0.5])
    table = np.array([[0.0, 0.0], acc])
    pivot_acc = (lambda j: table[j]) if as_function else table
    tau = 1.0 / 600.0
    system.step(theta, omega, pivot_acc, tau)
    th, om = expected_step(0.2, 0.5, acc, 1000.0, 0.3, tau)
    assert float(theta[1]) == pytest.approx(th, abs=1e-13)
    assert float(omega[1]) == pytest.approx(om, abs=1e-12)
    assert not system.bounces
