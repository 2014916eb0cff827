"""A limited pendulum stepped with a pivot acceleration given as a function (the form the
simulation cache passes) against one hand-written symplectic Euler step of the equation of
motion (targets a mutation-test survivor in the bounded step's callable path)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.mass import MassProperties
from qtanimator.core.pendulum import PendulumParams, PendulumSystem, _decay, single_acceleration
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


# ----------------------------------------------------------------------------------------
# The handout's point-mass forcing, limits by index, the equilibrium, the damping factor,
# the integrators and the energy, each against a hand-written formula.
L2 = float(Y0 @ Y0)


def hand_acceleration(theta: float, acc: np.ndarray, g: float, point_mass: bool) -> float:
    """I θ'' = m (g_vec − a)·∂r/∂θ; the handout's 3B form puts 1/L² (L = |y0|) in place of m/I
    on the forcing: θ'' = −(⟨a, y⊥⟩ / L² + m g L sin(θ + φ) / I) (notes 9.2/9.3)."""
    dr = rotation(theta + math.pi / 2) @ Y0
    grav = MASS * g * float(dr[1]) / INERTIA
    forcing = float(acc @ dr) * (1.0 / L2 if point_mass else MASS / INERTIA)
    return grav - forcing


@pytest.mark.parametrize("point_mass", [True, False])
@pytest.mark.parametrize("acc", [(40.0, -25.0), (0.0, 300.0), (-500.0, 0.0)])
def test_single_acceleration_matches_the_equation(point_mass: bool, acc: tuple[float, float]) -> None:
    """Both forcing forms, floats and arrays alike, and through the system's own θ''."""
    a = np.array(acc)
    thetas = np.array([0.2, -1.1, 2.5])
    for th in thetas:
        got = single_acceleration(math.cos(th), math.sin(th), Y0[0], Y0[1], a[0], a[1], MASS, 1000.0, INERTIA, L2,
                                  point_mass)
        assert float(got) == pytest.approx(hand_acceleration(th, a, 1000.0, point_mass), rel=1e-12)
    got = single_acceleration(np.cos(thetas), np.sin(thetas), Y0[0], Y0[1], a[0], a[1], MASS, 1000.0, INERTIA, L2,
                              point_mass)
    expected = [hand_acceleration(t, a, 1000.0, point_mass) for t in thetas]
    np.testing.assert_allclose(got, expected, rtol=1e-12)
    system = PendulumSystem(base_and_bob(), PendulumParams(g=1000.0, point_mass_forcing=point_mass))
    [group] = system.groups
    got = system.group_acceleration(group, np.array([0.2]), np.zeros(1), a)
    assert float(got[0]) == pytest.approx(hand_acceleration(0.2, a, 1000.0, point_mass), rel=1e-12)


def test_the_point_mass_forcing_pulls_the_bob_behind_the_pivot() -> None:
    """notes 9.3: the pivot accelerating towards +x with the bob straight below gives
    ⟨a, y⊥⟩ = |a|·L > 0, so θ'' < 0 (the bob lags); with the handout's 1/L², θ'' = −|a| / L."""
    y0 = np.array([0.0, 50.0])
    got = single_acceleration(1.0, 0.0, y0[0], y0[1], 10.0, 0.0, 3.0, 0.0, 7.0, 2500.0, True)
    assert float(got) == pytest.approx(-10.0 / 50.0, rel=1e-14)
    # the m/I form: θ'' = −m |a| L / I
    got = single_acceleration(1.0, 0.0, y0[0], y0[1], 10.0, 0.0, 3.0, 0.0, 7.0, 2500.0, False)
    assert float(got) == pytest.approx(-3.0 * 10.0 * 50.0 / 7.0, rel=1e-14)


