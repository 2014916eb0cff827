"""Pose copy / paste / paste mirrored with real clicks and key presses: Ctrl+C, Ctrl+V and
Ctrl+Shift+V in the 2D editor (the demo's Pip) and the 3D view; one undo step each."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtGui import QAction
from rig_helpers import open_demo

from qtanimator.document import character2d as c2d
from qtanimator.ui import rig_interaction as ri

COPY_FRAME, PASTE_FRAME = 45.0, 100.0  # the demo has no key at frame 100
CTRL, SHIFT = Qt.KeyboardModifier.ControlModifier, Qt.KeyboardModifier.ShiftModifier

#: Pip's keyframed joints and their mirror partners (Pip is drawn from the front).
MIRROR = {"torso": "torso", "head": "head", "leg_left": "leg_right", "leg_right": "leg_left",
          "upper_arm_left": "upper_arm_right", "forearm_left": "forearm_right", "hand_left": "hand_right",
          "upper_arm_right": "upper_arm_left", "forearm_right": "forearm_left", "hand_right": "hand_left"}


@pytest.fixture
def demo(make_window, qtbot):
    ri.pose_clipboard.clip = None
    window, view = open_demo(make_window, qtbot, focus=True)
    window.ctx.set_frame(COPY_FRAME)
    yield window, view
    ri.pose_clipboard.clip = None


def joint_pixel(window, view, name: str) -> QPoint:
    """A pixel that picks Pip's joint ``name`` in the pose shown now."""
    doc = window.doc
    ch = doc.runtime["pip"]
    j = ch.joint_index(name)
    shown = c2d.evaluate_pose(doc, "pip", window.ctx.time)
    pts = ch.joints[j].shapes[0].points
    centre = pts.mean(axis=0)
    for local in [centre] + [centre + f * (p - centre) for f in (0.5, 0.8) for p in pts]:
        xy = view.from_scene(shown.to_world(j, local))
        pixel = QPoint(int(round(xy.x())), int(round(xy.y())))
        if ri.pick(doc, window.ctx.time, view.to_scene(QPointF(pixel))) == ("pip", j):
            return pixel
    raise AssertionError(f"{name} is covered everywhere")


def value(doc, cid: str, frame: float) -> float:
    ch = doc.channels.get(cid)
    return 0.0 if ch is None or not ch.keys else float(ch.evaluate(frame / doc.fps))


def channels(doc) -> dict:
    return {cid: ch.to_dict() for cid, ch in doc.channels.items()}


def changed(before: dict, doc) -> set[str]:
    now = channels(doc)
    return {cid for cid in set(now) | set(before) if now.get(cid) != before.get(cid)}


def test_the_pose_actions_are_the_views_own(demo):
    window, view = demo
    for name, keys in (("actionSetKey", ["S", "I"]), ("actionSetKeyCharacter", ["Shift+S"]),
                       ("actionCopyPose", ["Ctrl+C"]), ("actionPastePose", ["Ctrl+V"]),
                       ("actionPasteMirrored", ["Ctrl+Shift+V"])):
        action = window.findChild(QAction, name)
        assert action is not None and action in view.actions()
        assert [s.toString() for s in action.shortcuts()] == keys
        assert action.shortcutContext() == Qt.ShortcutContext.WidgetWithChildrenShortcut


def test_copy_the_character_then_paste_and_paste_mirrored(demo, qtbot):
    window, view = demo
    doc, ctx = window.doc, window.ctx
    # Clicking the root (the torso) selects the character: Ctrl+C copies all its joints.
    qtbot.mouseClick(view.viewport(), Qt.MouseButton.LeftButton, pos=joint_pixel(window, view, "torso"))
    assert ctx.selection == ("pip", "") and ctx.undo_stack.count() == 0
    qtbot.keyClick(view, Qt.Key.Key_C, CTRL)
    source = {n: value(doc, f"pip/{n}/angle", COPY_FRAME) for n in MIRROR}
    assert source["upper_arm_left"] != pytest.approx(source["upper_arm_right"])
    assert ri.pose_clipboard.clip is not None and sorted(ri.pose_clipboard.clip.joints) == sorted(MIRROR)

    ctx.set_frame(PASTE_FRAME)
    before, state0 = channels(doc), doc.state()
    qtbot.keyClick(view, Qt.Key.Key_V, CTRL)
    assert ctx.undo_stack.count() == 1
    assert changed(before, doc) == {f"pip/{n}/angle" for n in MIRROR}  # rotations only, no position
    for n in MIRROR:
        assert value(doc, f"pip/{n}/angle", PASTE_FRAME) == pytest.approx(source[n], abs=1e-12)
    ctx.undo_stack.undo()
    assert doc.state() == state0

    # Mirrored: left and right swap and every angle negates (a mirror about Pip's vertical axis).
    qtbot.keyClick(view, Qt.Key.Key_V, CTRL | SHIFT)
    assert ctx.undo_stack.count() == 1
    for n, m in MIRROR.items():
        assert value(doc, f"pip/{m}/angle", PASTE_FRAME) == pytest.approx(-source[n], abs=1e-12)
    ctx.undo_stack.undo()
    assert doc.state() == state0


