"""Cloth simulation off the UI thread (ARCHITECTURE §3: simulations never run on the UI thread).

Two Qt-free helpers, each with its own thread; views only observe them (they poll
:attr:`ClothWorker.revision` / :attr:`LiveCloths.version` from a timer and draw what is there):

* :class:`ClothWorker` (``doc.caches["cloths"]``, see :func:`cloth_worker`; its thread is a
  :class:`~qtanimator.document.simulation.SimulationWorker`) fills the document's cloth caches
  (:class:`~qtanimator.document.cloth.ClothCache`) forward, frame by frame, from the first
  frame missing up to ``frame_end``. It listens to the document: a change that touches a
  cloth (see :func:`cloth_invalidations`) drops that cloth's job, cancels its step in flight
  (between two substeps) and starts again on the rebuilt cache. Work can be cancelled and
  resumed; the frames are those of a synchronous run (the same
  :class:`~qtanimator.core.cloth.Cloth` steps, and a cancelled step is undone).
* :class:`LiveCloths` runs the interactive cloths (pins moved with the keyboard, a particle
  grabbed with the mouse) in real time on a thread; the UI sends it edits (which never wait
  for a step in flight) and draws its latest :class:`LiveClothFrame`.

The symplectic substep is one numba kernel that releases the GIL (``nogil=True``), and a
thread that holds the GIL hands it over every ``sys.getswitchinterval()`` (5 ms), so the UI
thread keeps running while these work.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from qtanimator.core.cloth import (
    BoolArray,
    Cloth,
    ClothParams,
    FloatArray,
    IntArray,
    nearest_particle,
)
from qtanimator.document.cloth import ASSET_KIND, ClothCache, cloth_cache, cloth_params
from qtanimator.document.document import Document, DocumentChange
from qtanimator.document.simulation import SimulationWorker, ui_idle

#: Parameters that set every cloth's frame grid: a change rebuilds every cloth cache.
GRID_PARAMETERS = frozenset({"fps", "frame_start"})
#: Parameters that only move the end of the work (no frame becomes invalid).
TARGET_PARAMETERS = frozenset({"frame_end"})


def cloth_invalidations(doc: Document, change: DocumentChange) -> dict[str, float]:
    """Which cloth caches ``change`` invalidates, and from which frame on: ``{asset id: frame}``.

    A cloth's simulation depends on its own properties, on ``fps`` / ``frame_start`` and, when
    it is attached to a character (``attach``), on that character's channels and properties;
    a cloth is touched when its asset was added, replaced or removed, the frame grid changed,
    or its character changed, and then from its first frame (``-inf``: everything).
    Removed assets are included (their work is dropped).
    """
    cloths = {a for a, asset in doc.assets.items() if asset.kind == ASSET_KIND}
    if change.reset or change.parameters & GRID_PARAMETERS:
        touched = set(cloths) | set(change.assets)
    else:
        touched = set(change.assets)
        # A cloth attached to a character (cloth_attach) follows its channels and properties.
        drivers = set(change.assets) | change.channel_assets()
        for aid in cloths:
            value = doc.assets[aid].properties.get("attach")
            if isinstance(value, dict) and value.get("asset") in drivers:
                touched.add(aid)
    return {aid: -math.inf for aid in sorted(touched) if aid in cloths or aid not in doc.assets}


# --------------------------------------------------------------------------- cache filling
@dataclass(frozen=True)
class ClothProgress:
    """Where the worker stands with one cloth."""

    asset_id: str
    done: int          # frames cached, the rest frame included
    wanted: int        # frames the worker fills towards
    elapsed: float     # seconds this fill has been running (until it finished or stopped)
    running: bool      # frames are still being computed
    cancelled: bool    # stopped by the user (``resume`` goes on)
    error: str = ""    # why the simulation stopped (a blow-up), "" if it did not

    @property
    def fraction(self) -> float:
        return 1.0 if self.wanted <= 0 else min(1.0, self.done / self.wanted)


class _Job:
    """Filling one cache up to ``wanted`` frames."""

    def __init__(self, asset_id: str, cache: ClothCache, wanted: int) -> None:
        self.asset_id = asset_id
        self.cache = cache
        self.wanted = wanted
        self.cancelled = False
        self.dropped = False        # replaced by a job on a rebuilt cache, or the asset is gone
        self.failure = ""           # an unexpected exception while stepping
        self.started: float | None = None
        self.finished: float | None = None

    def needs_work(self) -> bool:
        return (not self.cancelled and not self.dropped and not self.failure and self.cache.error is None
                and self.cache.cached_frames < self.wanted)


#: The key of the cloth worker in ``doc.caches``.
CLOTH_CACHE = "cloths"


def cloth_worker(doc: Document) -> ClothWorker:
    """The document's cloth worker, ``doc.caches["cloths"]`` (created and started on first use)."""
    worker = doc.caches.get(CLOTH_CACHE)
    if not isinstance(worker, ClothWorker):
        worker = ClothWorker(doc)
        doc.caches[CLOTH_CACHE] = worker
    return worker


