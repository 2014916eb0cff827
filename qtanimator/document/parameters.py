"""The typed parameter schema: every setting's default, range, unit and validation, in one place.

A :class:`Param` describes one setting: its key, default, kind (``float``, ``int``, ``bool``,
``choice``, ``vector``, ``color``, ``str`` or ``list``), the label and unit the panels show,
the range (``minimum`` / ``maximum``, inclusive), the step and decimals of its field, the
choices, the text shown at the minimum when that value means something else ("auto"), the
reasons shown when a value beyond a limit is refused, and a help text. ``validate(value)``
returns the value or raises ValueError with a sentence naming the setting and what it takes.

The groups (:class:`Schema`):

* :data:`PROJECT`: ``fps``, ``frame_start``, ``frame_end`` (every document has them);
* :data:`IK`: the ``ik.*`` settings (:mod:`qtanimator.document.ik_settings`);
* :data:`LIGHTS`: ``light1.*``, ``light2.*`` (each with its own defaults) and ``lights.ambient``;
* :data:`PENDULUM` / :data:`SPRING`: the per-character constants stored as
  ``"<asset>.pendulum.<key>"`` / ``"<asset>.spring.<key>"``; keys and defaults come from the
  fields of :class:`~qtanimator.core.pendulum.PendulumParams` /
  :class:`~qtanimator.core.spring_joint.SpringParams`, only the ranges are added here;
* :data:`CLOTH`: the cloth asset's properties, keys and defaults from
  :class:`~qtanimator.core.cloth.ClothParams` (``ClothParams.validate`` stays the model's check);
* :data:`RENDER`: what File > Export Animation offers (size, frame rate, background…).

Where a model only asks for a finite number the range is wide (far beyond use) so that a
field never clamps a useful value. :func:`param_for` resolves a document parameter path to
its Param; ``SetParameter`` validates with it. Qt-free: ``core`` only.
"""

from __future__ import annotations

import copy
import math
import numbers
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, fields
from typing import Any

from qtanimator.core import cloth_params as _cloth
from qtanimator.core import ik_methods
from qtanimator.core.pendulum import INTEGRATORS as PENDULUM_INTEGRATORS
from qtanimator.core.pendulum import MIN_STEP, PRESETS, PendulumParams
from qtanimator.core.spring_joint import SPRING_PRESETS, SpringParams

KINDS = ("float", "int", "bool", "choice", "vector", "color", "str", "list")


def _number(value: float) -> str:
    return f"{value:g}"