def test_copy_one_joint_and_paste_it_mirrored_on_its_partner(demo, qtbot):
    window, view = demo
    doc, ctx = window.doc, window.ctx
    qtbot.mouseClick(view.viewport(), Qt.MouseButton.LeftButton, pos=joint_pixel(window, view, "upper_arm_left"))
    assert ctx.selection == ("pip", "upper_arm_left") and ctx.undo_stack.count() == 0
    qtbot.keyClick(view, Qt.Key.Key_C, CTRL)
    copied = value(doc, "pip/upper_arm_left/angle", COPY_FRAME)
    ctx.set_frame(PASTE_FRAME)
    before, state0 = channels(doc), doc.state()
    qtbot.keyClick(view, Qt.Key.Key_V, CTRL | SHIFT)
    assert changed(before, doc) == {"pip/upper_arm_right/angle"}
    assert value(doc, "pip/upper_arm_right/angle", PASTE_FRAME) == pytest.approx(-copied, abs=1e-12)
    assert ctx.undo_stack.count() == 1
    ctx.undo_stack.undo()
    assert doc.state() == state0
    qtbot.keyClick(view, Qt.Key.Key_V, CTRL)  # plain paste: the same joint, the same value
    assert changed(before, doc) == {"pip/upper_arm_left/angle"}
    assert value(doc, "pip/upper_arm_left/angle", PASTE_FRAME) == pytest.approx(copied, abs=1e-12)


def test_a_mirrored_pose_mirrors_the_picture(demo, qtbot):
    """Independent of the channels: with Pip's rest pose symmetric about the torso's pivot,
    the mirrored paste puts every joint's pivot at the mirror image (about the torso's
    vertical line) of where the copied pose had its partner's pivot."""
    window, view = demo
    doc, ctx = window.doc, window.ctx
    qtbot.mouseClick(view.viewport(), Qt.MouseButton.LeftButton, pos=joint_pixel(window, view, "torso"))
    qtbot.keyClick(view, Qt.Key.Key_C, CTRL)
    ch = doc.runtime["pip"]
    copied = c2d.evaluate_pose(doc, "pip", COPY_FRAME / doc.fps)
    ctx.set_frame(PASTE_FRAME)
    qtbot.keyClick(view, Qt.Key.Key_V, CTRL | SHIFT)
    pasted = c2d.evaluate_pose(doc, "pip", PASTE_FRAME / doc.fps)
    axis_copied = copied.pivots[0][0]
    axis_pasted = pasted.pivots[0][0]
    for n, m in MIRROR.items():
        a, b = copied.pivots[ch.joint_index(n)], pasted.pivots[ch.joint_index(m)]
        assert b[0] - axis_pasted == pytest.approx(-(a[0] - axis_copied), abs=1e-9)
        assert b[1] - pasted.pivots[0][1] == pytest.approx(a[1] - copied.pivots[0][1], abs=1e-9)


@pytest.mark.gl
def test_3d_copy_and_paste_mirrored_in_the_view(make_window, qtbot, shared_data):
    """The dragon's file poses its left arm as its right arm mirrored across x, (rx, −ry, −rz):
    copying the right shoulder and pasting it mirrored must give the file's left shoulder."""
    from qtanimator.document.character3d import add_character3d_command, pose_skeleton

    ri.pose_clipboard.clip = None
    window = make_window(editors=("viewport", "timeline"), size=(640, 480))
    window.central_tabs.setCurrentWidget(window.viewport_panel)
    view = window.viewport3d
    doc, ctx = window.doc, window.ctx
    ctx.push(add_character3d_command(doc, shared_data / "cse169" / "skeleton" / "dragon.skel", asset_id="dragon"))
    view.setFocus()
    qtbot.waitUntil(view.hasFocus)
    for right, left, expected in (("elbow_right_1", "elbow_left_1", (0.0, 0.66, -0.66)),
                                  ("wrist_right_1", "wrist_left_1", (-0.41, -0.5, 0.87))):
        ctx.select("dragon", right)
        qtbot.keyClick(view, Qt.Key.Key_C, CTRL)
        before, steps = channels(doc), ctx.undo_stack.count()
        qtbot.keyClick(view, Qt.Key.Key_V, CTRL | SHIFT)
        assert changed(before, doc) == {f"dragon/{left}/rx", f"dragon/{left}/ry", f"dragon/{left}/rz"}
        assert ctx.undo_stack.count() == steps + 1
        skel = pose_skeleton(doc, "dragon", ctx.time)
        j = skel.joint_keys().index(left)
        np.testing.assert_allclose([d.value for d in skel.joints[j].dofs], expected, atol=1e-12)
    ri.pose_clipboard.clip = None
