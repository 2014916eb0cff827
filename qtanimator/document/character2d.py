"""2D characters in the document: assets, channels, key edits, IK drags and the pendulum cache.

One asset of kind ``character2d`` per character (``source`` = the SVG file or folder,
property ``index`` = which character of a folder). Channels:

* ``"<asset>/<joint name>/angle"`` — a keyframed joint's local angle (radians);
* ``"<asset>//x"``, ``"<asset>//y"`` — the character's translation from the rest pose;
* a dynamic (pendulum) joint may have an angle channel too: it holds the joint's **world**
  angle θ and sets the simulation's state at its keys (θ from the key, ω = 0), so the
  animator can pose a pendulum's starting angle. Between keys physics drives it.

With auto-key off, posing writes no key: the values are the document's *pending pose*
(:mod:`qtanimator.document.pose`), which every evaluation here shows at its time (a
dynamic joint's pending value is its world angle) until the frame changes or it is keyed.

Keys use smooth tangents with constant extrapolation, which is the reference program's
Catmull-Rom spline. Per-joint keys by default; with the parameter ``animation.key_all``
true an edit sets the reference program's universal keyframe (every joint of every 2D
character and every position keyed at that time).

Pendulum parameters are document parameters ``"<asset>.pendulum.<name>"`` (see
:class:`qtanimator.core.pendulum.PendulumParams`); :func:`set_pendulum_preset` applies a
named preset (``physical`` or ``handout``).

A spring joint's channel holds its keyed local angle, as a keyframed joint's does; the
simulation makes the joint follow it through a damped spring (secondary motion,
:mod:`qtanimator.core.spring_joint`). Its constants are document parameters
``"<asset>.spring.<name>"`` (:class:`~qtanimator.core.spring_joint.SpringParams`);
:func:`set_spring_preset` applies ``soft`` or ``stiff``. Springs run in the pendulum cache,
on its worker thread, with the pendulums' sub-step.

Joint limits are document parameters ``"<asset>.limits.<joint name>"`` holding ``[lo, hi]``,
the range of the joint's **local** angle (relative to its parent, radians). A keyframed
joint's angle is clamped to its range wherever it is evaluated (the channel keeps its keys,
as Maya's transform limits do) and every edit that keys or poses a joint clamps the value it
writes (:func:`clamp_values`); :func:`joint_limits` gives them by joint index to the IK
solvers and the pendulums.
"""

from __future__ import annotations

import math
import threading
import time
import weakref
from collections import Counter
from collections.abc import Callable, Hashable, Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.core.channel import Channel, Key
from qtanimator.core.pendulum import (
    PRESETS,
    PendulumBlowUp,
    PendulumParams,
    PendulumSystem,
    check_state,
    rotation_pivot_terms,
)
from qtanimator.core.rig2d import Character, Pose, angle_sums
from qtanimator.core.spring_joint import SPRING_PRESETS, SpringParams, SpringSystem
from qtanimator.document.commands import AddAsset, Command, DeleteKeys, Macro, SetKeys, SetParameter
from qtanimator.document.document import (
    PROJECT_DEFAULTS,
    Asset,
    Document,
    DocumentChange,
    channel_id,
    split_channel_id,
)
from qtanimator.document.ik_settings import IK_DEFAULTS as IK_DEFAULTS
from qtanimator.document.ik_settings import ik_setting as ik_setting
from qtanimator.document.ik_settings import solve_character
from qtanimator.document.pending_pose import pending_value, pending_values
from qtanimator.document.placement import PLACEMENT, matrix2d
from qtanimator.document.simulation import SimulationWorker, ui_idle

ASSET_KIND = "character2d"
KEY_ALL_PARAMETER = "animation.key_all"

# IK settings (``IK_DEFAULTS``, ``ik_setting``) and the solver they pick live in
# qtanimator.document.ik_settings (shared with 3D); imported here for existing callers.
DELETE_TOLERANCE_FRAMES = 0.1
FloatArray = npt.NDArray[np.float64]


# ------------------------------------------------------------------------ assets
def load_character_asset(asset: Asset) -> Character:
    """Loader for ``character2d`` assets (registered in :mod:`qtanimator.document.loaders`)."""
    from qtanimator.formats.errors import FormatError
    from qtanimator.formats.svg_rig import load_characters, load_rigged_character

    if asset.source is None:
        raise FormatError(f"the 2D character '{asset.id}' has no source file.")
    index = int(asset.properties.get("index", 0))
    rig = asset.properties.get("rig")
    if rig is not None:  # rigged in the program (qtanimator.document.rigging): the SVG is unchanged
        return load_rigged_character(asset.source, index, rig)
    chars = load_characters(asset.source)
    if not 0 <= index < len(chars):
        raise FormatError(f"the 2D character '{asset.id}' refers to character {index + 1}, but the "
                          f"source holds {len(chars)}.", asset.source)
    return chars[index]


#: The frame range of a new, empty document (``PROJECT_DEFAULTS``).
NEW_PROJECT_RANGE = (int(PROJECT_DEFAULTS["frame_start"]), int(PROJECT_DEFAULTS["frame_end"]))
#: The last frame of a new project of SVG characters: the CMU animator's timeline starts at 300.
SVG_PROJECT_FRAME_END = 300


