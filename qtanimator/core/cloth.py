"""Mass-spring cloth: springs, drag, wind, collisions, pins and grabbing (issue 5).

A rectangular cloth of ``rows × cols`` particles, SI units, y up (ARCHITECTURE §4 Cloth).

Model
-----
* Particle ``(r, c)`` has index ``r·cols + c``; row 0 is the top edge. In the cloth's own
  frame the top edge is centred on the origin and the cloth hangs down along −y, spanning x;
  ``ClothParams.orientation`` (a rotation vector, radians) and ``origin`` place it.
* Springs (spring-dampers along the line between two particles), each kind with its own
  stiffness ``k`` and damping ``c``: structural (right and down neighbours), shear (both
  diagonals of every quad) and bend (skip one particle, horizontally and vertically).
  ``f_i = (k·(l − L) + c·(v_j − v_i)·u)·u`` with ``u`` the unit vector from i to j.
* Gravity ``−g·ŷ`` and aerodynamic drag per triangle ``−½·ρ·c_d·|v|²·a·n̂`` with
  ``v`` = triangle velocity − wind (the mean over its corners), ``a = area·(v̂·n̂)``, split ⅓
  per corner. Optional turbulence adds a deterministic, seeded, smoothly varying gust field
  (a sum of travelling sine waves, amplitude ``turbulence`` m/s) to the wind, sampled at the
  particles once per frame.
* Collisions with a ground plane ``y = ground_height`` and spheres: particles are projected
  to the surface (plus ``collision_margin``), the normal velocity is reflected with the
  restitution and the tangential velocity loses Coulomb friction.
* Moving capsules (:meth:`Cloth.set_capsules`: segments with a radius, e.g. a character's
  bones): after every substep a particle inside one is pushed out to ``radius + margin``
  along the normal from the segment (the deepest capsule first, three passes where capsules
  overlap) and the inward normal component of its velocity is removed. The capsules move
  linearly from their start to their end place over the substeps of the next step.
* Kinematic particles: the pinned set (moved rigidly by :meth:`Cloth.move_pins`) and the
  grabbed particle. They move linearly to their targets over the substeps of the next
  :meth:`Cloth.step` and land on them exactly.

Integration
-----------
* ``"implicit"`` (the default): backward Euler linearised once per step (Baraff & Witkin
  1998): solve ``(M − h·∂f/∂v − h²·∂f/∂x)·Δv = h·(f + h·∂f/∂x·v)``. Springs and their damping
  are implicit, drag and gravity explicit; compressed springs drop their transverse stiffness
  so the matrix stays positive definite. Pins and the grabbed particle are constraints of the
  solve (identity rows and columns, zero right-hand side). The block-CSR sparsity pattern is
  built once per grid; with numba every step writes the matrix values straight into it and
  solves with a compiled block-Jacobi conjugate gradient (:mod:`qtanimator.core.cloth_kernels`),
  without numba the same system is assembled with numpy / scipy.sparse and solved by the same
  CG in numpy (5-7× slower; ``cloth_kernels.SLOW_PATH_NOTE`` says so). The CG starts from the
  previous step's velocity change and stops at ``|r| ≤ max(rtol·|b|, atol)`` with
  ``rtol`` = :data:`SOLVER_RTOL` (1e-3: over 250 frames of the 2 m benchmark cloth the
  positions stay within about 1 mm of a solve to 1e-9) and ``atol`` =
  :data:`SOLVER_ATOL_ACCELERATION` × h × particle mass × √N (every eigenvalue of the matrix
  is at least the particle mass, so the RMS error of the velocity change stays below
  1e-3 m/s² × h: a settled cloth does not chase ever smaller residuals), or after
  ``max(200, 8·√N)`` iterations. Stable for every
  stiffness and damping the cloth panel allows; large steps damp fast motion (backward Euler
  loses energy), so :data:`IMPLICIT_MAX_STEP` caps the automatic step.
* ``"symplectic"``: semi-implicit Euler (``v += a·h; x += v·h``), accurate and cheap per
  substep but only stable below a step that shrinks with stiffness and damping and with
  lighter particles (finer grids). The springs live on a regular grid, so every spring
  family is a pair of slices of the flat particle array (offset 1, cols, cols ± 1, 2, 2·cols):
  gather and scatter are slice arithmetic, no index arrays, no per-particle Python loop. When
  numba is installed the spring and drag forces come from compiled kernels (~10× faster,
  tested against the numpy code); ``Cloth(params, accelerate=False)`` forces numpy.
* ``substeps`` = 0 (the default, "auto") picks the steps per frame: the fewest that keep the
  implicit step at most :data:`IMPLICIT_MAX_STEP`, or the symplectic substep inside its
  stability bound (:meth:`Cloth.stable_substeps`). A number set by hand is used as it is.

A step that produces non-finite or runaway values is undone and raises :class:`ClothBlowUp`,
whose message names the parameter to change; the cloth stays stopped (``cloth.error``) until
:meth:`Cloth.reset`, :meth:`Cloth.set_state` or :meth:`Cloth.set_params`. Everything is
deterministic: the same parameters and calls give bit-identical arrays.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field, fields, replace
from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt

from qtanimator.core import cloth_kernels

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]
BoolArray = npt.NDArray[np.bool_]

__all__ = [
    "AUTO_SUBSTEPS", "IMPLICIT_MAX_STEP", "INTEGRATORS", "MAX_AUTO_SUBSTEPS", "PARAM_RANGES", "PIN_MODES",
    "SOLVER_ATOL_ACCELERATION", "SOLVER_RTOL", "SPRING_KINDS", "Cloth", "ClothBlowUp", "ClothParams", "ClothState",
    "ClothStepCancelled", "Sphere", "grid_index", "nearest_particle", "pins_from_cells", "rotation_matrix",
    "vertex_normals",
]

PIN_MODES = ("top_corners", "top_edge", "none", "custom")
INTEGRATORS = ("symplectic", "implicit")
SPRING_KINDS = ("structural", "shear", "bend")

#: Suggested editor ranges (min, max) for numeric parameters, after notes/cse169-formats.md §11.
PARAM_RANGES: dict[str, tuple[float, float]] = {
    "rows": (2, 128), "cols": (2, 128), "width": (0.05, 20.0), "height": (0.05, 20.0), "total_mass": (0.001, 100.0),
    "structural_stiffness": (0.0, 1.0e5), "shear_stiffness": (0.0, 1.0e5), "bend_stiffness": (0.0, 1.0e5),
    "structural_damping": (0.0, 50.0), "shear_damping": (0.0, 50.0), "bend_damping": (0.0, 50.0),
    "drag_coefficient": (0.0, 2.0), "air_density": (0.0, 2.0), "turbulence": (0.0, 20.0), "gravity": (0.0, 20.0),
    "ground_height": (-10.0, 10.0), "ground_restitution": (0.0, 1.0), "ground_friction": (0.0, 2.0),
    "collision_margin": (0.0, 0.1), "substeps": (0, 200),
}

#: ``substeps`` = AUTO_SUBSTEPS lets the cloth choose its steps per frame (see the module docstring).
AUTO_SUBSTEPS = 0
#: Longest automatic implicit step (s): one step a frame at 60 fps, 2 at 30 fps, 3 at 24 fps.
IMPLICIT_MAX_STEP = 1.0 / 60.0
#: The most substeps "auto" gives the symplectic integrator; settings that need more raise
#: ClothBlowUp before stepping, naming the implicit integrator.
MAX_AUTO_SUBSTEPS = 5000
#: The implicit solver's relative tolerance on the residual (see the module docstring).
SOLVER_RTOL = 1.0e-3
#: The solver's absolute floor as an RMS acceleration error (m/s², a ten-thousandth of g):
#: a settled cloth does not chase ever smaller residuals.
SOLVER_ATOL_ACCELERATION = 1.0e-3

#: Speeds above this (m/s) count as a blow-up even while the numbers are still finite.
RUNAWAY_SPEED = 1.0e4

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


class ClothBlowUp(RuntimeError):
    """The simulation went unstable; ``parameter`` names the setting to change first."""

    def __init__(self, message: str, parameter: str, time: float) -> None:
        super().__init__(message)
        self.message = message
        self.parameter = parameter
        self.time = time


class ClothStepCancelled(Exception):
    """:meth:`Cloth.step` was asked to stop between two substeps; the cloth is back in the
    state from before the step, so stepping again later gives the same frames."""


@dataclass
class ClothState:
    """Everything that evolves: enough to resume a simulation exactly (caches keep these).

    ``solver_start`` is the implicit solver's last velocity change, where its next solve
    starts (None: from zero); it is part of the state so that resuming gives identical frames."""

    positions: FloatArray
    velocities: FloatArray
    pin_targets: FloatArray
    time: float
    grabbed: int | None = None
    grab_target: FloatArray | None = None
    solver_start: FloatArray | None = None

    def copy(self) -> ClothState:
        return ClothState(self.positions.copy(), self.velocities.copy(), self.pin_targets.copy(), self.time,
                          self.grabbed, None if self.grab_target is None else self.grab_target.copy(),
                          None if self.solver_start is None else self.solver_start.copy())


def rotation_matrix(rotation: Any) -> FloatArray:
    """A 3×3 rotation from a rotation vector (axis·angle, radians) or a 3×3 matrix."""
    r = np.asarray(rotation, dtype=np.float64)
    if r.shape == (3, 3):
        return r.copy()
    if r.shape != (3,):
        raise ValueError("a rotation is an axis-angle vector (3,) or a 3×3 matrix")
    angle = float(np.linalg.norm(r))
    if angle < 1e-15:
        return np.eye(3)
    k = r / angle
    kx = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + math.sin(angle) * kx + (1.0 - math.cos(angle)) * (kx @ kx)


@dataclass(frozen=True)
class _Family:
    """Springs ``(i, i + offset)`` for ``i`` in ``[0, n − offset)``; segment ``[start, stop)`` of the buffers."""

    offset: int
    start: int
    stop: int


class Cloth:
    """A simulated cloth. See the module docstring for the model."""

    def __init__(self, params: ClothParams | None = None, *, accelerate: bool | None = None) -> None:
        """``accelerate``: use the compiled force kernels (default: when numba is installed).

        ``False`` forces the vectorised numpy code (the reference the kernels are tested against).
        """
        self.params = ClothParams() if params is None else params
        self.accelerated = cloth_kernels.HAVE_NUMBA if accelerate is None else bool(accelerate and
                                                                                   cloth_kernels.HAVE_NUMBA)
        self.params.validate()
        self.error: ClothBlowUp | None = None
        #: The implicit solver's stopping rule (module docstring); tests tighten it.
        self.solver_rtol = SOLVER_RTOL
        self.solver_atol_acceleration = SOLVER_ATOL_ACCELERATION
        #: Start each implicit solve from the previous step's velocity change (else from zero).
        self.warm_start = True
        #: Conjugate-gradient iterations of the last implicit substep (for benchmarks and tests).
        self.last_iterations = 0
        self._build()
        self.reset()

    # ------------------------------------------------------------- structure
    def _build(self) -> None:
        p = self.params
        R, C = p.rows, p.cols
        n = R * C
        self.rows, self.cols, self.n = R, C, n
        dx, dy = p.width / (C - 1), p.height / (R - 1)
        r, c = np.divmod(np.arange(n), C)
        local = np.stack([c * dx - p.width / 2.0, -r * dy, np.zeros(n)], axis=1)
        self._rot = rotation_matrix(p.orientation)
        self.rest_positions: FloatArray = local @ self._rot.T + np.asarray(p.origin, dtype=np.float64)
        self.uvs: FloatArray = np.stack([c / (C - 1), 1.0 - r / (R - 1)], axis=1).astype(np.float64)

        pinned = np.zeros(n, dtype=bool)
        if p.pin_mode == "top_corners":
            pinned[[0, C - 1]] = True
        elif p.pin_mode == "top_edge":
            pinned[:C] = True
        elif p.pin_mode == "custom":
            pinned[np.asarray(p.custom_pins, dtype=np.int64)] = True
        self.pinned: BoolArray = pinned
        self._pin_index: IntArray = np.flatnonzero(pinned)

        self.particle_mass = p.particle_mass
        self._inv_mass = np.full(n, 1.0 / self.particle_mass)

        # Spring families: (offset, kind, valid mask over i in [0, n - offset), rest length).
        diag = math.hypot(dx, dy)
        spec = [
            (1, 0, c < C - 1, dx), (C, 0, r < R - 1, dy),
            (C + 1, 1, (c < C - 1) & (r < R - 1), diag), (C - 1, 1, (c > 0) & (r < R - 1), diag),
            (2, 2, c < C - 2, 2 * dx), (2 * C, 2, r < R - 2, 2 * dy),
        ]
        families: list[_Family] = []
        masks, kinds, rests = [], [], []
        start = 0
        for offset, kind, valid, rest in spec:
            if offset <= 0 or offset >= n:
                continue
            v = valid[: n - offset]
            if not v.any():
                continue
            families.append(_Family(offset, start, start + n - offset))
            start += n - offset
            masks.append(v)
            kinds.append(np.full(n - offset, kind, dtype=np.int8))
            rests.append(np.full(n - offset, rest))
        self._families = families
        self._fam_valid = np.concatenate(masks)
        self._fam_kind = np.concatenate(kinds)
        self._fam_rest = np.concatenate(rests)
        m = start
        self._buf_d = np.empty((m, 3))
        self._buf_dv = np.empty((m, 3))
        self._buf_l = np.empty(m)
        self._buf_s = np.empty(m)
        self._force = np.empty((n, 3))

        # The same springs as an explicit list (for the implicit solver and for drawing).
        seg_i = [np.arange(f.stop - f.start) for f in families]
        idx_i = np.concatenate(seg_i)
        idx_j = np.concatenate([s + f.offset for s, f in zip(seg_i, families)])
        valid_all = self._fam_valid
        self.springs: IntArray = np.stack([idx_i[valid_all], idx_j[valid_all]], axis=1).astype(np.int64)
        self.spring_kinds: npt.NDArray[np.int8] = self._fam_kind[valid_all]
        self.rest_lengths: FloatArray = np.ascontiguousarray(self._fam_rest[valid_all])
        self._si = np.ascontiguousarray(self.springs[:, 0])
        self._sj = np.ascontiguousarray(self.springs[:, 1])
        self._set_spring_constants()

        # Triangles: per quad (a, c, d) and (a, d, b) with a = (r, c), b = right, c = below, d = below-right.
        qa = (r * C + c)[(r < R - 1) & (c < C - 1)]
        tris = np.empty((2 * len(qa), 3), dtype=np.int64)
        tris[0::2] = np.stack([qa, qa + C, qa + C + 1], axis=1)
        tris[1::2] = np.stack([qa, qa + C + 1, qa + 1], axis=1)
        self.triangles: IntArray = tris

        self._spheres = [(np.asarray(s.centre, dtype=np.float64), float(s.radius), float(s.restitution),
                          float(s.friction)) for s in p.spheres]
        rng = np.random.default_rng(p.turbulence_seed)
        self._turb_k = rng.normal(0.0, 1.5, size=(4, 3, 3))  # (mode, component, xyz) wave vectors, 1/m
        self._turb_w = rng.uniform(0.5, 3.0, size=(4, 3)) * 2 * math.pi  # angular frequencies, rad/s
        self._turb_phase = rng.uniform(0.0, 2 * math.pi, size=(4, 3))
        self._implicit_cache: dict[str, Any] | None = None
        self._stable_dt_cache: float | None = None
        self._solver_start: FloatArray = np.zeros((n, 3))
        self._air: FloatArray | None = None
        self._wind_cache: FloatArray | None = None
        self._inv_mass_h: tuple[float, FloatArray] | None = None
        self._capsules: tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray] | None = None
        self._capsules_now: tuple[FloatArray, FloatArray, FloatArray] | None = None

    def _wind_field(self) -> FloatArray:
        """The steady wind at every particle, (N, 3) (the fused kernel wants an array)."""
        wind = np.asarray(self.params.wind, dtype=np.float64)
        if self._wind_cache is None or not np.array_equal(self._wind_cache[0], wind):
            self._wind_cache = np.ascontiguousarray(np.broadcast_to(wind, (self.n, 3)))
        return self._wind_cache

    def _set_spring_constants(self) -> None:
        p = self.params
        ks = np.array([p.structural_stiffness, p.shear_stiffness, p.bend_stiffness])
        cs = np.array([p.structural_damping, p.shear_damping, p.bend_damping])
        self._fam_k = np.where(self._fam_valid, ks[self._fam_kind], 0.0)
        self._fam_c = np.where(self._fam_valid, cs[self._fam_kind], 0.0)
        self._spring_k = ks[self.spring_kinds]
        self._spring_c = cs[self.spring_kinds]

    # ------------------------------------------------------------------ state
    def reset(self) -> None:
        """Back to the initial state: rest positions, zero velocity, pins home, time 0.

        ``positions`` and ``velocities`` stay the same array objects while the grid keeps its size
        (reset, set_state, set_params); a viewer may hold on to them.
        """
        self._assign(self.rest_positions, np.zeros((self.n, 3)))
        self.pin_targets: FloatArray = self.positions[self._pin_index].copy()
        self.time = 0.0
        self.grabbed: int | None = None
        self._grab_target: FloatArray | None = None
        self._solver_start = np.zeros((self.n, 3))
        self.error = None

    def _assign(self, positions: FloatArray, velocities: FloatArray) -> None:
        if getattr(self, "positions", None) is None or self.positions.shape != (self.n, 3):
            self.positions: FloatArray = np.empty((self.n, 3))
            self.velocities: FloatArray = np.empty((self.n, 3))
        self.positions[...] = positions
        self.velocities[...] = velocities

    def state(self) -> ClothState:
        """A copy of everything that evolves."""
        return ClothState(self.positions.copy(), self.velocities.copy(), self.pin_targets.copy(), self.time,
                          self.grabbed, None if self._grab_target is None else self._grab_target.copy(),
                          self._solver_start.copy())

    def set_state(self, state: ClothState) -> None:
        """Resume from a state taken from a cloth with the same grid and pins."""
        if np.shape(state.positions) != (self.n, 3) or np.shape(state.velocities) != (self.n, 3):
            raise ValueError("the state belongs to a cloth with another number of particles")
        if np.shape(state.pin_targets) != (len(self._pin_index), 3):
            raise ValueError("the state belongs to a cloth with other pins")
        self._assign(np.asarray(state.positions, dtype=np.float64), np.asarray(state.velocities, dtype=np.float64))
        self.pin_targets = np.array(state.pin_targets, dtype=np.float64)
        self.time = float(state.time)
        self.grabbed = state.grabbed
        self._grab_target = None if state.grab_target is None else np.array(state.grab_target, dtype=np.float64)
        start = state.solver_start
        if start is None or np.shape(start) != (self.n, 3):
            self._solver_start = np.zeros((self.n, 3))
        else:
            self._solver_start = np.array(start, dtype=np.float64)
        self.error = None

    def set_params(self, params: ClothParams) -> bool:
        """Change parameters while running. Returns True when the cloth had to be reset.

        Material, forces, colliders and integrator changes keep the current state. A new pin
        mode or pin set also keeps it: the new pins hold their particles where they are now
        ("drop cloth" is ``pin_mode="none"``). A new grid, size or placement resets the cloth.
        """
        params.validate()
        old = self.params
        same_grid = all(getattr(old, k) == getattr(params, k) for k in
                        ("rows", "cols", "width", "height", "origin", "orientation"))
        if not same_grid:
            self.params = params
            self._build()
            self.positions = np.empty((0, 3))  # new sizes: new arrays
            self.reset()
            return True
        saved = self.state()
        old_pins = self._pin_index
        pattern = self._implicit_cache  # the matrix pattern depends on the grid only
        self.params = params
        self._build()
        self._implicit_cache = pattern
        if not np.array_equal(old_pins, self._pin_index):
            saved.pin_targets = saved.positions[self._pin_index].copy()
            if saved.grabbed is not None and self.pinned[saved.grabbed]:
                saved.grabbed, saved.grab_target = None, None
        self.set_state(saved)
        return False

    # ------------------------------------------------------------ read-outs
    def normals(self) -> FloatArray:
        """Smooth per-vertex unit normals (area-weighted triangle normals), (N, 3)."""
        return vertex_normals(self.positions, self.triangles, fallback=self._rot[:, 2])

    def spring_lengths(self) -> FloatArray:
        """Current length of every spring in :attr:`springs`."""
        d = self.positions[self.springs[:, 1]] - self.positions[self.springs[:, 0]]
        return np.asarray(np.linalg.norm(d, axis=1), dtype=np.float64)

    def stretch(self, kind: str = "structural") -> FloatArray:
        """Relative elongation ``l / L − 1`` of every spring of one kind."""
        sel = self.spring_kinds == SPRING_KINDS.index(kind)
        return np.asarray(self.spring_lengths()[sel] / self.rest_lengths[sel] - 1.0, dtype=np.float64)

    def pin_centroid(self) -> FloatArray:
        """Centroid of the pin targets (the pivot of :meth:`move_pins` rotations)."""
        if len(self._pin_index) == 0:
            return np.asarray(self.positions.mean(axis=0), dtype=np.float64)
        return np.asarray(self.pin_targets.mean(axis=0), dtype=np.float64)

    def stable_substeps(self, frame_dt: float = 1.0 / 60.0) -> int:
        """Fewest symplectic substeps per frame the stability estimate allows."""
        limit = self._stable_dt()
        if not math.isfinite(limit):
            return 1
        # The small allowance keeps 1/60 ÷ (1/120) at 2, not 3, after rounding.
        return max(1, math.ceil(frame_dt / limit - 1e-9))

    def substeps_for(self, frame_dt: float) -> int:
        """The steps a frame of ``frame_dt`` seconds takes: ``params.substeps`` when set by hand,
        else the automatic choice for the integrator (see the module docstring)."""
        p = self.params
        if p.substeps > 0:
            return p.substeps
        if p.integrator == "implicit":
            # Drag is explicit in the implicit step: very light cloth in strong wind needs more steps.
            rate = self._drag_rate()
            longest = IMPLICIT_MAX_STEP if rate <= 0 else min(IMPLICIT_MAX_STEP, 0.9 * 2.0 / rate)
            return max(1, math.ceil(frame_dt / longest - 1e-9))
        return self.stable_substeps(frame_dt)

    def _drag_rate(self) -> float:
        """A bound on the drag's ∂f/∂v ÷ m (1/s), Gershgorin over a particle's six triangles:
        each triangle's drag changes by at most 2·½ρc_d·|w|·area per m/s of its mean relative
        velocity ``w``, with |w| at most the wind, plus the gusts, plus 5 m/s of the cloth's own."""
        p = self.params
        if p.drag_coefficient <= 0 or p.air_density <= 0:
            return 0.0
        speed = float(np.linalg.norm(p.wind)) + 5.0 * p.turbulence + 5.0
        area = p.width * p.height / (2.0 * (self.rows - 1) * (self.cols - 1))
        return 4.0 * 0.5 * p.air_density * p.drag_coefficient * speed * area / self.particle_mass

    def _stable_dt(self) -> float:
        """Longest stable symplectic substep, estimated from the rest configuration.

        Gershgorin bounds per particle and axis on the largest eigenvalues λ_K of M⁻¹K and λ_C of
        M⁻¹C (springs act along their direction u: row a gets Σ k·|u_a|·Σ_b|u_b| from both ends),
        then the damped-oscillator condition of semi-implicit Euler, h²·λ_K/4 + h·λ_C/2 ≤ 1.
        Drag acts like damping and adds :meth:`_drag_rate` to λ_C.
        """
        if self._stable_dt_cache is None:
            self._stable_dt_cache = self._compute_stable_dt()
        return self._stable_dt_cache

    def _compute_stable_dt(self) -> float:
        i, j = self.springs[:, 0], self.springs[:, 1]
        d = self.rest_positions[j] - self.rest_positions[i]
        u = np.abs(d / np.linalg.norm(d, axis=1)[:, None])
        w = u * u.sum(axis=1)[:, None]  # (S, 3)
        lam = []
        for coef in (self._spring_k, self._spring_c):
            rows = np.zeros((self.n, 3))
            for a in range(3):
                rows[:, a] = np.bincount(i, coef * w[:, a], self.n) + np.bincount(j, coef * w[:, a], self.n)
            lam.append(2.0 * float(rows.max()) / self.particle_mass)
        lam[1] += self._drag_rate()
        qa, qb = lam[0] / 4.0, lam[1] / 2.0
        if qa <= 0 and qb <= 0:
            return math.inf
        h = 1.0 / qb if qa <= 0 else (-qb + math.sqrt(qb * qb + 4.0 * qa)) / (2.0 * qa)
        return 0.9 * h

    # ---------------------------------------------------------- interaction
    def move_pins(self, translation: Any = (0.0, 0.0, 0.0), rotation: Any = None, *, immediate: bool = False) -> None:
        """Move the pinned set rigidly: rotate about the pins' centroid, then translate.

        ``rotation`` is a rotation vector (axis·angle, radians) or a 3×3 matrix. The pins travel
        to their new places during the next :meth:`step` (with the matching velocity, so the
        springs see a smooth motion) and are exactly there after it. With ``immediate=True`` the
        pinned particles jump there now (for editing while paused).
        """
        t = np.asarray(translation, dtype=np.float64).reshape(3)
        if len(self._pin_index) == 0:
            return
        centre = self.pin_centroid()
        targets = self.pin_targets
        if rotation is not None:
            rot = rotation_matrix(rotation)
            targets = (targets - centre) @ rot.T + centre
        self.pin_targets = targets + t
        if immediate:
            self.positions[self._pin_index] = self.pin_targets
            self.velocities[self._pin_index] = 0.0

    def set_pin_targets(self, targets: Any) -> None:
        """Where the pinned particles are at the end of the next :meth:`step` (they land
        there exactly), in the order of :attr:`pinned_indices`. A character's joint drives
        an attached cloth this way."""
        t = np.asarray(targets, dtype=np.float64)
        if t.shape != (len(self._pin_index), 3):
            raise ValueError(f"pin targets must be ({len(self._pin_index)}, 3), not {t.shape}")
        self.pin_targets = t.copy()

    def set_capsules(self, a: Any, b: Any, radius: Any, a_start: Any = None, b_start: Any = None) -> None:
        """Capsule colliders for the next :meth:`step`: segments ``a[k] → b[k]`` (K, 3) with
        ``radius[k]``, where they are at the end of the step; ``a_start`` / ``b_start`` where
        they are at its start (default: already there). An empty K removes them."""
        end_a = np.asarray(a, dtype=np.float64).reshape(-1, 3)
        end_b = np.asarray(b, dtype=np.float64).reshape(-1, 3)
        rad = np.asarray(radius, dtype=np.float64).reshape(-1)
        if not (len(end_a) == len(end_b) == len(rad)):
            raise ValueError("capsule ends and radii must have the same length")
        if len(rad) and not (np.isfinite(end_a).all() and np.isfinite(end_b).all() and (rad > 0).all()):
            raise ValueError("capsules need finite ends and positive radii")
        if len(rad) == 0:
            self._capsules = self._capsules_now = None
            return
        sa = end_a if a_start is None else np.asarray(a_start, dtype=np.float64).reshape(-1, 3)
        sb = end_b if b_start is None else np.asarray(b_start, dtype=np.float64).reshape(-1, 3)
        if sa.shape != end_a.shape or sb.shape != end_b.shape:
            raise ValueError("capsule start and end places must have the same shape")
        self._capsules = (sa.copy(), sb.copy(), end_a.copy(), end_b.copy(), rad.copy())
        self._capsules_now = (end_a.copy(), end_b.copy(), rad.copy())

    def capsule_penetration(self) -> float:
        """The deepest a free particle lies inside a capsule (at its end place), in metres
        (≤ 0: none is inside)."""
        if self._capsules is None:
            return -math.inf
        _, _, a, b, r = self._capsules
        _, _, _, depth = _capsule_depths(self.positions, a, b, r)
        free = np.ones(self.n, dtype=bool)
        free[self._pin_index] = False
        return float(depth[free].max()) if free.any() else -math.inf

    def energy(self) -> tuple[float, float, float]:
        """(kinetic, gravitational above y = 0, spring) energy in joules."""
        m = self.particle_mass
        kinetic = 0.5 * m * float(np.einsum("ij,ij->", self.velocities, self.velocities))
        gravity = m * self.params.gravity * float(self.positions[:, 1].sum())
        stretch = self.spring_lengths() - self.rest_lengths
        spring = 0.5 * float(np.sum(self._spring_k * stretch * stretch))
        return kinetic, gravity, spring

    @property
    def pinned_indices(self) -> IntArray:
        """Indices of the pinned particles, in the order of :attr:`pin_targets`."""
        return self._pin_index.copy()

    def grab(self, ray_origin: Any, ray_dir: Any, max_distance: float | None = None) -> int | None:
        """Grab the particle nearest to a ray (in front of its origin); None when there is none.

        With ``max_distance`` only particles that close to the ray count.
        """
        i = nearest_particle(self.positions, ray_origin, ray_dir, max_distance)
        if i is not None:
            self.grab_particle(i)
        return i

    def grab_particle(self, index: int) -> None:
        """Grab particle ``index`` where it is now (:meth:`drag_grabbed` then moves it)."""
        if not 0 <= index < self.n:
            raise ValueError(f"particle {index} is outside the cloth's {self.n} particles")
        self.grabbed = int(index)
        self._grab_target = self.positions[index].copy()

    def drag_grabbed(self, target: Any) -> None:
        """Move the grabbed particle to ``target`` during the next step (no-op without a grab)."""
        if self.grabbed is None:
            return
        self._grab_target = np.asarray(target, dtype=np.float64).reshape(3).copy()
        if self.pinned[self.grabbed]:
            slot = int(np.searchsorted(self._pin_index, self.grabbed))
            self.pin_targets[slot] = self._grab_target

    def release(self) -> None:
        """Let go of the grabbed particle; it keeps its velocity."""
        self.grabbed = None
        self._grab_target = None

    # ----------------------------------------------------------- simulation
    def step(self, dt: float = 1.0 / 60.0, should_stop: Callable[[], bool] | None = None) -> None:
        """Advance one display frame of ``dt`` seconds (:meth:`substeps_for` substeps inside).

        Raises ClothBlowUp (and keeps the state from before the frame) when the simulation
        goes unstable; raises it again on every later step until reset. ``should_stop`` is
        asked before every substep; when it answers True the cloth goes back to the state
        from before the frame and :class:`ClothStepCancelled` is raised (a worker thread
        cancels a long implicit step this way, and resuming later gives identical frames).
        """
        if self.error is not None:
            raise self.error
        if not dt > 0:
            raise ValueError("dt must be positive")
        substeps = self.substeps_for(dt)
        if substeps > MAX_AUTO_SUBSTEPS and self.params.substeps == AUTO_SUBSTEPS:
            self.error = self._too_many_substeps_error(dt, substeps)
            raise self.error
        saved = self.state()
        kin_idx, kin_start, kin_end = self._kinematics()
        h = dt / substeps
        kin_vel = (kin_end - kin_start) / dt
        # The turbulent wind field is sampled at the particles once per frame (gusts are ≤ 3 Hz).
        self._air = self._wind_at(self.positions) if self.params.turbulence > 0 else None
        with np.errstate(all="ignore"):
            for s in range(1, substeps + 1):
                if should_stop is not None and should_stop():
                    self.set_state(saved)
                    self._air = None
                    raise ClothStepCancelled(f"cloth step cancelled at t = {self.time:.4f} s")
                kin_pos = kin_end if s == substeps else kin_start + (kin_end - kin_start) * (s / substeps)
                if self._capsules is not None:
                    ca0, cb0, ca1, cb1, cr = self._capsules
                    f = s / substeps
                    self._capsules_now = ((ca1, cb1, cr) if s == substeps else
                                          (ca0 + (ca1 - ca0) * f, cb0 + (cb1 - cb0) * f, cr))
                if self.params.integrator == "implicit":
                    self._implicit_substep(h, kin_idx, kin_pos, kin_vel)
                else:
                    self._symplectic_substep(h, kin_idx, kin_pos, kin_vel)
                self.time += h
            bad = not (np.isfinite(self.positions).all() and np.isfinite(self.velocities).all())
            if not bad:
                bad = float(np.max(np.einsum("ij,ij->i", self.velocities, self.velocities))) > RUNAWAY_SPEED ** 2
        if bad:
            blow_time = self.time
            self.set_state(saved)
            self.error = self._blow_up_error(dt, substeps, blow_time)
            raise self.error

    def _kinematics(self) -> tuple[IntArray, FloatArray, FloatArray]:
        idx = self._pin_index
        start = self.positions[idx]
        end = self.pin_targets
        g = self.grabbed
        if g is not None and self._grab_target is not None and not self.pinned[g]:
            idx = np.append(idx, g)
            start = np.vstack([start, self.positions[g][None]])
            end = np.vstack([end, self._grab_target[None]])
        return idx, start.copy(), end.copy()

    def _wind_at(self, points: FloatArray) -> FloatArray:
        p = self.params
        wind = np.asarray(p.wind, dtype=np.float64)
        if p.turbulence <= 0:
            return np.broadcast_to(wind, points.shape)
        gust = np.zeros(points.shape)
        for m in range(self._turb_k.shape[0]):
            phase = np.einsum("ij,kj->ik", points, self._turb_k[m]) + self._turb_w[m] * self.time + self._turb_phase[m]
            gust += np.sin(phase)
        return wind + gust * (p.turbulence / math.sqrt(self._turb_k.shape[0] / 2.0))

    def _add_drag(self, x: FloatArray, v: FloatArray, force: FloatArray) -> None:
        p = self.params
        coef = 0.5 * p.air_density * p.drag_coefficient
        if coef <= 0:
            return
        if self.accelerated:
            air = self._air if self._air is not None else self._wind_field()
            cloth_kernels.drag_forces(x, v, air, self.triangles, coef, force)
            return
        # Velocity relative to the air at each particle; a triangle's is the mean of its corners'.
        if self._air is not None:
            rel = v - self._air
        else:
            rel = v - np.asarray(p.wind, dtype=np.float64)
        R, C = self.rows, self.cols
        x2 = x.reshape(R, C, 3)
        r2 = rel.reshape(R, C, 3)
        f2 = force.reshape(R, C, 3)
        # Quad corners: a (r, c), b (r, c+1), c (r+1, c), d (r+1, c+1); triangles (a, c, d) and (a, d, b).
        sa, sb, sc, sd = (np.s_[:-1, :-1], np.s_[:-1, 1:], np.s_[1:, :-1], np.s_[1:, 1:])
        for corners in ((sa, sc, sd), (sa, sd, sb)):
            p0, p1, p2 = (x2[k] for k in corners)
            nrm = np.cross(p1 - p0, p2 - p0)
            vel = (r2[corners[0]] + r2[corners[1]] + r2[corners[2]]) / 3.0
            # |v|²·a·n̂ with a = area·(v̂·n̂), n̂ = nrm/|nrm|, area = |nrm|/2  →  |v|·(v·nrm)·nrm / (2·|nrm|)
            nlen = np.sqrt(np.einsum("...k,...k->...", nrm, nrm))
            speed = np.sqrt(np.einsum("...k,...k->...", vel, vel))
            vn = np.einsum("...k,...k->...", vel, nrm)
            scale = np.divide(-coef * speed * vn, 6.0 * nlen, out=np.zeros_like(nlen), where=nlen > 0)
            fc = nrm * scale[..., None]  # a third of the triangle's drag
            for corner in corners:
                f2[corner] += fc

    def _spring_forces(self, x: FloatArray, v: FloatArray, force: FloatArray) -> None:
        if self.accelerated:
            cloth_kernels.spring_forces(x, v, self._si, self._sj, self.rest_lengths, self._spring_k,
                                        self._spring_c, force)
            return
        d, dv, ln, s = self._buf_d, self._buf_dv, self._buf_l, self._buf_s
        for f in self._families:
            o = f.offset
            np.subtract(x[o:], x[:-o], out=d[f.start:f.stop])
            np.subtract(v[o:], v[:-o], out=dv[f.start:f.stop])
        np.einsum("ij,ij->i", d, d, out=ln)
        np.sqrt(ln, out=ln)
        np.maximum(ln, 1e-12, out=s)
        np.divide(1.0, s, out=s)
        d *= s[:, None]  # d is now the unit direction u from i to j
        np.einsum("ij,ij->i", d, dv, out=s)
        s *= self._fam_c
        ln -= self._fam_rest
        ln *= self._fam_k
        ln += s  # scalar tension k·(l − L) + c·(dv·u)
        d *= ln[:, None]  # force on i; j gets the opposite
        for f in self._families:
            o = f.offset
            seg = d[f.start:f.stop]
            force[:-o] += seg
            force[o:] -= seg

    def _external_forces(self, x: FloatArray, v: FloatArray) -> FloatArray:
        force = self._force
        force[:] = 0.0
        force[:, 1] = -self.params.gravity * self.particle_mass
        self._add_drag(x, v, force)
        return force

    def _symplectic_substep(self, h: float, kin_idx: IntArray, kin_pos: FloatArray, kin_vel: FloatArray) -> None:
        x, v = self.positions, self.velocities
        if self.accelerated:
            # Forces and the update in one compiled pass that releases the GIL.
            p = self.params
            coef = 0.5 * p.air_density * p.drag_coefficient
            air = self._air if self._air is not None else self._wind_field()
            if self._inv_mass_h is None or self._inv_mass_h[0] != h:
                self._inv_mass_h = (h, self._inv_mass * h)
            cloth_kernels.symplectic_substep(x, v, air, self._si, self._sj, self.rest_lengths, self._spring_k,
                                             self._spring_c, self.triangles, coef, p.gravity * self.particle_mass,
                                             self._inv_mass_h[1], h, kin_idx, np.ascontiguousarray(kin_pos),
                                             np.ascontiguousarray(kin_vel), self._force)
            self._collide(kin_idx)
            return
        force = self._external_forces(x, v)
        self._spring_forces(x, v, force)
        force *= self._inv_mass[:, None] * h
        v += force
        v[kin_idx] = kin_vel
        x += v * h
        x[kin_idx] = kin_pos
        self._collide(kin_idx)

    # ----------------------------------------------------------- implicit
    def _implicit_setup(self) -> dict[str, Any]:
        """The block-CSR pattern of the implicit matrix (built once per grid) and work arrays.

        Row i holds blocks (i, i) and (i, j) for every spring touching i, columns sorted;
        ``slot_diag[i]``, ``slot_ij[s]``, ``slot_ji[s]`` say where each spring writes."""
        if self._implicit_cache is not None:
            return self._implicit_cache
        n = self.n
        si, sj = self.springs[:, 0], self.springs[:, 1]
        ns = len(si)
        rows = np.concatenate([np.arange(n), si, sj])
        cols = np.concatenate([np.arange(n), sj, si])
        key = rows * n + cols
        order = np.argsort(key, kind="stable")
        slot = np.empty_like(order)
        slot[order] = np.arange(len(order))
        indptr = np.concatenate([[0], np.cumsum(np.bincount(rows, minlength=n))]).astype(np.int64)
        indices = np.ascontiguousarray(cols[order].astype(np.int64))
        nblocks = len(order)
        cache: dict[str, Any] = {
            "slot_diag": np.ascontiguousarray(slot[:n]), "slot_ij": np.ascontiguousarray(slot[n:n + ns]),
            "slot_ji": np.ascontiguousarray(slot[n + ns:]), "indptr": indptr, "indices": indices,
            "nblocks": nblocks, "data": np.zeros((nblocks, 9)), "pre": np.zeros((n, 6)), "rhs": np.zeros((n, 3)),
            "work": [np.zeros((n, 3)) for _ in range(4)],
            "maxiter": max(200, 8 * int(math.sqrt(n))),
        }
        if not self.accelerated:
            import scipy.sparse as sp  # only the numpy implicit path needs it

            cache["incidence"] = sp.csr_matrix(
                (np.ones(2 * ns), (np.concatenate([si, sj]), np.concatenate([np.arange(ns)] * 2))), shape=(n, ns))
            cache["bsr_matrix"] = sp.bsr_matrix
        self._implicit_cache = cache
        return cache

    def _implicit_substep(self, h: float, kin_idx: IntArray, kin_pos: FloatArray, kin_vel: FloatArray) -> None:
        cache = self._implicit_setup()
        n = self.n
        free = np.ones(n, dtype=bool)
        free[kin_idx] = False
        atol = self.solver_atol_acceleration * h * self.particle_mass * math.sqrt(n)
        dv = self._solver_start
        if self.accelerated:
            p = self.params
            air = self._air if self._air is not None else self._wind_field()
            r, z, d, ad = cache["work"]
            self.last_iterations = cloth_kernels.implicit_substep(
                self.positions, self.velocities, air, self._si, self._sj, self.rest_lengths, self._spring_k,
                self._spring_c, self.triangles, 0.5 * p.air_density * p.drag_coefficient,
                p.gravity * self.particle_mass, self.particle_mass, h, kin_idx, np.ascontiguousarray(kin_pos),
                np.ascontiguousarray(kin_vel), free, cache["indptr"], cache["indices"], cache["slot_diag"],
                cache["slot_ij"], cache["slot_ji"], cache["data"], cache["pre"], cache["rhs"], self._force, dv,
                r, z, d, ad, self.solver_rtol, atol, cache["maxiter"], self.warm_start)
            self._collide(kin_idx)
            return
        self._implicit_substep_numpy(h, kin_idx, kin_pos, kin_vel, free, atol, cache)

    def _implicit_substep_numpy(self, h: float, kin_idx: IntArray, kin_pos: FloatArray, kin_vel: FloatArray,
                                free: BoolArray, atol: float, cache: dict[str, Any]) -> None:
        """The same step as the compiled kernel, vectorised (the fallback without numba)."""
        n = self.n
        x, v = self.positions, self.velocities
        v[kin_idx] = kin_vel
        force = self._external_forces(x, v)
        self._spring_forces(x, v, force)

        si, sj = self._si, self._sj
        k, c, rest = self._spring_k, self._spring_c, self.rest_lengths
        d = x[sj] - x[si]
        ln = np.sqrt(np.einsum("ij,ij->i", d, d))
        u = d / np.maximum(ln, 1e-12)[:, None]
        beta = np.maximum(0.0, 1.0 - rest / np.maximum(ln, 1e-12))
        # Block per spring: S = h²·K_s + h·c·uuᵀ with K_s = k·(β·I + (1 − β)·uuᵀ).
        a_iso = h * h * k * beta
        a_uu = h * h * k * (1.0 - beta) + h * c
        uu = u[:, :, None] * u[:, None, :]
        blocks = uu * a_uu[:, None, None]
        blocks[:, 0, 0] += a_iso
        blocks[:, 1, 1] += a_iso
        blocks[:, 2, 2] += a_iso
        diag = (cache["incidence"] @ blocks.reshape(-1, 9)).reshape(n, 3, 3)
        diag[:, 0, 0] += self.particle_mass
        diag[:, 1, 1] += self.particle_mass
        diag[:, 2, 2] += self.particle_mass
        diag[~free] = np.eye(3)
        both_free = (free[si] & free[sj]).astype(np.float64)
        off = -blocks * both_free[:, None, None]
        data = np.empty((cache["nblocks"], 3, 3))
        data[cache["slot_diag"]] = diag
        data[cache["slot_ij"]] = off
        data[cache["slot_ji"]] = off
        a = cache["bsr_matrix"]((data, cache["indices"], cache["indptr"]), shape=(3 * n, 3 * n))

        # rhs = h·(f + h·(∂f/∂x)·v); (∂f/∂x·v)_i = Σ K_s·(v_j − v_i), the opposite at j.
        dv = v[sj] - v[si]
        kdv = (k * beta)[:, None] * dv + (k * (1.0 - beta) * np.einsum("ij,ij->i", u, dv))[:, None] * u
        kv = np.zeros((n, 3))
        for comp in range(3):
            kv[:, comp] = np.bincount(si, kdv[:, comp], n) - np.bincount(sj, kdv[:, comp], n)
        rhs = h * (force + h * kv)
        rhs[~free] = 0.0
        with np.errstate(all="ignore"):
            pre = np.linalg.inv(diag) if np.isfinite(diag).all() else np.full_like(diag, np.nan)
        start = self._solver_start
        self.last_iterations = _pcg(a, rhs.ravel(), pre, start.reshape(-1), self.solver_rtol, atol,
                                    cache["maxiter"], self.warm_start)
        v += start
        v[kin_idx] = kin_vel
        x += v * h
        x[kin_idx] = kin_pos
        self._collide(kin_idx)

    # ----------------------------------------------------------- collisions
    def _collide(self, kin_idx: IntArray) -> None:
        p = self.params
        x = self.positions
        margin = p.collision_margin
        if p.ground_enabled:
            floor = p.ground_height + margin
            hit = x[:, 1] < floor
            if len(kin_idx):
                hit[kin_idx] = False
            if hit.any():
                idx = np.flatnonzero(hit)
                x[idx, 1] = floor
                normal = np.broadcast_to(np.array([0.0, 1.0, 0.0]), (len(idx), 3))
                self._respond(idx, normal, p.ground_restitution, p.ground_friction)
        for centre, radius, restitution, friction in self._spheres:
            rad = radius + margin
            rel = x - centre
            dist2 = np.einsum("ij,ij->i", rel, rel)
            hit = dist2 < rad * rad
            if len(kin_idx):
                hit[kin_idx] = False
            if not hit.any():
                continue
            idx = np.flatnonzero(hit)
            r = rel[idx]
            dist = np.sqrt(dist2[idx])
            normal = np.empty_like(r)
            ok = dist > 1e-12
            normal[ok] = r[ok] / dist[ok, None]
            normal[~ok] = (0.0, 1.0, 0.0)
            # A relative 1e-12 outside the surface, so rounding never leaves a point inside.
            x[idx] = centre + normal * (rad * (1.0 + 1e-12))
            self._respond(idx, normal, restitution, friction)
        if self._capsules_now is not None:
            self._collide_capsules(kin_idx, *self._capsules_now)

    def _collide_capsules(self, kin_idx: IntArray, a: FloatArray, b: FloatArray, radius: FloatArray) -> None:
        """Push free particles out of the capsules to radius + margin; drop inward velocity."""
        x, v = self.positions, self.velocities
        reach = radius + self.params.collision_margin
        for _ in range(3):   # overlapping capsules: a push out of one may end in another
            closest, normal, which, depth = _capsule_depths(x, a, b, reach)
            if len(kin_idx):
                depth[kin_idx] = -math.inf
            hit = depth > 0
            if not hit.any():
                return
            idx = np.flatnonzero(hit)
            x[idx] = closest[idx] + normal[idx] * (reach[which[idx]] * (1.0 + 1e-12))[:, None]
            vn = np.einsum("ij,ij->i", v[idx], normal[idx])
            v[idx] -= np.minimum(vn, 0.0)[:, None] * normal[idx]

    def _respond(self, idx: IntArray, normal: FloatArray, restitution: float, friction: float) -> None:
        v = self.velocities
        vel = v[idx]
        vn = np.einsum("ij,ij->i", vel, normal)
        approaching = vn < 0
        dvn = np.where(approaching, -(1.0 + restitution) * vn, 0.0)
        vt = vel - vn[:, None] * normal
        vt_len = np.sqrt(np.einsum("ij,ij->i", vt, vt))
        # Coulomb friction: the tangential speed drops by μ·|Δv_n| (never reversing).
        keep = np.where(vt_len > 0, np.maximum(0.0, 1.0 - friction * dvn / np.maximum(vt_len, 1e-300)), 1.0)
        vn_new = np.where(approaching, -restitution * vn, vn)
        v[idx] = vt * keep[:, None] + vn_new[:, None] * normal

    # ------------------------------------------------------------ blow-ups
    def _too_many_substeps_error(self, dt: float, substeps: int) -> ClothBlowUp:
        msg = (f"The symplectic integrator would need {substeps} substeps for each {dt * 1000:.3g} ms frame "
               f"with these springs (more than {MAX_AUTO_SUBSTEPS}). Set 'integrator' to 'implicit', or lower "
               f"the stiffness or the damping, or raise 'total_mass'.")
        return ClothBlowUp(msg, "integrator", self.time)

    def _blow_up_error(self, dt: float, substeps: int, when: float) -> ClothBlowUp:
        p = self.params
        h = dt / substeps
        if p.integrator == "symplectic":
            limit = self._stable_dt()
            need = math.ceil(substeps * h / limit) if limit < math.inf else substeps
            ks = {kind: p.stiffness(kind) for kind in SPRING_KINDS}
            stiffest = max(ks, key=lambda kd: ks[kd])
            if h > limit:
                msg = (f"The cloth simulation blew up at t = {when:.3f} s: a symplectic substep of "
                       f"{h * 1000:.3g} ms is too long for {stiffest} stiffness {ks[stiffest]:g} N/m on "
                       f"{self.particle_mass:.3g} kg particles (stable below about {limit * 1000:.3g} ms). "
                       f"Raise 'substeps' to at least {max(need, substeps + 1)} (or 0, automatic), "
                       f"lower '{stiffest}_stiffness' "
                       f"or the damping, raise 'total_mass', or set 'integrator' to 'implicit'.")
                return ClothBlowUp(msg, "substeps", when)
            msg = (f"The cloth simulation blew up at t = {when:.3f} s although the substep looks stable; "
                   f"the forces are too strong for {substeps} substeps. Raise 'substeps', lower 'wind' or "
                   f"'turbulence' or 'drag_coefficient', or set 'integrator' to 'implicit'.")
            return ClothBlowUp(msg, "substeps", when)
        msg = (f"The implicit cloth solver blew up at t = {when:.3f} s. Lower 'wind', 'turbulence' or "
               f"'drag_coefficient', or raise 'substeps' (now {substeps} a frame).")
        return ClothBlowUp(msg, "wind", when)


