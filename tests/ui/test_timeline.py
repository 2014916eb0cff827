"""Timeline and playback: real key presses and mouse drags on the timeline widget."""

from __future__ import annotations

from PySide6.QtCore import QPoint, Qt
from PySide6.QtWidgets import QDockWidget, QWidget

from qtanimator.core.channel import Key
from qtanimator.document import InsertKey
from qtanimator.ui.playback import playback_frame


def test_playback_frame_follows_the_clock_and_drops_frames():
    # 1/60 s per frame: 0.5 s after starting at 10 is frame 40, whatever happened between.
    assert playback_frame(10, 0.5, 60, 0, 240, loop=False) == (40.0, True)
    assert playback_frame(10, 0.0, 60, 0, 240, loop=False) == (10.0, True)
    # Past the end without loop: stop on the last frame.
    assert playback_frame(230, 1.0, 60, 0, 240, loop=False) == (240.0, False)
    # With loop: wrap onto [first, last].
    assert playback_frame(230, 1.0, 60, 0, 240, loop=True) == ((230 + 60) % 241, True)


def test_timeline_dock_and_names(make_window, qtbot):
    window = make_window(full=True, size=None)
    assert window.findChild(QDockWidget, "timelineDock") is not None
    assert window.findChild(QWidget, "timeline") is not None
    assert window.findChild(type(window.action_save), "actionPlay") is not None


def test_keys_step_and_jump(make_window, qtbot):
    window = make_window(size=None)
    ctx = window.ctx
    timeline = window.findChild(QWidget, "timeline")
    timeline.setFocus()
    qtbot.waitUntil(timeline.hasFocus)
    qtbot.keyClick(timeline, Qt.Key.Key_Right)
    assert ctx.frame == 1
    qtbot.keyClick(timeline, Qt.Key.Key_Right, Qt.KeyboardModifier.ShiftModifier)
    assert ctx.frame == 11
    qtbot.keyClick(timeline, Qt.Key.Key_Left)
    assert ctx.frame == 10
    qtbot.keyClick(timeline, Qt.Key.Key_End)
    assert ctx.frame == 240
    qtbot.keyClick(timeline, Qt.Key.Key_Right)  # wraps
    assert ctx.frame == 0
    qtbot.keyClick(timeline, Qt.Key.Key_Left)
    assert ctx.frame == 240
    qtbot.keyClick(timeline, Qt.Key.Key_Up)
    assert ctx.frame == 0
    qtbot.keyClick(timeline, Qt.Key.Key_Down)
    assert ctx.frame == 240
    # Shift ±10 wraps around the range like the single steps (the CMU animator's keys).
    qtbot.keyClick(timeline, Qt.Key.Key_Right, Qt.KeyboardModifier.ShiftModifier)
    assert ctx.frame == 9  # 240 + 10 over the 241 frames 0…240
    qtbot.keyClick(timeline, Qt.Key.Key_Left, Qt.KeyboardModifier.ShiftModifier)
    assert ctx.frame == 240
    qtbot.keyClick(timeline, Qt.Key.Key_Home)
    assert ctx.frame == 0

    # Alt+arrows jump between keyed frames.
    doc = window.doc
    for t in (0.5, 1.0):  # frames 30 and 60 at 60 fps
        ctx.push(InsertKey(doc, "hero//x", Key(t, 1.0)))
    qtbot.keyClick(timeline, Qt.Key.Key_Right, Qt.KeyboardModifier.AltModifier)
    assert ctx.frame == 30
    qtbot.keyClick(timeline, Qt.Key.Key_Right, Qt.KeyboardModifier.AltModifier)
    assert ctx.frame == 60
    qtbot.keyClick(timeline, Qt.Key.Key_Right, Qt.KeyboardModifier.AltModifier)
    assert ctx.frame == 60
    qtbot.keyClick(timeline, Qt.Key.Key_Left, Qt.KeyboardModifier.AltModifier)
    assert ctx.frame == 30


def test_brackets_change_the_range_undoably(make_window, qtbot):
    window = make_window(size=None)
    timeline = window.findChild(QWidget, "timeline")
    timeline.setFocus()
    qtbot.waitUntil(timeline.hasFocus)
    qtbot.keyClick(timeline, Qt.Key.Key_BracketRight)
    assert window.doc.frame_range == (0, 340)
    qtbot.keyClick(timeline, Qt.Key.Key_BracketLeft)
    qtbot.keyClick(timeline, Qt.Key.Key_BracketLeft)
    assert window.doc.frame_range == (0, 140)
    qtbot.keyClick(timeline, Qt.Key.Key_BracketLeft)  # not shorter than 100 frames
    assert window.doc.frame_range == (0, 140)
    window.ctx.undo_stack.undo()
    assert window.doc.frame_range == (0, 240)


