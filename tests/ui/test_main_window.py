from __future__ import annotations

from qtanimator.core.channel import Key
from qtanimator.document import InsertKey
from qtanimator.ui.main_window import MainWindow


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
