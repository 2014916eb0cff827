"""The pendulum cache: every 2D character's simulated frames, and the worker that fills them.

Pendulums and spring joints are stepped by :mod:`qtanimator.document.pendulum_step`; this
module keeps their per-frame states in ``doc.caches["pendulums"]`` (:func:`simulation`),
drops what an edit invalidates, and runs the stepping on its worker thread
(:mod:`qtanimator.document.simulation`) for the views.
"""

from __future__ import annotations

import math
import threading
import time
import weakref
from collections import Counter
from collections.abc import Callable, Iterable

import numpy as np
import numpy.typing as npt

from qtanimator.core.pendulum import PendulumBlowUp, check_state
from qtanimator.core.rig2d import Character
from qtanimator.document.character2d_asset import character, character_assets
from qtanimator.document.document import Document, DocumentChange
from qtanimator.document.pendulum_step import AssetSim, advance, initial_angles, initial_state, new_sim
from qtanimator.document.simulation import SimulationWorker, ui_idle

FloatArray = npt.NDArray[np.float64]


class PendulumCache:
    """Per-frame pendulum states of every 2D character, at a fixed internal step.

    Frame f (from the project's ``frame_start``) holds the world angles after simulating up
    to time f / fps (a spring joint's entry is its simulated local angle and rate). A channel
    edit drops the frames from the edited time on (once per asset and change); a parameter
    or asset change drops that character's frames.

    Two ways to read:

    * exact (``state``, ``world_angles(..., wait=True)``): a frame not cached yet is
      simulated on the calling thread (headless render, export, commands, tests);
    * latest (``latest_state``, ``world_angles(..., wait=False)``): never steps; returns the
      last frame simulated at or before the one asked for (the keyed start state when
      nothing is), and asks the background worker (:mod:`qtanimator.document.simulation`)
      to fill up to that frame plus :attr:`LOOKAHEAD` seconds. Views use this.

    Threads: the worker and exact reads compute a frame without the lock and append it
    under the lock only if the character's simulation is still the same object, its
    ``generation`` unchanged (an invalidation that reaches the frame being computed bumps
    it) and the frame still the next one; so a frame computed from a dropped state never
    enters the cache, and every cached frame equals the synchronous result exactly.
    """

    MAX_FRAMES = 200_000
    #: Seconds of frames the worker simulates past the frame a view asked for.
    LOOKAHEAD = 1.0

    def __init__(self, doc: Document) -> None:
        self._doc = weakref.ref(doc)
        self._sims: dict[str, AssetSim] = {}
        self._lock = threading.Lock()
        self._epoch = 0  # bumped when simulations are dropped (a sim built meanwhile is stale)
        self._targets: dict[str, int] = {}  # frame index the worker fills each character to
        #: Sub-steps simulated (by any thread), and per thread id (frames later discarded included).
        self.steps_taken = 0
        self.steps_by_thread: Counter[int] = Counter()
        #: Frame-dropping invalidations (one per character per change at most), and restarts
        #: (worker wake-ups caused by a change: at most one per change).
        self.invalidations = 0
        self.restarts = 0
        #: Changes whenever frames are added or dropped (the UI polls it).
        self.revision = 0
        self._worker = SimulationWorker(self._work, "pendulums")
        weakref.finalize(self, self._worker.shutdown, 0.0)
        doc.subscribe(self._on_change)

    # ---- worker control
    @property
    def worker(self) -> SimulationWorker:
        return self._worker

    @property
    def busy(self) -> bool:
        """True while the worker has frames to simulate."""
        return self._worker.busy

    def shutdown(self, timeout: float | None = 5.0) -> None:
        """Stop the worker thread and forget what it was asked for (cached frames stay;
        a later latest-state read starts it again)."""
        with self._lock:
            self._targets.clear()
        self._worker.shutdown(timeout)

    def wait_idle(self, timeout: float = 30.0) -> bool:
        """Block until the worker has nothing to do (tests); False on timeout."""
        ui_idle()  # the calling thread waits: the worker need not leave it the interpreter
        deadline = time.monotonic() + timeout
        while self._worker.busy:
            if time.monotonic() > deadline:
                return False
            time.sleep(0.001)
        return True

    # ---- invalidation
    def _on_change(self, change: DocumentChange) -> None:
        doc = self._doc()
        if doc is None:
            return
        if change.reset:
            with self._lock:
                self._drop_all()
                self._targets.clear()
            self._worker.shutdown()
            return
        dropped = False
        with self._lock:
            for asset_id in change.assets:
                dropped |= self._drop(asset_id)
                if asset_id not in doc.assets:
                    self._targets.pop(asset_id, None)
            for path in change.parameters:
                if path in ("fps", "frame_start") or path.startswith("simulation."):
                    dropped |= self._drop_all()
                elif ".pendulum." in path:
                    dropped |= self._drop(path.split(".pendulum.", 1)[0])
                elif ".spring." in path:
                    dropped |= self._drop(path.split(".spring.", 1)[0])
                elif ".limits." in path:  # clamped parents swing the pendulums differently
                    dropped |= self._drop(path.split(".limits.", 1)[0])
            for asset_id in change.channel_assets():
                # One invalidation per asset and command, from its earliest edited time.
                dropped |= self._invalidate_locked(doc, asset_id, change.channel_time_from(asset_id))
            restart = dropped and bool(self._targets)
            if restart:
                self.restarts += 1
        if restart:
            self._worker.wake()

    def _drop(self, asset_id: str) -> bool:
        self._epoch += 1  # also when none is cached: one may be under construction
        if self._sims.pop(asset_id, None) is None:
            return False
        self.revision += 1
        self.invalidations += 1
        return True

    def _drop_all(self) -> bool:
        self._epoch += 1
        if not self._sims:
            return False
        self._sims.clear()
        self.revision += 1
        self.invalidations += 1
        return True

    def _invalidate_locked(self, doc: Document | None, asset_id: str, time_from: float) -> bool:
        sim = self._sims.get(asset_id)
        if sim is None or time_from == math.inf:
            return False
        if doc is None or time_from == -math.inf:
            return self._drop(asset_id)
        # Frame i (after the start) integrates inputs at times before its own time and
        # applies keys at its own time, so it is valid while its time < time_from.
        keep = max(math.ceil(time_from * doc.fps - doc.frame_range[0] - 1e-9), 0)
        if keep > len(sim.theta):
            return False  # neither a cached frame nor the one being computed is affected
        # The frame being computed (index len) may read the old inputs: make it stale too.
        sim.generation += 1
        sim.problem = None  # the frame that blew up is recomputed from the new inputs
        del sim.theta[keep:]
        del sim.omega[keep:]
        self.revision += 1
        self.invalidations += 1
        return True

    def invalidate(self, asset_id: str | None = None, time_from: float = -math.inf) -> None:
        """Drop the cached frames whose state depends on inputs at or after ``time_from``
        (every character's with ``asset_id`` None); the worker refills what views asked for."""
        doc = self._doc()
        with self._lock:
            targets = list(self._sims) if asset_id is None else [asset_id]
            dropped = False
            for aid in targets:
                dropped |= self._invalidate_locked(doc, aid, time_from)
            restart = dropped and bool(self._targets)
        if restart:
            self._worker.wake()

    def problem(self, asset_id: str) -> PendulumBlowUp | None:
        """The blow-up that stopped this character's simulation, or None."""
        with self._lock:
            sim = self._sims.get(asset_id)
            return None if sim is None else sim.problem

    def cached_frames(self, asset_id: str) -> int:
        sim = self._sims.get(asset_id)
        return 0 if sim is None else len(sim.theta)

    def baked_states(self) -> dict[str, tuple[FloatArray, FloatArray, PendulumBlowUp | None]]:
        """Every character's cached frames as ``{asset: (theta (F, J), omega (F, J), problem)}``:
        plain arrays that pickle, for :meth:`load_baked_states` in another process (the
        parallel render bakes the pendulums once and hands them to its workers)."""
        with self._lock:
            out: dict[str, tuple[FloatArray, FloatArray, PendulumBlowUp | None]] = {}
            for aid, sim in self._sims.items():
                if sim.theta:
                    out[aid] = (np.array(sim.theta), np.array(sim.omega), sim.problem)
            return out

    def load_baked_states(self, states: dict[str, tuple[FloatArray, FloatArray, PendulumBlowUp | None]]) -> None:
        """Put frames from :meth:`baked_states` (of the same document) into this cache; reads
        of those frames then never simulate."""
        doc = self._doc()
        if doc is None:
            raise RuntimeError("the document is gone")
        for aid, (theta, omega, problem) in states.items():
            sim = new_sim(doc, aid, character(doc, aid))
            sim.theta = [np.array(row) for row in theta]
            sim.omega = [np.array(row) for row in omega]
            sim.problem = problem
            with self._lock:
                self._sims[aid] = sim
                self.revision += 1

    # ---- exact reads
    def _sim(self, doc: Document, asset_id: str) -> AssetSim:
        while True:
            with self._lock:
                sim = self._sims.get(asset_id)
                epoch = self._epoch
            if sim is not None:
                return sim
            built = new_sim(doc, asset_id, character(doc, asset_id))
            with self._lock:
                if self._epoch == epoch:  # else a change dropped it meanwhile: build again
                    return self._sims.setdefault(asset_id, built)

    def _index(self, doc: Document, frame: int) -> int:
        return min(max(int(frame) - doc.frame_range[0], 0), self.MAX_FRAMES)

    def state(self, asset_id: str, frame: int) -> tuple[FloatArray, FloatArray]:
        """World angles and rates (J,) of every joint's pendulum state at an integer frame,
        simulated on the calling thread if not cached yet (exact)."""
        doc = self._doc()
        if doc is None:
            raise RuntimeError("the document is gone")
        f = self._index(doc, frame)
        while True:
            sim = self._sim(doc, asset_id)
            with self._lock:
                n = len(sim.theta)
                if n > f:
                    return sim.theta[f], sim.omega[f]
                if sim.problem is not None and n:
                    return sim.theta[-1], sim.omega[-1]  # it stops at the last good frame
                gen = sim.generation
                prev = (sim.theta[-1], sim.omega[-1]) if n else None
            self._step(doc, asset_id, sim, gen, n, prev)

    def world_angles(self, asset_id: str, time: float, wait: bool = True) -> FloatArray:
        """Dynamic joints' world angles at ``time`` (linear between cached frames).

        ``wait`` True: exact, simulating on this thread as needed. False: never steps;
        the latest state available (see :meth:`latest_state`), and the worker is asked to
        catch up.
        """
        doc = self._doc()
        if doc is None:
            raise RuntimeError("the document is gone")
        fr = time * doc.fps
        f0 = math.floor(fr + 1e-9)
        u = fr - f0
        if wait:
            th0 = self.state(asset_id, f0)[0]
            if u <= 1e-9:
                return th0.copy()
            th1 = self.state(asset_id, f0 + 1)[0]
            return np.asarray((1 - u) * th0 + u * th1, dtype=np.float64)
        if u <= 1e-9:
            return self.latest_state(asset_id, f0)[0].copy()
        th1, _om, at = self.latest_state(asset_id, f0 + 1)
        th0, _om, at0 = self.latest_state(asset_id, f0)
        if at < f0 + 1 or at0 < f0:
            return th0.copy()  # f0 + 1 is not simulated yet: the latest state at or before f0
        return np.asarray((1 - u) * th0 + u * th1, dtype=np.float64)

    # ---- latest reads (views)
    def latest_state(self, asset_id: str, frame: int) -> tuple[FloatArray, FloatArray, int]:
        """``(theta, omega, shown_frame)``: the state at ``frame`` if simulated, else at the
        last simulated frame before it (``shown_frame`` says which), or the keyed start
        state when nothing is. Never simulates on the calling thread; asks the worker to
        fill up to ``frame`` plus the look-ahead."""
        doc = self._doc()
        if doc is None:
            raise RuntimeError("the document is gone")
        start = doc.frame_range[0]
        f = self._index(doc, frame)
        with self._lock:
            sim = self._sims.get(asset_id)
            n = 0 if sim is None else len(sim.theta)
            if n:
                assert sim is not None
                k = min(f, n - 1)
                theta, omega = sim.theta[k], sim.omega[k]
            wake = self._request(doc, asset_id, f, n)
        if wake:
            self._worker.wake()
        if n:
            return theta, omega, start + k
        ch = character(doc, asset_id)
        theta = initial_angles(doc, asset_id, ch, start / doc.fps)
        return theta, np.zeros(len(ch.joints)), start

    def ready(self, asset_id: str, time: float) -> bool:
        """True when ``world_angles(asset_id, time, wait=False)`` is exact (its frames are
        simulated)."""
        doc = self._doc()
        if doc is None:
            return False
        fr = time * doc.fps
        f0 = math.floor(fr + 1e-9)
        need = self._index(doc, f0 + (0 if fr - f0 <= 1e-9 else 1))
        return self.cached_frames(asset_id) > need

    def _request(self, doc: Document, asset_id: str, index: int, cached: int) -> bool:
        """Record that a view shows frame ``index`` (lock held); True if the worker must be
        woken (its target moved and frames up to it are missing)."""
        first, last = doc.frame_range
        end = max(last - first, 0)
        ahead = int(math.ceil(self.LOOKAHEAD * doc.fps))
        want = max(index, min(index + ahead, end))
        old = self._targets.get(asset_id, -1)
        # Grow with the frame shown (playback stays ahead); start over when the view jumped
        # far back (a scrub), so the worker does not fill frames nobody looks at.
        changed = want > old or old > index + 2 * ahead
        if changed:
            self._targets[asset_id] = want
        # Wake it when frames are missing and it is not already on them (or was cancelled).
        return cached <= self._targets[asset_id] and (changed or not self._worker.busy)

    # ---- stepping (any thread)
    def _work(self, should_stop: Callable[[], bool]) -> bool:
        """The worker's job: simulate one frame of the character furthest behind its
        target. False when every target is reached."""
        doc = self._doc()
        if doc is None:
            return False
        with self._lock:
            best: tuple[int, str] | None = None
            for aid, target in list(self._targets.items()):
                sim = self._sims.get(aid)
                n = 0 if sim is None else len(sim.theta)
                if sim is not None and sim.problem is not None:
                    continue  # blown up: nothing more to simulate until an edit
                if n <= target and (best is None or n < best[0]):
                    best = (n, aid)
            if best is None:
                return False
            n, aid = best
            sim = self._sims.get(aid)
            epoch = self._epoch
            gen = -1 if sim is None else sim.generation
            prev = (sim.theta[-1], sim.omega[-1]) if sim is not None and n else None
        if should_stop():
            return False
        if sim is None:
            ch = doc.runtime.get(aid)
            if not isinstance(ch, Character):  # removed, or not loaded: nothing to simulate
                with self._lock:
                    self._targets.pop(aid, None)
                return True
            built = new_sim(doc, aid, ch)
            with self._lock:
                if self._epoch == epoch and aid not in self._sims:
                    self._sims[aid] = built
            return True
        self._step(doc, aid, sim, gen, n, prev)
        return True

    def _step(self, doc: Document, asset_id: str, sim: AssetSim, generation: int, index: int,
              prev: tuple[FloatArray, FloatArray] | None) -> bool:
        """Compute frame ``index`` from ``prev`` (frame ``index - 1``) without the lock and
        append it if nothing invalidated it meanwhile. True if it was appended."""
        start = doc.frame_range[0]
        if prev is None:
            theta, omega = initial_state(doc, asset_id, sim)
            steps = 0
        else:
            # A blow-up makes inf and NaN on the way; check_state below reports it.
            with np.errstate(over="ignore", invalid="ignore"):
                theta, omega, steps = self._advance(doc, asset_id, sim, start + index - 1, prev[0], prev[1])
        ident = threading.get_ident()
        problem = check_state(sim.system.character, sim.system.params, theta, omega, (start + index) / doc.fps)
        with self._lock:
            self.steps_taken += steps
            self.steps_by_thread[ident] += steps
            if self._sims.get(asset_id) is not sim or sim.generation != generation or len(sim.theta) != index:
                return False
            if problem is not None:
                # Stop at the last good frame: nothing non-finite reaches a view or a file.
                sim.problem = problem
                self.revision += 1
                return False
            sim.theta.append(theta)
            sim.omega.append(omega)
            self.revision += 1
            return True

    def _advance(self, doc: Document, asset_id: str, sim: AssetSim, frame: int, theta0: FloatArray,
                 omega0: FloatArray) -> tuple[FloatArray, FloatArray, int]:
        """One frame's stepping (:func:`~qtanimator.document.pendulum_step.advance`); a method
        so that a test can stall the worker in it."""
        return advance(doc, asset_id, sim, frame, theta0, omega0)


