"""One change per command, one refresh per frame during a gesture, and the gesture protocol
end to end in the real main window (the demo project, real mouse events)."""

from __future__ import annotations

import math

import pytest
from PySide6.QtCore import QEvent, QPoint, Qt
from rig_helpers import hand_point, open_demo, send_mouse

from qtanimator.core.channel import Key
from qtanimator.document import character2d as c2d
from qtanimator.document.commands import SetKeys
from qtanimator.document.document import DocumentChange
from qtanimator.document.io import save_document


@pytest.fixture
def demo(make_window, qtbot):
    window, view = open_demo(make_window, qtbot)
    seen: list[DocumentChange] = []
    window.ctx.documentChanged.connect(seen.append)
    return window, view, seen


def test_a_command_on_many_channels_is_one_notification(demo):
    window, _view, seen = demo
    doc = window.doc
    ch = doc.runtime["pip"]
    keys = {c2d.angle_channel_id("pip", j.name): Key(1.0, 0.1 * i)
            for i, j in enumerate(ch.joints) if not j.is_dynamic}
    assert len(keys) >= 8
    window.ctx.push(SetKeys(doc, keys))
    assert len(seen) == 1
    assert set(seen[0].channels) == set(keys)
    window.ctx.undo_stack.undo()
    window.ctx.undo_stack.redo()
    assert len(seen) == 3 and all(set(c.channels) == set(keys) for c in seen)


def test_a_drag_notifies_once_per_frame_with_everything_it_changed(demo, qtbot):
    window, view, seen = demo
    doc = window.doc
    window.ctx.set_frame(30.0)
    before = doc.state()
    start = hand_point(window, view)
    right = Qt.MouseButton.RightButton
    send_mouse(view, QEvent.Type.MouseButtonPress, start, right, right)
    for i in range(1, 11):  # ten moves delivered back to back, within one frame
        send_mouse(view, QEvent.Type.MouseMove, start + QPoint(-4 * i, 3 * i), Qt.MouseButton.NoButton, right)
    assert doc.state() != before  # the drag previews at once in the document and the editor
    assert seen == []  # ... while the other views wait for the frame clock
    qtbot.waitUntil(lambda: len(seen) == 1)
    moved = {cid for cid in seen[0].channels}
    assert moved and all(cid.startswith("pip/") for cid in moved)
    # Every channel the drag keyed is named, from the previous key of the edited span.
    changed = {cid for cid, ch in doc.channels.items() if ch.to_dict() != before["channels"].get(cid)}
    assert changed == moved
    send_mouse(view, QEvent.Type.MouseButtonRelease, start + QPoint(-40, 30), right, Qt.MouseButton.NoButton)
    assert window.ctx.undo_stack.count() == 1 and window.ctx.undo_stack.undoText() == "IK Drag"
    window.ctx.undo_stack.undo()
    assert doc.state() == before


def test_escape_aborts_an_ik_drag_exactly_and_records_nothing(demo, qtbot):
    window, view, seen = demo
    doc = window.doc
    window.ctx.set_frame(12.0)
    before = doc.state()
    start = hand_point(window, view)
    view.setFocus()
    right = Qt.MouseButton.RightButton
    send_mouse(view, QEvent.Type.MouseButtonPress, start, right, right)
    send_mouse(view, QEvent.Type.MouseMove, start + QPoint(-30, 25), Qt.MouseButton.NoButton, right)
    assert doc.state() != before
    qtbot.keyClick(view, Qt.Key.Key_Escape)
    assert doc.state() == before
    assert window.ctx.undo_stack.count() == 0
    assert not window.ctx.gesture_active
    send_mouse(view, QEvent.Type.MouseButtonRelease, start, right, Qt.MouseButton.NoButton)
    assert doc.state() == before and window.ctx.undo_stack.count() == 0


