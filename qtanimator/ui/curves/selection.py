"""The curve view's key selection: set, shared with the other editors, kept through edits.

The selection is key indices per channel. A change of the document (an undo, another
editor) maps it onto the channel's new keys by time and value, through the moves of
earlier drags (:data:`MOVE_HISTORY` per channel); keys that cannot be found are dropped.
The selection is published to ``ctx.key_selection`` and follows what another editor (the
dope sheet) selects there, for the channels the view shows.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

from PySide6.QtCore import QObject, QPointF

from qtanimator.core.channel import Channel
from qtanimator.document.document import DocumentChange, split_channel_id
from qtanimator.ui.curves.drags import MovedPairs
from qtanimator.ui.curves.picking import CurvePicking

MOVE_HISTORY = 4096      # (before, after) pairs of dragged keys remembered per channel


class CurveSelection(CurvePicking):
    """Key selection of the curve view."""

    def __init__(self, ctx: Any, parent: QObject | None = None) -> None:
        super().__init__(ctx, parent)
        # The channel object each selection's indices refer to, and (time, value) pairs of
        # keys moved by drags, so that the selection follows the same keys through undo / redo.
        self._selection_base: dict[str, Channel] = {}
        self._moves: dict[str, MovedPairs] = {}
        #: True while the view takes a selection another editor set (not published back).
        self._adopting = False
        ctx.documentChanged.connect(self._document_changed)
        self.keySelectionChanged.connect(self._publish_selection)
        ctx.key_selection.changed.connect(self._shared_selection_changed)

    def set_visible(self, cids: Iterable[str]) -> None:
        """Plot exactly these channels (in this order)."""
        wanted = [c for c in cids if c in self.doc.channels]
        self.visible = wanted
        for cid in set(self._drawings) - set(wanted):
            del self._drawings[cid]
        self._prune_selection()
        self._adopt_shared()  # keys another editor selected on channels now shown
        self.refresh_all()

    # ---------------------------------------------------- tracking the keys
    def _document_changed(self, change: DocumentChange) -> None:
        """Refresh the channels the change names (one change per command, or per frame
        during a gesture); the other channels keep their paths and cached pixels."""
        if "fps" in change.parameters:
            self.refresh_all()
        for cid in change.channels:
            if cid not in self.doc.channels:
                self.norm.drop(cid)
            if self._drag is None:
                self._map_selection(cid)
        if change.channels:
            self._prune_selection()
        for cid in change.channels:
            if cid in self.visible:
                self.refresh_channel(cid)
        if self.hover is not None and self.hover[1] in change.channels:
            self.hover_layer.update()

    def _map_selection(self, cid: str) -> None:
        """Channel ``cid`` changed (an undo, another editor): keep its selected keys selected.

        A key is found again by its time and value; a key moved by a drag (or put back by
        undoing one) by the time and value it had at the other end of the move; a key whose
        value alone changed by its time. Keys that cannot be found are dropped from the
        selection.
        """
        old = self._selection_base.get(cid)
        new = self.doc.channels.get(cid)
        idx = self.selection.get(cid)
        if old is None or new is None or not idx or old is new:
            return
        where = {(k.time, k.value): j for j, k in enumerate(new.keys)}
        at_time = {k.time: j for j, k in enumerate(new.keys)}
        moves = self._moves.get(cid, [])
        mapped: set[int] = set()
        active = None
        for i in sorted(idx):
            if i >= len(old.keys):
                continue
            tv = (old.keys[i].time, old.keys[i].value)
            j = where.get(tv)
            if j is None:
                for a, b in reversed(moves):
                    if b == tv and a in where:
                        j = where[a]
                        break
                    if a == tv and b in where:
                        j = where[b]
                        break
            if j is None:
                j = at_time.get(tv[0])  # same time, new value (a typed value, a slider)
            if j is not None:
                mapped.add(j)
                if self.active == (cid, i):
                    active = (cid, j)
        if mapped:
            self.selection[cid] = mapped
        else:
            del self.selection[cid]
        self._selection_base[cid] = new
        if self.active is not None and self.active[0] == cid:
            self.active = active or self._first_selected()
        self._update_live()
        self.keySelectionChanged.emit()

    def _note_selection_base(self) -> None:
        self._selection_base = {cid: self.doc.channels[cid] for cid, idx in self.selection.items()
                                if idx and cid in self.doc.channels}

    def _prune_selection(self) -> None:
        changed = False
        for cid in list(self.selection):
            ch = self.doc.channels.get(cid)
            if ch is None or cid not in self.visible:
                del self.selection[cid]
                changed = True
                continue
            keep = {i for i in self.selection[cid] if i < len(ch.keys)}
            if keep != self.selection[cid]:
                changed = True
                if keep:
                    self.selection[cid] = keep
                else:
                    del self.selection[cid]
        if self.active is not None and self.active[1] not in self.selection.get(self.active[0], set()):
            self.active = self._first_selected()
            changed = True
        if changed:
            self.keySelectionChanged.emit()

    # ------------------------------------------------------------ selecting
    def _first_selected(self) -> tuple[str, int] | None:
        for cid in self.visible:
            if self.selection.get(cid):
                return cid, min(self.selection[cid])
        return None

    def set_selection(self, selection: Mapping[str, Iterable[int]], active: tuple[str, int] | None = None) -> None:
        self.selection = {cid: set(idx) for cid, idx in selection.items() if idx}
        if active is not None and active[1] in self.selection.get(active[0], set()):
            self.active = active
        elif self.active is None or self.active[1] not in self.selection.get(self.active[0], set()):
            self.active = self._first_selected()
        self._note_selection_base()
        self._update_live()
        self.keySelectionChanged.emit()

    def clear_selection(self) -> None:
        self.set_selection({})

    def select_all(self) -> None:
        self.set_selection({cid: range(len(self.doc.channels[cid].keys)) for cid in self.visible})

    def select_under(self, scene: QPointF) -> None:
        """Right click: select what is under the cursor, so that the menu acts on it. A key
        that is selected already keeps the selection (it becomes the active key); another
        key becomes the selection; a curve away from keys is selected as a channel (its
        keys are deselected); empty space and handles keep the selection."""
        if self.handle_at(scene) is not None:
            return
        hit = self.key_at(scene)
        if hit is not None:
            cid, i = hit
            if i in self.selection.get(cid, ()):
                if self.active != hit:
                    self.active = hit
                    self.keySelectionChanged.emit()
            else:
                self.set_selection({cid: [i]}, hit)
            return
        curve = self.curve_at(scene)
        if curve is not None:
            asset, joint, _dof = split_channel_id(curve)
            self.ctx.select(asset, joint)
            self.ctx.select_channels([curve])
            self.clear_selection()

    # ------------------------------------------------------- shared selection
    def _publish_selection(self) -> None:
        """Our selection changed: share it (``ctx.key_selection``). Keys another editor
        selected on channels this view does not show stay selected there."""
        shared = self.ctx.key_selection
        if self._adopting:
            return
        channels = self.doc.channels
        shown = set(self.visible)
        keys: dict[str, Iterable[int]] = {cid: idx for cid, idx in shared.valid(channels).items()
                                          if cid not in shown}
        keys.update({cid: idx for cid, idx in self.selection.items() if idx})
        shared.set(keys, channels, self)

    def _shared_selection_changed(self, source: object) -> None:
        """Another editor (the dope sheet) selected keys: select those we show."""
        if source is self or source is None:
            return
        self._adopt_shared()

    def _adopt_shared(self) -> None:
        shared = self.ctx.key_selection
        if self._drag is not None:
            return
        shown = set(self.visible)
        wanted = {cid: set(idx) for cid, idx in shared.valid(self.doc.channels).items() if cid in shown}
        if wanted == {c: s for c, s in self.selection.items() if s}:
            return
        self._adopting = True
        try:
            self.set_selection(wanted)
        finally:
            self._adopting = False
