"""The pendulum simulation off the UI thread: the worker fills the cache with exactly the
frames a synchronous run computes, can be cancelled and restarted, edits invalidate from the
earliest affected time (never from 0 when a key has earlier keys), a frame computed from a
state an edit dropped never enters the cache, and latest-state reads never simulate.

No wall-clock asserts: waits have generous timeouts only so that a bug fails instead of
hanging.
"""

from __future__ import annotations

import gc
import math
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from qtanimator.core.channel import Channel, Key
from qtanimator.document import Document, SetKeys, UndoStack, open_document
from qtanimator.document.character2d import (
    PendulumCache,
    add_characters_command,
    angle_channel_id,
    character,
    evaluate_pose,
    key_joint,
    keyframed_angles,
    simulated_frames,
    simulation,
    simulation_ready,
)
from qtanimator.document.simulation import SimulationWorker, progress, running_workers, shutdown_all

SCENES = Path(__file__).resolve().parents[2] / "scenes"
DEMO = SCENES / "demo" / "demo.qtanim"
WAIT = 60.0  # seconds: a safety net against hangs, never a performance assertion


@pytest.fixture(autouse=True)
def no_threads_left() -> Iterator[None]:
    yield
    shutdown_all()
    assert running_workers() == []


@pytest.fixture(scope="module")
def demo_source() -> Document:
    return open_document(DEMO)


@pytest.fixture
def demo(demo_source: Document) -> Callable[[], Document]:
    """A fresh document with the demo's 2D characters with pendulums (Pip and the clock),
    their keys and parameters; characters and channels are shared (both are read-only)."""

    def make() -> Document:
        aids = ("pip", "pendulum_clock")
        doc = Document(parameters=demo_source.parameters,
                       channels={cid: ch for cid, ch in demo_source.channels.items() if cid.split("/", 1)[0] in aids})
        for aid in aids:
            doc.assets[aid] = demo_source.assets[aid].copy()
            doc.runtime[aid] = demo_source.runtime[aid]
        return doc

    return make


def owl_doc(shared_data: Path) -> tuple[Document, str]:
    """owl.svg (86 pendulums) with keys on its root translation and on one pendulum."""
    doc = Document()
    stack = UndoStack(doc)
    stack.push(add_characters_command(doc, shared_data / "cmu-animator" / "scenes" / "owl.svg"))
    aid = next(iter(doc.assets))
    ch = character(doc, aid)
    pendulum = int(np.flatnonzero(ch.dynamic)[0])
    stack.push(SetKeys(doc, {f"{aid}//x": Key(0.0, 0.0), f"{aid}//y": Key(0.0, 0.0),
                             angle_channel_id(aid, ch.joints[pendulum].name): Key(0.0, 0.6)}))
    stack.push(SetKeys(doc, {f"{aid}//x": Key(0.5, 80.0), f"{aid}//y": Key(0.5, -30.0)}))
    stack.push(SetKeys(doc, {f"{aid}//x": Key(1.0, -60.0), f"{aid}//y": Key(1.0, 10.0)}))
    return doc, aid


def frames_of(cache: PendulumCache, aid: str, count: int) -> list[tuple[np.ndarray, np.ndarray]]:
    return [cache.state(aid, f) for f in range(count)]


def assert_same_frames(a: list[tuple[np.ndarray, np.ndarray]], b: list[tuple[np.ndarray, np.ndarray]]) -> None:
    assert len(a) == len(b)
    for f, ((ta, oa), (tb, ob)) in enumerate(zip(a, b)):
        assert np.array_equal(ta, tb) and np.array_equal(oa, ob), f"frame {f} differs"


def main_thread_steps(cache: PendulumCache) -> int:
    return cache.steps_by_thread.get(threading.get_ident(), 0)


