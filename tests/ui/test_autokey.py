"""Auto-key and set key, driven by real mouse and key events in the main window (the demo
project): auto-key off poses without keys until the frame changes, S / I key the selected
joint, Shift+S the whole character, in the 2D editor and the 3D view; key-all keys the
same channels whatever the IK settings."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import QEvent, QPoint, Qt
from PySide6.QtGui import QAction
from PySide6.QtWidgets import QToolButton, QWidget
from rig_helpers import DEMO, hand_point, open_demo, send_mouse

from qtanimator.document import character2d as c2d
from qtanimator.document import pose
from qtanimator.document.commands import SetParameter

FRAME = 37.0  # no channel of the demo has a key here

#: Every keyframed joint of Pip and its position (what Shift+S keys).
PIP_ALL = {
    "pip/torso/angle", "pip/head/angle", "pip/leg_left/angle", "pip/leg_right/angle",
    "pip/upper_arm_left/angle", "pip/forearm_left/angle", "pip/hand_left/angle",
    "pip/upper_arm_right/angle", "pip/forearm_right/angle", "pip/hand_right/angle",
    "pip//x", "pip//y",
}


@pytest.fixture
def demo(make_window, qtbot):
    window, view = open_demo(make_window, qtbot, focus=True)
    window.ctx.set_frame(FRAME)
    return window, view


def channels(doc) -> dict:
    return {cid: ch.to_dict() for cid, ch in doc.channels.items()}


def changed(before: dict, doc) -> set[str]:
    now = channels(doc)
    return {cid for cid in set(now) | set(before) if now.get(cid) != before.get(cid)}


def picture(view) -> np.ndarray:
    """The editor's pixels without the bottom strip (where the unkeyed-pose note goes)."""
    image = view.grab().toImage()
    w, h = image.width(), image.height()
    ptr = image.constBits()
    arr = np.frombuffer(ptr, dtype=np.uint8, count=image.sizeInBytes()).reshape(h, image.bytesPerLine())
    return arr[: h - 40, : 4 * w].copy()


