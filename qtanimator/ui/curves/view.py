"""The curve plot: channels against time in frames, keys, handles and their interaction.

:class:`CurveView` owns the pyqtgraph plot (objectName ``curvePlot``), the per-channel
channel drawings, the key selection and the gestures. A click edit is one command pushed
with ``ctx.push``. A drag (keys, a tangent handle, Ctrl+drag time scaling) is a gesture
(``ctx.begin_gesture``): each mouse move previews a command built from the channels as
they were when the drag began, the release commits them as one undo step (nothing when
the keys end where they started), and Escape aborts it, putting the document back exactly.

Mouse: left click selects a key (Shift adds / toggles), left drag on a key moves the
selected keys (hold Shift once moving to lock to the main axis), Ctrl+drag on a key
scales the selected keys in time about the current frame, drag on a handle sets a fixed
slope (and, on a weighted key, the handle's length), on empty space box-selects;
Ctrl+click inserts a key on the curve under the cursor; right click selects the key or
curve under the cursor (a key already selected keeps the selection) and opens the menu;
middle drag or Alt+left drag pans; right drag zooms each axis; the wheel zooms (Ctrl:
time only, Shift: values only). The playhead moves by its handle (the triangle at the top)
or by a click or drag on the time axis; a key on the playhead drags like any other.
Keys: A frame all, F frame selected, N normalise, Delete removes selected keys, Ctrl+A
selects all keys, Escape aborts a drag.

Units: rotations (``angle``, ``rx``, ``ry``, ``rz``; radians in the document) are shown in
degrees, other channels in their own units (see :mod:`~.normalisation`); the display
transform of a channel carries the unit, so picking, drags and handles all work in what
is shown.

The key selection is shared with the other editors through ``ctx.key_selection``: the
view publishes its selection (source: the view) and takes the selection another editor
sets, for the channels it shows.

What a drag does is decided without Qt in :mod:`~.drags` (:class:`~.drags.MoveKeysDrag`,
:class:`~.drags.ScaleKeysDrag`, :class:`~.drags.HandleDrag`, :class:`~.drags.BoxSelect`);
this module picks what is under the press, turns mouse events into plot points
(:class:`~.drags.Cursor`) and feeds the drag's commands to the gesture. The view is built
up in layers, one idea each: :mod:`~.plot` (the widget and its event routing),
:mod:`~.canvas` (drawings, display transforms, framing), :mod:`~.picking` (hit tests),
:mod:`~.selection` (the key selection, kept through edits and shared), and here the
mouse and key gestures.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any

from PySide6.QtCore import QObject, QPointF, QRectF, Qt
from PySide6.QtGui import QKeyEvent

from qtanimator.core.channel import Key
from qtanimator.document.commands import Command, DeleteKeys, InsertKey
from qtanimator.document.document import split_channel_id
from qtanimator.ui.curves.drags import (
    ActiveDrag,
    BoxSelect,
    Cursor,
    HandleDrag,
    KeysDrag,
    MoveKeysDrag,
    ScaleKeysDrag,
    click_selection,
    press_selection,
)
from qtanimator.ui.curves.picking import CURVE_PICK_RADIUS, PICK_RADIUS
from qtanimator.ui.curves.plot import BACKGROUND, PLAYHEAD_HANDLE, CurvePlot, CurveViewBox, FrameLine
from qtanimator.ui.curves.selection import MOVE_HISTORY, CurveSelection

__all__ = ["BACKGROUND", "CURVE_PICK_RADIUS", "MOVE_HISTORY", "PICK_RADIUS", "PLAYHEAD_HANDLE", "CurvePlot",
           "CurveView", "CurveViewBox", "FrameLine"]


class CurveView(CurveSelection):
    """Plot, items, selection and gestures of the curve editor."""

    def __init__(self, ctx: Any, parent: QObject | None = None) -> None:
        super().__init__(ctx, parent)
        self.snap = True
        self.axis_lock = "none"   # "none", "time" or "value"
        #: The modifiers held when the button went down (set by the plot widget).
        self.press_modifiers = Qt.KeyboardModifier.NoModifier
        self._scrubbing = False

    def reset(self) -> None:
        """The document was replaced: forget caches and selection."""
        self.norm.clear()
        self._drawings.clear()
        self.selection.clear()
        self._selection_base.clear()
        self._moves.clear()
        self.hover = None
        self.active = None
        self._drag = None
        self._frozen_norm.clear()
        self._frame_changed(self.ctx.frame)
        self.keySelectionChanged.emit()

    # ------------------------------------------------------------- editing
    def push(self, command: Command) -> None:
        self.ctx.push(command)

    def delete_selected(self) -> None:
        sel = self.selected_keys()
        if not sel:
            return
        self.selection.clear()
        self._selection_base.clear()
        self.active = None
        keys: dict[str, Iterable[int]] = dict(sel)  # DeleteKeys takes any iterable of indices
        self.push(DeleteKeys(self.doc, keys))
        self.keySelectionChanged.emit()

    def insert_key_at(self, scene: QPointF) -> tuple[str, int] | None:
        """Ctrl+click: a key on the curve under the cursor (or the one highlighted channel)."""
        view = self.vb.mapSceneToView(scene)
        frame = round(view.x()) if self.snap else view.x()
        t = frame / self.fps
        cid = self.curve_at(scene)
        if cid is not None:
            value = float(self.doc.channels[cid].evaluate(t))
        else:
            candidates = [c for c in self.visible if c in self.highlighted]
            if len(candidates) != 1:
                return None
            cid = candidates[0]
            off, scale = self.display_transform(cid)
            value = view.y() / scale + off
        self.push(InsertKey(self.doc, cid, Key(t, value), text="Insert Key"))
        index = self.doc.channels[cid].key_index(t)
        if index is None:
            return None
        self.set_selection({cid: [index]}, (cid, index))
        return cid, index

    # ---------------------------------------------------------------- hover
    def hover_at(self, scene: QPointF | None) -> None:
        """Highlight the key or handle under the mouse and show a cursor that says what a
        drag will do there: move (keys), point (handles), move sideways (the playhead's
        handle, which takes the drag there), arrow elsewhere."""
        hit: tuple[Any, ...] | None = None
        if scene is not None and not self.dragging and self.frame_line.at_handle(scene):
            hit = ("playhead", "", -1)
        elif scene is not None and not self.dragging and self.vb.sceneBoundingRect().contains(scene):
            handle = self.handle_at(scene)
            if handle is not None:
                hit = ("handle", *handle)
            else:
                key = self.key_at(scene)
                if key is not None:
                    hit = ("key", *key)
        if hit == self.hover:
            return
        self.hover = hit
        shape = {None: None, "key": Qt.CursorShape.SizeAllCursor, "handle": Qt.CursorShape.PointingHandCursor,
                 "playhead": Qt.CursorShape.SizeHorCursor}[hit[0] if hit else None]
        viewport = self.widget.viewport()
        if shape is None:
            viewport.unsetCursor()
        else:
            viewport.setCursor(shape)
        self.hover_layer.update()

    def scrub(self, scene: QPointF, finish: bool = False) -> None:
        """A drag along the time axis: the current frame follows the mouse (whole frames)."""
        frame = float(round(self.vb.mapSceneToView(scene).x()))
        self._scrubbing = not finish
        if frame != self.ctx.frame:
            self.ctx.set_frame(frame)

    # ------------------------------------------------------------- gestures
    def click(self, scene: QPointF, mods: Qt.KeyboardModifier) -> None:
        self.widget.setFocus()
        shift = bool(mods & Qt.KeyboardModifier.ShiftModifier)
        if mods & Qt.KeyboardModifier.ControlModifier:
            self.insert_key_at(scene)
            return
        if self.handle_at(scene) is not None:
            return
        hit = self.key_at(scene)
        if hit is not None:
            self.set_selection(click_selection(self.selection, hit, toggle=shift), hit)
            return
        curve = self.curve_at(scene)
        if curve is not None and not shift:
            asset, joint, _dof = split_channel_id(curve)
            self.ctx.select(asset, joint)
            self.ctx.select_channels([curve])
        if not shift:
            self.clear_selection()


    def _cursor(self, scene: QPointF, mods: Qt.KeyboardModifier = Qt.KeyboardModifier.NoModifier) -> Cursor:
        """A scene position as a drag's plot point (frame, value as shown)."""
        p = self.vb.mapSceneToView(scene)
        return Cursor(p.x(), p.y(), bool(mods & Qt.KeyboardModifier.ShiftModifier), (scene.x(), scene.y()))

    def drag_event(self, ev: Any) -> bool:
        """Handle a pyqtgraph drag event; False lets the ViewBox pan or zoom."""
        button = ev.button()
        mods = ev.modifiers()
        if ev.isStart():
            self._drag = None
            if button != Qt.MouseButton.LeftButton or mods & Qt.KeyboardModifier.AltModifier:
                return False
            self.widget.setFocus()
            self._drag = self._begin_drag(ev.buttonDownScenePos(), mods | self.press_modifiers)
            self._update_live()
        active = self._drag
        if active is None:
            return False
        ev.accept()
        if active.aborted:
            if ev.isFinish():
                self._drag = None
            return True
        drag = active.drag
        cursor = self._cursor(ev.scenePos(), mods)
        if isinstance(drag, KeysDrag):
            self._drag_keys(active, drag, cursor)
        elif isinstance(drag, HandleDrag):
            self._drag_handle(active, drag, cursor)
        elif isinstance(drag, BoxSelect):
            self._drag_box(drag, cursor, finish=ev.isFinish())
        if ev.isFinish():
            self._finish_drag(active)
        return True

    def _begin_drag(self, scene: QPointF, mods: Qt.KeyboardModifier) -> ActiveDrag:
        """The drag a press at ``scene`` starts: a handle's, the keys' (a press on a key
        not selected selects it first; Ctrl scales) or a box select on empty space."""
        shift = bool(mods & Qt.KeyboardModifier.ShiftModifier)
        press = self._cursor(scene)
        handle = self.handle_at(scene)
        if handle is not None:
            cid, i, side = handle
            self._frozen_norm = {cid: self.display_transform(cid)}
            handle_drag = HandleDrag(self.doc, cid, i, side, self._frozen_norm[cid])
            return ActiveDrag(handle_drag, self.ctx.begin_gesture(handle_drag.text))
        hit = self.key_at(scene)
        if hit is not None:
            sel = press_selection(self.selection, hit, additive=shift)
            if sel is not None:
                self.set_selection(sel, hit)
            selection = self.selected_keys()
            self._frozen_norm = {c: self.display_transform(c) for c in selection}
            keys: KeysDrag
            if mods & Qt.KeyboardModifier.ControlModifier:
                keys = ScaleKeysDrag(self.doc, selection, hit, press, self.ctx.frame, self._frozen_norm, self.snap)
            else:
                keys = MoveKeysDrag(self.doc, selection, hit, press, self._frozen_norm, self.snap, self.axis_lock)
            return ActiveDrag(keys, self.ctx.begin_gesture(keys.text))
        return ActiveDrag(BoxSelect(press, additive=shift))

    def _preview(self, active: ActiveDrag, command: Command) -> None:
        """One mouse move of a gesture: the document shows ``command`` (built from the
        channels as they were when the drag began), folded into the drag's one step."""
        assert active.gesture is not None
        active.gesture.update(command)
        # The editor doing the gesture redraws its own preview now; the other views (and
        # this one again, at no cost: the channel object is the same) hear of the change at
        # the next tick of the frame clock, which would add up to a frame to every move.
        changes = getattr(command, "changes", None)
        if isinstance(changes, dict):
            for cid in changes:
                self.refresh_channel(cid)

    def _drag_keys(self, active: ActiveDrag, drag: KeysDrag, cursor: Cursor) -> None:
        """Move (or, Ctrl, scale about the current frame) the selected keys."""
        drag.snap = self.snap  # the editor's settings as they are at each move
        if isinstance(drag, ScaleKeysDrag):
            command = drag.move(cursor, pivot=self.ctx.frame)
        else:
            assert isinstance(drag, MoveKeysDrag)
            drag.axis_lock = self.axis_lock
            command = drag.move(cursor)
        if command is None:
            return
        self._preview(active, command)
        self._remap_selection(drag)

    def _remap_selection(self, drag: KeysDrag) -> None:
        """Keys may pass others while moving: select the moved keys at their new indices."""
        self.selection, active = drag.remap(self.doc.channels)
        self._note_selection_base()
        self.active = active or self._first_selected()
        self._update_live()
        self.keySelectionChanged.emit()

    def _drag_handle(self, active: ActiveDrag, drag: HandleDrag, cursor: Cursor) -> None:
        x0, x1 = self.vb.viewRange()[0]
        self._preview(active, drag.move(cursor, span=x1 - x0))
        self._update_live()
        self.keySelectionChanged.emit()

    def _drag_box(self, drag: BoxSelect, cursor: Cursor, finish: bool) -> None:
        if not finish:
            self.box.setRect(QRectF(*drag.rect(cursor)))
            self.box.show()
            return
        self.box.hide()
        channels = self.doc.channels
        display = {cid: self.display_transform(cid) for cid in self.visible
                   if cid in channels and channels[cid].keys}
        self.set_selection(drag.finish(self.doc, cursor, self.visible, display, self.selection))

    def _finish_drag(self, active: ActiveDrag) -> None:
        if active.gesture is not None:
            # Commit while the drag is still current: the views catch up on the last moves
            # (one change) without mapping the selection, which the drag kept itself.
            active.gesture.commit()
        self._drag = None
        drag = active.drag
        if isinstance(drag, KeysDrag):
            self._frozen_norm.clear()
            if any(self.doc.channels.get(c) != ch for c, ch in drag.base.items()):
                for cid, pairs in drag.moved.items():
                    history = self._moves.setdefault(cid, [])
                    history.extend((a, b) for a, b in pairs if a != b)
                    del history[:-MOVE_HISTORY]
        elif isinstance(drag, HandleDrag):
            self._frozen_norm.clear()
            self._note_selection_base()
        # The dragged channels stay live while selected; the cached layer is redrawn only
        # if some leave the live layer.
        self._update_live()

    @property
    def dragging(self) -> bool:
        return self._drag is not None and not self._drag.aborted

    def abort_drag(self) -> bool:
        """Escape: put everything back as it was before the drag and record nothing."""
        active = self._drag
        if active is None or active.aborted:
            return False
        if active.gesture is not None:
            active.gesture.abort()
            if isinstance(active.drag, KeysDrag):
                self.set_selection(active.drag.selection, active.drag.anchor)
            else:
                self._note_selection_base()
        self.box.hide()
        self._frozen_norm.clear()
        self._drag = ActiveDrag(None, aborted=True)
        self._update_live()
        return True

    # ------------------------------------------------------------------ keys
    _KEYS = {Qt.Key.Key_A, Qt.Key.Key_F, Qt.Key.Key_Home, Qt.Key.Key_Delete, Qt.Key.Key_Backspace,
             Qt.Key.Key_N, Qt.Key.Key_Escape}

    def handles_key(self, ev: QKeyEvent) -> bool:
        mods = ev.modifiers() & ~Qt.KeyboardModifier.KeypadModifier
        if ev.key() == Qt.Key.Key_A and mods == Qt.KeyboardModifier.ControlModifier:
            return True
        if ev.key() == Qt.Key.Key_Escape:
            return self.dragging
        return mods == Qt.KeyboardModifier.NoModifier and ev.key() in self._KEYS

    def key_press(self, ev: QKeyEvent) -> bool:
        key = ev.key()
        mods = ev.modifiers() & ~Qt.KeyboardModifier.KeypadModifier
        if key == Qt.Key.Key_Escape:
            return self.abort_drag()
        if mods not in (Qt.KeyboardModifier.NoModifier,):
            if key == Qt.Key.Key_A and mods == Qt.KeyboardModifier.ControlModifier:
                self.select_all()
                return True
            return False
        actions: dict[int, Callable[[], None]] = {
            Qt.Key.Key_A: self.frame_all,
            Qt.Key.Key_F: self.frame_selected,
            Qt.Key.Key_Home: self.frame_all,
            Qt.Key.Key_Delete: self.delete_selected,
            Qt.Key.Key_Backspace: self.delete_selected,
            Qt.Key.Key_N: lambda: self.set_normalised(not self.normalised),
        }
        fn = actions.get(key)
        if fn is None:
            return False
        fn()
        return True