@pytest.mark.parametrize("integrator", ["symplectic_euler", "leapfrog", "rk4"])
def test_a_point_mass_forced_pendulum_runs_as_the_hand_integrator(integrator: str) -> None:
    """20 steps with a constant pivot acceleration against a hand-written loop of the
    chosen integrator (symplectic Euler; leapfrog kick-drift-kick; classical RK4), damped."""
    a, g, damping, tau = np.array([150.0, -60.0]), 800.0, 0.7, 1.0 / 200.0
    params = PendulumParams(g=g, damping=damping, point_mass_forcing=True, integrator=integrator)
    system = PendulumSystem(base_and_bob(), params)
    theta, omega = np.array([0.0, 0.4]), np.array([0.0, -1.5])
    traj_t, traj_w = system.run(theta, omega, np.array([[0.0, 0.0], a]), 20, tau)

    def f(t: float) -> float:
        return hand_acceleration(t, a, g, True)

    th, om = 0.4, -1.5
    for i in range(20):
        if integrator == "symplectic_euler":
            om += tau * f(th)
            th += tau * om
        elif integrator == "leapfrog":
            om += 0.5 * tau * f(th)
            th += tau * om
            om += 0.5 * tau * f(th)
        else:
            k1t, k1w = om, f(th)
            k2t, k2w = om + 0.5 * tau * k1w, f(th + 0.5 * tau * k1t)
            k3t, k3w = om + 0.5 * tau * k2w, f(th + 0.5 * tau * k2t)
            k4t, k4w = om + tau * k3w, f(th + tau * k3t)
            th += tau / 6.0 * (k1t + 2 * k2t + 2 * k3t + k4t)
            om += tau / 6.0 * (k1w + 2 * k2w + 2 * k3w + k4w)
        om *= math.exp(-damping * tau)
        assert float(traj_t[i, 1]) == pytest.approx(th, abs=1e-12)
        assert float(traj_w[i, 1]) == pytest.approx(om, abs=1e-10)
        assert traj_t[i, 0] == 0.0 and traj_w[i, 0] == 0.0
    assert float(theta[1]) == pytest.approx(th, abs=1e-12) and float(omega[1]) == pytest.approx(om, abs=1e-10)
    # step() by step() gives the same trajectory
    t2, w2 = np.array([0.0, 0.4]), np.array([0.0, -1.5])
    for _ in range(20):
        system.step(t2, w2, np.array([[0.0, 0.0], a]), tau)
    assert float(t2[1]) == pytest.approx(th, abs=1e-12) and float(w2[1]) == pytest.approx(om, abs=1e-10)


def test_limits_past_the_last_joint_are_ignored() -> None:
    """``limits`` is by joint index; extra entries name no joint and change nothing."""
    system = PendulumSystem(base_and_bob(), PendulumParams(), [None, (-0.5, 0.5), (-1.0, 1.0), None])
    assert system.limits.shape == (2, 2)
    np.testing.assert_array_equal(system.limits[1], [-0.5, 0.5])
    assert list(system.bounded) == [False, True]


def test_limits_on_a_keyframed_joint_do_not_bound_it() -> None:
    system = PendulumSystem(base_and_bob(), PendulumParams(), [(-0.1, 0.1), None])
    assert np.isinf(system.limits).all()
    assert not system.bounded.any()


def test_equilibrium_hangs_every_centre_of_mass_below_its_pivot() -> None:
    """θ = −φ with φ = atan2(y0.x, y0.y); a joint whose centre of mass is on its pivot has no
    preferred angle and rests at 0."""
    pivot = np.array([0.0, 10.0])
    on_pivot = MassProperties(1.0, pivot.copy(), 3.0, pivot)
    ch = Character("c", [Joint("base", None, np.zeros(2)),
                         Joint("bob", 0, pivot, is_dynamic=True,
                               mass_properties=MassProperties(MASS, pivot + Y0, INERTIA, pivot)),
                         Joint("still", 0, pivot, is_dynamic=True, mass_properties=on_pivot)])
    eq = PendulumSystem(ch, PendulumParams()).equilibrium()
    assert eq[0] == 0.0 and eq[2] == 0.0
    assert float(eq[1]) == pytest.approx(-math.atan2(3.0, 40.0), rel=1e-15)
    # there the gravity torque vanishes
    assert hand_acceleration(float(eq[1]), np.zeros(2), 1000.0, False) == pytest.approx(0.0, abs=1e-12)


