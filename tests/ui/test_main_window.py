from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest
from docfix import set_parameters

from qtanimator.core.channel import Key
from qtanimator.document import InsertKey
from qtanimator.ui.main_window import MainWindow


@pytest.fixture(autouse=True)
def private_settings(tmp_path_factory, monkeypatch):
    """Each test gets its own settings file: layouts and recent files do not leak."""
    monkeypatch.setenv("QTANIMATOR_SETTINGS_DIR", str(tmp_path_factory.mktemp("settings")))


def test_window_runs_a_command_and_undoes_it(qtbot):
    window = MainWindow()
    qtbot.addWidget(window)
    window.show()
    doc = window.doc
    before = doc.state()
    window.ctx.push(InsertKey(doc, "hero//x", Key(0.5, 3.0)))
    assert doc.channels["hero//x"].evaluate(0.5) == 3.0
    assert window.isWindowModified()
    window.findChild(type(window.action_undo), "actionUndo").trigger()
    assert doc.state() == before
    assert not window.isWindowModified()
    window.action_redo.trigger()
    assert doc.channels["hero//x"].keys == (Key(0.5, 3.0),)


def test_drag_gesture_is_one_undo_step(qtbot):
    window = MainWindow()
    qtbot.addWidget(window)
    doc = window.doc
    for i in range(5):
        window.ctx.push(InsertKey(doc, "hero//x", Key(0.0, float(i)), gesture="drag-1"))
    assert window.ctx.undo_stack.count() == 1
    assert doc.channels["hero//x"].evaluate(0.0) == 4.0
    window.ctx.undo_stack.undo()
    assert "hero//x" not in doc.channels


def test_docks_have_stable_names(qtbot):
    window = MainWindow()
    qtbot.addWidget(window)
    from PySide6.QtWidgets import QDockWidget

    assert window.findChild(QDockWidget, "undoHistoryDock") is not None
    for name in ("actionUndo", "actionRedo", "actionSave", "actionOpen"):
        assert window.findChild(type(window.action_save), name) is not None


# ---------------------------------------------------------------------------- files
def _project(tmp_path, name="scene.qtanim", value=2.0):
    from qtanimator.document import Document, UndoStack, save_document

    doc = Document()
    UndoStack(doc).push(InsertKey(doc, "hero//x", Key(1.0, value)))
    path = tmp_path / name
    save_document(doc, path)
    return path


def test_unsaved_changes_prompt_then_open(qtbot, tmp_path, monkeypatch):
    from PySide6.QtWidgets import QMessageBox

    window = MainWindow(install_editors=False)
    qtbot.addWidget(window)
    asked: list[str] = []

    def question(_parent, title, text, *args, **kwargs):  # type: ignore[no-untyped-def]
        asked.append(title)
        return QMessageBox.StandardButton.Cancel

    monkeypatch.setattr(QMessageBox, "question", staticmethod(question))
    window.ctx.push(InsertKey(window.doc, "hero//y", Key(0.0, 1.0)))
    assert window.isWindowModified()
    window.new_document()  # the user cancels: nothing happens
    assert asked == ["Unsaved changes"] and "hero//y" in window.doc.channels
    monkeypatch.setattr(QMessageBox, "question", staticmethod(lambda *a, **k: QMessageBox.StandardButton.Discard))
    window.new_document()  # the user discards
    assert window.doc.channels == {} and not window.isWindowModified()
    assert window.ctx.undo_stack.count() == 0


def test_save_then_open_gives_the_same_state(qtbot, tmp_path):
    window = MainWindow(install_editors=False)
    qtbot.addWidget(window)
    window.ctx.push(InsertKey(window.doc, "hero//x", Key(0.25, 4.0)))
    window.ctx.push(InsertKey(window.doc, "hero//x", Key(1.0, -1.0)))
    state = window.doc.state()
    path = tmp_path / "saved.qtanim"
    assert window.save_to(path)
    assert not window.isWindowModified() and "saved.qtanim" in window.windowTitle()
    window.new_document()
    assert window.doc.state() != state
    resets: list[bool] = []
    window.ctx.documentReset.connect(lambda: resets.append(True))
    assert window.open_path(path)
    assert window.doc.state() == state and resets == [True]
    assert window.doc.path == str(path.resolve())
    # Save goes back to the same file without asking.
    window.ctx.push(InsertKey(window.doc, "hero//x", Key(2.0, 0.0)))
    window.action_save.trigger()
    assert not window.isWindowModified()
    from qtanimator.document import open_document

    assert open_document(path).state() == window.doc.state()


