"""Qt-free undoable commands.

A command captures the old and new state of what it touches when it is built, so ``do``
and ``undo`` are exact and can be repeated (redo). ``merge`` folds a later command of the
same gesture into this one, so that one mouse drag is one undo step: commands built with
the same ``gesture`` token (any hashable the widget picks at mouse press) merge.

The ``ui`` package wraps each command in a QUndoCommand (``qtanimator.ui.undo``).
"""

from __future__ import annotations

import math
from collections.abc import Hashable, Iterable, Mapping, Sequence
from dataclasses import replace
from typing import Any

from qtanimator.core.channel import Channel, Extrapolation, Key, Tangent
from qtanimator.document.document import Asset, Document
from qtanimator.document.parameters import validate_parameter


class Command:
    """Base class: subclasses implement ``do`` and ``undo``; ``text`` names the step."""

    text: str = "Edit"
    gesture: Hashable | None = None

    def do(self, doc: Document) -> None:
        raise NotImplementedError

    def undo(self, doc: Document) -> None:
        raise NotImplementedError

    def merge(self, other: Command) -> bool:
        """Absorb ``other`` (pushed right after this one). Return True if merged."""
        return False

    def is_noop(self) -> bool:
        return False


class SetChannels(Command):
    """Replace whole channels: ``changes`` maps channel id to ``(old, new)``.

    ``None`` as old means the channel is created, as new that it is removed. Every key
    edit is one of these; the named subclasses below build ``changes`` from the document.
    """

    def __init__(self, text: str, changes: dict[str, tuple[Channel | None, Channel | None]],
                 gesture: Hashable | None = None) -> None:
        self.text = text
        self.changes = dict(changes)
        self.gesture = gesture

    def do(self, doc: Document) -> None:
        for cid, (_old, new) in self.changes.items():
            doc.apply_channel(cid, new, _first_difference(doc.channels.get(cid), new))

    def undo(self, doc: Document) -> None:
        for cid, (old, _new) in reversed(list(self.changes.items())):
            doc.apply_channel(cid, old, _first_difference(doc.channels.get(cid), old))

    def merge(self, other: Command) -> bool:
        if self.gesture is None or other.gesture != self.gesture or not isinstance(other, SetChannels):
            return False
        for cid, (old, new) in other.changes.items():
            if cid in self.changes:
                self.changes[cid] = (self.changes[cid][0], new)
            else:
                self.changes[cid] = (old, new)
        return True

    def is_noop(self) -> bool:
        return all(old == new for old, new in self.changes.values())


def _first_difference(a: Channel | None, b: Channel | None) -> float:
    """Earliest time from which two versions of a channel may evaluate differently."""
    if a is None or b is None or a.pre != b.pre or not a.keys or not b.keys:
        return -math.inf
    if a == b:
        return math.inf
    if a.pre.periodic:
        return -math.inf  # a cycle before the first key repeats every key
    for ka, kb in zip(a.keys, b.keys):
        if ka != kb:
            # The span before a changed key changes too (its end value and slopes).
            return _previous_key_time(a, ka.time, b, kb.time)
    if len(a.keys) != len(b.keys):
        n = min(len(a.keys), len(b.keys))
        return _previous_key_time(a, a.keys[n - 1].time, b, b.keys[n - 1].time) if n else -math.inf
    return a.keys[-1].time if a.post != b.post else math.inf


def _previous_key_time(a: Channel, ta: float, b: Channel, tb: float) -> float:
    # Smooth tangents reach one key further back, so go back two keys to be safe.
    def back(ch: Channel, t: float) -> float:
        times = [k.time for k in ch.keys if k.time < t]
        return times[-2] if len(times) >= 2 else -math.inf
    return min(back(a, ta), back(b, tb))


def _get(doc: Document, cid: str) -> Channel:
    return doc.channels.get(cid) or Channel()


class InsertKey(SetChannels):
    """Set a key (creating the channel if needed); a key at the same time is replaced."""

    def __init__(self, doc: Document, cid: str, key: Key, gesture: Hashable | None = None,
                 text: str = "Set Key") -> None:
        old = doc.channels.get(cid)
        new = (old or Channel()).set_key(key)
        super().__init__(text, {cid: (old, new)}, gesture)


class SetKeys(SetChannels):
    """Set several keys at once: ``keys`` maps channel id to the key to set."""

    def __init__(self, doc: Document, keys: dict[str, Key], text: str = "Set Keys",
                 gesture: Hashable | None = None) -> None:
        changes: dict[str, tuple[Channel | None, Channel | None]] = {}
        for cid, key in keys.items():
            old = doc.channels.get(cid)
            changes[cid] = (old, (old or Channel()).set_key(key))
        super().__init__(text, changes, gesture)


