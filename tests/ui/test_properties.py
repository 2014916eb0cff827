"""The properties dock: joint facts, pendulum parameters and preset, IK settings — all undoable."""

from __future__ import annotations

import math

import numpy as np
import pytest
from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtWidgets import QCheckBox, QComboBox, QDockWidget, QDoubleSpinBox, QLabel

from qtanimator.document import character2d as c2d
from qtanimator.ui.rig_interaction import pick


@pytest.fixture
def clock(make_window, qtbot, shared_data):
    window = make_window(active=False)
    assert window.open_path(shared_data / "cmu-animator" / "scenes" / "clock.svg")
    window.ctx.undo_stack.clear()
    return window, window.properties_panel


def test_joint_facts_follow_the_selection(qtbot, clock):
    window, panel = clock
    assert window.findChild(QDockWidget, "propertiesDock") is not None
    character = window.doc.runtime["clock"]
    window.ctx.select("clock", character.joints[5].name)
    assert panel.findChild(QLabel, "jointType").text().startswith("dynamic")
    window.ctx.select("clock", character.joints[4].name)
    assert panel.findChild(QLabel, "jointType").text() == "keyframed"
    window.joint_tree.dofs.rows[0].spin.setValue(12.5)
    assert panel.findChild(QLabel, "jointAngle").text() == "12.500°"


def test_pendulum_preset_and_parameters_are_undoable_commands(qtbot, clock):
    window, panel = clock
    doc = window.doc
    window.ctx.select("clock", "")
    preset = panel.findChild(QComboBox, "pendulumPreset")
    assert preset.currentText() == "physical"
    before = doc.state()
    preset.setCurrentText("handout")
    assert c2d.pendulum_params(doc, "clock").g == 5000.0
    assert window.ctx.undo_stack.count() == 1
    g_box = panel.findChild(QDoubleSpinBox, "param_clock_pendulum_g")
    assert g_box.value() == pytest.approx(5000.0)
    g_box.setValue(4000.0)
    assert c2d.pendulum_params(doc, "clock").g == 4000.0
    assert preset.currentText() == "custom"
    window.ctx.undo_stack.undo()
    assert g_box.value() == pytest.approx(5000.0)
    window.ctx.undo_stack.undo()
    assert doc.state() == before
    assert preset.currentText() == "physical"


def test_damping_changes_the_simulation(qtbot, clock):
    window, panel = clock
    doc = window.doc
    window.ctx.select("clock", doc.runtime["clock"].joints[5].name)
    window.joint_tree.dofs.rows[0].spin.setValue(20.0)
    swing = c2d.evaluate_pose(doc, "clock", 2.0).world_angles[5]
    panel.findChild(QDoubleSpinBox, "param_clock_pendulum_damping").setValue(50.0)
    damped = c2d.evaluate_pose(doc, "clock", 2.0).world_angles[5]
    assert abs(damped - swing) > 1e-3  # the cached swing was dropped and simulated again
    window.ctx.undo_stack.undo()
    assert c2d.evaluate_pose(doc, "clock", 2.0).world_angles[5] == pytest.approx(swing)


def test_ik_solver_settings_drive_the_right_drag(make_window, qtbot, shared_data):
    window = make_window(active=False)
    assert window.open_path(shared_data / "cmu-animator" / "scenes" / "arm.svg")
    panel = window.properties_panel
    view = window.rig_editor.view
    view.fit_view()
    asset = next(iter(window.doc.assets))
    solver = panel.findChild(QComboBox, "param_ik_solver")
    solver.setCurrentText("handout")
    assert window.doc.parameters["ik.solver"] == "handout"
    freeze = panel.findChild(QCheckBox, "param_ik_freeze_root")
    assert freeze.isChecked()

    pose = c2d.evaluate_pose(window.doc, asset, 0.0)
    local = window.doc.runtime[asset].joints[2].shapes[0].points.mean(axis=0)
    start_xy = pose.to_world(2, local)
    p = view.from_scene(start_xy)
    start = QPoint(int(p.x()), int(p.y()))
    assert pick(window.doc, 0.0, view.to_scene(QPointF(start))) == (asset, 2)
    vp = view.viewport()
    qtbot.mousePress(vp, Qt.MouseButton.RightButton, pos=start)
    qtbot.mouseMove(vp, start + QPoint(-60, 10))
    qtbot.mouseRelease(vp, Qt.MouseButton.RightButton, pos=start + QPoint(-60, 10))
    after = c2d.joint_angles(window.doc, asset, 0.0)
    # The handout's gradient step (τ = 1e-6, 10 steps) moves the chain only a little, and
    # in the direction of the cursor.
    assert 0 < np.abs(after).max() < math.radians(30)
    moved = c2d.evaluate_pose(window.doc, asset, 0.0).to_world(2, local)
    target = view.to_scene(QPointF(start + QPoint(-60, 10)))
    assert np.hypot(*(moved - target)) < np.hypot(*(start_xy - target))


def test_a_pendulum_value_the_simulation_cannot_take_is_refused_with_its_reason(qtbot, clock):
    window, panel = clock
    doc = window.doc
    window.ctx.select("clock", "")
    step = panel.findChild(QDoubleSpinBox, "param_clock_pendulum_step")
    before = c2d.pendulum_params(doc, "clock").step
    qtbot.mouseClick(step, Qt.MouseButton.LeftButton)
    qtbot.keyClick(step, Qt.Key.Key_A, Qt.KeyboardModifier.ControlModifier)
    qtbot.keyClicks(step, "0")
    qtbot.keyClick(step, Qt.Key.Key_Return)
    assert c2d.pendulum_params(doc, "clock").step == before     # PendulumParams refuses a zero step
    assert step.value() == pytest.approx(before, abs=1e-6)   # shown to 6 decimals
    assert "at least" in step.toolTip() and "at least" in window.statusBar().currentMessage()
    assert window.ctx.undo_stack.count() == 0
    qtbot.keyClick(step, Qt.Key.Key_A, Qt.KeyboardModifier.ControlModifier)
    qtbot.keyClicks(step, "0.001")
    qtbot.keyClick(step, Qt.Key.Key_Return)
    assert c2d.pendulum_params(doc, "clock").step == pytest.approx(0.001)
    assert window.ctx.undo_stack.count() == 1
