"""Cloth off the UI thread: the cache worker and the live cloths (document/cloth_worker.py)."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

from qtanimator.core.cloth import Cloth, ClothParams
from qtanimator.document import Document, SetParameter, UndoStack
from qtanimator.document.cloth import add_cloth_command, cloth_cache, set_cloth_param_command
from qtanimator.document.cloth_worker import ClothWorker, LiveCloths, cloth_invalidations, cloth_worker
from qtanimator.document.commands import RemoveAsset
from qtanimator.document.document import DocumentChange

#: A flag like the demo's: wind, gusts (turbulence), custom pins, ground.
FLAG = ClothParams(rows=8, cols=10, width=1.2, height=0.8, total_mass=1.0, wind=(6.0, 0.0, 0.8),
                   turbulence=0.5, turbulence_seed=3, pin_mode="custom", custom_pins=[0, 10, 20, 30],
                   substeps=16, origin=(0.0, 1.5, 0.0), integrator="symplectic")
DT = 1.0 / 60.0


def sync_frames(params: ClothParams, count: int, dt: float = DT) -> list[np.ndarray]:
    """What the synchronous cache computes: the rest frame and ``count − 1`` steps."""
    cloth = Cloth(params)
    frames = [cloth.positions.copy()]
    for _ in range(count - 1):
        cloth.step(dt)
        frames.append(cloth.positions.copy())
    return frames


def make_doc(params: ClothParams = FLAG, frame_end: int = 30) -> tuple[Document, UndoStack]:
    doc = Document()
    stack = UndoStack(doc)
    stack.push(SetParameter(doc, "frame_end", frame_end))
    stack.push(add_cloth_command(doc, params, asset_id="flag"))
    return doc, stack


@pytest.fixture
def worker_doc():
    doc, stack = make_doc()
    worker = ClothWorker(doc)
    yield worker, doc, stack
    worker.close()


def assert_frames_equal(frames: list[np.ndarray], expected: list[np.ndarray]) -> None:
    assert len(frames) == len(expected)
    for k, (a, b) in enumerate(zip(frames, expected)):
        assert np.array_equal(a, b), f"frame {k} differs"


def test_worker_fills_the_cache_with_the_frames_of_a_synchronous_run(worker_doc) -> None:
    worker, doc, _stack = worker_doc
    assert worker.wait(60)
    cache = cloth_cache(doc, "flag")
    assert cache.cached_frames == 31            # frame_start … frame_end
    assert_frames_equal(cache.frames, sync_frames(FLAG, 31))
    (progress,) = worker.progress()
    assert progress.asset_id == "flag" and progress.done == progress.wanted == 31
    assert not progress.running and progress.fraction == 1.0 and not progress.error


def test_cancel_and_resume_give_identical_frames(worker_doc) -> None:
    worker, doc, _stack = worker_doc
    cache = cloth_cache(doc, "flag")
    for _ in range(5):                          # stop and go at whatever points the timing gives
        worker.cancel()
        stopped = cache.cached_frames
        (progress,) = worker.progress()
        assert progress.cancelled or progress.done == progress.wanted
        time.sleep(0.01)
        assert cache.cached_frames <= stopped + 1   # at most the step that was in flight lands
        worker.resume()
        time.sleep(0.005)
    assert worker.wait(60)
    assert_frames_equal(cache.frames, sync_frames(FLAG, 31))


def test_a_step_cancelled_between_substeps_is_undone_and_redone_identically() -> None:
    cache_doc, _ = make_doc(FLAG.replace(integrator="implicit", substeps=4))
    cache = cloth_cache(cache_doc, "flag")
    calls = []

    def stop_at_third_substep() -> bool:
        calls.append(1)
        return len(calls) == 3

    assert cache.fill(4)
    before = cache.cloth.state()
    assert not cache.step_frame(stop_at_third_substep)      # cancelled inside the step
    assert cache.cached_frames == 4
    after = cache.cloth.state()
    assert np.array_equal(before.positions, after.positions)
    assert np.array_equal(before.velocities, after.velocities) and before.time == after.time
    assert cache.fill(12)
    assert_frames_equal(cache.frames, sync_frames(FLAG.replace(integrator="implicit", substeps=4), 12))


def test_cancelling_interrupts_a_long_step_quickly() -> None:
    # A stiff implicit cloth: one frame takes long; cancel answers between two substeps.
    stiff = FLAG.replace(rows=16, cols=16, custom_pins=[0, 16, 32], integrator="implicit",
                         structural_stiffness=1.0e6, substeps=32)
    doc, _ = make_doc(stiff, frame_end=240)
    worker = ClothWorker(doc)
    try:
        deadline = time.monotonic() + 30
        while not (worker.progress()[0].elapsed > 0.05) and time.monotonic() < deadline:
            time.sleep(0.01)
        t0 = time.monotonic()
        worker.cancel()
        assert worker.wait(10)
        assert time.monotonic() - t0 < 5.0   # generous: the machine may be busy
        (progress,) = worker.progress()
        assert progress.cancelled and not progress.running and progress.done < 241
    finally:
        worker.close()


def test_a_parameter_change_restarts_on_the_rebuilt_cache_and_undo_too(worker_doc) -> None:
    worker, doc, stack = worker_doc
    old = cloth_cache(doc, "flag")
    stack.push(set_cloth_param_command(doc, "flag", "integrator", "implicit"))
    new = cloth_cache(doc, "flag")
    assert new is not old
    assert worker.wait(60)
    assert_frames_equal(new.frames, sync_frames(FLAG.replace(integrator="implicit"), 31))
    stack.undo()
    assert worker.wait(60)
    assert_frames_equal(cloth_cache(doc, "flag").frames, sync_frames(FLAG, 31))


def test_cancelled_work_restarts_when_a_parameter_changes(worker_doc) -> None:
    worker, doc, stack = worker_doc
    worker.cancel()
    stack.push(set_cloth_param_command(doc, "flag", "wind", [0.0, 0.0, 3.0]))
    assert worker.wait(60)
    assert_frames_equal(cloth_cache(doc, "flag").frames, sync_frames(FLAG.replace(wind=(0.0, 0.0, 3.0)), 31))


def test_frame_grid_and_range_changes(worker_doc) -> None:
    worker, doc, stack = worker_doc
    assert worker.wait(60)
    stack.push(SetParameter(doc, "frame_end", 40))          # more frames wanted, none invalid
    cache = cloth_cache(doc, "flag")
    assert worker.wait(60)
    assert cloth_cache(doc, "flag") is cache and cache.cached_frames == 41
    stack.push(SetParameter(doc, "fps", 30.0))              # a new frame grid: rebuilt
    assert worker.wait(60)
    assert_frames_equal(cloth_cache(doc, "flag").frames, sync_frames(FLAG, 41, 1.0 / 30.0))


def test_a_view_may_ask_for_frames_past_the_range(worker_doc) -> None:
    worker, doc, _stack = worker_doc
    worker.request("flag", 45.5)
    assert worker.wait(60)
    cache = cloth_cache(doc, "flag")
    assert cache.cached_frames == 46
    positions, exact = cache.latest(45)
    assert exact and np.array_equal(positions, sync_frames(FLAG, 46)[45])
    positions, exact = cache.latest(80)
    assert not exact and positions is cache.frames[-1]


def test_removed_cloths_are_dropped_and_new_ones_filled(worker_doc) -> None:
    worker, doc, stack = worker_doc
    stack.push(add_cloth_command(doc, FLAG.replace(wind=(0.0, 0.0, -2.0)), asset_id="sail"))
    stack.push(RemoveAsset(doc, "flag"))
    assert worker.wait(60)
    assert [p.asset_id for p in worker.progress()] == ["sail"]
    assert_frames_equal(cloth_cache(doc, "sail").frames, sync_frames(FLAG.replace(wind=(0.0, 0.0, -2.0)), 31))


def test_a_blow_up_stops_the_work_and_says_why() -> None:
    doc, _ = make_doc(FLAG.replace(structural_stiffness=1.0e4, substeps=1))
    worker = ClothWorker(doc)
    try:
        assert worker.wait(60)
        (progress,) = worker.progress()
        assert not progress.running and "substeps" in progress.error
        assert progress.done < 31
    finally:
        worker.close()


def test_document_replaced_resyncs(worker_doc) -> None:
    worker, doc, _stack = worker_doc
    other, _ = make_doc(FLAG.replace(gravity=3.0), frame_end=10)
    doc.replace_all(other)
    assert worker.wait(60)
    assert_frames_equal(cloth_cache(doc, "flag").frames, sync_frames(FLAG.replace(gravity=3.0), 11))


def test_invalidations_map_changes_to_cloths() -> None:
    doc, _ = make_doc()
    doc.apply_asset("other", None)
    assert cloth_invalidations(doc, DocumentChange(parameters=frozenset({"fps"}))) == {"flag": -math.inf}
    assert cloth_invalidations(doc, DocumentChange(parameters=frozenset({"light1.position"}))) == {}
    assert cloth_invalidations(doc, DocumentChange(assets=frozenset({"flag"}))) == {"flag": -math.inf}
    assert cloth_invalidations(doc, DocumentChange(assets=frozenset({"gone"}))) == {"gone": -math.inf}
    assert cloth_invalidations(doc, DocumentChange(channels={"arm/elbow/x": 0.5})) == {}
    assert cloth_invalidations(doc, DocumentChange(reset=True)) == {"flag": -math.inf}


def test_the_worker_thread_stops_on_close() -> None:
    doc, _ = make_doc(frame_end=2000)
    worker = cloth_worker(doc)
    assert doc.caches["cloths"] is worker and cloth_worker(doc) is worker
    assert worker.alive and worker.busy
    worker.shutdown()
    assert not worker.alive and not worker.busy
    revision = worker.revision
    worker.request("flag", 10)          # more work starts the thread again
    assert worker.alive
    worker.close()
    assert worker.closed and not worker.alive and worker.revision >= revision


# ------------------------------------------------------------------ live cloths
def test_live_cloths_step_on_their_thread_and_publish_snapshots() -> None:
    doc, _ = make_doc()
    live = LiveCloths()
    try:
        live.sync(doc)
        assert set(live.cloths) == {"flag"} and live.frame("flag") is not None
        live.enabled = True
        deadline = time.monotonic() + 10
        while live.frame("flag").time < 0.1 and time.monotonic() < deadline:
            time.sleep(0.01)
        live.paused = True
        assert live.settle()
        cloth = live.cloths["flag"]
        snap = live.frame("flag")
        assert snap.time == cloth.time > 0.1
        assert np.array_equal(snap.positions, cloth.positions) and snap.positions is not cloth.positions
        assert abs(cloth.time / live.dt - round(cloth.time / live.dt)) < 1e-6
    finally:
        live.close()


def test_live_edits_never_wait_for_a_step_and_keep_their_order() -> None:
    doc, _ = make_doc()
    live = LiveCloths()
    try:
        live.sync(doc)
        cloth = live.cloths["flag"]
        start = cloth.pin_targets.copy()
        with live._sim:                      # a step in flight on another thread
            t0 = time.monotonic()
            live.move_pins((0.1, 0.0, 0.0))
            live.move_pins((0.0, 0.2, 0.0))
            assert time.monotonic() - t0 < 0.5
            assert np.array_equal(cloth.pin_targets, start)     # queued, not applied yet
        live.step()                          # the queue is applied before the next step
        assert np.allclose(cloth.pin_targets, start + [0.1, 0.2, 0.0])
        hit = live.grab(np.array([5.0, 1.5, 0.0]), np.array([-1.0, 0.0, 0.0]))
        assert hit is not None and hit[0] == "flag" and cloth.grabbed is not None
        live.drag_grabbed("flag", hit[1] + [0.0, 0.0, 0.3])
        live.step()
        live.release()
        assert cloth.grabbed is None
        live.reset()
        assert cloth.time == 0.0 and np.array_equal(cloth.pin_targets, start)
        doc2, _ = make_doc(FLAG.replace(gravity=2.0))
        live.sync(doc2)
        assert live.cloths["flag"].params.gravity == 2.0
        live.clear()
        assert live.cloths == {} and live.frames() == {}
    finally:
        live.close()


def test_live_cloth_with_invalid_parameters_is_reported_not_replaced_by_defaults() -> None:
    """A cloth whose stored parameters cannot make a cloth gets no live simulation with made-up
    (default) parameters: the problem is in ``errors`` (the Cloth dock shows it)."""
    from qtanimator.document.commands import SetAssetProperty

    doc, stack = make_doc(FLAG.replace(gravity=2.0))
    live = LiveCloths()
    try:
        live.sync(doc)
        live.step()
        assert live.cloths["flag"].params.gravity == 2.0 and "flag" not in live.errors
        stack.push(SetAssetProperty(doc, "flag", "rows", -3))
        live.sync(doc)
        live.step()
        assert "flag" not in live.cloths
        assert "flag" in live.errors and "rows" in live.errors["flag"]
        stack.undo()
        live.sync(doc)
        live.step()
        assert live.cloths["flag"].params.gravity == 2.0 and "flag" not in live.errors
    finally:
        live.close()