def test_the_damping_factor_and_its_overflow() -> None:
    """e^(−aτ); a negative damping so strong that e^(−aτ) overflows gives inf, not an error."""
    assert _decay(0.3, 0.01) == pytest.approx(math.exp(-0.003), rel=1e-15)
    assert _decay(-2.0, 0.5) == pytest.approx(math.e, rel=1e-15)
    assert _decay(-700.0, 1.0) == pytest.approx(math.exp(700.0), rel=1e-12)
    for exponent in (709.9, 750.0, 1.0e6):
        assert _decay(-exponent, 1.0) >= 1e307  # inf, or at least no OverflowError


def test_the_energy_of_a_single_pendulum() -> None:
    """E = I ω² / 2 − m g L cos(θ + φ) (potential −m g y.y, y = R(θ) y0, y down)."""
    g = 700.0
    for coupled in (True, False):
        system = PendulumSystem(base_and_bob(), PendulumParams(g=g, coupled=coupled))
        th, om = 0.9, -2.0
        r = rotation(th) @ Y0
        expected = 0.5 * INERTIA * om ** 2 - MASS * g * float(r[1])
        assert system.energy(np.array([0.0, th]), np.array([0.0, om])) == pytest.approx(expected, rel=1e-12)


# ----------------------------------------------------------------------------------------
# A coupled double pendulum against Euler-Lagrange equations written in the test.
P1, P2 = np.array([0.0, 10.0]), np.array([4.0, 50.0])
CHAIN_BODIES = [(2.0, np.array([1.0, 20.0]), 1102.0), (1.5, np.array([-2.0, 15.0]), 443.5)]  # m, y0, I (pivot)


def double_pendulum() -> Character:
    (m1, y1, i1), (m2, y2, i2) = CHAIN_BODIES
    return Character("d", [Joint("base", None, np.zeros(2)),
                           Joint("upper", 0, P1, is_dynamic=True, mass_properties=MassProperties(m1, P1 + y1, i1, P1)),
                           Joint("lower", 1, P2, is_dynamic=True, mass_properties=MassProperties(m2, P2 + y2, i2, P2))])


def com_positions(th: np.ndarray) -> list[np.ndarray]:
    """Centres of mass: x1 = P1 + R(θ1)·y1; the lower pivot P1 + R(θ1)·(P2 − P1), x2 = it + R(θ2)·y2."""
    (_, y1, _), (_, y2, _) = CHAIN_BODIES
    pivot2 = P1 + rotation(th[0]) @ (P2 - P1)
    return [P1 + rotation(th[0]) @ y1, pivot2 + rotation(th[1]) @ y2]


def hand_mass_matrix(th: np.ndarray) -> np.ndarray:
    """M = Σ m_k J_kᵀ J_k + diag(I_k − m_k |y_k|²) with J_k = ∂x_k/∂θ (d/dθ R(θ)v = R(θ + π/2)v)."""
    (m1, y1, i1), (m2, y2, i2) = CHAIN_BODIES
    j1 = np.column_stack([rotation(th[0] + math.pi / 2) @ y1, np.zeros(2)])
    j2 = np.column_stack([rotation(th[0] + math.pi / 2) @ (P2 - P1), rotation(th[1] + math.pi / 2) @ y2])
    return m1 * j1.T @ j1 + m2 * j2.T @ j2 + np.diag([i1 - m1 * y1 @ y1, i2 - m2 * y2 @ y2])


def hand_chain_acceleration(th: np.ndarray, om: np.ndarray, g: float, acc: np.ndarray) -> np.ndarray:
    """Euler-Lagrange: M θ'' + Ṁ θ' − ∂T/∂θ = −∂V/∂θ, V = Σ m_k (⟨a, x_k⟩ − g x_k.y) (y down, the
    pivot frame's pseudo-force −m a); the derivatives of M and V by central differences."""
    masses = [b[0] for b in CHAIN_BODIES]

    def potential(t: np.ndarray) -> float:
        return sum(m * (float(acc @ x) - g * float(x[1])) for m, x in zip(masses, com_positions(t)))

    h = 1e-6
    dm = []
    dv = np.zeros(2)
    for j in range(2):
        e = np.zeros(2)
        e[j] = h
        dm.append((hand_mass_matrix(th + e) - hand_mass_matrix(th - e)) / (2 * h))
        dv[j] = (potential(th + e) - potential(th - e)) / (2 * h)
    mdot_om = sum(dm[j] * om[j] for j in range(2)) @ om
    dt_dth = np.array([0.5 * om @ dm[i] @ om for i in range(2)])
    return np.linalg.solve(hand_mass_matrix(th), -dv - mdot_om + dt_dth)


