"""Pendulum joints with angle limits bounce (issue 18 item 4): the angle never leaves the
limits, and every bounce keeps e of the relative speed, so e² of the kinetic energy at impact.

The exact-energy checks use RK4 (energy drift ~1e-12 over the run), so the speed at the limit
before and after a bounce can be read from the energy on either side of it, independently of
what the bounce code records."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.joint_bounce import BoundedUnit, bounded_step, hermite
from qtanimator.core.pendulum import PRESETS, PendulumParams, PendulumSystem
from qtanimator.core.rig2d import Character, Joint, Shape

G = 1000.0


def chain(lengths: list[float]) -> Character:
    """A keyframed base holding a chain of dynamic joints with disc bobs."""
    joints = [Joint("base", None, np.array([0.0, 0.0]))]
    y = 0.0
    for i, ell in enumerate(lengths):
        t = np.linspace(0, 2 * math.pi, 32, endpoint=False)
        pts = np.stack([2 * np.cos(t), y + ell + 2 * np.sin(t)], axis=1)
        shape = Shape(pts, True, fill=(1, 1, 1, 1), kind="ellipse",
                      ellipse=(np.array([0.0, y + ell]), np.diag([2.0, 2.0])))
        joints.append(Joint(f"p{i}", i, np.array([0.0, y]), is_dynamic=True, shapes=[shape]))
        y += ell
    return Character("pendulums", joints)


def potential(system: PendulumSystem, theta: np.ndarray) -> float:
    return system.energy(theta, np.zeros_like(theta))


@pytest.mark.parametrize("e", [0.5, 0.8, 1.0, 0.0])
def test_a_released_pendulum_keeps_e_of_its_speed_at_every_bounce(e: float) -> None:
    ch = chain([100.0])
    lo, hi = -0.05, 0.6
    system = PendulumSystem(ch, PendulumParams(g=G, damping=0.0, restitution=e, integrator="rk4"),
                            limits=[None, (lo, hi)])
    inertia = float(system.groups[0].inertia[0])
    theta, omega = np.array([0.0, 0.5]), np.zeros(2)
    at_limit = potential(system, np.array([0.0, lo]))
    energies, bounces = [system.energy(theta, omega)], []
    for _ in range(3000):
        system.step(theta, omega, np.zeros((2, 2)))
        assert lo - 1e-12 <= theta[1] <= hi + 1e-12
        energies.append(system.energy(theta, omega))
        bounces.append(list(system.bounces))
    hits = [i for i, b in enumerate(bounces) if b]
    assert len(hits) >= (1 if e == 0.0 else 4)
    speeds = []
    for i in hits[:6]:
        [b] = bounces[i]
        assert b.limit == lo and b.joint == 1
        assert b.rate_after == pytest.approx(-e * b.rate_before, abs=1e-12)
        # Speeds at the limit read from the energy just before and just after the step.
        before = math.sqrt(2 * (energies[i] - at_limit) / inertia)
        after = math.sqrt(max(2 * (energies[i + 1] - at_limit) / inertia, 0.0))
        assert before == pytest.approx(abs(b.rate_before), rel=1e-6)
        assert after == pytest.approx(e * before, rel=1e-6, abs=1e-6 * before)
        speeds.append(before)
    # The next impact comes at the speed the last bounce left with (no energy lost between).
    for a, b in zip(speeds, speeds[1:]):
        assert b == pytest.approx(e * a, rel=1e-6)


@pytest.mark.parametrize("integrator", ["symplectic_euler", "leapfrog", "rk4"])
def test_the_angle_never_leaves_the_limits(integrator: str) -> None:
    ch = chain([100.0])
    system = PendulumSystem(ch, PendulumParams(g=G, damping=0.0, restitution=0.7, integrator=integrator),
                            limits=[None, (-0.25, 0.3)])
    theta, omega = np.array([0.0, 0.3]), np.array([0.0, 6.0])  # thrown hard into the upper limit
    count = 0
    for _ in range(4000):
        system.step(theta, omega, np.zeros((2, 2)))
        assert -0.25 - 1e-12 <= theta[1] <= 0.3 + 1e-12
        for b in system.bounces:
            assert b.rate_after == pytest.approx(-0.7 * b.rate_before, abs=1e-12)
        count += len(system.bounces)
    assert count >= 3


def test_a_pendulum_pushed_into_its_limit_rests_on_it() -> None:
    ch = chain([100.0])
    system = PendulumSystem(ch, PendulumParams(g=G, damping=0.3, restitution=0.5), limits=[None, (0.1, 0.6)])
    theta, omega = np.array([0.0, 0.5]), np.zeros(2)
    for _ in range(6000):
        system.step(theta, omega, np.zeros((2, 2)))
        assert 0.1 - 1e-12 <= theta[1] <= 0.6 + 1e-12
    assert theta[1] == pytest.approx(0.1, abs=1e-12)
    assert omega[1] == pytest.approx(0.0, abs=1e-9)


def test_a_turning_parent_carries_the_limits_along() -> None:
    """The limit is on the angle relative to the parent: a keyed parent spinning at 2 rad/s
    drags the pendulum round once it reaches the limit."""
    ch = chain([100.0])
    tau = 1.0 / 600.0
    system = PendulumSystem(ch, PendulumParams(g=G, damping=0.0, restitution=0.5), limits=[None, (-0.3, 0.3)])
    theta, omega = np.array([0.0, 0.0]), np.zeros(2)
    rate = 2.0
    for i in range(1200):
        motion = np.zeros((2, 4))
        motion[1] = (rate * i * tau, rate, rate * (i + 1) * tau, rate)
        system.step(theta, omega, np.zeros((2, 2)), tau, motion)
        local = theta[1] - rate * (i + 1) * tau
        assert -0.3 - 1e-12 <= local <= 0.3 + 1e-12


@pytest.mark.parametrize("e", [1.0, 0.5])
def test_a_limited_joint_inside_a_coupled_chain(e: float) -> None:
    """The impulse acts through the chain's mass matrix: with e = 1 energy is kept (RK4
    accuracy), with e < 1 the relative rate reverses times e and the limit holds."""
    ch = chain([100.0, 80.0])
    system = PendulumSystem(ch, PendulumParams(g=G, damping=0.0, restitution=e), limits=[None, None, (-0.3, 0.3)])
    theta, omega = np.array([0.0, 1.0, 1.0]), np.zeros(3)
    e0 = system.energy(theta, omega)
    count = 0
    for _ in range(3000):
        system.step(theta, omega, np.zeros((3, 2)))
        assert abs(theta[2] - theta[1]) <= 0.3 + 1e-12
        for b in system.bounces:
            assert b.rate_after == pytest.approx(-e * b.rate_before, rel=1e-9, abs=1e-12)
        count += len(system.bounces)
    assert count >= 3
    if e == 1.0:
        assert system.energy(theta, omega) == pytest.approx(e0, rel=1e-8)
    else:
        assert system.energy(theta, omega) < e0


def test_bounded_step_on_a_parabola_finds_the_crossing_time() -> None:
    """θ(t) = θ0 + v t (no forces): the crossing of θ = 1 from 0 at v = 4 is at t = 0.25,
    and the rest of the step goes back at e·v."""

    def step(th: np.ndarray, om: np.ndarray, _t: float, h: float) -> tuple[np.ndarray, np.ndarray]:
        return th + h * om, om.copy()

    unit = BoundedUnit(np.array([0]), np.array([-1.0]), np.array([1.0]), np.array([-1]),
                       lambda _t: (np.zeros(1), np.zeros(1)))
    bounces: list = []
    th, om = bounded_step(unit, step, np.array([0.0]), np.array([4.0]), 0.5, 0.5, bounces)
    [b] = bounces
    assert b.time == pytest.approx(0.25, abs=1e-14)
    assert om[0] == pytest.approx(-2.0)
    assert th[0] == pytest.approx(1.0 - 2.0 * 0.25, abs=1e-12)


def test_hermite_parent_motion_is_exact_at_both_ends() -> None:
    f = hermite(np.array([0.2]), np.array([1.0]), np.array([0.5]), np.array([-2.0]), 0.01)
    a, r = f(0.0)
    assert (a[0], r[0]) == (0.2, 1.0)
    a, r = f(0.01)
    assert (a[0], r[0]) == (0.5, -2.0)


def test_restitution_is_a_pendulum_parameter_in_every_preset() -> None:
    assert PendulumParams().restitution == 0.5
    assert all(0.0 <= p.restitution <= 1.0 for p in PRESETS.values())
    assert PendulumParams.from_dict({"restitution": 0.25}).restitution == 0.25
    for bad in (-0.1, 1.5, float("nan")):
        with pytest.raises(ValueError, match="restitution"):
            PendulumParams(restitution=bad)


def test_without_limits_nothing_changes() -> None:
    """A limit on a joint that is not dynamic, or none at all, leaves the old step bit for bit."""
    ch = chain([100.0, 60.0])
    a = PendulumSystem(ch, PendulumParams(g=G))
    b = PendulumSystem(ch, PendulumParams(g=G), limits=[(-0.1, 0.1), None, None])
    ta, wa = np.array([0.0, 0.7, -0.4]), np.zeros(3)
    tb, wb = ta.copy(), wa.copy()
    for _ in range(200):
        a.step(ta, wa, np.zeros((3, 2)))
        b.step(tb, wb, np.zeros((3, 2)))
    assert np.array_equal(ta, tb) and np.array_equal(wa, wb)
