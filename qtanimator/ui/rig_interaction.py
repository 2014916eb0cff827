"""What the mouse does in the 2D rig editor, as plain functions and generators (no Qt).

A drag is a generator (as in napari's mouse bindings): prime it with ``next(drag)``, then
``drag.send(cursor)`` for each mouse move returns the command for that position, built
from the document as it is now. The editor feeds each command to the gesture protocol
(:class:`qtanimator.document.gesture.Gesture`: ``update`` previews it, ``commit`` makes the
drag one undo step, ``abort`` — Escape — takes it back exactly).

Points are world (scene) coordinates: SVG user units, y down.
"""

from __future__ import annotations

import math
from collections.abc import Generator, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.document import character2d as c2d
from qtanimator.document import pose
from qtanimator.document.commands import Command
from qtanimator.document.document import Document, channel_id
from qtanimator.document.outliner import pickable

FloatArray = npt.NDArray[np.float64]
Drag = Generator["Command | None", Any, None]

#: Hit-test tolerance in scene units for thin strokes.
PICK_TOLERANCE = 2.0


# ----------------------------------------------------------------------- scene
def character_ids(doc: Document) -> list[str]:
    """The 2D characters of the document in draw order (later ones on top)."""
    kind = c2d.ASSET_KIND
    return [aid for aid, a in doc.assets.items() if a.kind == kind and aid in doc.runtime]


def pick(doc: Document, time: float, point: Sequence[float],
         tolerance: float = PICK_TOLERANCE) -> tuple[str, int] | None:
    """The topmost (character, joint index) under ``point``, or None. Picks what the editor
    shows: pendulums at their latest simulated state (nothing is simulated here)."""
    for aid in reversed(character_ids(doc)):
        if not pickable(doc, aid):
            continue  # hidden or locked in the outliner
        character = doc.runtime[aid]
        pose = c2d.evaluate_pose(doc, aid, time, block=False)
        j = character.hit_test(pose, np.asarray(point, dtype=np.float64), tolerance)
        if j is not None:
            return aid, int(j)
    return None


def rotation_delta(pivot: Sequence[float], press: Sequence[float], cursor: Sequence[float]) -> float:
    """The joint angle (counter-clockwise on a y-down screen) carrying the press direction
    onto the cursor direction about ``pivot`` — the reference's atan2(a×b, a·b)."""
    ax, ay = cursor[0] - pivot[0], cursor[1] - pivot[1]
    bx, by = press[0] - pivot[0], press[1] - pivot[1]
    if (ax == 0 and ay == 0) or (bx == 0 and by == 0):
        return 0.0
    return math.atan2(ax * by - ay * bx, ax * bx + ay * by)


def nearest_allowed_angle(angle: float, lo: float, hi: float) -> float:
    """The angle within ``lo``…``hi`` that points nearest to ``angle``: ``angle`` itself,
    else ``angle`` ± whole turns when that lies inside, else the limit the shorter way
    round (a joint dragged past its limit stops at it and follows the cursor back)."""
    if lo <= angle <= hi:
        return angle
    turn = 2.0 * math.pi
    turns = range(math.ceil((lo - angle) / turn), math.floor((hi - angle) / turn) + 1)
    if turns:
        return min(max(angle + min(turns, key=abs) * turn, lo), hi)
    to_lo = abs(math.remainder(angle - lo, turn))
    to_hi = abs(math.remainder(angle - hi, turn))
    return lo if to_lo < to_hi else hi


# ------------------------------------------------------------------------ drags
def pose_edit(doc: Document, values: dict[str, float], time: float, text: str, autokey: bool) -> Command:
    """What a drag does with new channel values: key them (auto-key on, key-all
    respected) or only show them as the pending, unkeyed pose (auto-key off)."""
    if autokey:
        return c2d.key_values(doc, values, time, text)  # clamps to the joint limits
    return pose.PosePreview(doc, c2d.clamp_values(doc, values, time), time, text)