@dataclass(frozen=True)
class Param:
    """One setting. ``key`` is its document parameter path (``"fps"``, ``"ik.solver"``), or,
    for per-asset groups, the last part of it (``"damping"`` of ``"<asset>.pendulum.damping"``)
    or the asset property's name (cloth). ``minimum`` / ``maximum`` bound a number (each
    component of a vector or colour). ``reason``: why the field stops at its maximum (shown
    when a larger value is refused); ``reason_below``: the same for the minimum."""

    key: str
    default: Any
    kind: str
    label: str
    unit: str = ""
    minimum: float | None = None
    maximum: float | None = None
    step: float | None = None
    decimals: int | None = None
    choices: tuple[str, ...] = ()
    special_minimum: str = ""
    reason: str = ""
    reason_below: str = ""
    help: str = ""
    #: The number of components of a vector or colour.
    size: int = 3

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"unknown parameter kind {self.kind!r}")
        if self.kind == "choice" and self.default not in self.choices:
            raise ValueError(f"{self.key}: the default {self.default!r} is not one of its choices")

    @property
    def title(self) -> str:
        """The label with its unit: ``"Gravity (units/s²)"``."""
        return f"{self.label} ({self.unit})" if self.unit else self.label

    def range_text(self) -> str:
        """What the setting takes, as a phrase: ``"a number from 0 to 1"``."""
        if self.kind == "choice":
            return "one of " + ", ".join(self.choices)
        if self.kind == "bool":
            return "true or false"
        if self.kind in ("str", "list"):
            return "a text" if self.kind == "str" else "a list"
        what = {"int": "a whole number", "float": "a number",
                "vector": f"{self.size} numbers", "color": f"{self.size} colour components"}[self.kind]
        lo, hi = self.minimum, self.maximum
        unit = f" {self.unit}" if self.unit and self.kind in ("int", "float") else ""
        if lo is not None and hi is not None:
            return f"{what} from {_number(lo)} to {_number(hi)}{unit}"
        if lo is not None:
            return f"{what} of at least {_number(lo)}{unit}"
        if hi is not None:
            return f"{what} of at most {_number(hi)}{unit}"
        return f"finite {what}" if self.kind != "int" else what

    def _refuse(self, value: Any, path: str | None, why: str = "") -> ValueError:
        name = path or self.key
        tail = f" ({why})" if why else ""
        return ValueError(f"{self.label} ({name}) must be {self.range_text()}, not {value!r}{tail}.")

    def _check_number(self, x: Any, value: Any, path: str | None, integral: bool) -> None:
        if isinstance(x, bool) or not isinstance(x, numbers.Real):
            raise self._refuse(value, path)
        if integral and not isinstance(x, numbers.Integral):
            raise self._refuse(value, path)
        if not math.isfinite(float(x)):
            raise self._refuse(value, path)
        if self.minimum is not None and float(x) < self.minimum:
            raise self._refuse(value, path, self.reason_below)
        if self.maximum is not None and float(x) > self.maximum:
            raise self._refuse(value, path, self.reason)

    def validate(self, value: Any, path: str | None = None) -> Any:
        """``value`` if the setting takes it (unchanged: an int stays an int), else ValueError
        naming the setting (``path``, or the key) and what it takes."""
        if self.kind in ("float", "int"):
            self._check_number(value, value, path, self.kind == "int")
        elif self.kind == "bool":
            if not isinstance(value, bool):
                raise self._refuse(value, path)
        elif self.kind == "choice":
            if not isinstance(value, str) or value not in self.choices:
                raise self._refuse(value, path)
        elif self.kind in ("vector", "color"):
            if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or len(value) != self.size:
                raise self._refuse(value, path)
            for x in value:
                self._check_number(x, value, path, False)
        elif self.kind == "str":
            if not isinstance(value, str):
                raise self._refuse(value, path)
        elif self.kind == "list":
            if not isinstance(value, (list, tuple)):
                raise self._refuse(value, path)
        return value

    def is_valid(self, value: Any) -> bool:
        try:
            self.validate(value)
        except ValueError:
            return False
        return True


class Schema(Mapping[str, Param]):
    """A named group of Params, by key (in the order the panels show them). ``scope``: for a
    per-asset group, the middle part of its paths (``"pendulum"`` → ``"<asset>.pendulum.<key>"``)."""

    def __init__(self, name: str, params: tuple[Param, ...], scope: str = "") -> None:
        self.name = name
        self.scope = scope
        self._params = {p.key: p for p in params}
        if len(self._params) != len(params):
            raise ValueError(f"{name}: duplicate keys")

    def __getitem__(self, key: str) -> Param:
        return self._params[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._params)

    def __len__(self) -> int:
        return len(self._params)

    def path(self, key: str, asset: str = "") -> str:
        """The document parameter path of ``key`` (of ``asset`` for a per-asset group)."""
        return f"{asset}.{self.scope}.{key}" if self.scope else key

    def __repr__(self) -> str:
        return f"Schema({self.name!r}, {list(self._params)})"


def defaults(group: Schema) -> dict[str, Any]:
    """Key → default of every Param of ``group`` (a fresh copy: lists may be changed)."""
    return {k: copy.deepcopy(p.default) for k, p in group.items()}


# ------------------------------------------------------------------- project
#: Frames as far as a project file may hold them (``formats.project``).
FRAME_LIMIT = 10**9

PROJECT = Schema("project", (
    Param("fps", 60.0, "float", "Frame rate", unit="fps", minimum=0.01, maximum=10000.0, step=1.0, decimals=3,
          reason="a project holds at most 10000 frames per second",
          help="frames per second; keys are in seconds, so they keep their time"),
    Param("frame_start", 0, "int", "First frame", minimum=-FRAME_LIMIT, maximum=FRAME_LIMIT, step=1,
          help="the first frame of the animation range"),
    Param("frame_end", 240, "int", "Last frame", minimum=-FRAME_LIMIT, maximum=FRAME_LIMIT, step=1,
          help="the last frame of the animation range"),
))

