"""Autosave and crash recovery, with the real recovery folder under QTANIMATOR_SETTINGS_DIR."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from PySide6.QtWidgets import QMessageBox

from qtanimator.core.channel import Key
from qtanimator.document import InsertKey
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
    assert manager.autosave()
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
    assert first.recovery.autosave()
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
    assert first.recovery.autosave()
    note = json.loads(first.recovery.note_path.read_text())
    note["pid"] = _dead_pid()
    first.recovery.note_path.write_text(json.dumps(note))
    project = first.recovery.project_path
    second = MainWindow()  # conftest answers every question with Discard
    qtbot.addWidget(second)
    qtbot.waitUntil(lambda: not project.exists())
    assert second.doc.channels == {}
