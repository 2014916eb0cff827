"""The dope sheet view (:class:`DopeSheetView`, object name ``dopeSheet``): the mouse, the
keys and the key edits on top of :class:`~qtanimator.ui.dope_canvas.DopeSheetCanvas`.

What a press, a box or a drag does to the keys is :mod:`qtanimator.ui.dope_drags` (no Qt);
this class picks what is under the mouse, turns pixels into frames and runs the gesture
protocol: a retime or a scale is one ``ctx.begin_gesture`` (one undo step; Escape or a
right click aborts it exactly), a paste or a delete one command.
"""

from __future__ import annotations

from typing import Any

from PySide6.QtCore import QEvent, QPointF, QRectF, Qt, Signal
from PySide6.QtGui import QContextMenuEvent, QCursor, QKeyEvent, QMouseEvent, QWheelEvent
from PySide6.QtWidgets import QWidget

from qtanimator.document.keying import KeyClip, KeyEdit, copy_keys, delete_keys_command
from qtanimator.ui import dope_drags as drags
from qtanimator.ui.dope_canvas import DopeSheetCanvas
from qtanimator.ui.dope_rows import HEADER_HEIGHT, INDENT, NAME_WIDTH, ROW_HEIGHT, Selection
from qtanimator.ui.key_clipboard import key_clip, put_key_clip

DRAG_START = 4           # pixels the mouse moves before a press becomes a drag