# ------------------------------------------------------------------ exactness
def test_worker_frames_equal_a_synchronous_run_owl(shared_data: Path) -> None:
    doc, aid = owl_doc(shared_data)
    ref, _ = owl_doc(shared_data)
    cache = simulation(doc)
    assert cache is doc.caches["pendulums"]
    # A view asks for frame 30: nothing is simulated on this thread, the worker fills.
    cache.LOOKAHEAD = 0.0
    theta, omega, shown = cache.latest_state(aid, 30)
    assert shown == 0 and main_thread_steps(cache) == 0
    assert cache.wait_idle(WAIT)
    assert cache.cached_frames(aid) == 31
    assert main_thread_steps(cache) == 0 and cache.steps_taken == 30 * 10
    assert_same_frames(frames_of(cache, aid, 31), frames_of(simulation(ref), aid, 31))


def test_worker_can_be_cancelled_and_restarted(demo: Callable[[], Document]) -> None:
    doc = demo()
    ref = demo()
    cache = simulation(doc)
    # Hold the cache's lock: the worker blocks inside its first job call, so the cancel
    # lands mid-run whatever the machine's speed.
    with cache._lock:
        cache._request(doc, "pip", 200, 0)
        cache.worker.wake()
        started = threading.Event()
        for _ in range(6000):
            if cache.worker._running:
                break
            started.wait(0.01)
        assert cache.worker._running == 1 and cache.worker.runs == 1
        cache.worker.cancel()
    assert cache.wait_idle(WAIT)
    runs = cache.worker.runs
    assert cache.cached_frames("pip") <= 2  # at most the frame in flight was finished
    # Asked again, it restarts from where it stopped and fills up to the target.
    cache.latest_state("pip", 200)
    assert cache.wait_idle(WAIT)
    assert cache.worker.runs == runs + 1
    assert cache.cached_frames("pip") == 241  # 200 + one second of look-ahead, capped at frame_end
    assert main_thread_steps(cache) == 0
    assert_same_frames(frames_of(cache, "pip", 241), frames_of(simulation(ref), "pip", 241))


# ---------------------------------------------------------------- invalidation
def test_an_edit_at_frame_200_invalidates_from_the_previous_key_not_from_zero(demo: Callable[[], Document]) -> None:
    doc = demo()
    stack = UndoStack(doc)
    cache = simulation(doc)
    cache.state("pip", 200)
    assert cache.cached_frames("pip") == 201
    invalidations, restarts = cache.invalidations, cache.restarts
    ch = character(doc, "pip")
    arm = ch.joint_index("upper_arm_right")  # keys at 0, 1, 2, 3, 4 s
    t = 200 / doc.fps
    stack.push(key_joint(doc, "pip", arm, 0.9, t))
    # The new key at 3.33 s changes the spline from the key two before it (2 s) on.
    assert cache.cached_frames("pip") == 120
    assert cache.invalidations == invalidations + 1
    assert cache.restarts == restarts  # nothing asked for frames: no worker to restart
    steps = cache.steps_taken
    cache.state("pip", 200)
    assert cache.steps_taken - steps == (200 - 120 + 1) * 10  # not 200 frames again
    # And the refilled frames are those of a document that always had the key.
    fresh = demo()
    UndoStack(fresh).push(key_joint(fresh, "pip", arm, 0.9, t))
    assert_same_frames(frames_of(cache, "pip", 201), frames_of(simulation(fresh), "pip", 201))


def test_one_invalidation_and_at_most_one_restart_per_change(demo: Callable[[], Document]) -> None:
    doc = demo()
    stack = UndoStack(doc)
    cache = simulation(doc)
    cache.latest_state("pip", 100)
    assert cache.wait_idle(WAIT)
    ch = character(doc, "pip")
    keys = {angle_channel_id("pip", j.name): Key(2.5, 0.1 * i)
            for i, j in enumerate(ch.joints) if not j.is_dynamic}
    assert len(keys) >= 8
    invalidations, restarts, runs = cache.invalidations, cache.restarts, cache.worker.runs
    stack.push(SetKeys(doc, keys))  # one command, many channels of one character
    assert cache.invalidations == invalidations + 1
    assert cache.restarts == restarts + 1
    assert cache.wait_idle(WAIT)
    assert cache.worker.runs <= runs + 1
    assert main_thread_steps(cache) == 0


