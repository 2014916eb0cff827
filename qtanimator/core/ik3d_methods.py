"""More IK solvers for 3D skeletons: CCD, FABRIK and the analytic two-bone solver.

They solve the problem of :func:`qtanimator.core.ik3d.solve_ik` (damped least squares):
move joint ``end`` to a target by changing the rotation DOFs ``dofs`` of its ancestors
(default :func:`~qtanimator.core.ik3d.chain_dofs`), every DOF kept inside its limits and
every other DOF left as it is, and return an :class:`~qtanimator.core.ik3d.IKResult`. The
skeleton is not changed. Only the *path* matters: the joints from the highest joint owning
a DOF down to ``end``; the frame above it is fixed for the whole solve.

* **CCD, one DOF at a time** (Welman 1993): each DOF is a hinge about its world axis
  (``F_j·R_1⋯R_{k−1}·e_a``, as in the Jacobian); it turns by the angle that brings the end's
  projection on the hinge plane onto the target's, clamped to its limits. A sweep goes from
  the end up, and within a joint from the last Euler factor to the first: then no DOF's
  axis or pivot has moved before its turn, so one sweep costs one forward kinematics.
  After a sweep, a pattern move goes on along the sweep's net change while that helps
  (coordinate descent zigzags along narrow valleys).
* **FABRIK** (Aristidou & Lasenby 2011) on the path's joint positions. Converting the
  positions back to rotations, top down: a joint whose three DOFs are free turns by the
  shortest arc carrying its child's current direction onto the new one (no twist), written
  as Euler angles in its order (the equivalent triple nearest the current values), each
  clamped to its limits; a joint with fewer free DOFs aims its child with hinge turns
  instead. Each joint is aimed from where its parent really put it, and the next pass starts
  from the positions those clamped angles give, so limits are always respected.
* **Two-bone**: when the DOFs belong to exactly the end's parent (the middle joint) and
  grandparent. The middle joint bends in its current bend plane (about the plane's normal,
  or its free hinge axis most aligned with it) until the end is at the target's distance
  (law of cosines, solved exactly for the hinge), then the first joint turns the triangle
  onto the target, the knee kept on the side of ``pole`` (a world point; default: where the
  knee is now). With limits or DOFs that cannot make that exact, CCD sweeps finish the solve.

Every solver takes an optional ``offset``: the effector is then the point ``W_end · offset``
(a clicked point of the skin in the end joint's frame) instead of the end's origin. It is
a virtual child of the end with no DOFs, so the end's own DOFs move it like an ancestor's
(two-bone: the end is the middle joint, its parent the first).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from qtanimator.core.ik3d import DofRef, IKResult, chain_dofs
from qtanimator.core.ik_methods import StallCheck
from qtanimator.core.rotation import AXES
from qtanimator.core.skeleton import Skeleton

FloatArray = npt.NDArray[np.float64]
_TWO_PI = 2.0 * math.pi


def _rotation_about(axis: FloatArray, angle: float) -> FloatArray:
    """The 3×3 rotation by ``angle`` about the unit ``axis`` (Rodrigues)."""
    x, y, z = (float(v) for v in axis)
    c, s = math.cos(angle), math.sin(angle)
    t = 1.0 - c
    return np.array([[t * x * x + c, t * x * y - s * z, t * x * z + s * y],
                     [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
                     [t * x * z - s * y, t * y * z + s * x, t * z * z + c]])


Vec = tuple[float, float, float]


def _turn_about_axis(i: int, angle: float, v: Vec) -> Vec:
    """``v`` turned by ``angle`` about coordinate axis ``i`` (x 0, y 1, z 2), right-handed."""
    c, s = math.cos(angle), math.sin(angle)
    x, y, z = v
    if i == 0:
        return x, c * y - s * z, s * y + c * z
    if i == 1:
        return c * x + s * z, y, c * z - s * x
    return c * x - s * y, s * x + c * y, z


def _euler_matrix(angles: Sequence[float], order: str) -> FloatArray:
    """``R_a·R_b·R_c`` for ``order`` "abc", for one joint
    (:func:`qtanimator.core.rotation.rotation_matrices` with less overhead)."""
    out = None
    for letter in order:
        i = AXES.index(letter)
        c, s = math.cos(angles[i]), math.sin(angles[i])
        if i == 0:
            r = np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
        elif i == 1:
            r = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
        else:
            r = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        out = r if out is None else out @ r
    assert out is not None
    return out


def _nearest_euler(rotation: FloatArray, order: str, previous: Sequence[float]) -> list[float]:
    """Euler angles (x, y, z) of ``rotation`` in ``order``, as the equivalent triple nearest
    ``previous``: :func:`~qtanimator.core.rotation.euler_from_matrices` followed by
    :func:`~qtanimator.core.rotation.euler_filter`'s rule, in plain floats."""
    m = rotation.tolist()
    a, b, c = (AXES.index(letter) for letter in order)
    sign = 1.0 if (b - a) % 3 == 1 else -1.0
    sb = min(max(sign * m[a][c], -1.0), 1.0)
    cb = math.hypot(m[a][a], m[a][b])
    angles = [0.0, 0.0, 0.0]
    angles[b] = math.atan2(sb, cb)
    if cb < 1e-12:
        angles[a], angles[c] = math.atan2(sign * m[c][b], m[b][b]), 0.0
    else:
        angles[a], angles[c] = math.atan2(-sign * m[b][c], m[c][c]), math.atan2(-sign * m[a][b], m[a][a])
    flipped = list(angles)
    flipped[a] += math.pi
    flipped[b] = math.pi - flipped[b]
    flipped[c] += math.pi
    best: list[float] = []
    best_distance = math.inf
    for cand in (angles, flipped):
        moved = [x + _TWO_PI * round((p - x) / _TWO_PI) for x, p in zip(cand, previous)]
        distance = sum(abs(x - p) for x, p in zip(moved, previous))
        if distance < best_distance:
            best, best_distance = moved, distance
    return best


