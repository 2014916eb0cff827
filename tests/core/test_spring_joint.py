"""Spring joints (issue 18 item 4): a joint that follows its keyed angle through a damped
spring. At rest on constant keys it stays on them exactly; a step in the keys gives the
closed-form damped response; the parent turning drags it (inertia); limits bounce."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.rig2d import Character, Joint, Shape
from qtanimator.core.spring_joint import SPRING_PRESETS, SpringParams, SpringSystem, expm, propagator

TAU = 1.0 / 600.0


def tail_character(spring_root: bool = False) -> Character:
    """A keyframed base and a spring tail (a bar hanging below the base's pivot)."""
    bar = Shape(np.array([[-2.0, 0.0], [2.0, 0.0], [2.0, 60.0], [-2.0, 60.0]]), True)
    return Character("c", [Joint("base", None, np.zeros(2), is_spring=spring_root),
                           Joint("tail", 0, np.zeros(2), is_spring=True, shapes=[bar])])


def run(system: SpringSystem, keys: np.ndarray, steps: int, theta: np.ndarray | None = None,
        base_rate: float = 0.0, base_acc: float = 0.0, translation_acc: tuple[float, float] = (0.0, 0.0)
        ) -> list[float]:
    """Step with the tail's key ``keys[i]`` at sub-step i (constant within it); the base
    turns at ``base_rate`` with ``base_acc``. Returns the tail's angle after each step."""
    theta = np.zeros(2) if theta is None else theta
    omega = np.zeros(2)
    out = []
    for i in range(steps):
        t_mid = (i + 0.5) * TAU
        key = np.array([base_rate * t_mid + 0.5 * base_acc * t_mid ** 2, keys[i]])
        rate = np.array([base_rate + base_acc * t_mid, 0.0])
        acc = np.array([base_acc, 0.0])
        system.step(theta, omega, TAU, key, rate, acc, np.zeros(2), np.zeros(2), np.array(translation_acc))
        out.append(float(theta[1]))
    return out


def test_at_rest_on_constant_keys_it_follows_them_exactly() -> None:
    for params in (SpringParams(), SPRING_PRESETS["stiff"], SpringParams(stiffness=0.0, damping=0.0)):
        system = SpringSystem(tail_character(), params)
        key = 0.4321
        out = run(system, np.full(1800, key), 1800, theta=np.array([0.0, key]))
        assert max(abs(v - key) for v in out) == 0.0


@pytest.mark.parametrize("k,c", [(120.0, 5.0), (1000.0, 30.0), (50.0, 0.0)])
def test_a_step_in_the_keys_gives_the_damped_response(k: float, c: float) -> None:
    """θ(t) = A·(1 − e^(−σt)(cos ω_d t + σ/ω_d·sin ω_d t)), σ = c/2, ω_d = √(k − σ²)."""
    system = SpringSystem(tail_character(), SpringParams(stiffness=k, damping=c))
    amplitude, before = 0.7, 120
    keys = np.r_[np.zeros(before), np.full(1200, amplitude)]
    out = run(system, keys, len(keys))
    assert out[:before] == [0.0] * before
    sigma = c / 2.0
    wd = math.sqrt(k - sigma ** 2)
    for i in range(before, len(keys)):
        t = (i + 1 - before) * TAU
        exact = amplitude * (1.0 - math.exp(-sigma * t) * (math.cos(wd * t) + sigma / wd * math.sin(wd * t)))
        assert out[i] == pytest.approx(exact, abs=1e-9)


def test_linear_keys_lag_by_c_over_k_times_the_rate() -> None:
    """θ'' = k(u − θ) − cθ' on a ramp u = v·t settles at u − c·v/k (the model's drag)."""
    k, c, v = 400.0, 20.0, 0.5
    system = SpringSystem(tail_character(), SpringParams(stiffness=k, damping=c, inertia=0.0))
    theta, omega = np.zeros(2), np.zeros(2)
    for i in range(3000):
        t_mid = (i + 0.5) * TAU
        system.step(theta, omega, TAU, np.array([0.0, v * t_mid]), np.array([0.0, v]), np.zeros(2),
                    np.zeros(2), np.zeros(2), np.zeros(2))
    assert theta[1] == pytest.approx(v * 3000 * TAU - c * v / k, abs=1e-9)
    assert omega[1] == pytest.approx(v, abs=1e-9)


def test_the_parent_turning_drags_the_joint_only_with_inertia() -> None:
    keys = np.zeros(600)
    rigid = SpringSystem(tail_character(), SpringParams(inertia=0.0))
    assert run(rigid, keys, 600, base_rate=0.0, base_acc=3.0) == [0.0] * 600
    loose = SpringSystem(tail_character(), SpringParams(inertia=1.0))
    lag = run(loose, keys, 600, base_acc=3.0)
    # The base speeds up counter-clockwise: the tail is left behind (negative local angle),
    # about −β·Θ''/k once it has settled.
    assert min(lag) < -0.01
    assert lag[-1] == pytest.approx(-3.0 / 120.0, rel=0.05)


def test_the_body_accelerating_swings_the_joint() -> None:
    """A push to the right (+x) leaves a part hanging below its pivot behind (to the left: a
    clockwise, negative angle on screen, y down), as a pendulum does; without inertia it rides along."""
    loose = SpringSystem(tail_character(), SpringParams(inertia=1.0))
    out = run(loose, np.zeros(300), 300, translation_acc=(2000.0, 0.0))
    assert out[-1] < -0.05
    rigid = SpringSystem(tail_character(), SpringParams(inertia=0.0))
    assert run(rigid, np.zeros(300), 300, translation_acc=(2000.0, 0.0)) == [0.0] * 300


def test_limits_bounce_a_spring_too() -> None:
    system = SpringSystem(tail_character(), SpringParams(stiffness=400.0, damping=0.0),
                          limits=[None, (-0.2, 0.3)], restitution=0.5)
    keys = np.full(1200, 0.29)
    theta, omega = np.zeros(2), np.zeros(2)
    seen = []
    for i in range(1200):
        system.step(theta, omega, TAU, np.array([0.0, keys[i]]), np.zeros(2), np.zeros(2), np.zeros(2),
                    np.zeros(2), np.zeros(2))
        assert -0.2 - 1e-12 <= theta[1] <= 0.3 + 1e-12
        seen += system.bounces
    assert seen
    for b in seen:
        assert b.rate_after == pytest.approx(-0.5 * b.rate_before, abs=1e-12)


def test_parameters_and_presets() -> None:
    assert set(SPRING_PRESETS) == {"soft", "stiff"}
    assert SPRING_PRESETS["soft"] == SpringParams()
    assert SpringParams.from_dict({"mix": 0.25, "unknown": 1}).mix == 0.25
    for bad in ({"stiffness": -1.0}, {"damping": -0.1}, {"mix": 1.5}, {"inertia": -0.5}, {"stiffness": math.inf}):
        with pytest.raises(ValueError):
            SpringParams(**bad)


def test_expm_matches_a_closed_form() -> None:
    a = np.array([[0.0, 1.0], [-4.0, 0.0]])  # e^(At): rotation at ω = 2
    t = 0.7
    np.testing.assert_allclose(expm(a * t), [[math.cos(2 * t), math.sin(2 * t) / 2], [-2 * math.sin(2 * t),
                                                                                      math.cos(2 * t)]], atol=1e-14)
    e = propagator(120.0, 5.0, TAU)
    np.testing.assert_allclose(e @ expm(np.zeros((3, 3))), e)
