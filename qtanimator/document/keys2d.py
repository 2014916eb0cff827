"""Key edits of 2D characters: keying joints and positions, IK drags, deleting keys.

Keys use smooth tangents with constant extrapolation, which is the reference program's
Catmull-Rom spline. Per-joint keys by default; with the parameter ``animation.key_all``
true an edit sets the reference program's universal keyframe (every joint of every 2D
character and every position keyed at that time). Every edit that keys or poses a joint
clamps the value it writes to the joint's limits (:func:`clamp_values`).
"""

from __future__ import annotations

import math
from collections.abc import Hashable, Iterable

import numpy as np
import numpy.typing as npt

from qtanimator.core.channel import Key
from qtanimator.document.character2d_asset import (
    ASSET_KIND,
    angle_channel_id,
    character,
    character_assets,
    position_channel_ids,
)
from qtanimator.document.commands import Command, DeleteKeys, SetKeys
from qtanimator.document.document import Document, split_channel_id
from qtanimator.document.evaluation2d import (
    evaluate_pose,
    joint_angles,
    keyframed_angles,
    to_character_frame,
    translation,
)
from qtanimator.document.ik_settings import solve_character
from qtanimator.document.joint_limits import clamp_angle, joint_limits, limits_array

KEY_ALL_PARAMETER = "animation.key_all"
DELETE_TOLERANCE_FRAMES = 0.1


def clamp_values(doc: Document, values: dict[str, float], time: float) -> dict[str, float]:
    """Channel ``values`` with every 2D joint angle clamped to its joint's limits (other
    channels as they are). A dynamic joint's channel holds its world angle: its local
    angle, relative to the parent's world angle at ``time`` with the new values, is clamped."""
    by_asset: dict[str, list[tuple[str, int]]] = {}
    for cid in values:
        asset_id, joint_name, dof = split_channel_id(cid)
        if dof != "angle" or not joint_name:
            continue
        asset = doc.assets.get(asset_id)
        if asset is None or asset.kind != ASSET_KIND:
            continue
        ch = character(doc, asset_id)
        if joint_name in {j.name for j in ch.joints}:
            by_asset.setdefault(asset_id, []).append((cid, ch.joint_index(joint_name)))
    out = dict(values)
    for asset_id, items in by_asset.items():
        limits = joint_limits(doc, asset_id)
        if not any(limits[k] is not None for _cid, k in items):
            continue
        ch = character(doc, asset_id)
        dynamic_new: dict[int, str] = {}
        for cid, k in items:
            lim = limits[k]
            if ch.joints[k].is_dynamic:
                dynamic_new[k] = cid
            elif lim is not None:
                out[cid] = min(max(float(out[cid]), lim[0]), lim[1])
        if not any(limits[k] is not None for k in dynamic_new):
            continue
        # Parents' world angles with the new values; dynamic joints keep their world angle.
        old_world = evaluate_pose(doc, asset_id, time).world_angles
        local = {k: float(out[cid]) for cid, k in items if not ch.joints[k].is_dynamic}
        angles = joint_angles(doc, asset_id, time)
        world = np.empty(len(ch.joints))
        for k, j in enumerate(ch.joints):
            parent = 0.0 if j.parent is None else float(world[j.parent])
            if k in dynamic_new:
                lim = limits[k]
                theta = float(out[dynamic_new[k]])
                if lim is not None:
                    theta = parent + min(max(theta - parent, lim[0]), lim[1])
                    out[dynamic_new[k]] = theta
                world[k] = theta
            elif j.is_dynamic:
                world[k] = old_world[k]
            else:
                world[k] = parent + local.get(k, float(angles[k]))
    return out


def _key(time: float, value: float) -> Key:
    return Key(float(time), float(value))


def _key_all_values(doc: Document, time: float) -> dict[str, Key]:
    """The universal keyframe: every keyframed joint and position of every 2D character."""
    keys: dict[str, Key] = {}
    for aid in character_assets(doc):
        ch = character(doc, aid)
        vals = keyframed_angles(doc, aid, time)
        for j, v in zip(ch.joints, vals):
            if not j.is_dynamic:
                keys[angle_channel_id(aid, j.name)] = _key(time, v)
        cx, cy = position_channel_ids(aid)
        t = translation(doc, aid, time)
        keys[cx] = _key(time, t[0])
        keys[cy] = _key(time, t[1])
    return keys


def key_values(doc: Document, values: dict[str, float], time: float, text: str,
               gesture: Hashable | None = None) -> Command:
    """Key channel ``values`` at ``time`` — the one place a 2D edit becomes keys. With
    key-all (``animation.key_all``) the edit sets the universal keyframe: every keyframed
    joint and position of every 2D character keyed at ``time`` as well. Joint angles are
    clamped to their limits (:func:`clamp_values`)."""
    keys = {cid: _key(time, v) for cid, v in clamp_values(doc, values, time).items()}
    if keys and bool(doc.parameter(KEY_ALL_PARAMETER, False)):
        merged = _key_all_values(doc, time)  # evaluated: already within the limits
        merged.update(keys)
        keys = merged
    return SetKeys(doc, keys, text=text, gesture=gesture)