def test_scrub_by_drag(make_window, qtbot):
    window = make_window(size=None)
    timeline = window.findChild(QWidget, "timeline")
    y = timeline.height() // 2
    qtbot.mousePress(timeline, Qt.MouseButton.LeftButton, pos=QPoint(int(timeline.frame_to_x(100)), y))
    assert window.ctx.frame == 100
    qtbot.mouseMove(timeline, QPoint(int(timeline.frame_to_x(150)), y))
    qtbot.mouseRelease(timeline, Qt.MouseButton.LeftButton, pos=QPoint(int(timeline.frame_to_x(150)), y))
    assert abs(window.ctx.frame - 150) <= 1


def test_playback_advances_frames_and_signals(make_window, qtbot):
    window = make_window(size=None)
    ctx = window.ctx
    states: list[bool] = []
    ctx.playingChanged.connect(states.append)
    seen: list[float] = []
    ctx.frameChanged.connect(seen.append)
    timeline = window.findChild(QWidget, "timeline")
    timeline.setFocus()
    qtbot.keyClick(timeline, Qt.Key.Key_Space)
    assert window.playback.playing
    qtbot.waitUntil(lambda: ctx.frame >= 10, timeout=5000)
    qtbot.keyClick(timeline, Qt.Key.Key_Space)
    assert not window.playback.playing
    assert states == [True, False]
    assert seen == sorted(seen)  # frames only went forward
    paused_at = ctx.frame
    qtbot.wait(100)
    assert ctx.frame == paused_at


def test_play_without_loop_stops_at_the_end(make_window, qtbot):
    window = make_window(size=None)
    ctx = window.ctx
    window.findChild(type(window.action_save), "actionLoop").setChecked(False)
    ctx.set_frame(230)
    window.findChild(type(window.action_save), "actionPlay").trigger()
    qtbot.waitUntil(lambda: not window.playback.playing, timeout=5000)
    assert ctx.frame == 240


def test_slow_frames_are_dropped_not_slowed_down(make_window, qtbot):
    import time

    window = make_window(size=None)
    ctx = window.ctx
    shown: list[float] = []

    def slow_frame(frame: float) -> None:
        shown.append(frame)
        time.sleep(0.05)  # a frame that takes three 60 fps frames to draw

    ctx.frameChanged.connect(slow_frame)
    window.playback.play()
    qtbot.waitUntil(lambda: len(shown) >= 6, timeout=10000)
    window.playback.pause()
    steps = [b - a for a, b in zip(shown, shown[1:])]
    assert all(s >= 1 for s in steps)
    assert max(steps) >= 3  # playback skipped frames to keep up with the clock
    assert window.playback.dropped_frames > 0


def test_stop_button_returns_to_where_playback_began(make_window, qtbot):
    from PySide6.QtWidgets import QToolButton

    window = make_window(size=None)
    ctx = window.ctx
    ctx.set_frame(20)
    play = window.findChild(QToolButton, "buttonPlay")
    stop = window.findChild(QToolButton, "buttonStop")
    qtbot.mouseClick(play, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: ctx.frame >= 25, timeout=5000)
    qtbot.mouseClick(stop, Qt.MouseButton.LeftButton)
    assert not window.playback.playing and ctx.frame == 20
    rewind = window.findChild(QToolButton, "buttonRewind")
    qtbot.mouseClick(rewind, Qt.MouseButton.LeftButton)
    assert ctx.frame == 0


def test_space_and_stop_pause_the_3d_clip_controls_too(make_window, qtbot):
    """While the 3D viewport's clip controls play, the timeline's Play button shows Pause:
    Space (and the button) must pause them, not start the timeline over them; Stop stops
    them as well."""
    from PySide6.QtGui import QAction

    window = make_window(full=True, size=None)
    controls = window.viewport_panel.controls
    play = window.findChild(QAction, "actionPlay")
    rig = window.findChild(QWidget, "rigEditorView")
    rig.setFocus()
    controls.play_button.click()
    assert controls.playing and play.text() == "Pause"
    qtbot.waitUntil(lambda: window.ctx.frame > 2)
    qtbot.keyClick(rig, Qt.Key.Key_Space)
    assert not controls.playing and not window.playback.playing
    assert play.text() == "Play" and controls.play_button.text() == "Play"
    frame = window.ctx.frame
    qtbot.wait(60)
    assert window.ctx.frame == frame                      # really paused
    qtbot.keyClick(rig, Qt.Key.Key_Space)                 # Space again plays the timeline
    assert window.playback.playing and not controls.playing
    window.playback.pause()
    controls.play_button.click()
    window.findChild(QAction, "actionStop").trigger()
    assert not controls.playing and not window.playback.playing