def _hinge_turn(axis: Vec, pivot: Vec, end: Vec, goal: Vec) -> float:
    """The turn about the unit ``axis`` through ``pivot`` that brings ``end``'s projection
    on the hinge plane onto ``goal``'s (0 when either projection is a point)."""
    ax, ay, az = axis
    ux, uy, uz = end[0] - pivot[0], end[1] - pivot[1], end[2] - pivot[2]
    wx, wy, wz = goal[0] - pivot[0], goal[1] - pivot[1], goal[2] - pivot[2]
    du, dw = ux * ax + uy * ay + uz * az, wx * ax + wy * ay + wz * az
    ux, uy, uz = ux - du * ax, uy - du * ay, uz - du * az
    wx, wy, wz = wx - dw * ax, wy - dw * ay, wz - dw * az
    if ux * ux + uy * uy + uz * uz <= 1e-300 or wx * wx + wy * wy + wz * wz <= 1e-300:
        return 0.0
    cross = ax * (uy * wz - uz * wy) + ay * (uz * wx - ux * wz) + az * (ux * wy - uy * wx)
    return math.atan2(cross, ux * wx + uy * wy + uz * wz)


def _rotate_point(axis: Vec, angle: float, pivot: Vec, point: Vec) -> Vec:
    """``point`` turned by ``angle`` about the unit ``axis`` through ``pivot`` (Rodrigues)."""
    ax, ay, az = axis
    x, y, z = point[0] - pivot[0], point[1] - pivot[1], point[2] - pivot[2]
    c, s = math.cos(angle), math.sin(angle)
    d = (ax * x + ay * y + az * z) * (1.0 - c)
    cx, cy, cz = ay * z - az * y, az * x - ax * z, ax * y - ay * x
    return (pivot[0] + c * x + s * cx + d * ax, pivot[1] + c * y + s * cy + d * ay,
            pivot[2] + c * z + s * cz + d * az)


def _unit(v: FloatArray) -> FloatArray | None:
    n = float(np.linalg.norm(v))
    if not math.isfinite(n) or n <= 1e-300:
        return None
    return v / n


def _shortest_arc(u: FloatArray, v: FloatArray) -> FloatArray:
    """The smallest rotation taking the direction of ``u`` onto that of ``v`` (identity
    when either is zero; a half turn about some perpendicular when they are opposite)."""
    a, b = _unit(u), _unit(v)
    if a is None or b is None:
        return np.eye(3)
    axis = np.cross(a, b)
    s = float(np.linalg.norm(axis))
    c = float(a @ b)
    if s < 1e-12:
        if c > 0:
            return np.eye(3)
        perp = np.cross(a, np.eye(3)[int(np.argmin(np.abs(a)))])
        return _rotation_about(perp / np.linalg.norm(perp), math.pi)
    return _rotation_about(axis / s, math.atan2(s, c))


