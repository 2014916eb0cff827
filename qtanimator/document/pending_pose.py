"""The pending pose: channel values shown at one time without keys (auto-key off).

With auto-key off a drag poses without keying: the values go to the document's pending
pose, held in ``doc.caches`` (never in the channels, never saved, never in the undo
history). Every evaluation at that time sees them (``character2d`` / ``character3d`` read
:func:`pending_values`), so all views agree on what is shown; see :mod:`qtanimator.document.pose`
for the whole story. This module is the part the character engines need, so it imports
neither of them.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

from qtanimator.document.commands import Command
from qtanimator.document.document import Document, DocumentChange

#: The pseudo parameter a change of the pending pose announces (not a real parameter).
PENDING_CHANGE = "pose.pending"
PENDING_CACHE = "pose.pending"
#: Two times closer than this are the same frame.
TIME_TOLERANCE = 1e-9

_EMPTY: Mapping[str, float] = MappingProxyType({})


# ------------------------------------------------------------------ pending pose
Entry = tuple[float, Any]
State = tuple["float | None", dict[str, Entry]]


class PendingPose:
    """Channel values shown at one time without keys (see the module's docstring).

    Each value remembers the channel object it was posed over (channels are immutable:
    every edit makes a new one). A value counts only while its channel is still that
    object: keying it, an edit in another editor or an undo ends it at once — and an
    undo that puts the very channel back (Escape on a drag, undoing set key) shows the
    unkeyed value again, as it was before.
    """

    def __init__(self, doc: Document) -> None:
        self.time: float | None = None
        self.entries: dict[str, Entry] = {}
        doc.subscribe(self._on_change)

    def _here(self, time: float) -> bool:
        return self.time is not None and bool(self.entries) and abs(time - self.time) <= TIME_TOLERANCE

    def value(self, doc: Document, cid: str, time: float) -> float | None:
        if not self._here(time):
            return None
        entry = self.entries.get(cid)
        if entry is None or doc.channels.get(cid) is not entry[1]:
            return None
        return entry[0]

    def at(self, doc: Document, time: float) -> dict[str, float]:
        if not self._here(time):
            return {}
        channels = doc.channels
        return {cid: v for cid, (v, ch) in self.entries.items() if channels.get(cid) is ch}

    def snapshot(self) -> State:
        return self.time, dict(self.entries)

    def restore(self, state: State) -> None:
        time, entries = state
        self.entries = dict(entries)
        self.time = time if self.entries else None

    def _on_change(self, change: DocumentChange) -> None:
        if change.reset and self.entries:
            self.restore((None, {}))


def pending_store(doc: Document) -> PendingPose:
    """The document's pending pose (created on first use)."""
    store = doc.caches.get(PENDING_CACHE)
    if not isinstance(store, PendingPose):
        store = PendingPose(doc)
        doc.caches[PENDING_CACHE] = store
    return store


def pending_values(doc: Document, time: float) -> Mapping[str, float]:
    """The pending channel values at ``time`` (empty unless a pose is pending there)."""
    store = doc.caches.get(PENDING_CACHE)
    if store is None:
        return _EMPTY
    return store.at(doc, time)


def pending_value(doc: Document, cid: str, time: float) -> float | None:
    """One channel's pending value at ``time``, or None."""
    store = doc.caches.get(PENDING_CACHE)
    if store is None:
        return None
    return store.value(doc, cid, time)


def has_pending(doc: Document, time: float | None = None) -> bool:
    """True when a pose is pending (at ``time`` when given)."""
    store = doc.caches.get(PENDING_CACHE)
    if not isinstance(store, PendingPose) or store.time is None:
        return False
    return bool(store.at(doc, store.time if time is None else time))


def _announce(doc: Document) -> None:
    doc.emit(DocumentChange(parameters=frozenset((PENDING_CHANGE,))))


def clear_pending(doc: Document) -> bool:
    """Drop the pending pose (the frame changed). True (and announced) if one was shown."""
    store = doc.caches.get(PENDING_CACHE)
    if not isinstance(store, PendingPose) or not store.entries:
        return False
    shown = has_pending(doc)
    store.restore((None, {}))
    if shown:
        _announce(doc)
    return shown


class PosePreview(Command):
    """Pose without keying: set pending values at a time. Never an undo step
    (:meth:`is_noop`), so a drag with auto-key off records nothing; ``undo`` puts the
    pending pose back as it was (Escape during the drag)."""

    def __init__(self, doc: Document, values: Mapping[str, float], time: float, text: str = "Pose",
                 gesture: Any = None) -> None:
        store = pending_store(doc)
        self.text = text
        self.gesture = gesture
        self.old = store.snapshot()
        entries = {cid: e for cid, e in store.entries.items() if store.value(doc, cid, time) is not None}
        for cid, v in values.items():
            entries[cid] = (float(v), doc.channels.get(cid))
        self.new: State = (float(time), entries)

    def do(self, doc: Document) -> None:
        pending_store(doc).restore(self.new)
        _announce(doc)

    def undo(self, doc: Document) -> None:
        pending_store(doc).restore(self.old)
        _announce(doc)

    def merge(self, other: Command) -> bool:
        if self.gesture is None or other.gesture != self.gesture or not isinstance(other, PosePreview):
            return False
        self.new = other.new
        return True

    def is_noop(self) -> bool:
        return True
