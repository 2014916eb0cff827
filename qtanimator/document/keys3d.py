"""Key edits of 3D characters: keying DOFs (Euler, quaternion, translation, scale) and IK.
"""

from __future__ import annotations

from collections.abc import Hashable, Mapping

import numpy as np
import numpy.typing as npt

from qtanimator.core.channel import Interpolation, Key, Tangent
from qtanimator.core.rotation import euler_to_quaternions, same_hemisphere
from qtanimator.document.channels3d import dof_kind
from qtanimator.document.character3d_model import (
    JOINT_DOFS,
    QUAT_DOFS,
    ROOT_DOFS,
    SCALE_DOFS,
    TRANSLATE_DOFS,
    character,
)
from qtanimator.document.commands import Command, SetKeys
from qtanimator.document.document import Document, channel_id
from qtanimator.document.evaluation3d import pose_skeleton, shown_quaternion
from qtanimator.document.ik_settings import solve_skeleton


def set_dof_command(doc: Document, asset_id: str, joint_index: int | None, axis: str | int, value: float,
                    time: float, gesture: Hashable | None = None) -> Command:
    """Key one DOF at ``time`` (value clamped to the DOF's limits)."""
    return set_dofs_command(doc, asset_id, {(joint_index, axis): value}, time, gesture)


def dof_values(doc: Document, asset_id: str, values: Mapping[tuple[int | None, str | int], float],
               time: float | None = None) -> dict[str, float]:
    """Channel values for DOF values: what a key or an unkeyed pose of those DOFs holds.

    ``values`` maps ``(joint, axis)`` to a value (see
    :func:`~qtanimator.document.channels3d.dof_kind`): rotations in radians (Euler, clamped
    to the DOF's limits), translations and scales as they are. A
    joint keyed as a quaternion gets all four components: its Euler angles are the given
    ones over the pose shown at ``time`` (the rest pose when None), and the quaternion is
    kept on the side of the one shown (so cubic spans do not flip)."""
    ch = character(doc, asset_id)
    skel = ch.skeleton
    keys = ch.joint_keys
    out: dict[str, float] = {}
    turned: dict[int, dict[int, float]] = {}
    for (joint, axis), v in values.items():
        kind, a = dof_kind(joint, axis)
        if kind == "root":
            out[channel_id(asset_id, "", ROOT_DOFS[a])] = float(v)
            continue
        assert joint is not None
        if not 0 <= joint < len(keys):
            raise IndexError(f"joint {joint} does not exist in {asset_id!r}")
        if kind == "translate":
            out[channel_id(asset_id, keys[joint], TRANSLATE_DOFS[a])] = float(v)
        elif kind == "scale":
            out[channel_id(asset_id, keys[joint], SCALE_DOFS[a])] = float(v)
        elif skel.joints[joint].quaternion:
            turned.setdefault(joint, {})[a] = float(v)
        else:
            out[channel_id(asset_id, keys[joint], JOINT_DOFS[a])] = skel.joints[joint].dofs[a].clamp(v)
    if turned:
        shown = skel if time is None else pose_skeleton(doc, asset_id, time)
        for joint, axes in turned.items():
            j = shown.joints[joint]
            euler = j.pose
            for a, v in axes.items():
                euler[a] = j.dofs[a].clamp(v)
            q = euler_to_quaternions(euler, j.rotation_order or shown.rotation_order)[0]
            ref = shown_quaternion(doc, asset_id, joint, time)
            q = same_hemisphere(q, ref)
            for slot, name in zip((3, 0, 1, 2), QUAT_DOFS):
                out[channel_id(asset_id, keys[joint], name)] = float(q[slot])
    return out


def new_key(cid: str, time: float, value: float) -> Key:
    """A new key; quaternion components are keyed linear (a slerp span, as glTF's LINEAR)."""
    if cid.rsplit("/", 1)[-1] in QUAT_DOFS:
        return Key(float(time), value, Tangent.LINEAR, Tangent.LINEAR, interpolation=Interpolation.LINEAR)
    return Key(float(time), value)


def set_dofs_command(doc: Document, asset_id: str, values: Mapping[tuple[int | None, str | int], float],
                     time: float, gesture: Hashable | None = None) -> Command:
    """Key several DOFs at ``time`` in one undo step; ``values`` maps (joint, axis) to a value."""
    keys = {cid: new_key(cid, time, v) for cid, v in dof_values(doc, asset_id, values, time).items()}
    text = "Set Joint" if len(values) == 1 else "Set Pose"
    return SetKeys(doc, keys, text=text, gesture=gesture)


def ik_values(doc: Document, asset_id: str, joint: int, target: npt.ArrayLike, time: float,
              dofs: list[tuple[int, int]], offset: npt.ArrayLike | None = None
              ) -> dict[tuple[int | None, str | int], float]:
    """Solve IK for ``joint`` towards ``target`` over ``dofs`` from the pose shown at
    ``time`` with the document's IK settings (:mod:`qtanimator.document.ik_settings`: the
    solver, two-bone for a two-joint chain): the new DOF values by (joint, axis). Both 3D
    IK paths (keying and posing without keys) get their values here. ``offset``: the
    point of ``joint``'s frame to move (a clicked skin point; None: its origin)."""
    skel = pose_skeleton(doc, asset_id, time)
    result = solve_skeleton(doc, skel, joint, np.asarray(target, dtype=np.float64), dofs, offset)
    return {(j, axis): v for (j, axis), v in result.by_axis_name().items()}

