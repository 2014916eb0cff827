"""2D joint limits in the GUI (issue 18, item 2): set in Properties (one undo step, saved),
respected by the right-drag IK, the left-drag rotation and the Joints slider, and drawn as a
wedge about the selected joint's pivot. Real widgets, real mouse and key events.

The CMU arm: root (pivot 40, 380) → joint1 (40, 340) → joint2, the hand (40, 140) → three
fingers (0, 60), (40, 60), (80, 60).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtGui import QImage
from PySide6.QtWidgets import QCheckBox, QDoubleSpinBox, QGraphicsView, QStyle, QStyleOptionSlider

from qtanimator.document import character2d as c2d
from qtanimator.ui.rig_editor import LIMIT_WEDGE_RADIUS_PX
from qtanimator.ui.rig_interaction import pick, rotation_delta

HAND = 2
HAND_PIVOT = np.array([40.0, 140.0])
FIRST_FINGER_PIVOT = np.array([0.0, 60.0])


@pytest.fixture
def arm(make_window, qtbot, shared_data):
    window = make_window()
    assert window.open_path(shared_data / "cmu-animator" / "scenes" / "arm.svg")
    view = window.findChild(QGraphicsView, "rigEditorView")
    view.fit_view()
    view.setFocus()
    qtbot.wait(10)
    window.ctx.undo_stack.clear()
    return window, view, next(iter(window.doc.assets))


def rot(a: float) -> np.ndarray:
    return np.array([[math.cos(a), math.sin(a)], [-math.sin(a), math.cos(a)]])


def vpos(view, xy) -> QPoint:
    p = view.from_scene(xy)
    return QPoint(int(round(p.x())), int(round(p.y())))


def scene_of(view, pos: QPoint) -> np.ndarray:
    return view.to_scene(QPointF(pos))


def limit(window, asset, joint, lo_deg, hi_deg) -> None:
    window.ctx.push(c2d.set_joint_limits_command(window.doc, asset, joint, math.radians(lo_deg),
                                                 math.radians(hi_deg)))


def hand_point(window, asset) -> np.ndarray:
    """A point of the hand's palm (rect 0…80 × 60…140) no finger covers, on a whole pixel."""
    view = window.rig_editor.view
    pose = c2d.evaluate_pose(window.doc, asset, window.ctx.time)
    world = scene_of(view, vpos(view, pose.to_world(HAND, (60.0, 110.0))))
    assert pick(window.doc, window.ctx.time, world) == (asset, HAND)
    return world


def drag(qtbot, view, button, start: QPoint, points: list[QPoint]) -> None:
    vp = view.viewport()
    qtbot.mousePress(vp, button, pos=start)
    for p in points:
        qtbot.mouseMove(vp, p)
    qtbot.mouseRelease(vp, button, pos=points[-1])


