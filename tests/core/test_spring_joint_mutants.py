"""Spring joints against a test-written integrator and closed forms (targets mutation-test
survivors): the pivot-acceleration forcing of a spring root joint, and the shown (mixed)
angle the springs hand to their children."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.mass import MassProperties
from qtanimator.core.rig2d import Character, Joint, rotation
from qtanimator.core.spring_joint import SPRING_PRESETS, SpringParams, SpringSystem, expm, propagator

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


# ----------------------------------------------------------------------------------------
# A spring joint under a turning keyed parent, validation, presets and the propagator.
CHILD_PIVOT = np.array([10.0, 4.0])


def spring_child() -> Character:
    """A keyed root at (2, 1) with a spring child at (10, 4), centre of mass y0 from its pivot."""
    mp = MassProperties(MASS, CHILD_PIVOT + Y0, INERTIA, CHILD_PIVOT)
    return Character("s", [Joint("root", None, np.array([2.0, 1.0])),
                           Joint("s", 0, CHILD_PIVOT, is_spring=True, mass_properties=mp)])


def damped_closed_form(k: float, c: float, d0: float, force: float, t: float) -> tuple[float, float]:
    """d'' + c d' + k d = F, d(0) = d0, d'(0) = 0 (underdamped): d = F/k + (d0 − F/k)·
    e^(−σt)(cos ω_d t + σ/ω_d sin ω_d t), d' = −(d0 − F/k)·e^(−σt)·(k/ω_d) sin ω_d t."""
    sigma = c / 2.0
    wd = math.sqrt(k - sigma * sigma)
    amp = d0 - force / k
    d = force / k + amp * math.exp(-sigma * t) * (math.cos(wd * t) + sigma / wd * math.sin(wd * t))
    dd = -amp * math.exp(-sigma * t) * (k / wd) * math.sin(wd * t)
    return d, dd


@pytest.mark.parametrize(("parent_angle", "parent_rate", "parent_acc"), [(0.4, 3.0, 0.0), (-1.0, 0.0, 20.0),
                                                                        (2.0, -5.0, -8.0)])
def test_a_turning_parent_drives_its_spring_child(parent_angle: float, parent_rate: float, parent_acc: float) -> None:
    """θ'' = k(u − θ) − cθ' − β(Θ_p'' + (m/I)⟨a, ∂r/∂φ⟩): the child's pivot, v = (8, 3) from
    the parent's, moves with a = Θ_p''·R(Θ_p + π/2)·v − Θ_p'²·R(Θ_p)·v (the second derivative
    of R(Θ_p)·v), r = R(φ)·y0 with φ = Θ_p + θ. The forcing is held for the step (its start
    value), so one step is the closed form of the damped spring with a constant force."""
    k, c, beta, u, theta0 = 90.0, 3.0, 0.7, 0.1, 0.35
    v = CHILD_PIVOT - np.array([2.0, 1.0])
    a = parent_acc * (rotation(parent_angle + math.pi / 2) @ v) - parent_rate ** 2 * (rotation(parent_angle) @ v)
    dr = rotation(parent_angle + theta0 + math.pi / 2) @ Y0
    force = -beta * (parent_acc + MASS / INERTIA * float(a @ dr))
    system = SpringSystem(spring_child(), SpringParams(stiffness=k, damping=c, inertia=beta, mix=1.0))
    theta, omega = np.array([0.0, theta0]), np.zeros(2)
    key = np.array([parent_angle, u])
    system.step(theta, omega, TAU, key, np.array([parent_rate, 0.0]), np.array([parent_acc, 0.0]),
                np.zeros(2), np.zeros(2), np.zeros(2))
    d, dd = damped_closed_form(k, c, theta0 - u, force, TAU)
    assert float(theta[1]) == pytest.approx(u + d, abs=1e-12)
    assert float(omega[1]) == pytest.approx(dd, rel=1e-9, abs=1e-12)
    assert abs(force) > 1.0  # the forcing is not negligible here
    assert theta[0] == 0.0 and key[0] == parent_angle  # the keyed root is not a spring