def test_the_coupled_mass_matrix_and_energy() -> None:
    system = PendulumSystem(double_pendulum(), PendulumParams(g=900.0, coupled=True))
    [group] = system.groups
    assert group.joints == [1, 2]
    rng = np.random.default_rng(5)
    for _ in range(3):
        th, om = rng.uniform(-3, 3, 2), rng.uniform(-4, 4, 2)
        np.testing.assert_allclose(system.group_mass_matrix(group, th), hand_mass_matrix(th), rtol=1e-12)
        v = -900.0 * sum(m * float(x[1]) for (m, _, _), x in zip(CHAIN_BODIES, com_positions(th)))
        # the energy is relative to the top pivot: the constant Σ m g P1.y drops out
        v += 900.0 * (CHAIN_BODIES[0][0] + CHAIN_BODIES[1][0]) * P1[1]
        expected = 0.5 * om @ hand_mass_matrix(th) @ om + v
        got = system.energy(np.concatenate([[0.0], th]), np.concatenate([[0.0], om]))
        assert got == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("acc", [(0.0, 0.0), (250.0, -400.0)])
def test_the_coupled_chain_follows_the_euler_lagrange_equations(acc: tuple[float, float]) -> None:
    a = np.array(acc)
    system = PendulumSystem(double_pendulum(), PendulumParams(g=900.0, coupled=True))
    [group] = system.groups
    rng = np.random.default_rng(11)
    for _ in range(3):
        th, om = rng.uniform(-3, 3, 2), rng.uniform(-4, 4, 2)
        got = system.group_acceleration(group, th, om, a)
        np.testing.assert_allclose(got, hand_chain_acceleration(th, om, 900.0, a), rtol=1e-6, atol=1e-6)


def test_a_coupled_step_is_one_rk4_step_of_the_chain() -> None:
    a, tau, damping = np.array([120.0, 60.0]), 1.0 / 300.0, 0.4
    system = PendulumSystem(double_pendulum(), PendulumParams(g=900.0, coupled=True, damping=damping))
    th0, om0 = np.array([0.7, -0.4]), np.array([1.5, -2.0])
    theta, omega = np.concatenate([[0.0], th0]), np.concatenate([[0.0], om0])
    system.step(theta, omega, np.array([[0.0, 0.0], a, [9.0, 9.0]]), tau)

    def f(t: np.ndarray, w: np.ndarray) -> np.ndarray:
        return hand_chain_acceleration(t, w, 900.0, a)

    k1t, k1w = om0, f(th0, om0)
    k2t, k2w = om0 + 0.5 * tau * k1w, f(th0 + 0.5 * tau * k1t, om0 + 0.5 * tau * k1w)
    k3t, k3w = om0 + 0.5 * tau * k2w, f(th0 + 0.5 * tau * k2t, om0 + 0.5 * tau * k2w)
    k4t, k4w = om0 + tau * k3w, f(th0 + tau * k3t, om0 + tau * k3w)
    th1 = th0 + tau / 6.0 * (k1t + 2 * k2t + 2 * k3t + k4t)
    om1 = (om0 + tau / 6.0 * (k1w + 2 * k2w + 2 * k3w + k4w)) * math.exp(-damping * tau)
    np.testing.assert_allclose(theta[1:], th1, rtol=1e-9, atol=1e-10)
    np.testing.assert_allclose(omega[1:], om1, rtol=1e-7, atol=1e-7)
    assert theta[0] == 0.0


