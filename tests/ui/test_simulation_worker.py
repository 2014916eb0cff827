"""The pendulums in the real main window (the demo project): a right-drag at frame 200 never
simulates on the UI thread and restarts the worker at most once per change, the rig editor
shows the latest state and repaints as the worker catches up, the timeline's cache bar shows
the simulated frames, and closing the window stops the worker. No wall-clock asserts."""

from __future__ import annotations

import threading

import numpy as np
import pytest
from PySide6.QtCore import QEvent, QPoint, Qt
from PySide6.QtWidgets import QApplication, QWidget
from rig_helpers import hand_point, open_demo, send_mouse

from qtanimator.document import character2d as c2d
from qtanimator.document.document import DocumentChange
from qtanimator.document.simulation import running_workers, shutdown_all
from qtanimator.ui.timeline import CACHE_COLOR, CacheBar

TIMEOUT_MS = 60_000  # a safety net against hangs, never a performance assertion


@pytest.fixture
def demo(make_window, qtbot):
    window, view = open_demo(make_window, qtbot)
    yield window, view
    shutdown_all()
    assert running_workers() == []


def ui_steps(sim: c2d.PendulumCache) -> int:
    return sim.steps_by_thread.get(threading.get_ident(), 0)


def test_a_drag_at_frame_200_never_simulates_on_the_ui_thread(demo, qtbot):
    window, view = demo
    doc, ctx = window.doc, window.ctx
    sim = c2d.simulation(doc)
    ctx.set_frame(200)
    view.viewport().repaint()
    qtbot.waitUntil(lambda: not sim.busy, timeout=TIMEOUT_MS)
    changes: list[DocumentChange] = []
    doc.subscribe(changes.append)
    restarts, invalidations, steps = sim.restarts, sim.invalidations, sim.steps_taken
    assert ui_steps(sim) == 0
    press = hand_point(window, view)
    send_mouse(view, QEvent.Type.MouseButtonPress, press, Qt.MouseButton.RightButton, Qt.MouseButton.RightButton)
    moves = 8
    for i in range(1, moves + 1):
        send_mouse(view, QEvent.Type.MouseMove, press + QPoint(2 * i, -i), Qt.MouseButton.NoButton,
                   Qt.MouseButton.RightButton)
        view.viewport().repaint()  # the frame drawn after this move: poses, HUD, onion skin
        QApplication.processEvents()
    send_mouse(view, QEvent.Type.MouseButtonRelease, press + QPoint(2 * moves, -moves),
               Qt.MouseButton.RightButton, Qt.MouseButton.NoButton)
    assert ctx.undo_stack.count() == 1 and len(changes) == moves  # one change per move
    assert ui_steps(sim) == 0  # every pendulum step of the drag ran on the worker thread
    assert sim.restarts - restarts <= len(changes)
    assert sim.invalidations - invalidations <= len(changes)  # one character per change
    # The worker catches up; the editor then shows exactly the synchronous frame.
    qtbot.waitUntil(lambda: not sim.busy and c2d.simulation_ready(doc, ctx.time), timeout=TIMEOUT_MS)
    assert sim.steps_taken > steps
    view.viewport().repaint()
    assert np.array_equal(view.poses()["pip"].world, c2d.evaluate_pose(doc, "pip", ctx.time).world)
    assert ui_steps(sim) == 0


def test_the_editor_shows_the_latest_state_and_repaints_as_frames_arrive(demo, qtbot):
    window, view = demo
    doc, ctx = window.doc, window.ctx
    sim = c2d.simulation(doc)
    qtbot.waitUntil(lambda: not sim.busy, timeout=TIMEOUT_MS)
    held: list[int] = []
    wake = sim.worker.wake
    sim.worker.wake = lambda: held.append(1)  # the worker is slow today: it does nothing yet
    sim.invalidate()  # start from nothing simulated
    t = 150 / doc.fps
    ctx.set_frame(150)
    view.viewport().repaint()
    assert held and sim.cached_frames("pip") == 0 and ui_steps(sim) == 0
    lantern = doc.runtime["pip"].joint_index("lantern")
    start = c2d.simulation(doc).latest_state("pip", 0)[0][lantern]
    assert view.poses()["pip"].world_angles[lantern] == pytest.approx(start, abs=1e-12)  # keyed start
    assert view._simulation_pending
    drawn = view.frames_drawn
    sim.worker.wake = wake
    wake()
    # No frame change, no edit: only the simulation's progress repaints the editor.
    qtbot.waitUntil(lambda: not view._simulation_pending, timeout=TIMEOUT_MS)
    assert view.frames_drawn > drawn
    assert view._poses_exact
    assert np.array_equal(view.poses()["pip"].world, c2d.evaluate_pose(doc, "pip", t).world)
    assert ui_steps(sim) == 0


