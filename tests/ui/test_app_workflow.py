"""Whole-application workflows: open, pose with the mouse, play, save, reopen, and look.

The image comparison renders the rig editor's view and compares it with
``tests/ui/reference/rig_editor_arm.png`` within a tolerance. To (re)generate the reference
after an intended change of the drawing, run once::

    QTANIMATOR_UPDATE_REFERENCE=1 .venv/bin/python -m pytest tests/ui/test_app_workflow.py -k image

and check the new PNG in.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest
from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtGui import QImage
from PySide6.QtWidgets import QGraphicsView

from qtanimator.document import character2d as c2d
from qtanimator.ui.rig_editor import RigEditorView
from qtanimator.ui.rig_interaction import pick

REFERENCE = Path(__file__).parent / "reference" / "rig_editor_arm.png"




def vpos(view, xy) -> QPoint:
    p = view.from_scene(xy)
    return QPoint(int(round(p.x())), int(round(p.y())))


def grab_point(window, view, asset, joint) -> QPoint:
    ch = window.doc.runtime[asset]
    pose = c2d.evaluate_pose(window.doc, asset, window.ctx.time)
    pts = ch.joints[joint].shapes[0].points
    centre = pts.mean(axis=0)
    for local in [centre] + [centre + f * (p - centre) for f in (0.5, 0.7, 0.9) for p in pts]:
        pos = vpos(view, pose.to_world(joint, local))
        if pick(window.doc, window.ctx.time, view.to_scene(QPointF(pos))) == (asset, joint):
            return pos
    raise AssertionError("joint not visible")


def left_drag(qtbot, view, start: QPoint, end: QPoint) -> None:
    vp = view.viewport()
    qtbot.mousePress(vp, Qt.MouseButton.LeftButton, pos=start)
    qtbot.mouseMove(vp, (start + end) / 2)
    qtbot.mouseMove(vp, end)
    qtbot.mouseRelease(vp, Qt.MouseButton.LeftButton, pos=end)


def test_pose_keys_save_and_reopen_give_the_same_document(make_window, qtbot, shared_data, tmp_path):
    window = make_window(full=True)
    assert window.open_path(shared_data / "cmu-animator" / "scenes" / "arm.svg")
    view = window.findChild(QGraphicsView, "rigEditorView")
    view.fit_view()
    asset = next(iter(window.doc.assets))
    for frame, dx in ((0, 30), (40, -30)):
        window.ctx.set_frame(frame)
        p = grab_point(window, view, asset, 2)
        left_drag(qtbot, view, p, p + QPoint(dx, 15))
        p = grab_point(window, view, asset, 0)
        left_drag(qtbot, view, p, p + QPoint(dx // 3, 0))
    state = window.doc.state()
    assert len(window.doc.channels) >= 3
    poses = [c2d.evaluate_pose(window.doc, asset, f / 60).world for f in range(0, 60, 7)]
    path = tmp_path / "arm.qtanim"
    assert window.save_to(path)
    assert not window.isWindowModified()

    other = make_window()
    assert other.open_path(path)
    assert other.doc.state() == state
    for f, world in zip(range(0, 60, 7), poses):
        np.testing.assert_array_equal(c2d.evaluate_pose(other.doc, asset, f / 60).world, world)
    assert other.rig_editor.view.items_by_asset.keys() == {asset}


def test_playback_plays_pendulums_from_the_simulation_cache(make_window, qtbot, shared_data):
    window = make_window()
    assert window.open_path(shared_data / "cmu-animator" / "scenes" / "clock.svg")
    doc = window.doc
    character = doc.runtime["clock"]
    pendulum = 5
    assert character.joints[pendulum].is_dynamic
    # Pull the pendulum aside with the DOF spin box (a key at frame 0 sets its start angle).
    window.ctx.select("clock", character.joints[pendulum].name)
    window.joint_tree.dofs.rows[0].spin.setValue(30.0)
    shown: list[float] = []
    window.ctx.frameChanged.connect(shown.append)
    view = window.rig_editor.view
    drawn = view.frames_drawn
    window.findChild(type(window.action_save), "actionPlay").trigger()
    qtbot.waitUntil(lambda: window.ctx.frame >= 45, timeout=10000)
    window.playback.pause()
    assert view.frames_drawn > drawn  # the editor repainted while playing
    assert shown == sorted(shown)
    sim = c2d.simulation(doc)
    assert sim.wait_idle()  # the background worker simulates ahead of the frame shown
    assert sim.cached_frames("clock") >= 45
    angles = [c2d.evaluate_pose(doc, "clock", f / doc.fps).world_angles[pendulum] for f in range(0, 46, 5)]
    assert angles[0] == pytest.approx(math.radians(30.0))
    assert max(angles) - min(angles) > 0.05  # it swings
    # Scrubbing back reads the cache: nothing is simulated again.
    steps = sim.steps_taken
    window.ctx.set_frame(10)
    view.grab()
    assert sim.steps_taken == steps


def test_open_a_folder_adds_every_character_sorted(make_window, qtbot, shared_data):
    window = make_window()
    folder = shared_data / "cmu-animator" / "scenes" / "testscene"
    assert window.open_path(folder)
    assert len(window.doc.assets) == 6
    names = [Path(a.source).name for a in window.doc.assets.values()]
    assert all(n == "testscene" for n in names)
    assert list(window.rig_editor.view.items_by_asset) == list(window.doc.assets)
    window.ctx.undo_stack.undo()
    assert window.doc.assets == {}


def _render_editor(qtbot, window) -> QImage:
    view = RigEditorView(window.ctx)
    qtbot.addWidget(view)
    view.setFixedSize(480, 360)
    view.show()
    qtbot.waitExposed(view)
    view.fit_view()
    return view.grab().toImage().convertToFormat(QImage.Format.Format_RGB32)


def _array(image: QImage) -> np.ndarray:
    w, h = image.width(), image.height()
    buf = np.frombuffer(image.constBits(), dtype=np.uint8, count=image.bytesPerLine() * h)
    return buf.reshape(h, image.bytesPerLine())[:, : w * 4].reshape(h, w, 4)[..., :3].astype(np.int16)


def test_image_of_the_editor_matches_the_reference(make_window, qtbot, shared_data):
    window = make_window()
    assert window.open_path(shared_data / "cmu-animator" / "scenes" / "arm.svg")
    asset = next(iter(window.doc.assets))
    doc = window.doc
    window.ctx.push(c2d.key_joint(doc, asset, 1, math.radians(25), 0.0))
    window.ctx.push(c2d.key_joint(doc, asset, 2, math.radians(-40), 0.0))
    window.ctx.select(asset, doc.runtime[asset].joints[2].name)  # highlighted
    image = _render_editor(qtbot, window)
    if os.environ.get("QTANIMATOR_UPDATE_REFERENCE"):
        REFERENCE.parent.mkdir(parents=True, exist_ok=True)
        assert image.save(str(REFERENCE))
    reference = QImage(str(REFERENCE)).convertToFormat(QImage.Format.Format_RGB32)
    assert not reference.isNull(), f"missing {REFERENCE}; see this module's docstring"
    a, b = _array(image), _array(reference)
    assert a.shape == b.shape
    diff = np.abs(a - b).max(axis=2)
    # Antialiasing may differ by a few levels on edge pixels; shapes and colours may not.
    assert diff.mean() < 1.0
    assert (diff > 48).mean() < 0.002
    # A pose change is detected by the same comparison.
    window.ctx.push(c2d.key_joint(doc, asset, 1, math.radians(35), 0.0))
    moved = _array(_render_editor(qtbot, window))
    assert (np.abs(moved - b).max(axis=2) > 48).mean() > 0.002
