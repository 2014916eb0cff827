"""Pendulum dynamics: period, energy, damping, pivot acceleration, coupled chains."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.pendulum import PRESETS, PendulumParams, PendulumSystem, pivot_accelerations
from qtanimator.core.rig2d import Character, Joint, Shape

G = 1000.0


def disc(cx: float, cy: float, r: float = 2.0) -> Shape:
    t = np.linspace(0, 2 * math.pi, 32, endpoint=False)
    pts = np.stack([cx + r * np.cos(t), cy + r * np.sin(t)], axis=1)
    return Shape(pts, True, fill=(1, 1, 1, 1), kind="ellipse",
                 ellipse=(np.array([cx, cy]), np.diag([r, r])))


def pendulum_chain(lengths: list[float], bob_offset_x: float = 0.0) -> Character:
    """A keyframed base joint holding a chain of dynamic joints with disc bobs."""
    joints = [Joint("base", None, np.array([0.0, 0.0]))]
    y = 0.0
    for i, ell in enumerate(lengths):
        joints.append(Joint(f"p{i}", i, np.array([0.0, y]), is_dynamic=True,
                            shapes=[disc(bob_offset_x, y + ell)]))
        y += ell
    return Character("pendulums", joints)


def simulate(system: PendulumSystem, theta: np.ndarray, steps: int, acc: np.ndarray | None = None,
             record: int | None = None) -> np.ndarray:
    n = len(system.character.joints)
    pa = np.zeros((n, 2)) if acc is None else acc
    omega = np.zeros(n)
    if record is not None:
        return system.run(theta, omega, pa, steps)[0][:, record]
    out = []
    for _ in range(steps):
        system.step(theta, omega, pa)
        out.append(system.energy(theta, omega))
    return np.array(out)


def measured_period(signal: np.ndarray, dt: float) -> float:
    s = np.sign(signal)
    ups = np.flatnonzero((s[:-1] < 0) & (s[1:] >= 0))
    # linear interpolation of the crossings
    t = [(i + signal[i] / (signal[i] - signal[i + 1])) * dt for i in ups]
    return float(np.mean(np.diff(t)))


def test_small_angle_period() -> None:
    ch = pendulum_chain([100.0])
    params = PendulumParams(g=G, damping=0.0)
    sys = PendulumSystem(ch, params)
    j = ch.joints[1]
    expected = 2 * math.pi * math.sqrt(j.inertia / (j.mass * G * 100.0))
    theta = np.zeros(2)
    theta[1] = 0.01
    sig = simulate(sys, theta, int(6 * expected / params.step), record=1)
    assert measured_period(sig, params.step) == pytest.approx(expected, rel=0.01)


def test_period_of_a_real_clock_pendulum_with_reference_moments() -> None:
    # notes 9.4: handout 3A (g = 3, reference I) gives about 1.13 s for clock joint 5
    from needs import shared_data_path

    root = shared_data_path("cmu-animator", "scenes")
    from qtanimator.formats.svg_rig import load_characters

    [clock] = load_characters(root / "clock.svg")
    sys = PendulumSystem(clock, PendulumParams(g=3.0, damping=0.0, inertia="reference", coupled=False,
                                               step=1 / 600))
    theta = sys.equilibrium()
    theta[5] += 0.01
    sig = simulate(sys, theta, 3000, record=5)
    assert measured_period(sig - sys.equilibrium()[5], 1 / 600) == pytest.approx(1.13, abs=0.01)


@pytest.mark.parametrize("integrator", ["symplectic_euler", "leapfrog"])
def test_undamped_energy_does_not_drift(integrator: str) -> None:
    ch = pendulum_chain([100.0])
    sys = PendulumSystem(ch, PendulumParams(g=G, damping=0.0, integrator=integrator))
    j = ch.joints[1]
    theta, omega = np.array([0.0, 1.0]), np.zeros(2)
    traj_t, traj_w = sys.run(theta, omega, np.zeros((2, 2)), 100_000)
    th, om = traj_t[:, 1], traj_w[:, 1]
    # E = ½ I ω² − m g L cos(θ + φ) (φ = 0 here), checked against the system's own energy
    e = 0.5 * j.inertia * om ** 2 - j.mass * G * 100.0 * np.cos(th)
    assert e[-1] == pytest.approx(sys.energy(theta, omega), rel=1e-9)
    e0 = sys.energy(np.array([0.0, 1.0]), np.zeros(2))
    swing = e0 - (-j.mass * G * 100.0)  # energy above the bottom
    if integrator == "leapfrog":
        assert np.max(np.abs(e - e0)) / swing < 1e-3
    else:
        # symplectic Euler's energy oscillates (O(τ)) but does not drift: compare the
        # average over the first and the last second
        n = int(1 / sys.params.step)
        assert abs(e[-n:].mean() - e[:n].mean()) / swing < 1e-3


def test_damping_decays_amplitude_as_exp_minus_a_t_over_2() -> None:
    ch = pendulum_chain([100.0])
    a = 0.8
    sys = PendulumSystem(ch, PendulumParams(g=G, damping=a, integrator="leapfrog"))
    theta = np.array([0.0, 0.05])
    sig = simulate(sys, theta, 6000, record=1)
    peaks = [i for i in range(1, len(sig) - 1) if sig[i] > sig[i - 1] and sig[i] >= sig[i + 1]]
    t = np.array(peaks) * sys.params.step
    slope = np.polyfit(t, np.log(sig[peaks]), 1)[0]
    assert slope == pytest.approx(-a / 2, rel=0.03)


def test_accelerating_pivot_makes_the_bob_lag() -> None:
    ch = pendulum_chain([100.0])
    sys = PendulumSystem(ch, PendulumParams(g=G, damping=0.0))
    theta = np.zeros(2)
    acc = np.zeros((2, 2))
    acc[:, 0] = 500.0  # towards +x
    omega = np.zeros(2)
    for _ in range(60):
        sys.step(theta, omega, acc)
    bob = ch.pose([0.0, theta[1]], (0, 0)).to_world(1, (0, 100))
    assert theta[1] < 0 and bob[0] < 0  # clockwise on screen: the bob swings back towards −x
    # with damping it settles where tan(angle) = −a/g
    sys = PendulumSystem(ch, PendulumParams(g=G, damping=5.0))
    theta, omega = np.zeros(2), np.zeros(2)
    for _ in range(6000):
        sys.step(theta, omega, acc)
    assert theta[1] == pytest.approx(-math.atan2(500.0, G), abs=1e-3)


def test_off_vertical_centre_of_mass_swings_towards_minus_phi() -> None:
    ch = pendulum_chain([100.0], bob_offset_x=30.0)
    sys = PendulumSystem(ch, PendulumParams(g=G, damping=3.0))
    theta, omega = np.zeros(2), np.zeros(2)
    for _ in range(6000):
        sys.step(theta, omega, np.zeros((2, 2)))
    assert theta[1] == pytest.approx(-math.atan2(30.0, 100.0), abs=1e-3)
    assert sys.equilibrium()[1] == pytest.approx(theta[1], abs=1e-3)


@pytest.mark.parametrize("mode,sign", [("slow", 1.0), ("fast", -1.0)])
def test_double_pendulum_normal_modes(mode: str, sign: float) -> None:
    ell = 100.0
    ch = pendulum_chain([ell, ell])
    sys = PendulumSystem(ch, PendulumParams(g=G, damping=0.0, integrator="rk4"))
    assert [g.joints for g in sys.groups] == [[1, 2]]
    # equal point masses on massless rods: ω² = (g/l)(2 ∓ √2), mode shape θ2/θ1 = ±√2
    omega2 = G / ell * (2 - sign * math.sqrt(2))
    theta = np.array([0.0, 0.002, sign * 0.002 * math.sqrt(2)])
    sig = simulate(sys, theta, int(5 * 2 * math.pi / math.sqrt(omega2) / sys.params.step), record=1)
    # tiny discs (r = 2) add a little rotational inertia: 1% tolerance
    assert measured_period(sig, sys.params.step) == pytest.approx(2 * math.pi / math.sqrt(omega2), rel=0.01)


@pytest.mark.parametrize("links,integrator,tol", [(2, "rk4", 1e-5), (3, "rk4", 1e-5), (2, "symplectic_euler", 1e-5)])
def test_chaotic_chain_conserves_energy(links: int, integrator: str, tol: float) -> None:
    ch = pendulum_chain([80.0] * links)
    sys = PendulumSystem(ch, PendulumParams(g=G, damping=0.0, integrator=integrator))
    theta = np.zeros(links + 1)
    theta[1:] = [1.5, -1.0, 0.5][:links]
    e0 = sys.energy(theta.copy(), np.zeros(links + 1))
    e = simulate(sys, theta, 3000)
    scale = sum(j.mass for j in ch.joints) * G * 80.0 * links
    assert np.max(np.abs(e - e0)) / scale < tol


def test_uncoupled_mode_and_presets() -> None:
    ch = pendulum_chain([50.0, 50.0])
    sys = PendulumSystem(ch, PRESETS["handout"])
    assert [g.joints for g in sys.groups] == [[1], [2]]
    theta, omega = np.zeros(3), np.zeros(3)
    theta[1:] = 0.3
    for _ in range(100):
        sys.step(theta, omega, np.zeros((3, 2)))
    assert np.all(np.isfinite(theta)) and abs(theta[1]) < 0.3
    with pytest.raises(ValueError):
        PendulumParams(integrator="euler")
    assert PendulumParams.from_dict({"g": 5.0, "unknown": 1}).g == 5.0


def test_pivot_acceleration_from_a_rotating_parent() -> None:
    # a parent turning at constant rate w about the origin: the child's pivot at distance r
    # has centripetal acceleration w² r towards the parent's pivot
    ch = pendulum_chain([100.0])
    w = 2.0
    acc = pivot_accelerations(ch, np.array([0.0, 0.0]), np.array([w, 0.0]), np.zeros(2), (0, 0))
    np.testing.assert_allclose(acc[1], (0, 0))  # the child's pivot is on the parent's pivot
    ch2 = pendulum_chain([100.0, 100.0])
    acc = pivot_accelerations(ch2, np.array([0.0, 0.3, 0.3]), np.array([0.0, w, w]), np.zeros(3), (1.0, 2.0))
    r = 100.0 * np.array([math.sin(0.3), math.cos(0.3)])
    np.testing.assert_allclose(acc[2], np.array([1.0, 2.0]) - w * w * r, atol=1e-9)


def test_a_blow_up_is_detected_and_names_what_to_change():
    from qtanimator.core.pendulum import RUNAWAY_RATE, PendulumParams, check_state
    from qtanimator.core.rig2d import Character, Joint

    ch = Character("c", [Joint("root", None, np.zeros(2), children=[1]),
                         Joint("bob", 0, np.array([0.0, 10.0]), is_dynamic=True)])
    params = PendulumParams()
    theta, omega = np.zeros(2), np.zeros(2)
    assert check_state(ch, params, theta, omega, 0.5) is None
    omega[1] = RUNAWAY_RATE * 1.01
    report = check_state(ch, params, theta, omega, 0.5)
    assert report is not None and report.joint == "bob" and report.parameter == "step" and "0.500 s" in report.message
    omega[1] = 0.0
    theta[1] = np.nan
    report = check_state(ch, PendulumParams(damping=-5.0), theta, omega, 1.0)
    assert report is not None and report.parameter == "damping" and "not a finite number" in report.message