@pytest.mark.parametrize("as_function", [True, False])
def test_uncoupled_joints_each_swing_with_their_own_pivot(as_function: bool) -> None:
    """With ``coupled`` off every dynamic joint is a single pendulum about its own pivot, driven
    by the acceleration given for that joint (a table or a function of the joint)."""
    g, tau = 900.0, 1.0 / 300.0
    system = PendulumSystem(double_pendulum(), PendulumParams(g=g, coupled=False, damping=0.0))
    assert [grp.joints for grp in system.groups] == [[1], [2]]
    table = np.array([[0.0, 0.0], [100.0, -50.0], [-30.0, 80.0]])
    theta, omega = np.array([0.0, 0.3, -0.6]), np.array([0.0, 1.0, 0.5])
    system.step(theta, omega, (lambda j: table[j]) if as_function else table, tau)
    for k, (m, y0, inertia) in zip((1, 2), CHAIN_BODIES):
        th, om = (0.3, 1.0) if k == 1 else (-0.6, 0.5)
        dr = rotation(th + math.pi / 2) @ y0
        alpha = m * float((np.array([0.0, g]) - table[k]) @ dr) / inertia
        assert float(omega[k]) == pytest.approx(om + tau * alpha, rel=1e-12)
        assert float(theta[k]) == pytest.approx(th + tau * (om + tau * alpha), rel=1e-12)


@pytest.mark.parametrize(("side", "limits"), [(-1.0, (-0.01, 0.5)), (1.0, (-0.5, 0.01))])
def test_a_free_pendulum_bounces_off_either_limit(side: float, limits: tuple[float, float]) -> None:
    """No gravity, no pivot acceleration: θ = ω t. From 0 at ω = ±12 rad/s the joint reaches
    ±0.01 at t = 1/1200 s, leaves with ∓e·12 = ∓6 and ends the 1/600 s step at ±0.01 ∓ 6/1200."""
    system = PendulumSystem(base_and_bob(), PendulumParams(g=0.0, damping=0.0, restitution=0.5), [None, limits])
    theta, omega = np.zeros(2), np.array([0.0, side * 12.0])
    system.step(theta, omega, np.zeros((2, 2)), 1.0 / 600.0)
    [b] = system.bounces
    assert b.joint == 1 and b.limit == side * 0.01
    assert b.time == pytest.approx(1.0 / 1200.0, abs=1e-15)
    assert b.rate_before == pytest.approx(side * 12.0) and b.rate_after == pytest.approx(-side * 6.0)
    assert float(omega[1]) == pytest.approx(-side * 6.0, rel=1e-12)
    assert float(theta[1]) == pytest.approx(side * (0.01 - 6.0 / 1200.0), abs=1e-14)


@pytest.mark.parametrize("integrator", ["symplectic_euler", "leapfrog"])
def test_a_tiny_pendulum_runs_with_its_own_moment_and_length(integrator: str) -> None:
    """Moments and lengths below 1 (the handout's lengths / 1000) are real divisors: m = 0.5,
    y0 = (0.3, 0.4) (L² = 0.25), I = 0.2, the 1/L² forcing; run() against a hand loop."""
    pivot, y0, m, inertia, g, tau = np.array([1.0, 1.0]), np.array([0.3, 0.4]), 0.5, 0.2, 40.0, 0.01
    mp = MassProperties(m, pivot + y0, inertia, pivot)
    ch = Character("t", [Joint("base", None, np.zeros(2)), Joint("bob", 0, pivot, is_dynamic=True, mass_properties=mp)])
    a = np.array([3.0, -2.0])
    system = PendulumSystem(ch, PendulumParams(g=g, damping=0.0, point_mass_forcing=True, integrator=integrator))
    traj_t, _ = system.run(np.array([0.0, 0.5]), np.zeros(2), np.array([[0.0, 0.0], a]), 10, tau)

    def f(t: float) -> float:
        dr = rotation(t + math.pi / 2) @ y0
        return m * g * float(dr[1]) / inertia - float(a @ dr) / float(y0 @ y0)

    th, om = 0.5, 0.0
    for i in range(10):
        if integrator == "leapfrog":
            om += 0.5 * tau * f(th)
            th += tau * om
            om += 0.5 * tau * f(th)
        else:
            om += tau * f(th)
            th += tau * om
        assert float(traj_t[i, 1]) == pytest.approx(th, abs=1e-12)


