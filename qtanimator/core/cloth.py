"""Mass-spring cloth: springs, drag, wind, collisions, pins and grabbing (issue 5).

A rectangular cloth of ``rows × cols`` particles, SI units, y up (ARCHITECTURE §4 Cloth).
This module holds the simulation: its state, the step and its integrators, and blow-ups.
The pieces it runs on have modules of their own (their docstrings give the model):
:mod:`~qtanimator.core.cloth_params` (:class:`ClothParams`, :class:`Sphere`, re-exported
here), :mod:`~qtanimator.core.cloth_grid` (particles, pins, spring families, triangles),
:mod:`~qtanimator.core.cloth_forces` (springs, gravity, drag, turbulent wind),
:mod:`~qtanimator.core.cloth_collide` (ground, spheres, moving capsules),
:mod:`~qtanimator.core.cloth_implicit` (the implicit solve in numpy) and
:mod:`~qtanimator.core.cloth_kernels` (the compiled kernels).

Kinematic particles (pins, the grabbed particle) and moving capsules are set between steps
(:mod:`~qtanimator.core.cloth_interaction`, whose methods :class:`Cloth` inherits).

Integration
-----------
* ``"implicit"`` (the default): backward Euler linearised once per step (Baraff & Witkin
  1998; :mod:`~qtanimator.core.cloth_implicit`), compiled with numba, else numpy / scipy
  (5-7× slower). Its conjugate gradient stops at ``|r| ≤ max(rtol·|b|, atol)``:
  ``rtol`` = :data:`SOLVER_RTOL`, ``atol`` = :data:`SOLVER_ATOL_ACCELERATION` × h × particle
  mass × √N, or after ``max(200, 8·√N)`` iterations (the reasons are in that module). Stable
  for every stiffness and damping the cloth panel allows; large steps damp fast motion
  (backward Euler loses energy), so :data:`IMPLICIT_MAX_STEP` caps the automatic step.
* ``"symplectic"``: semi-implicit Euler (``v += a·h; x += v·h``), accurate and cheap per
  substep but only stable below a step that shrinks with stiffness and damping and with
  lighter particles (finer grids). When numba is installed the spring and drag forces come
  from compiled kernels (~10× faster, tested against the numpy code);
  ``Cloth(params, accelerate=False)`` forces numpy.
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
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.core import cloth_kernels
from qtanimator.core.cloth_collide import collide, sphere_arrays
from qtanimator.core.cloth_forces import add_drag, add_springs, drag_rate, stable_dt, turbulence_modes, wind_at
from qtanimator.core.cloth_grid import BoolArray as BoolArray
from qtanimator.core.cloth_grid import FloatArray as FloatArray
from qtanimator.core.cloth_grid import IntArray as IntArray
from qtanimator.core.cloth_grid import build_grid
from qtanimator.core.cloth_grid import grid_index as grid_index
from qtanimator.core.cloth_grid import nearest_particle as nearest_particle
from qtanimator.core.cloth_grid import pins_from_cells as pins_from_cells
from qtanimator.core.cloth_grid import rotation_matrix as rotation_matrix
from qtanimator.core.cloth_grid import vertex_normals as vertex_normals
from qtanimator.core.cloth_implicit import implicit_pattern, implicit_step_numpy
from qtanimator.core.cloth_interaction import ClothInteraction
from qtanimator.core.cloth_params import AUTO_SUBSTEPS as AUTO_SUBSTEPS
from qtanimator.core.cloth_params import INTEGRATORS as INTEGRATORS
from qtanimator.core.cloth_params import PIN_MODES as PIN_MODES
from qtanimator.core.cloth_params import SPRING_KINDS as SPRING_KINDS
from qtanimator.core.cloth_params import ClothParams as ClothParams
from qtanimator.core.cloth_params import Sphere as Sphere

__all__ = [
    "AUTO_SUBSTEPS", "IMPLICIT_MAX_STEP", "INTEGRATORS", "MAX_AUTO_SUBSTEPS", "PIN_MODES",
    "SOLVER_ATOL_ACCELERATION", "SOLVER_RTOL", "SPRING_KINDS", "Cloth", "ClothBlowUp", "ClothParams", "ClothState",
    "ClothStepCancelled", "Sphere", "grid_index", "nearest_particle", "pins_from_cells", "rotation_matrix",
    "vertex_normals",
]


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


class Cloth(ClothInteraction):
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
        g = build_grid(p)
        n = g.n
        self.rows, self.cols, self.n = g.rows, g.cols, n
        self._rot = g.rotation
        self.rest_positions: FloatArray = g.rest_positions
        self.uvs: FloatArray = g.uvs
        self.pinned: BoolArray = g.pinned
        self._pin_index: IntArray = g.pin_index

        self.particle_mass = p.particle_mass
        self._inv_mass = np.full(n, 1.0 / self.particle_mass)

        # Spring families (slices of the particle array) and their work buffers.
        self._families = g.families
        self._fam_valid, self._fam_kind, self._fam_rest = g.fam_valid, g.fam_kind, g.fam_rest
        m = len(g.fam_valid)
        self._buf_d = np.empty((m, 3))
        self._buf_dv = np.empty((m, 3))
        self._buf_l = np.empty(m)
        self._buf_s = np.empty(m)
        self._force = np.empty((n, 3))

        # The same springs as an explicit list (for the implicit solver and for drawing).
        self.springs: IntArray = g.springs
        self.spring_kinds: npt.NDArray[np.int8] = g.spring_kinds
        self.rest_lengths: FloatArray = g.rest_lengths
        self._si, self._sj = g.si, g.sj
        self._set_spring_constants()
        self.triangles: IntArray = g.triangles

        self._spheres = sphere_arrays(p)
        self._turbulence = turbulence_modes(p.turbulence_seed)
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
        """A bound on the drag's ∂f/∂v ÷ m (1/s) (:func:`~qtanimator.core.cloth_forces.drag_rate`)."""
        return drag_rate(self.params, self.rows, self.cols, self.particle_mass)

    def _stable_dt(self) -> float:
        """Longest stable symplectic substep, estimated from the rest configuration
        (:func:`~qtanimator.core.cloth_forces.stable_dt`, cached)."""
        if self._stable_dt_cache is None:
            self._stable_dt_cache = stable_dt(self.springs, self.rest_positions, self._spring_k, self._spring_c,
                                              self.particle_mass, self._drag_rate())
        return self._stable_dt_cache

    def energy(self) -> tuple[float, float, float]:
        """(kinetic, gravitational above y = 0, spring) energy in joules."""
        m = self.particle_mass
        kinetic = 0.5 * m * float(np.einsum("ij,ij->", self.velocities, self.velocities))
        gravity = m * self.params.gravity * float(self.positions[:, 1].sum())
        stretch = self.spring_lengths() - self.rest_lengths
        spring = 0.5 * float(np.sum(self._spring_k * stretch * stretch))
        return kinetic, gravity, spring

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

    def _wind_at(self, points: FloatArray) -> FloatArray:
        return wind_at(self.params, self._turbulence, self.time, points)

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
        add_drag(x, rel, self.rows, self.cols, coef, force)

    def _spring_forces(self, x: FloatArray, v: FloatArray, force: FloatArray) -> None:
        if self.accelerated:
            cloth_kernels.spring_forces(x, v, self._si, self._sj, self.rest_lengths, self._spring_k,
                                        self._spring_c, force)
            return
        add_springs(self._families, x, v, self._fam_k, self._fam_c, self._fam_rest,
                    (self._buf_d, self._buf_dv, self._buf_l, self._buf_s), force)

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
        """The block-CSR pattern of the implicit matrix and work arrays, built once per grid
        (:func:`~qtanimator.core.cloth_implicit.implicit_pattern`)."""
        if self._implicit_cache is None:
            self._implicit_cache = implicit_pattern(self.n, self.springs, self.accelerated)
        return self._implicit_cache

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
        x, v = self.positions, self.velocities
        v[kin_idx] = kin_vel
        force = self._external_forces(x, v)
        self._spring_forces(x, v, force)
        springs = (self._si, self._sj, self._spring_k, self._spring_c, self.rest_lengths)
        self.last_iterations = implicit_step_numpy(x, v, force, springs, self.particle_mass, h, kin_idx, kin_pos,
                                                   kin_vel, free, self._solver_start, (self.solver_rtol, atol),
                                                   self.warm_start, cache)
        self._collide(kin_idx)

    # ----------------------------------------------------------- collisions
    def _collide(self, kin_idx: IntArray) -> None:
        collide(self.params, self.positions, self.velocities, self._spheres, self._capsules_now, kin_idx)

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