def drag(view, button, start: QPoint, offset: QPoint, steps: int = 4) -> None:
    send_mouse(view, QEvent.Type.MouseButtonPress, start, button, button)
    for i in range(1, steps + 1):
        p = start + QPoint(offset.x() * i // steps, offset.y() * i // steps)
        send_mouse(view, QEvent.Type.MouseMove, p, Qt.MouseButton.NoButton, button)
    send_mouse(view, QEvent.Type.MouseButtonRelease, start + offset, button, Qt.MouseButton.NoButton)


def autokey_off(window, qtbot) -> None:
    button = window.findChild(QToolButton, "autoKeyButton")
    assert button.isChecked()
    qtbot.mouseClick(button, Qt.MouseButton.LeftButton)
    assert not button.isChecked() and not pose.autokey(window.doc)
    window.rig_editor.view.setFocus()
    qtbot.waitUntil(window.rig_editor.view.hasFocus)


def test_the_auto_key_button_is_a_red_record_toggle_kept_per_project(demo, qtbot, tmp_path):
    window, view = demo
    action = window.findChild(QAction, "actionAutoKey")
    button = window.findChild(QToolButton, "autoKeyButton")
    assert action.isCheckable() and action.isChecked() and button.defaultAction() is action
    assert "checked" in button.styleSheet() and "rgb(200, 30, 30)" in button.styleSheet()
    steps = window.ctx.undo_stack.count()
    qtbot.mouseClick(button, Qt.MouseButton.LeftButton)
    assert not action.isChecked() and window.doc.view_state[pose.AUTOKEY_VIEW_STATE] is False
    assert window.ctx.undo_stack.count() == steps  # view state, not an edit
    # A checked button is drawn red: its pixels at the centre are red.
    qtbot.mouseClick(button, Qt.MouseButton.LeftButton)
    image = button.grab().toImage()
    reds = [image.pixelColor(x, image.height() // 2) for x in range(2, image.width() - 2)]
    assert any(c.red() > 150 and c.green() < 80 and c.blue() < 80 for c in reds)
    # Saved with the project, brought back by opening it.
    qtbot.mouseClick(button, Qt.MouseButton.LeftButton)
    path = tmp_path / "off.qtanim"
    assert window.save_to(path)
    assert window.open_path(DEMO)
    assert action.isChecked()
    assert window.open_path(path)
    assert not action.isChecked() and not pose.autokey(window.doc)


def test_auto_key_off_a_drag_poses_without_keys_until_the_frame_changes(demo, qtbot):
    window, view = demo
    doc, ctx = window.doc, window.ctx
    autokey_off(window, qtbot)
    before = channels(doc)
    pose0 = c2d.evaluate_pose(doc, "pip", ctx.time).world.copy()
    ctx.select("pip", "hand_right")  # what the drag selects: the same highlight in both pictures
    qtbot.waitUntil(lambda: c2d.simulation_ready(doc, ctx.time))  # the pendulums at rest in both
    view.viewport().repaint()
    image0 = picture(view)

    drag(view, Qt.MouseButton.RightButton, hand_point(window, view), QPoint(-40, 30))
    assert changed(before, doc) == set()  # no channel changed
    assert ctx.undo_stack.count() == 0  # and nothing to undo
    shown = view.poses()["pip"].world
    assert not np.allclose(shown, pose0)  # the editor shows the new pose
    np.testing.assert_array_equal(shown, c2d.evaluate_pose(doc, "pip", ctx.time).world)
    view.viewport().repaint()
    assert not np.array_equal(picture(view), image0)
    assert pose.has_pending(doc, ctx.time)

    # Another frame discards it; coming back shows the keyed pose again.
    ctx.set_frame(FRAME + 1)
    ctx.set_frame(FRAME)
    np.testing.assert_array_equal(view.poses()["pip"].world, pose0)
    view.viewport().repaint()
    np.testing.assert_array_equal(picture(view), image0)
    assert changed(before, doc) == set()


def test_s_keys_exactly_the_selected_joint_and_shift_s_every_joint(demo, qtbot):
    window, view = demo
    doc, ctx = window.doc, window.ctx
    autokey_off(window, qtbot)
    ch = doc.runtime["pip"]
    before = channels(doc)
    state0 = doc.state()
    # Rotate the left forearm with the left button: a pose, not a key.
    j = ch.joint_index("forearm_left")
    pose0 = c2d.evaluate_pose(doc, "pip", ctx.time)
    local = ch.joints[j].shapes[0].points.mean(axis=0)
    start = view.from_scene(pose0.to_world(j, local))
    start = QPoint(int(round(start.x())), int(round(start.y())))
    from qtanimator.ui.rig_interaction import pick

    assert pick(doc, ctx.time, view.to_scene(start)) == ("pip", j)
    drag(view, Qt.MouseButton.LeftButton, start, QPoint(0, 35))
    assert ctx.selection == ("pip", "forearm_left")
    shown = float(c2d.joint_angles(doc, "pip", ctx.time)[j])
    assert shown != pytest.approx(float(pose0.angles[j]))
    # And the right arm with IK.
    drag(view, Qt.MouseButton.RightButton, hand_point(window, view), QPoint(-30, 25))
    right_arm = c2d.joint_angles(doc, "pip", ctx.time).copy()
    assert changed(before, doc) == set() and ctx.undo_stack.count() == 0

    ctx.select("pip", "forearm_left")
    qtbot.keyClick(view, Qt.Key.Key_S)
    assert changed(before, doc) == {"pip/forearm_left/angle"}
    key = [k for k in doc.channels["pip/forearm_left/angle"].keys if abs(k.time - ctx.time) < 1e-9]
    assert len(key) == 1 and key[0].value == pytest.approx(shown, abs=1e-12)
    assert ctx.undo_stack.count() == 1
    # The IK pose of the right arm is still shown, unkeyed.
    np.testing.assert_allclose(c2d.joint_angles(doc, "pip", ctx.time)[~ch.dynamic], right_arm[~ch.dynamic],
                               atol=1e-12)

    # I does the same; Shift+S keys every joint of the character with what is shown.
    ctx.select("pip", "upper_arm_right")
    qtbot.keyClick(view, Qt.Key.Key_I)
    assert changed(before, doc) == {"pip/forearm_left/angle", "pip/upper_arm_right/angle"}
    assert ctx.undo_stack.count() == 2
    qtbot.keyClick(view, Qt.Key.Key_S, Qt.KeyboardModifier.ShiftModifier)
    assert changed(before, doc) == PIP_ALL
    assert ctx.undo_stack.count() == 3
    ctx.set_frame(FRAME + 1)
    ctx.set_frame(FRAME)  # the pose is keyed now: it stays (the pendulums follow the new keys)
    keyframed = ~ch.dynamic
    np.testing.assert_allclose(c2d.joint_angles(doc, "pip", ctx.time)[keyframed], right_arm[keyframed], atol=1e-9)
    # Keyed frames show on the timeline (the selected character's too).
    timeline = window.findChild(QWidget, "timeline")
    assert FRAME in timeline.keys() and FRAME in timeline.selected_keys()

    # One undo step each, undone exactly.
    ctx.undo_stack.undo()
    assert changed(before, doc) == {"pip/forearm_left/angle", "pip/upper_arm_right/angle"}
    ctx.undo_stack.undo()
    ctx.undo_stack.undo()
    assert doc.state() == state0
    assert FRAME not in timeline.keys()


def test_auto_key_on_keeps_keying_every_drag(demo, qtbot):
    window, view = demo
    doc, ctx = window.doc, window.ctx
    before = channels(doc)
    drag(view, Qt.MouseButton.RightButton, hand_point(window, view), QPoint(-30, 25))
    assert changed(before, doc) and ctx.undo_stack.count() == 1
    assert not pose.has_pending(doc)


@pytest.mark.parametrize("damping", [None, 0.05])
def test_key_all_ik_drag_keys_the_universal_keyframe_whatever_the_damping(demo, qtbot, damping):
    window, view = demo
    doc, ctx = window.doc, window.ctx
    ctx.push(SetParameter(doc, c2d.KEY_ALL_PARAMETER, True))
    if damping is not None:
        ctx.push(SetParameter(doc, "ik.damping", damping))
    before = channels(doc)
    drag(view, Qt.MouseButton.RightButton, hand_point(window, view), QPoint(-30, 25))
    keyed = changed(before, doc)
    # Every keyframed joint and position of every 2D character of the demo.
    expected = PIP_ALL | {
        "pendulum_clock/clock/angle", "pendulum_clock/hour_hand/angle", "pendulum_clock/minute_hand/angle",
        "pendulum_clock//x", "pendulum_clock//y",
        "robot/body/angle", "robot/leg_left/angle", "robot/shin_left/angle", "robot/leg_right/angle",
        "robot/shin_right/angle", "robot/head/angle", "robot/arm_left/angle", "robot/forearm_left/angle",
        "robot/claw_left/angle", "robot/arm_right/angle", "robot/forearm_right/angle", "robot/claw_right/angle",
        "robot//x", "robot//y",
    }
    assert keyed == expected


# ------------------------------------------------------------------------- 3D
@pytest.mark.gl
def test_3d_s_keys_the_selected_joints_dofs_and_auto_key_off_poses(make_window, qtbot, shared_data):
    from qtanimator.document.character3d import add_character3d_command, pose_skeleton
    from qtanimator.render.gl.camera import OrbitCamera

    window = make_window(editors=("viewport", "timeline"), size=(640, 480))
    window.central_tabs.setCurrentWidget(window.viewport_panel)
    view = window.viewport3d
    d = shared_data / "mit6837"
    window.ctx.push(add_character3d_command(window.doc, d / "Model1.skel", obj_path=d / "Model1.obj",
                                            attach_path=d / "Model1.attach", asset_id="mit"))
    view.options.show_skin = False
    view.camera = OrbitCamera(azimuth=0.0, inclination=0.0, distance=1.6, target=np.array([0.5, 0.5, 0.5]))
    view._framed_once = True
    ctx, doc = window.ctx, window.doc
    ctx.set_frame(12)
    keys = pose_skeleton(doc, "mit", ctx.time).joint_keys()
    view.setFocus()
    qtbot.waitUntil(view.hasFocus)

    # Auto-key off: a right-drag (IK on the right elbow) poses without keys.
    window.autokey_action.setChecked(False)
    before = channels(doc)
    joint = 14
    p0 = pose_skeleton(doc, "mit", ctx.time).world_matrices()[joint, :3, 3]
    px = view.camera.project(p0, view.width(), view.height())[0]
    a = QPoint(int(round(px[0])), int(round(px[1])))
    qtbot.mousePress(view, Qt.MouseButton.RightButton, pos=a)
    for k in range(1, 5):
        qtbot.mouseMove(view, a + QPoint(0, -10 * k))
    qtbot.mouseRelease(view, Qt.MouseButton.RightButton, pos=a + QPoint(0, -40))
    assert ctx.selection == ("mit", keys[joint])
    assert changed(before, doc) == set() and ctx.undo_stack.count() == 1  # only the import
    shown = pose_skeleton(doc, "mit", ctx.time)
    assert np.linalg.norm(shown.world_matrices()[joint, :3, 3] - p0) > 1e-3
    shown_dofs = shown.dof_values().copy()

    # S keys exactly the selected joint's three rotations.
    view.setFocus()
    qtbot.keyClick(view, Qt.Key.Key_S)
    assert changed(before, doc) == {f"mit/{keys[joint]}/rx", f"mit/{keys[joint]}/ry", f"mit/{keys[joint]}/rz"}
    assert ctx.undo_stack.count() == 2
    # Shift+S keys every DOF of the character with the pose shown.
    qtbot.keyClick(view, Qt.Key.Key_S, Qt.KeyboardModifier.ShiftModifier)
    from qtanimator.document.character3d import channel_ids

    assert changed(before, doc) == set(channel_ids(doc, "mit"))
    assert ctx.undo_stack.count() == 3
    ctx.set_frame(13)
    ctx.set_frame(12)
    np.testing.assert_allclose(pose_skeleton(doc, "mit", ctx.time).dof_values(), shown_dofs, atol=1e-12)
    ctx.undo_stack.undo()
    ctx.undo_stack.undo()
    assert changed(before, doc) == set()
