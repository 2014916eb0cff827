"""A pendulum on a moving pivot: vertical and rotational pivot accelerations.

The expected values come from a hand-derived Lagrangian, not from the simulation. A bob of
mass m whose centre of mass is at P(t) + L·(sin θ, cos θ) (y down, gravity g towards +y,
the rig's rotation convention R(θ)·(0, L) = L·(sin θ, cos θ)), with moment I_c about its
centre, has

    T = ½·m·|P' + L·θ'·(cos θ, −sin θ)|² + ½·I_c·θ'²,   V = −m·g·(P_y + L·cos θ)

and Euler–Lagrange gives

    (m·L² + I_c)·θ'' = −m·L·(g·sin θ + P''_x·cos θ − P''_y·sin θ).

So an upward pivot acceleration a (P''_y = −a) is gravity g + a: the small-oscillation period
is 2π·√((L² + I_c/m) / ((g + a)·L)). For a pivot carried by a parent turning by Θ(t) at
distance r (P = r·(sin Θ, cos Θ)), P'' = r·(cos Θ·Θ'' − sin Θ·Θ'², −sin Θ·Θ'' − cos Θ·Θ'²).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.pendulum import PendulumParams, PendulumSystem, pivot_accelerations
from qtanimator.core.rig2d import Character, Joint, Shape

G = 1000.0
L = 100.0
RHO = 2.0  # bob disc radius
IC_OVER_M = RHO * RHO / 2.0  # a disc's moment about its centre, per unit mass


def disc(cx: float, cy: float, r: float = RHO) -> Shape:
    t = np.linspace(0, 2 * math.pi, 64, endpoint=False)
    pts = np.stack([cx + r * np.cos(t), cy + r * np.sin(t)], axis=1)
    return Shape(pts, True, fill=(1, 1, 1, 1), kind="ellipse", ellipse=(np.array([cx, cy]), np.diag([r, r])))


def one_pendulum(pivot_y: float = 0.0) -> Character:
    """A keyframed base at the origin and one dynamic joint at (0, pivot_y), bob L below."""
    return Character("p", [Joint("base", None, np.array([0.0, 0.0])),
                           Joint("bob", 0, np.array([0.0, pivot_y]), is_dynamic=True,
                                 shapes=[disc(0.0, pivot_y + L)])])


def theta_dd(theta: float, g: float, ax: float, ay: float) -> float:
    """θ'' of the hand-derived equation above (pivot acceleration (ax, ay))."""
    return -L * (g * math.sin(theta) + ax * math.cos(theta) - ay * math.sin(theta)) / (L * L + IC_OVER_M)


def crossings_period(signal: np.ndarray, dt: float) -> float:
    s = np.sign(signal)
    ups = np.flatnonzero((s[:-1] < 0) & (s[1:] >= 0))
    t = [(i + signal[i] / (signal[i] - signal[i + 1])) * dt for i in ups]
    assert len(t) >= 3
    return float(np.mean(np.diff(t)))


# ----------------------------------------------------------------- vertical pivot acceleration

@pytest.mark.parametrize("integrator", ["symplectic_euler", "leapfrog", "rk4"])
@pytest.mark.parametrize("via", ["run", "step"])
def test_upward_pivot_acceleration_is_extra_gravity(integrator: str, via: str) -> None:
    a = 3.0 * G  # upward (−y): effective gravity 4 g, half the period of a still pivot
    ch = one_pendulum()
    sys = PendulumSystem(ch, PendulumParams(g=G, damping=0.0, integrator=integrator, step=1.0 / 2000.0))
    expected = 2 * math.pi * math.sqrt((L * L + IC_OVER_M) / ((G + a) * L))
    acc = np.zeros((2, 2))
    acc[:, 1] = -a
    theta, omega = np.zeros(2), np.zeros(2)
    theta[1] = 0.01
    steps = int(5 * expected / sys.params.step)
    if via == "run":
        sig = sys.run(theta, omega, acc, steps)[0][:, 1]
    else:
        out = []
        for _ in range(steps):
            sys.step(theta, omega, acc)
            out.append(theta[1])
        sig = np.array(out)
    assert crossings_period(sig, sys.params.step) == pytest.approx(expected, rel=2e-3)
    # amplitude is unchanged (no energy from a constant pivot acceleration along the rest line)
    assert np.max(np.abs(sig)) == pytest.approx(0.01, rel=2e-2)


def test_downward_pivot_acceleration_weakens_gravity() -> None:
    a = 0.75 * G  # downward: effective gravity g/4, twice the period
    ch = one_pendulum()
    sys = PendulumSystem(ch, PendulumParams(g=G, damping=0.0, integrator="rk4", step=1.0 / 1000.0))
    expected = 2 * math.pi * math.sqrt((L * L + IC_OVER_M) / ((G - a) * L))
    acc = np.array([[0.0, a], [0.0, a]])
    theta, omega = np.array([0.0, 0.01]), np.zeros(2)
    sig = sys.run(theta, omega, acc, int(4 * expected / sys.params.step))[0][:, 1]
    assert crossings_period(sig, sys.params.step) == pytest.approx(expected, rel=2e-3)


@pytest.mark.parametrize("integrator", ["symplectic_euler", "rk4"])
@pytest.mark.parametrize("theta0,ax,ay", [(0.7, 0.0, -1500.0), (-1.2, 0.0, 800.0), (0.4, 300.0, -2000.0),
                                          (2.5, -700.0, 400.0)])
def test_first_step_angular_acceleration_matches_the_lagrangian(integrator: str, theta0: float, ax: float,
                                                                ay: float) -> None:
    """From rest, one tiny step gives ω ≈ τ·θ''(θ0): compare with the closed form at
    angles where sin θ ≠ 0, so the vertical term −P''_y·sin θ counts."""
    ch = one_pendulum()
    tau = 1e-7 if integrator == "rk4" else 1e-5
    sys = PendulumSystem(ch, PendulumParams(g=G, damping=0.0, integrator=integrator, step=max(tau, 1e-5)))
    acc = np.array([[ax, ay], [ax, ay]])
    expected = theta_dd(theta0, G, ax, ay)
    for via in ("step", "run"):
        theta, omega = np.array([0.0, theta0]), np.zeros(2)
        if via == "step":
            sys.step(theta, omega, acc, tau)
        else:
            sys.run(theta, omega, acc, 1, tau)
        assert omega[1] / tau == pytest.approx(expected, rel=1e-3), via
    # the group equations (the same pendulum as a one-joint group) agree too
    [group] = sys.groups
    got = sys.group_acceleration(group, np.array([theta0]), np.zeros(1), np.array([ax, ay]))
    assert got[0] == pytest.approx(expected, rel=1e-3)


def test_settles_along_the_effective_gravity() -> None:
    """Damped, under a constant pivot acceleration (ax, ay) the bob hangs along g − a:
    θ = atan2(−ax, g − ay)."""
    ax, ay = 400.0, 600.0  # g − ay = 400: 45° the other way
    ch = one_pendulum()
    sys = PendulumSystem(ch, PendulumParams(g=G, damping=5.0))
    theta, omega = np.zeros(2), np.zeros(2)
    sys.run(theta, omega, np.array([[ax, ay], [ax, ay]]), 8000)
    assert theta[1] == pytest.approx(math.atan2(-ax, G - ay), abs=1e-3)
    assert theta[1] == pytest.approx(-math.pi / 4, abs=1e-3)


def test_coupled_double_pendulum_in_a_rising_lift() -> None:
    """Equal point masses on massless rods (length l): ω² = (g_eff/l)(2 ∓ √2); in a lift
    accelerating upward at a, g_eff = g + a."""
    ell, a = 100.0, G
    joints = [Joint("base", None, np.array([0.0, 0.0])),
              Joint("p0", 0, np.array([0.0, 0.0]), is_dynamic=True, shapes=[disc(0.0, ell)]),
              Joint("p1", 1, np.array([0.0, ell]), is_dynamic=True, shapes=[disc(0.0, 2 * ell)])]
    ch = Character("double", joints)
    sys = PendulumSystem(ch, PendulumParams(g=G, damping=0.0, integrator="rk4"))
    assert [g.joints for g in sys.groups] == [[1, 2]]
    omega2 = (G + a) / ell * (2 - math.sqrt(2))  # the slow mode, θ2/θ1 = √2
    theta = np.array([0.0, 0.002, 0.002 * math.sqrt(2)])
    acc = np.zeros((3, 2))
    acc[:, 1] = -a
    period = 2 * math.pi / math.sqrt(omega2)
    sig = sys.run(theta, np.zeros(3), acc, int(5 * period / sys.params.step))[0][:, 1]
    assert crossings_period(sig, sys.params.step) == pytest.approx(period, rel=0.01)


# ------------------------------------------------------------- rotational pivot acceleration

def _pivot_position(ch: Character, angles: np.ndarray, joint: int) -> np.ndarray:
    return np.asarray(ch.pose(angles).pivots[joint], dtype=np.float64)


@pytest.mark.parametrize("angle,rate,accel", [(0.0, 0.0, 5.0), (0.6, 0.0, -3.0), (-1.1, 2.0, 7.0),
                                              (2.0, -1.5, 0.0)])
def test_pivot_accelerations_match_forward_kinematics(angle: float, rate: float, accel: float) -> None:
    """The second time derivative of the child pivot's forward-kinematics position, by
    central differences over Θ(t) = Θ0 + Θ'·t + ½Θ''·t² (an independent computation)."""
    ch = Character("arm", [Joint("base", None, np.array([10.0, -5.0])),
                           Joint("upper", 0, np.array([40.0, 30.0])),
                           Joint("bob", 1, np.array([40.0, 130.0]), is_dynamic=True,
                                 shapes=[disc(40.0, 230.0)])])
    local = np.array([0.0, 0.3, 0.0])

    def pivot_at(t: float) -> np.ndarray:
        a = local.copy()
        a[0] = angle + rate * t + 0.5 * accel * t * t
        return _pivot_position(ch, a, 2)

    h = 1e-4
    fd = (pivot_at(h) - 2 * pivot_at(0.0) + pivot_at(-h)) / (h * h)
    world = np.array([angle, angle + 0.3, angle + 0.3])
    rates = np.array([rate, rate, rate])
    accels = np.array([accel, accel, accel])
    acc = pivot_accelerations(ch, world, rates, accels, (0.0, 0.0))
    np.testing.assert_allclose(acc[2], fd, rtol=1e-4, atol=1e-3 * (1 + abs(accel)))
    # tangential part alone: the whole arm starting from rest (Θ' = 0) at Θ = 0 with angular
    # acceleration Θ'': P'' = Θ''·d/dΘ(R(Θ)v) = Θ''·(v_y, −v_x), v the pivot − base pivot
    acc0 = pivot_accelerations(ch, np.zeros(3), np.zeros(3), np.full(3, accel), (0.0, 0.0))
    np.testing.assert_allclose(acc0[1], accel * np.array([35.0, -30.0]), atol=1e-9)
    np.testing.assert_allclose(acc0[2], accel * np.array([135.0, -30.0]), atol=1e-9)