def test_opening_a_bad_file_shows_the_error_and_changes_nothing(qtbot, tmp_path, dialog_log):
    window = MainWindow()
    qtbot.addWidget(window)
    window.ctx.push(InsertKey(window.doc, "hero//x", Key(0.5, 3.0)))
    before = window.doc.state()
    bad = tmp_path / "broken.qtanim"
    bad.write_text('{"format": "qtanimator-project", "version": 99}')
    assert not window.open_path(bad)
    assert dialog_log and dialog_log[-1][0] == "Cannot open file"
    assert "broken.qtanim" in dialog_log[-1][1] and "newer qtanimator" in dialog_log[-1][1]
    assert window.doc.state() == before
    assert window.ctx.undo_stack.count() == 1  # the history survives too
    assert not window.open_path(tmp_path / "notes.unknownsuffix")
    assert len(dialog_log) == 2 and window.doc.state() == before
    assert str(bad.resolve()) not in window.recent_files()


def test_saving_to_an_impossible_place_names_the_target_not_the_temporary_file(qtbot, tmp_path, dialog_log,
                                                                              monkeypatch):
    window = MainWindow(install_editors=False)
    qtbot.addWidget(window)
    window.ctx.push(InsertKey(window.doc, "hero//x", Key(0.5, 3.0)))
    blocker = tmp_path / "a_file.txt"
    blocker.write_text("not a folder")
    target = blocker / "inside" / "x.qtanim"  # a folder cannot be made inside a file
    assert not window.save_to(target)
    title, text = dialog_log[-1]
    assert title == "Cannot save"
    assert str(target.parent) in text and ".tmp" not in text
    assert window.isWindowModified()
    # A read-only folder (root may write anyway): the message names the project file, never
    # the temporary one.
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o555)
    try:
        if not os.access(locked, os.W_OK):
            assert not window.save_to(locked / "x.qtanim")
            assert str(locked / "x.qtanim") in dialog_log[-1][1] and ".tmp" not in dialog_log[-1][1]
    finally:
        locked.chmod(0o755)
    # Whatever the operating system's error names (the temporary file), the dialog names the target.
    import errno

    import qtanimator.ui.main_window as main_window

    def failing_save(doc, path):  # type: ignore[no-untyped-def]
        raise PermissionError(errno.EACCES, "Permission denied", str(Path(path).parent / ".x.qtanim.f8svxrjl.tmp"))

    monkeypatch.setattr(main_window, "save_document", failing_save)
    assert not window.save_to(tmp_path / "x.qtanim")
    assert dialog_log[-1][1] == f"Cannot save {tmp_path / 'x.qtanim'}: Permission denied."


def test_save_as_into_a_folder_that_does_not_exist_creates_it(qtbot, tmp_path, monkeypatch, dialog_log):
    window = MainWindow(install_editors=False)
    qtbot.addWidget(window)
    window.ctx.push(InsertKey(window.doc, "hero//x", Key(0.5, 3.0)))
    target = tmp_path / "new" / "deeper" / "myproj"  # no suffix typed: .qtanim is added
    monkeypatch.setattr(window, "ask_save_path", lambda start: (str(target), False))
    assert window.save_as()
    saved = target.with_suffix(".qtanim")
    assert saved.is_file() and not dialog_log
    assert not window.isWindowModified() and window.doc.path == str(saved.resolve())
    assert [p.name for p in saved.parent.iterdir()] == ["myproj.qtanim"]  # no temporary file left


