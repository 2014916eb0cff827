"""Simulations off the UI thread: a Qt-free background worker for the simulation caches.

A cache (the pendulum cache of :mod:`qtanimator.document.character2d`) owns one
:class:`SimulationWorker`. The worker is a daemon thread that calls the cache's ``job``
again and again while the job reports more to do; each call advances one frame (the job
decides which), so cancelling, restarting and shutting down take effect within one frame.

The cache keeps the thread-safety rules (see ``PendulumCache``): a job computes a frame
without holding the cache's lock and appends it under the lock only if no invalidation
happened meanwhile (a generation counter), so a frame computed from a state that an edit
dropped never enters the cache. Invalidation wakes the worker, which then refills from the
earliest invalid frame: that is the restart.

Nothing here touches Qt. The UI learns about progress by polling :func:`progress` (a
revision number and a busy flag) once per displayed frame.

Lifetime: the thread holds only a weak reference to its cache, so dropping a document
(and with it ``doc.caches``) ends the thread; :func:`stop_simulations` stops a document's
workers (File ▸ New / Open and closing the window call it); :func:`shutdown_all` stops
every worker of the process (tests).
"""

from __future__ import annotations

import threading
import time
import weakref
from collections.abc import Callable
from typing import Any, Protocol

from qtanimator.document.document import Document

#: A job: called with ``should_stop`` (poll it between sub-steps if a frame is long);
#: returns True while there is more to do.
Job = Callable[[Callable[[], bool]], bool]

_WORKERS: weakref.WeakSet[SimulationWorker] = weakref.WeakSet()

#: Set while no gesture is in progress. While the user drags, every worker waits between
#: frames: each mouse move invalidates what it would compute, and Python threads share one
#: interpreter lock, so a worker busy during a drag takes half the UI thread's time. The
#: simulation catches up when the gesture ends.
_RESUMED = threading.Event()
_RESUMED.set()
_PAUSES = 0
_PAUSE_LOCK = threading.Lock()


def pause_workers() -> None:
    """Hold every worker between frames until :func:`resume_workers` (nested calls count)."""
    global _PAUSES
    with _PAUSE_LOCK:
        _PAUSES += 1
        _RESUMED.clear()


def resume_workers() -> None:
    """Undo one :func:`pause_workers`; the workers go on when none is left."""
    global _PAUSES
    with _PAUSE_LOCK:
        _PAUSES = max(_PAUSES - 1, 0)
        if _PAUSES == 0:
            _RESUMED.set()


def workers_paused() -> bool:
    return not _RESUMED.is_set()


#: Set while the UI thread's event loop waits for events (or when there is no UI). Python
#: threads share one interpreter lock, and every Qt call the UI thread makes hands the lock
#: over: while a worker computes, each of those calls waits up to a switch interval to get
#: it back, so a paint of a few hundred calls takes tens of milliseconds instead of one.
#: The workers therefore run their frames (about a millisecond each) while the UI thread
#: idles; when it stays busy longer than :data:`UI_BUSY_WAIT_S` a worker goes on anyway, so
#: a simulation always makes progress.
_UI_IDLE = threading.Event()
_UI_IDLE.set()
#: The longest a worker waits for the UI thread to go idle before its next frame (s).
UI_BUSY_WAIT_S = 0.05


def ui_busy() -> None:
    """The UI thread is handling events (the event dispatcher woke up)."""
    if _UI_IDLE.is_set():  # is_set takes no lock: the common case costs nothing
        _UI_IDLE.clear()


def ui_idle() -> None:
    """The UI thread waits for events (the event dispatcher is about to block)."""
    if not _UI_IDLE.is_set():
        _UI_IDLE.set()


class SimulationCache(Protocol):
    """What the UI polls on every cache in ``doc.caches``."""

    @property
    def revision(self) -> int: ...

    @property
    def busy(self) -> bool: ...

    def shutdown(self, timeout: float | None = ...) -> None: ...