def test_the_translation_drives_a_spring_child_too() -> None:
    """With a still parent the pivot's acceleration is the body's: a = translation_acc."""
    k, c, beta, u, theta0 = 60.0, 2.0, 1.0, 0.0, -0.2
    acc = np.array([-40.0, 25.0])
    dr = rotation(0.5 + theta0 + math.pi / 2) @ Y0
    force = -beta * MASS / INERTIA * float(acc @ dr)
    system = SpringSystem(spring_child(), SpringParams(stiffness=k, damping=c, inertia=beta, mix=1.0))
    theta, omega = np.array([0.0, theta0]), np.zeros(2)
    system.step(theta, omega, TAU, np.array([0.5, u]), np.zeros(2), np.zeros(2), np.zeros(2), np.zeros(2), acc)
    d, dd = damped_closed_form(k, c, theta0 - u, force, TAU)
    assert float(theta[1]) == pytest.approx(u + d, abs=1e-12)
    assert float(omega[1]) == pytest.approx(dd, rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("acc", [(30.0, -20.0), (0.0, 25.0)])
def test_a_spring_root_step_is_the_closed_form(acc: tuple[float, float]) -> None:
    """A spring root: a = the translation, φ = θ; one step against the closed form."""
    k, c, beta, u, theta0 = 50.0, 2.0, 0.8, 0.3, 0.9
    a = np.array(acc)
    dr = rotation(theta0 + math.pi / 2) @ Y0
    force = -beta * MASS / INERTIA * float(a @ dr)
    system = SpringSystem(spring_root(), SpringParams(stiffness=k, damping=c, inertia=beta, mix=1.0))
    theta, omega = np.array([theta0]), np.zeros(1)
    system.step(theta, omega, TAU, np.array([u]), np.zeros(1), np.zeros(1), np.zeros(1), np.zeros(1), a)
    d, dd = damped_closed_form(k, c, theta0 - u, force, TAU)
    assert float(theta[0]) == pytest.approx(u + d, abs=1e-12)
    assert float(omega[0]) == pytest.approx(dd, rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("value", [0.0, 0.5, 1.0])
def test_inertia_and_mix_from_zero_to_one_are_accepted(value: float) -> None:
    p = SpringParams(inertia=value, mix=value)
    assert p.inertia == value and p.mix == value


@pytest.mark.parametrize(("name", "value"), [("inertia", 1.5), ("inertia", 1.01), ("inertia", -0.1),
                                             ("mix", 1.5), ("mix", -0.01), ("stiffness", -1.0),
                                             ("damping", -0.5), ("stiffness", math.inf), ("damping", math.nan),
                                             ("mix", math.nan), ("inertia", math.inf)])
def test_out_of_range_spring_constants_are_refused(name: str, value: float) -> None:
    """inertia β and mix are 0 … 1 (SpringParams' docstring); k, c ≥ 0 and finite."""
    with pytest.raises(ValueError, match=name):
        SpringParams(**{name: value})


def test_zero_stiffness_and_damping_are_accepted() -> None:
    p = SpringParams(stiffness=0.0, damping=0.0)
    assert p.stiffness == 0.0 and p.damping == 0.0


def test_spring_dict_round_trip_ignores_unknown_keys() -> None:
    p = SpringParams(stiffness=10.0, damping=1.0, mix=0.25, inertia=0.75)
    assert SpringParams.from_dict(p.to_dict()) == p
    assert SpringParams.from_dict({"stiffness": 5.0, "colour": 3}) == SpringParams(stiffness=5.0)


def test_the_presets_have_their_documented_frequencies() -> None:
    """``soft``: about 1.7 Hz, damping ratio 0.37; ``stiff``: about 5 Hz, ratio 0.63; both
    inertia 0.5, mix 1 (the comment above SPRING_PRESETS; f = √k / 2π, ζ = c / 2√k)."""
    for name, hz, zeta in (("soft", 1.7, 0.37), ("stiff", 5.0, 0.63)):
        p = SPRING_PRESETS[name]
        assert math.sqrt(p.stiffness) / (2 * math.pi) == pytest.approx(hz, abs=0.05)
        assert p.damping / (2 * math.sqrt(p.stiffness)) == pytest.approx(zeta, abs=0.005)
        assert p.inertia == 0.5 and p.mix == 1.0
    assert SPRING_PRESETS["soft"] == SpringParams()


@pytest.mark.parametrize(("k", "c", "h"), [(120.0, 8.0, 1.0 / 600.0), (1000.0, 40.0, 0.05), (4.0, 1.0, 3.0)])
def test_the_propagator_is_the_exact_solution(k: float, c: float, h: float) -> None:
    """Column by column: (d, d', F) = (1, 0, 0) and (0, 0, F) from the closed form; (0, 1, 0)
    from d = e^(−σt) sin(ω_d t) / ω_d."""
    e = propagator(k, c, h)
    d, dd = damped_closed_form(k, c, 1.0, 0.0, h)
    np.testing.assert_allclose(e[:2, 0], [d, dd], rtol=1e-10, atol=1e-13)
    d, dd = damped_closed_form(k, c, 0.0, 2.0, h)
    np.testing.assert_allclose(e[:2, 2] * 2.0, [d, dd], rtol=1e-10, atol=1e-13)
    sigma = c / 2.0
    wd = math.sqrt(k - sigma * sigma)
    d = math.exp(-sigma * h) * math.sin(wd * h) / wd
    dd = math.exp(-sigma * h) * (math.cos(wd * h) - sigma / wd * math.sin(wd * h))
    np.testing.assert_allclose(e[:2, 1], [d, dd], rtol=1e-10, atol=1e-13)
    np.testing.assert_allclose(e[2], [0.0, 0.0, 1.0], atol=1e-14)


def test_expm_of_small_and_large_matrices() -> None:
    """e^0 = I; e^(diag) = diag(e^x); a rotation generator gives the rotation."""
    np.testing.assert_array_equal(expm(np.zeros((2, 2))), np.eye(2))
    np.testing.assert_allclose(expm(np.diag([0.1, -3.0, 5.0])), np.diag(np.exp([0.1, -3.0, 5.0])), rtol=1e-12)
    t = 7.5
    np.testing.assert_allclose(expm(np.array([[0.0, t], [-t, 0.0]])), rotation(t), atol=1e-10)


def damped_general(k: float, c: float, d0: float, v0: float, force: float, t: float) -> tuple[float, float]:
    """d'' + c d' + k d = F, d(0) = d0, d'(0) = v0 (underdamped): d = F/k + e^(−σt)(A cos ω_d t +
    B sin ω_d t), A = d0 − F/k, B = (v0 + σA) / ω_d."""
    sigma = c / 2.0
    wd = math.sqrt(k - sigma * sigma)
    amp_a = d0 - force / k
    amp_b = (v0 + sigma * amp_a) / wd
    ex, co, si = math.exp(-sigma * t), math.cos(wd * t), math.sin(wd * t)
    d = force / k + ex * (amp_a * co + amp_b * si)
    dd = ex * ((-sigma * amp_a + wd * amp_b) * co + (-sigma * amp_b - wd * amp_a) * si)
    return d, dd


@pytest.mark.parametrize("mix", [1.0, 0.4])
def test_a_spring_follows_a_ramping_key(mix: float) -> None:
    """Key u(s) = u0 + u1·s over the sub-step, given by its mid-step value u0 + u1·τ/2 and its
    rate u1: in d = θ − u, d'' + c d' + k d = −c·u1 (no forcing), d(0) = θ0 − u0,
    d'(0) = ω0 − u1. The children see (1 − mix)·key + mix·spring: the angle and rate at
    mid-step (the mean of the ends), the acceleration (1 − mix)·u'' + mix·(ω1 − ω0)/τ."""
    k, c, u0, u1, th0, om0, tau, key_acc = 80.0, 5.0, 0.2, 3.0, 0.5, -1.0, 0.01, 7.0
    system = SpringSystem(spring_root(), SpringParams(stiffness=k, damping=c, inertia=0.0, mix=mix))
    theta, omega = np.array([th0]), np.array([om0])
    key, rate, acc = np.array([u0 + u1 * tau / 2]), np.array([u1]), np.array([key_acc])
    system.step(theta, omega, tau, key, rate, acc, np.zeros(1), np.zeros(1), np.zeros(2))
    d, dd = damped_general(k, c, th0 - u0, om0 - u1, -c * u1, tau)
    th1, om1 = u0 + u1 * tau + d, u1 + dd
    assert float(theta[0]) == pytest.approx(th1, abs=1e-12)
    assert float(omega[0]) == pytest.approx(om1, abs=1e-10)
    assert float(key[0]) == pytest.approx((1 - mix) * (u0 + u1 * tau / 2) + mix * 0.5 * (th0 + th1), abs=1e-12)
    assert float(rate[0]) == pytest.approx((1 - mix) * u1 + mix * 0.5 * (om0 + om1), abs=1e-10)
    assert float(acc[0]) == pytest.approx((1 - mix) * key_acc + mix * (om1 - om0) / tau, rel=1e-8)
    assert abs(om1 - om0) / tau > 10.0  # the spring's own acceleration matters here


@pytest.mark.parametrize(("side", "limits"), [(-1.0, (-0.2, 0.3)), (1.0, (-0.3, 0.2))])
def test_a_limited_spring_bounces_off_either_limit(side: float, limits: tuple[float, float]) -> None:
    """No stiffness, damping or forcing: θ = ω t. From 0 at ω = ±240 the joint reaches ±0.2 at
    t = 1/1200 s, leaves at ∓e·240 = ∓120 and ends the 1/600 s sub-step at ±0.2 ∓ 120/1200."""
    system = SpringSystem(spring_root(), SpringParams(stiffness=0.0, damping=0.0, inertia=0.0, mix=1.0),
                          [limits, (-9.0, 9.0)], restitution=0.5)
    np.testing.assert_array_equal(system.limits, [limits])  # entries past the last joint: ignored
    theta, omega = np.zeros(1), np.array([side * 240.0])
    system.step(theta, omega, 1.0 / 600.0, np.zeros(1), np.zeros(1), np.zeros(1), np.zeros(1), np.zeros(1),
                np.zeros(2))
    [b] = system.bounces
    assert b.joint == 0 and b.limit == side * 0.2
    assert b.time == pytest.approx(1.0 / 1200.0, abs=1e-15)
    assert b.rate_before == pytest.approx(side * 240.0) and b.rate_after == pytest.approx(-side * 120.0)
    assert float(omega[0]) == pytest.approx(-side * 120.0, rel=1e-12)
    assert float(theta[0]) == pytest.approx(side * (0.2 - 0.1), abs=1e-13)


def test_a_spring_inside_its_limits_is_not_bounced() -> None:
    system = SpringSystem(spring_root(), SpringParams(inertia=0.0), [(-1.0, 1.0)])
    free = SpringSystem(spring_root(), SpringParams(inertia=0.0))
    states = []
    for s in (system, free):
        theta, omega = np.array([0.5]), np.array([2.0])
        s.step(theta, omega, TAU, np.array([0.1]), np.zeros(1), np.zeros(1), np.zeros(1), np.zeros(1), np.zeros(2))
        states.append((float(theta[0]), float(omega[0])))
    assert states[0] == states[1] and not system.bounces


@pytest.mark.parametrize(("mass", "inertia"), [(0.5, 0.2), (2.0, 0.0)])
def test_small_and_zero_moments(mass: float, inertia: float) -> None:
    """The forcing's m/I with a moment below 1 is used as it is; a joint without a moment
    gets no pivot forcing (m/I undefined: 0) and is a plain spring."""
    k, c, beta, u, theta0 = 50.0, 2.0, 1.0, 0.0, 0.4
    y0 = np.array([0.3, 0.4])
    mp = MassProperties(mass, y0.copy(), inertia, np.zeros(2))
    system = SpringSystem(Character("s", [Joint("s", None, np.zeros(2), is_spring=True, mass_properties=mp)]),
                          SpringParams(stiffness=k, damping=c, inertia=beta, mix=1.0))
    a = np.array([30.0, -20.0])
    ratio = mass / inertia if inertia > 0 else 0.0
    force = -beta * ratio * float(a @ (rotation(theta0 + math.pi / 2) @ y0))
    theta, omega = np.array([theta0]), np.zeros(1)
    system.step(theta, omega, TAU, np.array([u]), np.zeros(1), np.zeros(1), np.zeros(1), np.zeros(1), a)
    d, _ = damped_closed_form(k, c, theta0 - u, force, TAU)
    assert float(theta[0]) == pytest.approx(u + d, abs=1e-12)
