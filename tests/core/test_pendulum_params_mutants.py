"""Pendulum constants against their sources (targets mutation-test survivors): the named
presets against the CMU handout (``/work/shared/seeds/003_*.txt``, Tasks 3A/3B, summarised in
``/work/shared/notes/cmu-animator.md`` section 9), the defaults and the blow-up threshold
against ``docs/decisions.md`` / ``docs/user-guide.md``, and the parameters' validation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.pendulum_params import (
    MIN_STEP,
    PRESETS,
    RUNAWAY_RATE,
    PendulumBlowUp,
    PendulumParams,
    check_state,
)
from qtanimator.core.rig2d import Character, Joint

FPS = 60.0  # the handout measures accelerations per frame², at 60 frames per second


def test_the_handout_preset_has_task_3b_constants() -> None:
    """Handout Task 3B: "g = 5000", "L is divided by 1000 before being used for anything",
    "acceleration due to joint rotation is scaled by 10000"; Task 3A: damping "a = 1"; the
    3B equation's forcing ⟨a, y⊥⟩ / L² (point mass); the reference program's moments; no
    coupling (multi-pendulums are extra credit); τ = 1/60 s (notes 9.1). Accelerations here
    are per s², the handout's per frame²: the scales carry 1/60²."""
    p = PRESETS["handout"]
    assert p.g == 5000.0
    assert p.length_scale == pytest.approx(1.0 / 1000.0, rel=1e-15)
    assert p.rotation_accel_scale * FPS ** 2 == pytest.approx(10000.0, rel=1e-12)
    assert p.accel_scale * FPS ** 2 == pytest.approx(1.0, rel=1e-12)  # translation: not scaled
    assert p.damping == 1.0
    assert p.point_mass_forcing is True
    assert p.inertia == "reference"
    assert p.coupled is False
    assert p.step == pytest.approx(1.0 / 60.0, rel=1e-15)
    assert p.integrator == "symplectic_euler"  # "integrate ... using the symplectic Euler method"
    assert p.restitution == 0.5  # docs/decisions.md: default 0.5 in every preset


def test_the_handout_3a_preset_has_task_3a_constants() -> None:
    """Task 3A: θ'' = −m g L sin θ / I with "g = 3", damping "a = 1", "pass in a zero vector
    for the acceleration", lengths unscaled, the reference program's moments, τ = 1/60 s."""
    p = PRESETS["handout_3a"]
    assert p.g == 3.0
    assert p.damping == 1.0
    assert p.accel_scale == 0.0 and p.rotation_accel_scale == 0.0
    assert p.length_scale == 1.0
    assert p.inertia == "reference"
    assert p.coupled is False
    assert p.step == pytest.approx(1.0 / 60.0, rel=1e-15)
    assert p.integrator == "symplectic_euler"


def test_the_physical_preset_is_the_documented_default() -> None:
    """docs/decisions.md: "physical (g = 3000 units/s², exact moments, coupled chains)",
    restitution 0.5; docs/user-guide.md: symplectic Euler by default, accelerations unscaled
    (units per second)."""
    p = PRESETS["physical"]
    assert p == PendulumParams()
    assert p.g == 3000.0
    assert p.inertia == "exact" and p.coupled is True and p.point_mass_forcing is False
    assert p.restitution == 0.5
    assert p.integrator == "symplectic_euler"
    assert p.length_scale == 1.0 and p.accel_scale == 1.0 and p.rotation_accel_scale == 1.0
    # docs/decisions.md: "A crossing that leaves and comes back within one step (≤ 1/600 s)"
    assert p.step == pytest.approx(1.0 / 600.0, rel=1e-15)


def test_the_handout_preset_gives_the_notes_clock_frequency() -> None:
    """notes 9.4: the clock pendulum (m = 28400.87, L = 296.63, reference I = 818059) has
    m g L / I = 51.5 s⁻² with the handout's g = 5000 and L / 1000 (the moment is not scaled)."""
    p = PRESETS["handout"]
    assert 28400.87 * p.g * 296.63 * p.length_scale / 818059.0 == pytest.approx(51.5, abs=0.05)


# ------------------------------------------------------------------ validation
def test_the_smallest_step_is_accepted_and_anything_smaller_refused() -> None:
    """MIN_STEP is 1e-5 s: 1,667 steps per 60 Hz frame (its comment)."""
    assert MIN_STEP == 1.0e-5
    assert 1.0 / 60.0 / MIN_STEP == pytest.approx(1666.7, abs=0.1)
    assert PendulumParams(step=1.0e-5).step == 1.0e-5
    for bad in (0.99e-5, 0.0, -1.0 / 600.0, math.inf, math.nan):
        with pytest.raises(ValueError, match="step"):
            PendulumParams(step=bad)


@pytest.mark.parametrize("value", [0.0, 0.25, 1.0])
def test_restitution_from_zero_to_one_is_accepted(value: float) -> None:
    assert PendulumParams(restitution=value).restitution == value


