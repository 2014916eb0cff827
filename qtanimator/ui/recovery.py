"""Autosave to a recovery file, and the offer to recover after a crash.

Every minute while the document has unsaved changes, the window writes it as an ordinary
project into the recovery folder (``<settings>/recovery``, under QTANIMATOR_SETTINGS_DIR
when set), next to a small ``.json`` note with the process id and the project's own path.
Saving, closing or discarding removes both. An untitled copy of a bundled sample notes the
sample (``"sample"``) and recovers as such a copy again; a note whose original path is in
the samples recovers as an untitled copy too, so that recovery never leads to a write into
the samples folder. At start, recovery files whose process is no
longer running were left by a crash, and the user is asked whether to recover them.

The UI thread only takes a snapshot of the document (a copy of a few dicts); a worker
thread serialises and writes it (:mod:`qtanimator.document.background_save`), and a timer
on the UI thread collects the result. One autosave is in flight at a time: a newer one
supersedes it, and discarding (save, close, New / Open) stops it and removes what it wrote.
"""

from __future__ import annotations

import json
import logging
import os
import time
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from PySide6.QtCore import QEvent, QObject, QStandardPaths, QTimer
from PySide6.QtWidgets import QApplication, QMessageBox

from qtanimator.document.background_save import BackgroundSaver, SaveJob, same_snapshot
from qtanimator.document.io import open_document, to_project_data
from qtanimator.formats.errors import FormatError
from qtanimator.paths import is_sample

if TYPE_CHECKING:
    from qtanimator.ui.main_window import MainWindow

AUTOSAVE_INTERVAL_MS = 60_000
#: How often the UI thread looks whether the autosave in flight has finished.
POLL_INTERVAL_MS = 50
SUFFIX = ".qtanim"

log = logging.getLogger(__name__)


def recovery_dir() -> Path:
    """Where recovery files live (created on demand)."""
    folder = os.environ.get("QTANIMATOR_SETTINGS_DIR")
    if folder:
        base = Path(folder)
    else:
        base = Path(QStandardPaths.writableLocation(QStandardPaths.StandardLocation.AppDataLocation)
                    or Path.home() / ".qtanimator")
    return base / "recovery"


def _process_alive(pid: int) -> bool:
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    except OSError:
        return False
    return True


@dataclass(frozen=True)
class RecoveryRecord:
    """One recovery file: the project copy and what its note says."""

    project: Path
    note: Path
    pid: int
    original_path: str | None
    saved_at: float
    #: The bundled sample the autosaved document was an untitled copy of.
    sample: str | None = None

    @property
    def orphaned(self) -> bool:
        """Left behind by a process that is no longer running (a crash)."""
        return not _process_alive(self.pid)


def list_recovery_files() -> list[RecoveryRecord]:
    """Every recovery file in the recovery folder, newest first."""
    folder = recovery_dir()
    records: list[RecoveryRecord] = []
    if not folder.is_dir():
        return records
    for note in folder.glob("*.json"):
        project = note.with_suffix(SUFFIX)
        try:
            meta = json.loads(note.read_text(encoding="utf-8"))
            sample = meta.get("sample")
            records.append(RecoveryRecord(project, note, int(meta.get("pid", 0)),
                                          meta.get("original_path"), float(meta.get("saved_at", 0.0)),
                                          sample if isinstance(sample, str) else None))
        except (OSError, ValueError, TypeError, AttributeError):
            continue
    records.sort(key=lambda r: -r.saved_at)
    return records


def crashed_sessions() -> list[RecoveryRecord]:
    return [r for r in list_recovery_files() if r.orphaned and r.project.is_file()]


def remove_record(record: RecoveryRecord) -> None:
    for p in (record.project, record.note):
        try:
            p.unlink()
        except FileNotFoundError:
            pass


def _remove_files(*paths: Path) -> None:
    for p in paths:
        try:
            p.unlink()
        except (FileNotFoundError, OSError):
            pass


