from __future__ import annotations

import pytest

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


def test_saving_to_an_impossible_place_shows_an_error(qtbot, tmp_path, dialog_log):
    window = MainWindow(install_editors=False)
    qtbot.addWidget(window)
    window.ctx.push(InsertKey(window.doc, "hero//x", Key(0.5, 3.0)))
    assert not window.save_to(tmp_path / "no" / "such" / "folder" / "x.qtanim")
    assert dialog_log[-1][0] == "Cannot save"
    assert window.isWindowModified()


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
    new.parameters["frame_start"] = 10
    ctx.replace_document(new)
    assert resets == [True] and ctx.frame == 10.0 and ctx.selection == ("", "")
    assert ctx.undo_stack.count() == 0 and ctx.undo_stack.isClean()
    assert channel_sel[-1] == [] and ctx.channel_selection == []
