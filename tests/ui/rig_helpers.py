"""Helpers shared by the UI tests that drive the 2D rig editor with real mouse events."""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QEvent, QPoint, QPointF, Qt
from PySide6.QtGui import QMouseEvent
from PySide6.QtWidgets import QApplication

from qtanimator.document import character2d as c2d
from qtanimator.ui.rig_interaction import pick


def send_mouse(view, kind: QEvent.Type, pos: QPoint, button: Qt.MouseButton,  # type: ignore[no-untyped-def]
               buttons: Qt.MouseButton) -> None:
    """Deliver one real mouse event to the viewport without processing other events."""
    vp = view.viewport()
    local = QPointF(pos)
    event = QMouseEvent(kind, local, vp.mapToGlobal(local), button, buttons, Qt.KeyboardModifier.NoModifier)
    QApplication.sendEvent(vp, event)


def hand_point(window, view) -> QPoint:  # type: ignore[no-untyped-def]
    """A pixel on Pip's right hand that picks the hand (a keyframed joint: exact at once)."""
    doc = window.doc
    ch = doc.runtime["pip"]
    j = ch.joint_index("hand_right")
    pose = c2d.evaluate_pose(doc, "pip", window.ctx.time, block=False)
    pts = ch.joints[j].shapes[0].points
    centre = pts.mean(axis=0)
    for local in [centre] + [centre + 0.5 * (p - centre) for p in pts]:
        xy = view.from_scene(pose.to_world(j, local))
        pixel = QPoint(int(round(xy.x())), int(round(xy.y())))
        if pick(doc, window.ctx.time, view.to_scene(QPointF(pixel))) == ("pip", j):
            return pixel
    raise AssertionError("the hand is covered everywhere")


#: The bundled demo project.
DEMO = Path(__file__).resolve().parents[2] / "scenes" / "demo" / "demo.qtanim"
#: The editors the demo tests of the 2D animator install.
DEMO_EDITORS = ("rig_editor", "timeline", "joint_tree", "properties")


def open_demo(make_window, qtbot, focus: bool = False):  # type: ignore[no-untyped-def]
    """A shown main window with the demo open in the 2D tab, the view fitted; with
    ``focus`` the rig editor has the keyboard focus. Returns ``(window, view)``."""
    window = make_window(editors=DEMO_EDITORS)
    assert window.open_path(DEMO)
    window.central_tabs.setCurrentWidget(window.rig_editor)
    view = window.rig_editor.view
    view.fit_view()
    if focus:
        view.setFocus()
        qtbot.waitUntil(view.hasFocus)
    else:
        qtbot.wait(10)
    return window, view