# ------------------------------------------------------------------------ IK
IK = Schema("ik", (
    Param("ik.solver", "dls", "choice", "Solver", choices=("dls", "ccd", "fabrik", "handout"),
          help="dls: damped least squares (recommended); ccd: cyclic coordinate descent, one joint at a time; "
               "fabrik: forward and backward reaching, on positions; handout: the course handout's gradient "
               "descent (2D). All respect joint limits"),
    Param("ik.two_bone", True, "bool", "Two-bone chains exactly",
          help="a chain with exactly two moving joints is solved exactly (law of cosines), whatever the solver"),
    Param("ik.bend_direction", "keep", "choice", "Two-bone bend", choices=tuple(ik_methods.BEND_DIRECTIONS),
          help="keep: the middle joint bends to the side it bends to now; positive / negative: "
               "counter-clockwise / clockwise on screen (2D)"),
    Param("ik.freeze_root", True, "bool", "Keep the root still",
          help="the dragged chain stops below the character's root joint"),
    Param("ik.max_iterations", 100, "int", "Precision (iterations)", minimum=1, maximum=10_000, step=1,
          reason="more would make every mouse move slow",
          help="more iterations reach the cursor more exactly"),
    Param("ik.damping", 1e-3, "float", "Smoothness", minimum=0.0, maximum=1000.0, step=1e-3, decimals=6,
          help="damped least squares' damping λ: higher is steadier near full stretch"),
    Param("ik.handout_step", 1e-6, "float", "Gradient step (handout solver)", minimum=0.0, maximum=1.0, step=1e-6,
          decimals=9, help="τ in the handout's update θ ← θ + τ·D"),
    Param("ik.handout_iterations", 10, "int", "Gradient steps per move (handout solver)", minimum=1,
          maximum=10_000, step=1, reason="more would make every mouse move slow",
          help="updates of the handout's solver per mouse move"),
    Param("ik.gradient_arrow_scale", 0.1, "float", "Debug arrow length", minimum=0.0, maximum=1000.0, step=0.1,
          decimals=6, help="length of the gradient arrows of the debug overlay"),
))
#: The values ``ik.solver`` takes.
IK_SOLVERS = IK["ik.solver"].choices

# -------------------------------------------------------------------- lights
LIGHT_NAMES = ("light1", "light2")
AMBIENT_PARAMETER = "lights.ambient"
#: A light's intensity is any number ≥ 0 (above 1 it brightens past its colour, which is
#: fine) and its position any place: the maximums are far beyond use.
INTENSITY_LIMIT = 1000.0
POSITION_LIMIT = 1e6


def _light(name: str, number: int, position: list[float], color: list[float], intensity: float) -> tuple[Param, ...]:
    return (
        Param(f"{name}.position", position, "vector", f"Light {number} position", unit="scene units",
              minimum=-POSITION_LIMIT, maximum=POSITION_LIMIT, step=0.1, decimals=2,
              help="where the point light is, in scene coordinates"),
        Param(f"{name}.color", color, "color", f"Light {number} colour", minimum=0.0, maximum=1.0,
              help="red, green and blue from 0 to 1"),
        Param(f"{name}.intensity", intensity, "float", f"Light {number} intensity", minimum=0.0,
              maximum=INTENSITY_LIMIT, step=0.05, decimals=2,
              help="multiplies the colour; above 1 the light is brighter than its colour"),
    )


LIGHTS = Schema("lights", (
    *_light("light1", 1, [4.0, 6.0, 5.0], [1.0, 0.95, 0.85], 0.8),
    *_light("light2", 2, [-5.0, 3.0, -3.0], [0.55, 0.65, 1.0], 0.5),
    Param(AMBIENT_PARAMETER, [0.16, 0.16, 0.18], "color", "Ambient colour", minimum=0.0, maximum=1.0,
          help="the light every surface gets, red, green and blue from 0 to 1"),
))


# --------------------------------------------------- pendulum and spring joints
def _kind_of(value: Any) -> str:
    if isinstance(value, bool):
        return "bool"
    if isinstance(value, int):
        return "int"
    if isinstance(value, float):
        return "float"
    return "str"