def _perpendicular_part(v: FloatArray, unit: FloatArray) -> FloatArray:
    return np.asarray(v - float(v @ unit) * unit, dtype=np.float64)


class _PathChain:
    """The DOF values of one solve and the forward kinematics of its path."""

    def __init__(self, skeleton: Skeleton, end: int, target: npt.ArrayLike, dofs: Sequence[DofRef] | None,
                 chain_length: int, values: npt.ArrayLike | None, offset: npt.ArrayLike | None = None) -> None:
        self.skeleton = skeleton
        self.end = end
        self.goal = np.asarray(target, dtype=np.float64).reshape(3)
        self.v = skeleton.dof_values() if values is None else np.array(values, dtype=np.float64).reshape(-1, 3)
        dof_list = list(chain_dofs(skeleton, end, chain_length) if dofs is None else dofs)
        self.dofs = dof_list
        # With an offset the effector is a virtual child ``tip`` of the end (index past the
        # joints, no DOFs, at ``offset`` in the end's frame): the path ends there and the
        # end's own DOFs move it like any ancestor's.
        self.tip: int | None = None if offset is None else len(skeleton.joints)
        ancestors: list[int] = []
        if self.tip is not None:
            ancestors.append(end)
            end = self.tip
        j = skeleton.joints[self.end].parent
        while j is not None:
            ancestors.append(j)
            j = skeleton.joints[j].parent
        owners = {j for j, _a in dof_list}
        used = [j for j in ancestors if j in owners]   # DOFs of joints off the path cannot move the end
        top = used[-1] if used else end
        self.path = ([*ancestors[:ancestors.index(top) + 1][::-1], end] if used else [end])
        self.free: dict[int, list[int]] = {}
        for j, a in dof_list:
            if j in used and a not in self.free.setdefault(j, []):
                self.free[j].append(a)
        self.lo, self.hi = skeleton.dof_limits()
        for j, axes in self.free.items():   # start inside the limits, as the DLS solver does
            for a in axes:
                self.v[j, a] = min(max(self.v[j, a], self.lo[j, a]), self.hi[j, a])
        base = np.eye(4) if skeleton.placement is None else skeleton.placement.copy()
        base[:3, 3] += base[:3, :3] @ skeleton.root_translation
        above = ancestors[ancestors.index(self.path[0]) + 1:] if self.path[0] in ancestors else ancestors
        if above:   # the fixed frame the path hangs from: its ancestors' local matrices
            local = skeleton.local_matrices(self.v)
            for a in reversed(above):
                base = base @ local[a]
        self.base = base
        joints = [j for j in self.path if j != self.tip]
        self.orders = {j: skeleton.joints[j].rotation_order or skeleton.rotation_order for j in joints}
        self.offsets = {j: skeleton.joints[j].offset + skeleton.joints[j].translation for j in joints}
        self.scales = {j: skeleton.joints[j].scale for j in joints}
        if self.tip is not None:
            self.orders[self.tip] = "xyz"
            self.offsets[self.tip] = np.asarray(offset, dtype=np.float64).reshape(3).copy()
            self.scales[self.tip] = np.ones(3)

    # ------------------------------------------------------------------ kinematics
    def rotation(self, j: int) -> FloatArray:
        if j == self.tip:
            return np.eye(3)
        return _euler_matrix(self.v[j].tolist(), self.orders[j])

    def local(self, j: int) -> FloatArray:
        m = np.eye(4)
        m[:3, :3] = self.rotation(j) * self.scales[j][None, :]
        m[:3, 3] = self.offsets[j]
        return m

    def frames(self) -> list[FloatArray]:
        """World matrices of the path's joints, top first."""
        out = []
        w = self.base
        for j in self.path:
            w = w @ self.local(j)
            out.append(w)
        return out

    def end_position(self) -> FloatArray:
        return np.asarray(self.frames()[-1][:3, 3], dtype=np.float64).copy()

    def error(self, position: FloatArray) -> float:
        return float(np.linalg.norm(self.goal - position))

    # ------------------------------------------------------------------ DOF updates
    def axis(self, j: int, a: int, parent_frame: FloatArray) -> FloatArray:
        """The world axis of DOF ``a`` of joint ``j`` (unit), for its current values."""
        return np.array(self._axis(j, a, parent_frame[:3, :3].tolist()))

    def _axis(self, j: int, a: int, m: list[list[float]]) -> Vec:
        order = self.orders[j]
        k = order.index(AXES[a])
        col: Vec = (1.0 if a == 0 else 0.0, 1.0 if a == 1 else 0.0, 1.0 if a == 2 else 0.0)
        for letter in reversed(order[:k]):   # R_1⋯R_{k−1}·e_a
            i = AXES.index(letter)
            col = _turn_about_axis(i, float(self.v[j, i]), col)
        x = m[0][0] * col[0] + m[0][1] * col[1] + m[0][2] * col[2]
        y = m[1][0] * col[0] + m[1][1] * col[1] + m[1][2] * col[2]
        z = m[2][0] * col[0] + m[2][1] * col[1] + m[2][2] * col[2]
        n = math.sqrt(x * x + y * y + z * z)   # a scaled parent (glTF) turns the joint about a unit axis
        return col if n <= 1e-300 or not math.isfinite(n) else (x / n, y / n, z / n)

    def _hinge_pass(self, j: int, parent_frame: FloatArray, point: Vec, goal: Vec) -> Vec:
        """Turn each free DOF of joint ``j``, the last Euler factor first, to bring ``point``
        (moving with the joint) towards ``goal``, clamped; returns where ``point`` went."""
        m = parent_frame[:3, :3].tolist()
        pf = parent_frame[:3, :3] @ self.offsets[j] + parent_frame[:3, 3]
        pivot: Vec = (float(pf[0]), float(pf[1]), float(pf[2]))
        order = self.orders[j]
        v = self.v
        lo, hi = self.lo, self.hi
        for a in sorted(self.free.get(j, []), key=lambda ax: order.index(AXES[ax]), reverse=True):
            axis = self._axis(j, a, m)
            turn = _hinge_turn(axis, pivot, point, goal)
            if turn == 0.0:
                continue
            old = float(v[j, a])
            new = min(max(old + turn, float(lo[j, a])), float(hi[j, a]))
            if new != old:
                v[j, a] = new
                point = _rotate_point(axis, new - old, pivot, point)
        return point

    def set_rotation(self, j: int, rotation: FloatArray) -> None:
        """Write a local rotation into joint ``j``'s free DOFs: Euler angles in its order,
        the equivalent triple nearest the current values, each clamped to its limits."""
        angles = _nearest_euler(rotation, self.orders[j], self.v[j].tolist())
        for a in self.free.get(j, []):
            self.v[j, a] = min(max(float(angles[a]), self.lo[j, a]), self.hi[j, a])

    def turn_world(self, j: int, parent_frame: FloatArray, world_rotation: FloatArray) -> None:
        """Turn joint ``j`` (its whole subtree) by ``world_rotation`` about its pivot."""
        m = parent_frame[:3, :3]
        gram = m.T @ m
        scale2 = float(gram[0, 0])
        if abs(gram - scale2 * np.eye(3)).max() <= 1e-12 * max(scale2, 1e-300):   # a turn and a uniform scale
            local: FloatArray = m.T @ world_rotation @ m / scale2   # the same turn in the joint's parent frame
        else:
            local = np.asarray(np.linalg.solve(m, world_rotation @ m), dtype=np.float64)
        self.set_rotation(j, local @ self.rotation(j))

    def ccd_sweep(self) -> None:
        """One CCD sweep from the end up (see the module docstring)."""
        frames = self.frames()
        e = frames[-1][:3, 3]
        end: Vec = (float(e[0]), float(e[1]), float(e[2]))
        goal: Vec = (float(self.goal[0]), float(self.goal[1]), float(self.goal[2]))
        parents = [self.base, *frames[:-1]]
        for k in range(len(self.path) - 2, -1, -1):
            if self.free.get(self.path[k]):
                end = self._hinge_pass(self.path[k], parents[k], end, goal)

    def aim_child(self, k: int, parent_frame: FloatArray, frame: FloatArray, goal: FloatArray) -> None:
        """Turn the path's joint ``k`` so that its child on the path points at ``goal``."""
        j = self.path[k]
        axes = self.free.get(j)
        if not axes:
            return
        child = self.path[k + 1]
        p = frame[:3, 3]
        now = frame[:3, :3] @ self.offsets[child] + p
        if len(axes) == 3:
            self.turn_world(j, parent_frame, _shortest_arc(now - p, goal - p))
            return
        point: Vec = (float(now[0]), float(now[1]), float(now[2]))
        target: Vec = (float(goal[0]), float(goal[1]), float(goal[2]))
        for _ in range(2):
            point = self._hinge_pass(j, parent_frame, point, target)

    def extrapolate(self, before: FloatArray, err: float) -> float:
        """A pattern move along the change since ``before`` while it lowers the error."""
        after = self.v.copy()
        step = after - before
        if not np.any(step):
            return err
        moving = step != 0.0
        best_v, best_err = after, err
        factor = 1.0
        for _ in range(8):
            factor *= 2.0
            self.v = np.where(moving, np.clip(before + factor * step, self.lo, self.hi), after)
            e = self.error(self.end_position())
            if e >= best_err:
                break
            best_v, best_err = self.v.copy(), e
        self.v = best_v
        return best_err

    def result(self, iterations: int, error: float | None = None) -> IKResult:
        p = self.end_position()
        values = {(j, a): float(self.v[j, a]) for j, a in self.dofs}
        return IKResult(values, p, self.error(p) if error is None else error, iterations, list(self.dofs))


