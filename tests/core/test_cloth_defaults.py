"""Default cloth settings that hold (issue 22): the default integrator and step count run 10 s
at 24, 30 and 60 fps without a blow-up or a non-finite value, for the default cloth, the demo
flag and the stiffest values the cloth panel allows; energy stays bounded without wind; the
explicit integrator's automatic substeps follow its stability bound."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from qtanimator.core.cloth import (
    AUTO_SUBSTEPS,
    IMPLICIT_MAX_STEP,
    MAX_AUTO_SUBSTEPS,
    Cloth,
    ClothBlowUp,
    ClothParams,
)
from qtanimator.core.cloth_kernels import HAVE_NUMBA

REPO = Path(__file__).resolve().parents[2]
FPS = (24, 30, 60)


def panel_float_ranges() -> dict[str, tuple[float, float, float, int]]:
    """The cloth panel's field ranges: the parameter schema's (document/parameters.py CLOTH,
    Qt-free), which the panel's fields are built from."""
    from qtanimator.document.parameters import CLOTH

    return {k: (float(p.minimum), float(p.maximum), float(p.step), int(p.decimals))  # type: ignore[arg-type]
            for k, p in CLOTH.items() if p.kind == "float"}


RANGES = panel_float_ranges()
#: The largest spring stiffness and damping the cloth panel allows.
PANEL_MAX_STIFFNESS = max(RANGES[f"{kind}_stiffness"][1] for kind in ("structural", "shear", "bend"))
PANEL_MAX_DAMPING = max(RANGES[f"{kind}_damping"][1] for kind in ("structural", "shear", "bend"))
STIFFEST = {f"{kind}_stiffness": PANEL_MAX_STIFFNESS for kind in ("structural", "shear", "bend")}
MOST_DAMPED = {f"{kind}_damping": PANEL_MAX_DAMPING for kind in ("structural", "shear", "bend")}
#: The default cloth laid flat, so that it falls and swings from its two pinned corners.
FLAT = {"orientation": (-math.pi / 2.0, 0.0, 0.0), "origin": (0.0, 2.0, -0.5)}


def demo_flag() -> ClothParams:
    """The demo's flag (scenes/demo/demo.qtanim) with the default integrator and step count."""
    data = json.loads((REPO / "scenes" / "demo" / "demo.qtanim").read_text(encoding="utf-8"))
    (props,) = [a["properties"] for a in data["assets"] if a["kind"] == "cloth" and a["id"] == "flag"]
    defaults = ClothParams()
    return ClothParams.from_dict(props).replace(integrator=defaults.integrator, substeps=defaults.substeps)


def cases() -> dict[str, ClothParams]:
    flag = demo_flag()
    return {
        "default cloth": ClothParams(),
        "default cloth, falling": ClothParams(**FLAT),  # type: ignore[arg-type]
        "demo flag": flag,
        "stiffest, falling": ClothParams(**STIFFEST, **FLAT),  # type: ignore[arg-type]
        "stiffest demo flag": flag.replace(**STIFFEST),
        "stiffest and most damped demo flag": flag.replace(**STIFFEST, **MOST_DAMPED),
    }


def run_seconds(params: ClothParams, fps: int, seconds: float = 10.0) -> Cloth:
    cloth = Cloth(params)
    for _ in range(round(seconds * fps)):
        cloth.step(1.0 / fps)  # a ClothBlowUp fails the test
        assert np.isfinite(cloth.positions).all() and np.isfinite(cloth.velocities).all()
    return cloth


def test_the_defaults_are_the_implicit_integrator_with_automatic_steps() -> None:
    p = ClothParams()
    assert p.integrator == "implicit" and p.substeps == AUTO_SUBSTEPS == 0
    cloth = Cloth(p)
    assert [cloth.substeps_for(1.0 / fps) for fps in FPS] == [3, 2, 1]  # steps of at most 1/60 s
    assert IMPLICIT_MAX_STEP == pytest.approx(1.0 / 60.0)
    # "auto" is accepted from files and the command line, and stored as 0.
    assert ClothParams.from_dict({"substeps": "auto"}).substeps == 0
    assert ClothParams.from_dict(json.loads(json.dumps(p.to_dict()))) == p


#: Every case at every rate; the most damped one (an extra) at 60 fps only, whose 1/60 s step
#: is the longest the defaults take (30 fps takes two of them, 24 fps three of 1/72 s).
RUNS = [(name, fps) for name in cases() if "damped" not in name for fps in FPS] + [
    ("stiffest and most damped demo flag", 60)]


@pytest.mark.parametrize("name,fps", RUNS)
def test_defaults_run_ten_seconds_without_blowing_up(name: str, fps: int) -> None:
    params = cases()[name]
    cloth = run_seconds(params, fps)
    pins = cloth.pinned_indices
    np.testing.assert_array_equal(cloth.positions[pins], cloth.rest_positions[pins])
    size = math.hypot(params.width, params.height)
    assert np.linalg.norm(cloth.positions - cloth.rest_positions, axis=1).max() < 2.0 * size
    assert cloth.stretch().max() < 0.5


