"""A pendulum simulation that blows up stops at its last good frame and says why."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from qtanimator.document import character2d as c2d
from qtanimator.document.commands import SetParameter, UndoStack
from qtanimator.document.document import Document

CLOCK = Path(__file__).resolve().parents[2] / "scenes" / "pendulum_clock.svg"


@pytest.fixture
def clock():
    doc = Document()
    stack = UndoStack(doc)
    stack.push(c2d.add_characters_command(doc, CLOCK))
    asset = next(iter(doc.assets))
    assert doc.runtime[asset].dynamic.any()
    yield doc, stack, asset
    c2d.simulation(doc).shutdown()


@pytest.mark.parametrize("name, value, parameter", [("damping", -200.0, "damping"), ("g", 1e12, "step")])
def test_a_blow_up_stops_at_the_last_good_frame_and_names_the_setting(clock, name, value, parameter):
    doc, stack, asset = clock
    sim = c2d.simulation(doc)
    assert sim.problem(asset) is None
    theta_ok = sim.state(asset, 60)[0].copy()
    # beyond the schema's range (validate=False): what a hand-written project could hold
    stack.push(SetParameter(doc, f"{asset}.pendulum.{name}", value, validate=False))
    last_theta, _omega = sim.state(asset, 200)  # returns instead of simulating garbage
    report = sim.problem(asset)
    assert report is not None and report.parameter == parameter
    good = sim.cached_frames(asset)
    assert 0 < good < 200
    assert report.time == pytest.approx((doc.frame_range[0] + good) / doc.fps)
    # Nothing non-finite is kept: every cached frame is finite, and reads beyond stay at the last one.
    for f in range(good):
        assert np.isfinite(sim.state(asset, f)[0]).all()
    np.testing.assert_array_equal(last_theta, sim.state(asset, good - 1)[0])
    np.testing.assert_array_equal(sim.latest_state(asset, 150)[0], last_theta)
    assert c2d.pendulum_problems(doc) == {asset: report}
    # Undoing the setting clears the report and the simulation runs through again, as before.
    stack.undo()
    assert sim.problem(asset) is None
    np.testing.assert_array_equal(sim.state(asset, 60)[0], theta_ok)
    sim.state(asset, 200)
    assert sim.problem(asset) is None and sim.cached_frames(asset) > 200  # the worker may be ahead


def test_the_worker_stops_too_and_reports(clock):
    doc, stack, asset = clock
    sim = c2d.simulation(doc)
    stack.push(SetParameter(doc, f"{asset}.pendulum.damping", -200.0, validate=False))
    sim.latest_state(asset, 150)  # a view asks: the worker fills in the background
    assert sim.wait_idle(30.0)
    assert sim.problem(asset) is not None
    assert sim.cached_frames(asset) < 150


def test_workers_wait_while_a_gesture_is_in_progress(clock):
    """pause_workers (the editor context calls it while a drag is in progress) holds every
    worker between frames; resume_workers lets it catch up."""
    import threading
    import time

    from qtanimator.document.simulation import pause_workers, resume_workers, workers_paused

    doc, _stack, asset = clock
    sim = c2d.simulation(doc)
    pause_workers()
    try:
        assert workers_paused()
        sim.latest_state(asset, 120)  # a view asks for frame 120: the worker is woken ...
        deadline = time.monotonic() + 0.5
        while time.monotonic() < deadline:  # ... but steps nothing while paused
            assert sim.cached_frames(asset) <= 1, "a paused worker simulated frames"
            threading.Event().wait(0.02)
    finally:
        resume_workers()
    assert not workers_paused()
    assert sim.wait_idle(30.0)
    assert sim.cached_frames(asset) >= 121


def test_the_issues_hostile_settings_end_in_a_report_not_a_hang(clock):
    """g = 1e9 with damping −1e9 blows up at once and says so; adding a step of 1e-9 s (16 M
    steps a frame) is refused as settings, so the preset's step is used instead of hanging."""
    from qtanimator.core.pendulum import MIN_STEP, PendulumParams

    doc, stack, asset = clock
    sim = c2d.simulation(doc)
    stack.push(SetParameter(doc, f"{asset}.pendulum.g", 1e9, validate=False))
    stack.push(SetParameter(doc, f"{asset}.pendulum.damping", -1e9, validate=False))
    sim.state(asset, 30)
    report = sim.problem(asset)
    assert report is not None and report.parameter == "damping" and sim.cached_frames(asset) < 30
    with pytest.raises(ValueError, match="at least"):
        PendulumParams(step=MIN_STEP / 2)
    stack.push(SetParameter(doc, f"{asset}.pendulum.step", 1e-9, validate=False))
    assert c2d.pendulum_params(doc, asset).step >= MIN_STEP
    sim.state(asset, 30)  # finishes: the refused settings fall back to the preset
