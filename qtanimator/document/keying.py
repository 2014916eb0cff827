"""Key edits shared by the editors that show keys (dope sheet, curve editor): copy and
paste, retime, scale in time, delete.

Each edit function returns a :class:`KeyEdit`: **one** command (a
:class:`~qtanimator.document.commands.SetChannels`, so undo puts back the very channel
objects that were there, and commands built in one gesture merge into one undo step) and
the indices the edited keys have in the new channels, so an editor can select them again.

Rules
-----
* Times are seconds; ``snap_fps`` (the document's fps) snaps to whole frames.
* **Retime** moves keys by ``delta_time``. Snapping rounds the *offset* to whole frames:
  keys on frames stay on frames and keys between frames (a 120 Hz capture in a 60 fps
  project) keep their place between frames.
* **Scale** maps a key time ``t`` to ``pivot + (t − pivot)·factor`` (``factor > 0``; fixed
  slopes are divided by the factor so handles keep their shape). Snapping rounds each
  scaled key to the nearest whole frame (halves round up, towards later frames).
* **A moved key wins.** A moved (or pasted) key that lands on the time of a key that did
  not move replaces it. When snapping puts several scaled keys on one frame, the one whose
  unsnapped time was nearest that frame stays (on a tie, the later key); the others are
  removed, as in Blender's dope sheet with automatic merging.
* Two times within :data:`TIME_TOLERANCE` seconds are the same time.
* **Copy** keeps the selected keys with times relative to the earliest selected key (over
  all channels), so **paste** at a time keeps their relative timing. Paste ``merge`` puts
  the keys in and replaces keys at the same times, keeping the others; ``replace`` first
  clears, in each target channel, the pasted time range (the clip's first to last key).
  Pasted times within a millionth of a frame of a whole frame are put exactly on it.
* Paste targets the channels of the same ids. A ``target`` mapping (clip channel id →
  document channel id) pastes elsewhere (another character) and may create channels; a
  clip channel that is not in the document and not mapped is skipped and reported in
  :attr:`KeyEdit.skipped`.
"""

from __future__ import annotations

import math
from bisect import bisect_left
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any

from qtanimator.core.channel import Channel, Key
from qtanimator.core.keys import KEY_TIME_TOLERANCE
from qtanimator.document import character2d, character3d
from qtanimator.document.commands import DeleteKeys, SetChannels, moved_key
from qtanimator.document.document import DEFAULT_FPS, Document, channel_id, split_channel_id

#: Two key times closer than this (seconds) are the same time (the one constant of core.keys).
TIME_TOLERANCE = KEY_TIME_TOLERANCE
#: A pasted or retimed frame number this close to a whole frame is put exactly on it.
FRAME_TIDY = 1e-6

Selection = Mapping[str, Iterable[int]]


