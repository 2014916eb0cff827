"""The cloth cache worker: cloth simulation off the UI thread (ARCHITECTURE §3: simulations
never run on the UI thread).

A Qt-free helper with its own thread; views only observe it (they poll
:attr:`ClothWorker.revision` from a timer and draw what is there):

* :class:`ClothWorker` (``doc.caches["cloths"]``, see :func:`cloth_worker`; its thread is a
  :class:`~qtanimator.document.simulation.SimulationWorker`) fills the document's cloth caches
  (:class:`~qtanimator.document.cloth.ClothCache`) forward, frame by frame, from the first
  frame missing up to ``frame_end``. It listens to the document: a change that touches a
  cloth (see :func:`cloth_invalidations`) drops that cloth's job, cancels its step in flight
  (between two substeps) and starts again on the rebuilt cache. Work can be cancelled and
  resumed; the frames are those of a synchronous run (the same
  :class:`~qtanimator.core.cloth.Cloth` steps, and a cancelled step is undone).
* The interactive live cloths (:class:`~qtanimator.document.live_cloth.LiveCloths`,
  :class:`~qtanimator.document.live_cloth.LiveClothFrame`) live in
  :mod:`qtanimator.document.live_cloth`; they are re-exported here.

The symplectic substep is one numba kernel that releases the GIL (``nogil=True``), and a
thread that holds the GIL hands it over every ``sys.getswitchinterval()`` (5 ms), so the UI
thread keeps running while it works.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass

from qtanimator.document.cloth import ASSET_KIND, ClothCache, cloth_cache
from qtanimator.document.document import Document, DocumentChange
from qtanimator.document.live_cloth import LiveClothFrame, LiveCloths
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


__all__ = [
    "CLOTH_CACHE",
    "GRID_PARAMETERS",
    "TARGET_PARAMETERS",
    "ClothProgress",
    "ClothWorker",
    "LiveClothFrame",
    "LiveCloths",
    "cloth_invalidations",
    "cloth_worker",
]