class DeleteKeys(SetChannels):
    """Delete keys by index: ``selection`` maps channel id to key indices."""

    def __init__(self, doc: Document, selection: dict[str, Iterable[int]], text: str = "Delete Keys") -> None:
        changes: dict[str, tuple[Channel | None, Channel | None]] = {}
        for cid, idx in selection.items():
            old = doc.channels.get(cid)
            if old is not None:
                changes[cid] = (old, old.remove_keys(idx))
        super().__init__(text, changes)


def moved_key(key: Key, dt: float, dv: float, time_scale: tuple[float, float] | None = None) -> Key:
    """``key`` moved by ``(dt, dv)`` or with its time scaled about a pivot, handles kept."""
    if time_scale is None:
        return key.moved(key.time + dt, key.value + dv)
    pivot, factor = time_scale
    if factor == 0.0:
        raise ValueError("a time scale factor must not be zero")
    new = key.moved(pivot + (key.time - pivot) * factor, key.value + dv)
    # A fixed slope is value per second: stretching time by the factor keeps the handle's
    # shape only if the slope shrinks by it.
    in_slope = key.in_slope / factor if key.in_tangent is Tangent.FIXED else key.in_slope
    out_slope = key.out_slope / factor if key.out_tangent is Tangent.FIXED else key.out_slope
    # A weight is a handle's extent in seconds: it stretches with time.
    scale = abs(factor)
    in_weight = None if key.in_weight is None else key.in_weight * scale
    out_weight = None if key.out_weight is None else key.out_weight * scale
    return replace(new, in_slope=in_slope, out_slope=out_slope, in_weight=in_weight, out_weight=out_weight)


class MoveKeys(SetChannels):
    """Move keys by ``(dt, dv)`` (or scale their times about a pivot), keeping each key's
    rules and span shape.

    Built from the channels as they were when the drag began (``base``), so that a drag
    merged from many mouse moves is exact: the last offset wins. ``dv`` is one value offset
    for all channels or a mapping channel id → offset (a drag in the curve editor's
    normalised view moves each channel by its own amount). Raises ValueError if a moved key
    would land on another key's time.
    """

    def __init__(self, base: Mapping[str, Channel], selection: Mapping[str, Sequence[int]], dt: float,
                 dv: float | Mapping[str, float] = 0.0, gesture: Hashable | None = None,
                 text: str = "Move Keys", time_scale: tuple[float, float] | None = None) -> None:
        changes: dict[str, tuple[Channel | None, Channel | None]] = {}
        for cid, idx in selection.items():
            old = base[cid]
            offset = dv if isinstance(dv, (int, float)) else float(dv.get(cid, 0.0))
            moved = {i: moved_key(old.keys[i], dt, float(offset), time_scale) for i in idx}
            changes[cid] = (old, old.replace_keys(moved))
        super().__init__(text, changes, gesture)


class EditKey(SetChannels):
    """Replace one key by an edited copy (numeric fields, handle drags, rule menus)."""

    def __init__(self, doc: Document, cid: str, index: int, key: Key, text: str = "Edit Key",
                 gesture: Hashable | None = None) -> None:
        old = doc.channels[cid]
        super().__init__(text, {cid: (old, old.replace_keys({index: key}))}, gesture)


class SetTangents(SetChannels):
    """Set the tangent rule of selected keys on the in side, the out side, or both."""

    def __init__(self, doc: Document, selection: dict[str, Iterable[int]], rule: Tangent | str,
                 side: str = "both", text: str | None = None) -> None:
        rule = Tangent(rule)
        if side not in ("in", "out", "both"):
            raise ValueError("side must be 'in', 'out' or 'both'")
        changes: dict[str, tuple[Channel | None, Channel | None]] = {}
        for cid, idx in selection.items():
            old = doc.channels[cid]
            s_in, s_out = old.slopes()
            edits = {}
            for i in idx:
                k = old.keys[i]
                kw: dict[str, Any] = {}
                if side in ("in", "both"):
                    kw.update(in_tangent=rule, in_slope=float(s_in[i]) if rule is Tangent.FIXED else 0.0)
                if side in ("out", "both"):
                    kw.update(out_tangent=rule, out_slope=float(s_out[i]) if rule is Tangent.FIXED else 0.0)
                edits[i] = _replace_key(k, **kw)
            changes[cid] = (old, old.replace_keys(edits))
        super().__init__(text or f"Tangents: {rule.value}", changes)


class SetExtrapolation(SetChannels):
    """Set pre and / or post extrapolation of channels."""

    def __init__(self, doc: Document, cids: Iterable[str], pre: Extrapolation | str | None = None,
                 post: Extrapolation | str | None = None, text: str = "Set Extrapolation") -> None:
        changes: dict[str, tuple[Channel | None, Channel | None]] = {}
        for cid in cids:
            old = doc.channels[cid]
            changes[cid] = (old, old.with_extrapolation(pre, post))
        super().__init__(text, changes)