def rotate_drag(doc: Document, asset: str, joint: int, press: Sequence[float], time: float,
                autokey: bool = True) -> Drag:
    """Left-drag on a joint: rotate it about its pivot following the cursor (from the pose
    the editor shows), within the joint's limits (:func:`nearest_allowed_angle`)."""
    shown = c2d.evaluate_pose(doc, asset, time, block=False)
    pivot = shown.pivots[joint].copy()
    start = float(np.asarray(c2d.joint_angles(doc, asset, time, block=False))[joint])
    name = doc.runtime[asset].joints[joint].name
    cursor = yield None
    while True:
        angle = start + rotation_delta(pivot, press, cursor)
        limit = c2d.joint_limits(doc, asset)[joint]
        if limit is not None:
            angle = nearest_allowed_angle(angle, *limit)
        values = c2d.joint_value(doc, asset, joint, angle, time)
        cursor = yield pose_edit(doc, values, time, f"Rotate {name}", autokey)


def move_drag(doc: Document, asset: str, press: Sequence[float], time: float, autokey: bool = True) -> Drag:
    """Left-drag on a root joint: move the character (a position key at ``time``)."""
    start = np.asarray(c2d.translation(doc, asset, time), dtype=np.float64).copy()
    p0 = np.asarray(press, dtype=np.float64)
    cursor = yield None
    while True:
        xy = start + c2d.to_character_frame(doc, asset, np.asarray(cursor, dtype=np.float64) - p0, vector=True)
        cursor = yield pose_edit(doc, c2d.position_values(asset, xy), time, f"Move {asset}", autokey)


def ik_drag(doc: Document, asset: str, joint: int, press: Sequence[float], time: float,
            autokey: bool = True) -> Drag:
    """Right-drag: pull the picked point of ``joint`` towards the cursor with the IK solver.
    Whatever the IK settings, ``character2d.ik_drag`` makes the keys (auto-key on) and
    ``character2d.ik_values`` the unkeyed pose (auto-key off): one solve, one keyer."""
    pose_now = c2d.evaluate_pose(doc, asset, time, block=False)
    local = pose_now.to_local(joint, np.asarray(press, dtype=np.float64))
    cursor = yield None
    while True:
        target = np.asarray(cursor, dtype=np.float64)
        if autokey:
            command = c2d.ik_drag(doc, asset, joint, local, target, time)
        else:
            command = pose.PosePreview(doc, c2d.ik_values(doc, asset, joint, local, target, time), time,
                                       "IK drag")
        cursor = yield command


#: Placement scale drags (Alt+Shift+left-drag): the scale doubles for every this many pixels
#: the cursor moves right (halves moving left), so it stays above zero.
SCALE_DOUBLING_PX = 100.0


def placement_move_drag(doc: Document, asset: str, press: Sequence[float]) -> Drag:
    """Alt+left-drag on a character: move its authored placement (issue 14) with the cursor —
    translate = translate at the press + cursor − press (scene units)."""
    from qtanimator.document.placement import placement_of, set_placement_command

    start = placement_of(doc, asset, 2)
    t0 = np.asarray(start["translate"], dtype=np.float64)
    p0 = np.asarray(press, dtype=np.float64)
    cursor = yield None
    while True:
        t = t0 + (np.asarray(cursor, dtype=np.float64) - p0)
        cursor = yield set_placement_command(doc, asset, {**start, "translate": [float(t[0]), float(t[1])]},
                                             text=f"Place {asset}")


def placement_scale(start: float, dx_px: float) -> float:
    """The uniform scale after a horizontal drag of ``dx_px`` pixels: ``start · 2^(dx/100)``."""
    return float(start) * 2.0 ** (float(dx_px) / SCALE_DOUBLING_PX)


def placement_scale_drag(doc: Document, asset: str, press: Sequence[float], pixel_size: float) -> Drag:
    """Alt+Shift+left-drag on a character: scale its placement uniformly about its pivot (the
    rest root pivot, :func:`qtanimator.document.placement.matrix2d`) by the horizontal motion
    (:func:`placement_scale`; ``pixel_size`` is scene units per pixel)."""
    from qtanimator.document.placement import placement_of, set_placement_command

    start = placement_of(doc, asset, 2)
    x0 = float(press[0])
    cursor = yield None
    while True:
        s = placement_scale(start["scale"], (float(cursor[0]) - x0) / pixel_size)
        cursor = yield set_placement_command(doc, asset, {**start, "scale": s}, text=f"Scale {asset}")