def _reference_trajectory(r: float, alpha: float, t_end: float, n: int) -> np.ndarray:
    """θ(t) of the hand-derived equation with P = r·(sin Θ, cos Θ), Θ = ½·α·t²,
    by RK4 with n steps (written here, independent of the program)."""

    def f(t: float, th: float) -> float:
        big, rate = 0.5 * alpha * t * t, alpha * t
        pxx = r * (math.cos(big) * alpha - math.sin(big) * rate * rate)
        pyy = r * (-math.sin(big) * alpha - math.cos(big) * rate * rate)
        return theta_dd(th, G, pxx, pyy)

    h = t_end / n
    th, om, t = 0.0, 0.0, 0.0
    out = np.empty(n)
    for i in range(n):
        k1t, k1w = om, f(t, th)
        k2t, k2w = om + 0.5 * h * k1w, f(t + 0.5 * h, th + 0.5 * h * k1t)
        k3t, k3w = om + 0.5 * h * k2w, f(t + 0.5 * h, th + 0.5 * h * k2t)
        k4t, k4w = om + h * k3w, f(t + h, th + h * k3t)
        th += h / 6 * (k1t + 2 * k2t + 2 * k3t + k4t)
        om += h / 6 * (k1w + 2 * k2w + 2 * k3w + k4w)
        t += h
        out[i] = th
    return out