def test_save_as_dialog_offers_to_collect_the_assets(qtbot, tmp_path):
    from PySide6.QtWidgets import QCheckBox, QFileDialog

    window = MainWindow(install_editors=False)
    qtbot.addWidget(window)
    seen: list[tuple[bool, str]] = []

    def fake_exec(dialog: QFileDialog) -> int:
        box = dialog.findChild(QCheckBox, "collectAssetsCheck")
        seen.append((box is not None and box.isVisibleTo(dialog), dialog.windowTitle()))
        box.setChecked(True)
        dialog.selectFile(str(tmp_path / "p.qtanim"))
        return 1

    import unittest.mock as mock

    with mock.patch.object(QFileDialog, "exec", fake_exec):
        path, collect = window.ask_save_path(str(tmp_path / "untitled.qtanim"))
    assert seen == [(True, "Save Project")]
    assert Path(path).name == "p.qtanim" and collect


def test_recent_files_menu(qtbot, tmp_path):
    window = MainWindow(install_editors=False)
    qtbot.addWidget(window)
    first = _project(tmp_path, "first.qtanim", 1.0)
    second = _project(tmp_path, "second.qtanim", 2.0)
    assert window.open_path(first) and window.open_path(second)
    assert window.recent_files()[:2] == [str(second.resolve()), str(first.resolve())]
    actions = window.recent_menu.actions()
    assert [a.text() for a in actions[:2]] == ["second.qtanim", "first.qtanim"]
    assert window.recent_menu.isEnabled()
    actions[1].trigger()  # reopen the first one from the menu
    assert window.doc.channels["hero//x"].evaluate(1.0) == 1.0
    assert window.recent_files()[0] == str(first.resolve())
    # Another window (another session) sees the same list.
    other = MainWindow(install_editors=False)
    qtbot.addWidget(other)
    assert other.recent_files()[:2] == [str(first.resolve()), str(second.resolve())]
    # A file deleted since leaves the menu when it fails to open.
    second.unlink()
    other.recent_menu.actions()[1].trigger()
    assert str(second.resolve()) not in other.recent_files()
    assert [a.text() for a in other.recent_menu.actions()][:1] == ["first.qtanim"]


def test_layout_is_kept_in_settings(qtbot):
    from PySide6.QtWidgets import QDockWidget

    window = MainWindow()
    qtbot.addWidget(window)
    window.show()
    dock = window.findChild(QDockWidget, "undoHistoryDock")
    assert dock.isHidden()
    dock.show()
    window.resize(1500, 950)
    qtbot.waitUntil(lambda: window.width() == 1500)
    window.close()
    again = MainWindow()
    qtbot.addWidget(again)
    again.show()
    assert not again.findChild(QDockWidget, "undoHistoryDock").isHidden()
    assert again.width() == 1500
    again.close()


def test_undo_history_view_follows_the_stack(qtbot):
    from PySide6.QtWidgets import QUndoView

    window = MainWindow(install_editors=False)
    qtbot.addWidget(window)
    view = window.findChild(QUndoView, "undoHistoryView")
    window.ctx.push(InsertKey(window.doc, "hero//x", Key(0.0, 1.0)))
    window.ctx.push(InsertKey(window.doc, "hero//x", Key(1.0, 2.0), text="Key hero x"))
    assert view.stack() is window.ctx.undo_stack
    assert window.ctx.undo_stack.text(1) == "Key hero x"
    assert window.action_undo.isEnabled() and not window.action_redo.isEnabled()
    window.action_undo.trigger()
    assert window.action_redo.isEnabled()
    assert len(window.doc.channels["hero//x"].keys) == 1


def test_a_noop_command_and_a_drag_back_leave_no_step(qtbot):
    from qtanimator.document import MoveKeys, SetParameter

    window = MainWindow(install_editors=False)
    qtbot.addWidget(window)
    window.ctx.push(SetParameter(window.doc, "fps", window.doc.fps))
    assert window.ctx.undo_stack.count() == 0 and not window.isWindowModified()
    window.ctx.push(InsertKey(window.doc, "hero//x", Key(0.0, 1.0)))
    base = dict(window.doc.channels)
    window.ctx.push(MoveKeys(base, {"hero//x": [0]}, 0.5, 0.0, gesture="drag"))
    window.ctx.push(MoveKeys(base, {"hero//x": [0]}, 0.0, 0.0, gesture="drag"))
    assert window.ctx.undo_stack.count() == 1
    assert window.doc.channels == base