def test_a_dynamic_child_bounces_off_its_dynamic_parent() -> None:
    """A dynamic root turning freely at 5 (no gravity) and its still dynamic child limited to
    ±0.01 relative to it: the local angle −5t reaches −0.01 at t = 0.002; relative rate −5
    becomes +2.5, the child's own 7.5 for the remaining 1/300 − 0.002 s: θ = 7.5/750 = 0.01."""
    mp0 = MassProperties(1.0, np.array([0.0, 5.0]), 40.0, np.zeros(2))
    mp1 = MassProperties(1.0, np.array([0.0, 15.0]), 40.0, np.array([0.0, 10.0]))
    ch = Character("r", [Joint("root", None, np.zeros(2), is_dynamic=True, mass_properties=mp0),
                         Joint("child", 0, np.array([0.0, 10.0]), is_dynamic=True, mass_properties=mp1)])
    system = PendulumSystem(ch, PendulumParams(g=0.0, damping=0.0, coupled=False, restitution=0.5),
                            [None, (-0.01, 0.01)])
    theta, omega = np.zeros(2), np.array([5.0, 0.0])
    system.step(theta, omega, lambda _j: np.zeros(2), 1.0 / 300.0)
    [b] = system.bounces
    assert b.joint == 1 and b.limit == -0.01
    assert b.time == pytest.approx(0.002, abs=1e-14)
    assert b.rate_before == pytest.approx(-5.0) and b.rate_after == pytest.approx(2.5)
    np.testing.assert_allclose(omega, [5.0, 7.5], rtol=1e-12)
    np.testing.assert_allclose(theta, [5.0 / 300.0, 0.01], atol=1e-14)


def test_a_pendulum_starting_outside_its_limit_is_put_back_on_it() -> None:
    """A joint whose local angle starts outside its limits (0.8 > hi = 0.5) is put on the
    limit at the step's start (joint_bounce: the event at h = 0), even when the free step
    would end inside: no gravity, moving in at ω = −40 over 0.01 s, it ends at
    0.5 − 0.4 = 0.1 (not the free 0.8 − 0.4 = 0.4), its rate unchanged and no bounce (it
    moves inward)."""
    system = PendulumSystem(base_and_bob(), PendulumParams(g=0.0, damping=0.0, restitution=0.5), [None, (-1.0, 0.5)])
    theta, omega = np.array([0.0, 0.8]), np.array([0.0, -40.0])
    system.step(theta, omega, np.zeros((2, 2)), 0.01)
    assert not system.bounces
    assert float(theta[1]) == pytest.approx(0.1, abs=1e-14)
    assert float(omega[1]) == -40.0


@pytest.mark.parametrize("point_mass", [False, True])
def test_a_joint_without_inertia_or_lever_does_not_swing(point_mass: bool) -> None:
    """single_acceleration: "A joint without inertia does not swing and one without a lever
    gets no point-mass forcing". A bob of mass 2 with its centre of mass on the pivot
    (y0 = 0: no lever) and moment 0, under gravity and a pivot acceleration, keeps its angle
    and rate (θ'' = 0) — beside an ordinary bob that does swing."""
    pivot = np.array([0.0, 10.0])
    dead = MassProperties(MASS, pivot.copy(), 0.0, pivot.copy())
    live = MassProperties(MASS, pivot + Y0, INERTIA, pivot.copy())
    ch = Character("z", [Joint("base", None, np.zeros(2)),
                         Joint("dead", 0, pivot, is_dynamic=True, mass_properties=dead),
                         Joint("live", 0, pivot, is_dynamic=True, mass_properties=live)])
    params = PendulumParams(g=1000.0, damping=0.0, point_mass_forcing=point_mass, integrator="symplectic_euler")
    system = PendulumSystem(ch, params)
    theta, omega = np.array([0.0, 0.3, 0.3]), np.array([0.0, 0.7, 0.7])
    acc = np.array([[0.0, 0.0], [40.0, -25.0], [40.0, -25.0]])
    system.step(theta, omega, acc, 0.01)
    assert float(theta[1]) == pytest.approx(0.3 + 0.01 * 0.7, abs=1e-15) and float(omega[1]) == 0.7
    assert np.isfinite(theta).all() and np.isfinite(omega).all()
    assert float(omega[2]) != 0.7
