"""Spine JSON animation onto a 2D character (issue 15, item 7: re-import the bone hierarchy
and animation here to compare poses): the inverse of :mod:`qtanimator.document.spine_export`.

:func:`spine_import_command` reads a Spine 4.x JSON file (:func:`qtanimator.formats.spine.read_spine`)
and returns one undoable command that puts one of its animations onto an existing character
(asset kind ``character2d``). The GUI's entry point: push the command, then show
``command.unmatched`` / ``command.skipped`` / ``command.notes`` to the user.

Mapping (the export's, inverted):

* **Bones ↔ joints by name.** A bone named as a joint drives it. The bones above the root
  joint's bone (the export's ``root``, or ``root_2``… when a joint is called ``root``) hold
  the placement; every other bone without a joint of its name is reported in
  ``unmatched``, and when no bone matches a joint the import is refused (ValueError).
* **Rotation.** A Spine rotation is degrees counter-clockwise with y up; the rig's angle θ is
  counter-clockwise on the y-down screen with R(θ) = [[c, s], [−s, c]], which is the same
  turn, so a ``rotate`` key of ``value`` degrees becomes a key of radians(value) on the
  joint's ``angle`` channel. Spine's value is an offset from the bone's setup rotation and
  the rig's angle one from its rest pose: the file's setup pose is taken to be the rig's rest
  pose (the export's setup rotations are 0).
* **Translation.** The root joint's bone's ``translate`` (``translatex`` / ``translatey``)
  timeline becomes the character's translation channels ``x`` = x, ``y`` = −y (y down).
  Translate timelines on other bones are ignored (a rig's bones keep their lengths; noted).
* **Placement** (``placement=True`` only): the setup transform of the bones above the root
  joint's bone, y flipped back, becomes the character's authored placement (translation,
  rotation, uniform scale about the rest root pivot); a transform with shear or unequal
  scale is not applied (noted). By default the character keeps its own placement.
* **Time.** Time 0 of the animation is the document's range start; the range's end grows to
  show the whole animation (never shrinks).
* **Keys and curves** (exact, no resampling where possible):

  - linear (no curve) → a key with linear interpolation;
  - ``"stepped"`` → a key with constant (step) interpolation;
  - a Bézier ``[cx1, cy1, cx2, cy2]`` (absolute time and value of the two handles) → a
    cubic span whose key tangents are fixed slopes with handle weights (the channel's
    weighted tangents, :mod:`qtanimator.core.bezier`): out slope (cy1 − v1) / (cx1 − t1),
    weight cx1 − t1 on the key, in slope (v2 − cy2) / (t2 − cx2), weight t2 − cx2 on the next
    key. That span is the same cubic Bézier in (time, value) evaluated exactly, as
    :meth:`qtanimator.formats.spine.SpineTimeline.evaluate` does; handles at one and two
    thirds of the span get no weights (they are then exactly a cubic Hermite span). A span
    whose handles cannot be weights (a handle at or beyond its own key's time, or the two
    handles overlapping in time) is sampled at :data:`BEZIER_SAMPLES` points with linear
    keys instead (noted);
  - before a timeline's first key Spine shows the setup pose: a timeline starting after time
    0 gets a step key holding 0 at the range start. Two keys at the same time keep the later
    one (the value Spine shows from that time on).

* Each imported channel is replaced as a whole (extrapolation constant, as Spine holds the
  last key); joints the animation has no timeline for keep their channels. Pendulum
  (dynamic) joints are driven by the simulation and their channels hold world angles, so
  their timelines are not imported (``skipped``); spring joints' channels hold the keyed
  local angle the spring follows, and get the timeline.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from typing import Any

import numpy as np

from qtanimator.core.channel import Channel, Interpolation, Key, Tangent
from qtanimator.document.character2d_asset import (
    ASSET_KIND,
    angle_channel_id,
    character,
    position_channel_ids,
)
from qtanimator.document.commands import Command, Macro, SetChannels, SetParameter
from qtanimator.document.document import Document
from qtanimator.document.placement import PLACEMENT, set_placement_command
from qtanimator.formats.spine import BEZIER, STEPPED, SpineData, SpineKey, SpineTimeline, bezier_value, read_spine

#: Linear keys per Bézier span that cannot be held exactly as weighted tangents.
BEZIER_SAMPLES = 32
#: Relative tolerance on handle times: at a third of the span, and handles filling the span.
_THIRD_TOLERANCE = 1e-12
FLIP = np.diag([1.0, -1.0, 1.0])


class SpineImportCommand(Macro):
    """One undo step putting a Spine animation onto a character, with what it did:
    ``animation`` the name imported, ``matched`` the joints driven (by name), ``unmatched``
    the file's bones that are no joint of the character (placement bones excluded),
    ``skipped`` joints whose timelines were not imported (pendulums), ``notes`` plain
    sentences for the user (ignored timelines, sampled curves, the range grown)."""

    def __init__(self, text: str, commands: Sequence[Command], animation: str, matched: list[str],
                 unmatched: list[str], skipped: list[str], notes: list[str]) -> None:
        super().__init__(text, commands)
        self.animation = animation
        self.matched = matched
        self.unmatched = unmatched
        self.skipped = skipped
        self.notes = notes


# --------------------------------------------------------------------------- channels
def _unique_times(keys: Sequence[SpineKey]) -> list[SpineKey]:
    """The keys with one per time: the later of two at the same time."""
    return [k for n, k in enumerate(keys) if n + 1 == len(keys) or keys[n + 1].time != k.time]


def timeline_channel(timeline: SpineTimeline, index: int, scale: float, t0: float) -> tuple[Channel, int]:
    """The channel of one value (``index``) of a timeline: Spine time ``s`` at document time
    ``t0 + s``, values times ``scale`` (radians per degree, or ±1 for translations). Returns
    the channel and the number of Bézier spans that had to be sampled."""
    keys = _unique_times(timeline.keys)
    out: list[dict[str, Any]] = []
    if keys[0].time > 0.0:  # Spine shows the setup pose before the first key
        out.append({"time": t0, "value": 0.0, "interpolation": Interpolation.CONSTANT})
    sampled = 0
    for n, k in enumerate(keys):
        key: dict[str, Any] = {"time": t0 + k.time, "value": scale * k.values[index]}
        if out and "next_in" in out[-1]:
            key.update(out[-1].pop("next_in"))
        out.append(key)
        if n + 1 == len(keys):
            key["interpolation"] = Interpolation.LINEAR
            break
        nxt = keys[n + 1]
        if k.curve == STEPPED:
            key["interpolation"] = Interpolation.CONSTANT
        elif k.curve == BEZIER:
            cx1, cy1, cx2, cy2 = k.bezier[index]
            span = nxt.time - k.time
            wa, wb = cx1 - k.time, nxt.time - cx2
            va, vb = k.values[index], nxt.values[index]
            if wa > 0.0 and wb > 0.0 and wa + wb <= span * (1.0 + _THIRD_TOLERANCE):
                thirds = (abs(wa - span / 3.0) <= _THIRD_TOLERANCE * span
                          and abs(wb - span / 3.0) <= _THIRD_TOLERANCE * span)
                key.update({"interpolation": Interpolation.CUBIC, "out_tangent": Tangent.FIXED,
                            "out_slope": scale * (cy1 - va) / wa, "out_weight": None if thirds else wa,
                            "next_in": {"in_tangent": Tangent.FIXED, "in_slope": scale * (vb - cy2) / wb,
                                        "in_weight": None if thirds else wb}})
            else:
                sampled += 1
                key["interpolation"] = Interpolation.LINEAR
                for j in range(1, BEZIER_SAMPLES):
                    s = k.time + span * j / BEZIER_SAMPLES
                    v = bezier_value(s, k.time, va, cx1, cy1, cx2, cy2, nxt.time, vb)
                    out.append({"time": t0 + s, "value": scale * v, "interpolation": Interpolation.LINEAR})
        else:
            key["interpolation"] = Interpolation.LINEAR
    made = []
    for d in out:
        d.pop("next_in", None)
        d.setdefault("in_tangent", Tangent.LINEAR)
        d.setdefault("out_tangent", Tangent.LINEAR)
        made.append(Key(**d))
    return Channel(made), sampled


# --------------------------------------------------------------------------- placement
def _placement_from_bones(data: SpineData, root_bone: str, pivot: np.ndarray) -> dict[str, Any] | None | str:
    """The placement property the bones above ``root_bone`` hold (None: identity), or a
    sentence saying why it cannot be one."""
    world = np.eye(3)
    for b in reversed(data.ancestors(root_bone)):
        world = world @ np.array(b.local_matrix())
    p = FLIP @ world @ FLIP
    lin = p[:2, :2]
    scale = math.sqrt(max(float(np.linalg.det(lin)), 0.0))
    size = max(float(np.abs(lin).max()), 1e-300)
    if (scale == 0.0 or abs(lin[0, 0] - lin[1, 1]) > 1e-9 * size or abs(lin[0, 1] + lin[1, 0]) > 1e-9 * size):
        return "the bones above the root joint's bone shear or scale unevenly, so they are no placement"
    phi = math.degrees(math.atan2(lin[0, 1], lin[0, 0]))
    translate = p[:2, 2] - pivot + lin @ pivot
    if abs(scale - 1.0) <= 1e-12 and abs(phi) <= 1e-12 and np.abs(translate).max() <= 1e-12:
        return None
    return {"translate": [float(translate[0]) + 0.0, float(translate[1]) + 0.0], "rotate": phi + 0.0,
            "scale": scale}


# --------------------------------------------------------------------------- the command
def spine_import_command(doc: Document, asset_id: str, path: str | os.PathLike[str] | SpineData,
                         animation: str | None = None, placement: bool = False) -> SpineImportCommand:
    """One undoable command putting the Spine animation ``animation`` (None: the file's
    first) of the JSON file ``path`` onto the 2D character ``asset_id`` (see the module
    docstring for the mapping). Raises FormatError for an unreadable file and ValueError
    (a plain sentence) for a file without that animation or whose bones match none of the
    character's joints."""
    asset = doc.assets.get(asset_id)
    if asset is None or asset.kind != ASSET_KIND:
        raise ValueError(f"'{asset_id}' is not a 2D character, so a Spine animation cannot go onto it.")
    data = path if isinstance(path, SpineData) else read_spine(path)
    if not data.animations:
        raise ValueError(f"{os.path.basename(data.path)} has no animations.")
    if animation is None:
        animation = next(iter(data.animations))
    anim = data.animations.get(animation)
    if anim is None:
        raise ValueError(f"{os.path.basename(data.path)} has no animation '{animation}'; it has "
                         + ", ".join(f"'{a}'" for a in data.animations) + ".")
    ch = character(doc, asset_id)
    joints = {j.name: k for k, j in enumerate(ch.joints)}
    root_name = ch.joints[0].name
    root_bone = data.bone(root_name)
    above = {b.name for b in data.ancestors(root_name)} if root_bone is not None else set()
    matched = [b.name for b in data.bones if b.name in joints]
    unmatched = [b.name for b in data.bones if b.name not in joints and b.name not in above]
    if not matched:
        raise ValueError(f"none of the bones of {os.path.basename(data.path)} ("
                         + ", ".join(b.name for b in data.bones)
                         + f") is a joint of '{asset_id}', so there is nothing to import.")

    t0 = doc.frame_to_time(doc.frame_range[0])
    notes = [f"Ignored: {what}." for what in anim.ignored]
    skipped: list[str] = []
    sampled = 0
    new: dict[str, Channel] = {}
    radians = math.pi / 180.0
    for bone, timelines in anim.bones.items():
        k = joints.get(bone)
        if k is None:
            if timelines:
                notes.append(f"The timelines of the bone '{bone}' are ignored: the character has no such joint.")
            continue
        for kind, tl in timelines.items():
            if not tl.keys:
                continue
            if kind == "rotate":
                if ch.joints[k].is_dynamic:
                    skipped.append(bone)
                    continue
                new[angle_channel_id(asset_id, bone)], n = timeline_channel(tl, 0, radians, t0)
                sampled += n
            elif k != 0:
                notes.append(f"The {kind} timeline of '{bone}' is ignored: only the root joint moves.")
            else:
                cx, cy = position_channel_ids(asset_id)
                targets = {"translate": [(cx, 0, 1.0), (cy, 1, -1.0)], "translatex": [(cx, 0, 1.0)],
                           "translatey": [(cy, 0, -1.0)]}[kind]
                for cid, index, scale in targets:
                    new[cid], n = timeline_channel(tl, index, scale, t0)
                    sampled += n
    if skipped:
        notes.append("Pendulum joints follow the simulation; their rotate timelines are not imported: "
                     + ", ".join(skipped) + ".")
    if sampled:
        notes.append(f"{sampled} Bézier curve span(s) whose handles are no tangent weights were sampled "
                     f"with {BEZIER_SAMPLES} linear keys each.")
    text = f"Import Spine animation {animation}"
    commands: list[Command] = []
    changes: dict[str, tuple[Channel | None, Channel | None]] = {
        cid: (doc.channels.get(cid), c) for cid, c in new.items() if doc.channels.get(cid) != c}
    if changes:
        commands.append(SetChannels(text, changes))
    if placement and root_bone is not None:
        value = _placement_from_bones(data, root_name, ch.rest_pivots[0])
        if isinstance(value, str):
            notes.append(f"The placement is not applied: {value}.")
        elif value != asset.properties.get(PLACEMENT):
            commands.append(set_placement_command(doc, asset_id, value))
    end_time = t0 + anim.duration
    end_frame = int(math.ceil(doc.time_to_frame(end_time) - 1e-6))
    if end_frame > doc.frame_range[1]:
        notes.append(f"Frame range extended to {doc.frame_range[0]}–{end_frame} to show the whole animation.")
        commands.append(SetParameter(doc, "frame_end", end_frame))
    return SpineImportCommand(text, commands, animation, matched, unmatched, skipped, notes)