def test_file_menu_and_closing_with_unsaved_changes(qtbot, monkeypatch):
    from PySide6.QtWidgets import QMessageBox

    window = MainWindow(install_editors=False)
    qtbot.addWidget(window)
    window.show()
    names = [a.objectName() for a in window.file_menu.actions()]
    for name in ("actionNew", "actionOpen", "actionSave", "actionSaveAs", "actionQuit"):
        assert name in names
    assert window.recent_menu.menuAction() in window.file_menu.actions()
    window.ctx.push(InsertKey(window.doc, "hero//x", Key(0.0, 1.0)))
    monkeypatch.setattr(QMessageBox, "question", staticmethod(lambda *a, **k: QMessageBox.StandardButton.Cancel))
    assert not window.close()  # cancelled: the window stays
    assert window.isVisible()
    monkeypatch.setattr(QMessageBox, "question", staticmethod(lambda *a, **k: QMessageBox.StandardButton.Discard))
    assert window.close()


def test_editor_context_signals(qtbot):
    from qtanimator.document import Document, SetParameter
    from qtanimator.ui.context import EditorContext

    ctx = EditorContext()
    frames: list[float] = []
    selections: list[tuple[str, str]] = []
    channel_sel: list[list[str]] = []
    changes: list[object] = []
    ctx.frameChanged.connect(frames.append)
    ctx.selectionChanged.connect(lambda a, j: selections.append((a, j)))
    ctx.channelSelectionChanged.connect(channel_sel.append)
    ctx.documentChanged.connect(changes.append)
    ctx.set_frame(30)
    ctx.set_frame(30)  # no change, no signal
    assert frames == [30.0] and ctx.time == 0.5
    ctx.select("hero", "arm")
    ctx.select("hero", "arm")
    assert selections == [("hero", "arm")] and ctx.selection == ("hero", "arm")
    ctx.select_channels(["hero//x"])
    assert channel_sel == [["hero//x"]] and ctx.channel_selection == ["hero//x"]
    ctx.push(SetParameter(ctx.doc, "fps", 30))
    assert ctx.time == 1.0 and len(changes) == 1 and ctx.undo_stack.count() == 1
    resets: list[bool] = []
    ctx.documentReset.connect(lambda: resets.append(True))
    new = Document()
    set_parameters(new, {"frame_start": 10})
    ctx.replace_document(new)
    assert resets == [True] and ctx.frame == 10.0 and ctx.selection == ("", "")
    assert ctx.undo_stack.count() == 0 and ctx.undo_stack.isClean()
    assert channel_sel[-1] == [] and ctx.channel_selection == []


# ---------------------------------------------------------------------- help menu
def test_help_menu_shows_the_installed_guides_and_opens_the_log_folder(qtbot, monkeypatch, tmp_path):
    from PySide6.QtGui import QAction, QDesktopServices
    from PySide6.QtWidgets import QTextBrowser

    from qtanimator import paths

    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
    window = MainWindow(install_editors=False)
    qtbot.addWidget(window)
    names = [a.objectName() for a in window.help_menu.actions()]
    for name in ("actionUserGuide", "actionKeyboardReference", "actionReportProblem", "actionAbout",
                 "actionAboutQt"):
        assert name in names
    assert not window.windowIcon().isNull()
    window.findChild(QAction, "actionUserGuide").trigger()
    browser = window.findChild(QTextBrowser, "helpBrowser")
    assert browser is not None and browser.isVisible()
    assert browser.source().toLocalFile() == str(paths.docs_dir() / "user-guide.md")
    assert "user guide" in browser.toPlainText().lower()
    window.findChild(QAction, "actionKeyboardReference").trigger()
    viewers = [b.source().toLocalFile() for b in window.findChildren(QTextBrowser, "helpBrowser")]
    assert str(paths.docs_dir() / "keyboard.md") in viewers
    # A link to another page opens it in the same viewer.
    from PySide6.QtCore import QUrl

    browser.anchorClicked.emit(QUrl("formats.md"))
    assert browser.source().toLocalFile() == str(paths.docs_dir() / "formats.md")
    opened: list[str] = []
    monkeypatch.setattr(QDesktopServices, "openUrl", staticmethod(lambda url: opened.append(url.toLocalFile())
                                                                  or True))
    window.findChild(QAction, "actionReportProblem").trigger()
    assert opened == [str(tmp_path / "state" / "qtanimator")]
    assert (tmp_path / "state" / "qtanimator").is_dir()