def _capsule_depths(x: FloatArray, a: FloatArray, b: FloatArray,
                    radius: FloatArray) -> tuple[FloatArray, FloatArray, IntArray, FloatArray]:
    """For every point: the closest point on its deepest capsule's segment, the outward unit
    normal, that capsule's index and the depth ``radius − distance`` (> 0: inside)."""
    ab = b - a
    ab2 = np.einsum("kj,kj->k", ab, ab)
    ap = x[:, None, :] - a[None, :, :]
    t = np.clip(np.einsum("nkj,kj->nk", ap, ab) / np.where(ab2 > 0, ab2, 1.0), 0.0, 1.0)
    closest = a[None, :, :] + t[:, :, None] * ab[None, :, :]
    d = x[:, None, :] - closest
    dist = np.sqrt(np.einsum("nkj,nkj->nk", d, d))
    pen = radius[None, :] - dist
    k = np.argmax(pen, axis=1)
    rows = np.arange(len(x))
    dk, lk = d[rows, k], dist[rows, k]
    normal = np.empty_like(dk)
    ok = lk > 1e-12
    normal[ok] = dk[ok] / lk[ok, None]
    # On the axis itself: any direction across the segment.
    across = np.cross(ab[k[~ok]], np.array([0.0, 0.0, 1.0]))
    across[np.einsum("ij,ij->i", across, across) < 1e-24] = (1.0, 0.0, 0.0)
    normal[~ok] = across / np.linalg.norm(across, axis=1)[:, None] if len(across) else across
    return closest[rows, k], normal, k.astype(np.int64), pen[rows, k]


