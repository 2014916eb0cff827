"""The collision radius of a 3D character's bone in the Properties dock (issue 14 item 5):
it shows the skin's default, a typed radius is one undo step that the cloth collides with and
that is saved with the project, and Reset goes back to the default."""

from __future__ import annotations

import pytest
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QDoubleSpinBox, QLabel, QToolButton

from qtanimator.core.cloth import ClothParams
from qtanimator.document.character3d import character
from qtanimator.document.cloth import add_cloth_command, cloth_cache
from qtanimator.document.cloth_attach import ATTACH, CAPSULE_RADII, capsule_radii, default_capsule_radii
from qtanimator.document.commands import SetAssetProperty
from qtanimator.ui.main_window import MainWindow


@pytest.fixture(autouse=True)
def private_settings(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("QTANIMATOR_SETTINGS_DIR", str(tmp_path_factory.mktemp("settings")))


def _window(qtbot) -> MainWindow:
    w = MainWindow()
    qtbot.addWidget(w)
    w.resize(1200, 800)
    w.show()
    qtbot.waitExposed(w)
    return w


def _type(qtbot, box: QDoubleSpinBox, text: str) -> None:
    box.setFocus()
    qtbot.keyClick(box, Qt.Key.Key_A, Qt.KeyboardModifier.ControlModifier)
    qtbot.keyClicks(box, text)
    qtbot.keyClick(box, Qt.Key.Key_Return)
    qtbot.wait(20)  # the command is pushed after the field's signal returns


def _field(window: MainWindow) -> tuple[QDoubleSpinBox, QLabel, QToolButton]:
    box = window.findChild(QDoubleSpinBox, "capsuleRadius")
    hint = window.findChild(QLabel, "capsuleRadiusHint")
    reset = window.findChild(QToolButton, "capsuleRadiusReset")
    assert box is not None and hint is not None and reset is not None
    return box, hint, reset


@pytest.fixture
def wasp(qtbot, shared_data, dialog_log):
    window = _window(qtbot)
    assert window.open_path(shared_data / "cse169" / "wasp_walk" / "wasp.skel"), dialog_log
    assert window.ctx.selection[0] == "wasp"
    # a cloth attached to the wasp's head collides with its bones' capsules
    window.ctx.push(add_cloth_command(window.doc, ClothParams(), asset_id="cape"))
    window.ctx.push(SetAssetProperty(window.doc, "cape", ATTACH, {"asset": "wasp", "joint": "head"}))
    window.ctx.undo_stack.clear()
    window.ctx.select("wasp", "knee_01_r")
    qtbot.wait(10)
    return window


def _driver_radius(window: MainWindow, joint: str) -> float:
    driver = cloth_cache(window.doc, "cape").driver
    assert driver is not None
    return float(driver.radii[driver.bone_names.index(joint)])


def test_the_field_shows_the_default_and_typing_is_one_undo_step(wasp, qtbot):
    window = wasp
    default = default_capsule_radii(character(window.doc, "wasp"))["knee_01_r"]
    box, hint, reset = _field(window)
    assert box.isVisible()
    assert box.value() == pytest.approx(default, abs=1e-4)
    assert hint.text() == "default" and not reset.isEnabled()
    count = window.ctx.undo_stack.count()
    _type(qtbot, box, "0.25")
    assert window.ctx.undo_stack.count() == count + 1
    assert window.doc.assets["wasp"].properties[CAPSULE_RADII] == {"knee_01_r": 0.25}
    assert capsule_radii(window.doc, "wasp")["knee_01_r"] == 0.25
    assert _driver_radius(window, "knee_01_r") == 0.25  # the cloth collides with it
    box, hint, reset = _field(window)  # the panel was rebuilt
    assert box.value() == 0.25 and hint.text() == "" and reset.isEnabled()
    window.action_undo.trigger()
    assert CAPSULE_RADII not in window.doc.assets["wasp"].properties
    box, hint, reset = _field(window)
    assert box.value() == pytest.approx(default, abs=1e-4) and hint.text() == "default"
    window.action_redo.trigger()
    assert capsule_radii(window.doc, "wasp")["knee_01_r"] == 0.25


def test_reset_goes_back_to_the_default(wasp, qtbot):
    window = wasp
    default = capsule_radii(window.doc, "wasp")["knee_01_r"]
    _type(qtbot, _field(window)[0], "0.3")
    assert capsule_radii(window.doc, "wasp")["knee_01_r"] == 0.3
    count = window.ctx.undo_stack.count()
    reset = _field(window)[2]
    qtbot.mouseClick(reset, Qt.MouseButton.LeftButton)
    qtbot.wait(20)
    assert window.ctx.undo_stack.count() == count + 1
    assert CAPSULE_RADII not in window.doc.assets["wasp"].properties
    assert capsule_radii(window.doc, "wasp")["knee_01_r"] == default
    assert _driver_radius(window, "knee_01_r") == pytest.approx(default)
    box, hint, reset = _field(window)
    assert box.value() == pytest.approx(default, abs=1e-4) and hint.text() == "default" and not reset.isEnabled()
    window.action_undo.trigger()
    assert capsule_radii(window.doc, "wasp")["knee_01_r"] == 0.3


def test_the_radius_is_saved_with_the_project(wasp, qtbot, tmp_path, dialog_log):
    window = wasp
    _type(qtbot, _field(window)[0], "0.125")
    target = tmp_path / "wasp.qtanim"
    assert window.save_to(target), dialog_log
    again = _window(qtbot)
    assert again.open_path(target), dialog_log
    assert again.doc.assets["wasp"].properties[CAPSULE_RADII] == {"knee_01_r": 0.125}
    assert capsule_radii(again.doc, "wasp")["knee_01_r"] == 0.125
    assert _driver_radius(again, "knee_01_r") == 0.125
    again.central_tabs.setCurrentWidget(again.viewport_panel)  # the 3D tab, as after an import
    again.ctx.select("wasp", "knee_01_r")
    qtbot.wait(10)
    box, hint, reset = _field(again)
    assert box.value() == 0.125 and reset.isEnabled()


def test_the_root_has_no_bone_and_no_field(wasp, qtbot):
    window = wasp
    window.ctx.select("wasp", "root")
    qtbot.wait(10)
    assert window.findChild(QDoubleSpinBox, "capsuleRadius") is None