# ---------------------------------------------------------------------- projects that travel
FLAPPY = Path(__file__).resolve().parents[2] / "scenes" / "flappy.svg"


def _window_with_character(qtbot, svg: Path) -> MainWindow:
    from qtanimator.document.character2d import add_characters_command

    window = MainWindow(install_editors=False)
    qtbot.addWidget(window)
    window.ctx.push(add_characters_command(window.doc, svg))
    window.ctx.push(InsertKey(window.doc, "hero//x", Key(0.5, 3.0)))
    return window


def test_collect_assets_then_moving_the_project_folder_still_opens(qtbot, tmp_path, monkeypatch, dialog_log):
    from PySide6.QtGui import QAction

    from qtanimator.document import open_document

    elsewhere = tmp_path / "downloads"
    elsewhere.mkdir()
    svg = elsewhere / "flappy.svg"
    shutil.copy(FLAPPY, svg)
    window = _window_with_character(qtbot, svg)
    (asset_id,) = [a.id for a in window.doc.assets.values() if a.source]
    state = window.doc.state()
    project = tmp_path / "work" / "bird" / "bird.qtanim"
    monkeypatch.setattr(window, "ask_save_path", lambda start: (str(project), True))
    assert window.save_as()  # Save As with "collect assets" ticked, into a new folder
    collected = project.parent / "assets" / "flappy.svg"
    assert collected.read_bytes() == svg.read_bytes()
    assert window.doc.assets[asset_id].source == str(collected.resolve())
    assert window.ctx.undo_stack.text(window.ctx.undo_stack.count() - 1) == "Collect Assets"
    assert not window.isWindowModified() and not dialog_log
    # Move the whole project folder and delete the original SVG: the project still opens.
    moved = shutil.move(str(project.parent), str(tmp_path / "usb" / "bird"))
    svg.unlink()
    doc = open_document(Path(moved) / "bird.qtanim")
    assert doc.assets[asset_id].source == str((Path(moved) / "assets" / "flappy.svg").resolve())
    assert asset_id in doc.runtime
    assert doc.state()["channels"] == state["channels"]
    # The file stores a relative path, and nothing outside the folder.
    text = (Path(moved) / "bird.qtanim").read_text()
    assert '"source": "assets/flappy.svg"' in text and '"outside"' not in text
    # File > Collect Assets on a project that already travels copies nothing.
    window2 = MainWindow(install_editors=False)
    qtbot.addWidget(window2)
    assert window2.open_path(Path(moved) / "bird.qtanim")
    window2.findChild(QAction, "actionCollectAssets").trigger()
    assert dialog_log[-1][0] == "Collect Assets" and "already" in dialog_log[-1][1]
    assert window2.ctx.undo_stack.count() == 0


def test_collect_assets_is_one_undoable_step(qtbot, tmp_path, dialog_log):
    from PySide6.QtGui import QAction

    from qtanimator.document import save_document

    elsewhere = tmp_path / "art"
    elsewhere.mkdir()
    shutil.copy(FLAPPY, elsewhere / "flappy.svg")
    window = _window_with_character(qtbot, elsewhere / "flappy.svg")
    project = tmp_path / "proj" / "p.qtanim"
    project.parent.mkdir()
    assert window.save_to(project)
    assert '"outside": [' in project.read_text()  # recorded: the user chose a file elsewhere
    before = window.doc.state()
    steps = window.ctx.undo_stack.count()
    window.findChild(QAction, "actionCollectAssets").trigger()
    assert window.ctx.undo_stack.count() == steps + 1 and window.isWindowModified()
    sources = [a.source for a in window.doc.assets.values() if a.source]
    assert sources and all(Path(s).parent == (project.parent / "assets").resolve() for s in sources)
    window.action_undo.trigger()
    assert window.doc.state() == before
    window.action_redo.trigger()
    save_document(window.doc, project)
    assert '"outside"' not in project.read_text()