def _finite(target: npt.ArrayLike) -> bool:
    return bool(np.all(np.isfinite(np.asarray(target, dtype=np.float64))))


def _unchanged(skeleton: Skeleton, end: int, dofs: Sequence[DofRef] | None, chain_length: int,
               values: npt.ArrayLike | None, offset: npt.ArrayLike | None = None) -> IKResult:
    """The result for a target that is not a point (NaN or infinite): nothing moves."""
    return _PathChain(skeleton, end, np.zeros(3), dofs, chain_length, values, offset).result(0, math.nan)


def _ccd_loop(chain: _PathChain, iterations: int, tolerance: float, accelerate: bool, done: int = 0) -> IKResult:
    err = chain.error(chain.end_position())
    it = done
    stalled = StallCheck(err, tolerance)
    while err > tolerance and it < iterations and chain.free:
        it += 1
        before = chain.v.copy()
        chain.ccd_sweep()
        new_err = chain.error(chain.end_position())
        if accelerate and new_err > tolerance:
            new_err = chain.extrapolate(before, new_err)
        err = new_err
        if stalled(err):
            break
    return chain.result(it)


def solve_ccd(skeleton: Skeleton, end: int, target: npt.ArrayLike, dofs: Sequence[DofRef] | None = None,
              chain_length: int = 3, iterations: int = 100, tolerance: float = 1e-5,
              values: npt.ArrayLike | None = None, accelerate: bool = True,
              offset: npt.ArrayLike | None = None) -> IKResult:
    """Move joint ``end`` towards ``target`` by CCD over the hinge DOFs (at most
    ``iterations`` sweeps), within the DOF limits. Arguments as
    :func:`qtanimator.core.ik3d.solve_ik` (``offset``: the effector in the end's frame)."""
    if not _finite(target):
        return _unchanged(skeleton, end, dofs, chain_length, values, offset)
    chain = _PathChain(skeleton, end, target, dofs, chain_length, values, offset)
    return _ccd_loop(chain, iterations, tolerance, accelerate)