def ik_source(doc: Document, asset: str, joint: int, press: Sequence[float], time: float) -> FloatArray:
    """The rest-pose point of ``joint`` under ``press`` (kept for the debug dot)."""
    pose = c2d.evaluate_pose(doc, asset, time, block=False)
    return np.asarray(pose.to_local(joint, np.asarray(press, dtype=np.float64)), dtype=np.float64)


# ------------------------------------------------------------------ joint limits
def rest_direction(character: Any, joint: int) -> FloatArray:
    """The unit direction a joint points along in the rest pose: towards its first child's
    pivot, else its centre of mass, else +x."""
    j = character.joints[joint]
    target = character.joints[j.children[0]].pivot if j.children else j.centroid
    d = np.asarray(target, dtype=np.float64) - np.asarray(j.pivot, dtype=np.float64)
    n = float(np.hypot(*d))
    return np.array([1.0, 0.0]) if n < 1e-9 else d / n


def limit_wedge(character: Any, pose: Any, joint: int, limit: tuple[float, float], radius: float,
                segments_per_turn: int = 96) -> FloatArray:
    """The outline (N, 2) of a joint's allowed range: from the pivot out to the joint's
    direction at the lower limit, along the arc of ``radius`` to the upper limit, back to
    the pivot. Directions are the rest direction turned by the parent's world angle plus
    the limit, so the wedge turns with the parent. A range of a whole turn or more is a
    circle (no radii)."""
    lo, hi = limit
    pivot = np.asarray(pose.pivots[joint], dtype=np.float64)
    parent = character.joints[joint].parent
    base = 0.0 if parent is None else float(pose.world_angles[parent])
    ref = rest_direction(character, joint)
    full = hi - lo >= 2.0 * math.pi
    if full:
        hi = lo + 2.0 * math.pi
    n = max(2, math.ceil((hi - lo) / (2.0 * math.pi) * segments_per_turn)) + 1
    theta = base + np.linspace(lo, hi, n)
    c, s = np.cos(theta), np.sin(theta)
    # R(θ)·ref with R(θ) = [[cos θ, sin θ], [−sin θ, cos θ]] (counter-clockwise on screen).
    arc = pivot + radius * np.stack([c * ref[0] + s * ref[1], -s * ref[0] + c * ref[1]], axis=1)
    if full:
        return np.asarray(arc, dtype=np.float64)
    return np.vstack([pivot, arc, pivot])


# --------------------------------------------------------------- debug overlays
def gradient_arrows(character: Any, pose: Any, gradient: FloatArray,
                    scale: float = 0.1) -> list[tuple[FloatArray, FloatArray]]:
    """Arrows (start, end) at each joint's first child, perpendicular to joint → child,
    of length ``scale · D`` (the reference's debug drawing)."""
    arrows = []
    for j, joint in enumerate(character.joints):
        if not joint.children or gradient[j] == 0:
            continue
        start = pose.pivots[joint.children[0]]
        e1 = start - pose.pivots[j]
        n = float(np.hypot(*e1))
        if n == 0:
            continue
        e1 = e1 / n
        e2 = np.array([-e1[1], e1[0]])
        arrows.append((start.copy(), start + e2 * scale * gradient[j]))
    return arrows


@dataclass(frozen=True)
class PathKey:
    """The character's root at one key of its position channels (per-second derivatives)."""

    time: float
    position: FloatArray
    velocity: FloatArray
    acceleration: FloatArray


def _xy_channels(doc: Document, asset: str) -> tuple[Any, Any]:
    return doc.channels.get(channel_id(asset, "", "x")), doc.channels.get(channel_id(asset, "", "y"))


def _eval(channel: Any, t: Any, d: int = 0) -> Any:
    if channel is None:
        return np.zeros_like(np.asarray(t, dtype=np.float64))
    return np.asarray(channel.evaluate(np.asarray(t, dtype=np.float64), d), dtype=np.float64)


