"""Numeric fields for the active key: frame, value, in slope and out slope.

Values are shown in the channel's display unit (degrees for rotations, as the plot shows
them) and slopes in that unit per second. Editing a slope makes that side fixed; unless
the key is broken, the other side follows, as when dragging a handle. Each edit is one
command. With no key selected the fields are empty and disabled.
"""

from __future__ import annotations

from typing import Any

from PySide6.QtWidgets import QHBoxLayout, QLabel, QWidget

from qtanimator.core.channel import Tangent
from qtanimator.document.commands import EditKey
from qtanimator.document.curve_commands import SetKeySlopes
from qtanimator.ui.curves.normalisation import unit_suffix
from qtanimator.ui.curves.view import CurveView
from qtanimator.ui.widgets import CheckedDoubleSpinBox


def _spin(name: str, decimals: int, tip: str) -> CheckedDoubleSpinBox:
    box = CheckedDoubleSpinBox(label=name.removeprefix("curveKey").replace("Slope", " slope"))
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

    def unit(self, cid: str) -> float:
        """Shown value per document value (degrees for rotations)."""
        return self.view.unit(cid)

    def load(self) -> None:
        found = self._active()
        boxes = (self.frame, self.value, self.in_slope, self.out_slope)
        for box in boxes:
            box.setEnabled(found is not None)
        if found is None:
            self.label.setText("No key selected")
            for box in boxes:
                box.clear()  # empty: nothing to show (the value is kept, unused)
            return
        cid, i, ch = found
        key = ch.keys[i]
        s_in, s_out = ch.slopes()
        count = sum(len(s) for s in self.view.selection.values())
        self.label.setText(f"{cid} [{i}]" + (f" (+{count - 1})" if count > 1 else ""))
        unit, suffix = self.unit(cid), unit_suffix(cid)
        self._loading = True
        try:
            self.value.setSuffix(suffix)
            self.in_slope.setSuffix(f"{suffix}/s" if suffix else "")
            self.out_slope.setSuffix(f"{suffix}/s" if suffix else "")
            self.frame.setValue(key.time * self.view.fps)
            self.value.setValue(key.value * unit)
            self.in_slope.setValue(float(s_in[i]) * unit)
            self.out_slope.setValue(float(s_out[i]) * unit)
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
            self.load()  # another key is at that time: refused, and the field says why
            self.frame.refuse(f"Another key of {cid} is at frame {frame:g}.")
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
        value = value / self.unit(cid)
        if not _same(value, key.value, self.value.decimals(), self.unit(cid)):
            self.view.push(EditKey(self.view.doc, cid, i, key.moved(key.time, value), text="Key Value"))

    def _slope_edited(self, side: str, slope: float) -> None:
        found = self._active()
        if self._loading or found is None:
            return
        cid, i, ch = found
        key = ch.keys[i]
        slope = slope / self.unit(cid)
        if key.broken:
            ins, outs = (slope, None) if side == "in" else (None, slope)
        else:
            ins = outs = slope
        if (ins is None or (key.in_tangent is Tangent.FIXED and key.in_slope == ins)) and \
                (outs is None or (key.out_tangent is Tangent.FIXED and key.out_slope == outs)):
            return
        self.view.push(SetKeySlopes(self.view.doc, cid, i, ins, outs, text="Key Slope"))



def _same(value: float, current: float, decimals: int, unit: float) -> bool:
    """True when ``value`` (from a field showing ``decimals`` decimals of ``unit``·value)
    is the document's ``current`` as the field shows it: no edit."""
    return round(value * unit, decimals) == round(current * unit, decimals)