def _dot(a: FloatArray, b: FloatArray) -> float:
    # einsum, not BLAS: a threaded BLAS dot stalls on a busy machine and is no faster at these sizes.
    return float(np.einsum("i,i->", a, b))


def _pcg(a: Any, b: FloatArray, pre: FloatArray, x: FloatArray, rtol: float, atol: float, maxiter: int,
         warm: bool) -> int:
    """Conjugate gradients on ``a·x = b``, preconditioned with ``pre`` (the inverse 3×3
    diagonal blocks, (N, 3, 3)), in place on ``x``: from ``x`` when ``warm`` else from zero,
    until ``|r| ≤ max(rtol·|b|, atol)`` or ``maxiter`` iterations. The numpy twin of
    ``cloth_kernels.block_pcg``; returns the iterations done (−1 when ``b`` is not finite)."""
    n = len(pre)

    def precondition(r: FloatArray) -> FloatArray:
        return np.einsum("nij,nj->ni", pre, r.reshape(n, 3)).reshape(-1)

    target = max(rtol * math.sqrt(_dot(b, b)), atol)
    if not math.isfinite(target):
        x[:] = np.nan  # the step is already lost; the caller reports the blow-up
        return -1
    if warm:
        r = b - a @ x
    else:
        x[:] = 0.0
        r = b.copy()
    if target == 0.0 or math.sqrt(_dot(r, r)) <= target:
        return 0
    z = precondition(r)
    p = z.copy()
    rz = _dot(r, z)
    it = 0
    while it < maxiter:
        it += 1
        ap = a @ p
        pap = _dot(p, ap)
        if not pap > 0.0:
            break
        alpha = rz / pap
        x += alpha * p
        r -= alpha * ap
        if math.sqrt(_dot(r, r)) <= target:
            break
        z = precondition(r)
        rz_new = _dot(r, z)
        p *= rz_new / rz
        p += z
        rz = rz_new
    return it


