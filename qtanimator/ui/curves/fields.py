"""Numeric fields for the active key: frame, value, in slope and out slope.

Slopes are shown in value per second (the channel's unit, as ``.anim`` files store them).
Editing a slope makes that side fixed; unless the key is broken, the other side follows,
as when dragging a handle. Each edit is one command.
"""

from __future__ import annotations

from typing import Any

from PySide6.QtWidgets import QDoubleSpinBox, QHBoxLayout, QLabel, QWidget

from qtanimator.core.channel import Tangent
from qtanimator.document.commands import EditKey
from qtanimator.document.curve_commands import SetKeySlopes
from qtanimator.ui.curves.view import CurveView


def _spin(name: str, decimals: int, tip: str) -> QDoubleSpinBox:
    box = QDoubleSpinBox()
    box.setObjectName(name)
    box.setRange(-1e9, 1e9)
    box.setDecimals(decimals)
    box.setKeyboardTracking(False)   # one command on Enter / focus out / arrow step
    box.setToolTip(tip)
    box.setMinimumWidth(90)
    return box


class KeyFields(QWidget):
    def __init__(self, view: CurveView, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.view = view
        self.frame = _spin("curveKeyFrame", 3, "Time of the active key, in frames")
        self.value = _spin("curveKeyValue", 5, "Value of the active key")
        self.in_slope = _spin("curveKeyInSlope", 5, "In slope (value per second); sets a fixed slope")
        self.out_slope = _spin("curveKeyOutSlope", 5, "Out slope (value per second); sets a fixed slope")
        self.label = QLabel("No key selected")
        self.label.setObjectName("curveKeyLabel")
        layout = QHBoxLayout(self)
        layout.setContentsMargins(4, 2, 4, 2)
        layout.addWidget(self.label, 1)
        for text, box in (("Frame", self.frame), ("Value", self.value), ("In", self.in_slope),
                          ("Out", self.out_slope)):
            layout.addWidget(QLabel(text))
            layout.addWidget(box)
        self._loading = False
        self.frame.valueChanged.connect(self._frame_edited)
        self.value.valueChanged.connect(self._value_edited)
        self.in_slope.valueChanged.connect(lambda v: self._slope_edited("in", v))
        self.out_slope.valueChanged.connect(lambda v: self._slope_edited("out", v))
        view.keySelectionChanged.connect(self.load)
        view.ctx.documentChanged.connect(lambda _e: self.load())
        self.load()

    def _active(self) -> tuple[str, int, Any] | None:
        active = self.view.active
        if active is None:
            return None
        cid, i = active
        ch = self.view.doc.channels.get(cid)
        if ch is None or i >= len(ch.keys):
            return None
        return cid, i, ch

    def load(self) -> None:
        found = self._active()
        boxes = (self.frame, self.value, self.in_slope, self.out_slope)
        for box in boxes:
            box.setEnabled(found is not None)
        if found is None:
            self.label.setText("No key selected")
            return
        cid, i, ch = found
        key = ch.keys[i]
        s_in, s_out = ch.slopes()
        count = sum(len(s) for s in self.view.selection.values())
        self.label.setText(f"{cid} [{i}]" + (f" (+{count - 1})" if count > 1 else ""))
        self._loading = True
        try:
            self.frame.setValue(key.time * self.view.fps)
            self.value.setValue(key.value)
            self.in_slope.setValue(float(s_in[i]))
            self.out_slope.setValue(float(s_out[i]))
        finally:
            self._loading = False

    def _frame_edited(self, frame: float) -> None:
        found = self._active()
        if self._loading or found is None:
            return
        cid, i, ch = found
        key = ch.keys[i]
        t = frame / self.view.fps
        if t == key.time:
            return
        try:
            cmd = EditKey(self.view.doc, cid, i, key.moved(t, key.value), text="Key Time")
        except ValueError:
            self.load()  # another key is at that time
            return
        self.view.push(cmd)
        j = self.view.doc.channels[cid].key_index(t)
        if j is not None:
            self.view.set_selection({**self.view.selected_keys(), cid: [j]}, (cid, j))

    def _value_edited(self, value: float) -> None:
        found = self._active()
        if self._loading or found is None:
            return
        cid, i, ch = found
        key = ch.keys[i]
        if value != key.value:
            self.view.push(EditKey(self.view.doc, cid, i, key.moved(key.time, value), text="Key Value"))

    def _slope_edited(self, side: str, slope: float) -> None:
        found = self._active()
        if self._loading or found is None:
            return
        cid, i, ch = found
        key = ch.keys[i]
        if key.broken:
            ins, outs = (slope, None) if side == "in" else (None, slope)
        else:
            ins = outs = slope
        if (ins is None or (key.in_tangent is Tangent.FIXED and key.in_slope == ins)) and \
                (outs is None or (key.out_tangent is Tangent.FIXED and key.out_slope == outs)):
            return
        self.view.push(SetKeySlopes(self.view.doc, cid, i, ins, outs, text="Key Slope"))