def _from_dataclass(cls: Any, specs: Mapping[str, dict[str, Any]], scope: str, name: str) -> Schema:
    """A Schema whose keys and defaults are the fields of the dataclass ``cls`` (so they cannot
    drift) and whose labels, ranges… come from ``specs`` (one entry per field, checked)."""
    instance = cls()
    names = [f.name for f in fields(cls)]
    if set(names) != set(specs):
        raise AssertionError(f"{name}: the schema's keys {sorted(specs)} differ from {cls.__name__}'s {sorted(names)}")
    params = []
    for key in names:
        spec = dict(specs[key])
        default = getattr(instance, key)
        kind = spec.pop("kind", "choice" if "choices" in spec else _kind_of(default))
        params.append(Param(key, default, kind, **spec))
    return Schema(name, tuple(params), scope)


#: Wide bounds where a model takes any finite number.
WIDE = 1e6

PENDULUM = _from_dataclass(PendulumParams, {
    "g": dict(label="Gravity", unit="units/s²", minimum=-WIDE, maximum=WIDE, step=100.0, decimals=6,
              help="g, in scene units per second² (pulls down the screen)"),
    "damping": dict(label="Damping", unit="1/s", minimum=0.0, maximum=WIDE, step=0.1, decimals=6,
                    reason_below="a negative damping adds energy every step",
                    help="how fast the swing dies out: a in ω ← ω·e^(−a·τ), per second"),
    "restitution": dict(label="Bounce", minimum=0.0, maximum=1.0, step=0.1, decimals=6,
                        reason="above 1 every bounce would gain energy",
                        help="restitution e: the share of its speed a pendulum or spring joint keeps when it hits "
                             "its joint limits (0 stops dead, 1 bounces back fully)"),
    "length_scale": dict(label="Length scale", minimum=0.0, maximum=WIDE, step=0.1, decimals=6,
                         help="multiplies the pivot-to-centre-of-mass lengths (the course handout uses 1/1000)"),
    "accel_scale": dict(label="Follow the body", minimum=0.0, maximum=WIDE, step=0.1, decimals=6,
                        help="how much the character's movement swings the pendulums "
                             "(translation acceleration scale)"),
    "rotation_accel_scale": dict(label="Follow the parent's rotation", minimum=0.0, maximum=WIDE, step=0.1,
                                 decimals=6, help="how much keyframed parents turning swings the pendulums "
                                                  "(rotation acceleration scale)"),
    "inertia": dict(label="Inertia from", choices=("exact", "reference"),
                    help="exact: from the drawn shapes; reference: the course starter's formulas"),
    "point_mass_forcing": dict(label="Point-mass swing", help="the course handout's 1/L² forcing in place of m/I"),
    "coupled": dict(label="Chains swing together", help="solve chains of pendulums as one coupled system"),
    "integrator": dict(label="Integrator", choices=tuple(PENDULUM_INTEGRATORS),
                       help="symplectic Euler (the course's), leapfrog or Runge–Kutta 4"),
    "step": dict(label="Simulation step", unit="s", minimum=MIN_STEP, maximum=1.0, step=0.001, decimals=6,
                 reason="a step longer than a second misses every swing",
                 reason_below=f"the step must be at least {MIN_STEP:g} s: a frame would take too many steps",
                 help="the fixed internal time step; smaller is steadier and slower"),
}, "pendulum", "pendulum")
PENDULUM_PRESET = Param("preset", "physical", "choice", "Preset", choices=tuple(PRESETS),
                        help="a named set of pendulum constants (the values over it are the character's own)")

SPRING = _from_dataclass(SpringParams, {
    "stiffness": dict(label="Stiffness", unit="1/s²", minimum=0.0, maximum=WIDE, step=10.0, decimals=4,
                      help="how hard the spring pulls the joint back to its keyed angle (k, per second²; "
                           "it wobbles at √k / 2π per second)"),
    "damping": dict(label="Damping", unit="1/s", minimum=0.0, maximum=WIDE, step=1.0, decimals=4,
                    reason_below="a negative damping adds energy every step",
                    help="how fast the wobble dies out (c, per second; none left at 2√k)"),
    "mix": dict(label="Mix", minimum=0.0, maximum=1.0, step=0.1, decimals=4,
                help="0 shows the keys, 1 the spring; in between, a blend"),
    "inertia": dict(label="Inertia", minimum=0.0, maximum=1.0, step=0.1, decimals=4,
                    help="how much the parent turning and the body moving drag the joint (0: it rides on its "
                         "parent, 1: it keeps its heading like a loose part)"),
}, "spring", "spring")
SPRING_PRESET = Param("preset", "soft", "choice", "Preset", choices=tuple(SPRING_PRESETS),
                      help="a named set of spring constants")

