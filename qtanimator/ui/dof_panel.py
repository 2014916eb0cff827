"""The DOF panel below the outliner: one slider and spin box per degree of freedom of the
selected joint (:func:`qtanimator.ui.dof_specs.dof_specs`), previous / next joint and Reset
Pose buttons.

An edit keys the DOF at the current frame (with auto-key off it only poses, like a drag in
the editors); one slider drag is one gesture (``ctx.begin_gesture``): one undo step, and
Escape during the drag puts the value back.
"""

from __future__ import annotations

import math

from PySide6.QtCore import Qt
from PySide6.QtGui import QKeyEvent
from PySide6.QtWidgets import (
    QDoubleSpinBox,
    QGridLayout,
    QLabel,
    QPushButton,
    QSlider,
    QVBoxLayout,
    QWidget,
)

from qtanimator.document.commands import Command
from qtanimator.document.gesture import Gesture
from qtanimator.document.pose import PosePreview, autokey
from qtanimator.ui.context import EditorContext
from qtanimator.ui.dof_specs import DofSpec, dof_specs


class DofRow:
    """Slider and spin box for one DOF; edits key through ``panel``."""

    def __init__(self, panel: DofPanel, grid: QGridLayout, row: int, spec: DofSpec) -> None:
        self.panel = panel
        self.spec = spec
        self.label = QLabel(spec.label, panel)
        self.slider = QSlider(Qt.Orientation.Horizontal, panel)
        self.slider.setObjectName(f"dofSlider_{spec.label.replace(' ', '_')}")
        self.steps = spec.steps
        self.slider.setRange(int(math.floor(spec.minimum * self.steps)), int(math.ceil(spec.maximum * self.steps)))
        self.slider.setPageStep(10 * self.steps)
        self.spin = QDoubleSpinBox(panel)
        self.spin.setObjectName(f"dofSpin_{spec.label.replace(' ', '_')}")
        self.spin.setDecimals(spec.decimals)
        self.spin.setRange(*(spec.typed_range or (spec.minimum, spec.maximum)))
        self.spin.setSuffix(spec.suffix)
        self.spin.setKeyboardTracking(False)
        self.spin.setSingleStep(10.0 / self.steps)
        grid.addWidget(self.label, row, 0)
        grid.addWidget(self.slider, row, 1)
        grid.addWidget(self.spin, row, 2)
        self._gesture: Gesture | None = None
        self._aborted = False  # Escape ended the drag: ignore the slider until released
        self.set_value(spec.value)
        self.slider.sliderPressed.connect(self._begin)
        self.slider.sliderReleased.connect(self._end)
        self.slider.valueChanged.connect(self._slider_changed)
        self.spin.valueChanged.connect(self._spin_changed)

    def widgets(self) -> list[QWidget]:
        return [self.label, self.slider, self.spin]

    def set_value(self, value: float) -> None:
        self.spec.value = value
        for w in (self.slider, self.spin):
            w.blockSignals(True)
        self.slider.setValue(int(round(value * self.steps)))
        self.spin.setValue(value)
        for w in (self.slider, self.spin):
            w.blockSignals(False)

    @property
    def dragging(self) -> bool:
        return self._gesture is not None

    def _begin(self) -> None:
        """Slider pressed: one gesture until it is released (one undo step)."""
        self._aborted = False
        self._gesture = self.panel.ctx.begin_gesture(f"Set {self.spec.label}")

    def _end(self) -> None:
        self._aborted = False
        gesture, self._gesture = self._gesture, None
        if gesture is not None:
            gesture.commit()

    def abort(self) -> None:
        """Escape while dragging: put the value back as it was before the drag."""
        gesture, self._gesture = self._gesture, None
        if gesture is not None:
            self._aborted = True
            gesture.abort()
            self.panel.rebuild()

    def _slider_changed(self, v: int) -> None:
        if self._aborted:
            return
        value = v / self.steps
        self.spin.blockSignals(True)
        self.spin.setValue(value)
        self.spin.blockSignals(False)
        self.panel.key(self.spec, value, self._gesture)

    def _spin_changed(self, value: float) -> None:
        self.slider.blockSignals(True)
        self.slider.setValue(int(round(value * self.steps)))
        self.slider.blockSignals(False)
        self.panel.key(self.spec, value, None)


class DofPanel(QWidget):
    """The sliders of the selected joint, plus previous / next joint and reset pose."""

    def __init__(self, ctx: EditorContext, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("dofPanel")
        self.ctx = ctx
        self.rows: list[DofRow] = []
        layout = QVBoxLayout(self)
        layout.setContentsMargins(2, 2, 2, 2)
        self.title = QLabel("No joint selected", self)
        self.title.setObjectName("dofTitle")
        layout.addWidget(self.title)
        self.grid_host = QWidget(self)
        self.grid = QGridLayout(self.grid_host)
        self.grid.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.grid_host)
        # Previous / Next above Reset Pose: the outliner dock can be narrow (issue 30).
        buttons = QGridLayout()
        self.prev_button = QPushButton("◀ Previous", self)
        self.prev_button.setObjectName("previousJointButton")
        self.next_button = QPushButton("Next ▶", self)
        self.next_button.setObjectName("nextJointButton")
        self.reset_button = QPushButton("Reset Pose (R)", self)
        self.reset_button.setObjectName("resetPoseButton")
        buttons.addWidget(self.prev_button, 0, 0)
        buttons.addWidget(self.next_button, 0, 1)
        buttons.addWidget(self.reset_button, 1, 0, 1, 2)
        layout.addLayout(buttons)
        layout.addStretch(1)
        self._editing = False
        self._shown: tuple[str, str, tuple[tuple[str, float, float, int], ...]] | None = None

    def rebuild(self) -> None:
        asset, joint = self.ctx.selection
        specs = dof_specs(self.ctx.doc, asset, joint, self.ctx.time) if asset else []
        key = (asset, joint, tuple((s.label, s.minimum, s.maximum, s.steps) for s in specs))
        if key == self._shown and len(self.rows) == len(specs):
            for row, spec in zip(self.rows, specs):
                row.spec = spec
                row.set_value(spec.value)
            return
        for row in self.rows:
            for w in row.widgets():
                self.grid.removeWidget(w)
                w.deleteLater()
        self.rows = [DofRow(self, self.grid, i, s) for i, s in enumerate(specs)]
        self._shown = key
        if not asset:
            self.title.setText("No joint selected")
        else:
            self.title.setText(f"{asset} / {joint}" if joint else f"{asset} (position)")

    def keyPressEvent(self, event: QKeyEvent) -> None:
        if event.key() == Qt.Key.Key_Escape and any(row.dragging for row in self.rows):
            for row in self.rows:
                row.abort()
            event.accept()
            return
        super().keyPressEvent(event)

    def refresh_values(self) -> None:
        if self._editing or any(row.dragging for row in self.rows):
            return  # the row being edited already shows its value
        self.rebuild()

    def key(self, spec: DofSpec, value: float, gesture: Gesture | None) -> None:
        """Key ``value``: a preview of the slider's gesture, or one undo step of its own
        (arrow keys, page steps and typed values)."""
        self._editing = True
        try:
            doc = self.ctx.doc
            if spec.channel and not autokey(doc):
                # Auto-key off: pose without keying, like a drag in the editors.
                command: Command = PosePreview(doc, spec.pose_values(value, self.ctx.time), self.ctx.time,
                                               f"Pose {spec.label}", gesture)
            else:
                command = spec.make(value, self.ctx.time, None)
            if gesture is not None:
                gesture.update(command)
            else:
                self.ctx.push(command)
        finally:
            self._editing = False
