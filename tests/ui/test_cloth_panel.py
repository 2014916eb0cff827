"""The cloth dock: one editor per ClothParams field, live edits through commands."""

from __future__ import annotations

from dataclasses import fields

import pytest
from PySide6.QtWidgets import QCheckBox, QComboBox, QDockWidget, QDoubleSpinBox, QLabel, QPushButton, QSpinBox

from qtanimator.core.cloth import ClothParams
from qtanimator.document.cloth import cloth_params
from qtanimator.ui import cloth_panel
from qtanimator.ui.main_window import MainWindow


def _window(qtbot):
    w = MainWindow(install_editors=False)
    cloth_panel.install(w)
    qtbot.addWidget(w)
    return w


def test_every_parameter_has_an_editor_and_add_creates_a_cloth(qtbot):
    w = _window(qtbot)
    assert w.findChild(QDockWidget, "clothDock") is not None
    assert set(w.cloth_panel.editors) == {f.name for f in fields(ClothParams)}
    assert not w.findChild(QSpinBox, "cloth_rows").isEnabled()     # no cloth yet
    w.findChild(QPushButton, "clothAdd").click()
    assert [a.kind for a in w.doc.assets.values()] == ["cloth"]
    assert w.findChild(QSpinBox, "cloth_rows").isEnabled()
    assert w.findChild(QComboBox, "clothAsset").currentText() == "cloth"


def test_edits_change_the_cloth_and_undo(qtbot):
    w = _window(qtbot)
    w.cloth_panel.add_cloth()
    doc = w.doc
    stiff = w.findChild(QDoubleSpinBox, "cloth_structural_stiffness")
    for v in (300.0, 350.0, 400.0):
        stiff.setValue(v)
    assert cloth_params(doc, "cloth").structural_stiffness == 400.0
    other = "symplectic" if ClothParams().integrator == "implicit" else "implicit"  # not the default
    w.findChild(QComboBox, "cloth_integrator").setCurrentText(other)
    assert cloth_params(doc, "cloth").integrator == other
    w.findChild(QDoubleSpinBox, "cloth_wind_x").setValue(2.0)
    assert cloth_params(doc, "cloth").wind == (2.0, 0.0, 0.0)
    w.findChild(QDoubleSpinBox, "cloth_wind_speed").setValue(5.0)
    assert cloth_params(doc, "cloth").wind == (5.0, 0.0, 0.0)
    w.findChild(QCheckBox, "cloth_sphere_on").setChecked(True)
    assert len(cloth_params(doc, "cloth").spheres) == 1
    w.findChild(QSpinBox, "cloth_rows").setValue(12)
    assert cloth_params(doc, "cloth").rows == 12
    count = w.ctx.undo_stack.count()
    w.ctx.undo_stack.undo()
    assert cloth_params(doc, "cloth").rows == 20 and w.findChild(QSpinBox, "cloth_rows").value() == 20
    # the stiffness drag was one undo step
    while w.ctx.undo_stack.index() > 1:
        w.ctx.undo_stack.undo()
    assert cloth_params(doc, "cloth").structural_stiffness == 200.0
    assert count - 1 == 5


def test_an_invalid_value_is_refused_with_a_message(qtbot):
    w = _window(qtbot)
    w.cloth_panel.add_cloth()
    assert not w.cloth_panel.edit("custom_pins", [100000])   # no such particle
    assert w.cloth_panel.message.text()


@pytest.mark.gl
def test_interactive_pause_and_reset_drive_the_viewport_cloth(qtbot):
    from qtanimator.ui import viewport

    w = MainWindow(install_editors=False)
    viewport.install(w)
    cloth_panel.install(w)
    qtbot.addWidget(w)
    w.cloth_panel.add_cloth()
    view = w.viewport3d
    live = w.findChild(QCheckBox, "clothLive")
    live.setChecked(True)
    assert view.live.enabled and "cloth" in view.live.cloths
    cloth = view.live.cloths["cloth"]
    w.findChild(QPushButton, "clothPause").setChecked(True)
    assert view.live.paused
    assert view.live.settle()   # no step in flight any more: edits apply at once
    view.live.step(1 / 60)
    assert cloth.time > 0
    w.findChild(QPushButton, "clothReset").click()
    assert cloth.time == 0
    # a parameter edit reaches the live cloth
    w.findChild(QDoubleSpinBox, "cloth_gravity").setValue(3.0)
    view.live.sync(w.doc)
    assert view.live.cloths["cloth"].params.gravity == 3.0
    view.set_live_cloth(False)
    assert not live.isChecked()


def _type_value(qtbot, spin, text: str) -> None:
    """Type a value into a spin box as a user does: select, type, Enter."""
    from PySide6.QtCore import Qt

    spin.setFocus()
    spin.selectAll()
    qtbot.keyClicks(spin, text)
    qtbot.keyClick(spin, Qt.Key.Key_Return)


