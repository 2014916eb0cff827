"""Spring joints: secondary motion that follows the animation.

A spring joint's channel holds its keyed **local** angle u(t), as a keyframed joint's does;
the joint itself follows u through a damped rotational spring:

    θ'' = k·(u(t) − θ) − c·θ' − β·(Θ_p'' + (m/I)·⟨a, y⊥⟩)

θ is the simulated local angle (relative to the parent), k the stiffness (1/s²), c the
damping (1/s), β the inertia (0 … 1), Θ_p'' the parent's world angular acceleration, a the
acceleration of the joint's pivot (the body's movement and its ancestors' turning), m, I the
joint's mass and moment about its pivot and y⊥ = J·R(φ)·y0 (φ its world angle, y0 the
rest pivot → centre of mass vector), as for pendulums. With β = 1 the part is a rigid body
on a rotational spring: it keeps its heading while the parent turns and the body speeds up,
then springs back; with β = 0 it rides on its parent and only lags its own keys. There is
no gravity, so a spring at rest on constant keys stays on them exactly. The angle shown is
(1 − mix)·u + mix·θ: mix 0 is the keys, 1 the spring. Spine's physics constraints have the
same knobs (strength, damping, inertia, mix).

Integration is exact for the linear part: over a sub-step [0, τ] the key is replaced by its
tangent line at the sub-step's midpoint, u ≈ u0 + u1·s, and the coupling term by its value
there. In d = θ − (u0 + u1·s) the equation is d'' + c·d' + k·d = F with F = −c·u1 − β·(…)
constant, whose exact solution is the matrix exponential of [[0, 1, 0], [−k, −c, 1],
[0, 0, 0]]. Keys that are linear or stepped between frames are followed exactly (to
rounding), smooth keys to second order, and any stiffness is stable (k, c ≥ 0).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass, fields, replace
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.core.joint_bounce import Bounce, BoundedUnit, bounded_step
from qtanimator.core.rig2d import Character, angle_sums

FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class SpringParams:
    """Spring joints' constants, one set per character.

    ``stiffness`` k (1/s²; the undamped frequency is √k / 2π Hz), ``damping`` c (1/s;
    critical at 2√k), ``mix`` (0: the keys, 1: the spring), ``inertia`` β (0 … 1: how much
    the parent's turning and the body's movement drag the joint).
    """

    stiffness: float = 120.0
    damping: float = 8.0
    mix: float = 1.0
    inertia: float = 0.5

    def __post_init__(self) -> None:
        for name in ("stiffness", "damping", "mix", "inertia"):
            if not math.isfinite(float(getattr(self, name))):
                raise ValueError(f"{name} must be finite")
        if self.stiffness < 0:
            raise ValueError("the stiffness must be 0 or more")
        if self.damping < 0:
            raise ValueError("the damping must be 0 or more (a negative damping adds energy every step)")
        if not 0.0 <= self.mix <= 1.0:
            raise ValueError("mix must be between 0 (the keys) and 1 (the spring)")
        if not 0.0 <= self.inertia <= 1.0:
            raise ValueError("inertia must be between 0 (rides on its parent) and 1 (keeps its heading)")

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> SpringParams:
        names = {f.name for f in fields(cls)}
        return replace(cls(), **{k: v for k, v in d.items() if k in names})


#: Named presets: ``soft`` (the default; about 1.7 Hz, damping ratio 0.37: overshoots by
#: about 30% and wobbles twice) and ``stiff`` (about 5 Hz, ratio 0.63: settles within a swing).
#: Both take half the parent's motion (inertia 0.5): in a chain every spring is driven by the
#: one above it, and a chain of soft springs at full inertia whips (each link can double the
#: swing of the one above near its resonance).
SPRING_PRESETS: dict[str, SpringParams] = {
    "soft": SpringParams(),
    "stiff": SpringParams(stiffness=1000.0, damping=40.0),
}


def expm(a: FloatArray) -> FloatArray:
    """e^A of a small square matrix (scaling and squaring with a Taylor series)."""
    a = np.asarray(a, dtype=np.float64)
    norm = float(np.abs(a).sum(axis=1).max()) if a.size else 0.0
    squarings = max(0, int(math.ceil(math.log2(norm))) + 1) if norm > 0.5 else 0
    scaled = a / (2.0 ** squarings)
    out = np.eye(len(a))
    term = np.eye(len(a))
    for k in range(1, 20):
        term = term @ scaled / k
        out = out + term
    for _ in range(squarings):
        out = out @ out
    return out


def propagator(stiffness: float, damping: float, h: float) -> FloatArray:
    """The 3×3 matrix that takes (d, d', F) over a time h (see the module)."""
    m = np.array([[0.0, 1.0, 0.0], [-stiffness, -damping, 1.0], [0.0, 0.0, 0.0]])
    return expm(m * h)


def spring_step(e: FloatArray, damping: float, theta: FloatArray | float, omega: FloatArray | float,
                u0: FloatArray | float, u1: FloatArray | float, force: FloatArray | float,
                h: float) -> tuple[FloatArray, FloatArray]:
    """(θ, θ') after a time h from (θ, θ') with the key u0 + u1·s and the extra angular
    acceleration ``force``; ``e`` is ``propagator(k, c, h)``."""
    d = np.asarray(theta, dtype=np.float64) - u0
    dd = np.asarray(omega, dtype=np.float64) - u1
    f = -damping * np.asarray(u1, dtype=np.float64) + force
    d1 = e[0, 0] * d + e[0, 1] * dd + e[0, 2] * f
    dd1 = e[1, 0] * d + e[1, 1] * dd + e[1, 2] * f
    return np.asarray(u0 + u1 * h + d1, dtype=np.float64), np.asarray(u1 + dd1, dtype=np.float64)


class SpringSystem:
    """The spring joints of one character and their integration, one sub-step at a time.

    World kinematics follow the pendulum cache's plan: a joint's world angle is the world
    angle of its nearest dynamic ancestor-or-self plus the local angles of the non-dynamic
    joints after it (``key_sum`` and ``dyn_pick``, (J, J)). Dynamic ancestors enter with
    their angle and rate at the sub-step's start; their angular acceleration is not known
    to the springs (the springs step first) and counts as 0.
    """

    def __init__(self, character: Character, params: SpringParams | None = None,
                 limits: Sequence[tuple[float, float] | None] | None = None, restitution: float = 0.5) -> None:
        self.character = character
        self.params = params or SpringParams()
        self.restitution = float(restitution)
        ch = character
        n = len(ch.joints)
        self.joints = np.flatnonzero(np.array([j.is_spring and not j.is_dynamic for j in ch.joints], dtype=bool))
        self.key_sum, self.dyn_pick = angle_sums(ch)
        self.limits = np.tile(np.array([-math.inf, math.inf]), (n, 1))
        for k, lim in enumerate(limits or []):
            if lim is not None and k < n:
                self.limits[k] = (float(lim[0]), float(lim[1]))
        # Per spring joint: its ancestors (parent first), the pivot vectors to them, mass data.
        self._plan = []
        for q in self.joints:
            j = ch.joints[int(q)]
            anc, vec = [], []
            child, m = int(q), j.parent
            while m is not None:
                anc.append(m)
                vec.append(ch.joints[child].pivot - ch.joints[m].pivot)
                child, m = m, ch.joints[m].parent
            mp = j.mass_properties
            ratio = mp.mass / mp.inertia if mp is not None and mp.inertia > 0 else 0.0
            offset = np.zeros(2) if mp is None else np.asarray(mp.centroid - mp.pivot, dtype=np.float64)
            self._plan.append((int(q), np.array(anc, dtype=np.intp), np.array(vec, dtype=np.float64).reshape(-1, 2),
                               ratio, offset))
        self._e_cache: dict[float, FloatArray] = {}
        #: The bounces of the last :meth:`step`.
        self.bounces: list[Bounce] = []

    def _e(self, h: float) -> FloatArray:
        e = self._e_cache.get(h)
        if e is None:
            if len(self._e_cache) > 64:
                self._e_cache.clear()
            e = self._e_cache[h] = propagator(self.params.stiffness, self.params.damping, h)
        return e

    def step(self, theta: FloatArray, omega: FloatArray, tau: float, key: FloatArray, key_rate: FloatArray,
             key_acc: FloatArray, dyn_world: FloatArray, dyn_rate: FloatArray, translation_acc: FloatArray) -> None:
        """Advance the spring joints' local angles and rates (entries of ``theta``,
        ``omega``, (J,)) in place over one sub-step of length ``tau``.

        ``key``, ``key_rate``, ``key_acc`` (J,): every non-dynamic joint's keyed local angle
        and its derivatives at the sub-step's midpoint (changed in place: spring joints get
        their shown values, so children see them). ``dyn_world``, ``dyn_rate`` (J,): the
        dynamic joints' world angles and rates at the start. ``translation_acc`` (2,): the
        character's acceleration at the midpoint.
        """
        p = self.params
        mix, beta = p.mix, p.inertia
        e = self._e(tau)
        self.bounces = []
        dyn_angle = self.dyn_pick @ dyn_world
        dyn_w = self.dyn_pick @ dyn_rate
        for q, anc, vec, ratio, offset in self._plan:
            u_m, u1 = float(key[q]), float(key_rate[q])
            force = 0.0
            if beta and len(anc):
                ks = self.key_sum[anc]
                world = ks @ key + dyn_angle[anc]
                rate = ks @ key_rate + dyn_w[anc]
                accel = ks @ key_acc
                parent_acc = float(accel[0])
                acc = np.asarray(translation_acc, dtype=np.float64).copy()
                if len(anc):
                    c, s = np.cos(world), np.sin(world)
                    rv = np.stack([c * vec[:, 0] + s * vec[:, 1], -s * vec[:, 0] + c * vec[:, 1]], axis=1)
                    jrv = np.stack([rv[:, 1], -rv[:, 0]], axis=1)
                    acc += (accel[:, None] * jrv - (rate ** 2)[:, None] * rv).sum(axis=0)
                phi = float(world[0]) + float(theta[q])
                c1, s1 = math.cos(phi), math.sin(phi)
                yx, yy = c1 * offset[0] + s1 * offset[1], -s1 * offset[0] + c1 * offset[1]
                force = -beta * (parent_acc + ratio * (yy * acc[0] - yx * acc[1]))
            elif beta:
                acc = np.asarray(translation_acc, dtype=np.float64)
                c1, s1 = math.cos(float(theta[q])), math.sin(float(theta[q]))
                yx, yy = c1 * offset[0] + s1 * offset[1], -s1 * offset[0] + c1 * offset[1]
                force = -beta * ratio * (yy * acc[0] - yx * acc[1])
            u0 = u_m - u1 * 0.5 * tau
            th0, om0 = float(theta[q]), float(omega[q])
            lo, hi = self.limits[q]
            th1, om1 = spring_step(e, p.damping, th0, om0, u0, u1, force, tau)
            if math.isfinite(lo) or math.isfinite(hi):
                th1, om1 = self._bounded(q, th0, om0, th1, om1, u0, u1, force, tau)
            theta[q], omega[q] = float(th1), float(om1)
            # What children and pendulums see: the shown (mixed) angle, mid-sub-step.
            key[q] = (1.0 - mix) * u_m + mix * 0.5 * (th0 + float(th1))
            key_rate[q] = (1.0 - mix) * u1 + mix * 0.5 * (om0 + float(om1))
            key_acc[q] = (1.0 - mix) * float(key_acc[q]) + mix * (float(om1) - om0) / tau

    def _bounded(self, q: int, th0: float, om0: float, th1: FloatArray, om1: FloatArray, u0: float, u1: float,
                 force: float, tau: float) -> tuple[FloatArray, FloatArray]:
        lo, hi = self.limits[q]
        if lo <= float(th1) <= hi and lo <= th0 <= hi:
            return th1, om1
        damping = self.params.damping

        def step(th: FloatArray, om: FloatArray, t: float, h: float) -> tuple[FloatArray, FloatArray]:
            return spring_step(self._e(h) if h == tau else propagator(self.params.stiffness, damping, h),
                               damping, th, om, u0 + u1 * t, u1, force, h)

        def outside(_t: float) -> tuple[FloatArray, FloatArray]:
            return np.zeros(1), np.zeros(1)  # θ is already local

        unit = BoundedUnit(np.array([q], dtype=np.intp), np.array([lo]), np.array([hi]), np.array([-1], dtype=np.intp),
                           outside)
        th, om = bounded_step(unit, step, np.array([th0]), np.array([om0]), tau, self.restitution, self.bounces)
        return np.asarray(th[0]), np.asarray(om[0])
