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


def two_member_unit(lo: float = -0.5, hi: float = 0.5) -> BoundedUnit:
    """Members at positions 0 and 1; member 1 hangs from member 0, member 0 from an outside
    parent at angle 0.25 + 2t turning at 2."""
    return BoundedUnit(np.array([3, 7]), np.array([lo, lo]), np.array([hi, hi]), np.array([-1, 0]),
                       lambda t: (np.array([0.25 + 2.0 * t, 99.0]), np.array([2.0, 99.0])))


def test_local_angles_and_parent_states_inside_and_outside_the_unit() -> None:
    """Member 0's parent is outside (its entry of outside(t)); member 1's is member 0 (the
    entries of outside(t) for members with an inside parent are ignored)."""
    unit = two_member_unit()
    theta, omega = np.array([0.5, 1.25]), np.array([3.0, -4.0])
    np.testing.assert_allclose(unit.local(theta, 0.1), [0.5 - 0.45, 1.25 - 0.5], atol=1e-15)
    assert unit.parent_state(theta, omega, 0, 0.1) == pytest.approx((0.45, 2.0), abs=1e-15)
    assert unit.parent_state(theta, omega, 1, 0.1) == (0.5, 3.0)


def test_a_child_bounces_off_its_parent_inside_the_unit() -> None:
    """Independent members (no mass matrix): member 0 turns at 2 with its outside parent (local
    0 throughout), member 1 is still at 0.25: its local angle 0.25 − (0.25 + 2t) = −2t reaches
    lo = −0.3 at t = 0.15, relative rate −2 becomes +1: member 1's own rate 2 + 1 = 3 from
    0.25 for the remaining 0.25: 1.0."""
    unit = two_member_unit(-0.3, 0.3)
    bounces: list[Bounce] = []
    th, om = bounded_step(unit, free_step(), np.array([0.25, 0.25]), np.array([2.0, 0.0]), 0.4, 0.5, bounces)
    [b] = bounces
    assert b.joint == 7 and b.limit == -0.3
    assert b.time == pytest.approx(0.15, abs=1e-14)
    assert b.rate_before == pytest.approx(-2.0) and b.rate_after == pytest.approx(1.0)
    np.testing.assert_allclose(om, [2.0, 3.0], rtol=1e-13)
    np.testing.assert_allclose(th, [0.25 + 0.8, 1.0], atol=1e-12)


def test_eight_elastic_bounces_in_one_step_follow_the_triangle_wave() -> None:
    """e = 1 between ±0.1 at speed 10: the angle is a triangle wave of period 0.04 s,
    bounces at 0.01 + 0.02 k alternately on hi and lo. A step of 0.16 s holds exactly
    MAX_EVENTS = 8 of them and then 0.01 s of free motion: back at 0 moving at +10."""
    unit = BoundedUnit(np.array([0]), np.array([-0.1]), np.array([0.1]), np.array([-1]), still_parent)
    bounces: list[Bounce] = []
    th, om = bounded_step(unit, free_step(), np.array([0.0]), np.array([10.0]), 0.16, 1.0, bounces)
    assert len(bounces) == 8
    for k, b in enumerate(bounces):
        assert b.time == pytest.approx(0.01 + 0.02 * k, abs=1e-12)
        assert b.limit == (0.1 if k % 2 == 0 else -0.1)
        assert b.rate_before == pytest.approx(10.0 if k % 2 == 0 else -10.0, rel=1e-12)
        assert b.rate_after == pytest.approx(-b.rate_before, rel=1e-12)
    assert float(th[0]) == pytest.approx(0.0, abs=1e-12)
    assert float(om[0]) == pytest.approx(10.0, rel=1e-12)


def test_the_crossing_is_found_in_few_evaluations() -> None:
    """Illinois regula falsi converges superlinearly: a smooth crossing to ~1e-15 of the step
    takes far fewer step evaluations than bisection's ~50 halvings."""
    calls = [0]
    base = free_step(3.0)

    def counted(th: np.ndarray, om: np.ndarray, t: float, h: float) -> tuple[np.ndarray, np.ndarray]:
        calls[0] += 1
        return base(th, om, t, h)

    unit = BoundedUnit(np.array([0]), np.array([-1.0]), np.array([0.3]), np.array([-1]), still_parent)
    bounces: list[Bounce] = []
    bounded_step(unit, counted, np.array([0.0]), np.array([1.0]), 0.5, 0.5, bounces)
    h_star = 2.0 * 0.3 / (1.0 + np.sqrt(1.0 + 2.0 * 3.0 * 0.3))  # v h + α h²/2 = 0.3
    assert bounces[0].time == pytest.approx(h_star, abs=1e-14)
    assert calls[0] < 35


def test_a_coupled_bounce_acts_through_the_mass_matrix() -> None:
    """Member 1 (parent member 0) reaches hi = 0.3 relative to it at t = 0.1 (rates 0 and 3).
    The stop's impulse is λ·Jᵀ with J = (−1, 1): M·Δω ∥ (−1, 1), and the relative rate
    becomes −e·3 = −1.5; then free motion for the remaining 0.1 s."""
    mass = np.array([[3.0, 1.0], [1.0, 2.0]])
    unit = BoundedUnit(np.array([0, 1]), np.array([-5.0, -5.0]), np.array([5.0, 0.3]), np.array([-1, 0]),
                       lambda t: (np.zeros(2), np.zeros(2)), lambda _th: mass)
    bounces: list[Bounce] = []
    th, om = bounded_step(unit, free_step(), np.zeros(2), np.array([0.0, 3.0]), 0.2, 0.5, bounces)
    [b] = bounces
    assert b.joint == 1 and b.time == pytest.approx(0.1, abs=1e-14)
    assert b.rate_before == pytest.approx(3.0) and b.rate_after == pytest.approx(-1.5)
    assert float(om[1] - om[0]) == pytest.approx(-1.5, rel=1e-12)
    impulse = mass @ (om - np.array([0.0, 3.0]))
    assert float(impulse[0]) == pytest.approx(-float(impulse[1]), rel=1e-12)
    assert abs(float(om[0])) > 0.1  # the parent member recoils
    np.testing.assert_allclose(th, [0.1 * om[0], 0.3 + 0.1 * om[1]], atol=1e-13)