def solve_fabrik(skeleton: Skeleton, end: int, target: npt.ArrayLike, dofs: Sequence[DofRef] | None = None,
                 chain_length: int = 3, iterations: int = 100, tolerance: float = 1e-5,
                 values: npt.ArrayLike | None = None, accelerate: bool = True,
                 offset: npt.ArrayLike | None = None) -> IKResult:
    """Move joint ``end`` (or the point ``offset`` in its frame) towards ``target`` by
    FABRIK on the path's positions (at most ``iterations`` backward + forward passes), the
    positions converted back to DOF values within their limits after every pass (then a
    pattern move in DOF space, as CCD's); the best pass is returned."""
    if not _finite(target):
        return _unchanged(skeleton, end, dofs, chain_length, values, offset)
    chain = _PathChain(skeleton, end, target, dofs, chain_length, values, offset)
    if not chain.free:
        return chain.result(0)
    frames = chain.frames()
    x = [f[:3, 3].copy() for f in frames]
    m = len(x) - 1
    length = [float(np.linalg.norm(x[k + 1] - x[k])) for k in range(m)]
    tiny = 1e-12 * max(sum(length), 1e-300)
    err = chain.error(x[-1])
    best_v, best_err = chain.v.copy(), err
    it = 0
    stalled = StallCheck(err, tolerance)
    while err > tolerance and it < iterations:
        it += 1
        before = chain.v.copy()
        back = [p.copy() for p in x]
        back[m] = chain.goal.copy()
        for k in range(m - 1, 0, -1):
            d = back[k] - back[k + 1]
            n = float(np.linalg.norm(d))
            if n <= tiny:
                d = x[k] - x[k + 1]
                n = float(np.linalg.norm(d))
            back[k] = back[k + 1] + (length[k] * d / n if n > tiny else 0.0)
        # forward, in rotations: each joint aims its child at the backward position
        parent = chain.base
        x = []
        for k in range(m):
            j = chain.path[k]
            frame = parent @ chain.local(j)
            if chain.free.get(j):
                chain.aim_child(k, parent, frame, back[k + 1])
                frame = parent @ chain.local(j)
            x.append(frame[:3, 3].copy())
            parent = frame
        x.append(parent[:3, :3] @ chain.offsets[chain.path[m]] + parent[:3, 3])
        new_err = chain.error(x[-1])
        if accelerate and new_err > tolerance:
            moved_err = chain.extrapolate(before, new_err)
            if moved_err < new_err:
                new_err = moved_err
                x = [f[:3, 3].copy() for f in chain.frames()]
        if new_err < best_err:
            best_v, best_err = chain.v.copy(), new_err
        err = new_err
        if stalled(err):
            break
    chain.v = best_v
    return chain.result(it)


