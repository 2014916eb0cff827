"""The 2D rig editor driven by real mouse and key events on its viewport."""

from __future__ import annotations

import math

import numpy as np
import pytest
from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtWidgets import QGraphicsView

from qtanimator.document import character2d as c2d
from qtanimator.ui.rig_interaction import pick, rotation_delta


@pytest.fixture
def arm(make_window, qtbot, shared_data):
    window = make_window()
    assert window.open_path(shared_data / "cmu-animator" / "scenes" / "arm.svg")
    view = window.findChild(QGraphicsView, "rigEditorView")
    view.fit_view()
    view.setFocus()
    qtbot.wait(10)
    window.ctx.undo_stack.clear()  # the import itself is an undo step; start counting here
    return window, view, next(iter(window.doc.assets))


def vpos(view, xy) -> QPoint:
    p = view.from_scene(xy)
    return QPoint(int(round(p.x())), int(round(p.y())))


def scene_of(view, pos: QPoint) -> np.ndarray:
    return view.to_scene(QPointF(pos))


def inside(window, asset, joint) -> np.ndarray:
    """A point inside ``joint``'s first shape, in the current pose (scene units)."""
    ch = window.doc.runtime[asset]
    pose = c2d.evaluate_pose(window.doc, asset, window.ctx.time)
    pts = ch.joints[joint].shapes[0].points
    centre = pts.mean(axis=0)
    candidates = [centre] + [centre + f * (p - centre) for f in (0.5, 0.7, 0.85, 0.95) for p in pts]
    for local in candidates:  # a point of the shape that no later joint covers
        view = window.rig_editor.view
        world = scene_of(view, vpos(view, pose.to_world(joint, local)))  # on a whole pixel
        if pick(window.doc, window.ctx.time, world) == (asset, joint):
            return world
    raise AssertionError(f"joint {joint} is covered everywhere")


def drag(qtbot, view, button, start: QPoint, points: list[QPoint], release: bool = True):
    vp = view.viewport()
    qtbot.mousePress(vp, button, pos=start)
    for p in points:
        qtbot.mouseMove(vp, p)
    if release:
        qtbot.mouseRelease(vp, button, pos=points[-1])


def test_left_drag_rotates_a_joint_one_undo_step_and_undo_is_exact(qtbot, arm):
    window, view, asset = arm
    doc = window.doc
    before_state = doc.state()
    before_pose = c2d.evaluate_pose(doc, asset, 0.0)
    joint = 2  # the hand
    start = vpos(view, inside(window, asset, joint))
    assert pick(doc, 0.0, scene_of(view, start)) == (asset, joint)
    pivot = before_pose.pivots[joint]
    # Swing the cursor about the pivot by 40° in steps.
    r = scene_of(view, start) - pivot
    moves = []
    for deg in (10, 20, 30, 40):
        a = math.radians(deg)
        rot = np.array([[math.cos(a), math.sin(a)], [-math.sin(a), math.cos(a)]])
        moves.append(vpos(view, pivot + rot @ r))
    drag(qtbot, view, Qt.MouseButton.LeftButton, start, moves)

    expected = rotation_delta(pivot, scene_of(view, start), scene_of(view, moves[-1]))
    assert expected == pytest.approx(math.radians(40), abs=0.02)
    angles = c2d.joint_angles(doc, asset, 0.0)
    assert angles[joint] == pytest.approx(expected, abs=1e-9)
    assert window.ctx.selection == (asset, doc.runtime[asset].joints[joint].name)
    assert window.ctx.undo_stack.count() == 1  # four moves, one step

    window.ctx.undo_stack.undo()
    assert doc.state() == before_state
    after = c2d.evaluate_pose(doc, asset, 0.0)
    np.testing.assert_array_equal(after.world, before_pose.world)
    window.ctx.undo_stack.redo()
    assert c2d.joint_angles(doc, asset, 0.0)[joint] == pytest.approx(expected, abs=1e-9)


