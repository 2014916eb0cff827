"""More IK solvers for 2D characters: CCD, FABRIK and the analytic two-bone solver.

They solve the same problem as :func:`qtanimator.core.ik.solve_ik` (damped least squares):
bring a point of the dragged joint (given in its rest-pose coordinates) to a target by
turning the chain from the root to that joint, the root frozen by default, dynamic
(pendulum) joints keeping their world angle, within optional per-joint limits (either
form :func:`~qtanimator.core.ik.limit_bounds` reads). Each returns every joint's new local
angle, never NaN, and never moves a joint off the chain.

* **CCD** (cyclic coordinate descent; Wang & Chen 1991, Welman 1993): sweeps from the
  dragged joint to the root, turning each joint by the angle that points the end at the
  target, clamped to its limits. Along a backward sweep a joint's pivot does not move when
  the joints below it turn, so one sweep costs one forward kinematics and O(n) scalar work.
  Every clamped turn lowers the distance, so the error never grows. After each sweep a
  pattern move goes on along the sweep's net change while that helps: coordinate descent
  zigzags slowly down the narrow valley of a chain near full stretch.
* **FABRIK** (forward and backward reaching IK; Aristidou & Lasenby 2011): a backward pass
  puts the end on the target and pulls each pivot to its bone length from the next, a
  forward pass puts the first moving pivot back and lays each bone along the new line.
  The forward pass is done in angles (each joint's local angle clamped to its limits as it
  is laid), so the positions are always the exact forward kinematics of the angles it
  returns: converting positions back to rotations is part of the pass. The same pattern
  move follows each pass; the best pass is returned.
* **Two-bone** (the law of cosines, as in Spine's two-bone IK constraint): for a chain whose
  moving joints are exactly the dragged joint and its parent, the exact answer in one step.
  ``bend`` chooses the side the middle joint bends to: ``"keep"`` (the side it bends to now),
  ``"positive"`` (counter-clockwise on screen: a positive local angle from straight) or
  ``"negative"``. When limits forbid that side and the other side is allowed, the other is
  used; when neither fits, the solution is projected onto the limits (the middle joint
  clamped, the first joint aimed and clamped, the middle aimed again and clamped).
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from qtanimator.core.ik import FloatArray, IKStats, Limits, _Chain, _plan, chain_result, limit_bounds
from qtanimator.core.rig2d import Character

#: The bend side settings of the two-bone solver.
BEND_DIRECTIONS = ("keep", "positive", "negative")

_TWO_PI = 2.0 * math.pi
#: Three sweeps or passes that together gain less than three times this fraction of the
#: tolerance end the solve (:class:`StallCheck`).
STALL_FRACTION = 1e-3


class StallCheck:
    """Ends an iterative solve that no longer gets closer: True once the last ``window``
    iterations together gained less than ``window`` × :data:`STALL_FRACTION` × the
    tolerance (an unreachable target, or limits in the way). One slow sweep alone does not
    stop it: coordinate descent alternates slow and quick sweeps."""

    def __init__(self, error: float, tolerance: float, window: int = 3) -> None:
        self.history = [error]
        self.window = window
        self.limit = window * STALL_FRACTION * tolerance

    def __call__(self, error: float) -> bool:
        self.history.append(error)
        if len(self.history) <= self.window:
            return False
        return self.history[-1 - self.window] - error < self.limit


def _wrap(angle: float) -> float:
    """``angle`` moved by whole turns into [−π, π]."""
    return math.remainder(angle, _TWO_PI)


def _bounds(limits: Limits, count: int, chain: _Chain) -> tuple[list[float], list[float]]:
    b = limit_bounds(limits, count)
    if b is None:
        return [-math.inf] * chain.n, [math.inf] * chain.n
    return b[0][chain.idx].tolist(), b[1][chain.idx].tolist()


def _clamp(value: float, lo: float, hi: float) -> float:
    return min(max(value, lo), hi)


def _start(character: Character, angles: npt.ArrayLike, target: npt.ArrayLike) -> tuple[FloatArray, FloatArray]:
    a0 = np.array(angles, dtype=np.float64).reshape(len(character.joints))
    q = np.asarray(target, dtype=np.float64).reshape(2)
    return a0, q


def _finish(stats: IKStats | None, method: str, iterations: int, error: float) -> None:
    if stats is not None:
        stats.method, stats.iterations, stats.error = method, iterations, error


# ------------------------------------------------------------------------------ CCD
def solve_ccd(character: Character, angles: npt.ArrayLike, translation: npt.ArrayLike, joint_index: int,
              local_point: npt.ArrayLike, target: npt.ArrayLike, limits: Limits = None, *,
              freeze_root: bool = True, tolerance: float = 1e-4, max_iterations: int = 100,
              hold_dynamic: bool = True, stats: IKStats | None = None, accelerate: bool = True) -> FloatArray:
    """Cyclic coordinate descent: at most ``max_iterations`` sweeps from the dragged joint
    to the root (an iteration is one sweep), stopping at ``tolerance`` or when sweeps gain
    almost nothing (:class:`StallCheck`; an unreachable target: the chain points at it).
    ``accelerate`` adds the pattern move after each sweep."""
    a0, q = _start(character, angles, target)
    if not np.all(np.isfinite(q)):
        _finish(stats, "ccd", 0, math.nan)
        return a0
    chain = _Chain(character, a0, translation, joint_index, local_point, freeze_root)
    n = chain.n
    lo, hi = _bounds(limits, len(a0), chain)
    var = chain.var.tolist()
    dyn = character.dynamic[chain.idx].tolist()
    local0 = a0[chain.idx].tolist()
    delta = [0.0] * n
    lo_a, hi_a, local0_a = np.array(lo), np.array(hi), np.array(local0)
    qx, qy = float(q[0]), float(q[1])
    _, pivots, tip = chain.evaluate(np.zeros(n))
    err = math.hypot(qx - tip[0], qy - tip[1])
    sweeps = 0
    stalled = StallCheck(err, tolerance)
    while err > tolerance and sweeps < max_iterations and any(var):
        piv = pivots.tolist()
        start = np.array(delta)
        tx, ty = float(tip[0]), float(tip[1])
        # The anchor is the point a joint's turn carries round its pivot: the end, or the
        # pivot of the next dynamic joint (below it the chain only translates).
        ax, ay = tx, ty
        for k in range(n - 1, -1, -1):
            if dyn[k]:
                ax, ay = piv[k]
                continue
            if not var[k]:
                continue
            px, py = piv[k]
            ux, uy = ax - px, ay - py
            # turning by d: anchor' = p + R(d)·u, end' = end + (anchor' − anchor): a circle
            # of radius |u| about p + (end − anchor); point u at the target from its centre
            vx, vy = qx - (px + tx - ax), qy - (py + ty - ay)
            if (ux == 0.0 and uy == 0.0) or (vx == 0.0 and vy == 0.0):
                continue
            d = -math.atan2(ux * vy - uy * vx, ux * vx + uy * vy)  # R(d) takes ψ to ψ − d
            current = local0[k] + delta[k]
            d = _clamp(current + d, lo[k], hi[k]) - current
            if d == 0.0:
                continue
            delta[k] += d
            c, s = math.cos(d), math.sin(d)
            nax, nay = px + c * ux + s * uy, py - s * ux + c * uy
            tx += nax - ax
            ty += nay - ay
            ax, ay = nax, nay
        sweeps += 1
        moved = np.array(delta)
        _, pivots, tip = chain.evaluate(moved)
        new_err = math.hypot(qx - tip[0], qy - tip[1])
        if accelerate and new_err > tolerance:
            moved, pivots, tip, new_err = _extrapolate(chain, start, moved, new_err, q, lo_a, hi_a, local0_a)
            delta = moved.tolist()
        err = new_err
        if stalled(err):
            break
    _finish(stats, "ccd", sweeps, err)
    return chain_result(chain, a0, np.array(delta), hold_dynamic)


def _extrapolate(chain: _Chain, before: FloatArray, after: FloatArray, err: float, q: FloatArray,
                 lo: FloatArray, hi: FloatArray, local0: FloatArray
                 ) -> tuple[FloatArray, FloatArray, FloatArray, float]:
    """A pattern move after a sweep: go on along the sweep's change (2, 4, 8… times it,
    within the limits) while that lowers the error, then try the vertex of the parabola
    through the last three errors. Coordinate descent zigzags down a narrow valley (a
    chain near full stretch); the sweep's net change points along it."""
    step = after - before
    moving = step != 0.0   # joints that did not turn (a frozen root) are left exactly as they are

    def at(factor: float) -> tuple[FloatArray, FloatArray, FloatArray, float]:
        cand = before + factor * step
        cand = np.where(moving, np.clip(local0 + cand, lo, hi) - local0, cand)
        _, piv, tip = chain.evaluate(cand)
        return cand, piv, tip, math.hypot(q[0] - tip[0], q[1] - tip[1])

    _, piv, tip = chain.evaluate(after)
    best = (after, piv, tip, err)
    tried = [(0.0, math.inf), (1.0, err)]
    factor = 1.0
    for _ in range(8):
        factor *= 2.0
        cand = at(factor)
        tried.append((factor, cand[3]))
        if cand[3] >= best[3]:
            break
        best = cand
    (f0, e0), (f1, e1), (f2, e2) = tried[-3:]
    if math.isfinite(e0) and f2 > f1:
        # squared errors are smooth in the factor: the parabola's vertex
        y0, y1, y2 = e0 * e0, e1 * e1, e2 * e2
        den = (f1 - f0) * (y1 - y2) - (f1 - f2) * (y1 - y0)
        if den != 0.0:
            vertex = f1 - 0.5 * ((f1 - f0) ** 2 * (y1 - y2) - (f1 - f2) ** 2 * (y1 - y0)) / den
            if f0 < vertex < f2 and vertex != f1:
                cand = at(vertex)
                if cand[3] < best[3]:
                    best = cand
    return best