@dataclass(frozen=True)
class KeyClip:
    """Copied keys: per channel id, the keys with times relative to the earliest copied key."""

    channels: Mapping[str, tuple[Key, ...]] = field(default_factory=dict)
    #: The fps of the document the keys were copied from (for information).
    fps: float = DEFAULT_FPS

    def __bool__(self) -> bool:
        return any(self.channels.values())

    @property
    def key_count(self) -> int:
        return sum(len(keys) for keys in self.channels.values())

    @property
    def span(self) -> float:
        """Seconds from the first to the last copied key."""
        return max((k.time for keys in self.channels.values() for k in keys), default=0.0)

    def assets(self) -> list[str]:
        """The asset ids the keys were copied from, in order."""
        return list(dict.fromkeys(split_channel_id(cid)[0] for cid in self.channels))

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON data (the system clipboard carries it)."""
        return {"fps": self.fps,
                "channels": {cid: [k.to_dict() for k in keys] for cid, keys in self.channels.items()}}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> KeyClip:
        """Inverse of :meth:`to_dict`; ValueError (or KeyError / TypeError) on bad data."""
        channels = {str(cid): tuple(sorted((Key.from_dict(k) for k in keys), key=lambda k: k.time))
                    for cid, keys in dict(data["channels"]).items()}
        for cid in channels:
            split_channel_id(cid)
        return cls(channels, float(data.get("fps", DEFAULT_FPS)))


@dataclass
class KeyEdit:
    """One key edit: the command (one undo step) and where the edited keys are afterwards."""

    command: SetChannels
    #: Channel id → indices of the moved / pasted keys in the command's new channels.
    selection: dict[str, frozenset[int]] = field(default_factory=dict)
    #: Clip channel ids a paste skipped (not in the document and not mapped).
    skipped: tuple[str, ...] = ()

    @property
    def text(self) -> str:
        return self.command.text

    def is_noop(self) -> bool:
        return self.command.is_noop()


# ------------------------------------------------------------------- helpers
def _picked(channels: Mapping[str, Channel], selection: Selection) -> dict[str, list[int]]:
    """``selection`` with indices sorted, deduplicated and checked against ``channels``."""
    out: dict[str, list[int]] = {}
    for cid, idx in selection.items():
        ch = channels.get(cid)
        if ch is None:
            continue
        chosen = sorted({int(i) for i in idx})
        if chosen and (chosen[0] < 0 or chosen[-1] >= len(ch.keys)):
            raise IndexError(f"key index out of range for {cid}")
        if chosen:
            out[cid] = chosen
    return out


def _on_frame(time: float, fps: float | None) -> float:
    """``time`` put exactly on a whole frame when it is within :data:`FRAME_TIDY` of one."""
    if not fps:
        return time
    f = time * fps
    r = round(f)
    return r / fps if abs(f - r) <= FRAME_TIDY else time


def _index_of(times: list[float], t: float) -> int:
    """Index of the key at ``t`` in sorted ``times`` (nearest)."""
    i = bisect_left(times, t)
    if i == len(times) or (i > 0 and abs(times[i - 1] - t) < abs(times[i] - t)):
        i -= 1
    return i


def _place(channel: Channel, keep: Iterable[Key],
           placed: list[tuple[Key, float, int]]) -> tuple[Channel, frozenset[int]]:
    """A new channel from ``keep`` (keys that did not move) and ``placed`` (moved or pasted
    keys with a rank and their order: on one time the lower rank wins, then the later
    order) by the rules above.
    Returns the channel and the indices of the placed keys that stayed."""
    placed = sorted(placed, key=lambda p: p[0].time)
    winners: list[tuple[Key, float, int]] = []
    for item in placed:
        if winners and item[0].time - winners[-1][0].time <= TIME_TOLERANCE:
            best = winners[-1]
            if (item[1], -item[2]) < (best[1], -best[2]):
                winners[-1] = item
            continue
        winners.append(item)
    times = [w[0].time for w in winners]
    kept = [k for k in keep if not times or abs(times[_index_of(times, k.time)] - k.time) > TIME_TOLERANCE]
    new = channel.with_keys([*kept, *(w[0] for w in winners)])
    new_times = [k.time for k in new.keys]
    return new, frozenset(_index_of(new_times, t) for t in times)


def _moved_channels(doc: Document, selection: Selection, base: Mapping[str, Channel] | None,
                    text: str, move: Any) -> KeyEdit:
    """Apply ``move(channel, index) -> (key, rank)`` to every selected key."""
    channels = doc.channels if base is None else base
    picked = _picked(channels, selection)
    changes: dict[str, tuple[Channel | None, Channel | None]] = {}
    new_selection: dict[str, frozenset[int]] = {}
    for cid, idx in picked.items():
        old = channels[cid]
        chosen = set(idx)
        placed = [(*move(old, i), i) for i in idx]
        new, where = _place(old, (k for i, k in enumerate(old.keys) if i not in chosen), placed)
        changes[cid] = (old, new if new != old else old)  # unchanged: keep the object
        new_selection[cid] = where
    return KeyEdit(SetChannels(text, changes), new_selection)


# --------------------------------------------------------------------- edits
def copy_keys(doc: Document, selection: Selection) -> KeyClip:
    """The selected keys (``{channel id: key indices}`` into ``doc.channels``) as a clip."""
    picked = _picked(doc.channels, selection)
    t0 = min((doc.channels[cid].keys[i].time for cid, idx in picked.items() for i in idx), default=0.0)
    clip = {cid: tuple(replace(doc.channels[cid].keys[i], time=doc.channels[cid].keys[i].time - t0) for i in idx)
            for cid, idx in picked.items()}
    return KeyClip(clip, doc.fps)


def paste_keys_command(doc: Document, clip: KeyClip, at_time: float, mode: str = "merge",
                       target: Mapping[str, str] | None = None) -> KeyEdit:
    """Paste ``clip`` with its first key at ``at_time`` (see the module rules)."""
    if mode not in ("merge", "replace"):
        raise ValueError("paste mode must be 'merge' or 'replace'")
    fps = doc.fps
    changes: dict[str, tuple[Channel | None, Channel | None]] = {}
    current: dict[str, Channel] = {}
    selection: dict[str, frozenset[int]] = {}
    skipped: list[str] = []
    start, end = at_time - TIME_TOLERANCE, at_time + clip.span + TIME_TOLERANCE
    for cid, keys in clip.channels.items():
        if not keys:
            continue
        mapped = target is not None and cid in target
        dest = target[cid] if target is not None and mapped else cid
        old = current.get(dest, doc.channels.get(dest))
        if old is None and not mapped:
            skipped.append(cid)
            continue
        base = old if old is not None else Channel()
        existing: Iterable[Key] = base.keys
        if mode == "replace":
            existing = [k for k in base.keys if not start <= k.time <= end]
        placed = [(replace(k, time=_on_frame(at_time + k.time, fps)), 0.0, i) for i, k in enumerate(keys)]
        new, where = _place(base, existing, placed)
        current[dest] = new
        changes[dest] = (changes[dest][0] if dest in changes else doc.channels.get(dest), new)
        selection[dest] = where
    count = sum(len(v) for v in selection.values())
    return KeyEdit(SetChannels(f"Paste {count} Key{'s' if count != 1 else ''}", changes), selection,
                   tuple(skipped))


def retime_keys_command(doc: Document, selection: Selection, delta_time: float, snap_fps: float | None = None,
                        base: Mapping[str, Channel] | None = None, text: str = "Retime Keys") -> KeyEdit:
    """Move the selected keys by ``delta_time`` seconds (snapped to whole frames with
    ``snap_fps``). ``base`` is the channels to start from (default: the document's; a drag
    passes the channels as they were when it began)."""
    if not math.isfinite(delta_time):
        raise ValueError("a retime offset must be finite")
    frames = round(delta_time * snap_fps) if snap_fps else 0

    def move(ch: Channel, i: int) -> tuple[Key, float]:
        k = ch.keys[i]
        if snap_fps:
            t = k.time if frames == 0 else _on_frame((k.time * snap_fps + frames) / snap_fps, snap_fps)
        else:
            t = k.time + delta_time
        return k.moved(t, k.value), 0.0

    return _moved_channels(doc, selection, base, text, move)


def scale_keys_command(doc: Document, selection: Selection, pivot_time: float, factor: float,
                       snap_fps: float | None = None, base: Mapping[str, Channel] | None = None,
                       text: str = "Scale Keys") -> KeyEdit:
    """Scale the selected keys' times by ``factor`` about ``pivot_time`` (each scaled key
    snapped to the nearest whole frame with ``snap_fps``)."""
    if not (math.isfinite(factor) and factor > 0.0):
        raise ValueError("a time scale factor must be positive")

    def move(ch: Channel, i: int) -> tuple[Key, float]:
        k = ch.keys[i]
        if factor == 1.0:
            return k, 0.0
        scaled = moved_key(k, 0.0, 0.0, (pivot_time, factor))
        if not snap_fps:
            return scaled, 0.0
        f = scaled.time * snap_fps
        whole = math.floor(f + 0.5)
        return replace(scaled, time=whole / snap_fps), abs(f - whole)

    return _moved_channels(doc, selection, base, text, move)


def delete_keys_command(doc: Document, selection: Selection) -> KeyEdit:
    """Delete the selected keys (a :class:`~qtanimator.document.commands.DeleteKeys`)."""
    picked: dict[str, Iterable[int]] = dict(_picked(doc.channels, selection))
    n = sum(len(list(v)) for v in picked.values())
    return KeyEdit(DeleteKeys(doc, picked, text=f"Delete {n} Key{'s' if n != 1 else ''}"))


# --------------------------------------------------------------- retargeting
def retarget(clip: KeyClip, asset_id: str, valid: Iterable[str] | None = None) -> dict[str, str]:
    """A paste ``target`` that puts every clip channel on the same joint and DOF of
    ``asset_id`` (only onto the channel ids in ``valid`` when given)."""
    allowed = None if valid is None else set(valid)
    out: dict[str, str] = {}
    for cid in clip.channels:
        _asset, joint, dof = split_channel_id(cid)
        dest = channel_id(asset_id, joint, dof)
        if allowed is None or dest in allowed:
            out[cid] = dest
    return out


def animatable_channel_ids(doc: Document, asset_id: str) -> list[str]:
    """The channel ids ``asset_id`` can have (its DOFs), whether keyed yet or not: a 2D
    character's position and joint angles, a 3D character's root translation and joint
    rotations; for other assets, the channels it has."""
    ids = [cid for cid, _ch in doc.channels_of(asset_id)]
    asset = doc.assets.get(asset_id)
    if asset is None:
        return ids
    if asset.kind == character2d.ASSET_KIND:
        try:
            ch = character2d.character(doc, asset_id)
        except (KeyError, ValueError, OSError):
            return ids
        more = [*character2d.position_channel_ids(asset_id),
                *(character2d.angle_channel_id(asset_id, j.name) for j in ch.joints)]
    elif asset.kind == character3d.ASSET_KIND:
        try:
            more = character3d.all_channel_ids(doc, asset_id)
        except KeyError:
            return ids
    else:
        return ids
    return list(dict.fromkeys([*ids, *more]))


__all__ = [
    "TIME_TOLERANCE", "KeyClip", "KeyEdit", "animatable_channel_ids", "copy_keys", "delete_keys_command",
    "paste_keys_command", "retarget", "retime_keys_command", "scale_keys_command",
]