class SimulationWorker:
    """One daemon thread running a cache's job while it has work.

    ``wake()`` asks for work (starting the thread on first use or after a shutdown);
    ``cancel()`` abandons the current run until the next ``wake()``; ``shutdown()`` ends
    the thread (a later ``wake()`` starts a new one).
    """

    def __init__(self, job: Job, name: str = "simulation") -> None:
        if hasattr(job, "__self__"):
            self._job: Callable[[], Job | None] = weakref.WeakMethod(job)
        else:
            self._job = lambda: job
        self.name = name
        self._cond = threading.Condition()
        self._thread: threading.Thread | None = None
        self._stop_thread = threading.Event()
        self._wanted = False
        self._running = 0  # threads inside a run (an old one may still be winding down)
        self._cancel = 0
        #: The last exception a job raised (that run stops; the next wake tries again).
        self.error: BaseException | None = None
        #: How many runs were started (a wake while idle) — a restart counter for tests.
        self.runs = 0
        _WORKERS.add(self)

    # ------------------------------------------------------------------ control
    @property
    def alive(self) -> bool:
        thread = self._thread
        return thread is not None and thread.is_alive()

    @property
    def busy(self) -> bool:
        """True while work is asked for or being done."""
        return self._wanted or self._running > 0

    def wake(self) -> None:
        """Ask for work: the thread runs the job until it reports nothing more to do."""
        with self._cond:
            self._wanted = True
            if self._thread is None or not self._thread.is_alive() or self._stop_thread.is_set():
                # Each thread has its own stop flag: one still winding down after a
                # shutdown exits on its own while the new one takes the work.
                self._stop_thread = threading.Event()
                self._thread = threading.Thread(target=self._loop, args=(self._stop_thread,),
                                                name=f"qtanimator-{self.name}", daemon=True)
                self._thread.start()
            self._cond.notify_all()

    def cancel(self) -> None:
        """Abandon the current run: the frame being computed is finished or discarded (the
        cache's generation check) and nothing more is done until the next ``wake()``."""
        with self._cond:
            self._wanted = False
            self._cancel += 1

    def shutdown(self, timeout: float | None = 5.0) -> None:
        """End the thread and wait for it (at most ``timeout`` seconds; never from itself)."""
        with self._cond:
            self._stop_thread.set()
            self._wanted = False
            self._cancel += 1
            thread = self._thread
            self._cond.notify_all()
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout)

    # --------------------------------------------------------------------- loop
    def _loop(self, stop: threading.Event) -> None:
        while True:
            with self._cond:
                while not self._wanted and not stop.is_set():
                    self._cond.wait()
                if stop.is_set():
                    return
                self._wanted = False
                self._running += 1
                token = self._cancel
                self.runs += 1

            def should_stop(token: int = token) -> bool:
                return stop.is_set() or self._cancel != token

            try:
                while not should_stop():
                    while not _RESUMED.wait(0.05):  # a gesture is in progress
                        if should_stop():
                            break
                    if should_stop():
                        break
                    _UI_IDLE.wait(UI_BUSY_WAIT_S)  # let a busy UI thread finish first
                    job = self._job()
                    if job is None:  # the cache (its document) is gone
                        stop.set()
                        return
                    try:
                        more = job(should_stop)
                    except Exception as exc:  # noqa: BLE001 - kept in .error, the run ends
                        self.error = exc
                        more = False
                    del job
                    if not more:
                        break
                    time.sleep(0)  # hand the interpreter to the UI thread between frames
            finally:
                with self._cond:
                    self._running -= 1


def running_workers() -> list[SimulationWorker]:
    """Workers whose thread is alive (tests check that none is left behind)."""
    return [w for w in list(_WORKERS) if w.alive]


def shutdown_all(timeout: float | None = 5.0) -> None:
    """Stop every worker thread of the process."""
    for worker in list(_WORKERS):
        worker.shutdown(timeout)


def progress(doc: Document) -> tuple[int, bool]:
    """``(revision, busy)`` over every simulation cache of ``doc``: the revision changes
    whenever frames are added or dropped; busy is True while a worker has work. Cheap: the
    UI polls it once per displayed frame."""
    busy = False
    revision = 0
    # Busy first: a worker that reads idle has committed everything the revision then shows.
    for cache in list(doc.caches.values()):
        busy = busy or bool(getattr(cache, "busy", False))
    for cache in list(doc.caches.values()):
        revision += int(getattr(cache, "revision", 0))
    return revision, busy


def stop_simulations(doc: Document) -> None:
    """Stop the worker threads of ``doc``'s caches (they start again when asked)."""
    for cache in list(doc.caches.values()):
        stop: Any = getattr(cache, "shutdown", None)
        if callable(stop):
            stop()