@pytest.mark.parametrize("refill", [False, True], ids=["in-flight-frame", "refilled-behind-it"])
def test_a_frame_computed_from_a_dropped_state_never_enters_the_cache(demo: Callable[[], Document],
                                                                    refill: bool) -> None:
    """The worker finishes frame N from the old keys while an edit invalidates it: the
    generation check must throw that frame away (also when the cache was refilled up to N
    on the UI thread meanwhile, so that the frame count alone would let it in)."""
    doc = demo()
    cache = simulation(doc)
    lantern = character(doc, "pip").joint_index("lantern")
    cid = angle_channel_id("pip", "lantern")
    assert cid not in doc.channels
    # A key at 0 with the rest angle: the start state is what it was without the channel.
    doc.apply_channel(cid, Channel([Key(0.0, 0.0)]))
    paused, resume = threading.Event(), threading.Event()
    stall_at = 100 if refill else 60  # the worker computes frame stall_at from stall_at - 1
    advance: Callable[..., Any] = cache._advance

    def stalling_advance(doc_: Document, aid: str, sim: Any, frame: int, *args: Any) -> Any:
        result = advance(doc_, aid, sim, frame, *args)
        if frame + 1 == stall_at and threading.current_thread() is not threading.main_thread():
            paused.set()
            assert resume.wait(WAIT)
        return result

    cache._advance = stalling_advance  # type: ignore[method-assign]
    cache.LOOKAHEAD = 0.0
    cache.latest_state("pip", 150)
    assert paused.wait(WAIT)
    assert cache.cached_frames("pip") == stall_at
    # A key on the lantern at 1 s (frame 60) poses it there: frames from 60 on change.
    doc.apply_channel(cid, Channel([Key(0.0, 0.0), Key(1.0, 0.8)]), time_from=1.0)
    assert cache.cached_frames("pip") == 60
    if refill:
        cache.state("pip", stall_at - 1)  # the UI thread refills up to the stalled frame
        assert cache.cached_frames("pip") == stall_at
    resume.set()
    assert cache.wait_idle(WAIT)
    assert cache.state("pip", 60)[0][lantern] == 0.8
    ref = demo()
    ref.apply_channel(cid, Channel([Key(0.0, 0.0), Key(1.0, 0.8)]), time_from=-math.inf)
    assert_same_frames(frames_of(cache, "pip", 151), frames_of(simulation(ref), "pip", 151))


# -------------------------------------------------------------- latest reads
def test_a_view_gets_the_latest_state_without_stepping(demo: Callable[[], Document]) -> None:
    doc = demo()
    cache = simulation(doc)
    woken: list[int] = []
    cache.worker.wake = lambda: woken.append(1)  # type: ignore[method-assign]
    t = 150 / doc.fps
    assert not simulation_ready(doc, t)
    pose = evaluate_pose(doc, "pip", t, block=False)
    assert cache.steps_taken == 0 and woken  # the worker was asked, nothing was stepped here
    # Keyframed joints are exact; the lantern shows the keyed start state (nothing simulated).
    exact_keyed = keyframed_angles(doc, "pip", t)
    ch = character(doc, "pip")
    for k, j in enumerate(ch.joints):
        if not j.is_dynamic and not ch.dynamic[ch.ancestors(k)].any():
            assert pose.angles[k] == exact_keyed[k]
    theta, _omega, shown = cache.latest_state("pip", 150)
    assert shown == 0 and cache.steps_taken == 0
    # Some frames simulated: the last one at or before the frame asked for is shown.
    cache.state("pip", 40)
    theta, omega, shown = cache.latest_state("pip", 150)
    assert shown == 40
    assert np.array_equal(theta, cache.state("pip", 40)[0])
    steps = cache.steps_taken
    assert np.array_equal(cache.world_angles("pip", t, wait=False), theta)
    assert cache.steps_taken == steps
    # Once simulated, latest reads are exact.
    cache.state("pip", 150)
    assert cache.ready("pip", t) and not simulation_ready(doc, t)  # the clock is not simulated
    cache.state("pendulum_clock", 150)
    assert simulation_ready(doc, t)
    assert np.array_equal(evaluate_pose(doc, "pip", t, block=False).world, evaluate_pose(doc, "pip", t).world)
    between = (150.5) / doc.fps
    assert not cache.ready("pip", between)
    assert np.array_equal(cache.world_angles("pip", between, wait=False), cache.state("pip", 150)[0])


