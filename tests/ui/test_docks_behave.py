"""Docks behave (issue 13, item 5): the wheel over an unfocused field changes nothing, Ctrl+Z
undoes the document from a focused field, out-of-range values are refused with a reason
or accepted (never clamped in silence), and the current frame is saved with the project.

Real key and mouse events on the real main window's docks; the wheel is a real QWheelEvent
delivered by the application (QTest has no wheel).
"""

from __future__ import annotations

import json

import pytest
from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtGui import QWheelEvent
from PySide6.QtWidgets import (
    QAbstractSpinBox,
    QApplication,
    QDockWidget,
    QDoubleSpinBox,
    QLineEdit,
    QScrollArea,
    QSpinBox,
    QWidget,
)

from qtanimator.core.cloth import ClothParams
from qtanimator.document.cloth import cloth_params
from qtanimator.ui.cloth_panel import FLOAT_RANGES, INT_RANGES
from qtanimator.ui.main_window import FRAME_VIEW_STATE


@pytest.fixture
def window(make_window):
    w = make_window(editors=("timeline", "properties", "cloth_panel", "light_panel"), size=(1200, 700))
    w.cloth_panel.add_cloth()
    w.ctx.undo_stack.clear()
    dock = w.findChild(QDockWidget, "clothDock")
    dock.raise_()
    QApplication.processEvents()
    return w


def wheel(widget: QWidget, steps: int = -1) -> None:
    """Turn the wheel ``steps`` notches (negative: towards the user) over ``widget``."""
    pos = QPointF(widget.rect().center())
    ev = QWheelEvent(pos, QPointF(widget.mapToGlobal(pos.toPoint())), QPoint(0, 0), QPoint(0, 120 * steps),
                     Qt.MouseButton.NoButton, Qt.KeyboardModifier.NoModifier, Qt.ScrollPhase.NoScrollPhase, False)
    QApplication.sendEvent(widget, ev)


def field(w, name: str, kind=QDoubleSpinBox):
    box = w.findChild(kind, name)
    assert box is not None, name
    return box


def type_into(qtbot, box: QAbstractSpinBox, text: str, enter: bool = True) -> None:
    qtbot.mouseClick(box, Qt.MouseButton.LeftButton)   # the field takes the focus
    qtbot.keyClick(box, Qt.Key.Key_A, Qt.KeyboardModifier.ControlModifier)
    qtbot.keyClicks(box, text)
    if enter:
        qtbot.keyClick(box, Qt.Key.Key_Return)


def _scroll_area(widget: QWidget) -> QScrollArea:
    w = widget.parentWidget()
    while not isinstance(w, QScrollArea):
        w = w.parentWidget()
    return w