def add_characters_command(doc: Document, path: str | Path, new_project_range: bool = False) -> Command:
    """A command adding every character of an SVG file or folder (FormatError if unreadable).

    With ``new_project_range`` (opening in the GUI, ``qtanimator render``), characters added
    to a new, empty document (no assets, no channels, the default range) also set the range
    to the CMU animator's 0…300, in the same undo step."""
    from qtanimator.formats.svg_rig import load_characters

    source = str(Path(path).resolve())
    chars = load_characters(source)
    new_project = (new_project_range and not doc.assets and not doc.channels
                   and doc.frame_range == NEW_PROJECT_RANGE)
    taken = set(doc.assets)
    commands: list[Command] = []
    offset = _beside_offset(doc, chars)
    for i, ch in enumerate(chars):
        asset_id = doc.unique_asset_id(ch.name)
        k = 2
        base = asset_id
        while asset_id in taken:
            asset_id = f"{base}_{k}"
            k += 1
        taken.add(asset_id)
        props: dict[str, Any] = {"index": i}
        if offset is not None:  # beside the characters already there (issue 14)
            props[PLACEMENT] = {"translate": [float(offset[0]), float(offset[1])], "rotate": 0.0, "scale": 1.0}
        asset = Asset(asset_id, ASSET_KIND, source, props)
        commands.append(AddAsset(asset, ch))
    text = commands[0].text if len(commands) == 1 else f"Add {len(commands)} characters"
    if new_project and commands:
        # A new project of SVG characters gets the CMU animator's range, 0…300, in the same step.
        commands.append(SetParameter(doc, "frame_end", SVG_PROJECT_FRAME_END))
    if len(commands) == 1:
        return commands[0]
    return Macro(text, commands)


def shown_bounds(doc: Document, asset_id: str, time: float = 0.0) -> tuple[float, float, float, float]:
    """(xmin, ymin, xmax, ymax) of the character's setup pose at its position and placement
    at ``time`` (what an import places new characters beside; nothing is simulated)."""
    ch = character(doc, asset_id)
    pose = ch.pose(np.zeros(len(ch.joints)), translation(doc, asset_id, time))
    return ch.bounds(pose.placed(placement_matrix(doc, asset_id)))


def _beside_offset(doc: Document, chars: list[Character]) -> FloatArray | None:
    """The translation that puts newly read characters (keeping their layout in the file)
    to the right of the document's 2D characters, bottoms aligned; None when there are none."""
    existing = [shown_bounds(doc, aid) for aid in character_assets(doc) if aid in doc.runtime]
    if not existing or not chars:
        return None
    new = [c.bounds() for c in chars]
    right = max(b[2] for b in existing)
    bottom = max(b[3] for b in existing)
    left = min(b[0] for b in new)
    height = max(max(b[3] for b in new) - min(b[1] for b in new), 1.0)
    return np.array([right + BESIDE_GAP * height - left, bottom - max(b[3] for b in new)])


#: The gap between an imported 2D character and the ones there, as a fraction of its height.
BESIDE_GAP = 0.1


def character(doc: Document, asset_id: str) -> Character:
    ch = doc.runtime.get(asset_id)
    if ch is None:
        asset = doc.assets[asset_id]
        if asset.kind != ASSET_KIND:
            raise KeyError(f"{asset_id} is not a 2D character")
        ch = load_character_asset(asset)
        doc.runtime[asset_id] = ch
    if not isinstance(ch, Character):
        raise KeyError(f"{asset_id} is not a 2D character")
    return ch


def character_assets(doc: Document) -> list[str]:
    return [a.id for a in doc.assets.values() if a.kind == ASSET_KIND]


def angle_channel_id(asset_id: str, joint_name: str) -> str:
    return channel_id(asset_id, joint_name, "angle")


def position_channel_ids(asset_id: str) -> tuple[str, str]:
    return channel_id(asset_id, "", "x"), channel_id(asset_id, "", "y")


# ------------------------------------------------------------------ joint limits
def limits_parameter(asset_id: str, joint_name: str) -> str:
    """The document parameter holding a joint's limits ``[lo, hi]`` (local angle, radians)."""
    return f"{asset_id}.limits.{joint_name}"


def _limit_pair(value: Any) -> tuple[float, float] | None:
    """A stored ``[lo, hi]`` as floats; None for anything else (a hand-edited project's
    malformed entry leaves the joint free rather than breaking every evaluation)."""
    if not isinstance(value, (list, tuple)) or len(value) != 2 or any(isinstance(v, bool) for v in value):
        return None
    try:
        lo, hi = float(value[0]), float(value[1])
    except (TypeError, ValueError):
        return None
    if not (math.isfinite(lo) and math.isfinite(hi)) or lo > hi:
        return None
    return lo, hi


def joint_limits(doc: Document, asset_id: str) -> list[tuple[float, float] | None]:
    """Each joint's limits ``(lo, hi)`` on its local angle (radians, relative to its
    parent), by joint index; None for a free joint."""
    ch = character(doc, asset_id)
    params = doc.parameters
    return [_limit_pair(params.get(limits_parameter(asset_id, j.name))) for j in ch.joints]


def limits_array(doc: Document, asset_id: str) -> FloatArray:
    """:func:`joint_limits` as a (J, 2) array, ±inf for free joints (``solve_ik``'s form)."""
    out = np.tile(np.array([-math.inf, math.inf]), (len(character(doc, asset_id).joints), 1))
    for k, lim in enumerate(joint_limits(doc, asset_id)):
        if lim is not None:
            out[k] = lim
    return out


def set_joint_limits_command(doc: Document, asset_id: str, joint: int | str, lo: float | None,
                             hi: float | None = None, gesture: Hashable | None = None) -> Command:
    """Limit ``joint`` (index or name) to local angles ``lo``…``hi`` (radians), or free it
    with ``lo`` and ``hi`` None: one undo step, saved with the project as a parameter.
    ValueError for an unknown joint, a missing, non-finite or reversed bound."""
    ch = character(doc, asset_id)
    if isinstance(joint, str):
        index = ch.joint_index(joint) if joint in {j.name for j in ch.joints} else -1
    else:
        index = int(joint)
    if not 0 <= index < len(ch.joints):
        raise ValueError(f"'{asset_id}' has no joint {joint!r}")
    name = ch.joints[index].name
    path = limits_parameter(asset_id, name)
    if lo is None and hi is None:
        return SetParameter(doc, path, None, text=f"Free {name}", gesture=gesture)
    if lo is None or hi is None:
        raise ValueError("a joint limit needs both a minimum and a maximum")
    lo_f, hi_f = float(lo), float(hi)
    if not (math.isfinite(lo_f) and math.isfinite(hi_f)):
        raise ValueError("joint limits must be finite numbers")
    if lo_f > hi_f:
        raise ValueError(f"the minimum ({math.degrees(lo_f):.6g}°) is above the maximum ({math.degrees(hi_f):.6g}°)")
    return SetParameter(doc, path, [lo_f, hi_f], text=f"Limit {name}", gesture=gesture)


