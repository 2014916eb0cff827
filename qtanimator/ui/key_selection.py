"""The selected keys, shared by the editors that show keys (curve editor, dope sheet).

One object per editor context (``ctx.key_selection``). A selection maps a channel id to the
indices of its selected keys *in a given channel object* (channels are immutable: a command
replaces the object, so indices are only meaningful with the object they were taken on).
An editor that changes the selection calls :meth:`KeySelection.set` with itself as the
source; every editor listens to ``changed`` and ignores the emissions it caused.

After a command replaced a channel, the editor that ran it (it knows where its keys went)
sets the new selection; an editor that only reads can call :meth:`valid` to drop entries
whose channel object is no longer the document's.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

from PySide6.QtCore import QObject, Signal

from qtanimator.core.channel import Channel


class KeySelection(QObject):
    """Selected keys: ``{channel id: frozenset of key indices}`` with the channel objects
    the indices refer to."""

    #: The selection changed: the source object given to :meth:`set` (None when cleared
    #: by the document being replaced).
    changed = Signal(object)

    def __init__(self, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self._keys: dict[str, frozenset[int]] = {}
        self._channels: dict[str, Channel] = {}

    # ------------------------------------------------------------------ read
    @property
    def keys(self) -> dict[str, frozenset[int]]:
        """A copy of ``{channel id: selected key indices}`` (no empty entries)."""
        return dict(self._keys)

    def channel(self, cid: str) -> Channel | None:
        """The channel object the indices of ``cid`` refer to."""
        return self._channels.get(cid)

    def count(self) -> int:
        return sum(len(v) for v in self._keys.values())

    def __bool__(self) -> bool:
        return bool(self._keys)

    def valid(self, channels: Mapping[str, Channel]) -> dict[str, frozenset[int]]:
        """The entries whose channel object is still ``channels[cid]`` (the document's)."""
        return {cid: idx for cid, idx in self._keys.items() if channels.get(cid) is self._channels.get(cid)}

    # ----------------------------------------------------------------- write
    def set(self, keys: Mapping[str, Iterable[int]], channels: Mapping[str, Channel], source: Any = None) -> None:
        """Replace the selection. ``channels`` gives, for each channel id in ``keys``, the
        channel object the indices refer to (usually ``doc.channels``). Emits ``changed``
        only when something differs."""
        new_keys: dict[str, frozenset[int]] = {}
        new_channels: dict[str, Channel] = {}
        for cid, idx in keys.items():
            ch = channels.get(cid)
            if ch is None:
                continue
            chosen = frozenset(int(i) for i in idx if 0 <= int(i) < len(ch.keys))
            if chosen:
                new_keys[cid] = chosen
                new_channels[cid] = ch
        if new_keys == self._keys and all(new_channels[c] is self._channels.get(c) for c in new_keys):
            return
        self._keys = new_keys
        self._channels = new_channels
        self.changed.emit(source)

    def clear(self, source: Any = None) -> None:
        if self._keys:
            self._keys = {}
            self._channels = {}
            self.changed.emit(source)


__all__ = ["KeySelection"]