def test_simulated_frames_and_progress(demo: Callable[[], Document]) -> None:
    doc = demo()
    assert simulated_frames(doc) == (0, -1)  # pendulum characters, nothing simulated yet
    cache = simulation(doc)
    revision = progress(doc)[0]
    cache.state("pip", 30)
    cache.state("pendulum_clock", 10)
    assert simulated_frames(doc) == (0, 10)
    assert progress(doc) == (revision + 31 + 11, False)
    only_robot = Document()
    UndoStack(only_robot).push(add_characters_command(only_robot, SCENES / "robot"))
    assert simulated_frames(only_robot) is None and simulation_ready(only_robot, 3.0)


# ------------------------------------------------------------------- lifetime
def test_the_worker_stops_when_the_document_is_replaced_or_dropped(demo: Callable[[], Document]) -> None:
    doc = demo()
    cache = simulation(doc)
    cache.latest_state("pip", 100)
    assert cache.worker.alive
    doc.replace_all(demo())  # File > Open: DocumentChange(reset=True)
    assert not cache.worker.alive and cache.cached_frames("pip") == 0
    # Asked again, it starts again; dropping the document ends the thread.
    cache.latest_state("pip", 100)
    worker: SimulationWorker = cache.worker
    thread = worker._thread
    assert thread is not None and thread.is_alive()
    del doc, cache
    gc.collect()
    thread.join(WAIT)
    assert not thread.is_alive()


def test_a_job_error_ends_the_run_and_is_kept() -> None:
    calls: list[int] = []

    def job(_should_stop: Callable[[], bool]) -> bool:
        calls.append(1)
        raise ValueError("boom")

    worker = SimulationWorker(job, "test")
    worker.wake()
    deadline = threading.Event()
    for _ in range(6000):
        if not worker.busy:
            break
        deadline.wait(0.01)
    assert isinstance(worker.error, ValueError) and calls == [1]
    worker.shutdown()
    assert not worker.alive


def test_a_worker_leaves_a_busy_ui_thread_alone_until_it_idles(monkeypatch: pytest.MonkeyPatch) -> None:
    """While the UI thread says it is busy, a woken worker starts no frame (up to its
    longest wait); the first ``ui_idle`` lets it run; a blocking wait counts as idle."""
    from qtanimator.document import simulation

    monkeypatch.setattr(simulation, "UI_BUSY_WAIT_S", 60.0)
    calls: list[int] = []
    started = threading.Event()

    def job(_should_stop: Callable[[], bool]) -> bool:
        calls.append(1)
        started.set()
        return len(calls) < 5

    simulation.ui_busy()
    try:
        worker = SimulationWorker(job, "test-gate")
        worker.wake()
        assert not started.wait(0.3)   # the UI thread is busy: nothing ran
        assert calls == [] and worker.busy
        simulation.ui_idle()
        assert started.wait(10)
        for _ in range(1000):
            if not worker.busy:
                break
            threading.Event().wait(0.01)
        assert calls == [1] * 5
        worker.shutdown()
    finally:
        simulation.ui_idle()


def test_waiting_for_the_pendulum_cache_marks_the_caller_idle(demo: Callable[[], Document],
                                                               monkeypatch: pytest.MonkeyPatch) -> None:
    """A thread blocked in ``wait_idle`` is not busy: the worker fills the cache."""
    from qtanimator.document import simulation as gate

    monkeypatch.setattr(gate, "UI_BUSY_WAIT_S", 60.0)
    doc = demo()
    cache = simulation(doc)
    gate.ui_busy()
    try:
        cache.latest_state("pip", 30)
        assert cache.wait_idle(60)
        assert cache.cached_frames("pip") > 30
    finally:
        gate.ui_idle()
