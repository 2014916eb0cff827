"""Inverse kinematics for 2D characters.

Two solvers:

* the handout's: the descent direction D_j = ⟨q − p, J(p − p_j)⟩ (J = R(π/2),
  J(x, y) = (y, −x)) for the dragged joint and its ancestors, the root frozen, and plain
  gradient descent ``angle += τ·D`` (:func:`handout_gradient`, :func:`gradient_descent_step`).
  D_j = −∂f/∂θ_j for f = ½|p − q|². It drives the editor's gradient arrows.
* the interactive one (:func:`solve_ik`): damped least squares on the chain from the root
  to the dragged joint, Levenberg-Marquardt style adaptive damping (every accepted step lowers
  the error), joint limits by clamping and freezing, the root frozen by default.

CCD, FABRIK and the analytic two-bone solver are in :mod:`qtanimator.core.ik_methods`; every
2D solver takes joint limits in either form :func:`limit_bounds` reads.

Dynamic (pendulum) joints keep their **world** angle while their ancestors turn (that is
what the simulation does), so a dynamic joint on the chain passes its ancestors' motion on
as a translation only; the Jacobian takes that into account, and dynamic joints are never
moved by the solver. Geometry mirrored in the SVG needs no special case: the rig's
transforms are rotations about pivots, the mirroring is baked into the shapes.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TypeAlias

import numpy as np
import numpy.typing as npt

from qtanimator.core.rig2d import Character, Pose

FloatArray = npt.NDArray[np.float64]

HANDOUT_STEP = 1e-6

#: Joint limits as the 2D solvers take them: a (J, 2) array of [min, max] local angles
#: (±inf for none), or one ``(lo, hi)`` or None (free) per joint.
Limits: TypeAlias = "npt.ArrayLike | Sequence[tuple[float, float] | None] | None"


@dataclass
class IKStats:
    """What a solve did, filled in when a solver is given one (benchmarks, tests)."""

    iterations: int = 0
    error: float = math.nan
    method: str = ""


def limit_bounds(limits: Limits, count: int) -> tuple[FloatArray, FloatArray] | None:
    """``(lo, hi)`` arrays (``count``,) of local-angle limits, ±inf where a joint is free;
    None when no joint is limited. Accepts a (J, 2) array or a list of ``(lo, hi) | None``
    (``character2d.joint_limits``)."""
    if limits is None:
        return None
    if isinstance(limits, (list, tuple)) and any(v is None for v in limits):
        arr = np.array([(-math.inf, math.inf) if v is None else v for v in limits], dtype=np.float64)
    else:
        arr = np.asarray(limits, dtype=np.float64)
    arr = arr.reshape(count, 2)
    lo = np.where(np.isnan(arr[:, 0]), -math.inf, arr[:, 0])
    hi = np.where(np.isnan(arr[:, 1]), math.inf, arr[:, 1])
    if not (np.isfinite(lo).any() or np.isfinite(hi).any()):
        return None
    return lo, hi


def _pose(character: Character, pose_or_angles: Pose | npt.ArrayLike,
          translation: npt.ArrayLike = (0.0, 0.0)) -> Pose:
    if isinstance(pose_or_angles, Pose):
        return pose_or_angles
    return character.pose(np.asarray(pose_or_angles, dtype=np.float64), translation)


def handout_gradient(character: Character, pose_or_angles: Pose | npt.ArrayLike, joint: int,
                     local_point: npt.ArrayLike, target: npt.ArrayLike,
                     translation: npt.ArrayLike = (0.0, 0.0)) -> FloatArray:
    """The handout's D (J,): ⟨q − p, J(p − p_j)⟩ for ``joint`` and its ancestors, else 0;
    the root's D is 0. ``local_point`` is in the joint's rest-pose coordinates."""
    pose = _pose(character, pose_or_angles, translation)
    p = pose.to_world(joint, local_point)
    q = np.asarray(target, dtype=np.float64)
    d = np.zeros(len(character.joints))
    e = q - p
    for j in character.ancestors(joint):
        if j == 0:
            continue
        r = p - pose.pivots[j]
        d[j] = e[0] * r[1] - e[1] * r[0]  # <e, (r.y, -r.x)>
    return d


def gradient_descent_step(character: Character, angles: npt.ArrayLike, translation: npt.ArrayLike,
                          joint: int, local_point: npt.ArrayLike, target: npt.ArrayLike,
                          step: float = HANDOUT_STEP, iterations: int = 10, limits: Limits = None,
                          stats: IKStats | None = None) -> FloatArray:
    """The handout's per-frame IK update: ``iterations`` steps of angle += step·D; with
    ``limits`` each step is projected onto them (projected gradient descent), for the joints
    the step moves."""
    a = np.array(angles, dtype=np.float64)
    bounds = limit_bounds(limits, len(a))
    for _ in range(iterations):
        d = handout_gradient(character, a, joint, local_point, target, translation)
        a += step * d
        if bounds is not None:
            moved = d != 0
            a[moved] = np.clip(a[moved], bounds[0][moved], bounds[1][moved])
    if stats is not None:
        stats.iterations = iterations
        stats.error = ik_error(character, a, translation, joint, local_point, target)
        stats.method = "handout"
    return a


def end_effector(character: Character, angles: npt.ArrayLike, translation: npt.ArrayLike,
                 joint: int, local_point: npt.ArrayLike) -> FloatArray:
    return character.pose(angles, translation).to_world(joint, local_point)


class _ChainPlan:
    """The static part of a root → joint chain (built once per character, joint and mode)."""

    def __init__(self, character: Character, joint: int, freeze_root: bool) -> None:
        idx = np.array(character.ancestors(joint)[::-1], dtype=np.intp)
        self.idx = idx
        c = character.rest_pivots[idx]
        self.c_last = c[-1].copy()
        self.dc = c[1:] - c[:-1]
        dyn = character.dynamic[idx]
        n = len(idx)
        pos = np.arange(n)
        self.last_dyn = np.maximum.accumulate(np.where(dyn, pos, -1))
        self.has_dyn = bool(dyn.any())
        nd = np.where(dyn, pos, n)
        next_dyn = np.minimum.accumulate(nd[::-1])[::-1]
        self.next_dyn = np.append(next_dyn[1:], n)
        self.anchor_is_tip = self.next_dyn >= n
        self.anchor_index = np.minimum(self.next_dyn, n - 1)
        var = ~dyn
        if freeze_root:
            var[0] = False
        self.var = var
        self.n = n
        # Dynamic joints whose parent's world angle follows a chain joint: (joint, chain position).
        on_chain = {int(j): k for k, j in enumerate(idx)}
        follow_j, follow_k = [], []
        for d, jd in enumerate(character.joints):
            if not jd.is_dynamic or jd.parent is None:
                continue
            m: int | None = jd.parent
            while m is not None and m not in on_chain:
                if character.joints[m].is_dynamic:
                    break
                m = character.joints[m].parent
            if m is not None and m in on_chain and not character.joints[m].is_dynamic:
                follow_j.append(d)
                follow_k.append(on_chain[m])
        self.follow_joint = np.array(follow_j, dtype=np.intp)
        self.follow_pos = np.array(follow_k, dtype=np.intp)


def _plan(character: Character, joint: int, freeze_root: bool) -> _ChainPlan:
    plans: dict[tuple[int, bool], _ChainPlan] = character.derived.setdefault("ik.plans", {})
    key = (int(joint), bool(freeze_root))
    plan = plans.get(key)
    if plan is None:
        plan = plans[key] = _ChainPlan(character, joint, freeze_root)
    return plan


class _Chain:
    """The root → joint chain, evaluated with vectorised numpy (no 3×3 matrices)."""

    def __init__(self, character: Character, angles: FloatArray, translation: npt.ArrayLike, joint: int,
                 local_point: npt.ArrayLike, freeze_root: bool = True) -> None:
        plan = _plan(character, joint, freeze_root)
        self.plan = plan
        self.idx = plan.idx
        self.theta0 = np.cumsum(angles[plan.idx])
        self.base = character.rest_pivots[plan.idx[0]] + np.asarray(translation, dtype=np.float64).reshape(2)
        self.dc = plan.dc
        self.tip = np.asarray(local_point, dtype=np.float64) - plan.c_last
        self.last_dyn = plan.last_dyn
        self.next_dyn = plan.next_dyn
        self.var = plan.var
        self.n = plan.n

    def world_change(self, delta: FloatArray) -> FloatArray:
        """Change of each chain joint's world angle for local changes ``delta``."""
        cum = np.cumsum(delta)
        if not self.plan.has_dyn:
            return cum
        held = np.where(self.last_dyn >= 0, cum[np.maximum(self.last_dyn, 0)], 0.0)
        return np.asarray(cum - held, dtype=np.float64)

    def evaluate(self, delta: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """World angles (n,), pivots (n, 2) and end point (2,) after local changes ``delta``."""
        theta = self.theta0 + self.world_change(delta)
        pivots = np.empty((self.n, 2))
        pivots[0] = self.base
        if self.n > 1:
            th = theta[:-1]
            cs, sn = np.cos(th), np.sin(th)
            dx, dy = self.dc[:, 0], self.dc[:, 1]
            pivots[1:, 0] = self.base[0] + np.cumsum(cs * dx + sn * dy)
            pivots[1:, 1] = self.base[1] + np.cumsum(cs * dy - sn * dx)
        t = theta[-1]
        ct, st = math.cos(t), math.sin(t)
        p = pivots[-1]
        tip = np.array([p[0] + ct * self.tip[0] + st * self.tip[1], p[1] - st * self.tip[0] + ct * self.tip[1]])
        return theta, pivots, tip

    def jacobian(self, pivots: FloatArray, tip: FloatArray) -> FloatArray:
        """(2, n): d tip / d local angle, zero for joints that do not move."""
        if self.plan.has_dyn:
            anchor = np.where(self.plan.anchor_is_tip[:, None], tip, pivots[self.plan.anchor_index])
        else:
            anchor = tip
        r = anchor - pivots
        jac = np.empty((2, self.n))
        jac[0] = r[:, 1] * self.var
        jac[1] = -r[:, 0] * self.var
        return jac


def solve_ik(character: Character, angles: npt.ArrayLike, translation: npt.ArrayLike, joint_index: int,
             local_point: npt.ArrayLike, target: npt.ArrayLike,
             limits: Limits = None, *, freeze_root: bool = True, tolerance: float = 1e-4,
             max_iterations: int = 100, damping: float = 1e-3, hold_dynamic: bool = True,
             stats: IKStats | None = None) -> FloatArray:
    """New local angles (J,) that bring ``local_point`` of ``joint_index`` towards ``target``.

    Damped least squares with adaptive (Levenberg-Marquardt) damping: a step is kept only
    if it lowers the distance, otherwise the damping grows, so the result is never worse
    than the start. ``limits`` (:data:`Limits`) are [min, max] local angles; a
    joint that hits a limit is clamped and frozen for the rest of that iteration. Only the
    chain from the root to ``joint_index`` moves; the root turns only with
    ``freeze_root=False``. An unreachable target gives the closest stretch, never NaN.
    Dynamic joints keep their world angle (their local angle compensates).
    """
    a0 = np.array(angles, dtype=np.float64).reshape(len(character.joints))
    q = np.asarray(target, dtype=np.float64).reshape(2)
    if stats is not None:
        stats.method, stats.iterations = "dls", 0
    if not np.all(np.isfinite(q)):
        return a0
    chain = _Chain(character, a0, translation, joint_index, local_point, freeze_root)
    n = chain.n
    local0 = a0[chain.idx]
    bounds = limit_bounds(limits, len(a0))
    if bounds is not None:
        lo, hi = bounds[0][chain.idx], bounds[1][chain.idx]
    delta = np.zeros(n)
    _, pivots, tip = chain.evaluate(delta)
    err = q - tip
    err2 = float(err @ err)
    scale = max(float(np.abs(pivots - tip).max()), 1e-9) if n else 1.0
    lam2 = damping * scale * scale
    tol2 = tolerance * tolerance
    if not chain.var.any():
        if stats is not None:
            stats.error = math.sqrt(err2)
        return a0
    iterations = 0
    for iterations in range(1, max_iterations + 1):
        if err2 <= tol2:
            iterations -= 1
            break
        jac = chain.jacobian(pivots, tip)
        free = chain.var
        improved = False
        for _attempt in range(12):
            step = _dls_step(jac, err, lam2)
            cand = delta + step
            if bounds is not None:
                clipped = np.clip(local0 + cand, lo, hi) - local0
                hit = (clipped != cand) & free
                if hit.any():
                    free = free & ~hit
                    jac = jac * free
                    cand = clipped
            _, piv_c, tip_c = chain.evaluate(cand)
            e_c = q - tip_c
            e2 = float(e_c @ e_c)
            if e2 < err2:
                delta, pivots, tip, err, err2 = cand, piv_c, tip_c, e_c, e2
                lam2 = max(lam2 * 0.3, 1e-12 * scale * scale)
                improved = True
                break
            lam2 *= 4.0
        if not improved:
            break
    if stats is not None:
        stats.iterations, stats.error = iterations, math.sqrt(err2)
    return chain_result(chain, a0, delta, hold_dynamic)


def chain_result(chain: _Chain, angles: FloatArray, delta: FloatArray, hold_dynamic: bool = True) -> FloatArray:
    """Every joint's local angle (J,) after the chain's local changes ``delta``: the chain
    joints changed, and (``hold_dynamic``) each dynamic joint hanging from a chain joint
    turned back by its parent's world-angle change, so that it keeps its world angle."""
    out = np.array(angles, dtype=np.float64)
    out[chain.idx] = out[chain.idx] + delta
    plan = chain.plan
    if hold_dynamic and len(plan.follow_joint):
        # a dynamic joint keeps its world angle: undo its parent's world-angle change
        change = chain.world_change(delta)
        out[plan.follow_joint] -= change[plan.follow_pos]
    return out


def _dls_step(jac: FloatArray, err: FloatArray, lam2: float) -> FloatArray:
    """Jᵀ (J Jᵀ + λ² I)⁻¹ e with the 2×2 inverse written out."""
    a = float(jac[0] @ jac[0]) + lam2
    b = float(jac[0] @ jac[1])
    d = float(jac[1] @ jac[1]) + lam2
    det = a * d - b * b
    if det <= 0 or not math.isfinite(det):
        return np.zeros(jac.shape[1])
    y0 = (d * err[0] - b * err[1]) / det
    y1 = (a * err[1] - b * err[0]) / det
    return np.asarray(jac[0] * y0 + jac[1] * y1, dtype=np.float64)


def ik_error(character: Character, angles: npt.ArrayLike, translation: npt.ArrayLike, joint: int,
             local_point: npt.ArrayLike, target: npt.ArrayLike) -> float:
    p = end_effector(character, angles, translation, joint, local_point)
    return float(np.hypot(*(np.asarray(target, dtype=np.float64) - p)))


def planar_chain(links: int, link_length: float = 10.0, name: str = "chain") -> Character:
    """A straight chain of ``links`` joints along +x, each link a thin rectangle; the last
    joint's tip is at ``(links * link_length, 0)`` (benchmarks and tests)."""
    from qtanimator.core.rig2d import Joint, Shape

    joints = []
    for i in range(links):
        x0, x1 = i * link_length, (i + 1) * link_length
        pts = np.array([[x0, -1.0], [x1, -1.0], [x1, 1.0], [x0, 1.0]])
        joints.append(Joint(f"link{i}", None if i == 0 else i - 1, np.array([x0, 0.0]),
                            shapes=[Shape(pts, True, fill=(0.2, 0.4, 0.8, 1.0))]))
    return Character(name, joints)
