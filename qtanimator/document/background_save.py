"""Saving a document on a worker thread, so that the UI thread only takes a snapshot.

The UI thread calls :func:`qtanimator.document.io.to_project_data`, which copies a few
dicts and no key: channels are immutable values and commands replace assets rather than
change them (parameters, view state and asset properties are small and copied in depth).
:class:`BackgroundSaver` then turns the snapshot into JSON text and writes it atomically on
its one worker thread. Whoever scheduled the save collects the finished jobs on its own
thread (:meth:`BackgroundSaver.collect`); the saver calls nothing back.

A newer save supersedes one still in flight: the older job stops between channels and
writes nothing. :meth:`BackgroundSaver.discard` goes further: what the jobs in flight
write is removed again, so that after it returns and the caller has removed the files, no
file of theirs appears (the crash-recovery file of a closed window must not outlive it).
"""

from __future__ import annotations

import logging
import os
import threading
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path

from qtanimator.formats.atomic import write_chunks_atomic
from qtanimator.formats.project import ProjectData, json_utf8, project_json_parts

log = logging.getLogger(__name__)

#: Writes the chunks to a path atomically (tests put a barrier in here).
FileWriter = Callable[[Path, Iterable[bytes]], None]


class _Stopped(Exception):
    """Raised into the writer by the chunks of a job that was called off: the writer
    removes its temporary file and the old file stays."""


class SaveJob:
    """One snapshot on its way to ``path``, then the small ``companions`` files (a note
    beside a recovery file), all written by the same writer after the project.
    ``context`` is whatever the scheduler wants to find on the job again."""

    def __init__(self, data: ProjectData, path: Path, companions: Sequence[tuple[Path, bytes]] = (),
                 context: object = None) -> None:
        self.data = data
        self.path = path
        self.companions = tuple(companions)
        self.context = context
        self.future: Future[bool] | None = None
        #: Set on the worker: the project and its companions are on disk (and were not
        #: discarded afterwards).
        self.written = False
        #: What stopped the write (an OSError, or a ValueError for a value JSON cannot store).
        self.error: Exception | None = None
        self._superseded = threading.Event()
        self._discarded = threading.Event()

    @property
    def superseded(self) -> bool:
        return self._superseded.is_set()

    @property
    def discarded(self) -> bool:
        return self._discarded.is_set()

    def stopped(self) -> bool:
        """True once a newer save or a discard made this one pointless."""
        return self._superseded.is_set() or self._discarded.is_set()

    @property
    def done(self) -> bool:
        return self.future is not None and self.future.done()

    def wait(self, timeout: float | None = None) -> bool:
        """Block until the job has finished; True if it wrote its files."""
        if self.future is not None:
            self.future.result(timeout)
        return self.written


class BackgroundSaver:
    """Writes project snapshots on one worker thread, newest first in importance.

    Every method is meant for one (the scheduling) thread; the worker only touches the
    jobs it runs. The worker thread starts with the first save.
    """

    def __init__(self, write_file: FileWriter = write_chunks_atomic, name: str = "qtanimator-save") -> None:
        self.write_file = write_file
        self._name = name
        self._executor: ThreadPoolExecutor | None = None
        self._jobs: list[SaveJob] = []
        self._closed = False

    # ------------------------------------------------------------ scheduling
    def submit(self, data: ProjectData, path: str | os.PathLike[str],
               companions: Sequence[tuple[Path, bytes]] = (), context: object = None) -> SaveJob:
        """Write ``data`` to ``path`` on the worker; every earlier job still in flight is
        superseded (it writes nothing unless it is already writing)."""
        if self._closed:
            raise RuntimeError("the saver has been shut down")
        for older in self._jobs:
            older._superseded.set()
        job = SaveJob(data, Path(path), companions, context)
        if self._executor is None:
            self._executor = ThreadPoolExecutor(max_workers=1, thread_name_prefix=self._name)
        job.future = self._executor.submit(self._run, job)
        self._jobs.append(job)
        return job

    @property
    def busy(self) -> bool:
        """A submitted job has not finished yet."""
        return any(not job.done for job in self._jobs)

    @property
    def latest(self) -> SaveJob | None:
        """The newest job not yet collected (finished or not)."""
        return self._jobs[-1] if self._jobs else None

    def collect(self) -> list[SaveJob]:
        """The jobs that have finished since the last call, oldest first."""
        finished = [job for job in self._jobs if job.done]
        self._jobs = [job for job in self._jobs if not job.done]
        return finished

    def discard(self) -> None:
        """Stop every job in flight and have each remove whatever it still writes.

        Does not wait: a job that is writing right now removes its files itself once it
        has written them, and the caller removes what is already there.
        """
        for job in self._jobs:
            job._discarded.set()

    def shutdown(self) -> None:
        """Discard what is in flight and let the worker thread end (without waiting)."""
        self.discard()
        self._closed = True
        if self._executor is not None:
            self._executor.shutdown(wait=False, cancel_futures=True)

    # ----------------------------------------------------------- worker thread
    def _run(self, job: SaveJob) -> bool:
        if job.stopped():
            return False
        try:
            # The text is encoded and written as it is made, a channel (or a long column's
            # thousand lines) at a time: no step holds the GIL for long, and the whole file
            # never sits in memory.
            self.write_file(job.path, _chunks(job))
            for path, data in job.companions:
                self.write_file(path, [data])
        except _Stopped:
            return False
        except (OSError, ValueError) as exc:
            job.error = exc
            log.warning("background save to %s failed: %s", job.path, exc)
            return False
        if job.discarded:
            # Discarded while writing: whoever discarded may already have removed the old
            # files, so take these back (superseded jobs keep theirs: a newer one follows).
            for path in (job.path, *(p for p, _ in job.companions)):
                try:
                    path.unlink()
                except OSError:
                    pass
            return False
        job.written = True
        return True


def _chunks(job: SaveJob) -> Iterator[bytes]:
    """The project file's bytes, ending in :class:`_Stopped` once the job is called off
    (checked between parts, and once more before the writer may swap the file in)."""
    for part in project_json_parts(job.data, job.path.parent):
        if job.stopped():
            raise _Stopped
        yield json_utf8(part)  # a file name that is not UTF-8 stays saveable (an escape)
    if job.stopped():
        raise _Stopped


def same_snapshot(a: ProjectData, b: ProjectData) -> bool:
    """True when two snapshots would save the same project.

    Channels are compared by identity (they are immutable, so the same object is the same
    channel, and comparing 600k keys is what a snapshot must avoid); the small rest by value.
    """
    if a.parameters != b.parameters or a.view != b.view or a.assets != b.assets:
        return False
    if list(a.channels) != list(b.channels):
        return False
    return all(ch is b.channels[cid] for cid, ch in a.channels.items())
