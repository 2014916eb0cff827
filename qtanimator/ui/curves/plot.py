"""The curve editor's plot widget and its pyqtgraph parts: they route mouse and key events.

:class:`CurvePlot` (objectName ``curvePlot``) hands its keys, hovers and press modifiers to
the curve view; :class:`CurveViewBox` its left-button clicks and drags (the rest zooms and
pans); :class:`FrameLine` is the playhead, dragged by its handle only. What the events do
is the view's (:class:`PlotOwner`, implemented by :class:`qtanimator.ui.curves.view.CurveView`).
"""

from __future__ import annotations

from typing import Any, Protocol

import pyqtgraph as pg
from PySide6.QtCore import QEvent, QPointF, Qt
from PySide6.QtGui import QColor, QKeyEvent, QMouseEvent
from PySide6.QtWidgets import QWidget

PLAYHEAD_HANDLE = 14.0  # pixels: the playhead's handle at the top of the plot
BACKGROUND = QColor(38, 40, 44)


class PlotOwner(Protocol):
    """What the plot's parts ask of the curve view."""

    ctx: Any
    press_modifiers: Qt.KeyboardModifier
    context_menu_requested: Any

    @property
    def vb(self) -> CurveViewBox: ...

    def click(self, scene: QPointF, mods: Qt.KeyboardModifier) -> None: ...

    def select_under(self, scene: QPointF) -> None: ...

    def drag_event(self, ev: Any) -> bool: ...

    def scrub(self, scene: QPointF, finish: bool = False) -> None: ...

    def hover_at(self, scene: QPointF | None) -> None: ...

    def handles_key(self, ev: QKeyEvent) -> bool: ...

    def key_press(self, ev: QKeyEvent) -> bool: ...


class FrameLine(pg.InfiniteLine):
    """The current-frame line (the playhead). Only its handle, the triangle at the top of
    the plot, drags it (and the time axis scrubs): a key or a handle on the line takes
    the mouse like any other, and clicks on the line go to what is under it."""

    def __init__(self, view: PlotOwner, **kw: Any) -> None:
        super().__init__(**kw)
        self._view = view
        self.addMarker("v", position=1.0, size=PLAYHEAD_HANDLE)

    def handle_scene_pos(self) -> QPointF:
        """Scene position of the middle of the handle."""
        vb = self._view.vb
        x = vb.mapViewToScene(QPointF(self.value(), 0.0)).x()
        return QPointF(x, vb.sceneBoundingRect().top() + PLAYHEAD_HANDLE / 4.0)

    def at_handle(self, scene: QPointF) -> bool:
        """True when ``scene`` is on the handle (a little larger than drawn)."""
        top = self._view.vb.sceneBoundingRect().top()
        x = self._view.vb.mapViewToScene(QPointF(self.value(), 0.0)).x()
        reach = PLAYHEAD_HANDLE / 2.0 + 3.0
        return abs(scene.x() - x) <= reach and top - 3.0 <= scene.y() <= top + PLAYHEAD_HANDLE / 2.0 + 4.0

    def hoverEvent(self, ev: Any) -> None:
        if not ev.isExit() and self.movable and self.at_handle(ev.scenePos()) \
                and ev.acceptDrags(Qt.MouseButton.LeftButton):
            self.setMouseHover(True)
        else:
            self.setMouseHover(False)

    def mouseDragEvent(self, ev: Any) -> None:
        if ev.isStart() and not self.at_handle(ev.buttonDownScenePos()):
            ev.ignore()
            return
        super().mouseDragEvent(ev)

    def mouseClickEvent(self, ev: Any) -> None:
        ev.ignore()  # a click on the line is a click on the plot (select, deselect, menu)


class CurveViewBox(pg.ViewBox):
    """A ViewBox whose left-button gestures edit keys; the rest zooms and pans."""

    def __init__(self, view: PlotOwner) -> None:
        super().__init__(enableMenu=False)
        self._view = view

    def mouseClickEvent(self, ev: Any) -> None:
        if not self.sceneBoundingRect().contains(ev.scenePos()):
            # A click forwarded by an axis: on the time axis it sets the current frame.
            if ev.button() == Qt.MouseButton.LeftButton and ev.scenePos().y() > self.sceneBoundingRect().bottom():
                ev.accept()
                self._view.ctx.set_frame(float(round(self.mapSceneToView(ev.scenePos()).x())))
            return
        if ev.button() == Qt.MouseButton.LeftButton:
            ev.accept()
            self._view.click(ev.scenePos(), ev.modifiers())
        elif ev.button() == Qt.MouseButton.RightButton:
            ev.accept()
            self._view.select_under(ev.scenePos())  # the menu acts on what was clicked
            self._view.context_menu_requested.emit(ev.screenPos())
        else:
            super().mouseClickEvent(ev)

    def mouseDragEvent(self, ev: Any, axis: int | None = None) -> None:
        if axis is None and self._view.drag_event(ev):
            return
        if axis == 0 and ev.button() == Qt.MouseButton.LeftButton:
            # A left drag forwarded by the time axis scrubs (middle / right drags still pan / zoom it).
            ev.accept()
            self._view.scrub(ev.scenePos(), finish=ev.isFinish())
            return
        super().mouseDragEvent(ev, axis)

    def wheelEvent(self, ev: Any, axis: int | None = None) -> None:
        if axis is None:
            mods = ev.modifiers()
            if mods & Qt.KeyboardModifier.ControlModifier:
                axis = 0
            elif mods & Qt.KeyboardModifier.ShiftModifier:
                axis = 1
        super().wheelEvent(ev, axis)


class CurvePlot(pg.PlotWidget):
    """The plot widget (objectName ``curvePlot``); keys go to the curve view first."""

    def __init__(self, view: PlotOwner, parent: QWidget | None = None) -> None:
        self._view = view
        super().__init__(parent, background=BACKGROUND, viewBox=CurveViewBox(view))
        self.setObjectName("curvePlot")
        self.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        #: The buttons pressed on this widget (from its own press and release events).
        self._pressed = Qt.MouseButton.NoButton

    def mousePressEvent(self, ev: QMouseEvent) -> None:
        # pyqtgraph's drag events carry the modifiers of each move; Shift-to-add is decided
        # by the modifiers held when the button went down.
        self._view.press_modifiers = ev.modifiers()
        self._pressed = ev.buttons()
        super().mousePressEvent(ev)

    def mouseReleaseEvent(self, ev: QMouseEvent) -> None:
        self._pressed = ev.buttons() & self._pressed
        super().mouseReleaseEvent(ev)

    def mouseMoveEvent(self, ev: QMouseEvent) -> None:
        super().mouseMoveEvent(ev)
        # Hover while no button pressed *here* is down. A move's own buttons() can name a
        # button pressed on another widget whose release never came (QTest keeps that state
        # across tests: the hover test failed in full runs after such a test).
        if not (ev.buttons() & self._pressed):
            self._view.hover_at(self.mapToScene(ev.position().toPoint()))

    def leaveEvent(self, ev: QEvent) -> None:
        self._view.hover_at(None)
        super().leaveEvent(ev)

    def event(self, ev: QEvent) -> bool:
        # Keys the curve editor uses win over window shortcuts while the plot has focus.
        if ev.type() == QEvent.Type.ShortcutOverride and self._view.handles_key(ev):  # type: ignore[arg-type]
            ev.accept()
            return True
        return super().event(ev)

    def keyPressEvent(self, ev: QKeyEvent) -> None:
        if self._view.key_press(ev):
            ev.accept()
            return
        super().keyPressEvent(ev)