def energy(cloth: Cloth) -> float:
    """Kinetic + gravitational + spring energy (J)."""
    p = cloth.params
    m = cloth.particle_mass
    k = np.array([p.structural_stiffness, p.shear_stiffness, p.bend_stiffness])[cloth.spring_kinds]
    stretch = cloth.spring_lengths() - cloth.rest_lengths
    return float(0.5 * m * np.sum(cloth.velocities ** 2) + m * p.gravity * np.sum(cloth.positions[:, 1])
                 + 0.5 * np.sum(k * stretch ** 2))


@pytest.mark.parametrize("integrator", ["implicit", "symplectic"])
@pytest.mark.parametrize("fps", FPS)
def test_energy_stays_bounded_without_wind(integrator: str, fps: int) -> None:
    """A falling cloth without wind only loses energy (damping, drag, the integrator's own
    loss): it never rises above the energy it started with, and it comes to rest."""
    cloth = Cloth(ClothParams(integrator=integrator, wind=(0.0, 0.0, 0.0), turbulence=0.0, **FLAT))  # type: ignore[arg-type]
    e0 = energy(cloth)
    drop_scale = cloth.params.total_mass * cloth.params.gravity * cloth.params.height  # J
    highest = -math.inf
    at_two_seconds = math.nan
    for frame in range(1, 10 * fps + 1):
        cloth.step(1.0 / fps)
        highest = max(highest, energy(cloth) - e0)
        if frame == 2 * fps:
            at_two_seconds = energy(cloth)
    assert highest <= 1e-3 * drop_scale
    assert energy(cloth) < e0 - 0.2 * drop_scale          # it fell and hangs
    assert energy(cloth) < at_two_seconds                  # and keeps losing energy
    if integrator == "implicit":                           # backward Euler damps the swing out
        assert np.abs(cloth.velocities).max() < 0.05


@pytest.mark.parametrize("fps", FPS)
@pytest.mark.parametrize("name", ["default cloth", "demo flag"])
def test_explicit_substeps_follow_the_stability_bound(name: str, fps: int) -> None:
    params = cases()[name].replace(integrator="symplectic")
    cloth = Cloth(params)
    expected = cloth.stable_substeps(1.0 / fps)
    assert cloth.substeps_for(1.0 / fps) == expected > 1
    run_seconds(params, fps)
    # A number set by hand is used as it is (here one that is too small: it says so).
    by_hand = Cloth(params.replace(substeps=1, **STIFFEST))
    assert by_hand.substeps_for(1.0 / fps) == 1
    with pytest.raises(ClothBlowUp) as info:
        for _ in range(fps):
            by_hand.step(1.0 / fps)
    assert info.value.parameter == "substeps" and "(or 0, automatic)" in info.value.message


def test_explicit_stiff_springs_follow_the_bound_too() -> None:
    """Springs of 1e6 N/m need about 1900 explicit substeps per 1/24 s frame: slow, stable."""
    stiff = {f"{kind}_stiffness": 1.0e6 for kind in ("structural", "shear", "bend")}
    params = ClothParams(integrator="symplectic", **stiff, **FLAT)  # type: ignore[arg-type]
    cloth = Cloth(params)
    substeps = cloth.substeps_for(1.0 / 24.0)
    assert 1000 < substeps <= MAX_AUTO_SUBSTEPS
    run_seconds(params, 24, seconds=0.5 if HAVE_NUMBA else 0.125)


@pytest.mark.parametrize("damped", [False, True])
def test_explicit_with_impossible_settings_says_to_use_the_implicit_integrator(damped: bool) -> None:
    """The panel's stiffest springs (or the most damped ones) would need more explicit substeps
    than MAX_AUTO_SUBSTEPS: the cloth says so before stepping."""
    extra = MOST_DAMPED if damped else {}
    cloth = Cloth(ClothParams(integrator="symplectic", **STIFFEST, **extra))  # type: ignore[arg-type]
    assert cloth.substeps_for(1.0 / 24.0) > MAX_AUTO_SUBSTEPS
    before = cloth.positions.copy()
    with pytest.raises(ClothBlowUp) as info:
        cloth.step(1.0 / 24.0)
    assert info.value.parameter == "integrator" and "'implicit'" in info.value.message
    assert np.array_equal(cloth.positions, before)
    Cloth(cloth.params.replace(integrator="implicit")).step(1.0 / 24.0)  # fine


def test_a_light_cloth_in_strong_wind_takes_more_implicit_steps() -> None:
    """Drag is explicit in the implicit step: the automatic step count follows its bound."""
    flag = demo_flag()
    assert Cloth(flag).substeps_for(1.0 / 60.0) == 1
    light = flag.replace(total_mass=0.001)
    cloth = Cloth(light)
    assert cloth.substeps_for(1.0 / 60.0) > 50
    run_seconds(light, 60, seconds=0.25 if HAVE_NUMBA else 0.1)