def test_left_drag_on_the_root_moves_the_character(qtbot, arm):
    window, view, asset = arm
    start = vpos(view, inside(window, asset, 0))
    assert pick(window.doc, 0.0, scene_of(view, start)) == (asset, 0)
    end = start + QPoint(60, 25)
    drag(qtbot, view, Qt.MouseButton.LeftButton, start, [start + QPoint(30, 10), end])
    moved = scene_of(view, end) - scene_of(view, start)
    t = c2d.translation(window.doc, asset, 0.0)
    np.testing.assert_allclose(t, moved, atol=1e-9)
    assert window.ctx.selection == (asset, "")
    assert window.ctx.undo_stack.count() == 1
    # The character moved on screen too: the root is now under the end point.
    assert pick(window.doc, 0.0, scene_of(view, end)) == (asset, 0)


def test_right_drag_brings_the_end_effector_to_the_cursor(qtbot, arm):
    window, view, asset = arm
    doc = window.doc
    joint = 2
    start = vpos(view, inside(window, asset, joint))
    press = scene_of(view, start)
    local = c2d.evaluate_pose(doc, asset, 0.0).to_local(joint, press)
    pose0 = c2d.evaluate_pose(doc, asset, 0.0)
    # A reachable target: rotate the grabbed point 35° about the arm joint's pivot.
    pivot = pose0.pivots[1]
    a = math.radians(35)
    rot = np.array([[math.cos(a), math.sin(a)], [-math.sin(a), math.cos(a)]])
    target = pivot + rot @ (press - pivot)
    steps = [vpos(view, press + (target - press) * f) for f in (0.25, 0.5, 0.75, 1.0)]
    drag(qtbot, view, Qt.MouseButton.RightButton, start, steps)
    cursor = scene_of(view, steps[-1])
    tip = c2d.evaluate_pose(doc, asset, 0.0).to_world(joint, local)
    assert np.hypot(*(tip - cursor)) < 0.5
    assert window.ctx.undo_stack.count() == 1
    window.ctx.undo_stack.undo()
    np.testing.assert_array_equal(c2d.evaluate_pose(doc, asset, 0.0).world, pose0.world)


def test_escape_aborts_a_drag(qtbot, arm):
    window, view, asset = arm
    before = window.doc.state()
    start = vpos(view, inside(window, asset, 2))
    drag(qtbot, view, Qt.MouseButton.LeftButton, start, [start + QPoint(40, 40)], release=False)
    assert window.doc.state() != before  # the drag shows live
    qtbot.keyClick(view, Qt.Key.Key_Escape)
    assert window.doc.state() == before
    qtbot.mouseRelease(view.viewport(), Qt.MouseButton.LeftButton, pos=start + QPoint(40, 40))
    assert window.doc.state() == before
    assert window.ctx.undo_stack.count() == 0


def test_ik_toggle_mode_follows_until_the_next_press(qtbot, arm):
    window, view, asset = arm
    window.rig_editor.ik_toggle_box.setChecked(True)
    joint = 2
    start = vpos(view, inside(window, asset, joint))
    vp = view.viewport()
    qtbot.mousePress(vp, Qt.MouseButton.RightButton, pos=start)
    qtbot.mouseRelease(vp, Qt.MouseButton.RightButton, pos=start)
    assert view.dragging  # still following after the release
    qtbot.mouseMove(vp, start + QPoint(-30, 20))
    qtbot.mouseMove(vp, start + QPoint(-50, 30))
    qtbot.mousePress(vp, Qt.MouseButton.RightButton, pos=start + QPoint(-50, 30))
    qtbot.mouseRelease(vp, Qt.MouseButton.RightButton, pos=start + QPoint(-50, 30))
    assert not view.dragging
    assert window.ctx.undo_stack.count() == 1


def test_hover_click_select_and_empty_click_deselects(qtbot, arm):
    window, view, asset = arm
    vp = view.viewport()
    p = vpos(view, inside(window, asset, 1))
    qtbot.mouseMove(vp, p)
    qtbot.waitUntil(lambda: view.hover == (asset, 1))
    qtbot.mouseClick(vp, Qt.MouseButton.LeftButton, pos=p)
    assert window.ctx.selection == (asset, window.doc.runtime[asset].joints[1].name)
    tree = window.joint_tree.tree
    assert tree.currentItem().text(0) == window.doc.runtime[asset].joints[1].name
    qtbot.mouseClick(vp, Qt.MouseButton.LeftButton, pos=QPoint(3, 3))
    assert window.ctx.selection == ("", "")
    assert window.ctx.undo_stack.count() == 0  # clicks without a move key nothing