def character_path(doc: Document, asset: str, frames: Sequence[float] | FloatArray) -> FloatArray:
    """Root pivot positions (N, 2) at ``frames`` (the debug spline)."""
    character = doc.runtime[asset]
    t = np.asarray(frames, dtype=np.float64) / doc.fps
    cx, cy = _xy_channels(doc, asset)
    pivot = character.joints[0].pivot
    return np.stack([_eval(cx, t) + pivot[0], _eval(cy, t) + pivot[1]], axis=1)


def path_keys(doc: Document, asset: str) -> list[PathKey]:
    """Position, velocity and acceleration at each key time of the position channels."""
    cx, cy = _xy_channels(doc, asset)
    times = sorted({k.time for ch in (cx, cy) if ch is not None for k in ch.keys})
    if not times:
        return []
    pivot = doc.runtime[asset].joints[0].pivot
    t = np.asarray(times)
    pos = np.stack([_eval(cx, t) + pivot[0], _eval(cy, t) + pivot[1]], axis=1)
    vel = np.stack([_eval(cx, t, 1), _eval(cy, t, 1)], axis=1)
    acc = np.stack([_eval(cx, t, 2), _eval(cy, t, 2)], axis=1)
    return [PathKey(float(t[i]), pos[i], vel[i], acc[i]) for i in range(len(times))]


def hud_lines(doc: Document, asset: str, joint: int | None, time: float) -> list[str]:
    """The HUD text: the character's position / velocity / acceleration and the joint's
    type with its angle (keyframed) or θ and ω (dynamic: the latest simulated state, never
    simulated here; a line says which frame it is from until the worker catches up)."""
    character = doc.runtime[asset]
    cx, cy = _xy_channels(doc, asset)
    pos = (float(_eval(cx, time)), float(_eval(cy, time)))
    vel = (float(_eval(cx, time, 1)), float(_eval(cy, time, 1)))
    acc = (float(_eval(cx, time, 2)), float(_eval(cy, time, 2)))
    lines = [f"CHARACTER  {asset}",
             f"position      ({pos[0]:8.2f}, {pos[1]:8.2f})",
             f"velocity      ({vel[0]:8.2f}, {vel[1]:8.2f}) /s",
             f"acceleration  ({acc[0]:8.2f}, {acc[1]:8.2f}) /s²"]
    if joint is None:
        return lines
    j = character.joints[joint]
    lines.append(f"JOINT  {j.name}")
    if j.is_dynamic:
        frame = int(round(doc.time_to_frame(time)))
        theta_all, omega_all, shown = c2d.simulation(doc).latest_state(asset, frame)
        theta, omega = float(theta_all[joint]), float(omega_all[joint])
        lines += ["type          dynamic (pendulum)",
                  f"θ             {math.degrees(theta):8.2f}°",
                  f"ω             {math.degrees(omega):8.2f}°/s"]
        if shown < frame:
            lines.append(f"simulating…   (frame {shown} shown)")
    else:
        angle = float(np.asarray(c2d.joint_angles(doc, asset, time, block=False))[joint])
        lines += ["type          keyframed", f"angle         {math.degrees(angle):8.2f}°"]
    return lines


# -------------------------------------------------------------------- onion skin
@dataclass(frozen=True)
class OnionSettings:
    enabled: bool = False
    before: int = 2
    after: int = 2
    step: int = 5
    before_tint: tuple[int, int, int] = (220, 60, 60)
    after_tint: tuple[int, int, int] = (60, 160, 60)
    opacity: float = 0.35


def onion_frames(frame: float, settings: OnionSettings, first: int, last: int) -> list[tuple[float, str, float]]:
    """Ghost frames ``(frame, 'before' | 'after', opacity)``, farthest first, inside the
    range; opacity fades with distance."""
    if not settings.enabled or settings.step <= 0:
        return []
    ghosts: list[tuple[float, str, float]] = []
    for side, count, sign in (("before", settings.before, -1), ("after", settings.after, 1)):
        for i in range(count, 0, -1):
            f = frame + sign * i * settings.step
            if first <= f <= last:
                ghosts.append((float(f), side, settings.opacity * (1.0 - (i - 1) / max(count, 1))))
    return ghosts


# ------------------------------------------------------------- set key, copy, paste
class PoseClipboard:
    """The copied pose, shared by the 2D editor and the 3D view (one per application, so a
    pose copied in one project pastes in another)."""

    def __init__(self) -> None:
        self.clip: pose.PoseClip | None = None


