"""The joint chain the 3D CCD and FABRIK solvers (:mod:`qtanimator.core.ik3d_methods`) work on: the
DOFs from the root to the end joint, their axes and pivots in world space, turning one DOF
about its axis or a whole joint along the shortest arc, and writing the turns back as Euler
angles nearest the previous ones.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from qtanimator.core.ik3d import DofRef, IKResult, chain_dofs
from qtanimator.core.rotation import AXES
from qtanimator.core.skeleton import Skeleton

FloatArray = npt.NDArray[np.float64]

_TWO_PI = 2.0 * math.pi

def rotation_about(axis: FloatArray, angle: float) -> FloatArray:
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

def unit(v: FloatArray) -> FloatArray | None:
    n = float(np.linalg.norm(v))
    if not math.isfinite(n) or n <= 1e-300:
        return None
    return v / n

def shortest_arc(u: FloatArray, v: FloatArray) -> FloatArray:
    """The smallest rotation taking the direction of ``u`` onto that of ``v`` (identity
    when either is zero; a half turn about some perpendicular when they are opposite)."""
    a, b = unit(u), unit(v)
    if a is None or b is None:
        return np.eye(3)
    axis = np.cross(a, b)
    s = float(np.linalg.norm(axis))
    c = float(a @ b)
    if s < 1e-12:
        if c > 0:
            return np.eye(3)
        perp = np.cross(a, np.eye(3)[int(np.argmin(np.abs(a)))])
        return rotation_about(perp / np.linalg.norm(perp), math.pi)
    return rotation_about(axis / s, math.atan2(s, c))

def perpendicular_part(v: FloatArray, unit: FloatArray) -> FloatArray:
    return np.asarray(v - float(v @ unit) * unit, dtype=np.float64)

class PathChain:
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
            self.turn_world(j, parent_frame, shortest_arc(now - p, goal - p))
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