def clamp_angle(doc: Document, asset_id: str, joint_index: int, angle: float) -> float:
    """A local ``angle`` of a joint clamped to its limits."""
    lim = joint_limits(doc, asset_id)[joint_index]
    return float(angle) if lim is None else min(max(float(angle), lim[0]), lim[1])


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


def _value(doc: Document, cid: str, time: float, derivative: int = 0) -> float:
    if derivative == 0:
        held = pending_value(doc, cid, time)  # an unkeyed pose shown at this time
        if held is not None:
            return held
    ch = doc.channels.get(cid)
    return 0.0 if ch is None or not ch.keys else float(ch.evaluate(time, derivative))


# ------------------------------------------------------------------ evaluation
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
    this thread (see :meth:`PendulumCache.latest_state`)."""
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


# ------------------------------------------------------------------- key edits
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


# -------------------------------------------------------------- pendulum params
def _preset_params(doc: Document, prefix: str, presets: Mapping[str, Any], default: str) -> Any:
    """A named preset (``default`` when unset) with the parameters ``prefix + <name>`` over
    it; the preset itself when they do not make valid constants."""
    # list() copies in one step: the simulation worker may read while the UI thread edits.
    values = {k[len(prefix):]: v for k, v in list(doc.parameters.items()) if k.startswith(prefix)}
    preset = presets.get(str(values.pop("preset", default)), presets[default])
    try:
        return type(preset).from_dict({**preset.to_dict(), **values})
    except (TypeError, ValueError):
        return preset


def _preset_command(doc: Document, prefix: str, presets: Mapping[str, Any], name: str, what: str) -> Command:
    """Every parameter ``prefix + <name>`` set to the preset ``name`` (one undo step)."""
    if name not in presets:
        raise ValueError(f"unknown {what.lower()} preset '{name}' (known: {', '.join(presets)})")
    cmds: list[Command] = [SetParameter(doc, prefix + "preset", name)]
    for k, v in presets[name].to_dict().items():
        cmds.append(SetParameter(doc, prefix + k, v))
    return Macro(f"{what} preset: {name}", cmds)


def pendulum_params(doc: Document, asset_id: str) -> PendulumParams:
    """The pendulum constants of a character: its preset (``physical`` when unset) with the
    parameters ``"<asset>.pendulum.<name>"`` over it."""
    params: PendulumParams = _preset_params(doc, f"{asset_id}.pendulum.", PRESETS, "physical")
    return params


def set_pendulum_preset(doc: Document, asset_id: str, name: str) -> Command:
    """Set all of a character's pendulum parameters to a named preset (one undo step)."""
    return _preset_command(doc, f"{asset_id}.pendulum.", PRESETS, name, "Pendulum")


def spring_params(doc: Document, asset_id: str) -> SpringParams:
    """The spring joints' constants of a character: its preset (``soft`` when unset) with
    the parameters ``"<asset>.spring.<name>"`` over it."""
    params: SpringParams = _preset_params(doc, f"{asset_id}.spring.", SPRING_PRESETS, "soft")
    return params


def set_spring_preset(doc: Document, asset_id: str, name: str) -> Command:
    """Set all of a character's spring constants to a named preset (one undo step)."""
    return _preset_command(doc, f"{asset_id}.spring.", SPRING_PRESETS, name, "Spring")


def _keyed_angles_at(channels: Mapping[str, Channel], asset_id: str, ch: Character, times: FloatArray,
                     limits: list[tuple[float, float] | None]) -> FloatArray:
    """(3, len(times), J): every non-dynamic joint's keyed local angle, rate and acceleration
    at ``times``, clamped to its limits (still while clamped), as ``_advance`` reads them."""
    out = np.zeros((3, len(times), len(ch.joints)))
    for k, j in enumerate(ch.joints):
        if j.is_dynamic:
            continue
        chn = channels.get(angle_channel_id(asset_id, j.name))
        if chn is not None and chn.keys:
            for d in range(3):
                out[d, :, k] = chn.evaluate(times, d)
        lim = limits[k]
        if lim is not None:
            held = (out[0, :, k] < lim[0]) | (out[0, :, k] > lim[1])
            out[0, :, k] = np.clip(out[0, :, k], lim[0], lim[1])
            out[1:, held, k] = 0.0
    return out


def _new_sim(doc: Document, asset_id: str, ch: Character) -> _AssetSim:
    limits = joint_limits(doc, asset_id) if ch.simulated.any() else None
    return _AssetSim(ch, pendulum_params(doc, asset_id), limits,
                     spring_params(doc, asset_id) if ch.spring.any() else None)


