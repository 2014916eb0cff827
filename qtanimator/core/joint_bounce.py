"""Joint limits that bounce: exact event handling inside one integration step.

A simulated joint's local angle (relative to its parent) must stay in ``[lo, hi]``. When a
step would take it out, the step is cut at the crossing: the time h* within the step where
the integrator's own trajectory (one step of length h from the step's start, as a function
of h) reaches the limit is found by root finding (bracketing, then Illinois regula falsi to
about 1e-15 of the step). There the joint is put exactly on the limit, its angular velocity
relative to the parent is reversed and multiplied by the restitution e (0 … 1), and the rest
of the step is integrated from that state, which may bounce again.

So at every bounce the relative speed after is e times the speed at impact, exactly: a
single pendulum on a still parent keeps e² of its kinetic energy. Members of a coupled chain
get the impulse through the chain's mass matrix M: Δω = M⁻¹·Jᵀ·λ with J the joint's
relative-velocity row (+1 on the joint, −1 on a parent inside the chain), λ chosen so that
J·ω after = −e·(J·ω before), which is the impulse the limit stop exerts on both bodies.

A joint that is pushed into its limit without moving into it (resting contact), or that
bounces more than :data:`MAX_EVENTS` times in one step (the ever faster bounces of e < 1
settling), ends the step stopped on the limit, moving with its parent (e = 0 for that
contact). A crossing that leaves and comes back within one step is not seen.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]

#: (theta, omega, t, h) -> the state at t + h from the state at t (0 ≤ t, t + h ≤ the step).
StepFunction = Callable[[FloatArray, FloatArray, float, float], tuple[FloatArray, FloatArray]]

#: Bounces handled exactly within one step; more make the joint stop on its limit.
MAX_EVENTS = 8
#: Radians: a joint this close to its limit counts as on it.
ON_LIMIT = 1e-12


@dataclass(frozen=True)
class Bounce:
    """One bounce: ``joint`` (character index) hit ``limit`` at ``time`` seconds into the
    step with relative angular velocity ``rate_before`` and left with ``rate_after``
    (= −e·rate_before)."""

    joint: int
    time: float
    limit: float
    rate_before: float
    rate_after: float


@dataclass(eq=False)
class BoundedUnit:
    """Joints integrated together (one pendulum, or a coupled chain) and their limits.

    ``parent`` is each member's parent's position in the unit, or −1 when the parent is
    outside it; ``outside(t)`` gives, for every member, the world angle and rate of its
    outside parent at time t within the step (entries of members with an inside parent are
    ignored). ``mass_matrix(theta)`` is the unit's mass matrix for impulses; None: the
    members are independent (each bounce changes only the joint's own rate).
    """

    joints: npt.NDArray[np.intp]
    lo: FloatArray
    hi: FloatArray
    parent: npt.NDArray[np.intp]
    outside: Callable[[float], tuple[FloatArray, FloatArray]]
    mass_matrix: Callable[[FloatArray], FloatArray] | None = None

    def local(self, theta: FloatArray, t: float) -> FloatArray:
        angle, _rate = self.outside(t)
        inside = self.parent >= 0
        par = np.where(inside, theta[np.maximum(self.parent, 0)], angle)
        return np.asarray(theta - par, dtype=np.float64)

    def parent_state(self, theta: FloatArray, omega: FloatArray, i: int, t: float) -> tuple[float, float]:
        p = int(self.parent[i])
        if p >= 0:
            return float(theta[p]), float(omega[p])
        angle, rate = self.outside(t)
        return float(angle[i]), float(rate[i])


def hermite(a0: FloatArray, r0: FloatArray, a1: FloatArray, r1: FloatArray,
            tau: float) -> Callable[[float], tuple[FloatArray, FloatArray]]:
    """Angle and rate at t of the cubic that has angle a0, rate r0 at 0 and a1, r1 at tau
    (a parent's motion over one step, exact at both ends)."""
    a0, r0 = np.asarray(a0, dtype=np.float64), np.asarray(r0, dtype=np.float64)
    if tau <= 0:
        return lambda _t: (a0, r0)
    da = np.asarray(a1, dtype=np.float64) - a0
    c2 = (3.0 * da / tau - 2.0 * r0 - np.asarray(r1, dtype=np.float64)) / tau
    c3 = (np.asarray(r1, dtype=np.float64) + r0 - 2.0 * da / tau) / (tau * tau)

    def f(t: float) -> tuple[FloatArray, FloatArray]:
        if t >= tau:  # exactly the end values
            return np.asarray(a1, dtype=np.float64), np.asarray(r1, dtype=np.float64)
        return a0 + t * (r0 + t * (c2 + t * c3)), r0 + t * (2.0 * c2 + 3.0 * t * c3)

    return f


def _set_relative_rate(unit: BoundedUnit, theta: FloatArray, omega: FloatArray, i: int, v: float,
                       v_new: float) -> None:
    """Change member i's rate relative to its parent from v to v_new, in place, with the
    impulse of the limit stop (through the mass matrix when the members are coupled)."""
    dv = v_new - v
    n = len(theta)
    if unit.mass_matrix is None or n == 1:
        omega[i] += dv
        return
    row = np.zeros(n)
    row[i] = 1.0
    if unit.parent[i] >= 0:
        row[unit.parent[i]] = -1.0
    mass = unit.mass_matrix(theta)
    try:
        x = np.linalg.solve(mass, row)
    except np.linalg.LinAlgError:
        x = np.linalg.lstsq(mass, row, rcond=None)[0]
    denom = float(row @ x)
    if not (denom > 0 and math.isfinite(denom)):
        omega[i] += dv
        return
    omega += x * (dv / denom)


def _root(g: Callable[[float], float], a: float, ga: float, b: float, gb: float, tol: float) -> float:
    """The crossing of g in [a, b], ga ≤ 0 < gb (Illinois regula falsi), to ``tol``."""
    fa, fb = ga, gb  # the Illinois-scaled end values
    side = 0
    for _ in range(200):
        if b - a <= tol:
            break
        c = b - fb * (b - a) / (fb - fa) if fb != fa else 0.5 * (a + b)
        if not a < c < b:
            c = 0.5 * (a + b)
        gc = g(c)
        if gc > 0:
            b, fb = c, gc
            if side == 1:
                fa *= 0.5
            side = 1
        else:
            if gc == 0:
                return c
            a, fa = c, gc
            if side == -1:
                fb *= 0.5
            side = -1
    return b


def _crossing(g: Callable[[float], float], rem: float, leaving: bool) -> float:
    """The first h in [0, rem] where g (≤ 0 inside, > 0 outside; g(rem) > 0) turns positive.
    ``leaving`` False: the joint starts on its limit moving back inside, so the crossing
    sought is the next one, after h = 0."""
    tol = 4.0 * np.finfo(float).eps * max(rem, 1e-300)
    g0 = g(0.0)
    if leaving and g0 > -ON_LIMIT:
        return 0.0
    width = rem
    for _depth in range(5):
        samples = [width * (k / 8.0) for k in range(1, 9)]
        found = None
        prev_h, prev_g = 0.0, g0
        for h in samples:
            gh = g(min(h, rem))
            if gh > 0:
                found = (prev_h, prev_g, min(h, rem), gh)
                break
            prev_h, prev_g = h, gh
        if found is None:
            return rem  # the crossing sits at the very end of the step
        a, ga, b, gb = found
        if a > 0 or ga < -ON_LIMIT:
            return _root(g, a, ga, b, gb, tol)
        width = b  # outside already in the first sample: look closer to h = 0
    return 0.0


def bounded_step(unit: BoundedUnit, step: StepFunction, theta: FloatArray, omega: FloatArray, tau: float,
                 restitution: float, bounces: list[Bounce] | None = None) -> tuple[FloatArray, FloatArray]:
    """One step of length ``tau`` of the unit's state (members' angles and rates) that
    keeps every member's local angle in its limits, bouncing with ``restitution``.
    Appends the bounces to ``bounces``. ``theta`` and ``omega`` are not changed."""
    th, om = np.array(theta, dtype=np.float64), np.array(omega, dtype=np.float64)
    t = 0.0
    for _event in range(MAX_EVENTS):
        rem = tau - t
        if rem <= 0:
            break
        th_e, om_e = step(th, om, t, rem)
        loc_end = unit.local(th_e, tau)
        out = (loc_end > unit.hi) | (loc_end < unit.lo)
        loc_now = unit.local(th, t)
        started_out = (loc_now > unit.hi + ON_LIMIT) | (loc_now < unit.lo - ON_LIMIT)
        if not out.any() and not started_out.any():
            return th_e, om_e
        best: tuple[float, int, float, float] | None = None
        for raw in np.flatnonzero(out | started_out):
            i = int(raw)
            if started_out[i]:
                sgn = 1.0 if loc_now[i] > unit.hi[i] else -1.0
            else:
                sgn = 1.0 if loc_end[i] > unit.hi[i] else -1.0
            bound = float(unit.hi[i] if sgn > 0 else unit.lo[i])
            _pa, pr = unit.parent_state(th, om, i, t)
            leaving = sgn * (float(om[i]) - pr) >= 0 or abs(float(loc_now[i]) - bound) > ON_LIMIT

            def g(h: float, i: int = i, sgn: float = sgn, bound: float = bound, th: FloatArray = th,
                  om: FloatArray = om, t: float = t) -> float:
                state = th if h <= 0 else step(th, om, t, h)[0]
                return sgn * (float(unit.local(state, t + h)[i]) - bound)

            h = 0.0 if started_out[i] else _crossing(g, rem, leaving)
            if best is None or h < best[0]:
                best = (h, i, sgn, bound)
        assert best is not None
        h, i, sgn, bound = best
        if h > 0:
            th, om = step(th, om, t, h)
            th, om = np.array(th, dtype=np.float64), np.array(om, dtype=np.float64)
        t += h
        pa, pr = unit.parent_state(th, om, i, t)
        th[i] = pa + bound
        v = float(om[i]) - pr
        if sgn * v <= 0:
            break  # pushed into the limit without moving into it: resting contact
        v_new = -restitution * v
        _set_relative_rate(unit, th, om, i, v, v_new)
        if bounces is not None:
            bounces.append(Bounce(int(unit.joints[i]), t, bound, v, v_new))
    # Resting contact, or bounces settling: finish the step, then stop every member that
    # ends outside on its limit, moving with its parent (parents first: members are in pre-order).
    if t < tau:
        th, om = step(th, om, t, tau - t)
        th, om = np.array(th, dtype=np.float64), np.array(om, dtype=np.float64)
    for i in range(len(th)):
        loc = float(unit.local(th, tau)[i])
        if unit.lo[i] <= loc <= unit.hi[i]:
            continue
        sgn = 1.0 if loc > unit.hi[i] else -1.0
        bound = float(unit.hi[i] if sgn > 0 else unit.lo[i])
        pa, pr = unit.parent_state(th, om, i, tau)
        th[i] = pa + bound
        v = float(om[i]) - pr
        if sgn * v > 0:
            _set_relative_rate(unit, th, om, i, v, 0.0)
    return th, om