def _replace_key(k: Key, **kw: Any) -> Key:
    from dataclasses import replace
    return replace(k, **kw)


class SetParameter(Command):
    """Set one parameter; consecutive sets of the same path in one gesture merge.

    Without a ``gesture`` every set is its own undo step (typing 24 then 30 into the fps
    field is two steps); a slider passes one token per drag.

    A value for a path the parameter schema knows (:func:`qtanimator.document.parameters.param_for`:
    the project, IK, light, pendulum and spring settings) is validated here: one it refuses
    raises ValueError naming the setting and its range, and nothing is done. None (unset)
    is always allowed. ``validate=False`` skips the check (tests that store what a
    hand-written project file could hold).
    """

    def __init__(self, doc: Document, path: str, value: Any, text: str | None = None,
                 gesture: Hashable | None = None, *, validate: bool = True) -> None:
        if validate:
            validate_parameter(path, value)
        self.path = path
        self.old = doc.parameters.get(path)
        self.new = value
        self.text = text or f"Set {path}"
        self.gesture = gesture

    def do(self, doc: Document) -> None:
        doc.apply_parameter(self.path, self.new)

    def undo(self, doc: Document) -> None:
        doc.apply_parameter(self.path, self.old)

    def merge(self, other: Command) -> bool:
        if (self.gesture is not None and isinstance(other, SetParameter) and other.path == self.path
                and other.gesture == self.gesture):
            self.new = other.new
            return True
        return False

    def is_noop(self) -> bool:
        return bool(self.old == self.new)


class AddAsset(Command):
    """Add an asset (with the object loaded from its source, and any channels).

    Whatever it replaces (an asset of the same id, channels of the same ids) is
    remembered when it is done and put back on undo.
    """

    def __init__(self, asset: Asset, runtime: Any = None, channels: dict[str, Channel] | None = None,
                 text: str | None = None) -> None:
        self.asset = asset
        self.runtime = runtime
        self.channels = dict(channels or {})
        self.text = text or f"Add {asset.id}"
        self._replaced: tuple[Asset | None, Any, int | None, dict[str, Channel | None]] | None = None

    def do(self, doc: Document) -> None:
        aid = self.asset.id
        index = list(doc.assets).index(aid) if aid in doc.assets else None
        self._replaced = (doc.assets.get(aid), doc.runtime.get(aid), index,
                          {cid: doc.channels.get(cid) for cid in self.channels})
        if index is not None:
            doc.apply_asset(aid, None)
        doc.apply_asset(aid, self.asset, self.runtime, index=index)
        for cid, ch in self.channels.items():
            doc.apply_channel(cid, ch)

    def undo(self, doc: Document) -> None:
        old_asset, old_runtime, index, old_channels = self._replaced or (None, None, None, {})
        for cid in reversed(list(self.channels)):
            doc.apply_channel(cid, old_channels.get(cid))
        doc.apply_asset(self.asset.id, None)
        if old_asset is not None:
            doc.apply_asset(self.asset.id, old_asset, old_runtime, index=index)


class RemoveAsset(Command):
    """Remove an asset and its channels."""

    def __init__(self, doc: Document, asset_id: str) -> None:
        self.asset = doc.assets[asset_id]
        self.runtime = doc.runtime.get(asset_id)
        self.index = list(doc.assets).index(asset_id)
        self.channels = dict(doc.channels_of(asset_id))
        self.text = f"Remove {asset_id}"

    def do(self, doc: Document) -> None:
        for cid in self.channels:
            doc.apply_channel(cid, None)
        doc.apply_asset(self.asset.id, None)

    def undo(self, doc: Document) -> None:
        doc.apply_asset(self.asset.id, self.asset, self.runtime, index=self.index)
        for cid, ch in self.channels.items():
            doc.apply_channel(cid, ch)


