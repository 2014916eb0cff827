"""The joint tree dock and its DOF panel, with real clicks and slider drags."""

from __future__ import annotations

import math

import pytest
from PySide6.QtCore import QPoint, Qt
from PySide6.QtWidgets import QDockWidget, QDoubleSpinBox, QSlider, QStyle, QStyleOptionSlider, QWidget

from qtanimator.document import character2d as c2d


@pytest.fixture
def clock(make_window, qtbot, shared_data):
    window = make_window()
    assert window.open_path(shared_data / "cmu-animator" / "scenes" / "clock.svg")
    window.ctx.undo_stack.clear()
    return window, window.joint_tree


def handle_center(slider: QSlider) -> QPoint:
    opt = QStyleOptionSlider()
    slider.initStyleOption(opt)
    rect = slider.style().subControlRect(QStyle.ComplexControl.CC_Slider, opt,
                                         QStyle.SubControl.SC_SliderHandle, slider)
    return rect.center()


def test_tree_lists_joints_with_icons_and_follows_selection(qtbot, clock):
    window, panel = clock
    assert window.findChild(QDockWidget, "jointTreeDock") is not None
    tree = panel.tree
    top = tree.topLevelItem(0)
    assert top.text(0) == "clock"
    character = window.doc.runtime["clock"]
    items = {character.joints[i].name: tree.item_for("clock", character.joints[i].name)
             for i in range(len(character.joints))}
    assert all(items.values())
    # Dynamic joints of the clock are 1, 2 and 5.
    dynamic = sorted(i for i, j in enumerate(character.joints) if "dynamic" in items[j.name].toolTip(0))
    assert dynamic == [1, 2, 5]
    # Selecting in the tree selects in the editor...
    name = character.joints[4].name
    rect = tree.visualItemRect(items[name])
    qtbot.mouseClick(tree.viewport(), Qt.MouseButton.LeftButton, pos=rect.center())
    assert window.ctx.selection == ("clock", name)
    # ... and the tree follows the editor's selection.
    window.ctx.select("clock", character.joints[6].name)
    assert tree.currentItem() is items[character.joints[6].name]
    # Next / previous joint.
    qtbot.mouseClick(panel.dofs.next_button, Qt.MouseButton.LeftButton)
    assert window.ctx.selection == ("clock", character.joints[7].name)
    qtbot.mouseClick(panel.dofs.prev_button, Qt.MouseButton.LeftButton)
    qtbot.mouseClick(panel.dofs.prev_button, Qt.MouseButton.LeftButton)
    assert window.ctx.selection == ("clock", character.joints[5].name)


def test_dof_slider_drag_keys_the_angle_in_one_undo_step(qtbot, clock):
    window, panel = clock
    doc = window.doc
    character = doc.runtime["clock"]
    joint = 4
    window.ctx.select("clock", character.joints[joint].name)
    slider = panel.dofs.rows[0].slider
    spin = panel.dofs.rows[0].spin
    assert slider.minimum() == -3600 and slider.maximum() == 3600
    qtbot.waitUntil(lambda: slider.isVisible())
    start = handle_center(slider)
    before = doc.state()
    qtbot.mousePress(slider, Qt.MouseButton.LeftButton, pos=start)
    for dx in (5, 10, 20):
        qtbot.mouseMove(slider, start + QPoint(dx, 0))
    qtbot.mouseRelease(slider, Qt.MouseButton.LeftButton, pos=start + QPoint(20, 0))
    assert slider.value() > 0
    angle = c2d.joint_angles(doc, "clock", 0.0)[joint]
    assert math.degrees(angle) == pytest.approx(slider.value() / 10.0)
    assert spin.value() == pytest.approx(slider.value() / 10.0)
    assert window.ctx.undo_stack.count() == 1
    window.ctx.undo_stack.undo()
    assert doc.state() == before
    assert slider.value() == 0


def test_dof_spin_box_and_scrubbing_show_the_current_value(qtbot, clock):
    window, panel = clock
    doc = window.doc
    character = doc.runtime["clock"]
    window.ctx.select("clock", character.joints[4].name)
    spin = panel.dofs.findChild(QDoubleSpinBox, "dofSpin_angle")
    spin.setFocus()
    spin.lineEdit().selectAll()
    qtbot.keyClicks(spin.lineEdit(), "30")
    qtbot.keyClick(spin.lineEdit(), Qt.Key.Key_Return)
    assert math.degrees(c2d.joint_angles(doc, "clock", 0.0)[4]) == pytest.approx(30.0)
    window.ctx.set_frame(60)
    spin.lineEdit().selectAll()
    qtbot.keyClicks(spin.lineEdit(), "-10")
    qtbot.keyClick(spin.lineEdit(), Qt.Key.Key_Return)
    window.ctx.set_frame(0)
    assert spin.value() == pytest.approx(30.0)
    window.ctx.set_frame(60)
    assert spin.value() == pytest.approx(-10.0)


def test_character_row_moves_and_reset_pose(qtbot, clock):
    window, panel = clock
    doc = window.doc
    window.ctx.select("clock", "")
    labels = [r.spec.label for r in panel.dofs.rows]
    assert labels == ["x", "y"]
    panel.dofs.rows[0].spin.setValue(25.0)
    assert c2d.translation(doc, "clock", 0.0)[0] == pytest.approx(25.0)
    window.ctx.select("clock", doc.runtime["clock"].joints[4].name)
    panel.dofs.rows[0].spin.setValue(45.0)
    panel.tree.setFocus()
    qtbot.keyClick(panel.tree, Qt.Key.Key_R)
    assert c2d.joint_angles(doc, "clock", 0.0)[4] == pytest.approx(0.0)
    window.ctx.undo_stack.undo()
    assert math.degrees(c2d.joint_angles(doc, "clock", 0.0)[4]) == pytest.approx(45.0)