# ------------------------------------------------------------ simulation cache
class _AssetSim:
    """One character's simulation: the system, its per-frame states and a kinematics plan.

    World angles: a joint's world angle is the world angle θ_D of its nearest dynamic
    ancestor-or-self D plus the local angles of the keyframed joints after D on its path
    (from the root when there is no D). ``key_sum`` (J, J) and ``dyn_pick`` (J, J) are those
    two sums as matrices, so every sub-step's kinematics is a few array operations. Pivot
    accelerations are only needed at the groups' top joints: one term per (top, ancestor).
    """

    def __init__(self, ch: Character, params: PendulumParams,
                 limits: list[tuple[float, float] | None] | None = None,
                 springs: SpringParams | None = None) -> None:
        self.system = PendulumSystem(ch, params, limits)
        #: The spring joints (None without any); their entries of ``theta`` / ``omega`` are
        #: their simulated local angles and rates.
        self.springs = (SpringSystem(ch, springs, limits, params.restitution)
                        if springs is not None and ch.spring.any() else None)
        self.theta: list[FloatArray] = []  # per frame (world angles, J)
        self.omega: list[FloatArray] = []
        #: Bumped by an invalidation that reaches the frame being computed (see PendulumCache).
        self.generation = 0
        #: Why the simulation stopped after its last cached frame (a blow-up), or None.
        self.problem: PendulumBlowUp | None = None
        self.key_sum, self.dyn_pick = angle_sums(ch)
        self.tops = np.array([g.top for g in self.system.groups], dtype=np.intp)
        top_of, anc, vec = [], [], []
        for ti, t in enumerate(self.tops):
            child, m = int(t), ch.joints[int(t)].parent
            while m is not None:
                top_of.append(ti)
                anc.append(m)
                vec.append(ch.joints[child].pivot - ch.joints[m].pivot)
                child, m = m, ch.joints[m].parent
        self.pair_top = np.array(top_of, dtype=np.intp)
        self.pair_anc = np.array(anc, dtype=np.intp)
        self.pair_vec = np.array(vec, dtype=np.float64).reshape(-1, 2)
        self.pair_sum = np.zeros((len(self.tops), len(anc)))
        self.pair_sum[self.pair_top, np.arange(len(anc))] = 1.0
        parents = np.array([-1 if j.parent is None else j.parent for j in ch.joints], dtype=np.intp)
        self.has_parent = parents >= 0
        self.parent_of = np.maximum(parents, 0)

    def spring_substep(self, s: int, theta: FloatArray, omega: FloatArray, tau: float, ang: FloatArray,
                       mid: FloatArray, tacc_mid: FloatArray, w_key: FloatArray, r_key: FloatArray,
                       a_key: FloatArray) -> None:
        """Step the spring joints over sub-step ``s`` (their entries of ``theta`` and
        ``omega``), then put their shown angles into the keyed kinematics of sub-step ``s``
        (``w_key``, ``r_key``, ``a_key``) that the pendulums read."""
        springs = self.springs
        assert springs is not None
        q = springs.joints
        before_t, before_w = theta[q].copy(), omega[q].copy()
        key, key_rate, key_acc = mid[0, s].copy(), mid[1, s].copy(), mid[2, s].copy()
        springs.step(theta, omega, tau, key, key_rate, key_acc, theta, omega, tacc_mid[s])
        mix = springs.params.mix
        if mix:
            avg_acc = (omega[q] - before_w) / tau
            cols = self.key_sum[:, q]
            w_key[s] += cols @ (mix * (before_t - ang[0, s, q]))
            r_key[s] += cols @ (mix * (before_w - ang[1, s, q]))
            a_key[s] += cols @ (mix * (avg_acc - ang[2, s, q]))

    def parent_motion(self, s: int, theta: FloatArray, omega: FloatArray, w_key: FloatArray, r_key: FloatArray,
                      ang: FloatArray, end: FloatArray) -> FloatArray:
        """(J, 4): the keyed part of every joint's parent's world angle and rate at the
        start and end of sub-step ``s`` (``PendulumSystem.step``'s ``parent_motion``), the
        springs stepped already. ``end`` (3, J): the keyed angles at the frame's end."""
        n = len(self.has_parent)
        nxt = end if s + 1 >= len(w_key) else ang[:, s + 1]
        w1 = nxt[0] @ self.key_sum.T
        r1 = nxt[1] @ self.key_sum.T
        if self.springs is not None and self.springs.params.mix:
            # Springs after this sub-step (what the next sub-step's correction will add).
            q = self.springs.joints
            mix = self.springs.params.mix
            cols = self.key_sum[:, q]
            w1 = w1 + cols @ (mix * (theta[q] - nxt[0, q]))
            r1 = r1 + cols @ (mix * (omega[q] - nxt[1, q]))
        out = np.zeros((n, 4))
        p, has = self.parent_of, self.has_parent
        out[has, 0] = w_key[s][p[has]]
        out[has, 1] = r_key[s][p[has]]
        out[has, 2] = w1[p[has]]
        out[has, 3] = r1[p[has]]
        return out


