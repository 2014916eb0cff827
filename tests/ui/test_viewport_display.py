"""The reference viewers' display keys and camera fields in the 3D view (issue 18), and the
floor shadow: real key presses, clicks and mouse drags, checked on the rendered pixels."""

from __future__ import annotations

import json

import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt
from PySide6.QtGui import QAction
from PySide6.QtWidgets import QDoubleSpinBox

from qtanimator.render.gl.camera import OrbitCamera
from qtanimator.render.gl.renderer import key_light, shadow_matrix
from qtanimator.ui import viewport
from qtanimator.ui.main_window import MainWindow

pytestmark = pytest.mark.gl


@pytest.fixture
def window(qtbot):
    w = MainWindow(install_editors=False)
    viewport.install(w)
    qtbot.addWidget(w)
    w.resize(480, 400)
    w.show()
    qtbot.waitExposed(w)
    return w


def _add_mit(window, shared_data):
    from qtanimator.document.character3d import add_character3d_command

    d = shared_data / "mit6837"
    window.ctx.push(add_character3d_command(window.doc, d / "Model1.skel", obj_path=d / "Model1.obj",
                                            attach_path=d / "Model1.attach", asset_id="mit"))


def _camera(view, **kw):
    args = {"azimuth": 0.0, "inclination": 0.0, "distance": 1.6, "target": np.array([0.5, 0.5, 0.5]), **kw}
    view.camera = OrbitCamera(**args)
    view._framed_once = True


def _changed(a, b, level=30):
    return np.any(np.abs(a.astype(int) - b.astype(int)) > level, axis=2)


# ------------------------------------------------------------------ X: axes, B: skeleton
def test_x_shows_the_axes_at_the_origin_and_at_every_joint(window, qtbot, shared_data):
    _add_mit(window, shared_data)
    view = window.viewport3d
    _camera(view)
    view.setFocus()
    before = view.render_image()
    action = window.findChild(QAction, "actionShowAxes3d")
    assert not action.isChecked()
    qtbot.keyClick(view, Qt.Key.Key_X)
    assert view.options.show_axes and action.isChecked()
    after = view.render_image()
    changed = _changed(before, after)
    assert changed.sum() > 100
    rgb = after[..., :3].astype(int)
    for channel in range(3):   # strong red, green and blue where the picture changed
        others = [c for c in range(3) if c != channel]
        pure = (rgb[..., channel] > 150) & (rgb[..., others].max(axis=2) < rgb[..., channel] - 60) & changed
        assert pure.sum() > 10, f"no axis in colour {channel}"
    # the axes are drawn over the skin, at the joints: around the projected joint centres
    from qtanimator.document.character3d import pose_skeleton

    joints = pose_skeleton(window.doc, "mit", 0.0).world_matrices()[:, :3, 3]
    px = view.camera.project(joints, after.shape[1], after.shape[0])
    near = sum(bool(changed[max(int(y) - 4, 0):int(y) + 5, max(int(x) - 4, 0):int(x) + 5].any()) for x, y, _z in px)
    assert near >= len(joints) - 2
    qtbot.keyClick(view, Qt.Key.Key_X)
    assert not view.options.show_axes and not action.isChecked()
    np.testing.assert_array_equal(view.render_image(), before)
    # the View menu's toggle does the same
    action.trigger()
    assert view.options.show_axes


def test_b_toggles_the_skeleton_and_s_still_sets_a_key(window, qtbot, shared_data):
    _add_mit(window, shared_data)
    panel = window.viewport_panel
    view = panel.view
    _camera(view)
    view.setFocus()
    action = window.findChild(QAction, "actionShowSkeleton3d")
    assert panel.show_mode.currentIndex() == 0 and action.isChecked()
    both = view.render_image()
    qtbot.keyClick(view, Qt.Key.Key_B)
    assert (view.options.show_skin, view.options.show_skeleton) == (True, False)
    assert panel.show_mode.currentIndex() == 1 and not action.isChecked()
    skin_only = view.render_image()
    assert _changed(both, skin_only).sum() > 50
    qtbot.keyClick(view, Qt.Key.Key_B)
    assert panel.show_mode.currentIndex() == 0 and action.isChecked()
    np.testing.assert_array_equal(view.render_image(), both)
    # from "Skeleton only", hiding the skeleton shows the skin (the MIT viewer's s)
    panel.show_mode.setCurrentIndex(2)
    assert not view.options.show_skin and action.isChecked()
    qtbot.keyClick(view, Qt.Key.Key_B)
    assert panel.show_mode.currentIndex() == 1
    # S is still Set Key with a joint selected (issue 13), not the skeleton
    window.ctx.set_frame(5.0)
    window.ctx.select("mit", view.ctx.doc.runtime["mit"].skeleton.joint_keys()[3])
    count = window.ctx.undo_stack.count()
    qtbot.keyClick(view, Qt.Key.Key_S)
    assert window.ctx.undo_stack.count() == count + 1
    assert panel.show_mode.currentIndex() == 1


