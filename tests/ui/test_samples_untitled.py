"""Bundled samples open as untitled copies (issue 30, part 4): Save asks where, the dialog
starts in the documents folder, nothing is ever written into the samples folder (not by
Save, not by autosave), and the saved copy reopens with the same assets from its new folder."""

from __future__ import annotations

import hashlib
import json
import subprocess
import sys
from pathlib import Path

import pytest
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QCheckBox, QFileDialog, QMessageBox

from qtanimator.core.channel import Key
from qtanimator.document import InsertKey, open_document
from qtanimator.document.asset_files import file_refs
from qtanimator.paths import demo_project, is_sample, sample_dirs
from qtanimator.ui.app_settings import documents_dir, save_dir, settings
from qtanimator.ui.main_window import MainWindow
from qtanimator.ui.recovery import list_recovery_files

DEMO = demo_project()


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _folder_listing(folder: Path) -> dict[str, str]:
    return {str(p.relative_to(folder)): _digest(p) for p in sorted(folder.rglob("*")) if p.is_file()}


class SaveDialogs:
    """Stands in for the Save As dialog's ``exec`` (``run``): records each call (its start folder and
    file name, the state of the collect box), then accepts ``answer`` or cancels."""

    def __init__(self, answer: Path | None, collect: bool | None = None) -> None:
        self.answer = answer
        self.collect = collect
        self.calls: list[dict[str, object]] = []

    def run(self, dialog: QFileDialog) -> int:
        box = dialog.findChild(QCheckBox, "collectAssetsCheck")
        self.calls.append({"folder": dialog.directory().absolutePath(), "box": box.isChecked(),
                           "files": QFileDialog.selectedFiles(dialog)})
        if self.answer is None:
            return 0
        if self.collect is not None:
            box.setChecked(self.collect)
        return 1

    def install(self, monkeypatch: pytest.MonkeyPatch) -> None:
        offered = QFileDialog.selectedFiles
        monkeypatch.setattr(QFileDialog, "exec", lambda dialog: self.run(dialog))
        # Before exec: the file name offered; after: the answer (in a folder not made yet).
        monkeypatch.setattr(QFileDialog, "selectedFiles",
                            lambda dialog: [str(self.answer)] if self.calls and self.answer else offered(dialog))


@pytest.fixture
def demo_window(make_window):  # type: ignore[no-untyped-def]
    window = make_window(full=True)
    before = _digest(DEMO)
    assert window.open_path(DEMO)
    yield window
    assert _digest(DEMO) == before, "the shipped demo was written"


def _edit(window: MainWindow, value: float = 0.25) -> None:
    window.ctx.push(InsertKey(window.doc, "pip/head/angle", Key(0.5, value)))
    assert window.is_modified()


def test_the_samples_folders_are_the_packages_scenes():
    assert sample_dirs() and all(d.name == "scenes" for d in sample_dirs())
    assert is_sample(DEMO) and is_sample(DEMO.parent) and not is_sample(Path.home())


def test_the_demo_opens_as_an_untitled_copy(demo_window):
    window = demo_window
    assert window.doc.path is None and window.sample == DEMO.resolve()
    assert window.windowTitle().startswith("demo (sample) — untitled")
    assert not window.is_modified()  # an untouched copy closes without asking
    # Its assets are still read from the sample's folder.
    pip = window.doc.assets["pip"]
    assert Path(pip.source) == (DEMO.parent / "pip.svg").resolve()


@pytest.mark.parametrize("collect", [True, False], ids=["collected", "referenced"])
def test_ctrl_s_on_the_demo_asks_where_and_leaves_the_sample_untouched(demo_window, qtbot, tmp_path, monkeypatch,
                                                                      collect):
    window = demo_window
    _edit(window)
    before = _folder_listing(DEMO.parent.parent)
    target = tmp_path / "mine" / "demo.qtanim"
    dialogs = SaveDialogs(target, collect)
    dialogs.install(monkeypatch)
    window.activateWindow()
    qtbot.keyClick(window, Qt.Key.Key_S, Qt.KeyboardModifier.ControlModifier)
    qtbot.waitUntil(lambda: bool(dialogs.calls))
    call = dialogs.calls[0]
    # Asked where, starting in the documents folder (not in the package), the sample's name
    # offered, and "collect assets" ticked for a copy of a sample.
    assert not is_sample(str(call["folder"])) and Path(str(call["folder"])) == Path(documents_dir())
    assert [Path(str(f)).name for f in call["files"]] == ["demo.qtanim"]  # type: ignore[attr-defined]
    assert call["box"] is True
    assert target.is_file()
    assert _folder_listing(DEMO.parent.parent) == before  # nothing in the samples changed
    assert window.doc.path == str(target.resolve()) and window.sample is None
    assert window.windowTitle().startswith("demo.qtanim") and not window.is_modified()
    # The copy reopens from its new folder with the same assets (the same files' content).
    saved = json.loads(target.read_text(encoding="utf-8"))
    again = open_document(target)
    assert set(again.assets) == set(window.doc.assets)
    assert again.channels == window.doc.channels
    original_refs = {(r.asset_id, r.key): Path(r.path) for r in file_refs(open_document(DEMO).assets.values())}
    refs = {(r.asset_id, r.key): Path(r.path) for r in file_refs(again.assets.values())}
    assert refs.keys() == original_refs.keys() and refs
    for ref, path in refs.items():
        original = original_refs[ref]
        assert path.exists() and path.name == original.name, ref
        if collect:  # copies that travel with the project
            assert path.is_relative_to(target.parent / "assets") and not is_sample(path), ref
            assert path.is_dir() or path.read_bytes() == original.read_bytes()
        else:  # the sample's own files, reached from the new folder
            assert path == original, ref
    if collect:
        assert all("outside" not in record for record in saved["assets"])
    # The next Ctrl+S saves in place without asking again.
    _edit(window, 0.5)
    qtbot.keyClick(window, Qt.Key.Key_S, Qt.KeyboardModifier.ControlModifier)
    qtbot.waitUntil(lambda: not window.is_modified())
    assert len(dialogs.calls) == 1


