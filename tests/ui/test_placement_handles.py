"""Placement handles (issue 14): Alt+left-drag moves a character's placement, Alt+Shift+left-drag
scales it, in the 2D rig editor and the 3D view — real mouse events, one undo step each,
Escape takes the drag back."""

from __future__ import annotations

import math

import numpy as np
import pytest
from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtWidgets import QGraphicsView

from qtanimator.document import character2d as c2d
from qtanimator.document.placement import PLACEMENT, placement_of
from qtanimator.render.gl.camera import OrbitCamera
from qtanimator.ui import viewport
from qtanimator.ui.main_window import MainWindow
from qtanimator.ui.rig_interaction import SCALE_DOUBLING_PX, pick

ALT = Qt.KeyboardModifier.AltModifier
ALT_SHIFT = Qt.KeyboardModifier.AltModifier | Qt.KeyboardModifier.ShiftModifier
LEFT = Qt.MouseButton.LeftButton


# ------------------------------------------------------------------------------ 2D
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


def _on_character(window, view, asset) -> QPoint:
    """A whole pixel over the character's root shape."""
    pose = c2d.evaluate_pose(window.doc, asset, window.ctx.time)
    pts = window.doc.runtime[asset].joints[0].shapes[0].points
    centre = pts.mean(axis=0)
    for local in [centre] + [centre + 0.5 * (p - centre) for p in pts]:
        p = view.from_scene(pose.to_world(0, local))
        q = QPoint(int(round(p.x())), int(round(p.y())))
        if pick(window.doc, window.ctx.time, view.to_scene(QPointF(q))) is not None:
            return q
    raise AssertionError("no pixel over the character")


def _drag2d(qtbot, view, mods, start: QPoint, points: list[QPoint], release: bool = True) -> None:
    vp = view.viewport()
    qtbot.mousePress(vp, LEFT, mods, start)
    for p in points:
        qtbot.mouseMove(vp, p)  # pytest-qt moves carry no buttons: the editor tracks its drag button
    if release:
        qtbot.mouseRelease(vp, LEFT, mods, points[-1])


def test_alt_drag_moves_the_2d_placement_in_one_undo_step(qtbot, arm):
    window, view, asset = arm
    doc = window.doc
    before = doc.state()
    window.ctx.select(asset, "")
    start = _on_character(window, view, asset)
    end = start + QPoint(50, -20)
    _drag2d(qtbot, view, ALT, start, [start + QPoint(20, -5), end])
    moved = view.to_scene(QPointF(end)) - view.to_scene(QPointF(start))
    scale = abs(view.viewportTransform().m11())
    np.testing.assert_allclose(moved, np.array([50.0, -20.0]) / scale, rtol=1e-9)  # closed form
    np.testing.assert_allclose(placement_of(doc, asset, 2)["translate"], moved, atol=1e-9)
    assert c2d.translation(doc, asset, 0.0).tolist() == [0.0, 0.0]  # no position key: the placement moved
    assert window.ctx.selection == (asset, "")
    assert window.ctx.undo_stack.count() == 1
    window.ctx.undo_stack.undo()
    assert doc.state() == before
    assert PLACEMENT not in doc.assets[asset].properties


def test_alt_shift_drag_scales_the_2d_placement_about_its_pivot(qtbot, arm):
    window, view, asset = arm
    doc = window.doc
    before = doc.state()
    pivot = doc.runtime[asset].rest_pivots[0].copy()
    start = _on_character(window, view, asset)
    _drag2d(qtbot, view, ALT_SHIFT, start, [start + QPoint(30, 7), start + QPoint(60, 13)])
    p = placement_of(doc, asset, 2)
    assert p["scale"] == pytest.approx(2.0 ** (60 / SCALE_DOUBLING_PX), rel=1e-6)
    assert p["translate"] == [0.0, 0.0]
    # the pivot stays where it was, the character grew about it
    pose = c2d.evaluate_pose(doc, asset, 0.0)
    np.testing.assert_allclose(pose.pivots[0], pivot, atol=1e-9)
    assert window.ctx.undo_stack.count() == 1
    window.ctx.undo_stack.undo()
    assert doc.state() == before
    # dragging left shrinks, never through zero
    _drag2d(qtbot, view, ALT_SHIFT, start, [start + QPoint(-400, 0)])
    assert 0.0 < placement_of(doc, asset, 2)["scale"] == pytest.approx(2.0 ** -4, rel=1e-6)


def test_escape_aborts_a_2d_placement_drag(qtbot, arm):
    window, view, asset = arm
    before = window.doc.state()
    start = _on_character(window, view, asset)
    _drag2d(qtbot, view, ALT, start, [start + QPoint(40, 30)], release=False)
    assert window.doc.state() != before  # previewed live
    qtbot.keyClick(view, Qt.Key.Key_Escape)
    assert window.doc.state() == before
    qtbot.mouseRelease(view.viewport(), LEFT, ALT, start + QPoint(40, 30))
    assert window.doc.state() == before
    assert window.ctx.undo_stack.count() == 0 and not window.ctx.undo_stack.canRedo()