# ------------------------------------------------------------------ camera fields
def _fields(window):
    dialog = window.camera_dialog
    return (dialog.findChild(QDoubleSpinBox, "cameraDistance"), dialog.findChild(QDoubleSpinBox, "cameraAzimuth"),
            dialog.findChild(QDoubleSpinBox, "cameraInclination"))


def _assert_fields_show(window, camera):
    distance, azimuth, inclination = _fields(window)
    assert distance.value() == pytest.approx(camera.distance, abs=1e-3)
    assert azimuth.value() == pytest.approx(camera.azimuth % 360.0, abs=0.05)
    assert inclination.value() == pytest.approx(camera.inclination, abs=0.05)


def test_camera_fields_follow_the_mouse_and_move_the_camera(window, qtbot, shared_data, tmp_path):
    _add_mit(window, shared_data)
    view = window.viewport3d
    _camera(view, azimuth=10.0, inclination=5.0, distance=2.0)
    window.findChild(QAction, "actionCamera3d").trigger()
    dialog = window.camera_dialog
    assert dialog.isVisible() and dialog.objectName() == "cameraDialog"
    _assert_fields_show(window, view.camera)
    # mouse → fields: orbit, then zoom with the wheel
    qtbot.mousePress(view, Qt.MouseButton.LeftButton, pos=QPoint(100, 100))
    qtbot.mouseMove(view, QPoint(140, 120))
    qtbot.mouseMove(view, QPoint(190, 150))
    qtbot.mouseRelease(view, Qt.MouseButton.LeftButton, pos=QPoint(190, 150))
    assert view.camera.azimuth != pytest.approx(10.0) and view.camera.inclination != pytest.approx(5.0)
    _assert_fields_show(window, view.camera)
    qtbot.mousePress(view, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.ControlModifier, QPoint(100, 100))
    qtbot.mouseMove(view, QPoint(100, 140))
    qtbot.mouseRelease(view, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.ControlModifier, QPoint(100, 140))
    _assert_fields_show(window, view.camera)
    view.frame_all()
    _assert_fields_show(window, view.camera)

    # fields → camera: typed values, an arrow key
    window.ctx.undo_stack.setClean()
    count = window.ctx.undo_stack.count()
    before = view.render_image()
    distance, azimuth, inclination = _fields(window)
    for box, text in ((azimuth, "123.5"), (inclination, "-30"), (distance, "2.5")):
        box.setFocus()
        box.lineEdit().selectAll()
        qtbot.keyClicks(box.lineEdit(), text)
        qtbot.keyClick(box.lineEdit(), Qt.Key.Key_Return)
    assert (view.camera.azimuth, view.camera.inclination, view.camera.distance) == (123.5, -30.0, 2.5)
    after = view.render_image()
    assert _changed(before, after).mean() > 0.01
    qtbot.keyClick(inclination.lineEdit(), Qt.Key.Key_Up)
    assert view.camera.inclination == pytest.approx(-25.0)
    # azimuth wraps round: 360° is 0°
    view.set_camera(azimuth=365.0)
    assert view.camera.azimuth == pytest.approx(5.0) and azimuth.value() == pytest.approx(5.0)
    # view state: no undo step, not modified, saved with the project
    assert window.ctx.undo_stack.count() == count and window.ctx.undo_stack.isClean() and not window.is_modified()
    path = tmp_path / "camera.qtanim"
    assert window.save_to(path)
    saved = json.loads(path.read_text())["view"]["view3d.camera"]
    assert (saved["azimuth"], saved["inclination"], saved["distance"]) == pytest.approx((5.0, -25.0, 2.5))


# ------------------------------------------------------------------ floor shadow
def test_shadow_matrix_puts_points_on_the_floor_along_the_light_ray():
    light = np.array([1.0, 5.0, -2.0])
    m = shadow_matrix(light)
    for p in ([0.3, 1.0, 0.2], [-2.0, 3.5, 1.0], [0.0, 0.0, 0.0]):
        h = m @ np.append(p, 1.0)
        q = h[:3] / h[3]
        assert q[1] == pytest.approx(0.0, abs=1e-12)
        d1, d2 = np.asarray(p) - light, q - light
        np.testing.assert_allclose(np.cross(d1, d2), 0.0, atol=1e-9)   # on the ray from the light
    q = shadow_matrix(light, floor=0.5) @ np.array([0.0, 1.0, 0.0, 1.0])
    assert q[1] / q[3] == pytest.approx(0.5)