def test_delete_removes_the_keys_at_the_current_frame(qtbot, arm):
    window, view, asset = arm
    doc = window.doc
    ctx = window.ctx
    for frame, dx in ((0, 0), (30, 40)):
        ctx.set_frame(frame)
        start = vpos(view, inside(window, asset, 0))
        drag(qtbot, view, Qt.MouseButton.LeftButton, start, [start + QPoint(dx + 1, 0)])
    assert len(doc.channels[f"{asset}//x"].keys) == 2
    qtbot.keyClick(view, Qt.Key.Key_Delete)
    assert [k.time for k in doc.channels[f"{asset}//x"].keys] == [0.0]
    ctx.undo_stack.undo()
    assert len(doc.channels[f"{asset}//x"].keys) == 2


def test_delete_takes_the_selected_characters_keys_and_shift_delete_everyones(qtbot, arm, shared_data):
    # Issue 18: Delete acts on the selected character, Shift+Delete on every character.
    window, view, first = arm
    doc, ctx = window.doc, window.ctx
    assert window.open_path(shared_data / "cmu-animator" / "scenes" / "arm.svg")
    second = [a for a in doc.assets if a != first][0]
    for asset in (first, second):
        for frame in (0, 30):
            ctx.push(c2d.key_joint(doc, asset, 1, 0.1 * (frame + 1), frame / doc.fps))
    ctx.set_frame(30)

    def frames(asset):
        ch = doc.channels[c2d.angle_channel_id(asset, doc.runtime[asset].joints[1].name)]
        return [round(k.time * doc.fps) for k in ch.keys]

    view.setFocus()
    ctx.select("", "")
    qtbot.keyClick(view, Qt.Key.Key_Delete)  # nothing selected: nothing deleted
    assert frames(first) == frames(second) == [0, 30]
    ctx.select(second, doc.runtime[second].joints[1].name)
    qtbot.keyClick(view, Qt.Key.Key_Delete)
    assert frames(first) == [0, 30] and frames(second) == [0]
    ctx.undo_stack.undo()
    assert frames(second) == [0, 30]
    qtbot.keyClick(view, Qt.Key.Key_Backspace, Qt.KeyboardModifier.ShiftModifier)
    assert frames(first) == frames(second) == [0]
    ctx.undo_stack.undo()
    ctx.select("", "")
    window.findChild(type(window.action_save), "actionDeleteFrameKeysAll").trigger()
    assert frames(first) == frames(second) == [0]


def test_a_new_project_of_svg_characters_gets_300_frames(qtbot, arm):
    window, _view, _asset = arm
    assert window.doc.frame_range == (0, 300)  # the CMU animator's timeline


def test_d_toggles_debug_overlays_and_hud(qtbot, arm):
    window, view, asset = arm
    assert not view.debug
    qtbot.keyClick(view, Qt.Key.Key_D)
    assert view.debug and window.rig_editor.debug_action.isChecked()
    window.ctx.select(asset, window.doc.runtime[asset].joints[2].name)
    text = "\n".join(view.hud_text())
    assert "keyframed" in text and "position" in text
    image = view.grab().toImage()
    # The HUD box is drawn black in the top right corner.
    c = image.pixelColor(image.width() - 30, 30)
    assert c.red() < 60 and c.green() < 60
    qtbot.keyClick(view, Qt.Key.Key_D)
    assert not view.debug