class PendulumCache:
    """Per-frame pendulum states of every 2D character, at a fixed internal step.

    Frame f (from the project's ``frame_start``) holds the world angles after simulating up
    to time f / fps (a spring joint's entry is its simulated local angle and rate). A channel
    edit drops the frames from the edited time on (once per asset and change); a parameter
    or asset change drops that character's frames.

    Two ways to read:

    * exact (``state``, ``world_angles(..., wait=True)``): a frame not cached yet is
      simulated on the calling thread (headless render, export, commands, tests);
    * latest (``latest_state``, ``world_angles(..., wait=False)``): never steps; returns the
      last frame simulated at or before the one asked for (the keyed start state when
      nothing is), and asks the background worker (:mod:`qtanimator.document.simulation`)
      to fill up to that frame plus :attr:`LOOKAHEAD` seconds. Views use this.

    Threads: the worker and exact reads compute a frame without the lock and append it
    under the lock only if the character's simulation is still the same object, its
    ``generation`` unchanged (an invalidation that reaches the frame being computed bumps
    it) and the frame still the next one; so a frame computed from a dropped state never
    enters the cache, and every cached frame equals the synchronous result exactly.
    """

    MAX_FRAMES = 200_000
    #: Seconds of frames the worker simulates past the frame a view asked for.
    LOOKAHEAD = 1.0

    def __init__(self, doc: Document) -> None:
        self._doc = weakref.ref(doc)
        self._sims: dict[str, _AssetSim] = {}
        self._lock = threading.Lock()
        self._epoch = 0  # bumped when simulations are dropped (a sim built meanwhile is stale)
        self._targets: dict[str, int] = {}  # frame index the worker fills each character to
        #: Sub-steps simulated (by any thread), and per thread id (frames later discarded included).
        self.steps_taken = 0
        self.steps_by_thread: Counter[int] = Counter()
        #: Frame-dropping invalidations (one per character per change at most), and restarts
        #: (worker wake-ups caused by a change: at most one per change).
        self.invalidations = 0
        self.restarts = 0
        #: Changes whenever frames are added or dropped (the UI polls it).
        self.revision = 0
        self._worker = SimulationWorker(self._work, "pendulums")
        weakref.finalize(self, self._worker.shutdown, 0.0)
        doc.subscribe(self._on_change)

    # ---- worker control
    @property
    def worker(self) -> SimulationWorker:
        return self._worker

    @property
    def busy(self) -> bool:
        """True while the worker has frames to simulate."""
        return self._worker.busy

    def shutdown(self, timeout: float | None = 5.0) -> None:
        """Stop the worker thread and forget what it was asked for (cached frames stay;
        a later latest-state read starts it again)."""
        with self._lock:
            self._targets.clear()
        self._worker.shutdown(timeout)

    def wait_idle(self, timeout: float = 30.0) -> bool:
        """Block until the worker has nothing to do (tests); False on timeout."""
        ui_idle()  # the calling thread waits: the worker need not leave it the interpreter
        deadline = time.monotonic() + timeout
        while self._worker.busy:
            if time.monotonic() > deadline:
                return False
            time.sleep(0.001)
        return True

    # ---- invalidation
    def _on_change(self, change: DocumentChange) -> None:
        doc = self._doc()
        if doc is None:
            return
        if change.reset:
            with self._lock:
                self._drop_all()
                self._targets.clear()
            self._worker.shutdown()
            return
        dropped = False
        with self._lock:
            for asset_id in change.assets:
                dropped |= self._drop(asset_id)
                if asset_id not in doc.assets:
                    self._targets.pop(asset_id, None)
            for path in change.parameters:
                if path in ("fps", "frame_start") or path.startswith("simulation."):
                    dropped |= self._drop_all()
                elif ".pendulum." in path:
                    dropped |= self._drop(path.split(".pendulum.", 1)[0])
                elif ".spring." in path:
                    dropped |= self._drop(path.split(".spring.", 1)[0])
                elif ".limits." in path:  # clamped parents swing the pendulums differently
                    dropped |= self._drop(path.split(".limits.", 1)[0])
            for asset_id in change.channel_assets():
                # One invalidation per asset and command, from its earliest edited time.
                dropped |= self._invalidate_locked(doc, asset_id, change.channel_time_from(asset_id))
            restart = dropped and bool(self._targets)
            if restart:
                self.restarts += 1
        if restart:
            self._worker.wake()

    def _drop(self, asset_id: str) -> bool:
        self._epoch += 1  # also when none is cached: one may be under construction
        if self._sims.pop(asset_id, None) is None:
            return False
        self.revision += 1
        self.invalidations += 1
        return True

    def _drop_all(self) -> bool:
        self._epoch += 1
        if not self._sims:
            return False
        self._sims.clear()
        self.revision += 1
        self.invalidations += 1
        return True

    def _invalidate_locked(self, doc: Document | None, asset_id: str, time_from: float) -> bool:
        sim = self._sims.get(asset_id)
        if sim is None or time_from == math.inf:
            return False
        if doc is None or time_from == -math.inf:
            return self._drop(asset_id)
        # Frame i (after the start) integrates inputs at times before its own time and
        # applies keys at its own time, so it is valid while its time < time_from.
        keep = max(math.ceil(time_from * doc.fps - doc.frame_range[0] - 1e-9), 0)
        if keep > len(sim.theta):
            return False  # neither a cached frame nor the one being computed is affected
        # The frame being computed (index len) may read the old inputs: make it stale too.
        sim.generation += 1
        sim.problem = None  # the frame that blew up is recomputed from the new inputs
        del sim.theta[keep:]
        del sim.omega[keep:]
        self.revision += 1
        self.invalidations += 1
        return True

    def invalidate(self, asset_id: str | None = None, time_from: float = -math.inf) -> None:
        """Drop the cached frames whose state depends on inputs at or after ``time_from``
        (every character's with ``asset_id`` None); the worker refills what views asked for."""
        doc = self._doc()
        with self._lock:
            targets = list(self._sims) if asset_id is None else [asset_id]
            dropped = False
            for aid in targets:
                dropped |= self._invalidate_locked(doc, aid, time_from)
            restart = dropped and bool(self._targets)
        if restart:
            self._worker.wake()

    def problem(self, asset_id: str) -> PendulumBlowUp | None:
        """The blow-up that stopped this character's simulation, or None."""
        with self._lock:
            sim = self._sims.get(asset_id)
            return None if sim is None else sim.problem

    def cached_frames(self, asset_id: str) -> int:
        sim = self._sims.get(asset_id)
        return 0 if sim is None else len(sim.theta)

    def baked_states(self) -> dict[str, tuple[FloatArray, FloatArray, PendulumBlowUp | None]]:
        """Every character's cached frames as ``{asset: (theta (F, J), omega (F, J), problem)}``:
        plain arrays that pickle, for :meth:`load_baked_states` in another process (the
        parallel render bakes the pendulums once and hands them to its workers)."""
        with self._lock:
            out: dict[str, tuple[FloatArray, FloatArray, PendulumBlowUp | None]] = {}
            for aid, sim in self._sims.items():
                if sim.theta:
                    out[aid] = (np.array(sim.theta), np.array(sim.omega), sim.problem)
            return out

    def load_baked_states(self, states: dict[str, tuple[FloatArray, FloatArray, PendulumBlowUp | None]]) -> None:
        """Put frames from :meth:`baked_states` (of the same document) into this cache; reads
        of those frames then never simulate."""
        doc = self._doc()
        if doc is None:
            raise RuntimeError("the document is gone")
        for aid, (theta, omega, problem) in states.items():
            sim = _new_sim(doc, aid, character(doc, aid))
            sim.theta = [np.array(row) for row in theta]
            sim.omega = [np.array(row) for row in omega]
            sim.problem = problem
            with self._lock:
                self._sims[aid] = sim
                self.revision += 1

    # ---- exact reads
    def _sim(self, doc: Document, asset_id: str) -> _AssetSim:
        while True:
            with self._lock:
                sim = self._sims.get(asset_id)
                epoch = self._epoch
            if sim is not None:
                return sim
            built = _new_sim(doc, asset_id, character(doc, asset_id))
            with self._lock:
                if self._epoch == epoch:  # else a change dropped it meanwhile: build again
                    return self._sims.setdefault(asset_id, built)

    def _index(self, doc: Document, frame: int) -> int:
        return min(max(int(frame) - doc.frame_range[0], 0), self.MAX_FRAMES)

    def state(self, asset_id: str, frame: int) -> tuple[FloatArray, FloatArray]:
        """World angles and rates (J,) of every joint's pendulum state at an integer frame,
        simulated on the calling thread if not cached yet (exact)."""
        doc = self._doc()
        if doc is None:
            raise RuntimeError("the document is gone")
        f = self._index(doc, frame)
        while True:
            sim = self._sim(doc, asset_id)
            with self._lock:
                n = len(sim.theta)
                if n > f:
                    return sim.theta[f], sim.omega[f]
                if sim.problem is not None and n:
                    return sim.theta[-1], sim.omega[-1]  # it stops at the last good frame
                gen = sim.generation
                prev = (sim.theta[-1], sim.omega[-1]) if n else None
            self._step(doc, asset_id, sim, gen, n, prev)

    def world_angles(self, asset_id: str, time: float, wait: bool = True) -> FloatArray:
        """Dynamic joints' world angles at ``time`` (linear between cached frames).

        ``wait`` True: exact, simulating on this thread as needed. False: never steps;
        the latest state available (see :meth:`latest_state`), and the worker is asked to
        catch up.
        """
        doc = self._doc()
        if doc is None:
            raise RuntimeError("the document is gone")
        fr = time * doc.fps
        f0 = math.floor(fr + 1e-9)
        u = fr - f0
        if wait:
            th0 = self.state(asset_id, f0)[0]
            if u <= 1e-9:
                return th0.copy()
            th1 = self.state(asset_id, f0 + 1)[0]
            return np.asarray((1 - u) * th0 + u * th1, dtype=np.float64)
        if u <= 1e-9:
            return self.latest_state(asset_id, f0)[0].copy()
        th1, _om, at = self.latest_state(asset_id, f0 + 1)
        th0, _om, at0 = self.latest_state(asset_id, f0)
        if at < f0 + 1 or at0 < f0:
            return th0.copy()  # f0 + 1 is not simulated yet: the latest state at or before f0
        return np.asarray((1 - u) * th0 + u * th1, dtype=np.float64)

    # ---- latest reads (views)
    def latest_state(self, asset_id: str, frame: int) -> tuple[FloatArray, FloatArray, int]:
        """``(theta, omega, shown_frame)``: the state at ``frame`` if simulated, else at the
        last simulated frame before it (``shown_frame`` says which), or the keyed start
        state when nothing is. Never simulates on the calling thread; asks the worker to
        fill up to ``frame`` plus the look-ahead."""
        doc = self._doc()
        if doc is None:
            raise RuntimeError("the document is gone")
        start = doc.frame_range[0]
        f = self._index(doc, frame)
        with self._lock:
            sim = self._sims.get(asset_id)
            n = 0 if sim is None else len(sim.theta)
            if n:
                assert sim is not None
                k = min(f, n - 1)
                theta, omega = sim.theta[k], sim.omega[k]
            wake = self._request(doc, asset_id, f, n)
        if wake:
            self._worker.wake()
        if n:
            return theta, omega, start + k
        ch = character(doc, asset_id)
        theta = _initial_angles(doc, asset_id, ch, start / doc.fps)
        return theta, np.zeros(len(ch.joints)), start

    def ready(self, asset_id: str, time: float) -> bool:
        """True when ``world_angles(asset_id, time, wait=False)`` is exact (its frames are
        simulated)."""
        doc = self._doc()
        if doc is None:
            return False
        fr = time * doc.fps
        f0 = math.floor(fr + 1e-9)
        need = self._index(doc, f0 + (0 if fr - f0 <= 1e-9 else 1))
        return self.cached_frames(asset_id) > need

    def _request(self, doc: Document, asset_id: str, index: int, cached: int) -> bool:
        """Record that a view shows frame ``index`` (lock held); True if the worker must be
        woken (its target moved and frames up to it are missing)."""
        first, last = doc.frame_range
        end = max(last - first, 0)
        ahead = int(math.ceil(self.LOOKAHEAD * doc.fps))
        want = max(index, min(index + ahead, end))
        old = self._targets.get(asset_id, -1)
        # Grow with the frame shown (playback stays ahead); start over when the view jumped
        # far back (a scrub), so the worker does not fill frames nobody looks at.
        changed = want > old or old > index + 2 * ahead
        if changed:
            self._targets[asset_id] = want
        # Wake it when frames are missing and it is not already on them (or was cancelled).
        return cached <= self._targets[asset_id] and (changed or not self._worker.busy)

    # ---- stepping (any thread)
    def _work(self, should_stop: Callable[[], bool]) -> bool:
        """The worker's job: simulate one frame of the character furthest behind its
        target. False when every target is reached."""
        doc = self._doc()
        if doc is None:
            return False
        with self._lock:
            best: tuple[int, str] | None = None
            for aid, target in list(self._targets.items()):
                sim = self._sims.get(aid)
                n = 0 if sim is None else len(sim.theta)
                if sim is not None and sim.problem is not None:
                    continue  # blown up: nothing more to simulate until an edit
                if n <= target and (best is None or n < best[0]):
                    best = (n, aid)
            if best is None:
                return False
            n, aid = best
            sim = self._sims.get(aid)
            epoch = self._epoch
            gen = -1 if sim is None else sim.generation
            prev = (sim.theta[-1], sim.omega[-1]) if sim is not None and n else None
        if should_stop():
            return False
        if sim is None:
            ch = doc.runtime.get(aid)
            if not isinstance(ch, Character):  # removed, or not loaded: nothing to simulate
                with self._lock:
                    self._targets.pop(aid, None)
                return True
            built = _new_sim(doc, aid, ch)
            with self._lock:
                if self._epoch == epoch and aid not in self._sims:
                    self._sims[aid] = built
            return True
        self._step(doc, aid, sim, gen, n, prev)
        return True

    def _step(self, doc: Document, asset_id: str, sim: _AssetSim, generation: int, index: int,
              prev: tuple[FloatArray, FloatArray] | None) -> bool:
        """Compute frame ``index`` from ``prev`` (frame ``index - 1``) without the lock and
        append it if nothing invalidated it meanwhile. True if it was appended."""
        start = doc.frame_range[0]
        if prev is None:
            theta, omega = self._initial(doc, asset_id, sim)
            steps = 0
        else:
            # A blow-up makes inf and NaN on the way; check_state below reports it.
            with np.errstate(over="ignore", invalid="ignore"):
                theta, omega, steps = self._advance(doc, asset_id, sim, start + index - 1, prev[0], prev[1])
        ident = threading.get_ident()
        problem = check_state(sim.system.character, sim.system.params, theta, omega, (start + index) / doc.fps)
        with self._lock:
            self.steps_taken += steps
            self.steps_by_thread[ident] += steps
            if self._sims.get(asset_id) is not sim or sim.generation != generation or len(sim.theta) != index:
                return False
            if problem is not None:
                # Stop at the last good frame: nothing non-finite reaches a view or a file.
                sim.problem = problem
                self.revision += 1
                return False
            sim.theta.append(theta)
            sim.omega.append(omega)
            self.revision += 1
            return True

    def _initial(self, doc: Document, asset_id: str, sim: _AssetSim) -> tuple[FloatArray, FloatArray]:
        ch = sim.system.character
        t0 = doc.frame_range[0] / doc.fps
        return _initial_angles(doc, asset_id, ch, t0), _initial_rates(doc, asset_id, ch, t0)

    def _advance(self, doc: Document, asset_id: str, sim: _AssetSim, frame: int, theta0: FloatArray,
                 omega0: FloatArray) -> tuple[FloatArray, FloatArray, int]:
        """The state at ``frame + 1`` from the state at ``frame``, and the sub-steps taken.
        Reads the document only through atomic lookups (it may run on the worker thread)."""
        system = sim.system
        ch = system.character
        params = system.params
        fps = doc.fps
        channels = doc.channels
        t0, t1 = frame / fps, (frame + 1) / fps
        n_steps = max(1, int(round((t1 - t0) / params.step)))
        tau = (t1 - t0) / n_steps
        times = t0 + tau * np.arange(n_steps)
        theta, omega = theta0.copy(), omega0.copy()
        dyn_idx = np.flatnonzero(ch.dynamic)
        # Channel values and derivatives at every sub-step time, evaluated at once.
        ang = np.zeros((3, n_steps, len(ch.joints)))
        stored = doc.parameters
        limits = [_limit_pair(stored.get(limits_parameter(asset_id, j.name))) for j in ch.joints]
        for k, j in enumerate(ch.joints):
            if j.is_dynamic:
                continue
            chn = channels.get(angle_channel_id(asset_id, j.name))
            if chn is not None and chn.keys:
                for d in range(3):
                    ang[d, :, k] = chn.evaluate(times, d)
            lim = limits[k]
            if lim is not None:  # as keyframed_angles: clamped, still while clamped
                held = (ang[0, :, k] < lim[0]) | (ang[0, :, k] > lim[1])
                ang[0, :, k] = np.clip(ang[0, :, k], lim[0], lim[1])
                ang[1:, held, k] = 0.0
        cx, cy = position_channel_ids(asset_id)
        tacc = np.zeros((n_steps, 2))
        for col, cid in enumerate((cx, cy)):
            chn = channels.get(cid)
            if chn is not None and chn.keys:
                tacc[:, col] = chn.evaluate(times, 2)
        # Keyframed parts of the world angles, rates and accelerations for every sub-step.
        w_key = ang[0] @ sim.key_sum.T
        r_key = ang[1] @ sim.key_sum.T
        a_key = ang[2] @ sim.key_sum.T
        springs, bounded = sim.springs, bool(system.bounded.any())
        mid, tacc_mid, end = ang, tacc, ang[:, 0]
        if springs is not None:  # keys and the body's acceleration at the sub-steps' midpoints
            mids = np.asarray(times + 0.5 * tau, dtype=np.float64)
            mid = _keyed_angles_at(channels, asset_id, ch, mids, limits)
            tacc_mid = np.zeros((n_steps, 2))
            for col, cid in enumerate((cx, cy)):
                chn = channels.get(cid)
                if chn is not None and chn.keys:
                    tacc_mid[:, col] = chn.evaluate(mids, 2)
        if bounded:  # limits: the parents' motion to the frame's end
            end = _keyed_angles_at(channels, asset_id, ch, np.array([t1]), limits)[:, 0]
        tacc = tacc * params.accel_scale
        pa = np.zeros((len(ch.joints), 2))
        rs = params.rotation_accel_scale
        for s in range(n_steps):
            if springs is not None:
                sim.spring_substep(s, theta, omega, tau, ang, mid, tacc_mid, w_key, r_key, a_key)
            if len(sim.pair_anc):
                world = w_key[s] + sim.dyn_pick @ theta
                rate = r_key[s] + sim.dyn_pick @ omega
                contrib = rotation_pivot_terms(world[sim.pair_anc], rate[sim.pair_anc], a_key[s][sim.pair_anc],
                                               sim.pair_vec, rs)
                pa[sim.tops] = tacc[s] + sim.pair_sum @ contrib
            else:
                pa[sim.tops] = tacc[s]
            motion = sim.parent_motion(s, theta, omega, w_key, r_key, ang, end) if bounded else None
            system.step(theta, omega, pa, tau, motion)
        # Keys on a dynamic joint's channel pose the pendulum at that frame.
        for kd in dyn_idx:
            k = int(kd)
            chn = channels.get(angle_channel_id(asset_id, ch.joints[k].name))
            if chn is None:
                continue
            for key in chn.keys:
                if abs(key.time * fps - (frame + 1)) < 0.5:
                    theta[k] = key.value
                    omega[k] = 0.0
        return theta, omega, n_steps