def vertex_normals(positions: FloatArray, triangles: IntArray, fallback: Any = (0.0, 0.0, 1.0)) -> FloatArray:
    """Smooth unit normals per vertex: the sum of the adjacent triangles' area-weighted normals.

    Vertices with no area around them get ``fallback``.
    """
    x = np.asarray(positions, dtype=np.float64)
    t = np.asarray(triangles, dtype=np.int64)
    n = len(x)
    fn = np.cross(x[t[:, 1]] - x[t[:, 0]], x[t[:, 2]] - x[t[:, 0]])
    vn = np.zeros((n, 3))
    for k in range(3):
        vn[:, k] = (np.bincount(t[:, 0], fn[:, k], n) + np.bincount(t[:, 1], fn[:, k], n)
                    + np.bincount(t[:, 2], fn[:, k], n))
    length = np.sqrt(np.einsum("ij,ij->i", vn, vn))
    ok = length > 1e-300
    vn[ok] /= length[ok, None]
    vn[~ok] = np.asarray(fallback, dtype=np.float64)
    return vn


def nearest_particle(positions: FloatArray, ray_origin: Any, ray_dir: Any,
                     max_distance: float | None = None) -> int | None:
    """The particle nearest to a ray (in front of its origin), or None.

    With ``max_distance`` only particles that close to the ray count. :meth:`Cloth.grab`
    uses it; a viewer holding a snapshot of the positions can pick with it too.
    """
    o = np.asarray(ray_origin, dtype=np.float64).reshape(3)
    d = np.asarray(ray_dir, dtype=np.float64).reshape(3)
    norm = float(np.linalg.norm(d))
    if not norm > 0 or len(positions) == 0:
        return None
    d = d / norm
    w = np.asarray(positions, dtype=np.float64) - o
    along = w @ d
    dist2 = np.einsum("ij,ij->i", w, w) - along * along
    dist2[along < 0] = np.inf
    i = int(np.argmin(dist2))
    if not np.isfinite(dist2[i]):
        return None
    if max_distance is not None and dist2[i] > max_distance * max_distance:
        return None
    return i


def grid_index(cols: int, row: int, col: int) -> int:
    """Flat particle index of ``(row, col)`` in a cloth with ``cols`` columns."""
    return row * cols + col


def pins_from_cells(cols: int, cells: Iterable[Sequence[int]]) -> list[int]:
    """Flat indices for ``custom_pins`` from ``(row, col)`` pairs."""
    return [grid_index(cols, int(r), int(c)) for r, c in cells]
