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
from qtanimator.core.ik3d_chain import (
    PathChain,
    perpendicular_part,
    rotation_about,
    shortest_arc,
    unit,
)
from qtanimator.core.ik_methods import StallCheck
from qtanimator.core.skeleton import Skeleton


def _finite(target: npt.ArrayLike) -> bool:
    return bool(np.all(np.isfinite(np.asarray(target, dtype=np.float64))))


def _unchanged(skeleton: Skeleton, end: int, dofs: Sequence[DofRef] | None, chain_length: int,
               values: npt.ArrayLike | None, offset: npt.ArrayLike | None = None) -> IKResult:
    """The result for a target that is not a point (NaN or infinite): nothing moves."""
    return PathChain(skeleton, end, np.zeros(3), dofs, chain_length, values, offset).result(0, math.nan)


def _ccd_loop(chain: PathChain, iterations: int, tolerance: float, accelerate: bool, done: int = 0) -> IKResult:
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
    chain = PathChain(skeleton, end, target, dofs, chain_length, values, offset)
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
    chain = PathChain(skeleton, end, target, dofs, chain_length, values, offset)
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
    chain = PathChain(skeleton, end, target, dof_list, 2, values, offset)
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
    normal = unit(np.cross(b - a, c - b))
    if normal is None and pole_point is not None:
        normal = unit(np.cross(b - a, pole_point - a))
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
                chain.turn_world(middle, base[1], rotation_about(hinge, turn))
            else:
                ax = free_mid[hinge_index]
                chain.v[middle, ax] = min(max(chain.v[middle, ax] + turn, chain.lo[middle, ax]), chain.hi[middle, ax])

    # 2. the first joint turns the triangle onto the target, the knee on the pole's side
    frames = chain.frames()
    c1 = frames[-1][:3, 3]
    u, target_dir = unit(c1 - a), unit(goal - a)
    if u is not None:
        if target_dir is None:
            target_dir = u
        knee = b - a
        side = knee if pole_point is None else pole_point - a
        k_perp, p_perp = unit(perpendicular_part(knee, u)), unit(perpendicular_part(side, target_dir))
        if k_perp is None or p_perp is None:
            swing = shortest_arc(u, target_dir)
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
