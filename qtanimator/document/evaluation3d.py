"""Evaluating 3D characters: the posed skeleton, its world matrices and skinned mesh at a time.

A DOF with no channel keeps the value the file gave it. Channel values are clamped to the
DOF limits when the skeleton is posed; a pending, unkeyed pose at the time is shown (see
:mod:`qtanimator.document.pose`). The authored placement goes on top of the file's.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from qtanimator.core.quaternion_channels import quaternion_at
from qtanimator.core.rotation import euler_to_quaternions, quaternions_to_euler, same_hemisphere
from qtanimator.core.skeleton import Skeleton
from qtanimator.core.skinning import skin_positions, skin_positions_and_normals, vertex_normals
from qtanimator.document.character3d_model import (
    JOINT_DOFS,
    QUAT_DOFS,
    ROOT_DOFS,
    SCALE_DOFS,
    TRANSLATE_DOFS,
    character,
)
from qtanimator.document.document import Document, channel_id
from qtanimator.document.pending_pose import pending_values
from qtanimator.document.placement import PLACEMENT, matrix3d

FloatArray = npt.NDArray[np.float64]


def authored_placement(doc: Document, asset_id: str) -> FloatArray | None:
    """The 4×4 authored placement of the character (asset property ``placement``,
    :mod:`qtanimator.document.placement`), None when it has none."""
    asset = doc.assets.get(asset_id)
    value = asset.properties.get(PLACEMENT) if asset is not None else None
    return None if value is None else matrix3d(value)


def pose_skeleton(doc: Document, asset_id: str, time: float) -> Skeleton:
    """A posed copy of the character's skeleton at ``time`` (channel values clamped; a
    pending, unkeyed pose at ``time`` is shown: see :mod:`qtanimator.document.pose`).

    A joint keyed as a quaternion is interpolated as one
    (:func:`~qtanimator.core.quaternion_channels.quaternions_at`) and posed with the
    equivalent Euler angles."""
    ch = character(doc, asset_id)
    skel = ch.skeleton.copy()
    placed = authored_placement(doc, asset_id)
    if placed is not None:  # the authored placement goes on top of the file's (issue 14)
        skel.placement = placed if skel.placement is None else placed @ skel.placement
    t = float(time)
    held = pending_values(doc, t)  # an unkeyed pose shown at this time (document.pose)
    channels = doc.channels

    def value(cid: str) -> float | None:
        v = held.get(cid) if held else None
        if v is None:
            channel = channels.get(cid)
            if channel is None or not channel.keys:
                return None
            v = channel.evaluate(t)
        return float(v)

    for a, dof in enumerate(ROOT_DOFS):
        v = value(channel_id(asset_id, "", dof))
        if v is not None:
            skel.root_translation[a] = v
    quat_joints: list[int] = []
    quats: list[FloatArray] = []
    for j, (key, joint) in enumerate(zip(skel.joint_keys(), skel.joints)):
        prefix = f"{asset_id}/{key}/"
        if joint.quaternion:
            cids = [prefix + d for d in QUAT_DOFS]
            pending = [held.get(c) for c in cids] if held else [None] * 4
            chans = [channels.get(c) for c in cids]
            if any(p is not None for p in pending):
                rest = ch.rest_quaternions()[j]
                comps = [p if p is not None else (c.evaluate(t) if c is not None and c.keys else rest[slot])
                         for p, c, slot in zip(pending, chans, (3, 0, 1, 2))]
                q = np.array([comps[1], comps[2], comps[3], comps[0]], dtype=np.float64)
                quat_joints.append(j)
                quats.append(q / (np.linalg.norm(q) or 1.0))
            elif any(c is not None and c.keys for c in chans):
                quat_joints.append(j)
                quats.append(quaternion_at(chans, ch.rest_quaternions()[j], t))
        else:
            for a, dof in enumerate(JOINT_DOFS):
                v = value(prefix + dof)
                if v is not None:
                    joint.dofs[a].value = v
        if joint.translates:
            for a, dof in enumerate(TRANSLATE_DOFS):
                v = value(prefix + dof)
                if v is not None:
                    joint.translation[a] = v
        if joint.scales:
            for a, dof in enumerate(SCALE_DOFS):
                v = value(prefix + dof)
                if v is not None:
                    joint.scale[a] = v
    if quat_joints:
        q_all = np.array(quats)
        orders = [skel.joints[j].rotation_order or skel.rotation_order for j in quat_joints]
        for order in set(orders):
            sel = [k for k, o in enumerate(orders) if o == order]
            euler = quaternions_to_euler(q_all[sel], order)
            for k, e in zip(sel, euler):
                for a in range(3):
                    skel.joints[quat_joints[k]].dofs[a].value = float(e[a])
    return skel


def pose_channel_values(doc: Document, asset_id: str, time: float) -> dict[str, float]:
    """Every channel of :func:`all_channel_ids` with the value the pose shown at ``time``
    gives it (what "key the whole character" keys)."""
    skel = pose_skeleton(doc, asset_id, time)
    out = {channel_id(asset_id, "", d): float(v) for d, v in zip(ROOT_DOFS, skel.root_translation)}
    for j, (key, joint) in enumerate(zip(skel.joint_keys(), skel.joints)):
        prefix = f"{asset_id}/{key}/"
        if joint.quaternion:
            q = euler_to_quaternions(joint.pose, joint.rotation_order or skel.rotation_order)[0]
            q = same_hemisphere(q, shown_quaternion(doc, asset_id, j, time))
            out.update({prefix + d: float(q[slot]) for d, slot in zip(QUAT_DOFS, (3, 0, 1, 2))})
        else:
            out.update({prefix + d: float(v) for d, v in zip(JOINT_DOFS, joint.pose)})
        if joint.translates:
            out.update({prefix + d: float(v) for d, v in zip(TRANSLATE_DOFS, joint.translation)})
        if joint.scales:
            out.update({prefix + d: float(v) for d, v in zip(SCALE_DOFS, joint.scale)})
    return out


def world_matrices(doc: Document, asset_id: str, time: float) -> FloatArray:
    """(J, 4, 4) joint-to-world matrices at ``time``."""
    return pose_skeleton(doc, asset_id, time).world_matrices()


def skinned_mesh(doc: Document, asset_id: str, time: float) -> tuple[FloatArray, FloatArray]:
    """(V, 3) positions and unit normals of the skinned mesh at ``time``.

    Skins with normals transform them; meshes without (MIT) get smooth normals of the
    skinned surface (the renderer may draw them faceted instead).
    """
    ch = character(doc, asset_id)
    if ch.skin is None:
        raise ValueError(f"3D character {asset_id!r} has no skin or mesh")
    w = ch.skinning_world(world_matrices(doc, asset_id, time))
    if ch.skin.normals is not None:
        return skin_positions_and_normals(ch.skin, w)
    positions = skin_positions(ch.skin, w)
    return positions, vertex_normals(positions, ch.skin.triangles)


def bounds(doc: Document, asset_id: str, time: float) -> tuple[FloatArray, FloatArray]:
    """(lo, hi) world-space box of the character at ``time``: its joints and its skinned mesh."""
    world = world_matrices(doc, asset_id, time)
    points = [world[:, :3, 3]]
    ch = character(doc, asset_id)
    if ch.skin is not None:
        points.append(skinned_mesh(doc, asset_id, time)[0])
    pts = np.concatenate(points, axis=0)
    return pts.min(axis=0), pts.max(axis=0)


def shown_quaternion(doc: Document, asset_id: str, joint: int, time: float | None) -> FloatArray:
    """The quaternion components a joint's channels hold at ``time`` (not normalised, sign
    as keyed); the rest rotation where there are none."""
    ch = character(doc, asset_id)
    rest = ch.rest_quaternions()[joint]
    if time is None:
        return rest
    key = ch.joint_keys[joint]
    out = rest.copy()
    for slot, name in zip((3, 0, 1, 2), QUAT_DOFS):
        c = doc.channels.get(channel_id(asset_id, key, name))
        if c is not None and c.keys:
            out[slot] = c.evaluate(float(time))
    return out