class DopeSheetView(DopeSheetCanvas):
    """The painted, interactive dope sheet (object name ``dopeSheet``)."""

    #: A sentence for the user (copied / pasted / skipped); the panel shows it.
    message = Signal(str)

    def __init__(self, ctx: Any, parent: QWidget | None = None) -> None:
        super().__init__(ctx, parent)
        self._pressed = Qt.MouseButton.NoButton
        self._press_pos = QPointF()
        self._last_pos: QPointF | None = None
        self._reselect: Selection | None = None
        self._box_mods = Qt.KeyboardModifier.NoModifier
        self._scale_origin = 0.0
        self._pan_start: tuple[QPointF, float, int] | None = None
        self._eat_context_menu = False

    # --------------------------------------------------------------- mouse
    def mousePressEvent(self, ev: QMouseEvent) -> None:
        pos = ev.position()
        button = ev.button()
        self._pressed |= button
        self._last_pos = pos
        if self._mode == "scale":
            if button == Qt.MouseButton.LeftButton:
                self.finish_scale()
            elif button == Qt.MouseButton.RightButton:
                self._eat_context_menu = True
                self.cancel()
            ev.accept()
            return
        if self._mode == "retime":
            if button == Qt.MouseButton.RightButton:
                self._eat_context_menu = True
                self.cancel()
            ev.accept()
            return
        if button == Qt.MouseButton.MiddleButton:
            self._mode = "pan"
            self._pan_start = (pos, self.left_frame, self._scroll)
            return
        if button != Qt.MouseButton.LeftButton:
            super().mousePressEvent(ev)
            return
        self._press_pos = pos
        mods = ev.modifiers()
        if pos.y() < HEADER_HEIGHT:
            if pos.x() >= NAME_WIDTH:
                self._mode = "scrub"
                self._scrub(pos.x())
            return
        if pos.x() < NAME_WIDTH:
            row = self.row_at(pos.y())
            if row is None:
                return
            if row.summary and pos.x() < 6 + row.depth * INDENT + INDENT:
                self.toggle_row(row)
            else:
                self.ctx.select(row.asset, row.joint)
                self.invalidate()
            return
        hit = self.key_at(pos)
        if hit is None:
            self._mode = "box"
            self._box_mods = mods
            self._box = QRectF(pos, pos)
            return
        press = drags.press_key(self.selection(), self.keys_at(*hit),
                                bool(mods & Qt.KeyboardModifier.ShiftModifier))
        if press.selection is not None:
            self.set_selection(press.selection)
        self._reselect = press.reselect  # a click (no drag) on a selected key selects only it
        self._mode = "press_key" if press.drag else ""
        ev.accept()

    def mouseMoveEvent(self, ev: QMouseEvent) -> None:
        pos = ev.position()
        self._last_pos = pos
        mode = self._mode
        if mode == "scale":
            self.update_scale(pos.x())
        elif not (ev.buttons() & self._pressed):
            return  # hover (a move's buttons can name a press made on another widget)
        elif mode == "scrub":
            self._scrub(pos.x())
        elif mode == "press_key":
            if (pos - self._press_pos).manhattanLength() >= DRAG_START and self.selection():
                self._begin_retime()
                self._update_retime(pos.x())
        elif mode == "retime":
            self._update_retime(pos.x())
        elif mode == "box":
            self._box = QRectF(self._press_pos, pos).normalized()
            self.update()
        elif mode == "pan" and self._pan_start is not None:
            start, left, scroll = self._pan_start
            self.left_frame = left - (pos.x() - start.x()) / self.px_per_frame
            self._auto_frame = False
            self.scrollbar.setValue(int(scroll - (pos.y() - start.y())))
            self.invalidate()

    def mouseReleaseEvent(self, ev: QMouseEvent) -> None:
        button = ev.button()
        self._pressed &= ~button
        mode = self._mode
        if button == Qt.MouseButton.MiddleButton and mode == "pan":
            self._mode = ""
            return
        if button != Qt.MouseButton.LeftButton:
            return
        if mode == "press_key":
            if self._reselect is not None:
                self.set_selection(self._reselect)
            self._mode = ""
        elif mode == "retime":
            self.finish_retime()
        elif mode == "box":
            self._finish_box(ev.position())
        elif mode == "scrub":
            self._mode = ""
        self._reselect = None

    def contextMenuEvent(self, event: QContextMenuEvent) -> None:
        if self._eat_context_menu or self._mode:
            self._eat_context_menu = False
            event.accept()
            return
        context_menu = getattr(self.parent(), "context_menu", None)  # the DopeSheetPanel's
        menu = context_menu() if callable(context_menu) else None
        if menu is not None:
            menu.popup(event.globalPos())

    def wheelEvent(self, ev: QWheelEvent) -> None:
        delta = ev.angleDelta()
        mods = ev.modifiers()
        steps = (delta.y() or delta.x()) / 120.0
        if mods & Qt.KeyboardModifier.ControlModifier:
            self.zoom(1.25 ** steps, ev.position().x())
        elif mods & Qt.KeyboardModifier.ShiftModifier or (delta.x() and not delta.y()):
            self.left_frame -= steps * 40.0 / self.px_per_frame
            self._auto_frame = False
            self.invalidate()
        else:
            self.scrollbar.setValue(int(self.scrollbar.value() - steps * 3 * ROW_HEIGHT))
        ev.accept()

    def _scrub(self, x: float) -> None:
        start, end = self.doc.frame_range
        self.ctx.set_frame(float(min(max(round(self.frame_at(x)), start), max(end, start))))

    def _finish_box(self, pos: QPointF) -> None:
        self._mode = ""
        rect = QRectF(self._press_pos, pos).normalized()
        shift = bool(self._box_mods & Qt.KeyboardModifier.ShiftModifier)
        ctrl = bool(self._box_mods & Qt.KeyboardModifier.ControlModifier)
        if rect.width() < DRAG_START and rect.height() < DRAG_START:
            if not (shift or ctrl):
                self.ctx.key_selection.clear(self)
            self.update()
            return
        rows = [r for i, r in enumerate(self.rows)
                if rect.top() <= self.row_y(i) + ROW_HEIGHT / 2.0 <= rect.bottom()]
        hits = self.keys_in(rows, self.frame_at(rect.left()), self.frame_at(rect.right()))
        self.set_selection(drags.box_select(self.selection(), hits, add=shift, remove=ctrl))

    # ------------------------------------------------------------- gestures
    def _begin_gesture(self, mode: str, drag: drags.RetimeDrag | drags.ScaleDrag) -> None:
        self._drag = drag
        self._gesture = self.ctx.begin_gesture(drag.text)
        self._mode = mode

    def _preview(self, edit: KeyEdit | None) -> None:
        if edit is None or self._gesture is None:
            return
        self._gesture.update(edit.command)
        self.set_selection(edit.selection)

    def _begin_retime(self) -> None:
        self._reselect = None
        sel = self.selection()
        if not sel:
            self._mode = ""
            return
        self._begin_gesture("retime", drags.RetimeDrag(self.doc, sel, self.snap))

    def _update_retime(self, x: float) -> None:
        if isinstance(self._drag, drags.RetimeDrag):
            self._preview(self._drag.move((x - self._press_pos.x()) / self.px_per_frame))

    def finish_retime(self) -> None:
        self._end_gesture(commit=True)

    def begin_scale(self) -> bool:
        """S: scale the selected keys about the current frame as the mouse moves."""
        if self._mode:
            return False
        pos = self._last_pos
        if pos is None or not self.rect().contains(pos.toPoint()):
            pos = QPointF(self.mapFromGlobal(QCursor.pos()))
        sel = self.selection()
        if not sel:
            self.message.emit("Select keys to scale first.")
            return False
        self._begin_gesture("scale", drags.ScaleDrag(self.doc, sel, self.snap))
        self._scale_origin = pos.x()
        self.setFocus()
        self.update()
        return True

    def scale_factor_at(self, x: float) -> float:
        """The factor the S gesture gives with the mouse at ``x`` (:func:`dope_drags.scale_factor`)."""
        return drags.scale_factor(x, float(self.x_of(self.ctx.frame)), self._scale_origin)

    def update_scale(self, x: float) -> None:
        if isinstance(self._drag, drags.ScaleDrag):
            edit = self._drag.move(self.scale_factor_at(x), self.ctx.time)
            if edit is not None:
                self._preview(edit)
                self.update()

    def finish_scale(self) -> None:
        self._end_gesture(commit=True)

    def cancel(self) -> bool:
        """Escape: abort a retime or scale (the document goes back exactly), or a box."""
        if self._mode in ("retime", "scale"):
            self._end_gesture(commit=False)
            return True
        if self._mode == "box":
            self._mode = ""
            self.update()
            return True
        return False

    def _end_gesture(self, commit: bool) -> None:
        gesture, self._gesture = self._gesture, None
        drag, self._drag = self._drag, None
        self._mode = ""
        if gesture is None:
            return
        if commit:
            gesture.commit()
        else:
            gesture.abort()
            if drag is not None:
                self.set_selection(drag.selection)
        self.invalidate()

    # ----------------------------------------------------------------- keys
    def _handles_key(self, ev: QKeyEvent) -> bool:
        key = ev.key()
        if key == Qt.Key.Key_Escape:
            return bool(self._mode)
        return self._mode == "scale" and key in (Qt.Key.Key_Return, Qt.Key.Key_Enter)

    def event(self, ev: QEvent) -> bool:
        if ev.type() == QEvent.Type.ShortcutOverride and self._handles_key(ev):  # type: ignore[arg-type]
            ev.accept()
            return True
        return super().event(ev)

    def keyPressEvent(self, ev: QKeyEvent) -> None:
        key = ev.key()
        if key == Qt.Key.Key_Escape and self.cancel():
            ev.accept()
            return
        if self._mode == "scale" and key in (Qt.Key.Key_Return, Qt.Key.Key_Enter):
            self.finish_scale()
            ev.accept()
            return
        super().keyPressEvent(ev)

    def focusOutEvent(self, ev: Any) -> None:
        if self._mode == "scale":
            self.finish_scale()  # like a click elsewhere: keep what the user sees
        super().focusOutEvent(ev)

    # ---------------------------------------------------------------- edits
    def _push(self, edit: KeyEdit) -> bool:
        if edit.is_noop():
            return False
        self._own_edit = True
        try:
            self.ctx.push(edit.command)
        finally:
            self._own_edit = False
        self.set_selection(edit.selection)
        return True

    def delete_selected(self) -> None:
        sel = self.selection()
        if sel and self._mode == "":
            self._push(delete_keys_command(self.doc, sel))

    def copy_selected(self) -> KeyClip | None:
        sel = self.selection()
        if not sel:
            self.message.emit("Select keys to copy first.")
            return None
        clip = copy_keys(self.doc, sel)
        put_key_clip(clip)
        self.message.emit(drags.copy_message(clip))
        return clip

    def paste(self, mode: str = "merge") -> KeyEdit | None:
        """Paste the clipboard's keys at the current frame (onto the selected character
        when none of the copied channels is in the document)."""
        if self._mode:
            return None
        clip = key_clip()
        if clip is None or not clip:
            self.message.emit("No keys to paste: copy keys first.")
            return None
        edit = drags.paste_edit(self.doc, clip, self.ctx.time, mode, self.ctx.selection[0])
        self._push(edit)
        self.message.emit(drags.paste_message(edit, self.ctx.frame))
        return edit