def test_a_crossing_on_a_sample_point_is_found_exactly() -> None:
    """θ = t (no acceleration) and hi = 0.25 over a step of 1: the crossing sits exactly on
    the second of the eight samples (g(0.25) = 0, every number exact in binary), so the root
    finder starts from a bracket whose left end is the root itself. The bounce is at 0.25,
    rate 1 → −e = −0.5, then θ = 0.25 − 0.5 · 0.75 = −0.125."""
    unit = BoundedUnit(np.array([0]), np.array([-1.0]), np.array([0.25]), np.array([-1]), still_parent)
    bounces: list[Bounce] = []
    th, om = bounded_step(unit, free_step(), np.array([0.0]), np.array([1.0]), 1.0, 0.5, bounces)
    [b] = bounces
    assert b.time == pytest.approx(0.25, abs=1e-15) and b.limit == 0.25
    assert b.rate_before == 1.0 and b.rate_after == -0.5
    assert float(om[0]) == -0.5
    assert float(th[0]) == pytest.approx(-0.125, abs=1e-15)


def test_a_step_ending_exactly_on_the_limit_has_not_left_it() -> None:
    """The local angle must stay in the closed interval [lo, hi]: θ = t over a step of 0.25
    ends exactly on hi = 0.25 (exact in binary), inside, so the step is not cut and keeps
    rate 1. The next step starts on the limit moving out: it bounces at once (time 0),
    rate 1 → −0.5, and ends at 0.25 − 0.5 · 0.25 = 0.125."""
    unit = BoundedUnit(np.array([0]), np.array([-1.0]), np.array([0.25]), np.array([-1]), still_parent)
    bounces: list[Bounce] = []
    th, om = bounded_step(unit, free_step(), np.array([0.0]), np.array([1.0]), 0.25, 0.5, bounces)
    assert not bounces
    assert float(th[0]) == 0.25 and float(om[0]) == 1.0
    th, om = bounded_step(unit, free_step(), th, om, 0.25, 0.5, bounces)
    [b] = bounces
    assert b.time == 0.0 and b.rate_before == 1.0 and b.rate_after == -0.5
    assert float(om[0]) == -0.5
    assert float(th[0]) == pytest.approx(0.125, abs=1e-15)


def test_a_concave_crossing_is_found_in_few_evaluations() -> None:
    """The Illinois rule for the other side: a decelerating joint (g concave, the bracket's
    right end moves every time) also converges superlinearly, far below bisection's ~50."""
    calls = [0]
    base = free_step(-3.0)

    def counted(th: np.ndarray, om: np.ndarray, t: float, h: float) -> tuple[np.ndarray, np.ndarray]:
        calls[0] += 1
        return base(th, om, t, h)

    unit = BoundedUnit(np.array([0]), np.array([-1.0]), np.array([0.1]), np.array([-1]), still_parent)
    bounces: list[Bounce] = []
    bounded_step(unit, counted, np.array([0.0]), np.array([1.0]), 0.3, 0.5, bounces)
    h_star = 0.2 / (1.0 + np.sqrt(1.0 - 2.0 * 3.0 * 0.1))  # v h − α h²/2 = 0.1
    assert bounces[0].time == pytest.approx(h_star, abs=1e-15)
    assert calls[0] < 35


def test_a_joint_on_its_limit_moving_in_and_pushed_back_out() -> None:
    """On hi = 0 at the start moving in at −1, pushed out by α = 4: θ = −h + 2h² is back on the
    limit at h = 1/2 (a sample point, every number exact in binary; not at h = 0) with rate
    −1 + 4·½ = 1 → −e = −0.5; then θ = −0.5 s + 2 s² is on it again at s = 1/4 (t = 3/4) with
    rate 0.5 → −0.25 (each crossing to ~1e-15 of what is left of the step). No bounce is
    before its predecessor or outside the step."""
    unit = BoundedUnit(np.array([0]), np.array([-1.0]), np.array([0.0]), np.array([-1]), still_parent)
    bounces: list[Bounce] = []
    bounded_step(unit, free_step(4.0), np.array([0.0]), np.array([-1.0]), 1.0, 0.5, bounces)
    assert len(bounces) >= 2
    assert bounces[0].time == pytest.approx(0.5, abs=1e-14)
    assert bounces[0].rate_before == pytest.approx(1.0, rel=1e-13)
    assert bounces[0].rate_after == pytest.approx(-0.5, rel=1e-13)
    assert bounces[1].time == pytest.approx(0.75, abs=1e-14)
    assert bounces[1].rate_before == pytest.approx(0.5, rel=1e-13)
    times = [b.time for b in bounces]
    assert times == sorted(times) and 0.0 < times[0] and times[-1] <= 1.0
