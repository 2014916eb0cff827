"""Mouse helpers shared by the curve editor's widget tests (real events on the plot)."""

from __future__ import annotations

from PySide6.QtCore import QEvent, QPoint, QPointF, Qt
from PySide6.QtGui import QMouseEvent
from PySide6.QtWidgets import QApplication

from qtanimator.ui.curve_editor import CurveEditor


def viewport_pos(ed: CurveEditor, scene: QPointF) -> QPoint:
    return ed.plot.mapFromScene(scene)


def key_pos(ed: CurveEditor, cid: str, i: int) -> QPoint:
    return viewport_pos(ed, ed.view.handle_positions(cid, i)[0])


def view_pos(ed: CurveEditor, frame: float, shown: float) -> QPoint:
    """Where (frame, value as shown: degrees for rotations) is on the viewport."""
    return viewport_pos(ed, ed.view.vb.mapViewToScene(QPointF(frame, shown)))


def hover(ed: CurveEditor, pos: QPoint) -> None:
    """Move the mouse over the plot with no button down, synchronously.

    ``qtbot.mouseMove`` with no button pressed moves the real pointer (``QCursor::setPos``,
    kept by QTest for compatibility) and, under Xvfb, the window system's move event can
    arrive after the next assertion: the hover test failed that way in busy full runs.
    Events already queued are handled first, so no late one lands after this move.
    """
    QApplication.processEvents()
    vp = ed.plot.viewport()
    ev = QMouseEvent(QEvent.Type.MouseMove, QPointF(pos), QPointF(vp.mapToGlobal(pos)), Qt.MouseButton.NoButton,
                     Qt.MouseButton.NoButton, Qt.KeyboardModifier.NoModifier)
    QApplication.sendEvent(vp, ev)


def drag(qtbot, ed: CurveEditor, start: QPoint, end: QPoint, steps: int = 6,  # type: ignore[no-untyped-def]
         mods=Qt.KeyboardModifier.NoModifier, release: bool = True) -> None:
    vp = ed.plot.viewport()
    qtbot.mousePress(vp, Qt.MouseButton.LeftButton, mods, start)
    for k in range(1, steps + 1):
        p = start + (end - start) * (k / steps)
        qtbot.wait(12)  # pyqtgraph drops moves closer than 10 ms apart (mouseRateLimit)
        qtbot.mouseMove(vp, p)
    qtbot.wait(12)
    if release:
        qtbot.mouseRelease(vp, Qt.MouseButton.LeftButton, mods, end)
