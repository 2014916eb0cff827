"""Cloth parameters: :class:`ClothParams` (the cloth asset's properties), sphere colliders,
their validation and their plain-JSON form, and the names and ranges the editors offer.

The simulation that uses them is :mod:`qtanimator.core.cloth` (which re-exports these names).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields, replace
from typing import Any, NamedTuple

__all__ = ["AUTO_SUBSTEPS", "INTEGRATORS", "PIN_MODES", "SPRING_KINDS", "ClothParams", "Sphere",
           "Vec3"]

PIN_MODES = ("top_corners", "top_edge", "none", "custom")
INTEGRATORS = ("symplectic", "implicit")
SPRING_KINDS = ("structural", "shear", "bend")

#: ``substeps`` = AUTO_SUBSTEPS lets the cloth choose its steps per frame (see :mod:`qtanimator.core.cloth`).
AUTO_SUBSTEPS = 0

Vec3 = tuple[float, float, float]


class Sphere(NamedTuple):
    """A static sphere collider: ``(centre, radius, restitution, friction)``."""

    centre: Vec3
    radius: float
    restitution: float = 0.2
    friction: float = 0.3

    def to_dict(self) -> dict[str, Any]:
        return {"centre": [float(v) for v in self.centre], "radius": float(self.radius),
                "restitution": float(self.restitution), "friction": float(self.friction)}

    @staticmethod
    def from_value(value: Any) -> Sphere:
        """A sphere from a dict (``to_dict`` form), a Sphere, or a ``(centre, radius, e, mu)`` sequence."""
        if isinstance(value, Mapping):
            centre = value.get("centre", value.get("center"))
            return Sphere(_vec3(centre, "sphere centre"), float(value["radius"]),
                          float(value.get("restitution", 0.2)), float(value.get("friction", 0.3)))
        items = list(value)
        if len(items) < 2:
            raise ValueError("a sphere needs at least a centre and a radius")
        rest = [float(v) for v in items[2:4]]
        return Sphere(_vec3(items[0], "sphere centre"), float(items[1]), *rest)


def _vec3(value: Any, what: str) -> Vec3:
    try:
        a = [float(v) for v in value]
    except TypeError as exc:
        raise ValueError(f"{what} must be three numbers") from exc
    if len(a) != 3:
        raise ValueError(f"{what} must be three numbers, got {len(a)}")
    return (a[0], a[1], a[2])


@dataclass
class ClothParams:
    """Everything that defines a cloth simulation (the cloth asset's properties).

    Units: metres, kilograms, seconds, newtons. Stiffness in N/m, damping in N·s/m.
    """

    rows: int = 20
    cols: int = 20
    width: float = 1.0
    height: float = 1.0
    total_mass: float = 1.0
    structural_stiffness: float = 200.0
    structural_damping: float = 0.4
    shear_stiffness: float = 100.0
    shear_damping: float = 0.2
    bend_stiffness: float = 20.0
    bend_damping: float = 0.05
    drag_coefficient: float = 1.0
    air_density: float = 1.225
    wind: Vec3 = (0.0, 0.0, 0.0)
    turbulence: float = 0.0
    turbulence_seed: int = 0
    gravity: float = 9.8
    ground_enabled: bool = True
    ground_height: float = 0.0
    ground_restitution: float = 0.1
    ground_friction: float = 0.3
    spheres: list[Sphere] = field(default_factory=list)
    collision_margin: float = 0.005
    pin_mode: str = "top_corners"
    custom_pins: list[int] = field(default_factory=list)
    integrator: str = "implicit"
    substeps: int = AUTO_SUBSTEPS
    origin: Vec3 = (0.0, 2.0, 0.0)
    orientation: Vec3 = (0.0, 0.0, 0.0)

    # ------------------------------------------------------------ conversion
    def to_dict(self) -> dict[str, Any]:
        """Plain JSON data (lists, floats, ints, strings, bools)."""
        out: dict[str, Any] = {}
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name == "spheres":
                out[f.name] = [Sphere.from_value(s).to_dict() for s in v]
            elif f.name == "custom_pins":
                out[f.name] = [int(i) for i in v]
            elif isinstance(v, tuple):
                out[f.name] = [float(x) for x in v]
            else:
                out[f.name] = v
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> ClothParams:
        """Parameters from ``to_dict`` data; missing names take their defaults, unknown ones are ignored.

        Raises ValueError with a readable message for a value of the wrong type or range.
        """
        kw: dict[str, Any] = {}
        names = {f.name: f for f in fields(cls)}
        for name, value in data.items():
            if name not in names:
                continue
            kw[name] = _coerce(name, value)
        params = cls(**kw)
        params.validate()
        return params

    def replace(self, **changes: Any) -> ClothParams:
        """A validated copy with some fields changed (values coerced like ``from_dict``)."""
        bad = [k for k in changes if k not in {f.name for f in fields(self)}]
        if bad:
            raise ValueError(f"unknown cloth parameter(s): {', '.join(sorted(bad))}")
        params = replace(self, **{k: _coerce(k, v) for k, v in changes.items()})
        params.validate()
        return params

    def validate(self) -> None:
        """Raise ValueError naming the first parameter out of range."""
        if self.rows < 2 or self.cols < 2:
            raise ValueError("rows and cols must be at least 2")
        for name in ("width", "height", "total_mass"):
            if not (getattr(self, name) > 0 and math.isfinite(getattr(self, name))):
                raise ValueError(f"{name} must be a positive number")
        for name in ("structural_stiffness", "structural_damping", "shear_stiffness", "shear_damping",
                     "bend_stiffness", "bend_damping", "drag_coefficient", "air_density", "turbulence",
                     "ground_restitution", "ground_friction", "collision_margin"):
            v = getattr(self, name)
            if not (v >= 0 and math.isfinite(v)):
                raise ValueError(f"{name} must be a finite number ≥ 0")
        if not math.isfinite(self.gravity) or not math.isfinite(self.ground_height):
            raise ValueError("gravity and ground_height must be finite")
        for name in ("wind", "origin", "orientation"):
            if not all(math.isfinite(x) for x in getattr(self, name)):
                raise ValueError(f"{name} must be finite")
        if self.pin_mode not in PIN_MODES:
            raise ValueError(f"pin_mode must be one of {', '.join(PIN_MODES)}, not {self.pin_mode!r}")
        if self.integrator not in INTEGRATORS:
            raise ValueError(f"integrator must be one of {', '.join(INTEGRATORS)}, not {self.integrator!r}")
        if self.substeps < 0:
            raise ValueError("substeps must be 0 (automatic) or a positive number")
        n = self.rows * self.cols
        for i in self.custom_pins:
            if not 0 <= i < n:
                raise ValueError(f"custom pin {i} is outside the cloth's {n} particles")
        for s in self.spheres:
            if not (s.radius > 0 and math.isfinite(s.radius)):
                raise ValueError("a sphere's radius must be a positive number")
            if s.restitution < 0 or s.friction < 0:
                raise ValueError("a sphere's restitution and friction must be ≥ 0")

    @property
    def particle_mass(self) -> float:
        return self.total_mass / (self.rows * self.cols)

    def stiffness(self, kind: str) -> float:
        return float(getattr(self, f"{kind}_stiffness"))

    def damping(self, kind: str) -> float:
        return float(getattr(self, f"{kind}_damping"))


_INT_FIELDS = {"rows", "cols", "turbulence_seed", "substeps"}
_STR_FIELDS = {"pin_mode", "integrator"}
_VEC_FIELDS = {"wind", "origin", "orientation"}


def _coerce(name: str, value: Any) -> Any:
    if name == "substeps" and isinstance(value, str) and value.strip().lower() == "auto":
        return AUTO_SUBSTEPS
    if name in _INT_FIELDS:
        if isinstance(value, bool) or not float(value).is_integer():
            raise ValueError(f"{name} must be a whole number")
        return int(value)
    if name in _STR_FIELDS:
        return str(value)
    if name in _VEC_FIELDS:
        return _vec3(value, name)
    if name == "ground_enabled":
        return bool(value)
    if name == "spheres":
        return [Sphere.from_value(s) for s in value]
    if name == "custom_pins":
        pins = []
        for i in value:
            if isinstance(i, bool) or not float(i).is_integer():
                raise ValueError("custom_pins must be particle indices")
            pins.append(int(i))
        return pins
    try:
        return float(value)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be a number") from exc
