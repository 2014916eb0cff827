"""Numeric fields for the active key: frame, value, in slope and out slope.

Values are shown in the channel's display unit (degrees for rotations, as the plot shows
them) and slopes in that unit per second. Editing a slope makes that side fixed; unless
the key is broken, the other side follows, as when dragging a handle. Each edit is one
command. With no key selected the fields are empty and disabled. When the active key has a
TCB (Kochanek–Bartels) side, its Tension, Continuity and Bias fields (−1…1) show too.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from PySide6.QtWidgets import QHBoxLayout, QLabel, QSizePolicy, QWidget

from qtanimator.core.channel import Tangent
from qtanimator.document.commands import EditKey
from qtanimator.document.curve_commands import SetKeySlopes
from qtanimator.ui.curves.normalisation import unit_suffix
from qtanimator.ui.curves.view import CurveView
from qtanimator.ui.widgets import CheckedDoubleSpinBox

#: The narrowest a key field may get, in pixels: the row shares the curve editor's width with
#: the channel tree (a 1366-pixel laptop screen, issue 30); a long value scrolls in its field.
KEY_FIELD_MIN_WIDTH = 64


def _spin(name: str, decimals: int, tip: str) -> CheckedDoubleSpinBox:
    box = CheckedDoubleSpinBox(label=name.removeprefix("curveKey").replace("Slope", " slope"))
    box.setObjectName(name)
    box.setRange(-1e9, 1e9)
    box.setDecimals(decimals)
    box.setKeyboardTracking(False)   # one command on Enter / focus out / arrow step
    box.setToolTip(tip)
    box.setMinimumWidth(KEY_FIELD_MIN_WIDTH)
    return box


class KeyFields(QWidget):
    def __init__(self, view: CurveView, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.view = view
        self.frame = _spin("curveKeyFrame", 3, "Time of the active key, in frames")
        self.value = _spin("curveKeyValue", 5, "Value of the active key")
        self.in_slope = _spin("curveKeyInSlope", 5, "In slope (value per second); sets a fixed slope")
        self.out_slope = _spin("curveKeyOutSlope", 5, "Out slope (value per second); sets a fixed slope")
        # Kochanek–Bartels parameters of a key with a TCB side (hidden otherwise).
        self.tcb: dict[str, CheckedDoubleSpinBox] = {}
        self._tcb_labels: list[QLabel] = []
        for name, tip in (("tension", "Tension: +1 tightens the curve at the key, −1 rounds it"),
                          ("continuity", "Continuity: 0 keeps the slope continuous; −1 box corners, +1 inverted "
                                         "corners"),
                          ("bias", "Bias: +1 overshoots after the key (follow-through), −1 before it")):
            box = _spin(f"curveKey{name.capitalize()}", 3, tip)
            box.setRange(-1.0, 1.0)
            box.setSingleStep(0.1)
            box.setMinimumWidth(70)
            self.tcb[name] = box
        self.label = QLabel("No key selected")
        self.label.setObjectName("curveKeyLabel")
        # The channel name takes what room is left, and none when there is none (its full
        # text is the tooltip): it never makes the curve editor wider.
        self.label.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Preferred)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(4, 2, 4, 2)
        layout.addWidget(self.label, 1)
        for text, box in (("Frame", self.frame), ("Value", self.value), ("In", self.in_slope),
                          ("Out", self.out_slope), ("T", self.tcb["tension"]), ("C", self.tcb["continuity"]),
                          ("B", self.tcb["bias"])):
            label = QLabel(text)
            layout.addWidget(label)
            layout.addWidget(box)
            if len(text) == 1:
                label.setToolTip(box.toolTip())
                self._tcb_labels.append(label)
        self._loading = False
        self.frame.valueChanged.connect(self._frame_edited)
        self.value.valueChanged.connect(self._value_edited)
        self.in_slope.valueChanged.connect(lambda v: self._slope_edited("in", v))
        self.out_slope.valueChanged.connect(lambda v: self._slope_edited("out", v))
        for name, box in self.tcb.items():
            box.valueChanged.connect(lambda v, n=name: self._tcb_edited(n, v))
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
            self._show_tcb(None)
            self.label.setText("No key selected")
            self.label.setToolTip("")
            for box in boxes:
                box.clear()  # empty: nothing to show (the value is kept, unused)
            return
        cid, i, ch = found
        key = ch.keys[i]
        self._show_tcb(key if Tangent.TCB in (key.in_tangent, key.out_tangent) else None)
        s_in, s_out = ch.slopes()
        count = sum(len(s) for s in self.view.selection.values())
        self.label.setText(f"{cid} [{i}]" + (f" (+{count - 1})" if count > 1 else ""))
        self.label.setToolTip(self.label.text())
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

    def _show_tcb(self, key: Any) -> None:
        """The Tension / Continuity / Bias fields: shown with ``key``'s values, or hidden."""
        shown = key is not None
        for label in self._tcb_labels:
            label.setVisible(shown)
        was = self._loading
        self._loading = True
        try:
            for name, box in self.tcb.items():
                box.setVisible(shown)
                box.setEnabled(shown)
                if shown:
                    box.setValue(float(getattr(key, name)))
        finally:
            self._loading = was

    def _tcb_edited(self, name: str, value: float) -> None:
        found = self._active()
        if self._loading or found is None:
            return
        cid, i, ch = found
        key = ch.keys[i]
        if round(float(getattr(key, name)), 3) == round(value, 3):
            return
        self.view.push(EditKey(self.view.doc, cid, i, replace(key, **{name: float(value)}),
                               text=f"Key {name.capitalize()}"))

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