def test_cancelling_the_save_dialog_saves_nothing(demo_window, qtbot, tmp_path, monkeypatch):
    window = demo_window
    _edit(window)
    before = _folder_listing(DEMO.parent.parent)
    dialogs = SaveDialogs(None)
    dialogs.install(monkeypatch)
    window.activateWindow()
    qtbot.keyClick(window, Qt.Key.Key_S, Qt.KeyboardModifier.ControlModifier)
    qtbot.waitUntil(lambda: bool(dialogs.calls))
    assert _folder_listing(DEMO.parent.parent) == before
    assert window.is_modified() and window.doc.path is None and window.sample == DEMO.resolve()
    assert window.windowTitle().startswith("demo (sample) — untitled")
    assert not list(tmp_path.iterdir())


def test_the_user_choice_of_collecting_is_not_changed_by_a_sample(demo_window, tmp_path, monkeypatch):
    settings().setValue("collectAssets", False)
    _edit(demo_window)
    dialogs = SaveDialogs(tmp_path / "a.qtanim")
    dialogs.install(monkeypatch)
    assert demo_window.save()
    assert settings().value("collectAssets", type=bool) is False


def test_saving_into_the_samples_folder_is_refused(demo_window, dialog_log):
    window = demo_window
    _edit(window)
    assert not window.save_to(DEMO)
    assert not window.save_to(DEMO.parent / "new.qtanim")
    assert not (DEMO.parent / "new.qtanim").exists()
    assert dialog_log and all(title == "Cannot save" for title, _text in dialog_log)
    assert "samples" in dialog_log[0][1]
    assert window.is_modified()


def test_after_opening_a_sample_save_dialogs_start_outside_the_samples(demo_window):
    # Opening the demo made its folder the last folder (for Open); Save starts elsewhere.
    assert is_sample(settings().value("lastDir"))
    assert not is_sample(save_dir()) and save_dir() == documents_dir()


def _dead_pid() -> int:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def test_autosave_of_the_demo_writes_only_to_the_recovery_folder_and_recovers_a_copy(demo_window, qtbot,
                                                                                      monkeypatch):
    window = demo_window
    _edit(window)
    before = _folder_listing(DEMO.parent.parent)
    manager = window.recovery
    assert manager.autosave(wait=True)
    assert not is_sample(manager.project_path) and manager.project_path.is_file()
    assert _folder_listing(DEMO.parent.parent) == before
    note = json.loads(manager.note_path.read_text())
    assert note["original_path"] is None and Path(note["sample"]) == DEMO.resolve()
    expected = window.doc.state()
    # The window "crashes": recovery offers the work as an untitled copy of the demo.
    note["pid"] = _dead_pid()
    manager.note_path.write_text(json.dumps(note))
    asked: list[str] = []

    def answer_yes(_parent, _title, text, *args, **kwargs):  # type: ignore[no-untyped-def]
        asked.append(text)
        return QMessageBox.StandardButton.Yes

    monkeypatch.setattr(QMessageBox, "question", staticmethod(answer_yes))
    second = MainWindow()
    qtbot.addWidget(second)
    qtbot.waitUntil(lambda: bool(asked))
    assert "sample demo" in asked[0]
    assert second.doc.state() == expected and second.doc.path is None
    assert second.sample == DEMO.resolve() and second.is_modified()
    assert second.windowTitle().startswith("demo (sample) — untitled")
    assert manager.project_path not in [r.project for r in list_recovery_files()]


def test_a_recovery_note_naming_a_sample_as_its_path_recovers_a_copy(qtbot, monkeypatch):
    first = MainWindow(install_editors={"recovery"})
    qtbot.addWidget(first)
    qtbot.wait(20)
    first.ctx.push(InsertKey(first.doc, "hero//x", Key(0.5, 3.0)))
    assert first.recovery.autosave(wait=True)
    note = json.loads(first.recovery.note_path.read_text())
    note.update(pid=_dead_pid(), original_path=str(DEMO), sample=None)  # as an older version wrote it
    first.recovery.note_path.write_text(json.dumps(note))
    monkeypatch.setattr(QMessageBox, "question", staticmethod(lambda *a, **k: QMessageBox.StandardButton.Yes))
    second = MainWindow(install_editors={"recovery"})
    qtbot.addWidget(second)
    qtbot.waitUntil(lambda: "hero//x" in second.doc.channels)
    assert second.doc.path is None and second.sample == DEMO