def joint_value(doc: Document, asset_id: str, joint_index: int, angle: float, time: float) -> dict[str, float]:
    """The channel value that poses a joint at local ``angle``, clamped to the joint's
    limits (a dynamic joint's channel holds the matching world angle)."""
    ch = character(doc, asset_id)
    j = ch.joints[joint_index]
    value = clamp_angle(doc, asset_id, joint_index, angle)
    if j.is_dynamic and j.parent is not None:
        # The parent's world angle needs the simulation only under a dynamic ancestor.
        exact = bool(ch.dynamic[ch.ancestors(j.parent)].any())
        angles = joint_angles(doc, asset_id, time) if exact else keyframed_angles(doc, asset_id, time)
        value = float(ch.pose(angles).world_angles[j.parent]) + value
    return {angle_channel_id(asset_id, j.name): value}


def key_joint(doc: Document, asset_id: str, joint_index: int, angle: float, time: float,
              gesture: Hashable | None = None) -> Command:
    """Key a joint's local ``angle`` at ``time``. For a dynamic joint the key holds the
    matching world angle and restarts the pendulum there."""
    name = character(doc, asset_id).joints[joint_index].name
    return key_values(doc, joint_value(doc, asset_id, joint_index, angle, time), time, f"Rotate {name}", gesture)


def position_values(asset_id: str, xy: npt.ArrayLike) -> dict[str, float]:
    """The channel values that put the character at offset ``xy`` from its rest pose."""
    x, y = (float(v) for v in np.asarray(xy, dtype=np.float64).reshape(2))
    cx, cy = position_channel_ids(asset_id)
    return {cx: x, cy: y}


def move_character(doc: Document, asset_id: str, xy: npt.ArrayLike, time: float,
                   gesture: Hashable | None = None) -> Command:
    """Key the character's translation (offset from the rest pose) to ``xy`` at ``time``."""
    return key_values(doc, position_values(asset_id, xy), time, f"Move {asset_id}", gesture)


def ik_values(doc: Document, asset_id: str, joint_index: int, local_point: npt.ArrayLike,
              target: npt.ArrayLike, time: float, limits: npt.ArrayLike | None = None) -> dict[str, float]:
    """Solve IK from the pose shown at ``time`` with the document's IK settings
    (``IK_DEFAULTS``): the new angles of the keyframed joints that moved, by channel.
    Every IK path (a drag that keys, one that only poses) gets its values here."""
    ch = character(doc, asset_id)
    if ch.dynamic[ch.ancestors(joint_index)].any():
        before = joint_angles(doc, asset_id, time)
    else:
        # The chain's pose needs only its own (keyframed) angles: no simulation to run.
        before = keyframed_angles(doc, asset_id, time)
    position = translation(doc, asset_id, time)
    # The joints' limits (joint_limits) unless the caller gives its own; IK never moves a
    # dynamic joint, so those are left free for the solver.
    lim = (limits_array(doc, asset_id) if limits is None
           else np.array(limits, dtype=np.float64).reshape(len(ch.joints), 2))
    lim[ch.dynamic] = (-math.inf, math.inf)
    limits = lim
    target = to_character_frame(doc, asset_id, target)  # the solver works in the character's frame
    after = solve_character(doc, ch, before, position, joint_index, local_point, target, limits)
    # Whatever the solver, the result is within the limits (every solver clamps what it moves).
    after = np.where(ch.dynamic, after, np.clip(after, lim[:, 0], lim[:, 1]))
    return {angle_channel_id(asset_id, j.name): float(after[k])
            for k, j in enumerate(ch.joints)
            if not j.is_dynamic and abs(after[k] - before[k]) > 1e-12}


def ik_drag(doc: Document, asset_id: str, joint_index: int, local_point: npt.ArrayLike,
            target: npt.ArrayLike, time: float, gesture: Hashable | None = None,
            limits: npt.ArrayLike | None = None) -> Command:
    """The keys of an IK drag, whatever the solver settings: the joints :func:`ik_values`
    moved, through :func:`key_values` (every joint in key-all mode)."""
    values = ik_values(doc, asset_id, joint_index, local_point, target, time, limits)
    return key_values(doc, values, time, "IK drag", gesture)


def delete_keys_at(doc: Document, asset_id: str | None, time: float) -> Command | None:
    """Delete the keys within 0.1 frame of ``time`` from a character's channels (every 2D
    character's with ``asset_id`` None or in key-all mode); None when there are none."""
    tol = DELETE_TOLERANCE_FRAMES / doc.fps
    if asset_id is None or bool(doc.parameter(KEY_ALL_PARAMETER, False)):
        assets = set(character_assets(doc))
    else:
        assets = {asset_id}
    selection: dict[str, Iterable[int]] = {}
    for cid, chn in doc.channels.items():
        if split_channel_id(cid)[0] not in assets:
            continue
        idx = [i for i, k in enumerate(chn.keys) if abs(k.time - time) < tol]
        if idx:
            selection[cid] = idx
    if not selection:
        return None
    return DeleteKeys(doc, selection, text="Delete Keyframe")