# ---------------------------------------------------------------------------- FABRIK
def solve_fabrik(character: Character, angles: npt.ArrayLike, translation: npt.ArrayLike, joint_index: int,
                 local_point: npt.ArrayLike, target: npt.ArrayLike, limits: Limits = None, *,
                 freeze_root: bool = True, tolerance: float = 1e-4, max_iterations: int = 100,
                 hold_dynamic: bool = True, stats: IKStats | None = None, accelerate: bool = True) -> FloatArray:
    """FABRIK: at most ``max_iterations`` backward + forward passes (an iteration is one of
    each). The forward pass lays the bones in angles, clamping each local angle to its
    limits, so every iterate is a pose; the best one is returned. A dynamic joint's bone
    keeps its world direction in both passes. A zero-length bone keeps its local angle."""
    a0, q = _start(character, angles, target)
    if not np.all(np.isfinite(q)):
        _finish(stats, "fabrik", 0, math.nan)
        return a0
    chain = _Chain(character, a0, translation, joint_index, local_point, freeze_root)
    n = chain.n
    var = chain.var.tolist()
    qx, qy = float(q[0]), float(q[1])
    _, pivots, tip = chain.evaluate(np.zeros(n))
    err = math.hypot(qx - tip[0], qy - tip[1])
    if not any(var):
        _finish(stats, "fabrik", 0, err)
        return a0
    first = var.index(True)
    lo, hi = _bounds(limits, len(a0), chain)
    dyn = character.dynamic[chain.idx].tolist()
    local0 = a0[chain.idx].tolist()
    theta0 = chain.theta0.tolist()
    rest = np.vstack([chain.dc, chain.tip[None, :]])   # bone k: pivot k → pivot k + 1 (the end for the last)
    rx, ry = rest[:, 0].tolist(), rest[:, 1].tolist()
    length = np.hypot(rest[:, 0], rest[:, 1]).tolist()
    rest_angle = np.arctan2(rest[:, 1], rest[:, 0]).tolist()
    scale = max(sum(length[first:]), 1e-300)
    tiny = 1e-12 * scale
    parent_world = theta0[first - 1] if first > 0 else 0.0
    x = [*pivots.tolist(), [float(tip[0]), float(tip[1])]]
    local = list(local0)
    lo_a, hi_a, local0_a = np.array(lo), np.array(hi), np.array(local0)
    best_err, best_local = err, list(local)
    iterations = 0
    stalled = StallCheck(err, tolerance)
    while err > tolerance and iterations < max_iterations:
        iterations += 1
        before = np.array([0.0 if dyn[k] else local[k] - local0[k] for k in range(n)])
        # backward: the end on the target, each pivot pulled to its bone length
        back = [list(p) for p in x]
        back[n] = [qx, qy]
        for k in range(n - 1, first, -1):
            nx_, ny_ = back[k + 1]
            if dyn[k]:  # a pendulum keeps its world direction: a rigid bone
                back[k] = [nx_ - (x[k + 1][0] - x[k][0]), ny_ - (x[k + 1][1] - x[k][1])]
                continue
            dx, dy = back[k][0] - nx_, back[k][1] - ny_
            dist = math.hypot(dx, dy)
            if dist <= tiny:
                dx, dy = x[k][0] - x[k + 1][0], x[k][1] - x[k + 1][1]
                dist = math.hypot(dx, dy)
            if dist <= tiny:
                back[k] = [nx_, ny_]
                continue
            back[k] = [nx_ + length[k] * dx / dist, ny_ + length[k] * dy / dist]
        # forward, in angles: each bone aimed at the next backward point, clamped
        px, py = x[first]
        world_prev = parent_world
        for k in range(first, n):
            if dyn[k]:
                world_k = theta0[k]
            else:
                wx, wy = back[k + 1][0] - px, back[k + 1][1] - py
                if length[k] > tiny and math.hypot(wx, wy) > tiny:
                    # R(Θ) takes the rest bone's ψ to ψ − Θ: Θ = ψ(rest) − ψ(w)
                    raw = rest_angle[k] - math.atan2(wy, wx)
                    local[k] += _wrap(raw - world_prev - local[k])
                local[k] = _clamp(local[k], lo[k], hi[k])
                world_k = world_prev + local[k]
            c, s = math.cos(world_k), math.sin(world_k)
            px, py = px + c * rx[k] + s * ry[k], py - s * rx[k] + c * ry[k]
            x[k + 1] = [px, py]
            world_prev = world_k
        new_err = math.hypot(qx - px, qy - py)
        if accelerate and new_err > tolerance:
            after = np.array([0.0 if dyn[k] else local[k] - local0[k] for k in range(n)])
            moved, piv, end, new_err = _extrapolate(chain, before, after, new_err, q, lo_a, hi_a, local0_a)
            x = [*piv.tolist(), [float(end[0]), float(end[1])]]
            local = [local0[k] if dyn[k] else local0[k] + float(moved[k]) for k in range(n)]
        if new_err < best_err:
            best_err, best_local = new_err, list(local)
        err = new_err
        if stalled(err):
            break
    delta = np.array([0.0 if dyn[k] else best_local[k] - local0[k] for k in range(n)])
    _finish(stats, "fabrik", iterations, best_err)
    return chain_result(chain, a0, delta, hold_dynamic)