class RenameAsset(Command):
    """Give an asset a new id: its channels ``old/…`` become ``new/…`` and its parameters
    ``old.…`` become ``new.…`` (those of a longer asset id such as ``old.b`` stay); the
    asset keeps its place in the scene order and its loaded object. Undo puts everything
    back exactly. The caller checks the name (``outliner.rename_command``)."""

    def __init__(self, doc: Document, old: str, new: str) -> None:
        if new in doc.assets and new != old:
            raise ValueError(f"the name {new!r} is already in use")
        self.old, self.new = old, new
        self.asset = doc.assets[old]
        self.runtime = doc.runtime.get(old)
        self.index = list(doc.assets).index(old)
        self.channels = dict(doc.channels_of(old))
        longer = [aid + "." for aid in doc.assets if aid != old and aid.startswith(old + ".")]
        self.parameters = {p: v for p, v in doc.parameters.items()
                           if p.startswith(old + ".") and not any(p.startswith(x) for x in longer)}
        self.text = f"Rename {old} to {new}"

    def _move(self, doc: Document, src: str, dst: str) -> None:
        def named(key: str, sep: str, aid: str) -> str:
            return aid + sep + key[len(self.old) + 1:]

        for cid in self.channels:
            doc.apply_channel(named(cid, "/", src), None)
        for p in self.parameters:
            doc.apply_parameter(named(p, ".", src), None)
        doc.apply_asset(src, None)
        asset = self.asset if dst == self.old else Asset(dst, self.asset.kind, self.asset.source,
                                                          self.asset.properties)
        doc.apply_asset(dst, asset, self.runtime, index=self.index)
        for cid, ch in self.channels.items():
            doc.apply_channel(named(cid, "/", dst), ch)
        for p, v in self.parameters.items():
            doc.apply_parameter(named(p, ".", dst), v)

    def do(self, doc: Document) -> None:
        self._move(doc, self.old, self.new)

    def undo(self, doc: Document) -> None:
        self._move(doc, self.new, self.old)

    def is_noop(self) -> bool:
        return self.old == self.new


class SetAssetProperty(Command):
    """Set one authored property of an asset (merges within a gesture)."""

    def __init__(self, doc: Document, asset_id: str, name: str, value: Any,
                 text: str | None = None, gesture: Hashable | None = None) -> None:
        self.asset_id = asset_id
        self.name = name
        self.old = doc.assets[asset_id].properties.get(name)
        self.new = value
        self.text = text or f"Set {name}"
        self.gesture = gesture

    def _set(self, doc: Document, value: Any) -> None:
        # Assets are replaced, not changed in place: other commands keep the old object.
        asset = doc.assets[self.asset_id].copy()
        if value is None:
            asset.properties.pop(self.name, None)
        else:
            asset.properties[self.name] = value
        doc.apply_asset(self.asset_id, asset)

    def do(self, doc: Document) -> None:
        self._set(doc, self.new)

    def undo(self, doc: Document) -> None:
        self._set(doc, self.old)

    def merge(self, other: Command) -> bool:
        if (self.gesture is not None and isinstance(other, SetAssetProperty) and other.asset_id == self.asset_id
                and other.name == self.name and other.gesture == self.gesture):
            self.new = other.new
            return True
        return False

    def is_noop(self) -> bool:
        return bool(self.old == self.new)


class Macro(Command):
    """Several commands as one undo step (e.g. an IK drag that keys many joints)."""

    def __init__(self, text: str, commands: Sequence[Command], gesture: Hashable | None = None) -> None:
        self.text = text
        self.commands = list(commands)
        self.gesture = gesture

    def do(self, doc: Document) -> None:
        for c in self.commands:
            c.do(doc)

    def undo(self, doc: Document) -> None:
        for c in reversed(self.commands):
            c.undo(doc)

    def merge(self, other: Command) -> bool:
        if self.gesture is None or other.gesture != self.gesture:
            return False
        incoming = other.commands if isinstance(other, Macro) else [other]
        for c in incoming:
            # Only the last command may absorb it: merging into an earlier one would
            # reorder edits when a later command touches the same channel.
            if not (self.commands and self.commands[-1].merge(c)):
                self.commands.append(c)
        return True

    def is_noop(self) -> bool:
        return all(c.is_noop() for c in self.commands)


class UndoStack:
    """A plain undo stack with merging, for scripts and tests without Qt.

    The GUI uses QUndoStack through ``qtanimator.ui.undo`` with the same semantics.
    """

    def __init__(self, doc: Document) -> None:
        self.doc = doc
        self.done: list[Command] = []
        self.undone: list[Command] = []

    def push(self, cmd: Command) -> None:
        """Do ``cmd`` and record it. Like QUndoStack with obsolete commands, a command
        that changes nothing is not recorded, and a gesture merged back to where it
        started disappears from the history."""
        with self.doc.batch():
            cmd.do(self.doc)
        self.undone.clear()
        if self.done and self.done[-1].merge(cmd):
            if self.done[-1].is_noop():
                self.done.pop()
            return
        if not cmd.is_noop():
            self.done.append(cmd)

    def record(self, cmd: Command) -> None:
        """Record a command that is already done as one step: the ``record`` of a
        :class:`qtanimator.document.gesture.Gesture` committed without Qt."""
        self.undone.clear()
        if not cmd.is_noop():
            self.done.append(cmd)

    def undo(self) -> bool:
        if not self.done:
            return False
        cmd = self.done.pop()
        with self.doc.batch():
            cmd.undo(self.doc)
        self.undone.append(cmd)
        return True

    def redo(self) -> bool:
        if not self.undone:
            return False
        cmd = self.undone.pop()
        with self.doc.batch():
            cmd.do(self.doc)
        self.done.append(cmd)
        return True