class ClothWorker:
    """Fills the cloth caches of ``doc`` on a background thread (see the module docstring).

    It is one of the document's simulation caches (``doc.caches["cloths"]``, see
    :mod:`qtanimator.document.simulation`: ``revision``, ``busy``, ``shutdown``), and runs on
    a :class:`~qtanimator.document.simulation.SimulationWorker` (one frame per call, the
    thread holds the worker only weakly). Every public method is meant for the thread that
    owns the document (the UI thread) and returns at once; :meth:`wait` is the only one
    that blocks (tests, scripts).
    """

    def __init__(self, doc: Document, *, start: bool = True) -> None:
        self.doc = doc
        #: Bumped whenever a frame is added or a job changes (views poll it).
        self.revision = 0
        self._lock = threading.Lock()
        self._jobs: dict[str, _Job] = {}
        self._turn = 0
        self._closed = False
        self._started = start
        self._thread = SimulationWorker(self._step_one, name="cloth-cache")
        doc.subscribe(self._on_change)
        self.sync()

    # ------------------------------------------------------------ lifecycle
    @property
    def version(self) -> int:
        return self.revision

    def start(self) -> None:
        """Let the thread run (the constructor does unless ``start=False``)."""
        self._started = True
        self._wake()

    def shutdown(self, timeout: float | None = 5.0) -> None:
        """Stop the thread (a step in flight is cancelled); more work starts it again."""
        self._thread.shutdown(timeout)

    def close(self, timeout: float | None = 5.0) -> None:
        """Stop the thread for good and stop listening to the document."""
        self._closed = True
        self.doc.unsubscribe(self._on_change)
        self.shutdown(timeout)

    @property
    def closed(self) -> bool:
        return self._closed

    @property
    def alive(self) -> bool:
        """True while the thread exists (it ends on :meth:`shutdown`)."""
        return self._thread.alive

    def _wake(self) -> None:
        if self._started and not self._closed:
            self._thread.wake()

    # ------------------------------------------------------------- requests
    def _on_change(self, change: DocumentChange) -> None:
        invalid = cloth_invalidations(self.doc, change)
        if change.reset or change.parameters & TARGET_PARAMETERS:
            self.sync()
        elif invalid:
            self.sync(invalid)

    def sync(self, asset_ids: Iterable[str] | None = None) -> None:
        """Bring the jobs in line with the document: a job per cloth asset on its current
        cache (rebuilt by :func:`~qtanimator.document.cloth.cloth_cache` when its inputs
        changed), filling up to ``frame_end``. ``asset_ids`` limits the check to those."""
        doc = self.doc
        cloths = [a for a, asset in doc.assets.items() if asset.kind == ASSET_KIND]
        check = cloths if asset_ids is None else [a for a in asset_ids if a in cloths]
        start, end = doc.frame_range
        caches: dict[str, ClothCache] = {}
        for aid in check:
            try:
                caches[aid] = cloth_cache(doc, aid)
            except (ValueError, TypeError, KeyError):
                continue  # unreadable properties: the view reports the error when it draws
        with self._lock:
            for aid in [a for a in self._jobs if a not in cloths]:
                self._jobs.pop(aid).dropped = True
            for aid, cache in caches.items():
                wanted = max(1, end - start + 1)
                job = self._jobs.get(aid)
                if job is None or job.cache is not cache:
                    if job is not None:
                        job.dropped = True   # its step in flight stops between two substeps
                    self._jobs[aid] = _Job(aid, cache, wanted)  # a new simulation starts running
                else:
                    job.wanted = wanted
            self._jobs = {aid: self._jobs[aid] for aid in cloths if aid in self._jobs}  # document order
            self.revision += 1
        self._wake()

    def request(self, asset_id: str, frame: float) -> None:
        """Make sure ``frame`` will be computed (a view showing a frame past ``frame_end``)."""
        with self._lock:
            job = self._jobs.get(asset_id)
            if job is None:
                return
            try:
                count = job.cache.index_of(frame) + 1
            except ValueError:
                return
            if count <= job.wanted:
                if not job.needs_work() or self._thread.busy:
                    return
            else:
                job.wanted = count
                job.finished = None
        self._wake()

    def cancel(self, asset_id: str | None = None) -> None:
        """Stop filling (one cloth or all); the frames computed so far stay."""
        with self._lock:
            for aid, job in self._jobs.items():
                if (asset_id is None or aid == asset_id) and job.needs_work():
                    job.cancelled = True
                    job.finished = time.monotonic()
            self.revision += 1

    def resume(self, asset_id: str | None = None) -> None:
        """Go on after :meth:`cancel`, from the last frame computed."""
        with self._lock:
            for aid, job in self._jobs.items():
                if (asset_id is None or aid == asset_id) and job.cancelled:
                    job.cancelled = False
                    job.started = job.finished = None
            self.revision += 1
        self._wake()

    # ------------------------------------------------------------ read-outs
    @property
    def busy(self) -> bool:
        """True while the thread has work or a step in flight (after :meth:`cancel` it winds
        down within one substep)."""
        return self._thread.busy

    def progress(self) -> list[ClothProgress]:
        """One :class:`ClothProgress` per cloth asset, in document order."""
        now = time.monotonic()
        out = []
        with self._lock:
            for aid, job in self._jobs.items():
                cache = job.cache
                started = job.started
                end = job.finished if job.finished is not None else now
                error = job.failure or (cache.error.message if cache.error is not None else "")
                out.append(ClothProgress(aid, cache.cached_frames, job.wanted,
                                         0.0 if started is None else max(0.0, end - started),
                                         job.needs_work(), job.cancelled, error))
        return out

    def wait(self, timeout: float | None = None) -> bool:
        """Block until no cache needs work (True) or ``timeout`` seconds passed (False)."""
        ui_idle()  # the calling thread waits: the worker need not leave it the interpreter
        deadline = None if timeout is None else time.monotonic() + timeout
        while self.busy:
            if deadline is not None and time.monotonic() >= deadline:
                return False
            time.sleep(0.002)
        return True

    # --------------------------------------------------------------- thread
    def _next_job(self) -> _Job | None:
        jobs = [j for j in self._jobs.values() if j.needs_work()]
        if not jobs:
            return None
        self._turn = (self._turn + 1) % len(jobs)
        return jobs[self._turn]   # round robin: every cloth advances

    def _step_one(self, should_stop: Callable[[], bool]) -> bool:
        """The thread's job: simulate one frame of one cloth; True while work is left."""
        with self._lock:
            job = self._next_job()
            if job is None:
                return False
            if job.started is None:
                job.started = time.monotonic()

        def stop(j: _Job = job) -> bool:
            return j.cancelled or j.dropped or should_stop()

        try:
            job.cache.step_frame(stop)
        except Exception as exc:  # noqa: BLE001 - reported in the progress, the others go on
            job.failure = f"{type(exc).__name__}: {exc}"
        with self._lock:
            if not job.needs_work() and job.finished is None:
                job.finished = time.monotonic()
            self.revision += 1
            return any(j.needs_work() for j in self._jobs.values())