def test_pendulum_on_an_angularly_accelerating_arm_follows_the_lagrangian() -> None:
    """The base turns with Θ = ½·α·t² from rest; the pendulum hangs from a pivot r below it.
    The pivot accelerations come from :func:`pivot_accelerations` each step."""
    r, alpha, t_end = 100.0, 12.0, 0.4
    ch = one_pendulum(pivot_y=r)
    tau = 1.0 / 20000.0
    n = int(round(t_end / tau))
    sys = PendulumSystem(ch, PendulumParams(g=G, damping=0.0, integrator="rk4", step=tau))
    theta, omega = np.zeros(2), np.zeros(2)
    got = np.empty(n)
    for i in range(n):
        t = (i + 0.5) * tau  # the pivot acceleration at the step's midpoint
        big = 0.5 * alpha * t * t
        acc = pivot_accelerations(ch, np.array([big, theta[1]]), np.array([alpha * t, omega[1]]),
                                  np.array([alpha, 0.0]), (0.0, 0.0))
        sys.step(theta, omega, acc)
        got[i] = theta[1]
    expected = _reference_trajectory(r, alpha, t_end, 4000)
    sample = np.arange(1, 11) * (n // 10) - 1
    ref = expected[np.arange(1, 11) * (4000 // 10) - 1]
    # the motion is large (the tangential kick r·α is comparable to g): compare in radians
    assert np.max(np.abs(ref)) > 0.5
    np.testing.assert_allclose(got[sample], ref, atol=2e-3)
