"""Cloth parameters (cloth_params.py): validation at the documented boundaries (zero is allowed
for every "≥ 0" setting), the editor ranges against the defaults, and the JSON round trip of
every field kind (ints, "auto" substeps, strings, vectors, spheres, pins)."""

from __future__ import annotations

from dataclasses import fields

import pytest

from qtanimator.core.cloth_params import AUTO_SUBSTEPS, ClothParams, Sphere
from qtanimator.document.parameters import CLOTH

NON_NEGATIVE = ("structural_stiffness", "structural_damping", "shear_stiffness", "shear_damping", "bend_stiffness",
                "bend_damping", "drag_coefficient", "air_density", "turbulence", "ground_restitution",
                "ground_friction", "collision_margin")


def _number_ranges() -> dict[str, tuple[float, float]]:
    """The schema's (document/parameters.py) range of every numeric cloth setting."""
    return {key: (p.minimum, p.maximum) for key, p in CLOTH.items()
            if p.minimum is not None and p.maximum is not None and p.kind not in ("vector", "list")}


def test_every_default_lies_inside_its_editor_range() -> None:
    """An editor must be able to show the default value: lo ≤ default ≤ hi, lo < hi."""
    defaults = ClothParams()
    ranges = _number_ranges()
    assert {"rows", "cols", "ground_restitution", "substeps", "gravity"} <= set(ranges)
    for name, (lo, hi) in ranges.items():
        assert lo < hi, name
        assert lo <= getattr(defaults, name) <= hi, name


def test_every_range_end_is_a_valid_setting() -> None:
    for name, (lo, hi) in _number_ranges().items():
        for value in (lo, hi):
            ClothParams(**{name: int(value) if name in ("rows", "cols", "substeps", "turbulence_seed")
                           else value}).validate()


@pytest.mark.parametrize("name", NON_NEGATIVE)
def test_zero_is_allowed_and_negative_refused(name: str) -> None:
    ClothParams(**{name: 0.0}).validate()  # type: ignore[arg-type]
    with pytest.raises(ValueError):
        ClothParams(**{name: -0.001}).validate()  # type: ignore[arg-type]
    with pytest.raises(ValueError):
        ClothParams(**{name: float("inf")}).validate()  # type: ignore[arg-type]


def test_integrators_substeps_and_pins_are_checked() -> None:
    for integrator in ("symplectic", "implicit"):
        ClothParams(integrator=integrator).validate()
    with pytest.raises(ValueError):
        ClothParams(integrator="verlet").validate()
    ClothParams(substeps=0).validate()
    ClothParams(substeps=1).validate()
    with pytest.raises(ValueError):
        ClothParams(substeps=-1).validate()
    ClothParams(rows=3, cols=3, pin_mode="custom", custom_pins=[0, 8]).validate()
    with pytest.raises(ValueError):
        ClothParams(rows=3, cols=3, pin_mode="custom", custom_pins=[9]).validate()
    with pytest.raises(ValueError):
        ClothParams(rows=3, cols=3, pin_mode="custom", custom_pins=[-1]).validate()
    with pytest.raises(ValueError):
        ClothParams(pin_mode="middle").validate()


def test_sphere_checks_allow_small_radii_and_zero_coefficients() -> None:
    ClothParams(spheres=[Sphere((0.0, 1.0, 0.0), 0.05, 0.0, 0.0)]).validate()
    ClothParams(spheres=[Sphere((0.0, 1.0, 0.0), 0.5)]).validate()
    for bad in (Sphere((0.0, 0.0, 0.0), 0.0), Sphere((0.0, 0.0, 0.0), 0.5, -0.1, 0.0),
                Sphere((0.0, 0.0, 0.0), 0.5, 0.0, -0.1), Sphere((0.0, 0.0, 0.0), float("inf"))):
        with pytest.raises(ValueError):
            ClothParams(spheres=[bad]).validate()


def test_sphere_from_a_dict_a_sequence_and_a_sphere() -> None:
    assert Sphere.from_value({"centre": [1, 2, 3], "radius": 0.5}) == Sphere((1.0, 2.0, 3.0), 0.5, 0.2, 0.3)
    assert Sphere.from_value({"center": (1, 2, 3), "radius": 2, "restitution": 0.6, "friction": 0.1}) == Sphere(
        (1.0, 2.0, 3.0), 2.0, 0.6, 0.1)
    assert Sphere.from_value(([0, 1, 0], 0.4)) == Sphere((0.0, 1.0, 0.0), 0.4)
    assert Sphere.from_value(([0, 1, 0], 0.4, 0.7)) == Sphere((0.0, 1.0, 0.0), 0.4, 0.7, 0.3)
    s = Sphere((0.0, 1.0, 0.0), 0.4, 0.5, 0.6)
    assert Sphere.from_value(s) == s
    assert Sphere.from_value(s.to_dict()) == s
    with pytest.raises(ValueError):
        Sphere.from_value(([0, 1, 0],))
    with pytest.raises(ValueError):
        Sphere.from_value(([0, 1], 0.4))