def test_the_key_light_is_the_brightest():
    from qtanimator.render.gl.lights import DEFAULTS, lights_of

    lights = lights_of(dict(DEFAULTS))
    assert key_light(lights) is lights[0]
    brighter = dict(DEFAULTS, **{"light2.intensity": 2.0})
    lights = lights_of(brighter)
    assert key_light(lights) is lights[1]
    assert key_light([]) is None


def _shadow_pixels(view, panel, qtbot):
    """Pixels the Shadow toggle darkens (clicked off, on, off again with the real check box)."""
    assert not panel.shadow.isChecked()
    off = view.render_image()
    qtbot.mouseClick(panel.shadow, Qt.MouseButton.LeftButton)
    assert panel.shadow.isChecked() and view.options.show_shadow
    on = view.render_image()
    qtbot.mouseClick(panel.shadow, Qt.MouseButton.LeftButton)
    assert not view.options.show_shadow
    diff = on[..., :3].astype(int) - off[..., :3].astype(int)
    assert (diff > 3).sum() == 0, "the shadow only darkens"
    return np.all(diff < -8, axis=2)


def _expected_shadow(view, window, image_shape):
    """Screen positions of the joints flattened onto the floor from the key light."""
    from qtanimator.document.character3d import pose_skeleton
    from qtanimator.render.gl.lights import lights_of

    light = key_light(lights_of(window.doc))
    joints = pose_skeleton(window.doc, "mit", window.ctx.time).world_matrices()[:, :3, 3]
    h = np.c_[joints, np.ones(len(joints))] @ shadow_matrix(light.position).T
    floor = h[:, :3] / h[:, 3:]
    return view.camera.project(floor, image_shape[1], image_shape[0])[:, :2]


def test_floor_shadow_darkens_the_floor_below_the_character_and_follows_the_light(window, qtbot, shared_data):
    from qtanimator.document.commands import SetParameter

    _add_mit(window, shared_data)
    panel = window.viewport_panel
    view = panel.view
    _camera(view, azimuth=20.0, inclination=40.0, distance=3.2, target=np.array([0.2, 0.2, 0.2]))
    view.options.show_lights = False
    dark = _shadow_pixels(view, panel, qtbot)
    assert dark.sum() > 300
    ys, xs = np.nonzero(dark)
    expected = _expected_shadow(view, window, dark.shape)
    # the darkened region covers where the joints' shadows fall, below the character's feet
    inside = [dark[max(int(y) - 3, 0):int(y) + 4, max(int(x) - 3, 0):int(x) + 4].any() for x, y in expected]
    assert np.mean(inside) > 0.8
    centre = np.array([xs.mean(), ys.mean()])
    assert np.linalg.norm(centre - expected.mean(axis=0)) < 25

    # Moving the key light (one undoable edit) moves the shadow the same way.
    window.ctx.push(SetParameter(window.doc, "light1.position", [-4.0, 6.0, 3.0]))
    dark2 = _shadow_pixels(view, panel, qtbot)
    ys2, xs2 = np.nonzero(dark2)
    centre2 = np.array([xs2.mean(), ys2.mean()])
    expected2 = _expected_shadow(view, window, dark2.shape)
    moved = expected2.mean(axis=0) - expected.mean(axis=0)
    assert np.linalg.norm(moved) > 20
    assert np.dot(centre2 - centre, moved) / np.linalg.norm(moved) > 0.6 * np.linalg.norm(moved)
    assert np.linalg.norm(centre2 - expected2.mean(axis=0)) < 25
    # A light under the floor casts nothing.
    window.ctx.push(SetParameter(window.doc, "light1.position", [0.0, -2.0, 0.0]))
    window.ctx.push(SetParameter(window.doc, "light2.position", [0.0, -3.0, 0.0]))
    assert _shadow_pixels(view, panel, qtbot).sum() == 0


def test_the_skeleton_casts_the_shadow_when_the_skin_is_hidden(window, qtbot, shared_data):
    _add_mit(window, shared_data)
    panel = window.viewport_panel
    view = panel.view
    _camera(view, azimuth=20.0, inclination=40.0, distance=3.2, target=np.array([0.2, 0.2, 0.2]))
    view.options.show_lights = False
    skin = _shadow_pixels(view, panel, qtbot)
    panel.show_mode.setCurrentIndex(2)    # skeleton only
    bones = _shadow_pixels(view, panel, qtbot)
    assert bones.sum() > 50
    assert bones.sum() < skin.sum()       # thin bones: a thinner shadow than the body's


def test_the_shadow_toggle_is_in_the_view_menu_too(window, qtbot):
    panel = window.viewport_panel
    action = window.findChild(QAction, "actionFloorShadow3d")
    action.trigger()
    assert panel.view.options.show_shadow and panel.shadow.isChecked()
    qtbot.mouseClick(panel.shadow, Qt.MouseButton.LeftButton)
    assert not panel.view.options.show_shadow and not action.isChecked()
