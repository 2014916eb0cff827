"""IK where you click in the 3D view: a right-drag on the skin moves the point under the
cursor (real GL under the private Xvfb, real mouse events on the demo's skinned arm)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from PySide6.QtCore import QPoint, QPointF, Qt

from qtanimator.render.gl.camera import OrbitCamera
from qtanimator.ui import viewport
from qtanimator.ui.main_window import MainWindow

pytestmark = pytest.mark.gl

ELBOW = 1


@pytest.fixture
def arm_window(qtbot):
    from qtanimator.document.character3d import add_character3d_command
    from qtanimator.paths import scenes_dir

    w = MainWindow(install_editors=False)
    viewport.install(w)
    qtbot.addWidget(w)
    w.resize(420, 360)
    w.show()
    qtbot.waitExposed(w)
    d = scenes_dir() / "arm3d"
    w.ctx.push(add_character3d_command(w.doc, d / "arm.skel", d / "arm.skin", asset_id="arm"))
    view = w.viewport3d
    view.options.show_skin = True
    view.camera = OrbitCamera(azimuth=0.0, inclination=0.0, distance=5.0, target=np.array([0.8, 1.4, 0.0]))
    view._framed_once = True
    w.ctx.set_frame(0)
    return w, view


def _pixel(view, point) -> QPoint:
    x, y, _z = view.camera.project(np.asarray(point, dtype=float), view.width(), view.height())[0]
    return QPoint(int(round(x)), int(round(y)))


def _projected(view, point) -> np.ndarray:
    return np.asarray(view.camera.project(np.asarray(point, dtype=float), view.width(), view.height())[0][:2])


def _surface_pixel(window, view, along: float) -> tuple[QPoint, object]:
    """A pixel whose ray hits the forearm's skin (dominant joint: the elbow), near the point
    ``along`` of the way from the elbow to the forearm's far end, and the hit there."""
    from qtanimator.core.skinning import skin_positions
    from qtanimator.document import character3d

    doc, t = window.doc, window.ctx.time
    ch = character3d.character(doc, "arm")
    world = character3d.world_matrices(doc, "arm", t)
    pos = skin_positions(ch.skin, ch.skinning_world(world))
    local = (np.linalg.inv(world[ELBOW]) @ np.c_[pos, np.ones(len(pos))].T).T[:, :3]
    length = local[:, 0].max()
    order = np.argsort(np.abs(local[:, 0] - along * length) + 0.3 * np.abs(local[:, 1]) - 0.1 * pos[:, 2])
    for v in order[:200]:
        px = _pixel(view, pos[v])
        hit = view.pick_surface(QPointF(px))
        if hit is not None and hit.joint == ELBOW:
            return px, hit
    raise AssertionError("no pixel hits the forearm's skin")


def _drag_along(qtbot, window, view, hit, start: QPoint, angles_deg) -> list[float]:
    """Right-drag from ``start`` through the projections of the hit point turned about the
    world z axis through the elbow (the front camera looks down −z, so those points stay in
    the view plane through the hit point); returns the pixel error after each move."""
    from qtanimator.document.character3d import world_matrices
    from qtanimator.document.surface_pick import effector_point

    pivot = world_matrices(window.doc, "arm", window.ctx.time)[ELBOW, :3, 3]
    qtbot.mousePress(view, Qt.MouseButton.RightButton, pos=start)
    errors = []
    for deg in angles_deg:
        a = math.radians(deg)
        rot = np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0], [0, 0, 1]])
        cursor = _pixel(view, pivot + rot @ (hit.point - pivot))
        qtbot.mouseMove(view, cursor)
        now = effector_point(window.doc, "arm", hit.joint, hit.offset, window.ctx.time)
        errors.append(float(np.hypot(*(_projected(view, now) - np.array([cursor.x(), cursor.y()])))))
    return errors


