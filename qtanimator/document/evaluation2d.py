"""Evaluating 2D characters: joint angles, translation and the pose at a time.

Keyframed joints come from their channels (clamped to their limits,
:mod:`qtanimator.document.joint_limits`), dynamic and spring joints from the pendulum cache
(:mod:`qtanimator.document.pendulum_cache`). With auto-key off, posing writes no key: the
values are the document's *pending pose* (:mod:`qtanimator.document.pose`), which every
evaluation here shows at its time (a dynamic joint's pending value is its world angle) until
the frame changes or it is keyed. The pose is placed by the character's authored placement
(:mod:`qtanimator.document.placement`).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from qtanimator.core.rig2d import Character, Pose
from qtanimator.document.character2d_asset import angle_channel_id, character, position_channel_ids
from qtanimator.document.document import Document
from qtanimator.document.joint_limits import joint_limits
from qtanimator.document.pending_pose import pending_value, pending_values
from qtanimator.document.pendulum_cache import simulation
from qtanimator.document.pendulum_presets import spring_params
from qtanimator.document.placement import PLACEMENT, matrix2d

FloatArray = npt.NDArray[np.float64]


def _value(doc: Document, cid: str, time: float, derivative: int = 0) -> float:
    if derivative == 0:
        held = pending_value(doc, cid, time)  # an unkeyed pose shown at this time
        if held is not None:
            return held
    ch = doc.channels.get(cid)
    return 0.0 if ch is None or not ch.keys else float(ch.evaluate(time, derivative))


def translation(doc: Document, asset_id: str, time: float, derivative: int = 0) -> FloatArray:
    cx, cy = position_channel_ids(asset_id)
    return np.array([_value(doc, cx, time, derivative), _value(doc, cy, time, derivative)])


def keyframed_angles(doc: Document, asset_id: str, time: float, derivative: int = 0) -> FloatArray:
    """Channel values (J,) of every joint (dynamic joints' channels hold world angles),
    keyframed joints clamped to their limits (a derivative is 0 where the value is clamped)."""
    ch = character(doc, asset_id)
    out = np.array([_value(doc, angle_channel_id(asset_id, j.name), time, derivative) for j in ch.joints])
    for k, lim in enumerate(joint_limits(doc, asset_id)):
        if lim is None or ch.joints[k].is_dynamic:
            continue
        if derivative == 0:
            out[k] = min(max(float(out[k]), lim[0]), lim[1])
        elif not lim[0] <= _value(doc, angle_channel_id(asset_id, ch.joints[k].name), time) <= lim[1]:
            out[k] = 0.0
    return out


def _local_from_world_dynamic(ch: Character, angles: FloatArray, dyn_world: FloatArray) -> FloatArray:
    out = angles.copy()
    world = np.empty_like(out)
    for k, j in enumerate(ch.joints):
        parent = 0.0 if j.parent is None else world[j.parent]
        if j.is_dynamic:
            out[k] = dyn_world[k] - parent
        world[k] = parent + out[k]
    return out


def joint_angles(doc: Document, asset_id: str, time: float, block: bool = True) -> FloatArray:
    """Local angles (J,) at ``time``: channels for keyframed joints, the simulation for
    dynamic ones. ``block`` False (views): the latest simulated state, never stepping on
    this thread (see
    :meth:`~qtanimator.document.pendulum_cache.PendulumCache.latest_state`)."""
    ch = character(doc, asset_id)
    angles = keyframed_angles(doc, asset_id, time)
    if ch.spring.any():
        # Spring joints show (1 − mix)·key + mix·spring; a pose held without a key shows as posed.
        state = simulation(doc).world_angles(asset_id, time, wait=block)
        mix = spring_params(doc, asset_id).mix
        held_spring = pending_values(doc, time)
        for k in np.flatnonzero(ch.spring):
            if angle_channel_id(asset_id, ch.joints[int(k)].name) not in held_spring:
                angles[k] = (1.0 - mix) * angles[k] + mix * state[k]
    if ch.dynamic.any():
        world = simulation(doc).world_angles(asset_id, time, wait=block)
        held = pending_values(doc, time)
        if held:  # a pendulum posed without a key shows its posed world angle
            world = np.array(world, dtype=np.float64)
            for k in np.flatnonzero(ch.dynamic):
                v = held.get(angle_channel_id(asset_id, ch.joints[int(k)].name))
                if v is not None:
                    world[k] = v
        angles = _local_from_world_dynamic(ch, angles, world)
    if not block and ch.simulated.any():
        # A view may read a state the worker has not caught up with (its parent already at
        # this time): keep the shown local angles in their limits, as the simulation does.
        for q, lim in enumerate(joint_limits(doc, asset_id)):
            if lim is not None and ch.simulated[q]:
                angles[q] = min(max(float(angles[q]), lim[0]), lim[1])
    return angles


def evaluate_pose(doc: Document, asset_id: str, time: float, block: bool = True) -> Pose:
    """The character's pose at ``time`` (keyframes, pendulums and translation).

    ``block`` True is exact: pendulum frames not simulated yet are simulated on the calling
    thread (render, export, commands). ``block`` False is for views: the pendulums show the
    latest state the background worker has (exact once it has caught up); nothing is
    simulated on the calling thread.
    """
    ch = character(doc, asset_id)
    pose = ch.pose(joint_angles(doc, asset_id, time, block), translation(doc, asset_id, time))
    return pose.placed(placement_matrix(doc, asset_id))


def placement_matrix(doc: Document, asset_id: str) -> FloatArray | None:
    """The character's authored placement P (3×3, :mod:`qtanimator.document.placement`)
    about its rest root pivot; None when it has none. Views draw, pick and drag through
    :func:`evaluate_pose`, whose world matrices are P · W; IK maps its target back."""
    asset = doc.assets.get(asset_id)
    value = asset.properties.get(PLACEMENT) if asset is not None else None
    if value is None:
        return None
    return matrix2d(value, character(doc, asset_id).rest_pivots[0])


def to_character_frame(doc: Document, asset_id: str, point: npt.ArrayLike, vector: bool = False) -> FloatArray:
    """A scene point (or with ``vector`` a displacement) in the character's own frame (P⁻¹)."""
    p = np.asarray(point, dtype=np.float64).reshape(2)
    m = placement_matrix(doc, asset_id)
    if m is None:
        return p.copy()
    return np.asarray(np.linalg.solve(m[:2, :2], p if vector else p - m[:2, 2]), dtype=np.float64)
