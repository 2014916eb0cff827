"""Inverse kinematics for 3D skeletons: damped least squares over rotational DOFs.

Qt-free and numpy only. The solver moves one joint (the *end*) of a
:class:`~qtanimator.core.skeleton.Skeleton` towards a target point by changing the rotation
DOFs of a chain of its ancestors, keeping every DOF inside its limits:

* the Jacobian is analytic: the DOF ``a`` of joint ``j`` turns about the world axis
  ``F_j·R_1⋯R_{k-1}·e_a`` (``F_j`` = parent world · T(offset), the factors in the joint's
  rotation order), so its column is ``axis × (p_end − p_j)``;
* each iteration takes the damped least-squares step
  ``Δq = Jᵀ(JJᵀ + λ²I)⁻¹e`` (Wampler; Buss 2004), with λ scaled to the chain's reach so the
  solver behaves the same on the wasp and on the MIT models;
* limits use an active set: a DOF at a limit whose step pushes past it is locked and the
  step solved again without it, so the others make up for it (no chattering against the
  limit), and every value is clamped.

The skeleton itself is left untouched: the result is a set of new DOF values that the
caller writes through a command (one undo step, keyed at the current frame).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from qtanimator.core.skeleton import AXES, Skeleton, axis_rotations

FloatArray = npt.NDArray[np.float64]
DofRef = tuple[int, int]   # (joint index, axis 0/1/2)


@dataclass
class IKResult:
    """New values of the chain's DOFs and how close the end got."""

    values: dict[DofRef, float]
    position: FloatArray
    error: float
    iterations: int
    dofs: list[DofRef] = field(default_factory=list)

    def by_axis_name(self) -> dict[tuple[int, str], float]:
        """The values keyed by ``(joint index, "x" | "y" | "z")``."""
        return {(j, AXES[a]): v for (j, a), v in self.values.items()}


def chain_joints(skeleton: Skeleton, end: int, chain_length: int = 3, include_root: bool = False) -> list[int]:
    """The ancestors of ``end`` that the solver may rotate, nearest first.

    The end's own rotation does not move its position, so the chain starts at its parent.
    The root joint is left out unless ``include_root`` (it turns the whole character).
    """
    out: list[int] = []
    j = skeleton.joints[end].parent
    while j is not None and len(out) < chain_length:
        if skeleton.joints[j].parent is None and not include_root:
            break
        out.append(j)
        j = skeleton.joints[j].parent
    return out


def chain_dofs(skeleton: Skeleton, end: int, chain_length: int = 3, include_root: bool = False) -> list[DofRef]:
    """The free DOFs (limits not pinned to one value) of :func:`chain_joints`."""
    dofs: list[DofRef] = []
    for j in chain_joints(skeleton, end, chain_length, include_root):
        for a, d in enumerate(skeleton.joints[j].dofs):
            if d.max - d.min > 1e-12:
                dofs.append((j, a))
    return dofs


def end_position(skeleton: Skeleton, values: npt.ArrayLike, end: int) -> FloatArray:
    w = skeleton.world_matrices(values)
    return np.asarray(w[end, :3, 3], dtype=np.float64).copy()


def effector(world: FloatArray, end: int, offset: npt.ArrayLike | None = None) -> FloatArray:
    """The end effector ``W_end · offset`` (the end's origin when ``offset`` is None)."""
    if offset is None:
        return np.asarray(world[end, :3, 3], dtype=np.float64).copy()
    return np.asarray(world[end, :3, :3] @ np.asarray(offset, dtype=np.float64).reshape(3) + world[end, :3, 3],
                      dtype=np.float64)


def jacobian(skeleton: Skeleton, values: npt.ArrayLike, dofs: Sequence[DofRef],
             end: int, offset: npt.ArrayLike | None = None) -> tuple[FloatArray, FloatArray]:
    """``(p_end (3,), J (3, len(dofs)))`` for the DOF values ``values`` (J, 3); ``p_end``
    is :func:`effector` (the end's own DOFs may be in ``dofs`` when ``offset`` is given)."""
    v = np.asarray(values, dtype=np.float64).reshape(len(skeleton.joints), 3)
    world = skeleton.world_matrices(v)
    p_end = effector(world, end, offset)
    jac = np.zeros((3, len(dofs)))
    root = np.eye(4) if skeleton.placement is None else skeleton.placement.copy()
    root[:3, 3] += root[:3, :3] @ skeleton.root_translation
    frames: dict[int, FloatArray] = {}
    for col, (j, a) in enumerate(dofs):
        joint = skeleton.joints[j]
        if j not in frames:
            parent = root if joint.parent is None else world[joint.parent]
            f = parent.copy()
            f[:3, 3] = parent[:3, :3] @ (joint.offset + joint.translation) + parent[:3, 3]
            frames[j] = f
        f = frames[j]
        order = joint.rotation_order or skeleton.rotation_order
        k = order.index(AXES[a])
        pre = np.eye(3)
        for letter in order[:k]:
            i = AXES.index(letter)
            pre = pre @ axis_rotations(i, v[j, i])[0]
        axis = f[:3, :3] @ pre[:, a]
        axis /= np.linalg.norm(axis) or 1.0  # a scaled parent (glTF) turns the joint about a unit axis
        jac[:, col] = np.cross(axis, p_end - f[:3, 3])
    return p_end, jac