PENDULUM_CACHE = "pendulums"


def simulation(doc: Document) -> PendulumCache:
    """The document's pendulum cache, ``doc.caches["pendulums"]`` (created on first use)."""
    cache = doc.caches.get(PENDULUM_CACHE)
    if not isinstance(cache, PendulumCache):
        cache = PendulumCache(doc)
        doc.caches[PENDULUM_CACHE] = cache
    return cache


def ensure_caches(doc: Document) -> None:
    """Create ``doc``'s simulation caches now. An editor context calls it before it
    subscribes to the document, so that the caches drop what a change invalidates before any
    view hears of the change (listeners are told in the order they subscribed). The cloth
    caches live in ``doc.runtime`` and subscribe through their worker."""
    simulation(doc)


def simulation_ready(doc: Document, times: float | Iterable[float]) -> bool:
    """True when every 2D character's pendulums are simulated at ``times`` (so views that
    read the latest state show the exact one). Cheap; steps nothing."""
    cache = doc.caches.get(PENDULUM_CACHE)
    ts = [float(times)] if isinstance(times, (int, float)) else [float(t) for t in times]
    for aid in character_assets(doc):
        ch = doc.runtime.get(aid)
        if not isinstance(ch, Character) or not ch.simulated.any():
            continue
        if not isinstance(cache, PendulumCache) or not all(cache.ready(aid, t) for t in ts):
            return False
    return True


def simulated_frames(doc: Document) -> tuple[int, int] | None:
    """The frames ``(first, last)`` simulated for every 2D character with pendulums (last
    < first when none is yet); None when no character has pendulums."""
    cache = doc.caches.get(PENDULUM_CACHE)
    first = doc.frame_range[0]
    counts = []
    for aid in character_assets(doc):
        ch = doc.runtime.get(aid)
        if isinstance(ch, Character) and ch.simulated.any():
            counts.append(cache.cached_frames(aid) if isinstance(cache, PendulumCache) else 0)
    if not counts:
        return None
    return first, first + min(counts) - 1


def pendulum_problems(doc: Document) -> dict[str, PendulumBlowUp]:
    """The blow-ups that stopped the pendulum simulations, by character."""
    cache = doc.caches.get(PENDULUM_CACHE)
    if not isinstance(cache, PendulumCache):
        return {}
    found = {aid: cache.problem(aid) for aid in character_assets(doc)}
    return {aid: p for aid, p in found.items() if p is not None}