def _initial_angles(doc: Document, asset_id: str, ch: Character, t0: float) -> FloatArray:
    """The simulation's start state: dynamic joints' keyed world angles at ``t0`` (else 0),
    spring joints on their keyed local angle (clamped to their limits)."""
    theta = np.zeros(len(ch.joints))
    for k, j in enumerate(ch.joints):
        if j.is_dynamic:
            chn = doc.channels.get(angle_channel_id(asset_id, j.name))
            if chn is not None and chn.keys:
                theta[k] = float(chn.evaluate(t0))
    if ch.spring.any():
        limits = joint_limits(doc, asset_id)
        keyed = _keyed_angles_at(doc.channels, asset_id, ch, np.array([t0]), limits)
        theta[ch.spring] = keyed[0, 0, ch.spring]
    return theta


def _initial_rates(doc: Document, asset_id: str, ch: Character, t0: float) -> FloatArray:
    """The start rates: 0 for pendulums; spring joints move with their keys."""
    omega = np.zeros(len(ch.joints))
    if ch.spring.any():
        keyed = _keyed_angles_at(doc.channels, asset_id, ch, np.array([t0]), joint_limits(doc, asset_id))
        omega[ch.spring] = keyed[1, 0, ch.spring]
    return omega


PENDULUM_CACHE = "pendulums"