def test_a_full_round_trip_through_json_data() -> None:
    p = ClothParams(rows=5, cols=6, width=1.5, wind=(1.0, 0.0, -2.0), turbulence=0.5, turbulence_seed=3,
                    ground_enabled=False, spheres=[Sphere((0.0, 1.0, 0.0), 0.3, 0.1, 0.2)], pin_mode="custom",
                    custom_pins=[0, 7], integrator="symplectic", substeps=12, origin=(0.0, 1.0, 2.0),
                    orientation=(0.1, 0.2, 0.3))
    data = p.to_dict()
    assert data["wind"] == [1.0, 0.0, -2.0] and data["custom_pins"] == [0, 7]
    assert data["spheres"] == [{"centre": [0.0, 1.0, 0.0], "radius": 0.3, "restitution": 0.1, "friction": 0.2}]
    q = ClothParams.from_dict(data)
    assert q == p
    for f in fields(q):
        assert type(getattr(q, f.name)) is type(getattr(p, f.name)), f.name


def test_from_dict_coerces_each_kind_of_field() -> None:
    q = ClothParams.from_dict({"rows": 4.0, "substeps": " Auto ", "pin_mode": "none", "integrator": "implicit",
                               "wind": [1, 2, 3], "ground_enabled": 0, "custom_pins": [1.0], "width": "2.5",
                               "spheres": [[[0, 1, 0], 0.2]], "unknown": 5})
    assert q.rows == 4 and isinstance(q.rows, int)
    assert q.substeps == AUTO_SUBSTEPS
    assert q.pin_mode == "none" and q.integrator == "implicit"
    assert q.wind == (1.0, 2.0, 3.0)
    assert q.ground_enabled is False
    assert q.custom_pins == [1]
    assert q.width == 2.5
    assert q.spheres == [Sphere((0.0, 1.0, 0.0), 0.2)]
    assert ClothParams.from_dict({"substeps": 7}).substeps == 7
    for bad in ({"rows": 4.5}, {"rows": True}, {"width": "wide"}, {"custom_pins": [1.5]}, {"wind": [1, 2]},
                {"wind": 3}):
        with pytest.raises(ValueError):
            ClothParams.from_dict(bad)


def test_replace_coerces_validates_and_refuses_unknown_names() -> None:
    p = ClothParams()
    q = p.replace(substeps="auto", wind=[0, 0, 1], rows=10)
    assert q.substeps == 0 and q.wind == (0.0, 0.0, 1.0) and q.rows == 10
    assert p.rows == 20
    with pytest.raises(ValueError):
        p.replace(colour="red")
    with pytest.raises(ValueError):
        p.replace(rows=1)


def test_particle_mass_and_per_kind_settings() -> None:
    p = ClothParams(rows=4, cols=5, total_mass=2.0, shear_stiffness=77.0, bend_damping=0.125)
    assert p.particle_mass == pytest.approx(0.1, rel=1e-15)
    assert p.stiffness("shear") == 77.0
    assert p.damping("bend") == 0.125


def test_the_defaults_are_the_user_guides() -> None:
    """docs/user-guide.md, "Defaults": a new cloth is 20 × 20 particles, 1 m × 1 m and 1 kg;
    springs 200 / 100 / 20 N/m with damping 0.4 / 0.2 / 0.05 N·s/m; drag coefficient 1, air
    density 1.225 kg/m³, no wind, gravity 9.8 m/s², ground at height 0, top corners pinned,
    integrator implicit, substeps auto (0)."""
    p = ClothParams()
    assert (p.rows, p.cols) == (20, 20)
    assert (p.width, p.height, p.total_mass) == (1.0, 1.0, 1.0)
    assert (p.structural_stiffness, p.shear_stiffness, p.bend_stiffness) == (200.0, 100.0, 20.0)
    assert (p.structural_damping, p.shear_damping, p.bend_damping) == (0.4, 0.2, 0.05)
    assert (p.drag_coefficient, p.air_density, p.wind) == (1.0, 1.225, (0.0, 0.0, 0.0))
    assert (p.gravity, p.ground_enabled, p.ground_height) == (9.8, True, 0.0)
    assert (p.pin_mode, p.integrator, p.substeps) == ("top_corners", "implicit", AUTO_SUBSTEPS)
    assert AUTO_SUBSTEPS == 0


def test_the_ground_restitution_range_never_gains_energy() -> None:
    """A restitution above 1 would make a bounce faster than the impact (energy from nowhere);
    the document schema (document/parameters.py) caps it at 1 as well."""
    assert (CLOTH["ground_restitution"].minimum, CLOTH["ground_restitution"].maximum) == (0.0, 1.0)
