"""The 3D view's camera as numbers: distance, azimuth and inclination (CSE169's camera
controls), in View ▸ 3D Camera….

The fields follow the camera both ways: orbiting, zooming or framing with the mouse updates
them (``Viewport3D.cameraChanged``), and editing one moves the camera at once
(``Viewport3D.set_camera``). The camera is view state: no undo step, saved with the project.
"""

from __future__ import annotations

from typing import Any, Protocol

from PySide6.QtCore import Qt, SignalInstance
from PySide6.QtWidgets import (
    QAbstractSpinBox,
    QDialog,
    QDialogButtonBox,
    QDoubleSpinBox,
    QFormLayout,
    QVBoxLayout,
    QWidget,
)

from qtanimator.render.gl.camera import OrbitCamera


class CameraView(Protocol):
    """What the fields need of a view (the 3D view, :mod:`qtanimator.ui.viewport`, is one):
    its orbit camera, a signal when that moves, and a way to place it by numbers."""

    @property
    def camera(self) -> OrbitCamera: ...

    @property
    def cameraChanged(self) -> SignalInstance: ...

    def set_camera(self, distance: float | None = None, azimuth: float | None = None,
                   inclination: float | None = None) -> None: ...


def _box(parent: QWidget, name: str, lo: float, hi: float, decimals: int, suffix: str = "") -> QDoubleSpinBox:
    box = QDoubleSpinBox(parent)
    box.setObjectName(name)
    box.setRange(lo, hi)
    box.setDecimals(decimals)
    box.setSuffix(suffix)
    box.setAccelerated(True)
    return box


class CameraFields(QWidget):
    """Distance, azimuth and inclination (degrees) of a view's orbit camera (the 3D view's)."""

    def __init__(self, view: CameraView, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("cameraFields")
        self.view = view
        form = QFormLayout(self)
        self.distance = _box(self, "cameraDistance", 1e-3, 1e5, 3)
        self.distance.setStepType(QAbstractSpinBox.StepType.AdaptiveDecimalStepType)
        self.distance.setToolTip("Distance from the camera to the point it orbits")
        self.azimuth = _box(self, "cameraAzimuth", 0.0, 360.0, 1, "°")
        self.azimuth.setWrapping(True)
        self.azimuth.setSingleStep(5.0)
        self.azimuth.setToolTip("Angle about the vertical axis; 0° looks along −z")
        self.inclination = _box(self, "cameraInclination", -89.0, 89.0, 1, "°")
        self.inclination.setSingleStep(5.0)
        self.inclination.setToolTip("Elevation above the floor; negative looks from below")
        form.addRow("Distance", self.distance)
        form.addRow("Azimuth", self.azimuth)
        form.addRow("Inclination", self.inclination)
        self._showing = False
        self.refresh()
        self.distance.valueChanged.connect(lambda v: self._edited(distance=v))
        self.azimuth.valueChanged.connect(lambda v: self._edited(azimuth=v))
        self.inclination.valueChanged.connect(lambda v: self._edited(inclination=v))
        view.cameraChanged.connect(self.refresh)

    def refresh(self) -> None:
        """Show the camera's values (a field being typed in keeps an equal value as typed)."""
        c = self.view.camera
        self._showing = True
        try:
            for box, value in ((self.distance, c.distance), (self.azimuth, c.azimuth % 360.0),
                               (self.inclination, c.inclination)):
                shown = box.value()
                same = abs(shown - value) < 0.5 * 10.0 ** -box.decimals()
                if box is self.azimuth:
                    same = same or abs(abs(shown - value) - 360.0) < 0.05
                if not same:
                    box.setValue(value)
        finally:
            self._showing = False

    def _edited(self, **value: Any) -> None:
        if not self._showing:
            self.view.set_camera(**value)


class CameraDialog(QDialog):
    """A small tool window holding :class:`CameraFields` (it stays open while you orbit)."""

    def __init__(self, view: CameraView, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("cameraDialog")
        self.setWindowTitle("3D Camera")
        self.setWindowFlag(Qt.WindowType.Tool, True)
        self.fields = CameraFields(view, self)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Close, self)
        buttons.rejected.connect(self.close)
        layout = QVBoxLayout(self)
        layout.addWidget(self.fields)
        layout.addWidget(buttons)


def show_camera_dialog(window: Any, view: CameraView) -> CameraDialog:
    """View ▸ 3D Camera…: show (or raise) the window's camera dialog."""
    dialog = getattr(window, "camera_dialog", None)
    if not isinstance(dialog, CameraDialog) or dialog.fields.view is not view:
        dialog = CameraDialog(view, window)
        window.camera_dialog = dialog
    dialog.fields.refresh()
    dialog.show()
    dialog.raise_()
    dialog.activateWindow()
    return dialog


__all__ = ["CameraDialog", "CameraFields", "CameraView", "show_camera_dialog"]