def simulation(doc: Document) -> PendulumCache:
    """The document's pendulum cache, ``doc.caches["pendulums"]`` (created on first use)."""
    cache = doc.caches.get(PENDULUM_CACHE)
    if not isinstance(cache, PendulumCache):
        cache = PendulumCache(doc)
        doc.caches[PENDULUM_CACHE] = cache
    return cache


def ensure_caches(doc: Document) -> None:
    """Create ``doc``'s simulation caches now. An editor context calls it before it
    subscribes to the document, so that the caches drop what a change invalidates before any
    view hears of the change (listeners are told in the order they subscribed). The cloth
    caches live in ``doc.runtime`` and subscribe through their worker."""
    simulation(doc)


def simulation_ready(doc: Document, times: float | Iterable[float]) -> bool:
    """True when every 2D character's pendulums are simulated at ``times`` (so views that
    read the latest state show the exact one). Cheap; steps nothing."""
    cache = doc.caches.get(PENDULUM_CACHE)
    ts = [float(times)] if isinstance(times, (int, float)) else [float(t) for t in times]
    for aid in character_assets(doc):
        ch = doc.runtime.get(aid)
        if not isinstance(ch, Character) or not ch.simulated.any():
            continue
        if not isinstance(cache, PendulumCache) or not all(cache.ready(aid, t) for t in ts):
            return False
    return True