# --------------------------------------------------------------------------- live cloths
@dataclass(frozen=True)
class LiveClothFrame:
    """A snapshot of a live cloth for drawing and picking (copies, never changed)."""

    positions: FloatArray
    triangles: IntArray
    params: ClothParams
    pinned: BoolArray
    pin_targets: FloatArray
    time: float
    grabbed: int | None
    vertex_normals: FloatArray = field(repr=False)

    def normals(self) -> FloatArray:
        return self.vertex_normals


def _snapshot(cloth: Cloth) -> LiveClothFrame:
    positions = cloth.positions.copy()
    normals = cloth.normals()
    return LiveClothFrame(positions, cloth.triangles, cloth.params, cloth.pinned, cloth.pin_targets.copy(),
                          cloth.time, cloth.grabbed, normals)


class LiveCloths:
    """Interactive cloth simulations, one per cloth asset, stepped in real time on a thread.

    While ``enabled`` (and not ``paused``) a thread steps every cloth by ``dt`` whenever the
    wall clock has moved on by ``dt`` (at most three steps behind: a slow simulation runs in
    slow motion instead of piling up). Edits (:meth:`move_pins`, :meth:`grab`,
    :meth:`drag_grabbed`, :meth:`release`, :meth:`reset`, :meth:`sync`) are applied at once
    when no step is in flight, else queued and applied, in order, before the next step: the
    caller never waits. Views draw :meth:`frame` / :meth:`frames` (snapshots); ``cloths``
    holds the simulations themselves, to be read only while the thread is idle (paused).
    """

    def __init__(self, dt: float = 1.0 / 60.0, clock: Callable[[], float] = time.monotonic) -> None:
        self.dt = float(dt)
        self.cloths: dict[str, Cloth] = {}
        self.errors: dict[str, str] = {}
        #: Bumped whenever a snapshot changes (views poll it).
        self.version = 0
        self._clock = clock
        self._enabled = False
        self._paused = False
        self._closed = False
        self._stepping = False
        self._frames: dict[str, LiveClothFrame] = {}
        self._ops: list[Callable[[], None]] = []
        self._sim = threading.Lock()          # held while stepping or applying edits
        self._cond = threading.Condition()    # guards _ops and the flags, wakes the thread
        self._thread: threading.Thread | None = None

    # ------------------------------------------------------------- switches
    @property
    def enabled(self) -> bool:
        return self._enabled

    @enabled.setter
    def enabled(self, on: bool) -> None:
        with self._cond:
            self._enabled = bool(on)
            if on and self._thread is None and not self._closed:
                self._thread = threading.Thread(target=self._run, name="live-cloth", daemon=True)
                self._thread.start()
            self._cond.notify_all()

    @property
    def paused(self) -> bool:
        return self._paused

    @paused.setter
    def paused(self, on: bool) -> None:
        with self._cond:
            self._paused = bool(on)
            self._cond.notify_all()

    @property
    def stepping(self) -> bool:
        """True while a step is in flight on the thread."""
        return self._stepping

    def close(self, timeout: float = 5.0) -> None:
        with self._cond:
            self._closed = True
            self._cond.notify_all()
            thread = self._thread
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout)

    # ---------------------------------------------------------------- edits
    #: How long an edit may wait for the thread to let go of the cloths (seconds): enough for
    #: it to finish applying edits, far less than a step (then the edit is queued).
    SUBMIT_WAIT_S = 0.005

    def _submit(self, op: Callable[[], None]) -> None:
        """Apply ``op`` now if no step is in flight, else before the next step."""
        with self._cond:
            self._ops.append(op)
            self._cond.notify_all()
        if self._sim.acquire(timeout=self.SUBMIT_WAIT_S):
            try:
                self._apply_ops()
            finally:
                self._sim.release()

    def settle(self, timeout: float = 5.0) -> bool:
        """Wait until no step is in flight (True) or ``timeout`` passed (False). After
        ``paused = True`` and ``settle()`` the thread steps no more: the cloths may be read."""
        if self._sim.acquire(timeout=timeout):
            self._sim.release()
            return True
        return False

    def _running(self) -> bool:
        return self._enabled and not self._paused and not self._closed

    def _apply_ops(self) -> None:
        """With ``_sim`` held: apply the queued edits in order and publish the result."""
        with self._cond:
            ops, self._ops = self._ops, []
        if not ops:
            return
        for op in ops:
            op()
        self._publish()

    def sync(self, doc: Document) -> None:
        """Create live cloths for new cloth assets, drop removed ones, follow parameter edits."""
        wanted: dict[str, ClothParams] = {}
        invalid: dict[str, str] = {}
        for aid, asset in doc.assets.items():
            if asset.kind != ASSET_KIND:
                continue
            try:
                wanted[aid] = cloth_params(doc, aid)
            except (ValueError, TypeError, KeyError) as exc:
                # no live cloth with made-up parameters: the Cloth dock shows why there is none
                invalid[aid] = f"invalid parameters: {exc}"
        fresh = {aid: Cloth(p) for aid, p in wanted.items() if aid not in self.cloths}

        def apply() -> None:
            for aid in [a for a in self.cloths if a not in wanted]:
                del self.cloths[aid]
                self._frames.pop(aid, None)
                self.errors.pop(aid, None)
            self.errors.update(invalid)
            for aid, params in wanted.items():
                cloth = self.cloths.get(aid)
                if cloth is None:
                    self.cloths[aid] = fresh.get(aid) or Cloth(params)
                    self.errors.pop(aid, None)
                elif cloth.params != params:
                    cloth.set_params(params)
                    self.errors.pop(aid, None)

        self._submit(apply)

    def clear(self) -> None:
        """Forget every live cloth (a new document); :meth:`sync` makes them again."""
        def apply() -> None:
            self.cloths.clear()
            self.errors.clear()
            self._frames = {}

        self._submit(apply)

    def reset(self) -> None:
        """Every live cloth back to its rest state."""
        def apply() -> None:
            for cloth in self.cloths.values():
                cloth.reset()
            self.errors.clear()

        self._submit(apply)

    def move_pins(self, translation: Any = (0.0, 0.0, 0.0), rotation: Any = None) -> None:
        def apply() -> None:
            for cloth in self.cloths.values():
                cloth.move_pins(translation, rotation)

        self._submit(apply)

    def grab(self, ray_origin: Any, ray_dir: Any,
             max_distance: Callable[[ClothParams], float] | None = None) -> tuple[str, FloatArray] | None:
        """Grab the particle nearest to a ray in the latest snapshots: ``(asset id, where)``
        or None. ``max_distance(params)`` limits how far from the ray a particle may be."""
        for aid, frame in self.frames().items():
            limit = None if max_distance is None else max_distance(frame.params)
            index = nearest_particle(frame.positions, ray_origin, ray_dir, limit)
            if index is not None:
                def apply(a: str = aid, i: int = index) -> None:
                    cloth = self.cloths.get(a)
                    if cloth is not None and i < cloth.n:
                        cloth.grab_particle(i)

                self._submit(apply)
                return aid, frame.positions[index].copy()
        return None

    def drag_grabbed(self, asset_id: str, target: Any) -> None:
        point = np.asarray(target, dtype=np.float64).reshape(3).copy()

        def apply() -> None:
            cloth = self.cloths.get(asset_id)
            if cloth is not None:
                cloth.drag_grabbed(point)

        self._submit(apply)

    def release(self) -> None:
        def apply() -> None:
            for cloth in self.cloths.values():
                cloth.release()

        self._submit(apply)

    # ------------------------------------------------------------- stepping
    def step(self, dt: float | None = None) -> None:
        """Step every cloth once now, on the calling thread (waits for a step in flight)."""
        with self._sim:
            self._apply_ops()
            self._step_all(self.dt if dt is None else dt)

    def _step_all(self, dt: float) -> None:
        for aid, cloth in list(self.cloths.items()):
            if cloth.error is not None:
                continue
            try:
                cloth.step(dt)
            except RuntimeError as exc:  # ClothBlowUp: the cloth stays stopped until reset
                self.errors[aid] = str(exc)
        self._publish()

    def _publish(self) -> None:
        self._frames = {aid: _snapshot(c) for aid, c in self.cloths.items()}
        self.version += 1

    def frame(self, asset_id: str) -> LiveClothFrame | None:
        """The latest snapshot of one live cloth."""
        return self._frames.get(asset_id)

    def frames(self) -> dict[str, LiveClothFrame]:
        """The latest snapshots of every live cloth (what a view draws)."""
        return dict(self._frames)

    def _run(self) -> None:
        last = self._clock()
        acc = 0.0
        while True:
            with self._cond:
                while not self._closed and not self._ops and not self._running():
                    self._cond.wait()
                    last, acc = self._clock(), 0.0
                if self._closed:
                    return
            running = False
            with self._sim:
                self._apply_ops()
                with self._cond:
                    running = self._running()   # checked again under _sim: see settle()
                if running:
                    now = self._clock()
                    acc = min(acc + (now - last), 3 * self.dt)
                    last = now
                    if acc >= self.dt:
                        acc -= self.dt
                        self._stepping = True
                        try:
                            self._step_all(self.dt)
                        finally:
                            self._stepping = False
            if running and acc < self.dt:
                with self._cond:
                    if not self._ops and self._running():
                        self._cond.wait(self.dt - acc)