def test_the_cache_bar_shows_the_simulated_frames(demo, qtbot):
    window, view = demo
    doc, ctx = window.doc, window.ctx
    timeline = window.findChild(QWidget, "timeline")
    bar = window.findChild(QWidget, "cacheBar")
    assert isinstance(bar, CacheBar) and bar.parent() is timeline
    assert bar.geometry().top() >= timeline.height() - 6  # a strip under the ruler
    sim = c2d.simulation(doc)
    progressed: list[int] = []
    ctx.simulationProgressed.connect(lambda: progressed.append(1))
    refreshes = bar.refreshes
    ctx.set_frame(100)
    view.viewport().repaint()
    qtbot.waitUntil(lambda: not sim.busy and bar.simulated() == c2d.simulated_frames(doc), timeout=TIMEOUT_MS)
    first, last = bar.simulated()
    assert first == 0 and last >= 100
    assert bar.toolTip() == f"Simulated frames 0–{last}"
    # Updated at most once per progress report (once per frame) plus once per document change.
    assert bar.refreshes - refreshes <= len(progressed) + 1
    image = bar.grab().toImage()
    y = bar.height() // 2
    assert image.pixelColor(int(timeline.frame_to_x(50)), y) == CACHE_COLOR
    assert image.pixelColor(int(timeline.frame_to_x(min(last + 20, 240))), y) != CACHE_COLOR
    # An edit at frame 200 drops Pip's frames from its previous key but one (2 s = frame 120).
    sim.worker.wake = lambda: None  # keep the worker from refilling while we look
    pip = doc.runtime["pip"]
    ctx.push(c2d.key_joint(doc, "pip", pip.joint_index("upper_arm_right"), 0.9, 200 / doc.fps))
    assert bar.simulated() == (0, 119)
    assert bar.toolTip() == "Simulated frames 0–119"


def test_closing_the_window_stops_the_worker(demo, qtbot):
    window, view = demo
    sim = c2d.simulation(window.doc)
    window.ctx.set_frame(120)
    view.viewport().repaint()
    assert sim.worker.alive
    window.close()
    assert not sim.worker.alive


def test_the_ui_thread_is_busy_while_it_handles_events_and_idle_while_it_waits(qtbot):
    """The gate the workers wait on (document.simulation.ui_idle): an event being handled
    marks the UI thread busy; an event loop waiting for events marks it idle."""
    import time

    from qtanimator.document import simulation as gate
    from qtanimator.ui.context import gate_workers_on_idle

    assert gate_workers_on_idle()
    seen: list[bool] = []

    class Probe(QWidget):
        def event(self, e):  # type: ignore[no-untyped-def]
            if e.type() == QEvent.Type.User:
                seen.append(gate._UI_IDLE.is_set())
            return super().event(e)

    probe = Probe()
    gate.ui_idle()
    QApplication.postEvent(probe, QEvent(QEvent.Type.User))
    qtbot.waitUntil(lambda: bool(seen))
    assert seen == [False]
    samples: list[bool] = []
    stop = threading.Event()

    def sample() -> None:
        while not stop.is_set():
            samples.append(gate._UI_IDLE.is_set())
            time.sleep(0.001)

    sampler = threading.Thread(target=sample)
    sampler.start()
    qtbot.wait(150)  # an event loop with nothing to do
    stop.set()
    sampler.join()
    assert any(samples)
