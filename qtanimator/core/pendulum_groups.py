"""How a character's dynamic joints group into pendulums (:class:`PendulumGroup`: a chain of
dynamic joints through dynamic parents, with its masses, inertias and lever arms) and the
accelerations their pivots get from the root's translation and the ancestors' rotation
(:func:`pivot_accelerations`, :func:`rotation_pivot_terms`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from qtanimator.core.pendulum_params import FloatArray, PendulumParams
from qtanimator.core.rig2d import Character


def rotate(v: FloatArray, theta: FloatArray | float) -> FloatArray:
    """R(θ)·v, vectorised over leading axes (θ broadcast against v[..., 0])."""
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([c * v[..., 0] + s * v[..., 1], -s * v[..., 0] + c * v[..., 1]], axis=-1)

def perp(v: FloatArray) -> FloatArray:
    """J·v with J(x, y) = (y, −x), i.e. R(π/2)."""
    return np.stack([v[..., 1], -v[..., 0]], axis=-1)

@dataclass(eq=False)
class PendulumGroup:
    """Dynamic joints connected through dynamic parents, in pre-order (top first)."""

    joints: list[int]
    parent: npt.NDArray[np.intp]  # index into ``joints`` or -1
    mass: FloatArray
    inertia: FloatArray  # about each joint's own pivot
    offset: FloatArray  # (n, 2) y0: pivot -> centre of mass, rest pose, scaled
    ancestor: npt.NDArray[np.bool_]  # (n, n): i is k or an ancestor of k
    arm: FloatArray  # (n, n, 2) v_ik: i's pivot -> the point of i that carries k (rest, scaled)

    @property
    def top(self) -> int:
        return self.joints[0]

def _position(pos: dict[int, int], parent: int | None) -> int:
    return -1 if parent is None else pos.get(parent, -1)

def build_groups(character: Character, params: PendulumParams) -> list[PendulumGroup]:
    joints = character.joints
    dyn = [j.is_dynamic for j in joints]
    s = params.length_scale
    groups: list[PendulumGroup] = []
    for top, joint in enumerate(joints):
        if not dyn[top] or (joint.parent is not None and dyn[joint.parent] and params.coupled):
            continue
        members = [top]
        if params.coupled:
            stack = list(reversed(joint.children))
            while stack:
                k = stack.pop()
                if dyn[k]:
                    members.append(k)
                    stack.extend(reversed(joints[k].children))
        n = len(members)
        pos = {j: i for i, j in enumerate(members)}
        parent = np.array([_position(pos, joints[j].parent) for j in members], dtype=np.intp)
        if n:
            parent[0] = -1
        mp = [(joints[j].reference_mass_properties if params.inertia == "reference"
               else joints[j].mass_properties) for j in members]
        mass = np.array([p.mass if p else 0.0 for p in mp])
        offset = np.array([(p.centroid - p.pivot) * s if p else np.zeros(2) for p in mp]).reshape(n, 2)
        inertia = np.array([p.inertia if p else 0.0 for p in mp])
        if s != 1.0 and params.inertia == "exact":
            inertia = inertia * s * s
        ancestor = np.zeros((n, n), dtype=bool)
        arm = np.zeros((n, n, 2))
        for k in range(n):
            arm[k, k] = offset[k]
            ancestor[k, k] = True
            child, i = k, parent[k]
            while i >= 0:
                ancestor[i, k] = True
                arm[i, k] = (joints[members[child]].pivot - joints[members[i]].pivot) * s
                child, i = i, parent[i]
        groups.append(PendulumGroup(members, parent, mass, inertia, offset, ancestor, arm))
    return groups

def pivot_accelerations(character: Character, world_angles: FloatArray, world_rates: FloatArray,
                        world_accels: FloatArray, translation_acc: npt.ArrayLike,
                        accel_scale: float = 1.0, rotation_accel_scale: float = 1.0) -> FloatArray:
    """Acceleration (J, 2) of every joint's pivot from the root's translation and the
    rotation of its ancestors (world angle, rate and acceleration per joint).

    p_n = p_m + R(Θ_m)(c_n − c_m), so p_n'' = p_m'' + Θ_m''·R(Θ_m)·J·v − Θ_m'²·R(Θ_m)·v.
    """
    n = len(character.joints)
    acc = np.zeros((n, 2))
    acc[0] = np.asarray(translation_acc, dtype=np.float64) * accel_scale
    c = character.rest_pivots
    for k in range(1, n):
        m = int(character.parents[k])
        acc[k] = acc[m] + rotation_pivot_terms(world_angles[m:m + 1], world_rates[m:m + 1], world_accels[m:m + 1],
                                               (c[k] - c[m])[None, :], rotation_accel_scale)[0]
    return acc

def rotation_pivot_terms(angles: FloatArray, rates: FloatArray, accels: FloatArray, arms: FloatArray,
                         scale: float = 1.0) -> FloatArray:
    """The pivot acceleration an ancestor's rotation adds, for each (ancestor, rest arm v to
    the pivot): scale·(Θ''·J·R(Θ)·v − Θ'²·R(Θ)·v), the last two terms of
    p_n'' = p_m'' + Θ_m''·R(Θ_m)·J·v − Θ_m'²·R(Θ_m)·v (:func:`pivot_accelerations`; the
    document's simulation sums them over each pendulum's ancestors)."""
    rv = rotate(arms, angles)
    return np.asarray(scale * (accels[:, None] * perp(rv) - (rates ** 2)[:, None] * rv), dtype=np.float64)