def test_wheel_zooms_and_middle_drag_pans(qtbot, arm):
    window, view, asset = arm
    vp = view.viewport()
    center = QPoint(vp.width() // 2, vp.height() // 2)
    before = scene_of(view, center)
    scale = view.transform().m11()
    from PySide6.QtCore import QPoint as P
    from PySide6.QtGui import QWheelEvent
    from PySide6.QtWidgets import QApplication

    ev = QWheelEvent(QPointF(center), QPointF(vp.mapToGlobal(center)), P(0, 0), P(0, 120),
                     Qt.MouseButton.NoButton, Qt.KeyboardModifier.NoModifier, Qt.ScrollPhase.NoScrollPhase, False)
    QApplication.sendEvent(vp, ev)
    assert view.transform().m11() == pytest.approx(scale * 1.0015 ** 120)
    np.testing.assert_allclose(scene_of(view, center), before, atol=1.0 / view.transform().m11())
    drag(qtbot, view, Qt.MouseButton.MiddleButton, center, [center + QPoint(40, 0)])
    moved = scene_of(view, center) - before
    assert moved[0] == pytest.approx(-40 / view.transform().m11(), abs=2 / view.transform().m11())
    assert window.ctx.undo_stack.count() == 0


def test_opening_a_bad_svg_shows_the_reason_and_keeps_the_document(qtbot, arm, tmp_path, dialog_log):
    window, view, asset = arm
    before = window.doc.state()
    bad = tmp_path / "broken.svg"
    bad.write_text("<svg><g><rect")
    assert not window.open_path(bad)
    assert dialog_log and "broken.svg" in dialog_log[-1][1]
    assert window.doc.state() == before


def _color_at(view, xy):
    image = view.grab().toImage()
    p = vpos(view, xy)
    return image.pixelColor(p.x(), p.y())


def test_onion_skin_shows_tinted_ghosts_of_other_frames(qtbot, arm):
    window, view, asset = arm
    doc = window.doc
    from qtanimator.core.channel import Key
    from qtanimator.document.commands import SetKeys

    window.ctx.push(SetKeys(doc, {f"{asset}//x": Key(0.0, 0.0), f"{asset}//y": Key(0.0, 0.0)}))
    window.ctx.push(SetKeys(doc, {f"{asset}//x": Key(20 / 60, 300.0), f"{asset}//y": Key(20 / 60, 0.0)}))
    from PySide6.QtCore import QRectF

    view.fitInView(QRectF(-100, -50, 600, 500), Qt.AspectRatioMode.KeepAspectRatio)
    window.ctx.set_frame(10)
    ghost_point = inside(window, asset, 1) + c2d.translation(doc, asset, 20 / 60) - c2d.translation(doc, asset, 10 / 60)
    plain = _color_at(view, ghost_point)
    assert (plain.red(), plain.green(), plain.blue()) == (153, 153, 230)  # background
    editor = window.rig_editor
    editor.before_box.setValue(1)
    editor.after_box.setValue(1)
    editor.step_box.setValue(10)
    qtbot.mouseClick(editor.onion_box, Qt.MouseButton.LeftButton)
    assert view.onion.enabled
    ghost = _color_at(view, ghost_point)
    assert (ghost.red(), ghost.green(), ghost.blue()) != (153, 153, 230)
    assert ghost.green() > ghost.red() and ghost.green() > ghost.blue() - 40  # the later frames' green tint


def test_debug_overlay_draws_ik_source_and_target_dots(qtbot, arm):
    window, view, asset = arm
    qtbot.keyClick(view, Qt.Key.Key_D)
    start = vpos(view, inside(window, asset, 2))
    target = start + QPoint(-200, -40)  # out of reach: the source cannot get there
    drag(qtbot, view, Qt.MouseButton.RightButton, start, [target], release=False)
    blue = _color_at(view, scene_of(view, target))
    assert blue.blue() > 150 and blue.red() < 80
    source = view.poses()[asset].to_world(2, view._ik[2])
    red = _color_at(view, source)
    assert red.red() > 200 and red.green() < 60 and red.blue() < 60
    qtbot.mouseRelease(view.viewport(), Qt.MouseButton.RightButton, pos=target)
    assert view._ik is None


# ------------------------------------------------------- the gesture logic, without Qt
def test_rotation_delta_is_counter_clockwise_on_a_y_down_screen():
    # Right of the pivot to straight up (y down) is a quarter turn counter-clockwise.
    assert rotation_delta((0, 0), (1, 0), (0, -1)) == pytest.approx(math.pi / 2)
    assert rotation_delta((0, 0), (1, 0), (0, 1)) == pytest.approx(-math.pi / 2)
    assert rotation_delta((5, 5), (5, 5), (9, 9)) == 0.0  # pressed on the pivot itself


def test_drag_generators_fold_into_one_exact_undo_step(shared_data):
    from qtanimator.document.commands import UndoStack
    from qtanimator.document.document import Document
    from qtanimator.document.gesture import Gesture
    from qtanimator.ui import rig_interaction as ri

    doc = Document()
    stack = UndoStack(doc)
    stack.push(c2d.add_characters_command(doc, shared_data / "cmu-animator" / "scenes" / "arm.svg"))
    asset = next(iter(doc.assets))
    before = doc.state()
    pose = c2d.evaluate_pose(doc, asset, 0.0)
    pivot = pose.pivots[2]
    press = pivot + np.array([0.0, -50.0])
    gesture = Gesture(doc, "Rotate", stack.record)
    drag_ = ri.rotate_drag(doc, asset, 2, press, 0.0)
    next(drag_)
    for deg in (5, 15, 30):
        a = math.radians(deg)
        cursor = pivot + np.array([[math.cos(a), math.sin(a)], [-math.sin(a), math.cos(a)]]) @ (press - pivot)
        gesture.update(drag_.send(cursor))
    assert c2d.joint_angles(doc, asset, 0.0)[2] == pytest.approx(math.radians(30))
    assert gesture.commit() is not None
    assert len(stack.done) == 2  # the import and the whole drag
    after = doc.state()
    stack.undo()
    assert doc.state() == before
    stack.redo()
    assert doc.state() == after

    # Abort leaves nothing behind.
    stack.undo()
    gesture = Gesture(doc, "Move", stack.record)
    move = ri.move_drag(doc, asset, (0.0, 0.0), 0.0)
    next(move)
    gesture.update(move.send((10.0, 4.0)))
    np.testing.assert_allclose(c2d.translation(doc, asset, 0.0), (10.0, 4.0))
    gesture.abort()
    assert doc.state() == before and gesture.commit() is None and len(stack.done) == 1


def test_ik_generator_reaches_a_reachable_target(shared_data):
    from qtanimator.document.document import Document
    from qtanimator.document.gesture import Gesture
    from qtanimator.ui import rig_interaction as ri

    doc = Document()
    c2d.add_characters_command(doc, shared_data / "cmu-animator" / "scenes" / "arm.svg").do(doc)
    asset = next(iter(doc.assets))
    pose = c2d.evaluate_pose(doc, asset, 0.0)
    press = pose.to_world(2, doc.runtime[asset].joints[2].shapes[0].points.mean(axis=0))
    target = press + np.array([-40.0, 30.0])
    gesture = Gesture(doc, "IK", lambda _c: None)
    ik = ri.ik_drag(doc, asset, 2, press, 0.0)
    next(ik)
    gesture.update(ik.send(target))
    local = pose.to_local(2, press)
    assert np.hypot(*(c2d.evaluate_pose(doc, asset, 0.0).to_world(2, local) - target)) < 1e-2
    # The handout's debug arrows start at each joint's first child, perpendicular to the bone.
    from qtanimator.core.ik import handout_gradient

    character = doc.runtime[asset]
    grad = handout_gradient(character, pose, 2, local, target)
    arrows = ri.gradient_arrows(character, pose, grad, 0.1)
    assert len(arrows) == int(np.count_nonzero(grad))
    movers = [j for j in range(len(character.joints)) if grad[j] != 0 and character.joints[j].children]
    for j, (start, end) in zip(movers, arrows):
        child = character.joints[j].children[0]
        np.testing.assert_allclose(start, pose.pivots[child])
        bone = pose.pivots[child] - pose.pivots[j]
        assert abs(float(np.dot(end - start, bone))) < 1e-6 * (1 + np.hypot(*bone) * np.hypot(*(end - start)))


def test_onion_frames_counts_step_and_range():
    from qtanimator.ui.rig_interaction import OnionSettings, onion_frames

    s = OnionSettings(enabled=True, before=2, after=1, step=5)
    ghosts = onion_frames(12, s, 0, 100)
    assert [(f, side) for f, side, _o in ghosts] == [(2.0, "before"), (7.0, "before"), (17.0, "after")]
    assert ghosts[1][2] > ghosts[0][2]  # nearer ghosts are more opaque
    assert [f for f, _s, _o in onion_frames(3, s, 0, 100)] == [8.0]  # earlier ghosts fall before 0
    assert onion_frames(12, OnionSettings(enabled=False), 0, 100) == []
    assert [f for f, _s, _o in onion_frames(98, s, 0, 100)] == [88.0, 93.0]


def test_timeline_keys_work_in_the_editor_and_f_fits(qtbot, arm):
    window, view, asset = arm
    qtbot.keyClick(view, Qt.Key.Key_Right)
    qtbot.keyClick(view, Qt.Key.Key_Right, Qt.KeyboardModifier.ShiftModifier)
    assert window.ctx.frame == 11
    qtbot.keyClick(view, Qt.Key.Key_Home)
    assert window.ctx.frame == 0
    fitted = view.transform().m11()
    view.scale(3.0, 3.0)
    qtbot.keyClick(view, Qt.Key.Key_F)
    assert view.transform().m11() == pytest.approx(fitted)


def test_playback_sprites_keep_what_the_svg_draws_beyond_the_geometry(make_window, qtbot, tmp_path):
    """While playing, the editor draws each joint from an image made once: a drop shadow
    reaching past the shapes must be in it (the picture is sized from what the SVG draws,
    not from the geometry alone), so the playing picture equals the still one."""
    from PySide6.QtGui import QImage

    svg = ('<svg xmlns="http://www.w3.org/2000/svg" width="200" height="200"><g id="body">'
           '<defs><filter id="d" x="-50%" y="-50%" width="200%" height="200%">'
           '<feGaussianBlur in="SourceAlpha" stdDeviation="3"/><feOffset dx="30" dy="30" result="o"/>'
           '<feMerge><feMergeNode in="o"/><feMergeNode in="SourceGraphic"/></feMerge></filter></defs>'
           '<rect x="40" y="40" width="60" height="60" fill="tomato" filter="url(#d)"/>'
           '<circle cx="70" cy="70" r="2" fill="black"/></g></svg>')
    path = tmp_path / "shadow.svg"
    path.write_text(svg)
    window = make_window()
    assert window.open_path(path)
    view = window.findChild(QGraphicsView, "rigEditorView")
    view.fit_view()
    qtbot.wait(20)

    def grab(mode: str) -> np.ndarray:
        view.sprite_mode = mode
        view.sprites.clear()
        view.viewport().update()
        qtbot.wait(30)
        img = view.viewport().grab().toImage().convertToFormat(QImage.Format.Format_RGBA8888)
        return np.frombuffer(img.constBits(), np.uint8).reshape(img.height(), img.width(), 4).astype(int)

    still, playing = grab("never"), grab("always")
    shadow = (np.abs(still[..., :3] - still[0, 0, :3]).sum(axis=2) > 0)
    assert shadow.sum() > 500      # something beyond the rectangle is drawn
    differ = np.abs(still[..., :3] - playing[..., :3]).max(axis=2) > 48
    assert differ.mean() < 0.01


def test_selecting_a_3d_joint_while_the_2d_editor_shows_draws_without_error(qtbot, make_window, shared_data):
    """The 2D editor's selected-joint overlays ignore a 3D character's joint (it once asked
    the 3D character for a 2D joint index while painting)."""
    from qtanimator.document.character3d import add_character3d_command

    window = make_window()
    window.ctx.push(add_character3d_command(window.doc, shared_data / "cse169" / "wasp_walk" / "wasp.skel",
                                            asset_id="wasp"))
    window.central_tabs.setCurrentWidget(window.rig_editor)
    window.ctx.select("wasp", "knee_01_r")
    view = window.rig_editor.view
    assert view.selected_joint_index("wasp") is None
    view.viewport().repaint()  # painting the overlays must not raise
    qtbot.wait(10)
