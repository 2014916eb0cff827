"""Autosave and crash recovery, with the real recovery folder under QTANIMATOR_SETTINGS_DIR."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import threading
from collections.abc import Iterable
from pathlib import Path

from PySide6.QtWidgets import QMessageBox

from qtanimator.core.channel import Key
from qtanimator.document import InsertKey, open_document
from qtanimator.formats.atomic import write_chunks_atomic
from qtanimator.ui.main_window import MainWindow
from qtanimator.ui.recovery import crashed_sessions, list_recovery_files, recovery_dir


def _dead_pid() -> int:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def test_recovery_folder_respects_settings_dir():
    assert Path(os.environ["QTANIMATOR_SETTINGS_DIR"]) in recovery_dir().parents


def test_autosave_writes_only_with_unsaved_changes_and_save_removes_it(qtbot, tmp_path):
    window = MainWindow()
    qtbot.addWidget(window)
    manager = window.recovery
    assert manager.timer.interval() == 60_000 and manager.timer.isActive()
    assert not manager.autosave()  # nothing to save
    assert not manager.project_path.exists()
    window.ctx.push(InsertKey(window.doc, "hero//x", Key(0.5, 3.0)))
    assert manager.autosave(wait=True)
    assert manager.project_path.is_file()
    note = json.loads(manager.note_path.read_text())
    assert note["pid"] == os.getpid()
    assert not manager.autosave()  # no change since the last autosave
    # A live process's file is not a crash.
    assert manager.project_path not in [r.project for r in crashed_sessions()]
    assert window.save_to(tmp_path / "p.qtanim")
    assert not manager.project_path.exists() and not manager.note_path.exists()


def test_recovery_after_a_crash(qtbot, tmp_path, monkeypatch):
    # A first window autosaves, then "crashes": its note now names a dead process.
    first = MainWindow()
    qtbot.addWidget(first)
    qtbot.wait(20)  # let the first window make its own start-up offer (there is nothing yet)
    first.ctx.push(InsertKey(first.doc, "hero//x", Key(0.5, 3.0)))
    first.ctx.push(InsertKey(first.doc, "hero//x", Key(1.0, -2.0)))
    expected = first.doc.state()
    assert first.recovery.autosave(wait=True)
    note = json.loads(first.recovery.note_path.read_text())
    note["pid"] = _dead_pid()
    note["original_path"] = str(tmp_path / "work.qtanim")
    first.recovery.note_path.write_text(json.dumps(note))
    project = first.recovery.project_path
    assert project in [r.project for r in crashed_sessions()]

    asked: list[str] = []

    def answer_yes(_parent, title, text, *args, **kwargs):
        asked.append(text)
        return QMessageBox.StandardButton.Yes

    monkeypatch.setattr(QMessageBox, "question", staticmethod(answer_yes))
    second = MainWindow()
    qtbot.addWidget(second)
    qtbot.waitUntil(lambda: bool(asked))
    assert "work.qtanim" in asked[0]
    assert second.doc.state() == expected
    assert second.doc.path == str(tmp_path / "work.qtanim")
    assert second.is_modified()
    assert project not in [r.project for r in list_recovery_files()]


def test_discarding_a_crash_file_removes_it(qtbot):
    first = MainWindow()
    qtbot.addWidget(first)
    qtbot.wait(20)  # let the first window make its own start-up offer (there is nothing yet)
    first.ctx.push(InsertKey(first.doc, "hero//x", Key(0.5, 3.0)))
    assert first.recovery.autosave(wait=True)
    note = json.loads(first.recovery.note_path.read_text())
    note["pid"] = _dead_pid()
    first.recovery.note_path.write_text(json.dumps(note))
    project = first.recovery.project_path
    second = MainWindow()  # conftest answers every question with Discard
    qtbot.addWidget(second)
    qtbot.waitUntil(lambda: not project.exists())
    assert second.doc.channels == {}


# ------------------------------------------------------------- writing off the UI thread
WAIT = 10.0  # seconds the held writer waits for the test (never reached when all is well)


class HeldWriter:
    """Stands in for the saver's file writer: records the writing thread and, for the
    recovery project file, waits until the test releases it."""

    def __init__(self, hold: Path) -> None:
        self.hold = hold
        self.entered = threading.Event()
        self.released = threading.Event()
        self.calls: list[tuple[Path, threading.Thread]] = []

    def __call__(self, path: Path, chunks: Iterable[bytes]) -> None:
        self.calls.append((path, threading.current_thread()))
        if path == self.hold:
            self.entered.set()
            if not self.released.wait(WAIT):
                raise OSError("the test never released the writer")
        write_chunks_atomic(path, chunks)

    def release(self) -> None:
        self.released.set()


def held_autosave(window: MainWindow) -> HeldWriter:
    writer = HeldWriter(window.recovery.project_path)
    window.recovery.saver.write_file = writer
    return writer


def test_autosave_returns_before_the_worker_writes(make_window, qtbot):
    window = make_window()
    manager = window.recovery
    writer = held_autosave(window)
    window.ctx.push(InsertKey(window.doc, "hero//x", Key(0.5, 3.0)))
    window.ctx.push(InsertKey(window.doc, "hero//x", Key(1.0, -2.0)))
    expected = window.doc.state()
    # The writer cannot finish until this thread releases it, so autosave() returning
    # True at all shows the UI thread only scheduled the save.
    assert manager.autosave()
    assert writer.entered.wait(WAIT)
    assert manager.busy and manager.poll_timer.isActive()
    assert not manager.project_path.exists() and not manager.note_path.exists()
    assert not manager.autosave()  # this state is being written already
    # The window keeps working meanwhile: an edit and a round of events.
    window.ctx.push(InsertKey(window.doc, "hero//x", Key(2.0, 5.0)))
    qtbot.wait(1)
    writer.release()
    qtbot.waitUntil(lambda: not manager.poll_timer.isActive())  # collected on the UI thread
    (thread,) = {t for _, t in writer.calls}
    assert thread is not threading.current_thread()
    assert [p for p, _ in writer.calls] == [manager.project_path, manager.note_path]
    assert open_document(manager.project_path).state() == expected
    assert json.loads(manager.note_path.read_text())["pid"] == os.getpid()
    # The edit made during the write goes into the next autosave; after it, nothing is new.
    assert manager.autosave(wait=True)
    assert open_document(manager.project_path).state() == window.doc.state() != expected
    assert not manager.autosave()


def test_a_newer_autosave_supersedes_the_one_in_flight(make_window, qtbot):
    window = make_window()
    manager = window.recovery
    writer = held_autosave(window)
    window.ctx.push(InsertKey(window.doc, "hero//x", Key(0.5, 3.0)))
    assert manager.autosave()
    assert writer.entered.wait(WAIT)
    window.ctx.push(InsertKey(window.doc, "hero//x", Key(1.0, 4.0)))
    assert manager.autosave()  # queued behind the write in progress, which it supersedes
    window.ctx.push(InsertKey(window.doc, "hero//x", Key(1.5, 5.0)))
    assert manager.autosave()  # supersedes the queued one before it starts
    writer.release()
    qtbot.waitUntil(lambda: not manager.poll_timer.isActive())
    # The write under way stopped before its file was swapped in, the queued one never
    # began: only the newest wrote.
    assert [p for p, _ in writer.calls] == [manager.project_path, manager.project_path, manager.note_path]
    assert open_document(manager.project_path).state() == window.doc.state()


def test_closing_during_an_autosave_leaves_no_recovery_file(make_window, qtbot):
    window = make_window()
    manager = window.recovery
    writer = held_autosave(window)
    window.ctx.push(InsertKey(window.doc, "hero//x", Key(0.5, 3.0)))
    assert manager.autosave()
    assert writer.entered.wait(WAIT)
    job = manager.saver.latest
    assert job is not None
    window.close()  # conftest answers "Discard" to "Save changes?"
    # The close does not wait for the worker: the discard happens with the write held.
    qtbot.waitUntil(lambda: job.discarded)
    assert not job.done
    writer.release()
    assert not job.wait(WAIT)
    assert not manager.project_path.exists() and not manager.note_path.exists()
    assert manager.project_path not in [r.project for r in list_recovery_files()]
