"""Bounded steps against closed forms (targets mutation-test survivors): the Hermite parent
motion inside the step, the crossing time with a turning parent, the crossing time's
relative precision on short steps, and a joint on its limit moving out bouncing at once."""

from __future__ import annotations

import numpy as np
import pytest

from qtanimator.core.joint_bounce import ON_LIMIT, Bounce, BoundedUnit, StepFunction, bounded_step, hermite


def free_step(alpha: float = 0.0) -> StepFunction:
    """θ(t + h) = θ + ω h + α h²/2, ω + α h: a constant angular acceleration α, exactly."""
    def step(th: np.ndarray, om: np.ndarray, _t: float, h: float) -> tuple[np.ndarray, np.ndarray]:
        return th + h * om + 0.5 * alpha * h * h, om + alpha * h
    return step


def still_parent(_t: float) -> tuple[np.ndarray, np.ndarray]:
    return np.zeros(1), np.zeros(1)


@pytest.mark.parametrize("t", [0.05, 0.2, 0.37, 0.49])
def test_hermite_reproduces_a_cubic_inside_the_step(t: float) -> None:
    """a(t) = 0.3 + 1.2 t − 4 t² + 7 t³ is its own Hermite interpolant over [0, 0.5]."""
    def a(s: float) -> float:
        return 0.3 + 1.2 * s - 4.0 * s ** 2 + 7.0 * s ** 3

    def r(s: float) -> float:
        return 1.2 - 8.0 * s + 21.0 * s ** 2

    f = hermite(np.array([a(0.0)]), np.array([r(0.0)]), np.array([a(0.5)]), np.array([r(0.5)]), 0.5)
    angle, rate = f(t)
    assert float(angle[0]) == pytest.approx(a(t), abs=1e-13)
    assert float(rate[0]) == pytest.approx(r(t), abs=1e-12)


def test_a_turning_parent_brings_the_limit_to_a_still_child() -> None:
    """The parent turns at w = 2 (outside(t) = (2t, 2)), the child is still at 0: its local
    angle −2t reaches lo = −0.3 at t = 0.15. Relative rate −2 becomes +e·2 = 1, so the
    child's own rate is 2 + 1 = 3 from θ = 0 for the remaining 0.25: θ = 0.75."""
    unit = BoundedUnit(np.array([4]), np.array([-0.3]), np.array([0.3]), np.array([-1]),
                       lambda t: (np.array([2.0 * t]), np.array([2.0])))
    bounces: list[Bounce] = []
    th, om = bounded_step(unit, free_step(), np.array([0.0]), np.array([0.0]), 0.4, 0.5, bounces)
    [b] = bounces
    assert b.joint == 4 and b.limit == -0.3
    assert b.time == pytest.approx(0.15, abs=1e-14)
    assert b.rate_before == pytest.approx(-2.0) and b.rate_after == pytest.approx(1.0)
    assert float(om[0]) == pytest.approx(3.0)
    assert float(th[0]) == pytest.approx(0.75, abs=1e-12)


def forced_step(k: float) -> StepFunction:
    """θ'' = k·t³ (a forcing known in time), integrated exactly from t to t + h."""
    def step(th: np.ndarray, om: np.ndarray, t: float, h: float) -> tuple[np.ndarray, np.ndarray]:
        s = t + h
        return (th + om * h + 0.25 * k * ((s ** 5 - t ** 5) / 5.0 - t ** 4 * h),
                om + 0.25 * k * (s ** 4 - t ** 4))
    return step


@pytest.mark.parametrize("tau", [1e-3, 1e-6, 1e-9])
def test_the_crossing_time_is_precise_relative_to_the_step_quadratic(tau: float) -> None:
    """θ = v h + α h²/2 reaches L at h* = 2L / (v + √(v² + 2αL)); the module finds the
    crossing to about 1e-15 of the step, whatever the step's length."""
    v, alpha = 1.0, 3.0e5 / tau
    limit = 0.6 * tau + 0.5 * alpha * (0.6 * tau) ** 2
    h_star = 2.0 * limit / (v + np.sqrt(v * v + 2.0 * alpha * limit))
    unit = BoundedUnit(np.array([0]), np.array([-1.0]), np.array([limit]), np.array([-1]), still_parent)
    bounces: list[Bounce] = []
    bounded_step(unit, free_step(alpha), np.array([0.0]), np.array([v]), tau, 0.5, bounces)
    assert bounces, "the joint crosses its limit within the step"
    assert abs(bounces[0].time - h_star) <= 1e-14 * tau


@pytest.mark.parametrize("tau", [1e-3, 1e-6, 1e-9])
def test_the_crossing_time_is_precise_relative_to_the_step_quintic(tau: float) -> None:
    """From rest with θ'' = k t³: θ = k t⁵ / 20 reaches L = k (0.6 τ)⁵ / 20 at 0.6 τ."""
    k = 1.0 / tau ** 5
    limit = k * (0.6 * tau) ** 5 / 20.0
    h_star = (20.0 * limit / k) ** 0.2
    unit = BoundedUnit(np.array([0]), np.array([-1.0]), np.array([limit]), np.array([-1]), still_parent)
    bounces: list[Bounce] = []
    bounded_step(unit, forced_step(k), np.array([0.0]), np.array([0.0]), tau, 0.5, bounces)
    assert bounces, "the joint crosses its limit within the step"
    assert abs(bounces[0].time - h_star) <= 1e-14 * tau


@pytest.mark.parametrize("side", [1.0, -1.0])
def test_a_joint_on_its_limit_moving_out_bounces_at_once(side: float) -> None:
    """Within ON_LIMIT of the limit counts as on it: a joint that close, moving out however
    slowly, bounces at time 0 (rate 1e-6 becomes −e·1e-6) and spends the whole step going back."""
    lo, hi = -0.5, 0.5
    bound = hi if side > 0 else lo
    theta0 = bound - side * 0.5 * ON_LIMIT
    v = side * 1e-6
    unit = BoundedUnit(np.array([0]), np.array([lo]), np.array([hi]), np.array([-1]), still_parent)
    bounces: list[Bounce] = []
    tau = 0.01
    th, om = bounded_step(unit, free_step(), np.array([theta0]), np.array([v]), tau, 0.5, bounces)
    [b] = bounces
    assert b.time == 0.0 and b.limit == bound
    assert b.rate_before == v and b.rate_after == -0.5 * v
    assert float(om[0]) == pytest.approx(-0.5 * v, rel=1e-12)
    assert float(th[0]) == pytest.approx(bound - 0.5 * v * tau, abs=1e-18)