def test_3d_skeleton_joints_and_dof_limits(make_window, qtbot, shared_data):
    skel = shared_data / "cse169" / "skeleton" / "wasp.skel"
    from qtanimator.document import character3d as c3d

    window = make_window()
    window.ctx.push(c3d.add_character3d_command(window.doc, skel))
    aid = next(a for a, v in window.doc.assets.items() if v.kind == c3d.ASSET_KIND)
    panel = window.joint_tree
    skeleton = window.doc.runtime[aid].skeleton
    assert panel.tree.item_for(aid, skeleton.joints[1].name) is not None
    window.ctx.select(aid, skeleton.joints[1].name)
    rows = panel.dofs.rows
    assert rows
    row = rows[0]
    dof = skeleton.joints[1].dofs["xyz".index(row.spec.label[-1])]
    assert row.spin.minimum() == pytest.approx(math.degrees(max(dof.min, -math.pi)), abs=0.01)
    row.spin.setValue(row.spin.maximum())
    posed = c3d.pose_skeleton(window.doc, aid, 0.0)
    assert posed.joints[1].dofs["xyz".index(row.spec.label[-1])].value == pytest.approx(
        math.radians(row.spin.maximum()), abs=1e-6)
    # The skeleton's own row moves its root.
    window.ctx.select(aid, "")
    assert [r.spec.label for r in panel.dofs.rows] == ["translate x", "translate y", "translate z"]
    panel.dofs.rows[1].spin.setValue(0.5)
    assert c3d.pose_skeleton(window.doc, aid, 0.0).root_translation[1] == pytest.approx(0.5)



def test_arrow_keys_move_between_tree_rows_not_frames(make_window, qtbot):
    """Up / Down on the tree move the current row; the timeline keys stay in the rig editor,
    the 3D viewport and the curve plot."""
    from qtanimator.paths import scenes_dir

    window = make_window(full=True, size=(1400, 900))
    assert window.open_path(scenes_dir() / "pendulum_clock.svg")
    tree = window.joint_tree.tree
    window.ctx.set_frame(30)
    top = tree.topLevelItem(0)
    first = top.child(0)
    qtbot.mouseClick(tree.viewport(), Qt.MouseButton.LeftButton, pos=tree.visualItemRect(first).center())
    assert tree.hasFocus() and window.ctx.selection == first.data(0, Qt.ItemDataRole.UserRole)
    qtbot.keyClick(tree, Qt.Key.Key_Down)
    assert window.ctx.frame == 30  # not "go to the last frame"
    below = tree.itemBelow(first)
    assert tree.currentItem() is below
    assert window.ctx.selection == below.data(0, Qt.ItemDataRole.UserRole)
    qtbot.keyClick(tree, Qt.Key.Key_Up)
    assert window.ctx.frame == 30 and tree.currentItem() is first
    qtbot.keyClick(tree, Qt.Key.Key_Up)
    assert tree.currentItem() is top and window.ctx.selection == (top.text(0), "")
    # Left closes the branch instead of stepping a frame; Right opens it again.
    qtbot.keyClick(tree, Qt.Key.Key_Left)
    assert not top.isExpanded() and window.ctx.frame == 30
    qtbot.keyClick(tree, Qt.Key.Key_Right)
    assert top.isExpanded() and window.ctx.frame == 30
    # The timeline keys work in the rig editor and in the curve plot.
    for name in ("rigEditorView", "curvePlot"):
        view = window.findChild(QWidget, name)
        window.ctx.set_frame(30)
        view.setFocus()
        qtbot.waitUntil(view.hasFocus)
        qtbot.keyClick(view, Qt.Key.Key_Right)
        assert window.ctx.frame == 31, name
        qtbot.keyClick(view, Qt.Key.Key_Down)
        assert window.ctx.frame == window.doc.frame_range[1], name


def test_with_auto_key_off_a_dof_slider_drag_poses_without_keying(qtbot, clock):
    """Auto-key off: the slider shows the pose it was dragged to (the joint's evaluated
    angle follows) but writes no key and leaves no undo step; another frame discards it."""
    from qtanimator.document import pose

    window, panel = clock
    doc = window.doc
    character = doc.runtime["clock"]
    joint = 4
    pose.set_autokey(doc, False)
    window.ctx.select("clock", character.joints[joint].name)
    slider = panel.dofs.rows[0].slider
    qtbot.waitUntil(lambda: slider.isVisible())
    start = handle_center(slider)
    channels = {cid: ch.to_dict() for cid, ch in doc.channels.items()}
    undo_count = window.ctx.undo_stack.count()
    qtbot.mousePress(slider, Qt.MouseButton.LeftButton, pos=start)
    for dx in (5, 10, 20):
        qtbot.mouseMove(slider, start + QPoint(dx, 0))
    qtbot.mouseRelease(slider, Qt.MouseButton.LeftButton, pos=start + QPoint(20, 0))
    assert slider.value() > 0
    assert {cid: ch.to_dict() for cid, ch in doc.channels.items()} == channels   # no key
    assert window.ctx.undo_stack.count() == undo_count
    shown = c2d.joint_angles(doc, "clock", window.ctx.time)[joint]
    assert math.degrees(shown) == pytest.approx(slider.value() / 10.0)
    window.ctx.set_frame(5.0)
    window.ctx.set_frame(0.0)
    assert c2d.joint_angles(doc, "clock", 0.0)[joint] == pytest.approx(0.0)