# ------------------------------------------------------------------ Properties
def test_limits_set_in_properties_are_undoable_and_saved(qtbot, arm, tmp_path):
    window, _view, asset = arm
    doc = window.doc
    window.ctx.select(asset, "joint2")
    panel = window.properties_panel
    enabled = panel.findChild(QCheckBox, "jointLimitsEnabled")
    lo_box = panel.findChild(QDoubleSpinBox, "jointLimitMin")
    hi_box = panel.findChild(QDoubleSpinBox, "jointLimitMax")
    assert not enabled.isChecked() and not lo_box.isEnabled() and not hi_box.isEnabled()
    assert (lo_box.value(), hi_box.value()) == (-90.0, 90.0)  # offered: ±90° around the rest angle 0

    qtbot.mouseClick(enabled, Qt.MouseButton.LeftButton, pos=QPoint(8, enabled.height() // 2))
    assert enabled.isChecked() and lo_box.isEnabled() and hi_box.isEnabled()
    assert window.ctx.undo_stack.count() == 1
    assert c2d.joint_limits(doc, asset)[HAND] == (math.radians(-90.0), math.radians(90.0))

    lo_box.setFocus()
    lo_box.lineEdit().selectAll()
    qtbot.keyClicks(lo_box.lineEdit(), "-15")
    qtbot.keyClick(lo_box.lineEdit(), Qt.Key.Key_Return)
    assert window.ctx.undo_stack.count() == 2
    assert c2d.joint_limits(doc, asset)[HAND] == (math.radians(-15.0), math.radians(90.0))
    assert doc.parameters["arm.limits.joint2"] == [math.radians(-15.0), math.radians(90.0)]

    # A minimum above the maximum is refused with a reason; the document is unchanged.
    hi_box.setFocus()
    hi_box.lineEdit().selectAll()
    qtbot.keyClicks(hi_box.lineEdit(), "-40")
    qtbot.keyClick(hi_box.lineEdit(), Qt.Key.Key_Return)
    assert window.ctx.undo_stack.count() == 2
    assert hi_box.refusing and "minimum" in hi_box.toolTip().lower()
    assert hi_box.value() == 90.0

    window.ctx.undo_stack.undo()
    assert lo_box.value() == -90.0 and enabled.isChecked()
    window.ctx.undo_stack.undo()
    assert not enabled.isChecked() and not lo_box.isEnabled()
    assert c2d.joint_limits(doc, asset)[HAND] is None
    window.ctx.undo_stack.redo()
    window.ctx.undo_stack.redo()

    path = tmp_path / "limits.qtanim"
    assert window.save_to(path)
    window.new_document()
    assert window.open_path(path)
    assert c2d.joint_limits(window.doc, asset)[HAND] == (math.radians(-15.0), math.radians(90.0))
    window.ctx.select(asset, "joint2")
    panel = window.properties_panel
    assert panel.findChild(QCheckBox, "jointLimitsEnabled").isChecked()
    assert panel.findChild(QDoubleSpinBox, "jointLimitMin").value() == -15.0
    assert panel.findChild(QDoubleSpinBox, "jointLimitMax").value() == 90.0

    # Unticking frees the joint: one more step.
    enabled = panel.findChild(QCheckBox, "jointLimitsEnabled")
    qtbot.mouseClick(enabled, Qt.MouseButton.LeftButton, pos=QPoint(8, enabled.height() // 2))
    assert c2d.joint_limits(window.doc, asset)[HAND] is None
    assert window.ctx.undo_stack.count() == 1


# ------------------------------------------------------------------ gestures
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_ik_right_drag_past_the_limit_stops_at_it(qtbot, arm, sign):
    window, view, asset = arm
    doc = window.doc
    limit(window, asset, 1, 0.0, 0.0)  # the upper arm locked: the hand alone can turn
    limit(window, asset, HAND, -20.0, 30.0)
    window.ctx.undo_stack.clear()
    press = hand_point(window, asset)
    # Where the grabbed point would be with the hand turned 70°: past either limit.
    target = HAND_PIVOT + rot(sign * math.radians(70.0)) @ (press - HAND_PIVOT)
    steps = [vpos(view, press + (target - press) * f) for f in (0.25, 0.5, 0.75, 1.0)]
    drag(qtbot, view, Qt.MouseButton.RightButton, vpos(view, press), steps)
    angles = c2d.joint_angles(doc, asset, 0.0)
    expected = math.radians(30.0) if sign > 0 else math.radians(-20.0)
    assert angles[HAND] == pytest.approx(expected, abs=1e-9)
    assert angles[1] == 0.0
    assert window.ctx.undo_stack.count() == 1


def test_left_drag_rotation_stops_at_the_limit_and_follows_back(qtbot, arm):
    window, view, asset = arm
    doc = window.doc
    limit(window, asset, HAND, -20.0, 30.0)
    window.ctx.undo_stack.clear()
    press = hand_point(window, asset)
    start = vpos(view, press)
    r = scene_of(view, start) - HAND_PIVOT
    vp = view.viewport()
    qtbot.mousePress(vp, Qt.MouseButton.LeftButton, pos=start)
    seen = []
    for deg in (10, 20, 30, 40, 50, 70, 90):
        qtbot.mouseMove(vp, vpos(view, HAND_PIVOT + rot(math.radians(deg)) @ r))
        seen.append(float(c2d.joint_angles(doc, asset, 0.0)[HAND]))
    assert max(seen) == pytest.approx(math.radians(30.0), abs=1e-9)  # held at the limit...
    assert seen[-1] == pytest.approx(math.radians(30.0), abs=1e-9)
    back = vpos(view, HAND_PIVOT + rot(math.radians(12.0)) @ r)
    qtbot.mouseMove(vp, back)
    qtbot.mouseRelease(vp, Qt.MouseButton.LeftButton, pos=back)
    # ...and follows the cursor back inside the range.
    expected = rotation_delta(HAND_PIVOT, scene_of(view, start), scene_of(view, back))
    assert expected == pytest.approx(math.radians(12.0), abs=0.02)
    assert c2d.joint_angles(doc, asset, 0.0)[HAND] == pytest.approx(expected, abs=1e-9)
    assert window.ctx.undo_stack.count() == 1
    # The other side: the minimum.
    press = hand_point(window, asset)
    start = vpos(view, press)
    r = scene_of(view, start) - HAND_PIVOT
    drag(qtbot, view, Qt.MouseButton.LeftButton, start,
         [vpos(view, HAND_PIVOT + rot(math.radians(-d)) @ r) for d in (20, 40, 60, 80)])
    assert c2d.joint_angles(doc, asset, 0.0)[HAND] == pytest.approx(math.radians(-20.0), abs=1e-9)


def _handle_centre(slider) -> QPoint:
    opt = QStyleOptionSlider()
    slider.initStyleOption(opt)
    rect = slider.style().subControlRect(QStyle.ComplexControl.CC_Slider, opt,
                                         QStyle.SubControl.SC_SliderHandle, slider)
    return rect.center()


def test_the_joints_slider_spans_the_limits_and_cannot_go_past(qtbot, arm):
    window, _view, asset = arm
    doc = window.doc
    limit(window, asset, HAND, -20.0, 30.0)
    window.ctx.select(asset, "joint2")
    row = window.joint_tree.dofs.rows[0]
    slider, spin = row.slider, row.spin
    assert (slider.minimum(), slider.maximum()) == (-200, 300)  # 0.1° steps
    assert (spin.minimum(), spin.maximum()) == (-20.0, 30.0)
    window.ctx.undo_stack.clear()
    # Drag the handle far past the right end.
    centre = _handle_centre(slider)
    qtbot.mousePress(slider, Qt.MouseButton.LeftButton, pos=centre)
    for x in (centre.x() + 40, slider.width() + 100, slider.width() + 400):
        qtbot.mouseMove(slider, QPoint(x, centre.y()))
    qtbot.mouseRelease(slider, Qt.MouseButton.LeftButton, pos=QPoint(slider.width() + 400, centre.y()))
    assert slider.value() == 300
    assert c2d.joint_angles(doc, asset, 0.0)[HAND] == math.radians(30.0)
    assert window.ctx.undo_stack.count() == 1
    # Keys past the end change nothing; page steps (10°) down stop at the other limit.
    slider.setFocus()
    qtbot.keyClick(slider, Qt.Key.Key_PageUp)
    assert slider.value() == 300
    assert c2d.joint_angles(doc, asset, 0.0)[HAND] == math.radians(30.0)
    for _ in range(8):
        qtbot.keyClick(slider, Qt.Key.Key_PageDown)
    assert slider.value() == -200
    assert c2d.joint_angles(doc, asset, 0.0)[HAND] == math.radians(-20.0)
    # Freeing the joint gives the slider its full turn both ways again.
    window.ctx.push(c2d.set_joint_limits_command(doc, asset, HAND, None, None))
    row = window.joint_tree.dofs.rows[0]
    assert (row.slider.minimum(), row.slider.maximum()) == (-3600, 3600)


# ------------------------------------------------------------------ the wedge
def _orange(image: QImage, x: float, y: float, reach: int = 2) -> bool:
    """An orange wedge pixel (255, 140, 0) within ``reach`` pixels of (x, y)."""
    cx, cy = int(round(x)), int(round(y))
    for dx in range(-reach, reach + 1):
        for dy in range(-reach, reach + 1):
            c = image.pixelColor(cx + dx, cy + dy)
            if c.red() > 200 and 90 < c.green() < 190 and c.blue() < 70:
                return True
    return False


def _screen_point(view, pivot_scene, angle: float, radius_px: float) -> tuple[float, float]:
    """The view pixel ``radius_px`` from the hand's pivot along its rest direction (towards
    the first finger's pivot) turned by ``angle``."""
    d = FIRST_FINGER_PIVOT - HAND_PIVOT
    d = rot(angle) @ (d / np.hypot(*d))
    p = view.from_scene(pivot_scene)
    scale = view.transform().m11()
    # Scene and view share orientation (a uniform scale, no flip): the same direction on screen.
    assert view.transform().m22() == pytest.approx(scale) and view.transform().m12() == 0.0
    return p.x() + radius_px * d[0], p.y() + radius_px * d[1]


def test_the_selected_joints_limits_are_drawn_as_a_wedge_that_turns_with_the_parent(qtbot, arm):
    window, view, asset = arm
    doc = window.doc
    window.ctx.select(asset, "joint2")
    qtbot.wait(10)
    plain = view.grab().toImage()
    lo, hi = -20.0, 30.0
    limit(window, asset, HAND, lo, hi)
    qtbot.wait(10)
    image = view.grab().toImage()
    radius = LIMIT_WEDGE_RADIUS_PX
    pivot = HAND_PIVOT
    inside = [math.radians(a) for a in np.linspace(lo + 3, hi - 3, 9)]
    outside = [math.radians(a) for a in (hi + 25, lo - 25, 180.0)]
    assert all(_orange(image, *_screen_point(view, pivot, a, radius)) for a in inside)
    # The two radii (edges of the wedge) from the pivot out to the arc.
    for edge in (lo, hi):
        assert all(_orange(image, *_screen_point(view, pivot, math.radians(edge), f * radius)) for f in (0.4, 0.7))
    assert not any(_orange(image, *_screen_point(view, pivot, a, radius)) for a in outside)
    assert not any(_orange(plain, *_screen_point(view, pivot, a, radius)) for a in inside)

    # Another joint selected: no wedge. Back on the hand: the wedge again.
    window.ctx.select(asset, "joint1")
    qtbot.wait(10)
    other = view.grab().toImage()
    assert not any(_orange(other, *_screen_point(view, pivot, a, radius)) for a in inside)

    # The parent (joint1) turns 40°: the hand's pivot moves and the wedge turns with it.
    window.ctx.select(asset, "joint2")
    window.ctx.push(c2d.key_joint(doc, asset, 1, math.radians(40.0), 0.0))
    qtbot.wait(10)
    turned = view.grab().toImage()
    moved_pivot = np.array([40.0, 340.0]) + rot(math.radians(40.0)) @ (HAND_PIVOT - np.array([40.0, 340.0]))
    np.testing.assert_allclose(c2d.evaluate_pose(doc, asset, 0.0).pivots[HAND], moved_pivot, atol=1e-9)
    shifted = [a + math.radians(40.0) for a in inside]
    assert all(_orange(turned, *_screen_point(view, moved_pivot, a, radius)) for a in shifted)
    assert not _orange(turned, *_screen_point(view, moved_pivot, math.radians(hi + 25 + 40), radius))