def test_undoing_every_drag_restores_the_saved_bytes(demo, qtbot, tmp_path):
    window, view, _seen = demo
    doc = window.doc
    save_document(doc, tmp_path / "before.qtanim")
    right, left = Qt.MouseButton.RightButton, Qt.MouseButton.LeftButton
    for frame, button, offset in ((5.0, right, QPoint(-25, 20)), (60.0, left, QPoint(15, -10)),
                                  (200.0, right, QPoint(20, 30))):
        window.ctx.set_frame(frame)
        start = hand_point(window, view)
        send_mouse(view, QEvent.Type.MouseButtonPress, start, button, button)
        for f in (0.5, 1.0):
            p = start + QPoint(int(offset.x() * f), int(offset.y() * f))
            send_mouse(view, QEvent.Type.MouseMove, p, Qt.MouseButton.NoButton, button)
        send_mouse(view, QEvent.Type.MouseButtonRelease, start + offset, button, Qt.MouseButton.NoButton)
    assert window.ctx.undo_stack.count() == 3
    while window.ctx.undo_stack.canUndo():
        window.ctx.undo_stack.undo()
    save_document(doc, tmp_path / "after.qtanim")
    assert (tmp_path / "after.qtanim").read_bytes() == (tmp_path / "before.qtanim").read_bytes()


def test_a_dof_slider_drag_is_one_gesture_and_escape_puts_it_back(demo, qtbot):
    window, _view, seen = demo
    doc = window.doc
    window.ctx.select("pip", "head")
    panel = window.joint_tree.dofs
    row = panel.rows[0]
    before = doc.state()
    angle0 = float(c2d.joint_angles(doc, "pip", window.ctx.time)[doc.runtime["pip"].joint_index("head")])
    row.slider.sliderPressed.emit()
    for v in (5, 10, 20):
        row.slider.setValue(row.slider.value() + v)
    head = doc.runtime["pip"].joint_index("head")
    moved = float(c2d.joint_angles(doc, "pip", window.ctx.time)[head])
    assert moved != pytest.approx(angle0)
    qtbot.keyClick(panel, Qt.Key.Key_Escape)
    assert doc.state() == before and window.ctx.undo_stack.count() == 0
    row.slider.sliderReleased.emit()
    # A second drag, released: one undo step that keys the value the slider shows.
    row = panel.rows[0]
    row.slider.sliderPressed.emit()
    row.slider.setValue(row.slider.value() + 300)
    row.slider.setValue(row.slider.value() + 200)
    shown = row.slider.value() / 10.0
    row.slider.sliderReleased.emit()
    assert window.ctx.undo_stack.count() == 1
    assert math.degrees(float(c2d.joint_angles(doc, "pip", window.ctx.time)[head])) == pytest.approx(shown)
    window.ctx.undo_stack.undo()
    assert doc.state() == before


def test_a_change_that_removes_the_selected_asset_or_joint_clears_that_selection(qtbot, tmp_path):
    """Views hear of a change only after the selection stopped naming what the change
    removed (an undone "Make Joint", a removed character)."""
    from qtanimator.document.commands import RemoveAsset
    from qtanimator.document.io import open_document
    from qtanimator.paths import scenes_dir
    from qtanimator.ui.context import EditorContext

    ctx = EditorContext(open_document(scenes_dir() / "demo" / "demo.qtanim"))
    seen: list[tuple[str, str]] = []
    ctx.documentChanged.connect(lambda _c: seen.append(ctx.selection))
    ctx.select("pip", "no_such_joint")
    ctx.push(RemoveAsset(ctx.doc, "pendulum_clock"))        # another asset changed: the stale joint goes
    assert ctx.selection == ("pip", "") and seen[-1] == ("pip", "")
    ctx.select("pip", "hand_right")
    ctx.push(RemoveAsset(ctx.doc, "robot"))
    assert ctx.selection == ("pip", "hand_right")   # still there: kept
    ctx.push(RemoveAsset(ctx.doc, "pip"))
    assert ctx.selection == ("", "") and seen[-1] == ("", "")


def test_a_stale_3d_joint_selection_is_dropped_too():
    """3D characters name their joints by key (``Character3D.joint_keys``, a list)."""
    from qtanimator.document.commands import RemoveAsset
    from qtanimator.document.io import open_document
    from qtanimator.paths import scenes_dir
    from qtanimator.ui.context import EditorContext

    ctx = EditorContext(open_document(scenes_dir() / "demo" / "demo.qtanim"))
    real = ctx.doc.runtime["arm"].joint_keys[-1]
    ctx.select("arm", real)
    ctx.push(RemoveAsset(ctx.doc, "pendulum_clock"))
    assert ctx.selection == ("arm", real)
    ctx.select("arm", "no_such_joint")
    ctx.push(RemoveAsset(ctx.doc, "robot"))
    assert ctx.selection == ("arm", "")
