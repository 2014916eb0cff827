"""The clips of 3D characters and the frame range they set.

A character from glTF may have several **clips** (the file's animations,
:class:`~qtanimator.document.character3d_model.ClipSource`). The document's channels hold the
active clip (asset property ``clip``); :func:`set_clip_command` makes another clip active,
putting the edited channels of the one left in the asset property ``clip_store`` so that
they survive (and are saved). :func:`clip_from_document` gives the channels as an ``.anim``
clip.
"""

from __future__ import annotations

import numpy as np

from qtanimator.core.channel import Channel, Key
from qtanimator.core.clip import AnimationClip
from qtanimator.document.channels3d import channel_ids
from qtanimator.document.character3d_model import CLIP, CLIP_STORE, ClipSource, character
from qtanimator.document.commands import Command, Macro, SetAssetProperty, SetChannels, SetParameter
from qtanimator.document.document import Document
from qtanimator.document.rotation_mode import in_rotation_mode


def clip_from_document(doc: Document, asset_id: str, start: float | None = None,
                       end: float | None = None) -> AnimationClip:
    """The character's channels as an ``.anim`` clip (for :func:`qtanimator.formats.anim.save_anim`).

    A DOF without a channel becomes a one-key constant channel holding the file's pose
    value (root translation: the skeleton's). The range defaults to the document's.
    """
    ch = character(doc, asset_id)
    first, last = doc.frame_range
    t0 = doc.frame_to_time(first) if start is None else float(start)
    t1 = doc.frame_to_time(last) if end is None else float(end)
    rest = [*ch.skeleton.root_translation.tolist(), *ch.skeleton.dof_values().reshape(-1).tolist()]
    channels = []
    for cid, value in zip(channel_ids(doc, asset_id), rest):
        existing = doc.channels.get(cid)
        channels.append(existing if existing is not None and existing.keys else Channel([Key(t0, value)]))
    return AnimationClip(channels, t0, max(t0, t1))


def active_clip(doc: Document, asset_id: str) -> ClipSource | None:
    """The clip whose channels the document holds (None: the character has no clips)."""
    ch = character(doc, asset_id)
    name = doc.assets[asset_id].properties.get(CLIP)
    found = ch.clip_named(name) if isinstance(name, str) else None
    return found


def clip_channels_of(doc: Document, asset_id: str, name: str) -> dict[str, Channel]:
    """A clip's channels by document channel id: the document's for the active clip, the
    edited ones kept in ``clip_store`` for a clip left, else the file's."""
    ch = character(doc, asset_id)
    clip = ch.clip_named(name)
    if clip is None:
        raise KeyError(f"{asset_id!r} has no clip {name!r}")
    active = active_clip(doc, asset_id)
    if active is not None and active.name == name:
        return dict(doc.channels_of(asset_id))
    stored = (doc.assets[asset_id].properties.get(CLIP_STORE) or {}).get(name)
    if isinstance(stored, dict):
        rel = {r: Channel.from_dict(d) for r, d in stored.items()}
    else:
        rel = dict(clip.channels)
    # The file's keys are quaternions; joints switched to Euler get them converted.
    rel = in_rotation_mode(ch, rel, doc.fps)
    return {f"{asset_id}/{r}": c for r, c in rel.items()}


def clip_duration(doc: Document, asset_id: str, name: str) -> tuple[float, float]:
    """``(start, end)`` of a clip: the file's, or its keys' where the user keyed beyond them."""
    ch = character(doc, asset_id)
    clip = ch.clip_named(name)
    if clip is None:
        raise KeyError(f"{asset_id!r} has no clip {name!r}")
    start, end = clip.start, clip.end
    for c in clip_channels_of(doc, asset_id, name).values():
        if c.keys:
            start, end = min(start, c.keys[0].time), max(end, c.keys[-1].time)
    return start, end


def clip_range_command(doc: Document, start: float, end: float, fps: float | None = None) -> Command | None:
    """The document's frame range set to the frames covering ``start … end`` seconds (None:
    it is that already). ``fps`` counts the frames at another rate than the document's (a
    command that also changes it)."""
    rate = doc.fps if fps is None else float(fps)
    first = int(np.floor(start * rate + 1e-6))
    last = max(first, int(np.ceil(end * rate - 1e-6)))
    commands: list[Command] = []
    if doc.frame_range[0] != first:
        commands.append(SetParameter(doc, "frame_start", first))
    if doc.frame_range[1] != last:
        commands.append(SetParameter(doc, "frame_end", last))
    if first > doc.frame_range[1]:
        commands.reverse()  # the end moves first, so that start never passes end
    if not commands:
        return None
    return commands[0] if len(commands) == 1 else Macro("Frame range", commands)


def set_fps_command(doc: Document, fps: float) -> Command:
    """One undo step that sets the project's frame rate (the ``fps`` parameter) and keeps
    the frame range's time: keys are in seconds and stay, ``frame_start`` / ``frame_end``
    are rescaled to the frames covering the same seconds at the new rate (the start rounded
    down, the end up). Raises ValueError for a rate that is not a positive number."""
    rate = float(fps)
    if not (np.isfinite(rate) and rate > 0):
        raise ValueError(f"frame rate must be a positive number, not {fps!r}")
    value: float | int = int(rate) if rate.is_integer() else rate
    first, last = doc.frame_range
    commands: list[Command] = [SetParameter(doc, "fps", value)]
    rng = clip_range_command(doc, doc.frame_to_time(first), doc.frame_to_time(last), rate)
    if rng is not None:
        commands.append(rng)
    return Macro(f"Frame rate {rate:g} fps", commands)


def set_clip_command(doc: Document, asset_id: str, name: str) -> Command:
    """One undo step that makes the clip ``name`` the character's active one: the
    document's channels of the character become that clip's, the channels of the clip
    left are kept (edits included) in ``clip_store``, and the frame range fits the clip.

    Raises KeyError for an unknown clip."""
    ch = character(doc, asset_id)
    if ch.clip_named(name) is None:
        raise KeyError(f"{asset_id!r} has no clip {name!r}")
    asset = doc.assets[asset_id]
    current = active_clip(doc, asset_id)
    new_channels = clip_channels_of(doc, asset_id, name)
    store = {k: v for k, v in (asset.properties.get(CLIP_STORE) or {}).items() if k != name}
    if current is not None and current.name != name:
        store[current.name] = {cid[len(asset_id) + 1:]: c.to_dict() for cid, c in doc.channels_of(asset_id)}
    old = dict(doc.channels_of(asset_id))
    changes = {cid: (old.get(cid), new_channels.get(cid)) for cid in dict.fromkeys([*old, *new_channels])}
    commands: list[Command] = [
        SetChannels(f"Clip {name}", changes),
        SetAssetProperty(doc, asset_id, CLIP, name),
        SetAssetProperty(doc, asset_id, CLIP_STORE, store or None),
    ]
    start, end = clip_duration(doc, asset_id, name)
    rng = clip_range_command(doc, start, end)
    if rng is not None:
        commands.append(rng)
    return Macro(f"Play clip {name}", commands)