def test_plain_left_drag_on_the_root_still_keys_position_not_placement(qtbot, arm):
    window, view, asset = arm
    start = _on_character(window, view, asset)
    _drag2d(qtbot, view, Qt.KeyboardModifier.NoModifier, start, [start + QPoint(30, 0)])
    assert PLACEMENT not in window.doc.assets[asset].properties


# ------------------------------------------------------------------------------ 3D
@pytest.fixture
def window3d(qtbot, shared_data):
    from qtanimator.document.character3d import add_character3d_command

    w = MainWindow(install_editors=False)
    viewport.install(w)
    qtbot.addWidget(w)
    w.resize(420, 360)
    w.show()
    qtbot.waitExposed(w)
    d = shared_data / "mit6837"
    w.ctx.push(add_character3d_command(w.doc, d / "Model1.skel", obj_path=d / "Model1.obj",
                                       attach_path=d / "Model1.attach", asset_id="mit"))
    view = w.viewport3d
    view.camera = OrbitCamera(azimuth=0.0, inclination=0.0, distance=1.6, target=np.array([0.5, 0.5, 0.5]))
    view._framed_once = True
    view.options.show_skin = False  # pick the root joint's sphere
    view.render_image()
    view.setFocus()
    w.ctx.undo_stack.clear()
    return w, view


def _root(window):
    from qtanimator.document.character3d import pose_skeleton

    return pose_skeleton(window.doc, "mit", window.ctx.time).world_matrices()[0, :3, 3].copy()


def _root_pixel(view, root) -> QPoint:
    px = view.camera.project(root, view.width(), view.height())[0]
    return QPoint(int(round(px[0])), int(round(px[1])))


def _world_per_pixel(view, point) -> float:
    """Scene units per pixel on the plane through ``point`` facing the camera (closed form)."""
    cam = view.camera
    forward = np.asarray(cam.target, dtype=float) - cam.eye()
    depth = float((np.asarray(point) - cam.eye()) @ (forward / np.linalg.norm(forward)))
    return 2.0 * depth * math.tan(math.radians(cam.fov_y) / 2.0) / view.height()


@pytest.mark.gl
def test_alt_drag_moves_the_3d_placement_in_the_view_plane(window3d, qtbot):
    window, view = window3d
    doc = window.doc
    before = doc.state()
    root = _root(window)
    a = _root_pixel(view, root)
    assert view.pick(QPointF(a)) is not None
    qtbot.mousePress(view, LEFT, ALT, a)
    for k in range(1, 4):
        qtbot.mouseMove(view, a + QPoint(10 * k, -5 * k))
    qtbot.mouseRelease(view, LEFT, ALT, a + QPoint(30, -15))
    wpp = _world_per_pixel(view, root)
    v = view.camera.view()
    expected = wpp * (30 * v[0, :3] + 15 * v[1, :3])  # right 30 px, up 15 px
    t = np.asarray(placement_of(doc, "mit", 3)["translate"])
    np.testing.assert_allclose(t, expected, atol=1e-6)
    np.testing.assert_allclose(_root(window), root + expected, atol=1e-6)
    assert window.ctx.selection == ("mit", "")
    assert window.ctx.undo_stack.count() == 1
    assert view.camera.azimuth == 0.0  # the Alt drag on a character does not orbit
    window.ctx.undo_stack.undo()
    assert doc.state() == before


@pytest.mark.gl
def test_alt_shift_drag_scales_the_3d_placement_about_the_root(window3d, qtbot):
    window, view = window3d
    doc = window.doc
    before = doc.state()
    root = _root(window)
    a = _root_pixel(view, root)
    qtbot.mousePress(view, LEFT, ALT_SHIFT, a)
    qtbot.mouseMove(view, a + QPoint(25, 3))
    qtbot.mouseMove(view, a + QPoint(-50, 3))
    qtbot.mouseRelease(view, LEFT, ALT_SHIFT, a + QPoint(-50, 3))
    assert placement_of(doc, "mit", 3)["scale"] == pytest.approx(2.0 ** (-50 / SCALE_DOUBLING_PX), rel=1e-9)
    np.testing.assert_allclose(_root(window), root, atol=1e-9)  # scaled about the root
    assert window.ctx.undo_stack.count() == 1
    window.ctx.undo_stack.undo()
    assert doc.state() == before


@pytest.mark.gl
def test_escape_aborts_a_3d_placement_drag(window3d, qtbot):
    window, view = window3d
    before = window.doc.state()
    a = _root_pixel(view, _root(window))
    qtbot.mousePress(view, LEFT, ALT, a)
    qtbot.mouseMove(view, a + QPoint(20, 0))
    assert window.doc.state() != before
    qtbot.keyClick(view, Qt.Key.Key_Escape)
    qtbot.mouseRelease(view, LEFT, ALT, a + QPoint(20, 0))
    assert window.doc.state() == before
    assert window.ctx.undo_stack.count() == 0 and not window.ctx.undo_stack.canRedo()


@pytest.mark.gl
def test_alt_drag_off_a_character_still_orbits(window3d, qtbot):
    window, view = window3d
    qtbot.mousePress(view, LEFT, ALT, QPoint(5, 5))
    qtbot.mouseMove(view, QPoint(45, 5))
    qtbot.mouseRelease(view, LEFT, ALT, QPoint(45, 5))
    assert view.camera.azimuth != 0.0
    assert window.ctx.undo_stack.count() == 0