# --------------------------------------------------------------------- cloth
_GRID = "a bigger grid would take too long to simulate"
_SPRING_K = dict(unit="N/m", minimum=0.0, maximum=1e9, decimals=2)
_SPRING_C = dict(unit="N·s/m", minimum=0.0, maximum=1e6, decimals=3)
_VECTOR = dict(minimum=-WIDE, maximum=WIDE, step=0.1, decimals=3)

CLOTH = _from_dataclass(_cloth.ClothParams, {
    "rows": dict(label="Rows", minimum=2, maximum=1000, step=1, reason=_GRID),
    "cols": dict(label="Cols", minimum=2, maximum=1000, step=1, reason=_GRID),
    "width": dict(label="Width", unit="m", minimum=0.001, maximum=1e4, step=0.1, decimals=3),
    "height": dict(label="Height", unit="m", minimum=0.001, maximum=1e4, step=0.1, decimals=3),
    "total_mass": dict(label="Total mass", unit="kg", minimum=0.001, maximum=1e6, step=0.1, decimals=3),
    "structural_stiffness": dict(label="Structural stiffness", step=10.0, **_SPRING_K),
    "structural_damping": dict(label="Structural damping", step=0.05, **_SPRING_C),
    "shear_stiffness": dict(label="Shear stiffness", step=10.0, **_SPRING_K),
    "shear_damping": dict(label="Shear damping", step=0.05, **_SPRING_C),
    "bend_stiffness": dict(label="Bend stiffness", step=1.0, **_SPRING_K),
    "bend_damping": dict(label="Bend damping", step=0.01, **_SPRING_C),
    "drag_coefficient": dict(label="Drag coefficient", minimum=0.0, maximum=1e3, step=0.05, decimals=3),
    "air_density": dict(label="Air density", unit="kg/m³", minimum=0.0, maximum=1e5, step=0.05, decimals=3),
    "wind": dict(label="Wind", unit="m/s", kind="vector", **_VECTOR),
    "turbulence": dict(label="Turbulence", minimum=0.0, maximum=1e4, step=0.1, decimals=3),
    "turbulence_seed": dict(label="Turbulence seed", minimum=0, maximum=2**31 - 1, step=1),
    "gravity": dict(label="Gravity", unit="m/s²", minimum=-1e4, maximum=1e4, step=0.1, decimals=3),
    "ground_enabled": dict(label="Ground enabled"),
    "ground_height": dict(label="Ground height", unit="m", minimum=-WIDE, maximum=WIDE, step=0.05, decimals=3),
    "ground_restitution": dict(label="Ground restitution", minimum=0.0, maximum=1.0, step=0.05, decimals=3,
                               reason="above 1 every bounce would gain energy"),
    "ground_friction": dict(label="Ground friction", minimum=0.0, maximum=100.0, step=0.05, decimals=3),
    "spheres": dict(label="Spheres", kind="list", help="collision spheres: centre and radius"),
    "collision_margin": dict(label="Collision margin", unit="m", minimum=0.0, maximum=100.0, step=0.001,
                             decimals=4),
    "pin_mode": dict(label="Pin mode", choices=tuple(_cloth.PIN_MODES)),
    "custom_pins": dict(label="Custom pins", kind="list", help="particle indices"),
    "integrator": dict(label="Integrator", choices=tuple(_cloth.INTEGRATORS)),
    "substeps": dict(label="Substeps", minimum=_cloth.AUTO_SUBSTEPS, maximum=100_000, step=1,
                     special_minimum="auto"),
    "origin": dict(label="Origin", unit="m", kind="vector", **_VECTOR),
    "orientation": dict(label="Orientation", unit="rad", kind="vector", minimum=-2 * math.pi,
                        maximum=2 * math.pi, step=0.1, decimals=3),
}, "", "cloth")
#: Fields of the cloth panel that are not ClothParams fields of their own.
CLOTH_WIND_SPEED = Param("wind_speed", 0.0, "float", "Wind speed", unit="m/s", minimum=0.0, maximum=WIDE,
                         step=0.5, decimals=2, help="the length of the wind vector (its direction stays)")