def test_typed_wind_speed_is_one_exact_undo_step_per_edit(qtbot):
    """Typing a wind speed for a wind that is not along an axis: each typed value is one
    undo step, and undo gives back exactly the wind before (the panel refreshing its
    rounded fields must not push commands of its own)."""
    from qtanimator.document.cloth import set_cloth_param_command

    w = _window(qtbot)
    w.show()
    qtbot.waitExposed(w)
    w.cloth_panel.add_cloth()
    doc = w.doc
    w.ctx.push(set_cloth_param_command(doc, "cloth", "wind", [6.0, 0.0, 1.5]))
    stack = w.ctx.undo_stack
    start = stack.count()
    speed = w.findChild(QDoubleSpinBox, "cloth_wind_speed")
    _type_value(qtbot, speed, "12")
    assert stack.count() == start + 1
    wind = cloth_params(doc, "cloth").wind
    assert sum(c * c for c in wind) ** 0.5 == pytest.approx(12.0, abs=1e-4)
    assert wind[2] / wind[0] == pytest.approx(0.25, abs=1e-4)    # same direction
    _type_value(qtbot, speed, "3")
    assert stack.count() == start + 2                            # a second edit, a second step
    stack.undo()
    assert sum(c * c for c in cloth_params(doc, "cloth").wind) ** 0.5 == pytest.approx(12.0, abs=1e-4)
    stack.undo()
    assert cloth_params(doc, "cloth").wind == (6.0, 0.0, 1.5)
    assert speed.value() == pytest.approx(6.18, abs=0.01)
    assert [s.value() for s in w.cloth_panel.editors["wind"]] == [6.0, 0.0, 1.5]


@pytest.mark.gl
def test_long_cloth_work_shows_progress_and_can_be_cancelled(qtbot, monkeypatch):
    """A stiff implicit cloth takes long to simulate: the edit returns at once, the dock
    shows how far the background worker is, Cancel stops it and Resume goes on."""
    from qtanimator.document.cloth import cloth_cache
    from qtanimator.document.cloth_worker import cloth_worker
    from qtanimator.ui import viewport

    monkeypatch.setattr(cloth_panel.ClothPanel, "PROGRESS_AFTER_S", 0.0)
    w = MainWindow(install_editors=False)
    viewport.install(w)
    cloth_panel.install(w)
    qtbot.addWidget(w)
    w.show()
    w.cloth_panel.add_cloth()
    worker = cloth_worker(w.doc)
    assert worker.wait(60)
    w.findChild(QDoubleSpinBox, "cloth_structural_stiffness").setValue(1.0e6)
    w.findChild(QComboBox, "cloth_integrator").setCurrentText("implicit")
    assert cloth_cache(w.doc, "cloth").cached_frames < 241      # the edit did not simulate
    label = w.findChild(QLabel, "clothProgress")
    button = w.findChild(QPushButton, "clothCancel")
    qtbot.waitUntil(lambda: label.isVisible() and "Simulating cloth" in label.text(), timeout=10000)
    assert button.isVisible() and button.text() == "Cancel"
    button.click()
    assert worker.wait(10)
    assert "stopped" in label.text() and button.text() == "Resume"
    button.click()
    qtbot.waitUntil(lambda: "Simulating cloth" in label.text(), timeout=10000)
    # Back to the explicit integrator: a new simulation, short; the progress goes away.
    w.findChild(QComboBox, "cloth_integrator").setCurrentText("symplectic")
    w.findChild(QDoubleSpinBox, "cloth_structural_stiffness").setValue(200.0)
    assert worker.wait(60)
    qtbot.waitUntil(lambda: not label.isVisible() and not button.isVisible(), timeout=5000)
    w.ctx.undo_stack.setClean()


@pytest.mark.parametrize("note", [None, "Cloth runs on the numpy fallback: slower."])
def test_the_dock_says_when_the_cloth_runs_without_the_compiled_solver(qtbot, monkeypatch, note):
    from qtanimator.core import cloth_kernels

    monkeypatch.setattr(cloth_kernels, "SLOW_PATH_NOTE", note)
    w = _window(qtbot)
    w.show()
    label = w.findChild(QLabel, "clothSpeedNote")
    assert label is not None
    assert label.isVisibleTo(w) == (note is not None)
    assert label.text() == (note or "")


def test_a_blow_up_is_explained_in_the_dock_and_the_status_bar(qtbot):
    """Issue 14: wind 1000 on the demo flag stops it; the dock and the status bar say why and
    name the parameter to change."""
    from pathlib import Path

    from qtanimator.ui import viewport

    w = MainWindow(install_editors=False)
    viewport.install(w)
    cloth_panel.install(w)
    qtbot.addWidget(w)
    w.show()
    demo = Path(__file__).resolve().parents[2] / "scenes" / "demo" / "demo.qtanim"
    assert w.open_path(demo)
    panel = w.cloth_panel
    panel.asset.setCurrentText("flag")
    assert panel.edit("wind", (1000.0, 0.0, 0.0))
    worker = w.viewport3d.cloth_worker
    assert worker.wait(60)
    qtbot.waitUntil(lambda: panel.problem.isVisibleTo(panel), timeout=5000)
    text = panel.findChild(QLabel, "clothProblem").text()
    assert "flag" in text and "blew up" in text and "'substeps'" in text
    assert "blew up" in w.statusBar().currentMessage()


def test_the_fields_fit_the_dock_without_sideways_scrolling(qtbot):
    """With the units in the labels, the rows of several fields (origin, wind and its speed,
    the sphere) still fit a 440-pixel-wide dock (the right dock area of a 1400-pixel window):
    the form's narrowest layout plus the vertical scroll bar is at most that wide, so no
    horizontal scroll bar appears. (Before the row fields could shrink, these rows needed
    about 600 pixels.)"""
    from PySide6.QtWidgets import QScrollArea

    w = _window(qtbot)
    w.findChild(QPushButton, "clothAdd").click()
    scroll = w.cloth_panel.findChild(QScrollArea)
    needed = (scroll.widget().minimumSizeHint().width() + scroll.verticalScrollBar().sizeHint().width()
              + 2 * scroll.frameWidth())
    assert needed <= 440
