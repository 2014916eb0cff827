"""Autosave to a recovery file, and the offer to recover after a crash.

Every minute while the document has unsaved changes, the window writes it as an ordinary
project into the recovery folder (``<settings>/recovery``, under QTANIMATOR_SETTINGS_DIR
when set), next to a small ``.json`` note with the process id and the project's own path.
Saving, closing or discarding removes both. At start, recovery files whose process is no
longer running were left by a crash, and the user is asked whether to recover them.
"""

from __future__ import annotations

import json
import os
import time
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from PySide6.QtCore import QEvent, QObject, QStandardPaths, QTimer
from PySide6.QtWidgets import QApplication, QMessageBox

from qtanimator.document.io import open_document, to_project_data
from qtanimator.formats.atomic import write_text_atomic
from qtanimator.formats.errors import FormatError
from qtanimator.formats.project import save_project

if TYPE_CHECKING:
    from qtanimator.ui.main_window import MainWindow

AUTOSAVE_INTERVAL_MS = 60_000
SUFFIX = ".qtanim"


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
            records.append(RecoveryRecord(project, note, int(meta.get("pid", 0)),
                                          meta.get("original_path"), float(meta.get("saved_at", 0.0))))
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
        self._saved_index: int | None = None
        self.timer = QTimer(self)
        self.timer.setObjectName("autosaveTimer")
        self.timer.setInterval(interval_ms)
        self.timer.timeout.connect(self.autosave)
        self.timer.start()
        stack = window.ctx.undo_stack
        stack.cleanChanged.connect(self._on_clean_changed)
        window.ctx.documentReset.connect(self._on_reset)
        project, note = self.project_path, self.note_path
        # Plain function: runs even while the window is being destroyed.
        window.destroyed.connect(lambda *_a: _remove_files(project, note))
        app = QApplication.instance()
        if app is not None:
            app.aboutToQuit.connect(self.discard)
        window.installEventFilter(self)

    # ---------------------------------------------------------------- autosave
    def has_unsaved_changes(self) -> bool:
        return not self.window.ctx.undo_stack.isClean()

    def autosave(self) -> bool:
        """Write the recovery file if there are changes since the last one. True if written."""
        if not self.has_unsaved_changes():
            self.discard()
            return False
        index = self.window.ctx.undo_stack.index()
        if index == self._saved_index and self.project_path.is_file():
            return False
        doc = self.window.doc
        try:
            self.window.prepare_save()
            self.project_path.parent.mkdir(parents=True, exist_ok=True)
            save_project(to_project_data(doc), self.project_path)
            note = {"pid": os.getpid(), "original_path": doc.path, "saved_at": time.time(),
                    "qtanimator_recovery": 1}
            write_text_atomic(self.note_path, json.dumps(note, indent=1))
        except (OSError, ValueError):
            return False  # autosave never interrupts work
        self._saved_index = index
        return True

    def discard(self) -> None:
        """Remove this window's recovery file (after a save, a close, or New / Open)."""
        self._saved_index = None
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
        doc.path = record.original_path
        self.window.ctx.replace_document(doc)
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
            name = Path(record.original_path).name if record.original_path else "an untitled project"
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