CLOTH_SPHERE_CENTRE = Param("sphere_centre", [0.0, 0.0, 0.0], "vector", "Sphere", unit="m", minimum=-WIDE,
                            maximum=WIDE, step=0.05, decimals=3)
CLOTH_SPHERE_RADIUS = Param("sphere_radius", 0.5, "float", "Sphere radius", unit="m", minimum=0.001, maximum=WIDE,
                            step=0.05, decimals=3)

# -------------------------------------------------------------------- render
RENDER = Schema("render", (
    Param("render.view", "2d", "choice", "View", choices=("2d", "3d", "gltf"),
          help="the 2D view, the 3D view, or the selected 3D character as a glTF file"),
    Param("render.format", "png", "choice", "Format", choices=("png", "gif", "mp4")),
    Param("render.width", 960, "int", "Width", unit="px", minimum=16, maximum=8192, step=1),
    Param("render.height", 640, "int", "Height", unit="px", minimum=16, maximum=8192, step=1),
    Param("render.fps", 60.0, "float", "Frame rate", unit="fps", minimum=1.0, maximum=240.0, step=1.0, decimals=2),
    Param("render.first", 0, "int", "First frame", minimum=-100_000, maximum=100_000, step=1),
    Param("render.last", 240, "int", "Last frame", minimum=-100_000, maximum=100_000, step=1),
    Param("render.background", [0.6, 0.6, 0.95], "color", "Background", minimum=0.0, maximum=1.0,
          help="the reference program's export background (2D; 3D keeps the viewport's)"),
))

#: Every group, by name.
GROUPS: dict[str, Schema] = {g.name: g for g in (PROJECT, IK, LIGHTS, PENDULUM, SPRING, CLOTH, RENDER)}
#: Groups whose keys are whole document parameter paths.
_PATH_GROUPS = (PROJECT, IK, LIGHTS)
_SCOPED: dict[str, tuple[Schema, Param]] = {"pendulum": (PENDULUM, PENDULUM_PRESET),
                                            "spring": (SPRING, SPRING_PRESET)}


def param_for(path: str) -> Param | None:
    """The Param of a document parameter path (``"fps"``, ``"ik.solver"``, ``"light1.color"``,
    ``"<asset>.pendulum.<key>"``, ``"<asset>.spring.<key>"``, including their ``preset``);
    None for a path the schema does not know (it is not validated)."""
    for group in _PATH_GROUPS:
        if path in group:
            return group[path]
    parts = path.rsplit(".", 2)
    if len(parts) == 3 and parts[0] and parts[1] in _SCOPED:
        group, preset = _SCOPED[parts[1]]
        if parts[2] == preset.key:
            return preset
        return group.get(parts[2])
    return None


def validate_parameter(path: str, value: Any) -> Any:
    """``value`` if the schema accepts it for ``path`` (None, unset, always; an unknown path
    takes anything), else ValueError naming the setting and its range."""
    param = param_for(path)
    if value is None or param is None:
        return value
    return param.validate(value, path)


def parameter_problems(parameters: Mapping[str, Any]) -> dict[str, str]:
    """Path → the reason for every stored value the schema refuses (a project written by
    hand or by an older version). Opening a project does not refuse them: see
    docs/decisions.md."""
    out: dict[str, str] = {}
    for path, value in parameters.items():
        try:
            validate_parameter(path, value)
        except ValueError as exc:
            out[path] = str(exc)
    return out


__all__ = [
    "AMBIENT_PARAMETER", "CLOTH", "CLOTH_SPHERE_CENTRE", "CLOTH_SPHERE_RADIUS", "CLOTH_WIND_SPEED", "GROUPS", "IK",
    "IK_SOLVERS", "LIGHTS", "LIGHT_NAMES", "PENDULUM", "PENDULUM_PRESET", "PROJECT", "Param", "RENDER", "SPRING",
    "SPRING_PRESET", "Schema", "defaults", "param_for", "parameter_problems", "validate_parameter",
]
