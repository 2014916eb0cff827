"""The light dock: fields edit the light parameters through undoable commands."""

from __future__ import annotations

from PySide6.QtGui import QColor
from PySide6.QtWidgets import QDockWidget, QDoubleSpinBox

from qtanimator.ui import light_panel
from qtanimator.ui.main_window import MainWindow


def _window(qtbot):
    w = MainWindow(install_editors=False)
    light_panel.install(w)
    qtbot.addWidget(w)
    return w


def test_dock_and_fields_show_the_defaults(qtbot):
    w = _window(qtbot)
    assert w.findChild(QDockWidget, "lightDock") is not None
    inten = w.findChild(QDoubleSpinBox, "light2_intensity")
    assert inten.value() == 0.5
    assert w.findChild(QDoubleSpinBox, "light1_position_y").value() == 6.0


def test_editing_position_intensity_and_colour_pushes_undoable_commands(qtbot):
    w = _window(qtbot)
    doc = w.doc
    w.findChild(QDoubleSpinBox, "light1_position_x").setValue(-3.0)
    assert doc.parameters["light1.position"] == [-3.0, 6.0, 5.0]
    inten = w.findChild(QDoubleSpinBox, "light2_intensity")
    for v in (0.6, 0.7, 0.8):          # one drag of the spin box: one undo step
        inten.setValue(v)
    assert doc.parameters["light2.intensity"] == 0.8
    w.light_panel.set_color("light1.color", QColor(255, 0, 0))
    assert doc.parameters["light1.color"] == [1.0, 0.0, 0.0]
    assert w.ctx.undo_stack.count() == 3
    w.ctx.undo_stack.undo()
    assert "light1.color" not in doc.parameters or doc.parameters["light1.color"] is None
    w.ctx.undo_stack.undo()
    assert inten.value() == 0.5           # the field follows undo
    w.ctx.undo_stack.redo()
    assert inten.value() == 0.8