def test_forearm_surface_drag_bends_the_elbow_and_the_point_follows_the_cursor(arm_window, qtbot):
    from qtanimator.document.character3d import pose_skeleton

    window, view = arm_window
    doc = window.doc
    px, hit = _surface_pixel(window, view, 0.5)
    # the pick is on the skin, off the elbow's pivot, in the elbow's frame
    w0 = pose_skeleton(doc, "arm", window.ctx.time).world_matrices()
    np.testing.assert_allclose(w0[ELBOW, :3, :3] @ hit.offset + w0[ELBOW, :3, 3], hit.point, atol=1e-9)
    assert np.linalg.norm(hit.offset) > 0.2
    before = pose_skeleton(doc, "arm", window.ctx.time).dof_values().copy()
    steps = window.ctx.undo_stack.count()
    errors = _drag_along(qtbot, window, view, hit, px, [6, 12, 18, 24, 30])
    last = view._drag and view._drag.get("last")
    qtbot.mouseRelease(view, Qt.MouseButton.RightButton, pos=QPoint(int(last.x()), int(last.y())))
    print("forearm drag: pixel error after each move", [round(e, 2) for e in errors])
    assert max(errors) < 3.0, errors                 # the clicked point stays under the cursor
    assert window.ctx.selection == ("arm", "elbow")
    after = pose_skeleton(doc, "arm", window.ctx.time).dof_values()
    np.testing.assert_allclose(after[0], before[0])   # the shoulder (the root) stays
    assert np.abs(after[ELBOW] - before[ELBOW]).max() > 0.2   # the elbow bent
    # towards the cursor: the forearm's far end went up the screen (the drag turned it up)
    tip_local = np.array([0.9, 0.0, 0.0])
    w1 = pose_skeleton(doc, "arm", window.ctx.time).world_matrices()
    up = px.y() - last.y()
    assert up > 5
    assert (_projected(view, w1[ELBOW, :3, :3] @ tip_local + w1[ELBOW, :3, 3])[1]
            < _projected(view, w0[ELBOW, :3, :3] @ tip_local + w0[ELBOW, :3, 3])[1] - up)
    assert window.ctx.undo_stack.count() == steps + 1    # one gesture, one undo step
    assert any(c.startswith("arm/elbow/") for c in doc.channels)
    window.ctx.undo_stack.undo()
    np.testing.assert_allclose(pose_skeleton(doc, "arm", window.ctx.time).dof_values(), before, atol=1e-12)


def test_the_arms_tip_is_draggable_and_escape_aborts(arm_window, qtbot):
    from qtanimator.document.character3d import pose_skeleton

    window, view = arm_window
    doc = window.doc
    px, hit = _surface_pixel(window, view, 0.97)
    w0 = pose_skeleton(doc, "arm", window.ctx.time).world_matrices()
    assert hit.offset[0] > 0.75    # at the far end of the forearm, beyond where any joint is
    state = doc.state()
    steps = window.ctx.undo_stack.count()
    errors = _drag_along(qtbot, window, view, hit, px, [-5, -10, -15, -20])
    assert max(errors) < 3.0, errors
    assert doc.state() != state
    qtbot.keyClick(view, Qt.Key.Key_Escape)               # aborts: the document goes back exactly
    assert doc.state() == state
    qtbot.mouseRelease(view, Qt.MouseButton.RightButton, pos=px)
    assert window.ctx.undo_stack.count() == steps
    # the same drag released: one undo step, the tip moved down the screen with the cursor
    errors = _drag_along(qtbot, window, view, hit, px, [-5, -10, -15, -20])
    qtbot.mouseRelease(view, Qt.MouseButton.RightButton, pos=view._drag["last"].toPoint())
    assert max(errors) < 3.0, errors
    assert window.ctx.undo_stack.count() == steps + 1
    w1 = pose_skeleton(doc, "arm", window.ctx.time).world_matrices()
    moved = w1[ELBOW, :3, :3] @ hit.offset + w1[ELBOW, :3, 3]
    assert _projected(view, moved)[1] > _projected(view, hit.point)[1] + 5
    np.testing.assert_allclose(w1[0], w0[0])


def test_with_the_skin_hidden_the_joint_pivot_is_dragged_as_before(arm_window, qtbot):
    from qtanimator.document.character3d import world_matrices

    window, view = arm_window
    view.options.show_skin = False
    elbow = world_matrices(window.doc, "arm", window.ctx.time)[ELBOW]
    px = _pixel(view, elbow[:3, :3] @ np.array([0.45, 0.0, 0.0]) + elbow[:3, 3])
    assert view.pick_surface(QPointF(px)) is None
    qtbot.mousePress(view, Qt.MouseButton.RightButton, pos=px)
    assert view._drag["mode"] == "ik" and view._drag["offset"] is None
    qtbot.mouseRelease(view, Qt.MouseButton.RightButton, pos=px)