def simulated_frames(doc: Document) -> tuple[int, int] | None:
    """The frames ``(first, last)`` simulated for every 2D character with pendulums (last
    < first when none is yet); None when no character has pendulums."""
    cache = doc.caches.get(PENDULUM_CACHE)
    first = doc.frame_range[0]
    counts = []
    for aid in character_assets(doc):
        ch = doc.runtime.get(aid)
        if isinstance(ch, Character) and ch.simulated.any():
            counts.append(cache.cached_frames(aid) if isinstance(cache, PendulumCache) else 0)
    if not counts:
        return None
    return first, first + min(counts) - 1


def pendulum_problems(doc: Document) -> dict[str, PendulumBlowUp]:
    """The blow-ups that stopped the pendulum simulations, by character."""
    cache = doc.caches.get(PENDULUM_CACHE)
    if not isinstance(cache, PendulumCache):
        return {}
    found = {aid: cache.problem(aid) for aid in character_assets(doc)}
    return {aid: p for aid, p in found.items() if p is not None}


def channel_for(doc: Document, asset_id: str, joint_index: int) -> Channel | None:
    ch = character(doc, asset_id)
    return doc.channels.get(angle_channel_id(asset_id, ch.joints[joint_index].name))


def summary(doc: Document, asset_id: str) -> dict[str, Any]:
    ch = character(doc, asset_id)
    return {"joints": len(ch.joints), "dynamic": int(ch.dynamic.sum())}