@pytest.mark.parametrize("value", [-0.01, 1.01, 1.5, 2.0, math.nan])
def test_restitution_outside_zero_to_one_is_refused(value: float) -> None:
    """0 stops a joint dead, 1 is a perfect bounce: above 1 every bounce adds energy."""
    with pytest.raises(ValueError, match="restitution"):
        PendulumParams(restitution=value)


@pytest.mark.parametrize("name", ["g", "damping", "length_scale", "accel_scale", "rotation_accel_scale"])
@pytest.mark.parametrize("value", [math.inf, -math.inf, math.nan])
def test_non_finite_constants_are_refused(name: str, value: float) -> None:
    with pytest.raises(ValueError, match=name):
        PendulumParams(**{name: value})


def test_finite_extremes_are_accepted() -> None:
    """Negative damping and zero gravity are allowed (the blow-up check reports the damping)."""
    p = PendulumParams(g=0.0, damping=-0.5, length_scale=1e-6, accel_scale=0.0, rotation_accel_scale=-2.0)
    assert (p.g, p.damping, p.rotation_accel_scale) == (0.0, -0.5, -2.0)


def test_unknown_inertia_and_integrator_are_refused() -> None:
    with pytest.raises(ValueError, match="inertia"):
        PendulumParams(inertia="approximate")
    with pytest.raises(ValueError, match="integrator"):
        PendulumParams(integrator="euler")
    for name in ("symplectic_euler", "leapfrog", "rk4"):
        assert PendulumParams(integrator=name).integrator == name
    assert PendulumParams(inertia="reference").inertia == "reference"


def test_dict_round_trip_ignores_unknown_keys() -> None:
    p = PendulumParams(g=12.5, damping=0.0, restitution=1.0, integrator="rk4", coupled=False)
    d = p.to_dict()
    assert d["g"] == 12.5 and d["integrator"] == "rk4" and d["coupled"] is False
    assert PendulumParams.from_dict(d) == p
    q = PendulumParams.from_dict({"g": 10.0, "colour": "red"})
    assert q == PendulumParams(g=10.0)


# ------------------------------------------------------------------ blow-up check
def two_joints() -> Character:
    return Character("c", [Joint("root", None, np.zeros(2)), Joint("tail", 0, np.array([1.0, 0.0]))])


def test_the_runaway_rate_is_the_documented_1000() -> None:
    """docs/decisions.md: "a non-finite or runaway rate above 1000 rad/s" is a blow-up:
    1000 itself is not, 1000.5 is (either sign)."""
    ch, p = two_joints(), PendulumParams()
    assert RUNAWAY_RATE == 1000.0
    theta = np.zeros(2)
    assert check_state(ch, p, theta, np.array([0.0, 1000.0]), 0.0) is None
    assert check_state(ch, p, theta, np.array([-1000.0, 999.9]), 0.0) is None
    for w in (1000.5, -1000.5):
        e = check_state(ch, p, theta, np.array([0.0, w]), 0.5)
        assert isinstance(e, PendulumBlowUp)
        assert e.joint == "tail" and e.time == 0.5 and e.parameter == "step"
        assert "spinning at 1e+03 rad/s" in e.message


def test_a_sound_state_is_no_blow_up() -> None:
    assert check_state(two_joints(), PendulumParams(), np.array([3.0, -50.0]), np.array([-2.0, 999.0]), 1.0) is None


@pytest.mark.parametrize("bad", ["theta_nan", "theta_inf", "omega_nan", "omega_inf"])
def test_non_finite_states_are_blow_ups(bad: str) -> None:
    theta, omega = np.zeros(2), np.zeros(2)
    arr = theta if bad.startswith("theta") else omega
    arr[1] = math.nan if bad.endswith("nan") else -math.inf
    e = check_state(two_joints(), PendulumParams(), theta, omega, 2.25)
    assert e is not None and e.joint == "tail" and e.time == 2.25
    assert "not a finite number" in e.message and "'tail'" in e.message and "2.250 s" in e.message


def test_the_first_joint_that_ran_away_is_named() -> None:
    e = check_state(two_joints(), PendulumParams(), np.array([math.nan, 0.0]), np.array([0.0, 5000.0]), 0.0)
    assert e is not None and e.joint == "root"
    assert "not a finite number" in e.message


@pytest.mark.parametrize(("damping", "parameter"), [(-0.1, "damping"), (-1e-12, "damping"), (0.0, "step"),
                                                    (0.3, "step"), (5.0, "step")])
def test_the_advice_names_negative_damping_else_the_step(damping: float, parameter: str) -> None:
    """A negative damping pumps energy in; zero or positive damping cannot, so the step is to blame."""
    p = PendulumParams(damping=damping, step=1.0 / 120.0, g=250.0)
    e = check_state(two_joints(), p, np.zeros(2), np.array([0.0, 2000.0]), 0.0)
    assert e is not None and e.parameter == parameter
    assert isinstance(e, RuntimeError)
    if parameter == "step":
        assert "step of 0.00833333 s" in e.message and "gravity 250" in e.message
    else:
        assert "damping is negative" in e.message