class RecoveryManager(QObject):
    """Autosaves one window's document and offers recovery at start."""

    def __init__(self, window: MainWindow, interval_ms: int = AUTOSAVE_INTERVAL_MS) -> None:
        super().__init__(window)
        self.setObjectName("recoveryManager")
        self.window = window
        stem = f"recovery-{os.getpid()}-{uuid.uuid4().hex[:8]}"
        self.project_path = recovery_dir() / f"{stem}{SUFFIX}"
        self.note_path = recovery_dir() / f"{stem}.json"
        #: Writes the recovery files on a worker thread (tests swap its ``write_file``).
        self.saver = BackgroundSaver(name="qtanimator-autosave")
        #: The last autosave that reached the disk (None once discarded).
        self._written: SaveJob | None = None
        self.timer = QTimer(self)
        self.timer.setObjectName("autosaveTimer")
        self.timer.setInterval(interval_ms)
        self.timer.timeout.connect(self.autosave)
        self.timer.start()
        self.poll_timer = QTimer(self)
        self.poll_timer.setObjectName("autosavePollTimer")
        self.poll_timer.setInterval(POLL_INTERVAL_MS)
        self.poll_timer.timeout.connect(self._collect)
        stack = window.ctx.undo_stack
        stack.cleanChanged.connect(self._on_clean_changed)
        window.ctx.documentReset.connect(self._on_reset)
        project, note, saver = self.project_path, self.note_path, self.saver

        def window_gone(*_args: object) -> None:
            # A plain function: runs even while the window is being destroyed.
            saver.shutdown()
            _remove_files(project, note)

        window.destroyed.connect(window_gone)
        app = QApplication.instance()
        if app is not None:
            app.aboutToQuit.connect(self.discard)
        window.installEventFilter(self)

    # ---------------------------------------------------------------- autosave
    def has_unsaved_changes(self) -> bool:
        return not self.window.ctx.undo_stack.isClean()

    @property
    def busy(self) -> bool:
        """An autosave is being written on the worker thread."""
        return self.saver.busy

    def autosave(self, wait: bool = False) -> bool:
        """Save the recovery file if the document changed since the last autosave.

        The UI thread takes a snapshot and returns; the worker thread writes it. Returns
        True when a save was started, or with ``wait`` (the same path, then blocking until
        the worker is done) True when it was written.
        """
        self._collect()
        if not self.has_unsaved_changes():
            self.discard()
            return False
        doc = self.window.doc
        try:
            self.window.prepare_save()
            data = to_project_data(doc)
            self.project_path.parent.mkdir(parents=True, exist_ok=True)
        except (OSError, ValueError):
            return False  # autosave never interrupts work
        latest = self.saver.latest
        if latest is not None and latest.stopped():
            latest = None
        if latest is None and self._written is not None and self.project_path.is_file():
            latest = self._written
        if latest is not None and same_snapshot(latest.data, data) and latest.context == doc.path:
            return False  # being written, or on disk already
        sample = self.window.sample
        note = {"pid": os.getpid(), "original_path": doc.path, "saved_at": time.time(),
                "qtanimator_recovery": 1, "sample": str(sample) if sample is not None else None}
        job = self.saver.submit(data, self.project_path,
                                [(self.note_path, json.dumps(note, indent=1).encode("utf-8"))],
                                context=doc.path)
        if wait:
            job.wait()
            self._collect()
            return job.written
        self.poll_timer.start()
        return True

    def _collect(self) -> None:
        """Take in the autosaves the worker has finished (UI thread)."""
        for job in self.saver.collect():
            if job.written and not job.discarded:
                self._written = job
            elif job.error is not None:
                log.warning("autosave failed: %s", job.error)
        if not self.saver.busy:
            self.poll_timer.stop()

    def discard(self) -> None:
        """Remove this window's recovery file (after a save, a close, or New / Open); an
        autosave in flight is stopped and what it still writes is removed too."""
        self._written = None
        self.saver.discard()
        _remove_files(self.project_path, self.note_path)

    def _on_clean_changed(self, clean: bool) -> None:
        if clean:
            self.discard()

    def _on_reset(self) -> None:
        if not self.has_unsaved_changes():
            self.discard()

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if watched is self.window and event.type() == QEvent.Type.Close:
            # closeEvent may still refuse; look once it has decided.
            QTimer.singleShot(0, self._after_close)
        return False

    def _after_close(self) -> None:
        if not self.window.isVisible():
            self.discard()

    # ---------------------------------------------------------------- recovery
    def recover(self, record: RecoveryRecord) -> bool:
        """Open a recovery file as unsaved work with its original path; True on success."""
        try:
            doc = open_document(record.project)
        except (FormatError, OSError) as exc:
            self.window.show_error("Cannot recover", str(exc))
            return False
        sample = record.sample
        if record.original_path and is_sample(record.original_path):
            sample = record.original_path  # written before samples opened as copies
        doc.path = None if sample else record.original_path
        self.window.sample = Path(sample) if sample else None
        self.window.ctx.replace_document(doc)
        self.window.restore_view_state()
        # The recovered work is not saved anywhere the user chose: keep it marked modified.
        self.window.ctx.undo_stack.resetClean()
        self.window.setWindowModified(True)
        remove_record(record)
        self.autosave()
        return True

    def offer_recovery(self) -> bool:
        """Ask about each crashed session's file (newest first). True if one was recovered."""
        for record in crashed_sessions():
            when = time.strftime("%Y-%m-%d %H:%M", time.localtime(record.saved_at))
            if record.original_path:
                name = Path(record.original_path).name
            elif record.sample:
                name = f"an untitled copy of the sample {Path(record.sample).stem}"
            else:
                name = "an untitled project"
            answer = QMessageBox.question(
                self.window, "Recover unsaved work",
                f"qtanimator did not close properly. Recover the changes to {name} autosaved at {when}?",
                QMessageBox.StandardButton.Yes | QMessageBox.StandardButton.Discard,
                QMessageBox.StandardButton.Yes)
            if answer == QMessageBox.StandardButton.Yes:
                if self.recover(record):
                    # Older crashed files stay for the next start.
                    return True
            else:
                remove_record(record)
        return False


def install(window: MainWindow) -> None:
    manager = RecoveryManager(window)
    window.recovery = manager  # type: ignore[attr-defined]
    QTimer.singleShot(0, manager.offer_recovery)
