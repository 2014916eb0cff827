"""Pendulum (dynamic) joints: secondary motion driven by gravity and the pivot's motion.

A dynamic joint's angle θ is its **world** angle (it hangs down whatever its parent does).
With y0 the rest-pose pivot → centre-of-mass vector, φ = atan2(y0.x, y0.y), m the mass,
I the moment about the pivot and a the pivot's acceleration (ARCHITECTURE section 4):

    I·θ'' = −m·g·L·sin(θ + φ) − m·⟨a, y⊥⟩,   y⊥ = J·R(θ)·y0,  J(x, y) = (y, −x)

Joints whose dynamic parent is dynamic too form a chain (a tree in general). With
``coupled`` on they are integrated with their true equations of motion (Lagrange, world
angles as coordinates): M(θ)·θ'' = Q(θ) + C(θ, θ'); with it off every joint swings on its
own with the acceleration of the top joint's pivot passed down (the reference program).

Time derivatives are per second; lengths are SVG units. Single joints integrate with
symplectic Euler (ω ← ω + τ·θ''; θ ← θ + τ·ω) at a fixed step, then damping
ω ← ω·e^(−aτ); ``leapfrog`` (second order, symplectic) and ``rk4`` can be chosen. A
coupled chain's Hamiltonian is not separable (its mass matrix depends on the angles), where
explicit symplectic Euler gains energy, so coupled chains always use RK4 (energy error
O(τ⁴), below 1e-5 relative over thousands of steps in the tests).

Joint limits (``limits``: the local angle relative to the parent, by joint) make a dynamic
joint bounce: the step is cut at the crossing, the relative angular velocity is reversed and
scaled by ``restitution`` (:mod:`qtanimator.core.joint_bounce`), so each bounce keeps e² of
the kinetic energy at impact.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.core.joint_bounce import ON_LIMIT, Bounce, BoundedUnit, bounded_step, hermite

# Re-exported: the groups and pivot accelerations, the constants and the blow-up check.
from qtanimator.core.pendulum_groups import (
    PendulumGroup,
    build_groups,
    perp,
    pivot_accelerations,
    rotate,
    rotation_pivot_terms,
)
from qtanimator.core.pendulum_params import (
    INTEGRATORS,
    MIN_STEP,
    PRESETS,
    RUNAWAY_RATE,
    FloatArray,
    PendulumBlowUp,
    PendulumParams,
    check_state,
)
from qtanimator.core.rig2d import Character


def _decay(damping: float, tau: float) -> float:
    """e^(−a·τ), the damping factor of one step; a negative damping so strong that the
    factor overflows gives inf (the blow-up check then reports it) instead of an error."""
    exponent = -damping * tau
    return math.inf if exponent > 709.0 else math.exp(exponent)


Num = Any  # a float or a float array: the single-pendulum equation takes either


def single_acceleration(c: Num, s: Num, ox: Num, oy: Num, ax: Num, ay: Num, mass: Num, g: float,
                        inertia: Num, ell2: Num, point_mass_forcing: bool,
                        live_inertia: Num = 1.0, live_ell2: Num = 1.0) -> Num:
    """θ'' of uncoupled pendulum joints: the module's equation, written once, for floats
    (one pendulum's fast loop) or arrays (every single joint at once) alike.

    ``c``, ``s``: cos θ, sin θ of the world angle; (``ox``, ``oy``): the rest pivot → centre
    of mass vector y0, so y = R(θ)·y0 = (c·ox + s·oy, −s·ox + c·oy) and y⊥ = J·y = (y.y, −y.x);
    (``ax``, ``ay``): the pivot's acceleration a; ``inertia``: I about the pivot; ``ell2``:
    |y0|² (the handout's point-mass forcing ``−⟨a, y⊥⟩ / L²`` in place of m / I). Then

        I·θ'' = m·⟨(0, g), y⊥⟩ − m·⟨a, y⊥⟩,   ⟨(0, g), y⊥⟩ = −g·y.x = −g·L·sin(θ + φ).

    A joint without inertia does not swing and one without a lever gets no point-mass
    forcing: the caller passes 1 for such a divisor and 0 as its ``live_*`` factor.
    """
    yx = c * ox + s * oy
    yy = -s * ox + c * oy
    grav = mass * g * (-yx)
    forcing = yy * ax - yx * ay
    if point_mass_forcing:
        return grav / inertia * live_inertia - forcing / ell2 * live_ell2
    return (grav - mass * forcing) / inertia * live_inertia


def _divisor(x: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``x`` as a divisor of :func:`single_acceleration` and its live factor (1 where x > 0)."""
    live = x > 0
    return np.where(live, x, 1.0), live.astype(np.float64)


class PendulumSystem:
    """All dynamic joints of one character and their integration.

    ``limits`` (by joint index, None = free) bound the dynamic joints' local angles
    (relative to the parent, radians); a joint that reaches one bounces (see the module).
    """

    def __init__(self, character: Character, params: PendulumParams | None = None,
                 limits: Sequence[tuple[float, float] | None] | None = None) -> None:
        self.character = character
        self.params = params or PendulumParams()
        self.groups = build_groups(character, self.params)
        singles = [g for g in self.groups if len(g.joints) == 1]
        self._coupled = [g for g in self.groups if len(g.joints) > 1]
        offset = np.array([g.offset[0] for g in singles]).reshape(-1, 2)
        self._singles = (np.array([g.top for g in singles], dtype=np.intp),
                         np.array([g.mass[0] for g in singles]), np.array([g.inertia[0] for g in singles]),
                         offset, (offset ** 2).sum(axis=1))
        n = len(character.joints)
        self.limits = np.tile(np.array([-math.inf, math.inf]), (n, 1))
        for k, lim in enumerate(limits or []):
            if lim is not None and k < n and character.joints[k].is_dynamic:
                self.limits[k] = (float(lim[0]), float(lim[1]))
        #: Dynamic joints with a limit: they bounce.
        self.bounded = np.asarray(character.dynamic & np.isfinite(self.limits).any(axis=1), dtype=bool)
        #: The bounces of the last :meth:`step`.
        self.bounces: list[Bounce] = []
        # The dynamic part of each joint's parent's world angle: its nearest dynamic
        # ancestor-or-self (−1: none; the parent's world angle is then all keyed).
        nearest = [-1] * n
        self._parent_dynamic = np.full(n, -1, dtype=np.intp)
        for k, j in enumerate(character.joints):
            if j.parent is not None:
                self._parent_dynamic[k] = nearest[j.parent]
            nearest[k] = k if j.is_dynamic else (-1 if j.parent is None else nearest[j.parent])
        self._units: list[tuple[int, PendulumGroup | int]] = []  # (top, group or single's position)
        for pos, top in enumerate(self._singles[0]):
            if self.bounded[int(top)]:
                self._units.append((int(top), pos))
        for g in self._coupled:
            if self.bounded[g.joints].any():
                self._units.append((g.top, g))
        self._units.sort(key=lambda u: u[0])
        self._bounded_singles = np.array([int(self._singles[0][u]) for _t, u in self._units
                                          if not isinstance(u, PendulumGroup)], dtype=np.intp)

    @property
    def dynamic_joints(self) -> list[int]:
        return [j for g in self.groups for j in g.joints]

    # --------------------------------------------------------------- dynamics
    def group_acceleration(self, g: PendulumGroup, theta: FloatArray, omega: FloatArray,
                           pivot_acc: FloatArray) -> FloatArray:
        """θ'' of a group's joints for world angles ``theta`` and rates ``omega`` (group order)."""
        p = self.params
        gvec = np.array([0.0, p.g])
        if not p.coupled or len(g.joints) == 1:
            return self._uncoupled(theta, pivot_acc[..., 0], pivot_acc[..., 1], g.mass, g.inertia, g.offset,
                                   (g.offset ** 2).sum(axis=1))
        # Coupled: w_ik = R(θ_i) v_ik (zero unless i is k or an ancestor of k).
        n = len(g.joints)
        w = rotate(g.arm, theta[:, None]) * g.ancestor[:, :, None]
        jw = perp(w)
        m = g.mass
        flat = w.reshape(n, 2 * n)
        M = (flat * np.repeat(m, 2)) @ flat.T + np.diag(g.inertia - m * (g.offset ** 2).sum(axis=1))
        force = gvec - pivot_acc
        Q = (jw @ force) @ m
        # Centripetal terms: ẍ_k contains −Σ_i w_ik ω_i², moved to the right-hand side.
        u = np.einsum("i,ikd->kd", omega ** 2, w)
        C = (jw * u[None, :, :]).sum(axis=2) @ m
        try:
            return np.asarray(np.linalg.solve(M, Q + C), dtype=np.float64)
        except np.linalg.LinAlgError:
            return np.asarray(np.linalg.lstsq(M, Q + C, rcond=None)[0], dtype=np.float64)

    def _group_fn(self, g: PendulumGroup, a: FloatArray) -> Callable[[FloatArray, FloatArray], FloatArray]:
        def f(t: FloatArray, w: FloatArray) -> FloatArray:
            return self.group_acceleration(g, t, w, a)
        return f

    def _singles_fn(self, acc: FloatArray,
                    sel: npt.NDArray[np.intp] | None = None) -> Callable[[FloatArray, FloatArray], FloatArray]:
        def f(t: FloatArray, w: FloatArray) -> FloatArray:
            return self._singles_acceleration(t, w, acc, sel)
        return f

    def _singles_acceleration(self, th: FloatArray, om: FloatArray, acc: FloatArray,
                              sel: npt.NDArray[np.intp] | None = None) -> FloatArray:
        """θ'' of all single (uncoupled) joints at once; ``acc`` is (k, 2). ``sel``: only
        the singles at these positions (``th``, ``om`` and ``acc`` are theirs)."""
        idx, mass, inertia, offset, ell2 = self._singles
        if sel is not None:
            mass, inertia, offset, ell2 = mass[sel], inertia[sel], offset[sel], ell2[sel]
        return self._uncoupled(th, acc[:, 0], acc[:, 1], mass, inertia, offset, ell2)

    def _uncoupled(self, th: FloatArray, ax: FloatArray, ay: FloatArray, mass: FloatArray, inertia: FloatArray,
                   offset: FloatArray, ell2: FloatArray) -> FloatArray:
        p = self.params
        inertia, live_inertia = _divisor(inertia)
        ell2, live_ell2 = _divisor(ell2)
        out = single_acceleration(np.cos(th), np.sin(th), offset[:, 0], offset[:, 1], ax, ay, mass, p.g,
                                  inertia, ell2, p.point_mass_forcing, live_inertia, live_ell2)
        return np.asarray(out, dtype=np.float64)

    def _advance_singles(self, th: FloatArray, om: FloatArray, acc: FloatArray,
                         tau: float, sel: npt.NDArray[np.intp] | None = None) -> tuple[FloatArray, FloatArray]:
        """One undamped step of the single pendulums with the chosen integrator."""
        f = self._singles_fn(acc, sel)
        method = self.params.integrator
        if method == "symplectic_euler":
            om = om + tau * f(th, om)
            th = th + tau * om
        elif method == "leapfrog":
            om = om + 0.5 * tau * f(th, om)
            th = th + tau * om
            om = om + 0.5 * tau * f(th, om)
        else:
            th, om = _rk4(f, th, om, tau)
        return th, om

    def group_mass_matrix(self, g: PendulumGroup, theta: FloatArray) -> FloatArray:
        """The mass matrix M(θ) of a coupled group (world angles as coordinates)."""
        n = len(g.joints)
        if not self.params.coupled or n == 1:
            return np.diag(np.asarray(g.inertia, dtype=np.float64))
        w = rotate(g.arm, theta[:, None]) * g.ancestor[:, :, None]
        flat = w.reshape(n, 2 * n)
        m = g.mass
        return np.asarray((flat * np.repeat(m, 2)) @ flat.T + np.diag(g.inertia - m * (g.offset ** 2).sum(axis=1)),
                          dtype=np.float64)

    def step(self, theta: FloatArray, omega: FloatArray, pivot_acc: Callable[[int], FloatArray] | FloatArray,
             tau: float | None = None, parent_motion: FloatArray | None = None) -> None:
        """Advance the world angles ``theta`` and rates ``omega`` (J,) in place by one step.

        ``pivot_acc`` gives the acceleration (units/s², already scaled) of each group's top
        pivot: an array (J, 2) indexed by joint, or a function of the top joint's index.
        Single joints use the chosen integrator; coupled chains are not separable
        Hamiltonian systems (symplectic Euler gains energy there), so they use RK4.

        ``parent_motion`` (J, 4) matters only with limits: for each joint, the keyed part of
        its parent's world angle (the local angles after the nearest dynamic ancestor) as
        angle and rate at the step's start, then at its end; None: 0 (a still parent).
        """
        tau = self.params.step if tau is None else tau
        if self._units:
            self._step_bounded(theta, omega, pivot_acc, tau, parent_motion)
            return
        decay = _decay(self.params.damping, tau)
        idx = self._singles[0]
        if len(idx):
            if callable(pivot_acc):
                acc = np.array([pivot_acc(int(j)) for j in idx], dtype=np.float64).reshape(-1, 2)
            else:
                acc = np.asarray(pivot_acc, dtype=np.float64)[idx]
            th, om = self._advance_singles(theta[idx], omega[idx], acc, tau)
            theta[idx] = th
            omega[idx] = om * decay
        for g in self._coupled:
            gi = np.asarray(g.joints)
            a = pivot_acc(g.top) if callable(pivot_acc) else np.asarray(pivot_acc)[g.top]
            a = np.asarray(a, dtype=np.float64)
            th, om = _rk4(self._group_fn(g, a), theta[gi], omega[gi], tau)
            theta[gi] = th
            omega[gi] = om * decay

    def _step_bounded(self, theta: FloatArray, omega: FloatArray,
                      pivot_acc: Callable[[int], FloatArray] | FloatArray, tau: float,
                      parent_motion: FloatArray | None) -> None:
        """:meth:`step` with limits: every unit steps freely, then each unit whose joints
        left their limits (parents first) steps again with exact bounces."""
        decay = _decay(self.params.damping, tau)
        start_t, start_w = theta.copy(), omega.copy()
        self.bounces = []
        idx = self._singles[0]
        acc = np.zeros((0, 2))
        if len(idx):
            if callable(pivot_acc):
                acc = np.array([pivot_acc(int(j)) for j in idx], dtype=np.float64).reshape(-1, 2)
            else:
                acc = np.asarray(pivot_acc, dtype=np.float64)[idx]
            theta[idx], omega[idx] = self._advance_singles(theta[idx], omega[idx], acc, tau)
        group_acc: dict[int, FloatArray] = {}
        for g in self._coupled:
            gi = np.asarray(g.joints)
            a = pivot_acc(g.top) if callable(pivot_acc) else np.asarray(pivot_acc)[g.top]
            group_acc[g.top] = a = np.asarray(a, dtype=np.float64)
            theta[gi], omega[gi] = _rk4(self._group_fn(g, a), theta[gi], omega[gi], tau)
        keyed = np.zeros((len(theta), 4)) if parent_motion is None else np.asarray(parent_motion, dtype=np.float64)
        # Which single pendulums left their limits, all at once; a unit is looked at again
        # below only when flagged or when the dynamic ancestor its parent hangs from bounced.
        flagged = np.zeros(len(theta), dtype=bool)
        if len(self._bounded_singles):
            m = self._bounded_singles
            dyn = self._parent_dynamic[m]
            has, d = dyn >= 0, np.maximum(dyn, 0)
            loc0 = start_t[m] - keyed[m, 0] - np.where(has, start_t[d], 0.0)
            loc1 = theta[m] - keyed[m, 2] - np.where(has, theta[d], 0.0)
            lo, hi = self.limits[m, 0], self.limits[m, 1]
            out = (loc0 < lo) | (loc0 > hi) | (loc1 < lo) | (loc1 > hi)
            # Resting contact, at once: on its limit at the start and pushed past it by the
            # free step, not moving faster than one step's change of speed (a bounce slower
            # than that is contact the step cannot resolve): stopped on the limit, moving
            # with its parent. Only where the parent's dynamic ancestor cannot bounce itself.
            bound = np.where(loc1 > hi, hi, lo)
            v0 = start_w[m] - keyed[m, 1] - np.where(has, start_w[d], 0.0)
            r1 = keyed[m, 3] + np.where(has, omega[d], 0.0)
            v1 = omega[m] - r1
            resting = (out & (np.abs(loc0 - bound) <= ON_LIMIT) & ((loc1 > hi) | (loc1 < lo))
                       & (np.abs(v0) <= np.abs(v1 - v0)) & ~(has & self.bounded[d]))
            if resting.any():
                r = m[resting]
                theta[r] = (theta[m] - loc1 + bound)[resting]
                omega[r] = r1[resting]
                out &= ~resting
            flagged[m] = out
        moved = np.zeros(len(theta), dtype=bool)
        for _top, unit_of in self._units:
            if not isinstance(unit_of, PendulumGroup):
                j = int(idx[unit_of])
                if not flagged[j] and not (self._parent_dynamic[j] >= 0 and moved[self._parent_dynamic[j]]):
                    continue
            if isinstance(unit_of, PendulumGroup):
                g = unit_of
                members = np.asarray(g.joints, dtype=np.intp)
                parent = np.asarray(g.parent, dtype=np.intp)
                step_fn = self._group_step(g, group_acc[g.top])
                mass_fn: Callable[[FloatArray], FloatArray] | None = self._group_mass(g)
            else:
                pos = unit_of
                members = np.array([idx[pos]], dtype=np.intp)
                parent = np.array([-1], dtype=np.intp)
                step_fn = self._single_step(acc[pos:pos + 1], np.array([pos], dtype=np.intp))
                mass_fn = None
            # The outside parents' world angles over the step: keyed part + dynamic part,
            # each exact at both ends (ancestors' units are final: they come first).
            dyn = self._parent_dynamic[members]
            has, d = dyn >= 0, np.maximum(dyn, 0)
            km = keyed[members]
            p0, p1 = km[:, 0] + np.where(has, start_t[d], 0.0), km[:, 2] + np.where(has, theta[d], 0.0)
            inside = parent >= 0
            pi = np.maximum(parent, 0)
            lo, hi = self.limits[members, 0], self.limits[members, 1]
            loc0 = start_t[members] - np.where(inside, start_t[members][pi], p0)
            loc1 = theta[members] - np.where(inside, theta[members][pi], p1)
            if ((loc0 >= lo) & (loc0 <= hi) & (loc1 >= lo) & (loc1 <= hi)).all():
                continue
            outside = hermite(p0, km[:, 1] + np.where(has, start_w[d], 0.0),
                              p1, km[:, 3] + np.where(has, omega[d], 0.0), tau)
            unit = BoundedUnit(members, lo, hi, parent, outside, mass_fn)
            theta[members], omega[members] = bounded_step(unit, step_fn, start_t[members], start_w[members], tau,
                                                          self.params.restitution, self.bounces)
            moved[members] = True
        dyn_all = np.asarray(self.dynamic_joints, dtype=np.intp)
        omega[dyn_all] = omega[dyn_all] * decay

    def _single_step(self, acc: FloatArray, sel: npt.NDArray[np.intp]
                     ) -> Callable[[FloatArray, FloatArray, float, float], tuple[FloatArray, FloatArray]]:
        def f(th: FloatArray, om: FloatArray, _t: float, h: float) -> tuple[FloatArray, FloatArray]:
            return self._advance_singles(th, om, acc, h, sel)
        return f

    def _group_step(self, g: PendulumGroup, a: FloatArray
                    ) -> Callable[[FloatArray, FloatArray, float, float], tuple[FloatArray, FloatArray]]:
        fn = self._group_fn(g, a)

        def f(th: FloatArray, om: FloatArray, _t: float, h: float) -> tuple[FloatArray, FloatArray]:
            return _rk4(fn, th, om, h)
        return f

    def _group_mass(self, g: PendulumGroup) -> Callable[[FloatArray], FloatArray]:
        def f(th: FloatArray) -> FloatArray:
            return self.group_mass_matrix(g, th)
        return f

    def run(self, theta: FloatArray, omega: FloatArray, pivot_acc: FloatArray, steps: int,
            tau: float | None = None) -> tuple[FloatArray, FloatArray]:
        """``steps`` steps with a constant pivot acceleration (J, 2), in place; returns the
        trajectory of world angles and rates, each (steps, J)."""
        tau = self.params.step if tau is None else tau
        if self._units:
            acc_b = np.asarray(pivot_acc, dtype=np.float64).reshape(len(theta), 2)
            out_t = np.empty((steps, len(theta)))
            out_w = np.empty((steps, len(theta)))
            for i in range(steps):
                self.step(theta, omega, acc_b, tau)
                out_t[i], out_w[i] = theta, omega
            return out_t, out_w
        acc_all = np.asarray(pivot_acc, dtype=np.float64).reshape(len(theta), 2)
        idx = self._singles[0]
        acc = acc_all[idx]
        decay = _decay(self.params.damping, tau)
        method = self.params.integrator
        traj_t = np.empty((steps, len(theta)))
        traj_w = np.empty((steps, len(theta)))
        if len(idx) == 1 and not self._coupled and method != "rk4":
            return self._run_scalar(theta, omega, acc[0], steps, tau, decay, traj_t, traj_w)
        th, om = theta[idx].copy(), omega[idx].copy()
        for i in range(steps):
            if len(idx):
                th, om = self._advance_singles(th, om, acc, tau)
                om = om * decay
                theta[idx], omega[idx] = th, om
            for g in self._coupled:
                gi = np.asarray(g.joints)
                a = acc_all[g.top]
                t2, w2 = _rk4(self._group_fn(g, a), theta[gi], omega[gi], tau)
                theta[gi], omega[gi] = t2, w2 * decay
            traj_t[i], traj_w[i] = theta, omega
        return traj_t, traj_w

    def _run_scalar(self, theta: FloatArray, omega: FloatArray, acc: FloatArray, steps: int, tau: float,
                    decay: float, traj_t: FloatArray, traj_w: FloatArray) -> tuple[FloatArray, FloatArray]:
        """One pendulum with plain floats (the same formulas as ``_singles_acceleration``)."""
        idx, mass, inertia, offset, ell2 = self._singles
        j = int(idx[0])
        m, inert, l2 = float(mass[0]), float(inertia[0]), float(ell2[0])
        ox, oy = float(offset[0, 0]), float(offset[0, 1])
        ax, ay = float(acc[0]), float(acc[1])
        g = self.params.g
        point = self.params.point_mass_forcing
        leap = self.params.integrator == "leapfrog"

        live_i, live_l = (1.0 if inert > 0 else 0.0), (1.0 if l2 > 0 else 0.0)
        inert, l2 = (inert if inert > 0 else 1.0), (l2 if l2 > 0 else 1.0)

        def f(t: float) -> float:
            return float(single_acceleration(math.cos(t), math.sin(t), ox, oy, ax, ay, m, g, inert, l2, point,
                                             live_i, live_l))

        th, om = float(theta[j]), float(omega[j])
        traj_t[:] = theta
        traj_w[:] = omega
        col_t, col_w = traj_t[:, j], traj_w[:, j]
        for i in range(steps):
            if leap:
                om += 0.5 * tau * f(th)
                th += tau * om
                om += 0.5 * tau * f(th)
            else:
                om += tau * f(th)
                th += tau * om
            om *= decay
            col_t[i], col_w[i] = th, om
        theta[j], omega[j] = th, om
        return traj_t, traj_w

    # ----------------------------------------------------------------- energy
    def energy(self, theta: FloatArray, omega: FloatArray) -> float:
        """Kinetic + potential energy of all groups (fixed pivots; coupled model)."""
        total = 0.0
        for g in self.groups:
            idx = np.asarray(g.joints)
            th, om = theta[idx], omega[idx]
            w = rotate(g.arm, th[:, None]) * g.ancestor[:, :, None]
            m = g.mass
            if self.params.coupled:
                inertia_c = g.inertia - m * (g.offset ** 2).sum(axis=1)
                M = np.einsum("k,ikd,jkd->ij", m, w, w) + np.diag(inertia_c)
            else:
                M = np.diag(g.inertia)
            # Centre-of-mass height relative to the top pivot: Σ_i w_ik (i on k's path).
            com = w.sum(axis=0)  # (n, 2): for each k, Σ_i w_ik
            potential = -float((m * com[:, 1]).sum()) * self.params.g
            total += 0.5 * float(om @ M @ om) + potential
        return total

    def equilibrium(self) -> FloatArray:
        """World angles (J,) with every centre of mass straight below its pivot (θ = −φ)."""
        out = np.zeros(len(self.character.joints))
        for g in self.groups:
            for k, j in enumerate(g.joints):
                y = g.offset[k]
                out[j] = -math.atan2(y[0], y[1]) if (y[0] or y[1]) else 0.0
        return out


def _rk4(f: Callable[[FloatArray, FloatArray], FloatArray], th: FloatArray, om: FloatArray,
         tau: float) -> tuple[FloatArray, FloatArray]:
    k1t, k1w = om, f(th, om)
    k2t, k2w = om + 0.5 * tau * k1w, f(th + 0.5 * tau * k1t, om + 0.5 * tau * k1w)
    k3t, k3w = om + 0.5 * tau * k2w, f(th + 0.5 * tau * k2t, om + 0.5 * tau * k2w)
    k4t, k4w = om + tau * k3w, f(th + tau * k3t, om + tau * k3w)
    return (th + tau / 6.0 * (k1t + 2 * k2t + 2 * k3t + k4t),
            om + tau / 6.0 * (k1w + 2 * k2w + 2 * k3w + k4w))


__all__ = [
    "INTEGRATORS", "MIN_STEP", "PRESETS", "RUNAWAY_RATE", "FloatArray", "PendulumBlowUp", "PendulumGroup",
    "PendulumParams", "PendulumSystem", "check_state", "perp", "pivot_accelerations", "rotate",
    "rotation_pivot_terms", "single_acceleration",
]
