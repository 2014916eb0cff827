"""File > Export Animation…: the View choice (2D view, 3D view with the viewport's camera, glTF file)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PySide6.QtCore import Qt, QTimer
from PySide6.QtGui import QAction
from PySide6.QtWidgets import QApplication, QComboBox, QDialogButtonBox, QLineEdit, QSpinBox

from qtanimator.ui.export_dialog import ExportDialog, ExportSettings, run_export, viewport_camera

ARM3D = Path(__file__).resolve().parents[2] / "scenes" / "arm3d" / "arm3d.qtanim"


def _accept_with(qtbot, fill) -> list[bool]:  # type: ignore[no-untyped-def]
    done: list[bool] = []

    def run() -> None:
        dialog = QApplication.activeModalWidget()
        assert dialog is not None and dialog.objectName() == "exportDialog"
        fill(dialog)
        box = dialog.findChild(QDialogButtonBox)
        qtbot.mouseClick(box.button(QDialogButtonBox.StandardButton.Ok), Qt.MouseButton.LeftButton)
        done.append(True)

    QTimer.singleShot(50, run)
    return done


def test_a_3d_scene_exports_the_3d_view_with_the_viewport_camera(make_window, qtbot, tmp_path):
    window = make_window(size=None, active=False, full=True)
    assert window.open_path(ARM3D)
    out = tmp_path / "frames"

    def fill(dialog) -> None:  # type: ignore[no-untyped-def]
        assert dialog.findChild(QComboBox, "exportView").currentData() == "3d"  # no 2D characters
        dialog.findChild(QLineEdit, "exportPath").setText(str(out))
        dialog.findChild(QSpinBox, "exportWidth").setValue(64)
        dialog.findChild(QSpinBox, "exportHeight").setValue(48)
        dialog.findChild(QSpinBox, "exportFirst").setValue(0)
        dialog.findChild(QSpinBox, "exportLast").setValue(1)

    done = _accept_with(qtbot, fill)
    window.findChild(QAction, "actionExport").trigger()
    assert done
    assert window.export_settings.view == "3d" and window.export_settings.camera is not None
    files = sorted(out.glob("*.png"))
    assert len(files) == 2
    from PIL import Image

    near = np.asarray(Image.open(files[0]).convert("RGB")).astype(int)
    assert near.shape == (48, 64, 3) and len(np.unique(near.reshape(-1, 3), axis=0)) > 1
    # the viewport's camera is the export's: moving it away changes the picture
    window.viewport3d.camera.distance *= 4
    far_dir = tmp_path / "far"
    settings = ExportSettings(out=str(far_dir), fmt="png", width=64, height=48, first=0, last=0, view="3d",
                              camera=viewport_camera(window))
    assert run_export(window, settings) == 1
    far = np.asarray(Image.open(sorted(far_dir.glob("*.png"))[0]).convert("RGB")).astype(int)
    assert np.abs(far - near).sum() > 1000


def test_the_gltf_choice_writes_the_character(make_window, qtbot, tmp_path):
    window = make_window(size=None, active=False, full=True)
    assert window.open_path(ARM3D)
    out = tmp_path / "arm"

    def fill(dialog) -> None:  # type: ignore[no-untyped-def]
        views = dialog.findChild(QComboBox, "exportView")
        views.setCurrentIndex(views.findData("gltf"))
        assert not dialog.findChild(QSpinBox, "exportWidth").isEnabled()
        assert not dialog.findChild(QComboBox, "exportFormat").isEnabled()
        path = dialog.findChild(QLineEdit, "exportPath")
        assert path.text().endswith(".glb")
        path.setText(str(out))

    done = _accept_with(qtbot, fill)
    window.findChild(QAction, "actionExport").trigger()
    assert done
    assert (tmp_path / "arm.glb").read_bytes()[:4] == b"glTF"


def test_switching_views_changes_the_suffix(qtbot, tmp_path):
    from qtanimator.document import Document

    dialog = ExportDialog(Document(), None, ExportSettings(out=str(tmp_path / "clip.gif"), fmt="gif"))
    qtbot.addWidget(dialog)
    views = dialog.findChild(QComboBox, "exportView")
    assert views.currentData() == "2d"
    views.setCurrentIndex(views.findData("gltf"))
    assert dialog.path_edit.text() == str(tmp_path / "clip.glb")
    assert dialog.gif_note.isHidden()
    views.setCurrentIndex(views.findData("3d"))
    assert dialog.path_edit.text() == str(tmp_path / "clip.gif")
    assert dialog.settings().view == "3d" and dialog.format_box.isEnabled()