# ------------------------------------------------------------------------- wheel
def test_the_wheel_over_an_unfocused_spin_box_scrolls_the_dock_and_changes_nothing(qtbot, window):
    w = window
    margin = field(w, "cloth_collision_margin")
    assert margin.value() == pytest.approx(0.005)
    area = _scroll_area(margin)
    bar = area.verticalScrollBar()
    assert bar.maximum() > 0              # the dock's form is taller than the dock
    area.ensureWidgetVisible(margin)
    bar.setValue(bar.maximum() // 2)
    QApplication.processEvents()
    top = bar.value()
    assert not margin.hasFocus()
    wheel(margin, -1)
    assert margin.value() == pytest.approx(0.005)
    assert cloth_params(w.doc, "cloth").collision_margin == pytest.approx(0.005)
    assert w.ctx.undo_stack.count() == 0
    assert bar.value() > top               # the wheel scrolled the dock instead
    stiffness = field(w, "cloth_structural_stiffness")
    wheel(stiffness, +1)
    assert stiffness.value() == 200.0 and w.ctx.undo_stack.count() == 0
    # A combo box and an int field too.
    rows = field(w, "cloth_rows", QSpinBox)
    wheel(rows, +1)
    assert rows.value() == 20 and w.ctx.undo_stack.count() == 0


def test_a_focused_spin_box_takes_the_wheel(qtbot, window):
    w = window
    margin = field(w, "cloth_collision_margin")
    _scroll_area(margin).ensureWidgetVisible(margin)
    qtbot.mouseClick(margin, Qt.MouseButton.LeftButton)
    assert margin.hasFocus()
    wheel(margin, -1)
    assert margin.value() == pytest.approx(0.004)   # one step of 0.001 down
    assert cloth_params(w.doc, "cloth").collision_margin == pytest.approx(0.004)
    assert w.ctx.undo_stack.count() == 1


# ------------------------------------------------------------------------ undo
def test_ctrl_z_with_a_focused_field_undoes_the_document(qtbot, window):
    w = window
    doc = w.doc
    stiffness = field(w, "cloth_structural_stiffness")
    _scroll_area(stiffness).ensureWidgetVisible(stiffness)
    type_into(qtbot, stiffness, "5000")
    assert cloth_params(doc, "cloth").structural_stiffness == 5000.0
    assert w.ctx.undo_stack.count() == 1
    assert stiffness.hasFocus()
    qtbot.keyClick(stiffness, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert cloth_params(doc, "cloth").structural_stiffness == 200.0
    assert w.ctx.undo_stack.index() == 0
    assert stiffness.value() == 200.0 and stiffness.hasFocus()
    qtbot.keyClick(stiffness, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.ShiftModifier)
    assert cloth_params(doc, "cloth").structural_stiffness == 5000.0
    qtbot.keyClick(stiffness, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    qtbot.keyClick(stiffness, Qt.Key.Key_Y, Qt.KeyboardModifier.ControlModifier)
    assert cloth_params(doc, "cloth").structural_stiffness == 5000.0


def test_ctrl_z_while_typing_undoes_the_typing_only(qtbot, window):
    w = window
    doc = w.doc
    stiffness = field(w, "cloth_structural_stiffness")
    _scroll_area(stiffness).ensureWidgetVisible(stiffness)
    type_into(qtbot, stiffness, "5000")
    type_into(qtbot, stiffness, "7", enter=False)          # typed, not entered
    assert stiffness.text() == "7"
    qtbot.keyClick(stiffness, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert stiffness.text() != "7"                         # the field's own undo
    assert cloth_params(doc, "cloth").structural_stiffness == 5000.0
    assert w.ctx.undo_stack.index() == 1


def test_ctrl_z_in_a_line_edit_undoes_the_document_once_its_text_is_entered(qtbot, window):
    w = window
    doc = w.doc
    pins = field(w, "cloth_custom_pins", QLineEdit)
    w.findChild(QWidget, "cloth_pin_mode").setCurrentText("custom")
    _scroll_area(pins).ensureWidgetVisible(pins)
    qtbot.mouseClick(pins, Qt.MouseButton.LeftButton)
    steps = w.ctx.undo_stack.index()
    qtbot.keyClicks(pins, "0 19")
    qtbot.keyClick(pins, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)   # editing: the text's undo
    assert pins.text() == ""
    assert cloth_params(doc, "cloth").pin_mode == "custom" and w.ctx.undo_stack.index() == steps
    qtbot.keyClicks(pins, "0 19")
    qtbot.keyClick(pins, Qt.Key.Key_Return)
    assert list(cloth_params(doc, "cloth").custom_pins) == [0, 19]
    qtbot.keyClick(pins, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)   # entered: the document's
    assert list(cloth_params(doc, "cloth").custom_pins) == []
    assert cloth_params(doc, "cloth").pin_mode == "custom"


# ------------------------------------------------------------------ out of range
def test_a_typed_value_beyond_the_field_is_refused_with_a_reason_or_accepted(qtbot, window):
    w = window
    doc = w.doc
    stiffness = field(w, "cloth_structural_stiffness")
    _scroll_area(stiffness).ensureWidgetVisible(stiffness)
    type_into(qtbot, stiffness, "10000000")                 # 1e7: physically fine, accepted
    assert cloth_params(doc, "cloth").structural_stiffness == 1e7
    assert stiffness.value() == 1e7 and not stiffness.refusing
    type_into(qtbot, stiffness, "-5")                       # refused, and the field says why
    assert cloth_params(doc, "cloth").structural_stiffness == 1e7
    assert stiffness.value() == 1e7
    assert stiffness.refusing and "below the smallest value, 0" in stiffness.toolTip()
    assert "below" in w.statusBar().currentMessage()
    assert "below" in w.cloth_panel.message.text()
    assert w.ctx.undo_stack.count() == 1
    type_into(qtbot, stiffness, "300")                      # a good value ends the refusal
    assert not stiffness.refusing and cloth_params(doc, "cloth").structural_stiffness == 300.0
    restitution = field(w, "cloth_ground_restitution")
    _scroll_area(restitution).ensureWidgetVisible(restitution)
    type_into(qtbot, restitution, "1.5")
    assert cloth_params(doc, "cloth").ground_restitution == pytest.approx(0.1)
    assert "gain energy" in restitution.toolTip()


def test_light_intensity_above_one_is_accepted_and_a_negative_one_refused(qtbot, window):
    w = window
    w.findChild(QDockWidget, "lightDock").raise_()
    QApplication.processEvents()
    inten = field(w, "light1_intensity")
    type_into(qtbot, inten, "1.5")
    assert w.doc.parameters["light1.intensity"] == 1.5
    type_into(qtbot, inten, "-1")
    assert w.doc.parameters["light1.intensity"] == 1.5
    assert inten.refusing and "below" in inten.toolTip()


def test_an_ik_setting_beyond_its_field_is_refused(qtbot, window):
    w = window
    w.findChild(QDockWidget, "propertiesDock").raise_()
    QApplication.processEvents()
    iterations = field(w, "param_ik_max_iterations", QSpinBox)
    type_into(qtbot, iterations, "5000000")
    assert "ik.max_iterations" not in w.doc.parameters
    assert iterations.refusing and "above the largest value" in iterations.toolTip()


def test_the_cloth_fields_take_every_value_the_cloth_accepts():
    """The fields' minimums are the cloth's own (ClothParams.validate): the least value is
    accepted and, where the cloth has a lower bound, anything below it is refused there too."""
    bounded_below = {"width", "height", "total_mass", "structural_stiffness", "structural_damping",
                     "shear_stiffness", "shear_damping", "bend_stiffness", "bend_damping", "drag_coefficient",
                     "air_density", "turbulence", "ground_restitution", "ground_friction", "collision_margin",
                     "rows", "cols", "substeps"}
    for name, (lo, hi, _step, decimals) in FLOAT_RANGES.items():
        ClothParams().replace(**{name: lo})
        ClothParams().replace(**{name: hi})
        if name in bounded_below:
            below = lo - 10.0 ** -decimals   # the next value the field could show below its least
            with pytest.raises(ValueError):
                ClothParams().replace(**{name: below})
    for name, (lo, hi) in INT_RANGES.items():
        ClothParams().replace(**{name: lo})
        ClothParams().replace(**{name: hi})
        if name in bounded_below:
            with pytest.raises(ValueError):
                ClothParams().replace(**{name: lo - 1})


# ------------------------------------------------------------------- view state
def test_the_current_frame_is_saved_with_the_project_without_an_undo_step(qtbot, make_window, tmp_path):
    w = make_window(editors=("timeline",))
    w.ctx.set_frame(37.0)
    path = tmp_path / "shot.qtanim"
    assert w.save_to(path)
    assert w.ctx.undo_stack.count() == 0 and not w.is_modified()
    assert json.loads(path.read_text())["view"][FRAME_VIEW_STATE] == 37.0
    w.new_document()
    assert w.ctx.frame == 0.0
    assert w.open_path(path)
    assert w.ctx.frame == 37.0
    assert w.ctx.undo_stack.count() == 0 and not w.is_modified()
