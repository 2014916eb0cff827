"""The light dock (``lightDock``): position, colour and intensity of the two lights, and the
ambient colour. Every edit is a ``SetParameter`` command on ``light1.*`` / ``light2.*`` /
``lights.ambient`` (one undo step per field drag); undo and redo refresh the fields."""

from __future__ import annotations

import itertools
from typing import Any

from PySide6.QtCore import Qt
from PySide6.QtGui import QColor
from PySide6.QtWidgets import (
    QColorDialog,
    QFormLayout,
    QFrame,
    QGroupBox,
    QHBoxLayout,
    QPushButton,
    QScrollArea,
    QVBoxLayout,
    QWidget,
)

from qtanimator.document.commands import SetParameter
from qtanimator.document.document import DocumentChange
from qtanimator.document.parameters import AMBIENT_PARAMETER, LIGHT_NAMES, LIGHTS
from qtanimator.render.gl.lights import parameter
from qtanimator.ui.context import EditorContext
from qtanimator.ui.param_fields import spin_for
from qtanimator.ui.widgets import CheckedDoubleSpinBox, wrap_long_rows

_gestures = itertools.count(1)
#: The narrowest a position field (x, y or z) may get, in pixels: three share a row.
POSITION_MIN_WIDTH = 56
# The fields' ranges, steps, decimals and labels come from the parameter schema
# (qtanimator.document.parameters.LIGHTS): a light's intensity is any number ≥ 0 and its
# position any place (the maximums are far beyond use). A typed value outside them is
# refused with the reason shown, never clamped.


def _to_qcolor(rgb: Any) -> QColor:
    r, g, b = (min(max(float(c), 0.0), 1.0) for c in rgb)
    return QColor.fromRgbF(r, g, b)


class ColorButton(QPushButton):
    """A button showing a colour; clicking opens the colour picker."""

    def __init__(self, panel: LightPanel, path: str) -> None:
        super().__init__(panel)
        self.panel = panel
        self.path = path
        self.setObjectName(path.replace(".", "_"))
        self.clicked.connect(self._pick)

    def show_color(self, rgb: Any) -> None:
        c = _to_qcolor(rgb)
        self.setText(c.name())
        self.setStyleSheet(f"background-color: {c.name()}; color: {'black' if c.lightnessF() > 0.5 else 'white'}")

    def _pick(self) -> None:
        c = QColorDialog.getColor(_to_qcolor(parameter(self.panel.ctx.doc, self.path)), self, "Light colour")
        if c.isValid():
            self.panel.set_color(self.path, c)
            self.panel.end_gesture()


class LightPanel(QWidget):
    def __init__(self, ctx: EditorContext, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("lightPanel")
        self.ctx = ctx
        self.position: dict[str, list[CheckedDoubleSpinBox]] = {}
        self.intensity: dict[str, CheckedDoubleSpinBox] = {}
        self.color: dict[str, ColorButton] = {}
        self._updating = False
        self._gesture: tuple[str, int] | None = None
        outer = QVBoxLayout(self)
        outer.setContentsMargins(0, 0, 0, 0)
        # The groups scroll when the dock is short or narrow (a laptop screen, issue 30).
        self.scroll_area = QScrollArea(self)
        self.scroll_area.setObjectName("lightScroll")
        self.scroll_area.setWidgetResizable(True)
        self.scroll_area.setFrameShape(QFrame.Shape.NoFrame)
        body = QWidget(self.scroll_area)
        self.scroll_area.setWidget(body)
        outer.addWidget(self.scroll_area)
        layout = QVBoxLayout(body)
        for i, name in enumerate(LIGHT_NAMES, start=1):
            box = QGroupBox(f"Light {i}", body)
            form = QFormLayout(box)
            position = LIGHTS[f"{name}.position"]
            row = QHBoxLayout()
            spins: list[CheckedDoubleSpinBox] = []
            for axis in "xyz":
                s = spin_for(position, box, f"{name}_position_{axis}", f"{position.label} {axis}")
                assert isinstance(s, CheckedDoubleSpinBox)
                s.setMinimumWidth(POSITION_MIN_WIDTH)
                s.valueChanged.connect(lambda _v, n=name: self._position_edited(n))
                s.editingFinished.connect(self.end_gesture)
                row.addWidget(s)
                spins.append(s)
            self.position[name] = spins
            form.addRow("Position", row)
            self.color[name] = ColorButton(self, f"{name}.color")
            form.addRow("Colour", self.color[name])
            # A typed value is one edit on Enter (spin_for turns keyboard tracking off): with a
            # command per keystroke, the refresh after "1" rewrote the field to "1.00" under
            # the typing and "1.5" became 1.0.
            inten = spin_for(LIGHTS[f"{name}.intensity"], box, f"{name}_intensity")
            assert isinstance(inten, CheckedDoubleSpinBox)
            inten.valueChanged.connect(lambda v, n=name: self._push(f"{n}.intensity", float(v)))
            inten.editingFinished.connect(self.end_gesture)
            self.intensity[name] = inten
            form.addRow("Intensity", inten)
            layout.addWidget(box)
        amb = QGroupBox("Ambient", body)
        form = QFormLayout(amb)
        self.color[AMBIENT_PARAMETER] = ColorButton(self, AMBIENT_PARAMETER)
        form.addRow("Colour", self.color[AMBIENT_PARAMETER])
        layout.addWidget(amb)
        layout.addStretch(1)
        wrap_long_rows(body)
        ctx.documentChanged.connect(self._on_changed)
        ctx.documentReset.connect(self.refresh)
        self.refresh()

    def _push(self, path: str, value: Any) -> None:
        if self._updating:
            return
        if parameter(self.ctx.doc, path) == value and path in self.ctx.doc.parameters:
            return
        if self._gesture is None or self._gesture[0] != path:
            self._gesture = (path, next(_gestures))
        self.ctx.push(SetParameter(self.ctx.doc, path, value, text=f"Set {path.replace('.', ' ')}",
                                   gesture=("light", self._gesture)))

    def end_gesture(self) -> None:
        """The next edit starts a new undo step (a field lost focus or Enter was pressed)."""
        self._gesture = None

    def _position_edited(self, name: str) -> None:
        self._push(f"{name}.position", [float(s.value()) for s in self.position[name]])

    def set_color(self, path: str, color: QColor) -> None:
        """Set a light (or the ambient) colour, as the colour picker does."""
        self._push(path, [round(color.redF(), 4), round(color.greenF(), 4), round(color.blueF(), 4)])

    def _on_changed(self, change: DocumentChange) -> None:
        if any(p.startswith("light") or p == AMBIENT_PARAMETER for p in change.parameters):
            self.refresh()

    def refresh(self) -> None:
        doc = self.ctx.doc
        self._updating = True
        try:
            for name in LIGHT_NAMES:
                for s, v in zip(self.position[name], parameter(doc, f"{name}.position")):
                    s.setValue(float(v))
                self.intensity[name].setValue(float(parameter(doc, f"{name}.intensity")))
                self.color[name].show_color(parameter(doc, f"{name}.color"))
            self.color[AMBIENT_PARAMETER].show_color(parameter(doc, AMBIENT_PARAMETER))
        finally:
            self._updating = False


def install(window: Any) -> None:
    panel = LightPanel(window.ctx, window)
    window.light_panel = panel
    window.add_dock("lightDock", "Lights", panel, Qt.DockWidgetArea.RightDockWidgetArea)