# -------------------------------------------------------------------------- two-bone
def two_bone_applies(character: Character, joint_index: int, freeze_root: bool = True) -> bool:
    """True when the chain to ``joint_index`` has exactly two moving joints: the joint and
    its parent (a pendulum joint, or the frozen root, does not move)."""
    var = _plan(character, joint_index, freeze_root).var
    return len(var) >= 2 and int(var.sum()) == 2 and bool(var[-1]) and bool(var[-2])


def two_bone_closed_form(upper: float, lower: float, distance: float, bend: int = 1) -> tuple[float, float]:
    """The law of cosines for bones of lengths ``upper`` and ``lower`` whose end must lie
    ``distance`` from the first pivot (clamped to what they can reach): ``(first, turn)``
    in joint angles (counter-clockwise positive): the first bone's angle from the line to
    the target, and the second bone's turn from the first. ``bend`` (±1) is the sign of the
    turn; the first bone then leans the other way."""
    if upper <= 0.0 or lower <= 0.0:
        return 0.0, 0.0
    d = min(max(distance, abs(upper - lower)), upper + lower)
    cos_inner = (upper * upper + lower * lower - d * d) / (2.0 * upper * lower)
    turn = math.pi - math.acos(min(max(cos_inner, -1.0), 1.0))
    if d <= 0.0:
        return -bend * math.pi / 2.0, bend * turn
    cos_alpha = (upper * upper + d * d - lower * lower) / (2.0 * upper * d)
    return -bend * math.acos(min(max(cos_alpha, -1.0), 1.0)), bend * turn


