"""The IK solvers in the editors: the Properties dock offers them, a right-drag on a two-joint
chain is solved exactly (two-bone), the chosen solver drives other drags; one undo step each."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtWidgets import QCheckBox, QComboBox

from qtanimator.document import SetParameter
from qtanimator.document import character2d as c2d


def _right_drag(qtbot, widget, start: QPoint, moves: list[QPoint]) -> None:  # type: ignore[no-untyped-def]
    qtbot.mousePress(widget, Qt.MouseButton.RightButton, pos=start)
    for m in moves:
        qtbot.mouseMove(widget, m)
    qtbot.mouseRelease(widget, Qt.MouseButton.RightButton, pos=moves[-1])


def test_2d_solver_choices_and_an_exact_two_bone_drag(make_window, qtbot, shared_data):
    window = make_window(active=False)
    assert window.open_path(shared_data / "cmu-animator" / "scenes" / "arm.svg")
    panel = window.properties_panel
    solver = panel.findChild(QComboBox, "param_ik_solver")
    assert [solver.itemText(i) for i in range(solver.count())] == ["dls", "ccd", "fabrik", "handout"]
    bend = panel.findChild(QComboBox, "param_ik_bend_direction")
    assert [bend.itemText(i) for i in range(bend.count())] == ["keep", "positive", "negative"]
    two_bone = panel.findChild(QCheckBox, "param_ik_two_bone")
    assert two_bone.isChecked()

    view = window.rig_editor.view
    view.fit_view()
    doc = window.doc
    asset = next(iter(doc.assets))
    # joint2 hangs from joint1 below the frozen root: two moving joints, the two-bone case
    local = doc.runtime[asset].joints[2].shapes[0].points.mean(axis=0)
    grabbed = c2d.evaluate_pose(doc, asset, 0.0).to_world(2, local)
    p = view.from_scene(grabbed)
    start = QPoint(int(p.x()), int(p.y()))
    local = c2d.evaluate_pose(doc, asset, 0.0).to_local(2, view.to_scene(QPointF(start)))   # the point pressed
    steps = window.ctx.undo_stack.count()
    moves = [start + QPoint(-15 * k, 5 * k) for k in range(1, 5)]
    _right_drag(qtbot, view.viewport(), start, moves)
    assert window.ctx.undo_stack.count() == steps + 1
    target = view.to_scene(QPointF(moves[-1]))
    now = c2d.evaluate_pose(doc, asset, 0.0).to_world(2, local)
    assert np.hypot(*(now - target)) < 1e-6   # exactly under the cursor

    # FABRIK with two-bone off: also one undo step, also towards the cursor (the dock was
    # rebuilt for the joint the drag selected)
    panel.findChild(QComboBox, "param_ik_solver").setCurrentText("fabrik")
    panel.findChild(QCheckBox, "param_ik_two_bone").setChecked(False)
    assert doc.parameters["ik.solver"] == "fabrik" and doc.parameters["ik.two_bone"] is False
    steps = window.ctx.undo_stack.count()
    # Towards the shoulder (joint 2's pivot, the chain's base): in reach whatever the view's
    # scale (a layout that leaves the 2D view small makes fixed pixel steps overshoot).
    pose = c2d.evaluate_pose(doc, asset, 0.0)
    shoulder = view.from_scene(pose.to_world(1, doc.runtime[asset].joints[2].pivot))
    shoulder_px = QPoint(int(shoulder.x()), int(shoulder.y()))
    back = [moves[-1] + (shoulder_px - moves[-1]) * (0.12 * k) for k in range(1, 4)]
    _right_drag(qtbot, view.viewport(), moves[-1], back)
    assert window.ctx.undo_stack.count() == steps + 1
    target = view.to_scene(QPointF(back[-1]))
    assert np.hypot(*(c2d.evaluate_pose(doc, asset, 0.0).to_world(2, local) - target)) < 1e-3


@pytest.mark.gl
@pytest.mark.parametrize("settings", [{}, {"ik.solver": "ccd", "ik.two_bone": False},
                                      {"ik.solver": "fabrik", "ik.two_bone": False}])
def test_3d_right_drag_with_each_solver_is_one_undo_step(qtbot, shared_data, settings):
    from qtanimator.document.character3d import add_character3d_command, pose_skeleton
    from qtanimator.render.gl.camera import OrbitCamera
    from qtanimator.ui import viewport
    from qtanimator.ui.main_window import MainWindow

    window = MainWindow(install_editors=False)
    viewport.install(window)
    qtbot.addWidget(window)
    window.resize(420, 360)
    window.show()
    qtbot.waitExposed(window)
    d = shared_data / "mit6837"
    window.ctx.push(add_character3d_command(window.doc, d / "Model1.skel", obj_path=d / "Model1.obj",
                                            attach_path=d / "Model1.attach", asset_id="mit"))
    for name, value in settings.items():
        window.ctx.push(SetParameter(window.doc, name, value))
    view = window.viewport3d
    view.options.show_skin = False
    view.camera = OrbitCamera(azimuth=0.0, inclination=0.0, distance=1.6, target=np.array([0.5, 0.5, 0.5]))
    view._framed_once = True
    joint = 14  # right elbow: its chain is the shoulder and the collarbone (two joints)
    p0 = pose_skeleton(window.doc, "mit", window.ctx.time).world_matrices()[joint, :3, 3]
    w, h = view.width(), view.height()
    start = view.camera.project(p0, w, h)[0]
    a = QPoint(int(round(start[0])), int(round(start[1])))
    steps = window.ctx.undo_stack.count()
    _right_drag(qtbot, view, a, [a + QPoint(2 * k, -8 * k) for k in range(1, 5)])
    assert window.ctx.undo_stack.count() == steps + 1
    p1 = pose_skeleton(window.doc, "mit", window.ctx.time).world_matrices()[joint, :3, 3]
    moved = view.camera.project(p1, w, h)[0]
    assert moved[1] < start[1] - 15   # up the screen, towards the mouse
    if not settings:   # two-bone: on the view plane through the elbow, under the cursor
        assert np.hypot(moved[0] - (a.x() + 8), moved[1] - (a.y() - 32)) < 1.0
