"""The 3D viewport widget: real GL under the private Xvfb, real mouse and key events."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt
from PySide6.QtWidgets import QTabWidget, QWidget

from qtanimator.render.gl.camera import OrbitCamera
from qtanimator.ui import viewport
from qtanimator.ui.main_window import MainWindow

pytestmark = pytest.mark.gl


@pytest.fixture
def window(qtbot):
    w = MainWindow(install_editors=False)
    viewport.install(w)
    qtbot.addWidget(w)
    w.resize(420, 360)
    w.show()
    qtbot.waitExposed(w)
    return w


def _add_mit(window, shared_data, model="Model1"):
    from qtanimator.document.character3d import add_character3d_command

    d = shared_data / "mit6837"
    window.ctx.push(add_character3d_command(window.doc, d / f"{model}.skel", obj_path=d / f"{model}.obj",
                                            attach_path=d / f"{model}.attach", asset_id="mit"))


def _front_camera(view):
    view.camera = OrbitCamera(azimuth=0.0, inclination=0.0, distance=1.6, target=np.array([0.5, 0.5, 0.5]))
    view._framed_once = True


def test_install_adds_a_3d_tab_with_the_gl_view(window, qtbot):
    tabs = window.findChild(QTabWidget, "centralTabs")
    titles = [tabs.tabText(i) for i in range(tabs.count())]
    assert "3D" in titles
    view = window.findChild(QWidget, "viewport3d")
    assert view is window.viewport3d
    fmt = view.format()
    assert (fmt.majorVersion(), fmt.minorVersion()) >= (3, 3) and fmt.depthBufferSize() >= 24
    img = view.render_image()
    assert img.shape[0] > 50 and img.shape[1] > 50
    # the ground grid draws lines over the background
    assert len(np.unique(img.reshape(-1, 4)[:, :3], axis=0)) > 5
    assert "Core" in view.gl_info or "core" in view.gl_info.lower() or view.gl_info


def test_orbit_pan_zoom_with_the_mouse(window, qtbot):
    view = window.viewport3d
    cam = view.camera
    az, inc, dist = cam.azimuth, cam.inclination, cam.distance
    qtbot.mousePress(view, Qt.MouseButton.LeftButton, pos=QPoint(100, 100))
    qtbot.mouseMove(view, QPoint(140, 120))
    qtbot.mouseMove(view, QPoint(180, 140))
    qtbot.mouseRelease(view, Qt.MouseButton.LeftButton, pos=QPoint(180, 140))
    assert cam.azimuth != az and cam.inclination != inc
    target = np.array(cam.target, dtype=float)
    qtbot.mousePress(view, Qt.MouseButton.MiddleButton, pos=QPoint(100, 100))
    qtbot.mouseMove(view, QPoint(150, 100))
    qtbot.mouseRelease(view, Qt.MouseButton.MiddleButton, pos=QPoint(150, 100))
    assert np.linalg.norm(np.array(cam.target) - target) > 1e-3
    from PySide6.QtCore import QPointF
    from PySide6.QtGui import QWheelEvent

    ev = QWheelEvent(QPointF(100, 100), QPointF(view.mapToGlobal(QPoint(100, 100))), QPoint(0, 0), QPoint(0, 240),
                     Qt.MouseButton.NoButton, Qt.KeyboardModifier.NoModifier, Qt.ScrollPhase.NoScrollPhase, False)
    view.wheelEvent(ev)
    assert cam.distance < dist


def test_clicking_a_joint_selects_it(window, qtbot, shared_data):
    _add_mit(window, shared_data)
    view = window.viewport3d
    view.options.show_skin = False
    _front_camera(view)
    from qtanimator.document.character3d import pose_skeleton

    skel = pose_skeleton(window.doc, "mit", window.ctx.time)
    pos = skel.world_matrices()[:, :3, 3]
    keys = skel.joint_keys()
    w, h = view.width(), view.height()
    for joint in (7, 11, 14, 17):   # feet and elbows: nothing in front of them from the front
        px = view.camera.project(pos[joint], w, h)[0]
        qtbot.mouseClick(view, Qt.MouseButton.LeftButton, pos=QPoint(int(round(px[0])), int(round(px[1]))))
        assert window.ctx.selection == ("mit", keys[joint])
    qtbot.mouseClick(view, Qt.MouseButton.LeftButton, pos=QPoint(3, 3))
    assert window.ctx.selection == ("", "")


def test_selected_joint_is_highlighted(window, qtbot, shared_data):
    _add_mit(window, shared_data)
    view = window.viewport3d
    view.options.show_skin = False
    view.options.show_grid = False
    _front_camera(view)
    before = view.render_image()
    from qtanimator.document.character3d import pose_skeleton

    skel = pose_skeleton(window.doc, "mit", 0.0)
    window.ctx.select("mit", skel.joint_keys()[14])
    after = view.render_image().astype(int)
    changed = np.any(np.abs(after - before.astype(int)) > 30, axis=2)
    assert changed.sum() > 5
    # the highlight is orange: red well above blue where it changed
    assert (after[changed][:, 0] - after[changed][:, 2]).mean() > 60


def test_right_drag_ik_moves_the_joint_and_is_one_undo_step_keyed_now(window, qtbot, shared_data):
    _add_mit(window, shared_data)
    view = window.viewport3d
    view.options.show_skin = False
    _front_camera(view)
    window.ctx.set_frame(12)
    from qtanimator.document.character3d import pose_skeleton

    joint = 14  # right elbow: chain = shoulder, collarbone
    p0 = pose_skeleton(window.doc, "mit", window.ctx.time).world_matrices()[joint, :3, 3]
    w, h = view.width(), view.height()
    start = view.camera.project(p0, w, h)[0]
    a = QPoint(int(round(start[0])), int(round(start[1])))
    b = a + QPoint(0, -40)
    steps = window.ctx.undo_stack.count()
    qtbot.mousePress(view, Qt.MouseButton.RightButton, pos=a)
    for k in range(1, 5):
        qtbot.mouseMove(view, a + QPoint(0, -10 * k))
    qtbot.mouseRelease(view, Qt.MouseButton.RightButton, pos=b)
    assert window.ctx.undo_stack.count() == steps + 1
    skel = pose_skeleton(window.doc, "mit", window.ctx.time)
    p1 = skel.world_matrices()[joint, :3, 3]
    moved = view.camera.project(p1, w, h)[0]
    assert moved[1] < start[1] - 15            # the elbow went up the screen, towards the mouse
    keyed = [cid for cid in window.doc.channels if cid.startswith("mit/")]
    assert keyed and all(any(abs(k.time - window.ctx.time) < 1e-9 for k in window.doc.channels[c].keys)
                         for c in keyed)
    window.ctx.undo_stack.undo()
    p2 = pose_skeleton(window.doc, "mit", window.ctx.time).world_matrices()[joint, :3, 3]
    np.testing.assert_allclose(p2, p0, atol=1e-9)


def test_display_modes_change_the_picture(window, qtbot, shared_data):
    _add_mit(window, shared_data)
    panel = window.viewport_panel
    view = panel.view
    _front_camera(view)
    both = view.render_image().astype(int)
    panel.show_mode.setCurrentIndex(2)        # skeleton only
    skel_only = view.render_image().astype(int)
    panel.show_mode.setCurrentIndex(1)        # skin only
    panel.weights.setCurrentIndex(1)          # all weights pseudo-colour
    weights = view.render_image().astype(int)
    panel.weights.setCurrentIndex(0)
    panel.wireframe.setChecked(True)
    wire = view.render_image().astype(int)
    for a, b in ((both, skel_only), (both, weights), (both, wire)):
        assert np.mean(np.any(np.abs(a - b) > 20, axis=2)) > 0.01
    # the pseudo-colour is colourful: strong saturation somewhere
    sat = weights[..., :3].max(axis=2) - weights[..., :3].min(axis=2)
    assert (sat > 100).sum() > 50


def test_cloth_keys_move_the_pins_of_the_live_cloth(window, qtbot):
    from qtanimator.core.cloth import ClothParams
    from qtanimator.document.cloth import add_cloth_command

    window.ctx.push(add_cloth_command(window.doc, ClothParams(rows=8, cols=8)))
    view = window.viewport3d
    view.setFocus()
    view.set_live_cloth(True)
    view.live.paused = True
    assert view.live.settle()   # paused: the live thread steps no more, edits apply at once
    cloth = view.live.cloths["cloth"]
    before = cloth.pin_targets.copy()
    qtbot.keyClick(view, Qt.Key.Key_D)
    qtbot.keyClick(view, Qt.Key.Key_D)
    qtbot.keyClick(view, Qt.Key.Key_Q)
    qtbot.keyClick(view, Qt.Key.Key_W)   # CSE169: W up (y), Q in (−z)
    moved = [2 * viewport.PIN_STEP, viewport.PIN_STEP, -viewport.PIN_STEP]
    np.testing.assert_allclose(cloth.pin_targets - before, np.tile(moved, (len(before), 1)), atol=1e-12)
    qtbot.keyClick(view, Qt.Key.Key_Z)
    centre = cloth.pin_targets.mean(axis=0)
    assert not np.allclose(cloth.pin_targets, before + moved)
    np.testing.assert_allclose(centre, before.mean(axis=0) + moved, atol=1e-9)
    view.live.step(1 / 60)      # one step now, on this thread
    np.testing.assert_allclose(cloth.positions[cloth.pinned], cloth.pin_targets, atol=1e-9)
    qtbot.keyClick(view, Qt.Key.Key_R, Qt.KeyboardModifier.ShiftModifier)   # Shift+R resets the cloth
    np.testing.assert_allclose(cloth.pin_targets, before)
    view.set_live_cloth(False)


def test_mouse_grab_drags_the_live_cloth(window, qtbot):
    from qtanimator.core.cloth import ClothParams
    from qtanimator.document.cloth import add_cloth_command

    window.ctx.push(add_cloth_command(window.doc, ClothParams(rows=8, cols=8, origin=(0.0, 1.5, 0.0))))
    view = window.viewport3d
    view.camera = OrbitCamera(azimuth=0.0, inclination=0.0, distance=3.0, target=np.array([0.0, 1.0, 0.0]))
    view._framed_once = True
    view.set_live_cloth(True)
    view.live.paused = True
    assert view.live.settle()
    cloth = view.live.cloths["cloth"]
    w, h = view.width(), view.height()
    corner = view.live.frame("cloth").positions[-1].copy()   # bottom right, not pinned
    np.testing.assert_array_equal(corner, cloth.positions[-1])
    px = view.camera.project(corner, w, h)[0]
    a = QPoint(int(round(px[0])), int(round(px[1])))
    qtbot.mousePress(view, Qt.MouseButton.LeftButton, pos=a)
    assert cloth.grabbed is not None
    qtbot.mouseMove(view, a + QPoint(30, 0))
    view.live.step(1 / 60)
    assert cloth.positions[cloth.grabbed][0] > corner[0] + 0.05
    qtbot.mouseRelease(view, Qt.MouseButton.LeftButton, pos=a + QPoint(30, 0))
    assert cloth.grabbed is None
    view.set_live_cloth(False)


def test_clip_controls_play_modes_drive_the_frame(window, qtbot):
    controls = window.viewport_panel.controls
    doc = window.doc
    start, end = controls.clip_range()
    window.ctx.set_frame(0)
    controls.mode.setCurrentText("loop")
    controls.set_playing(True)
    assert controls.playing
    controls.step(1.0)
    assert window.ctx.frame == pytest.approx(doc.time_to_frame(start + 1.0))
    assert controls.progress.value() == pytest.approx(1000 * 1.0 / (end - start), abs=1)
    controls.step(end - start)                      # wraps around
    assert window.ctx.frame == pytest.approx(doc.time_to_frame(start + 1.0), abs=1e-6)
    controls.speed.setValue(2.0)
    controls.step(0.5)
    assert window.ctx.frame == pytest.approx(doc.time_to_frame(start + 2.0), abs=1e-6)
    controls.set_playing(False)
    controls.mode.setCurrentText("once")
    controls.set_playing(True)
    controls.step(10 * (end - start))
    assert window.ctx.frame == pytest.approx(doc.time_to_frame(end))
    assert not controls.playing and controls.progress.value() == 1000
    controls.mode.setCurrentText("ping-pong")
    window.ctx.set_frame(0)
    controls.speed.setValue(1.0)
    controls.set_playing(True)
    controls.step((end - start) + 1.0)
    assert window.ctx.frame == pytest.approx(doc.time_to_frame(end - 1.0), abs=1e-6)
    controls.set_playing(False)
    controls.mode.setCurrentText("continue")
    window.ctx.set_frame(doc.time_to_frame(end))
    controls.set_playing(True)
    controls.step(1.0)
    assert window.ctx.frame == pytest.approx(doc.time_to_frame(end + 1.0), abs=1e-6)
    controls.set_playing(False)


def test_dragging_a_light_gizmo_moves_the_light_in_one_undo_step(window, qtbot):
    view = window.viewport3d
    view.camera = OrbitCamera(azimuth=0.0, inclination=0.0, distance=14.0, target=np.array([0.0, 3.0, 0.0]))
    view._framed_once = True
    view.render_image()
    from qtanimator.render.gl.lights import lights_of

    before = lights_of(window.doc)[0].position.copy()
    w, h = view.width(), view.height()
    px = view.camera.project(before, w, h)[0]
    a = QPoint(int(round(px[0])), int(round(px[1])))
    qtbot.mousePress(view, Qt.MouseButton.LeftButton, pos=a)
    for k in range(1, 4):
        qtbot.mouseMove(view, a + QPoint(-10 * k, 0))
    qtbot.mouseRelease(view, Qt.MouseButton.LeftButton, pos=a + QPoint(-30, 0))
    after = np.array(window.doc.parameters["light1.position"])
    assert after[0] < before[0] - 0.3 and abs(after[2] - before[2]) < 1e-6   # moved left in the view plane
    assert window.ctx.undo_stack.count() == 1
    window.ctx.undo_stack.undo()
    np.testing.assert_allclose(lights_of(window.doc)[0].position, before)


def test_f_frames_the_selection_and_escape_cancels_an_ik_drag(window, qtbot, shared_data):
    _add_mit(window, shared_data)
    view = window.viewport3d
    from qtanimator.document.character3d import pose_skeleton

    skel = pose_skeleton(window.doc, "mit", 0.0)
    window.ctx.select("mit", skel.joint_keys()[7])
    view.setFocus()
    qtbot.keyClick(view, Qt.Key.Key_F)
    np.testing.assert_allclose(view.camera.target, skel.world_matrices()[7, :3, 3])
    _front_camera(view)
    view.options.show_skin = False
    p0 = skel.world_matrices()[14, :3, 3]
    px = view.camera.project(p0, view.width(), view.height())[0]
    a = QPoint(int(round(px[0])), int(round(px[1])))
    steps = window.ctx.undo_stack.count()
    qtbot.mousePress(view, Qt.MouseButton.RightButton, pos=a)
    qtbot.mouseMove(view, a + QPoint(0, -20))
    # the drag previews on the document (a gesture); the undo step comes at release
    moved = pose_skeleton(window.doc, "mit", 0.0).world_matrices()[14, :3, 3]
    assert np.linalg.norm(moved - p0) > 1e-3
    assert window.ctx.undo_stack.count() == steps
    qtbot.keyClick(view, Qt.Key.Key_Escape)
    qtbot.mouseRelease(view, Qt.MouseButton.RightButton, pos=a + QPoint(0, -20))
    np.testing.assert_allclose(pose_skeleton(window.doc, "mit", 0.0).world_matrices()[14, :3, 3], p0, atol=1e-9)
    # Escape leaves neither an undo step nor a redo step behind
    assert window.ctx.undo_stack.count() == steps and not window.ctx.undo_stack.canRedo()


def test_an_asset_that_cannot_be_drawn_is_reported_and_the_rest_still_draws(window, qtbot):
    from qtanimator.document.cloth import add_cloth_command
    from qtanimator.document.commands import AddAsset
    from qtanimator.document.document import Asset
    from qtanimator.render.gl.renderer import ClothDraw

    window.ctx.push(AddAsset(Asset("ghost", "character3d"), runtime=None))
    window.ctx.push(add_cloth_command(window.doc))
    view = window.viewport3d
    items = view.build_items()
    assert [type(i) for i in items] == [ClothDraw]
    assert "ghost" in view.last_error
    view.render_image()
    assert "ghost" in window.viewport_panel.status.text()


def test_clip_controls_announce_playing_and_yield_to_the_timeline(window, qtbot):
    controls = window.viewport_panel.controls
    seen = []
    window.ctx.playingChanged.connect(seen.append)
    controls.play_button.click()
    assert controls.playing and seen == [True]
    window.ctx.playingChanged.emit(True)        # another player (the timeline) starts
    assert not controls.playing and controls.play_button.text() == "Play"
    assert seen == [True, True]                 # stopping for it announced nothing


def test_live_cloth_runs_on_the_timer_at_a_fixed_step(window, qtbot):
    from qtanimator.core.cloth import ClothParams
    from qtanimator.document.cloth import add_cloth_command

    window.ctx.push(add_cloth_command(window.doc, ClothParams(rows=6, cols=6)))
    view = window.viewport3d
    view.set_live_cloth(True)
    cloth = view.live.cloths["cloth"]
    # The live thread steps it; the view draws the snapshots it publishes.
    qtbot.waitUntil(lambda: view.live.frame("cloth").time > 0.05, timeout=5000)
    view.live.paused = True
    assert view.live.settle()
    t = cloth.time
    steps = t / viewport.SIM_DT
    assert abs(steps - round(steps)) < 1e-6
    snapshot = view.live.frame("cloth")
    assert snapshot.time == t
    (item,) = view.build_items()
    np.testing.assert_array_equal(item.positions, snapshot.positions)
    qtbot.wait(100)
    assert cloth.time == t
    view.set_live_cloth(False)


def test_right_drag_on_a_joint_whose_only_ancestor_is_the_root_turns_the_root(window, qtbot):
    """The demo arm: shoulder (root) and elbow. Dragging the elbow must move it (the
    shoulder turns), as one undo step keyed at the current frame; a right-drag on the root
    itself zooms."""
    from qtanimator.document.character3d import add_character3d_command, pose_skeleton
    from qtanimator.paths import scenes_dir

    window.ctx.push(add_character3d_command(window.doc, scenes_dir() / "arm3d" / "arm.skel", asset_id="arm"))
    view = window.viewport3d
    view.options.show_skin = False
    view.camera = OrbitCamera(azimuth=0.0, inclination=0.0, distance=5.0, target=np.array([0.8, 1.4, 0.0]))
    view._framed_once = True
    window.ctx.set_frame(20)
    elbow = pose_skeleton(window.doc, "arm", window.ctx.time).world_matrices()[1]
    p0 = elbow[:3, 3].copy()
    w, h = view.width(), view.height()
    start = view.camera.project(p0, w, h)[0]
    forearm = view.camera.project((elbow @ np.array([0.45, 0.0, 0.0, 1.0]))[:3], w, h)[0]
    a = QPoint(int(round(forearm[0])), int(round(forearm[1])))    # press on the forearm's box
    steps = window.ctx.undo_stack.count()
    qtbot.mousePress(view, Qt.MouseButton.RightButton, pos=a)
    assert window.ctx.selection == ("arm", "elbow")
    for k in range(1, 6):
        qtbot.mouseMove(view, a + QPoint(0, -8 * k))
    qtbot.mouseRelease(view, Qt.MouseButton.RightButton, pos=a + QPoint(0, -40))
    assert window.ctx.undo_stack.count() == steps + 1
    p1 = pose_skeleton(window.doc, "arm", window.ctx.time).world_matrices()[1, :3, 3]
    assert view.camera.project(p1, w, h)[0][1] < start[1] - 20      # the elbow went up the screen
    keyed = [c for c in window.doc.channels if c.startswith("arm/shoulder/")]
    assert keyed and all(any(abs(k.time - window.ctx.time) < 1e-9 for k in window.doc.channels[c].keys)
                         for c in keyed)
    window.ctx.undo_stack.undo()
    np.testing.assert_allclose(pose_skeleton(window.doc, "arm", window.ctx.time).world_matrices()[1, :3, 3], p0,
                               atol=1e-9)
    # the root cannot be dragged (nothing above it turns): a right-drag there zooms
    root = view.camera.project(pose_skeleton(window.doc, "arm", window.ctx.time).world_matrices()[0, :3, 3], w, h)[0]
    r = QPoint(int(round(root[0])), int(round(root[1])))
    distance = view.camera.distance
    qtbot.mousePress(view, Qt.MouseButton.RightButton, pos=r)
    qtbot.mouseMove(view, r + QPoint(0, 30))
    qtbot.mouseRelease(view, Qt.MouseButton.RightButton, pos=r + QPoint(0, 30))
    assert window.ctx.undo_stack.index() == steps and window.ctx.undo_stack.canRedo()
    assert view.camera.distance != distance


def test_status_text_does_not_resize_the_view(window, qtbot):
    """The frame-time label changes every frame while playing; the GL view keeps its size."""
    panel = window.viewport_panel
    qtbot.waitUntil(lambda: panel.status.text() != "")
    width = panel.view.width()
    for text in ("1.0 ms", "123.4 ms", "an asset could not be drawn: a long reason " * 3):
        panel.status.setText(text)
        qtbot.wait(20)
        assert panel.view.width() == width


def test_camera_is_saved_with_the_project_without_an_undo_step_and_restored(qtbot, tmp_path):
    from qtanimator.document.character3d import add_character3d_command
    from qtanimator.paths import scenes_dir
    from qtanimator.ui import import3d

    w = MainWindow(install_editors=("viewport", "import3d"))
    qtbot.addWidget(w)
    w.resize(420, 360)
    w.show()
    qtbot.waitExposed(w)
    view = w.viewport3d
    arm = scenes_dir() / "arm3d"
    w.ctx.push(add_character3d_command(w.doc, arm / "arm.skel", arm / "arm.skin", asset_id="arm"))
    w.ctx.undo_stack.setClean()
    view.render_image()  # the first paint frames the arm
    framed = view.camera_state()
    # Orbit, pan and zoom with the mouse: the view changes, the document does not.
    qtbot.mousePress(view, Qt.MouseButton.LeftButton, pos=QPoint(100, 100))
    qtbot.mouseMove(view, QPoint(140, 120))
    qtbot.mouseMove(view, QPoint(180, 150))
    qtbot.mouseRelease(view, Qt.MouseButton.LeftButton, pos=QPoint(180, 150))
    qtbot.mousePress(view, Qt.MouseButton.MiddleButton, pos=QPoint(100, 100))
    qtbot.mouseMove(view, QPoint(130, 90))
    qtbot.mouseRelease(view, Qt.MouseButton.MiddleButton, pos=QPoint(130, 90))
    moved = view.camera_state()
    assert moved != framed
    assert w.ctx.undo_stack.count() == 1 and w.ctx.undo_stack.isClean() and not w.is_modified()
    assert "view3d.camera" not in w.doc.view_state
    path = tmp_path / "cam.qtanim"
    assert w.save_to(path)
    assert w.ctx.undo_stack.count() == 1 and not w.is_modified()
    import json

    assert json.loads(path.read_text())["view"]["view3d.camera"] == moved
    # Opening the project restores the camera instead of framing the scene again.
    w.new_document()
    view.render_image()
    assert w.open_path(path)
    view.render_image()
    assert view.camera_state() == moved
    assert not w.is_modified()
    # A new 3D asset still frames itself.
    w.ctx.push(add_character3d_command(w.doc, arm / "arm.skel", arm / "arm.skin", asset_id="arm2"))
    import3d.show_character(w, "arm2")
    assert view.camera_state() != moved


def test_cloth_is_simulated_off_the_ui_thread_and_the_view_never_waits(window, qtbot):
    """A frame the cloth cache does not have yet: the view draws the newest cached one,
    asks the worker for the rest, and repaints when it is there."""
    from qtanimator.core.cloth import ClothParams
    from qtanimator.document.cloth import add_cloth_command, cloth_cache
    from qtanimator.document.cloth_worker import cloth_worker

    params = ClothParams(rows=10, cols=10, wind=(0.0, 0.0, 2.0))
    window.ctx.push(add_cloth_command(window.doc, params))
    view = window.viewport3d
    worker = cloth_worker(window.doc)
    assert view.cloth_worker is worker
    worker.cancel()                          # hold the worker: the cache stops where it is
    assert worker.wait(10)
    cache = cloth_cache(window.doc, "cloth")
    done = cache.cached_frames
    window.ctx.set_frame(done + 40.0)
    (item,) = view.build_items()
    assert item.stale and view.cloth_stale
    np.testing.assert_array_equal(item.positions, cache.frames[done - 1])
    assert cache.cached_frames == done       # drawing did not simulate
    worker.resume()
    assert worker.wait(60)
    qtbot.waitUntil(lambda: not view.cloth_stale, timeout=5000)   # the poll repainted it
    (item,) = view.build_items()
    assert not item.stale
    from qtanimator.core.cloth import Cloth

    direct = Cloth(params)
    for _ in range(done + 40):
        direct.step(1 / 60)
    np.testing.assert_array_equal(item.positions, direct.positions)


def test_escape_during_a_light_drag_puts_the_light_back_without_an_undo_step(window, qtbot):
    view = window.viewport3d
    view.camera = OrbitCamera(azimuth=0.0, inclination=0.0, distance=14.0, target=np.array([0.0, 3.0, 0.0]))
    view._framed_once = True
    view.render_image()
    from qtanimator.render.gl.lights import lights_of

    before = lights_of(window.doc)[0].position.copy()
    px = view.camera.project(before, view.width(), view.height())[0]
    a = QPoint(int(round(px[0])), int(round(px[1])))
    view.setFocus()
    qtbot.mousePress(view, Qt.MouseButton.LeftButton, pos=a)
    qtbot.mouseMove(view, a + QPoint(-20, 0))
    assert np.array(window.doc.parameters["light1.position"])[0] < before[0] - 0.1   # previewed
    qtbot.keyClick(view, Qt.Key.Key_Escape)
    qtbot.mouseRelease(view, Qt.MouseButton.LeftButton, pos=a + QPoint(-20, 0))
    np.testing.assert_allclose(lights_of(window.doc)[0].position, before)
    assert window.ctx.undo_stack.count() == 0 and not window.ctx.undo_stack.canRedo()


def _window_with_hidden_3d(qtbot):
    from qtanimator.document.character3d import add_character3d_command
    from qtanimator.paths import scenes_dir

    w = MainWindow(install_editors=("rig_editor", "viewport"))
    qtbot.addWidget(w)
    w.resize(640, 480)
    arm = scenes_dir() / "arm3d"
    w.ctx.push(add_character3d_command(w.doc, arm / "arm.skel", arm / "arm.skin", asset_id="arm"))
    w.ctx.set_frame(3.0)
    w.show()
    qtbot.waitExposed(w)
    assert w.central_tabs.currentWidget() is not w.viewport_panel   # the 2D tab is shown
    return w


def _open_3d_tab(w, qtbot):
    painted: list[float] = []
    w.viewport3d.frameRendered.connect(painted.append)
    w.central_tabs.setCurrentWidget(w.viewport_panel)
    qtbot.waitUntil(lambda: w.viewport3d.gl.isExposed() and bool(painted), timeout=10000)
    return w.viewport3d.render_image()


def test_a_hidden_3d_view_prepares_its_gl_early_and_then_draws_the_same_picture(qtbot, monkeypatch):
    """Shortly after the window shows, the hidden 3D view makes its context, programs and
    meshes (so that opening the tab only draws); while hidden it asks for no pictures; once
    opened it draws exactly what a view prepared the usual way (at its first show) draws."""
    w = _window_with_hidden_3d(qtbot)
    view = w.viewport3d
    qtbot.waitUntil(lambda: view._prepare_state == "done", timeout=10000)
    assert not view.gl.isExposed()
    assert view.gl.context() is not None and view.renderer.initialized
    painted: list[float] = []
    view.frameRendered.connect(painted.append)
    w.ctx.set_frame(4.0)
    qtbot.wait(100)
    assert painted == []          # hidden: nothing is drawn for it
    prepared = _open_3d_tab(w, qtbot)

    monkeypatch.setattr(viewport.Viewport3D, "PREPARE_PLATFORMS", ())
    plain = _window_with_hidden_3d(qtbot)
    plain.ctx.set_frame(4.0)
    qtbot.wait(PREPARE_WAIT_MS)
    assert plain.viewport3d._prepare_state == "" and plain.viewport3d.gl.context() is None
    usual = _open_3d_tab(plain, qtbot)
    assert prepared.shape == usual.shape
    np.testing.assert_array_equal(prepared, usual)


PREPARE_WAIT_MS = viewport.PREPARE_DELAY_MS + 200


def test_the_view_multisamples_on_a_gpu_but_not_on_a_software_rasteriser(window, monkeypatch):
    """4× multisampling takes most of a frame on llvmpipe: the interactive view leaves it
    out there (the renderer name decides), keeps it on a GPU, and obeys the override."""
    from qtanimator.render import gl as glmod

    view = window.viewport3d
    software = glmod.is_software_renderer(view.gl_info or glmod.gl_renderer_name())
    expected = 0 if software else glmod.VIEW_SAMPLES
    assert glmod.view_samples() == expected
    assert max(view.format().samples(), 0) == expected or (expected and view.format().samples() > 1)
    assert glmod.is_software_renderer("llvmpipe (LLVM 15.0.6, 256 bits)")
    assert not glmod.is_software_renderer("NVIDIA GeForce RTX 3060/PCIe/SSE2")
    monkeypatch.setenv("QTANIMATOR_VIEW_SAMPLES", "8")
    assert glmod.view_samples() == 8


def test_right_drag_ik_on_a_gltf_character_below_its_placement_keys_quaternions(window, qtbot, shared_data):
    """CesiumMan hangs below a Z-up to Y-up node (its placement) and its joints are keyed as
    quaternions: the drag picks the joint where it is drawn, moves it towards the mouse, and
    keys the four quaternion channels of the chain in one undo step."""
    from qtanimator.document.character3d import character, pose_skeleton
    from qtanimator.document.import3d import import_file

    imp = import_file(window.doc, shared_data / "gltf" / "CesiumMan.glb")
    window.ctx.push(imp.command)
    aid = imp.asset_id
    view = window.viewport3d
    view.options.show_skin = False
    skel = character(window.doc, aid).skeleton
    rest = skel.world_matrices()[:, :3, 3]
    centre = 0.5 * (rest.min(axis=0) + rest.max(axis=0))
    view.camera = OrbitCamera(azimuth=0.0, inclination=0.0, distance=4.0, target=centre)
    view._framed_once = True
    window.ctx.set_frame(30)
    keys = skel.joint_keys()
    # the joint farthest from the root along the chain that is furthest from the centre: a hand
    joint = int(np.argmax(np.linalg.norm(rest - centre, axis=1) * (np.array(skel.depths) >= 3)))
    p0 = pose_skeleton(window.doc, aid, window.ctx.time).world_matrices()[joint, :3, 3]
    w, h = view.width(), view.height()
    start = view.camera.project(p0, w, h)[0]
    a = QPoint(int(round(start[0])), int(round(start[1])))
    steps = window.ctx.undo_stack.count()
    qtbot.mousePress(view, Qt.MouseButton.RightButton, pos=a)
    for k in range(1, 5):
        qtbot.mouseMove(view, a + QPoint(0, -8 * k))
    qtbot.mouseRelease(view, Qt.MouseButton.RightButton, pos=a + QPoint(0, -32))
    assert window.ctx.undo_stack.count() == steps + 1
    p1 = pose_skeleton(window.doc, aid, window.ctx.time).world_matrices()[joint, :3, 3]
    moved = view.camera.project(p1, w, h)[0]
    assert moved[1] < start[1] - 10  # up the screen, towards the mouse
    parent = skel.joints[joint].parent
    qw = window.doc.channels[f"{aid}/{keys[parent]}/qw"]
    assert qw.key_index(window.ctx.time) is not None
    assert f"{aid}/{keys[parent]}/rx" not in window.doc.channels


def test_r_in_the_3d_view_resets_the_selected_characters_pose(window, qtbot):
    from pathlib import Path

    from qtanimator.document.character3d import add_character3d_command, pose_skeleton, set_dofs_command

    arm = Path(__file__).resolve().parents[2] / "scenes" / "arm3d"
    doc = window.doc
    window.ctx.push(add_character3d_command(doc, arm / "arm.skel", arm / "arm.skin", asset_id="arm"))
    t = window.ctx.time
    window.ctx.push(set_dofs_command(doc, "arm", {(0, "z"): 0.7, (1, "z"): 1.1}, t))
    window.ctx.select("arm", "")
    view = window.viewport3d
    view.setFocus()
    qtbot.keyClick(view, Qt.Key.Key_R)     # a real key event on the 3D view
    pose = pose_skeleton(doc, "arm", t)
    assert all(abs(v) < 1e-12 for j in pose.joints for v in j.pose)   # CSE169's R: zero angles
    window.ctx.undo_stack.undo()            # one undo step
    assert pose_skeleton(doc, "arm", t).joints[1].pose[2] == pytest.approx(1.1)