def _fit(angle: float, reference: float, lo: float, hi: float) -> float:
    """The whole-turn equivalent of ``angle`` inside [lo, hi] nearest ``reference`` (the
    one nearest ``reference`` when none is inside)."""
    near = reference + _wrap(angle - reference)
    inside = [a for a in (near, near - _TWO_PI, near + _TWO_PI) if lo <= a <= hi]
    if inside:
        return min(inside, key=lambda a: abs(a - reference))
    return near


def solve_two_bone(character: Character, angles: npt.ArrayLike, translation: npt.ArrayLike, joint_index: int,
                   local_point: npt.ArrayLike, target: npt.ArrayLike, limits: Limits = None, *,
                   freeze_root: bool = True, bend: str = "keep", tolerance: float = 1e-4,
                   hold_dynamic: bool = True, stats: IKStats | None = None) -> FloatArray:
    """The analytic two-bone solution (law of cosines) for a chain whose moving joints are
    ``joint_index`` and its parent (:func:`two_bone_applies`; ValueError otherwise).
    ``bend`` is one of :data:`BEND_DIRECTIONS`. An unreachable target gives the chain
    stretched (or folded) towards it; a target on the first pivot keeps the first bone's
    direction."""
    if bend not in BEND_DIRECTIONS:
        raise ValueError(f"unknown bend direction {bend!r}; expected one of {', '.join(BEND_DIRECTIONS)}")
    if not two_bone_applies(character, joint_index, freeze_root):
        raise ValueError("the two-bone solver needs a chain of exactly two moving joints")
    a0, q = _start(character, angles, target)
    if not np.all(np.isfinite(q)):
        _finish(stats, "two_bone", 0, math.nan)
        return a0
    chain = _Chain(character, a0, translation, joint_index, local_point, freeze_root)
    n = chain.n
    ia, ib = n - 2, n - 1
    lo, hi = _bounds(limits, len(a0), chain)
    theta0 = chain.theta0.tolist()
    parent_world = theta0[ia - 1] if ia > 0 else 0.0
    _, pivots, tip0 = chain.evaluate(np.zeros(n))
    pax, pay = float(pivots[ia][0]), float(pivots[ia][1])
    r1x, r1y = float(chain.dc[ia][0]), float(chain.dc[ia][1])
    r2x, r2y = float(chain.tip[0]), float(chain.tip[1])
    l1, l2 = math.hypot(r1x, r1y), math.hypot(r2x, r2y)
    qx, qy = float(q[0]), float(q[1])
    la0, lb0 = float(a0[chain.idx[ia]]), float(a0[chain.idx[ib]])

    def rot(theta: float, x: float, y: float) -> tuple[float, float]:
        c, s = math.cos(theta), math.sin(theta)
        return c * x + s * y, -s * x + c * y

    def end(la: float, lb: float) -> tuple[float, float, float, float]:
        """The middle pivot and the end point for local angles ``la``, ``lb``."""
        w1 = parent_world + la
        bx, by = rot(w1, r1x, r1y)
        bx, by = pax + bx, pay + by
        ex, ey = rot(w1 + lb, r2x, r2y)
        return bx, by, bx + ex, by + ey

    def error(la: float, lb: float) -> float:
        _bx, _by, ex, ey = end(la, lb)
        return math.hypot(qx - ex, qy - ey)

    def aim_first(la: float, lb: float) -> float:
        """The first joint's angle pointing the (rigid) two bones at the target."""
        _bx, _by, ex, ey = end(la, lb)
        ux, uy, vx, vy = ex - pax, ey - pay, qx - pax, qy - pay
        if math.hypot(ux, uy) == 0.0 or math.hypot(vx, vy) == 0.0:
            return la
        return la - math.atan2(ux * vy - uy * vx, ux * vx + uy * vy)

    def aim_second(la: float, lb: float) -> float:
        bx, by, ex, ey = end(la, lb)
        ux, uy, vx, vy = ex - bx, ey - by, qx - bx, qy - by
        if math.hypot(ux, uy) == 0.0 or math.hypot(vx, vy) == 0.0:
            return lb
        return lb - math.atan2(ux * vy - uy * vx, ux * vx + uy * vy)

    # ψ = atan2(y, x) of a vector in scene (y-down) coordinates: R(Θ) takes ψ to ψ − Θ
    straight = math.atan2(r2y, r2x) - math.atan2(r1y, r1x)   # the middle joint's angle with the bones in line
    bend_now = _wrap(lb0 - straight)
    if bend == "positive":
        side = 1
    elif bend == "negative":
        side = -1
    elif abs(bend_now) > 1e-9:
        side = 1 if bend_now > 0 else -1
    elif math.isfinite(lo[ib]) and math.isfinite(hi[ib]):   # straight: the side its limits lean to
        side = -1 if _wrap(0.5 * (lo[ib] + hi[ib]) - straight) < 0 else 1
    else:
        side = 1

    dx, dy = qx - pax, qy - pay
    d = math.hypot(dx, dy)
    if d > 0.0:
        aim = math.atan2(dy, dx)
    else:  # on the first pivot: keep pointing where the end points now
        ex, ey = float(tip0[0]) - pax, float(tip0[1]) - pay
        aim = math.atan2(ey, ex) if math.hypot(ex, ey) > 0.0 else math.atan2(*rot(parent_world + la0, r1x, r1y)[::-1])

    def analytic(s: int) -> tuple[float, float]:
        if l1 == 0.0 or l2 == 0.0:  # one bone has no length: aim the other
            la = aim_first(la0, lb0) if l1 > 0.0 else la0
            return la, aim_second(la, lb0)
        first, turn = two_bone_closed_form(l1, l2, d, s)
        w_aim = math.atan2(r1y, r1x) - aim   # the first bone's world angle pointing at the target
        return w_aim + first - parent_world, straight + turn

    def inside(la: float, lb: float) -> bool:
        return lo[ia] <= la <= hi[ia] and lo[ib] <= lb <= hi[ib]

    candidates: list[tuple[float, float, float]] = []
    chosen: tuple[float, float] | None = None
    for s in (side, -side):
        la, lb = analytic(s)
        la, lb = _fit(la, la0, lo[ia], hi[ia]), _fit(lb, lb0, lo[ib], hi[ib])
        if inside(la, lb):
            chosen = (la, lb)
            break
        # project onto the limits: the middle clamped, the first aimed, the middle re-aimed
        lb = _clamp(lb, lo[ib], hi[ib])
        la = _clamp(_fit(aim_first(la, lb), la, lo[ia], hi[ia]), lo[ia], hi[ia])
        lb = _clamp(_fit(aim_second(la, lb), lb, lo[ib], hi[ib]), lo[ib], hi[ib])
        candidates.append((error(la, lb), la, lb))
    if chosen is None:
        # neither side fits the limits: the closer projection (the preferred side when it
        # reaches), never further than the start put inside the limits
        la, lb = _clamp(la0, lo[ia], hi[ia]), _clamp(lb0, lo[ib], hi[ib])
        best = candidates[0] if candidates[0][0] <= tolerance else min([*candidates, (error(la, lb), la, lb)])
        chosen = (best[1], best[2])
    la, lb = chosen
    delta = np.zeros(n)
    delta[ia], delta[ib] = la - la0, lb - lb0
    _finish(stats, "two_bone", 1, error(la, lb))
    return chain_result(chain, a0, delta, hold_dynamic)


__all__ = ["BEND_DIRECTIONS", "solve_ccd", "solve_fabrik", "solve_two_bone", "two_bone_applies",
           "two_bone_closed_form"]