def test_a_missing_asset_is_found_beside_the_project(qtbot, tmp_path, monkeypatch, dialog_log):
    from PySide6.QtWidgets import QFileDialog

    from qtanimator.document import save_document

    svg = tmp_path / "old place" / "flappy.svg"
    svg.parent.mkdir()
    shutil.copy(FLAPPY, svg)
    window = _window_with_character(qtbot, svg)
    project = tmp_path / "proj" / "p.qtanim"
    project.parent.mkdir()
    save_document(window.doc, project)
    (project.parent / "art").mkdir()
    shutil.move(str(svg), str(project.parent / "art" / "flappy.svg"))  # the user tidied up
    monkeypatch.setattr(QFileDialog, "getOpenFileName", staticmethod(lambda *a, **k: pytest.fail("asked")))
    other = MainWindow(install_editors=False)
    qtbot.addWidget(other)
    assert other.open_path(project)
    (source,) = [a.source for a in other.doc.assets.values() if a.source]
    assert source == str((project.parent / "art" / "flappy.svg").resolve())
    assert dialog_log[-1][0] == "Assets found at new places" and "flappy.svg" in dialog_log[-1][1]
    assert other.isWindowModified()  # save to keep the new place
    assert other.save_to(project) and not other.isWindowModified()
    assert '"source": "art/flappy.svg"' in project.read_text()


def test_a_missing_asset_is_relinked_with_the_file_dialog(qtbot, tmp_path, monkeypatch, dialog_log):
    from PySide6.QtWidgets import QFileDialog

    from qtanimator.document import save_document

    svg = tmp_path / "old" / "flappy.svg"
    svg.parent.mkdir()
    shutil.copy(FLAPPY, svg)
    window = _window_with_character(qtbot, svg)
    project = tmp_path / "proj" / "p.qtanim"
    project.parent.mkdir()
    save_document(window.doc, project)
    state = window.doc.state()
    new_home = tmp_path / "elsewhere" / "renamed_bird.svg"
    new_home.parent.mkdir()
    shutil.move(str(svg), str(new_home))
    asked: list[str] = []

    def pick(_parent, title, *args, **kwargs):  # type: ignore[no-untyped-def]
        asked.append(title)
        return str(new_home), ""

    monkeypatch.setattr(QFileDialog, "getOpenFileName", staticmethod(pick))
    other = MainWindow(install_editors=False)
    qtbot.addWidget(other)
    assert other.open_path(project)
    assert len(asked) == 1 and "flappy.svg" in asked[0] and "missing" in asked[0]
    (asset,) = [a for a in other.doc.assets.values() if a.source]
    assert asset.source == str(new_home.resolve()) and asset.id in other.doc.runtime
    assert other.doc.state()["channels"] == state["channels"]
    assert "renamed_bird.svg" in dialog_log[-1][1] and other.isWindowModified()
    assert other.save_to(project)
    text = project.read_text()
    assert "../elsewhere/renamed_bird.svg" in text and '"outside": [' in text  # the user's choice, recorded
    # Cancelling the dialog: the open fails with the reader's sentence and changes nothing.
    new_home.unlink()
    monkeypatch.setattr(QFileDialog, "getOpenFileName", staticmethod(lambda *a, **k: ("", "")))
    third = MainWindow(install_editors=False)
    qtbot.addWidget(third)
    before = third.doc.state()
    assert not third.open_path(project)
    assert dialog_log[-1][0] == "Cannot open file" and "renamed_bird.svg" in dialog_log[-1][1]
    assert third.doc.state() == before