def two_bone_joints(skeleton: Skeleton, end: int, dofs: Sequence[DofRef],
                    tip: bool = False) -> tuple[int, int] | None:
    """``(first, middle)`` when ``dofs`` belong to exactly the end's grandparent and parent
    (the two-bone case), else None. With ``tip`` (an effector offset in the end's frame)
    the end itself is the middle joint and its parent the first."""
    middle = end if tip else skeleton.joints[end].parent
    first = None if middle is None else skeleton.joints[middle].parent
    if middle is None or first is None:
        return None
    return (first, middle) if {j for j, _a in dofs} == {first, middle} else None


def solve_two_bone(skeleton: Skeleton, end: int, target: npt.ArrayLike, dofs: Sequence[DofRef] | None = None,
                   pole: npt.ArrayLike | None = None, tolerance: float = 1e-5, iterations: int = 100,
                   values: npt.ArrayLike | None = None, offset: npt.ArrayLike | None = None) -> IKResult:
    """The analytic two-bone solution (see the module docstring). ``dofs`` default to the
    free DOFs of the end's parent and grandparent; ValueError when they are not exactly
    those joints' (:func:`two_bone_joints`). With ``offset`` (the effector in the end's
    frame) the end and its parent are the two joints. ``pole`` is a world point on the side the
    middle joint should bend to (default: the side it bends to now). When limits or
    missing DOFs keep the analytic pose from the target, at most ``iterations`` CCD sweeps
    follow. A zero-length bone leaves it all to CCD."""
    tip = offset is not None
    if dofs is not None:
        dof_list = list(dofs)
    elif tip:
        parent = skeleton.joints[end].parent
        dof_list = [(j, a) for j in (end, parent) if j is not None
                    for a, d in enumerate(skeleton.joints[j].dofs) if d.max - d.min > 1e-12]
    else:
        dof_list = list(chain_dofs(skeleton, end, 2))
    pair = two_bone_joints(skeleton, end, dof_list, tip)
    if pair is None:
        raise ValueError("the two-bone solver needs DOFs of exactly the end's parent and grandparent")
    first, middle = pair
    if not _finite(target):
        return _unchanged(skeleton, end, dof_list, 2, values, offset)
    chain = _PathChain(skeleton, end, target, dof_list, 2, values, offset)
    frames = chain.frames()
    start, start_error = chain.v.copy(), chain.error(frames[-1][:3, 3])
    base = [chain.base, *frames[:-1]]   # each path joint's parent world matrix
    a, b, c = (f[:3, 3].copy() for f in frames)
    l1, l2 = float(np.linalg.norm(b - a)), float(np.linalg.norm(c - b))
    if min(l1, l2) <= 1e-12 * max(l1 + l2, 1e-300):
        return _ccd_loop(chain, iterations, tolerance, True)
    goal = chain.goal
    pole_point = None if pole is None else np.asarray(pole, dtype=np.float64).reshape(3)
    distance = min(max(float(np.linalg.norm(goal - a)), abs(l1 - l2)), l1 + l2)

    # 1. the middle joint bends until the end is ``distance`` from the first pivot
    middle_parent = base[1].copy()
    middle_parent[:3, 3] = base[1][:3, :3] @ chain.offsets[middle] + base[1][:3, 3]
    free_mid = chain.free.get(middle, [])
    hinges = [chain.axis(middle, ax, middle_parent) for ax in free_mid]
    normal = _unit(np.cross(b - a, c - b))
    if normal is None and pole_point is not None:
        normal = _unit(np.cross(b - a, pole_point - a))
    if normal is None:   # in line: bend about the hinge most across the bone
        normal = min(hinges, key=lambda h: abs(float(h @ (b - a))) / l1) if hinges else None
    if normal is not None and hinges:
        hinge_index = max(range(len(hinges)), key=lambda i: abs(float(hinges[i] @ normal)))
        hinge = normal if len(free_mid) == 3 else hinges[hinge_index]
        w = c - b
        along = float(w @ hinge) * hinge
        across = w - along
        r = b - a + along
        k0 = float(r @ r + across @ across)
        ka, kb = 2.0 * float(r @ across), 2.0 * float(r @ np.cross(hinge, w))
        amplitude = math.hypot(ka, kb)
        if amplitude > 1e-300:
            phase = math.atan2(kb, ka)
            spread = math.acos(min(max((distance * distance - k0) / amplitude, -1.0), 1.0))
            turn = min((phase + spread, phase - spread), key=lambda t: abs(math.remainder(t, 2 * math.pi)))
            turn = math.remainder(turn, 2 * math.pi)
            if len(free_mid) == 3:
                chain.turn_world(middle, base[1], _rotation_about(hinge, turn))
            else:
                ax = free_mid[hinge_index]
                chain.v[middle, ax] = min(max(chain.v[middle, ax] + turn, chain.lo[middle, ax]), chain.hi[middle, ax])

    # 2. the first joint turns the triangle onto the target, the knee on the pole's side
    frames = chain.frames()
    c1 = frames[-1][:3, 3]
    u, target_dir = _unit(c1 - a), _unit(goal - a)
    if u is not None:
        if target_dir is None:
            target_dir = u
        knee = b - a
        side = knee if pole_point is None else pole_point - a
        k_perp, p_perp = _unit(_perpendicular_part(knee, u)), _unit(_perpendicular_part(side, target_dir))
        if k_perp is None or p_perp is None:
            swing = _shortest_arc(u, target_dir)
        else:
            before = np.column_stack([u, k_perp, np.cross(u, k_perp)])
            after = np.column_stack([target_dir, p_perp, np.cross(target_dir, p_perp)])
            swing = after @ before.T
        if len(chain.free.get(first, [])) == 3:
            chain.turn_world(first, base[0], swing)
        else:
            chain.aim_child(0, base[0], base[0] @ chain.local(first), a + swing @ (b - a))
    err = chain.error(chain.end_position())
    if err <= tolerance:
        return chain.result(1)
    if err > start_error:   # limits spoilt the analytic pose: CCD from the start instead
        chain.v = start
    return _ccd_loop(chain, iterations + 1, tolerance, True, done=1)


__all__ = ["solve_ccd", "solve_fabrik", "solve_two_bone", "two_bone_joints"]
