"""Spring joints against a test-written integrator and closed forms (targets mutation-test
survivors): the pivot-acceleration forcing of a spring root joint, and the shown (mixed)
angle the springs hand to their children."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.mass import MassProperties
from qtanimator.core.rig2d import Character, Joint, rotation
from qtanimator.core.spring_joint import SpringParams, SpringSystem

TAU = 1.0 / 600.0
MASS, INERTIA, Y0 = 2.0, 40.0, np.array([3.0, 4.0])


def spring_root(pivot: tuple[float, float] = (7.0, -2.0)) -> Character:
    c = np.asarray(pivot, dtype=np.float64)
    mp = MassProperties(MASS, c + Y0, INERTIA, c)
    return Character("s", [Joint("s", None, c, is_spring=True, mass_properties=mp)])


def reference_theta(k: float, c: float, beta: float, u: float, theta0: float, acc: np.ndarray,
                    t_end: float, h: float = 1e-4) -> float:
    """RK4 of the rigid body on a rotational spring whose pivot accelerates by ``acc``.

    The pivot frame's pseudo-force −m·a acts at the centre of mass r(θ) = R(θ)·y0, whose
    generalised force on θ is −m·a·∂r/∂θ, ∂r/∂θ = R(θ + π/2)·y0 (d/dθ of the rotation):
    θ'' = k(u − θ) − cθ' − β·(m/I)·a·∂r/∂θ."""
    def f(th: float, om: float) -> float:
        dr = rotation(th + math.pi / 2) @ Y0
        return k * (u - th) - c * om - beta * MASS / INERTIA * float(acc @ dr)

    th, om = theta0, 0.0
    for _ in range(int(round(t_end / h))):
        k1t, k1w = om, f(th, om)
        k2t, k2w = om + 0.5 * h * k1w, f(th + 0.5 * h * k1t, om + 0.5 * h * k1w)
        k3t, k3w = om + 0.5 * h * k2w, f(th + 0.5 * h * k2t, om + 0.5 * h * k2w)
        k4t, k4w = om + h * k3w, f(th + h * k3t, om + h * k3w)
        th += h * (k1t + 2 * k2t + 2 * k3t + k4t) / 6.0
        om += h * (k1w + 2 * k2w + 2 * k3w + k4w) / 6.0
    return th


@pytest.mark.parametrize("acc", [(30.0, -20.0), (-15.0, 0.0), (0.0, 25.0)])
def test_a_spring_root_follows_the_pivot_acceleration_equation(acc: tuple[float, float]) -> None:
    k, c, beta, u = 50.0, 2.0, 0.8, 0.3
    a = np.array(acc)
    system = SpringSystem(spring_root(), SpringParams(stiffness=k, damping=c, inertia=beta, mix=1.0))
    theta, omega = np.array([0.9]), np.zeros(1)
    steps = 300
    for _ in range(steps):
        system.step(theta, omega, TAU, np.array([u]), np.zeros(1), np.zeros(1), np.zeros(1), np.zeros(1), a.copy())
    expected = reference_theta(k, c, beta, u, 0.9, a, steps * TAU)
    # The system holds the forcing at its sub-step-start value: first order in the step.
    assert float(theta[0]) == pytest.approx(expected, abs=1e-3)
    # and the forcing matters here: without it the angle would be elsewhere
    assert abs(reference_theta(k, c, 0.0, u, 0.9, a, steps * TAU) - expected) > 0.05


@pytest.mark.parametrize("mix", [1.0, 0.4, 0.0])
def test_the_shown_angle_mixes_keys_and_spring_at_mid_step(mix: float) -> None:
    """No forcing, constant key u: d = θ − u is the damped oscillator
    d(t) = d0·e^(−σt)(cos ω_d t + σ/ω_d sin ω_d t); the children see (1 − mix)·u + mix·θ
    at the sub-step's middle, the mean of its ends."""
    k, c, u, d0 = 120.0, 8.0, 0.25, 0.5
    system = SpringSystem(spring_root(), SpringParams(stiffness=k, damping=c, inertia=0.0, mix=mix))
    theta, omega = np.array([u + d0]), np.zeros(1)
    key, rate = np.array([u]), np.zeros(1)
    system.step(theta, omega, TAU, key, rate, np.zeros(1), np.zeros(1), np.zeros(1), np.zeros(2))
    sigma = c / 2.0
    wd = math.sqrt(k - sigma ** 2)
    d1 = d0 * math.exp(-sigma * TAU) * (math.cos(wd * TAU) + sigma / wd * math.sin(wd * TAU))
    w1 = -d0 * math.exp(-sigma * TAU) * (k / wd) * math.sin(wd * TAU)
    assert float(theta[0]) == pytest.approx(u + d1, abs=1e-12)
    assert float(omega[0]) == pytest.approx(w1, abs=1e-10)
    assert float(key[0]) == pytest.approx((1 - mix) * u + mix * (u + 0.5 * (d0 + d1)), abs=1e-12)
    assert float(rate[0]) == pytest.approx(mix * 0.5 * w1, abs=1e-10)


def test_a_spring_at_rest_shows_its_keys() -> None:
    system = SpringSystem(spring_root(), SpringParams(mix=1.0))
    theta, omega, key = np.array([0.3]), np.zeros(1), np.array([0.3])
    system.step(theta, omega, TAU, key, np.zeros(1), np.zeros(1), np.zeros(1), np.zeros(1), np.zeros(2))
    assert float(key[0]) == 0.3 and float(theta[0]) == 0.3