def solve_ik(skeleton: Skeleton, end: int, target: npt.ArrayLike, dofs: Sequence[DofRef] | None = None,
             chain_length: int = 3, damping: float = 0.05, iterations: int = 40, tolerance: float = 1e-5,
             max_step: float = 0.25, values: npt.ArrayLike | None = None,
             offset: npt.ArrayLike | None = None) -> IKResult:
    """Move joint ``end`` towards ``target`` by damped least squares within the DOF limits.

    ``offset`` (3,) is a point in the end joint's frame to move instead of its origin (the
    effector ``W_end · offset``: a clicked point of the skin); then the end's own DOFs may
    be in ``dofs``. ``dofs`` defaults to :func:`chain_dofs` (``chain_length`` ancestors). ``values`` (J, 3)
    starts from other DOF values than the skeleton's. ``max_step`` caps the largest
    per-iteration angle change (radians).
    """
    goal = np.asarray(target, dtype=np.float64).reshape(3)
    q_all = skeleton.dof_values() if values is None else np.array(values, dtype=np.float64).reshape(-1, 3)
    dof_list = list(chain_dofs(skeleton, end, chain_length) if dofs is None else dofs)
    lo_all, hi_all = skeleton.dof_limits()
    lo = np.array([lo_all[j, a] for j, a in dof_list])
    hi = np.array([hi_all[j, a] for j, a in dof_list])
    q = np.clip(np.array([q_all[j, a] for j, a in dof_list]), lo, hi)

    def write(qv: FloatArray) -> FloatArray:
        out = q_all.copy()
        for (j, a), x in zip(dof_list, qv):
            out[j, a] = x
        return out

    world0 = skeleton.world_matrices(q_all)
    positions, tip = world0[:, :3, 3], effector(world0, end, offset)
    reach = max([float(np.linalg.norm(tip - positions[j])) for j, _a in dof_list] + [1e-6])
    lam2 = (damping * reach) ** 2

    p, jac = jacobian(skeleton, write(q), dof_list, end, offset)
    err = float(np.linalg.norm(goal - p))
    it = 0
    for it in range(1, iterations + 1):
        if err <= tolerance or not dof_list:  # reached at the tolerance, as every other solver
            it -= 1
            break
        e = goal - p
        locked = np.zeros(len(q), dtype=bool)
        for _ in range(4):
            jl = jac * ~locked
            dq = jl.T @ np.linalg.solve(jl @ jl.T + lam2 * np.eye(3), e)
            push_low = (q <= lo + 1e-12) & (dq < 0)
            push_high = (q >= hi - 1e-12) & (dq > 0)
            newly = (push_low | push_high) & ~locked
            if not newly.any():
                break
            locked |= newly
        dq[locked] = 0.0
        biggest = float(np.max(np.abs(dq))) if len(dq) else 0.0
        if biggest > max_step:
            dq *= max_step / biggest
        q_new = np.clip(q + dq, lo, hi)
        p_new, jac_new = jacobian(skeleton, write(q_new), dof_list, end, offset)
        err_new = float(np.linalg.norm(goal - p_new))
        if err_new > err and biggest < 1e-9:
            break
        if err_new > err:
            # overshoot: halve the step once and accept whatever is better
            q_half = np.clip(q + dq / 2, lo, hi)
            p_half, jac_half = jacobian(skeleton, write(q_half), dof_list, end, offset)
            err_half = float(np.linalg.norm(goal - p_half))
            if err_half >= err:
                break
            q_new, p_new, jac_new, err_new = q_half, p_half, jac_half, err_half
        q, p, jac, err = q_new, p_new, jac_new, err_new
    return IKResult({d: float(x) for d, x in zip(dof_list, q)}, p, err, it, dof_list)