pose_clipboard = PoseClipboard()


def set_key_command(doc: Document, selection: tuple[str, str], time: float,
                    whole_character: bool = False) -> Command | None:
    """S / I: key the selected joint (with the character selected: its root and
    position); Shift+S (``whole_character``): every joint of the selected character.
    None when no character is selected."""
    asset, joint = selection
    if not asset or not pose.is_character(doc, asset):
        return None
    try:
        if whole_character:
            return pose.key_character_command(doc, asset, time)
        return pose.key_selection_command(doc, asset, joint, time)
    except (KeyError, ValueError):
        return None  # the selected joint is not there (any more)


def copy_selection(doc: Document, selection: tuple[str, str], time: float) -> pose.PoseClip | None:
    """Ctrl+C: the selected joint's pose, or the whole character's when the character (its
    root in the 2D editor) is selected. None when no character is selected."""
    asset, joint = selection
    if not asset or not pose.is_character(doc, asset):
        return None
    try:
        return pose.copy_pose(doc, asset, joint, time)
    except (KeyError, ValueError):
        return None


def paste_command(doc: Document, clip: pose.PoseClip | None, selection: tuple[str, str], time: float,
                  mirrored: bool = False) -> Command | None:
    """Ctrl+V / Ctrl+Shift+V: key the copied pose on the selected character (the one it
    was copied from when none is selected) at ``time``; None when it does not fit."""
    if clip is None:
        return None
    asset = selection[0] or clip.source
    if not asset or not pose.is_character(doc, asset):
        return None
    return pose.paste_pose_command(doc, clip, asset, time, mirrored)


# -------------------------------------------------------------- rig mode (setup)
#: How near (in pixels) a press must be to a pivot marker to grab it in rig mode.
PIVOT_GRAB_PX = 8.0


def rig_poses(doc: Document, time: float) -> dict[str, Any]:
    """Rig mode shows the setup (rest) pose of each character, at its position at ``time``."""
    out = {}
    for aid in character_ids(doc):
        ch = doc.runtime[aid]
        out[aid] = ch.pose(np.zeros(len(ch.joints)), c2d.translation(doc, aid, time)).placed(
            c2d.placement_matrix(doc, aid))
    return out


def pick_rest(doc: Document, time: float, point: Sequence[float],
              tolerance: float = PICK_TOLERANCE) -> tuple[str, int] | None:
    """The topmost (character, joint) under ``point`` in the setup pose (rig mode)."""
    poses = rig_poses(doc, time)
    for aid in reversed(character_ids(doc)):
        if not pickable(doc, aid):
            continue
        j = doc.runtime[aid].hit_test(poses[aid], np.asarray(point, dtype=np.float64), tolerance)
        if j is not None:
            return aid, int(j)
    return None


def pivot_at(doc: Document, time: float, point: Sequence[float], radius: float) -> tuple[str, int] | None:
    """The pivot marker nearest ``point`` within ``radius`` (scene units), in rig mode;
    the last drawn wins a tie."""
    best: tuple[float, tuple[str, int]] | None = None
    q = np.asarray(point, dtype=np.float64)
    for aid, pose_ in rig_poses(doc, time).items():
        d = np.hypot(*(pose_.pivots - q).T)
        for j in np.flatnonzero(d <= radius):
            if best is None or d[j] <= best[0]:
                best = (float(d[j]), (aid, int(j)))
    return None if best is None else best[1]


def pivot_drag(doc: Document, asset: str, joint: int, press: Sequence[float]) -> Drag:
    """Left-drag on a pivot marker in rig mode: move the joint's rest pivot with the cursor."""
    from qtanimator.document import rigging

    ch = doc.runtime[asset]
    name = ch.joints[joint].name
    start = np.asarray(ch.rest_pivots[joint], dtype=np.float64).copy()
    p0 = np.asarray(press, dtype=np.float64)
    cursor = yield None
    while True:
        xy = start + (np.asarray(cursor, dtype=np.float64) - p0)
        cursor = yield rigging.set_pivot_command(doc, asset, name, (float(xy[0]), float(xy[1])))
