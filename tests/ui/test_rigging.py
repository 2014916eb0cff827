"""Rigging a plain drawing in the program with real mouse events (issue 23, item 3).

The drawing's first element is a <path>, its first Inkscape layer is empty, then three
layers. In the real window: Rig Mode on, right-click ▸ Make Joint From twice, drag a pivot,
drag a joint onto another in the joint tree, toggle Mark Dynamic, then (rig mode off)
IK-drag the arm. Undo restores the unrigged project byte for byte; save and reopen give
the same rig.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PySide6.QtCore import QEvent, QPoint, QPointF, Qt
from PySide6.QtGui import QMouseEvent
from PySide6.QtWidgets import QApplication, QMenu
from rig_helpers import send_mouse
from samples import PLAIN_DRAWING

from qtanimator.document import character2d as c2d
from qtanimator.document import open_document, save_document
from qtanimator.ui.rig_editor import open_characters

DRAWING = PLAIN_DRAWING  # a <path> first, an empty first layer, then three layers

LEFT, RIGHT, NONE = Qt.MouseButton.LeftButton, Qt.MouseButton.RightButton, Qt.MouseButton.NoButton


def rig_of(doc, aid):  # type: ignore[no-untyped-def]
    ch = c2d.character(doc, aid)
    return [(j.name, None if j.parent is None else ch.joints[j.parent].name,
             tuple(np.round(j.pivot, 6)), j.is_dynamic) for j in ch.joints]


def pixel(view, xy) -> QPoint:  # type: ignore[no-untyped-def]
    p = view.from_scene(xy)
    return QPoint(int(round(p.x())), int(round(p.y())))


def click_menu(qtbot, menu: QMenu, text: str) -> None:  # type: ignore[no-untyped-def]
    action = next(a for a in menu.actions() if a.text() == text)
    pos = menu.actionGeometry(action).center()
    for kind, button, buttons in ((QEvent.Type.MouseMove, NONE, NONE), (QEvent.Type.MouseButtonPress, LEFT, LEFT),
                                  (QEvent.Type.MouseButtonRelease, LEFT, NONE)):
        QApplication.sendEvent(menu, QMouseEvent(kind, QPointF(pos), menu.mapToGlobal(QPointF(pos)), button,
                                                 buttons, Qt.KeyboardModifier.NoModifier))


def make_joint(qtbot, view, at, label: str) -> None:  # type: ignore[no-untyped-def]
    """Right-click at scene point ``at`` and choose Make Joint From ▸ ``label``."""
    p = pixel(view, at)
    send_mouse(view, QEvent.Type.MouseButtonPress, p, RIGHT, RIGHT)
    send_mouse(view, QEvent.Type.MouseButtonRelease, p, RIGHT, NONE)
    menu = view.rig_menu
    qtbot.waitUntil(menu.isVisible)
    click_menu(qtbot, menu, "Make Joint From")
    sub = menu.findChild(QMenu, "rigMakeJointMenu")
    qtbot.waitUntil(sub.isVisible)
    click_menu(qtbot, sub, label)
    qtbot.waitUntil(lambda: not menu.isVisible())


def toggle_dynamic(qtbot, view, at) -> None:  # type: ignore[no-untyped-def]
    p = pixel(view, at)
    send_mouse(view, QEvent.Type.MouseButtonPress, p, RIGHT, RIGHT)
    send_mouse(view, QEvent.Type.MouseButtonRelease, p, RIGHT, NONE)
    qtbot.waitUntil(view.rig_menu.isVisible)
    click_menu(qtbot, view.rig_menu, "Mark Dynamic")


def drag(widget, points, button=LEFT) -> None:  # type: ignore[no-untyped-def]
    send_mouse(widget, QEvent.Type.MouseButtonPress, points[0], button, button)
    for p in points[1:]:
        send_mouse(widget, QEvent.Type.MouseMove, p, NONE, button)
    send_mouse(widget, QEvent.Type.MouseButtonRelease, points[-1], button, NONE)


@pytest.fixture
def rigging(make_window, tmp_path):  # type: ignore[no-untyped-def]
    svg = tmp_path / "plain.svg"
    svg.write_text(DRAWING)
    window = make_window()
    open_characters(window, svg)
    view = window.rig_editor.view
    view.resize(800, 700)
    view.fit_view()
    aid = next(iter(window.doc.assets))
    return window, view, aid


def test_rig_a_plain_drawing_with_the_mouse_undo_save_reopen(rigging, qtbot, tmp_path: Path) -> None:
    window, view, aid = rigging
    doc, stack = window.doc, window.ctx.undo_stack
    save_document(doc, tmp_path / "unrigged.qtanim")
    steps = stack.count()
    assert rig_of(doc, aid) == [("drawing", None, (80.0, 70.0), False)]
    editor = window.rig_editor
    qtbot.mouseClick(editor.toolbar.widgetForAction(editor.rig_mode_action), LEFT)
    assert view.rig_mode

    make_joint(qtbot, view, (70.0, 100.0), "Body")   # on the body: the root's part now
    make_joint(qtbot, view, (140.0, 65.0), "Arm")    # on the arm, still the root's
    assert rig_of(doc, aid) == [("drawing", None, (80.0, 70.0), False), ("Body", "drawing", (70.0, 90.0), False),
                                ("Arm", "drawing", (120.0, 65.0), False)]

    # Drag the arm's pivot marker (at the centre of its box) to its shoulder.
    press, release = pixel(view, (120.0, 65.0)), pixel(view, (91.0, 65.0))
    drag(view, [press, (press + release) / 2, release])
    moved = np.array([120.0, 65.0]) + view.to_scene(QPointF(release)) - view.to_scene(QPointF(press))
    ch = c2d.character(doc, aid)
    np.testing.assert_allclose(ch.joints[ch.joint_index("Arm")].pivot, moved)
    assert stack.undoText() == "Move Pivot of Arm"

    # Escape during a pivot drag takes it back and records nothing.
    before, count = doc.state(), stack.count()
    send_mouse(view, QEvent.Type.MouseButtonPress, pixel(view, moved), LEFT, LEFT)
    send_mouse(view, QEvent.Type.MouseMove, pixel(view, moved) + QPoint(30, 30), NONE, LEFT)
    assert doc.state() != before
    view.setFocus()
    qtbot.keyClick(view, Qt.Key.Key_Escape)
    send_mouse(view, QEvent.Type.MouseButtonRelease, pixel(view, moved) + QPoint(30, 30), LEFT, NONE)
    assert doc.state() == before and stack.count() == count

    # Re-parent in the joint tree: drag Arm onto Body.
    tree = window.joint_tree.tree
    arm_item, body_item = tree.item_for(aid, "Arm"), tree.item_for(aid, "Body")
    a, b = tree.visualItemRect(arm_item).center(), tree.visualItemRect(body_item).center()
    drag(tree, [a, a + QPoint(0, -6), b])
    assert [r[:2] for r in rig_of(doc, aid)] == [("drawing", None), ("Body", "drawing"), ("Arm", "Body")]
    assert stack.undoText() == "Re-parent Arm to Body"
    # Dropping Body onto its own child is refused with a message, and changes nothing.
    before = doc.state()
    body_item, arm_item = tree.item_for(aid, "Body"), tree.item_for(aid, "Arm")
    a, b = tree.visualItemRect(body_item).center(), tree.visualItemRect(arm_item).center()
    drag(tree, [a, a + QPoint(0, 6), b])
    assert doc.state() == before and "hang from itself" in tree.last_message

    # Mark the arm dynamic, then keyframed again: each one step.
    toggle_dynamic(qtbot, view, (140.0, 65.0))
    assert c2d.character(doc, aid).joints[2].is_dynamic and stack.undoText() == "Mark Arm Dynamic"
    toggle_dynamic(qtbot, view, (140.0, 65.0))
    assert not c2d.character(doc, aid).joints[2].is_dynamic
    rigged = rig_of(doc, aid)

    # Out of rig mode, right-drag the arm's tip: IK pulls it towards the cursor.
    qtbot.mouseClick(editor.toolbar.widgetForAction(editor.rig_mode_action), LEFT)
    assert not view.rig_mode
    tip = np.array([146.0, 65.0])
    target = np.array([100.0, 25.0])   # up and left: reachable by turning Body and Arm
    ik_steps = stack.count()
    drag(view, [pixel(view, tip), pixel(view, (tip + target) / 2), pixel(view, target)], RIGHT)
    assert stack.count() == ik_steps + 1 and stack.undoText() == "IK Drag"
    pose = c2d.evaluate_pose(doc, aid, window.ctx.time)
    source = view.to_scene(QPointF(pixel(view, tip)))
    reached = pose.to_world(2, source)
    aimed = view.to_scene(QPointF(pixel(view, target)))
    assert np.linalg.norm(reached - aimed) < 0.25 * np.linalg.norm(source - aimed)
    # The arm still hangs from the body: its pivot turned about Body's pivot.
    body_pivot, arm_pivot = np.array([70.0, 90.0]), np.array(rigged[2][2])
    assert np.linalg.norm(pose.pivots[2] - body_pivot) == pytest.approx(np.linalg.norm(arm_pivot - body_pivot))

    # Save, reopen: the same rig.
    save_document(doc, tmp_path / "rigged.qtanim")
    again = open_document(tmp_path / "rigged.qtanim")
    assert rig_of(again, aid) == rigged

    # Undo everything back to the opened drawing: the unrigged project, byte for byte.
    while stack.count() > steps and stack.index() > steps:
        stack.undo()
    save_document(doc, tmp_path / "undone.qtanim")
    assert (tmp_path / "undone.qtanim").read_bytes() == (tmp_path / "unrigged.qtanim").read_bytes()
    assert rig_of(doc, aid) == [("drawing", None, (80.0, 70.0), False)]
