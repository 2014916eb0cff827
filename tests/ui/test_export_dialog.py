"""File > Export Animation…: the dialog, the progress dialog and its Cancel."""

from __future__ import annotations

from PySide6.QtCore import QTimer
from PySide6.QtGui import QAction
from PySide6.QtWidgets import (
    QApplication,
    QComboBox,
    QDialogButtonBox,
    QLineEdit,
    QProgressDialog,
    QPushButton,
    QSpinBox,
)

from qtanimator.ui.export_dialog import ExportSettings, run_export


def test_export_dialog_writes_a_png_sequence(make_window, qtbot, shared_data, tmp_path):
    window = make_window(size=None, active=False)
    assert window.open_path(shared_data / "cmu-animator" / "scenes" / "arm.svg")
    out = tmp_path / "frames"
    done: list[bool] = []

    def fill_in() -> None:
        dialog = QApplication.activeModalWidget()
        assert dialog is not None and dialog.objectName() == "exportDialog"
        dialog.findChild(QComboBox, "exportFormat").setCurrentIndex(0)
        dialog.findChild(QLineEdit, "exportPath").setText(str(out))
        dialog.findChild(QSpinBox, "exportWidth").setValue(64)
        dialog.findChild(QSpinBox, "exportHeight").setValue(48)
        dialog.findChild(QSpinBox, "exportFirst").setValue(0)
        dialog.findChild(QSpinBox, "exportLast").setValue(4)
        box = dialog.findChild(QDialogButtonBox)
        qtbot.mouseClick(box.button(QDialogButtonBox.StandardButton.Ok), _left())
        done.append(True)

    QTimer.singleShot(50, fill_in)
    window.findChild(QAction, "actionExport").trigger()
    assert done
    files = sorted(out.glob("*.png"))
    assert len(files) == 5
    from PIL import Image

    img = Image.open(files[0])
    assert img.size == (64, 48)
    # The arm is drawn: not every pixel is the background.
    import numpy as np

    pixels = np.asarray(img.convert("RGB")).reshape(-1, 3)
    assert len(np.unique(pixels, axis=0)) > 1


def _left():
    from PySide6.QtCore import Qt

    return Qt.MouseButton.LeftButton


def test_gif_export_and_cancel(make_window, qtbot, shared_data, tmp_path):
    window = make_window(size=None, active=False)
    assert window.open_path(shared_data / "cmu-animator" / "scenes" / "arm.svg")
    from qtanimator.core.channel import Key
    from qtanimator.document.commands import SetKeys

    doc = window.doc
    window.ctx.push(SetKeys(doc, {"arm/joint1/angle": Key(0.0, 0.0)}))
    window.ctx.push(SetKeys(doc, {"arm/joint1/angle": Key(3 / doc.fps, 1.0)}))  # every frame differs
    gif = tmp_path / "arm.gif"
    n = run_export(window, ExportSettings(out=str(gif), fmt="gif", width=40, height=30, fps=30, first=0, last=3))
    assert n == 4 and gif.stat().st_size > 0
    from qtanimator.render.export import count_video_frames

    assert count_video_frames(gif) == 4
    # MP4: the suffix is added from the format.
    n = run_export(window, ExportSettings(out=str(tmp_path / "arm"), fmt="mp4", width=32, height=32, fps=30,
                                          first=0, last=2))
    assert n == 3 and count_video_frames(tmp_path / "arm.mp4") == 3

    def press_cancel() -> None:
        dialog = window.export_progress
        assert isinstance(dialog, QProgressDialog) and dialog.objectName() == "exportProgress"
        qtbot.mouseClick(dialog.findChild(QPushButton), _left())

    QTimer.singleShot(0, press_cancel)
    written = run_export(window, ExportSettings(out=str(tmp_path / "seq"), fmt="png", width=32, height=32,
                                                first=0, last=200))
    assert 0 < written < 201


def test_ctrl_shift_e_in_the_2d_editor_exports_png_frames(make_window, qtbot, shared_data, tmp_path):
    """The CMU animator's ``s`` (save an image sequence) is Ctrl+Shift+E here (S sets a key):
    the export dialog opens set to PNG frames, even after a GIF export, and writes them."""
    from PySide6.QtCore import Qt
    from PySide6.QtWidgets import QWidget

    window = make_window()
    assert window.open_path(shared_data / "cmu-animator" / "scenes" / "arm.svg")
    window.export_settings = ExportSettings(out=str(tmp_path / "before.gif"), fmt="gif", width=100, height=80)
    view = window.findChild(QWidget, "rigEditorView")
    view.setFocus()
    qtbot.waitUntil(view.hasFocus)
    out = tmp_path / "frames"
    seen: dict[str, object] = {}

    def fill_in() -> None:
        dialog = QApplication.activeModalWidget()
        assert dialog is not None and dialog.objectName() == "exportDialog"
        seen["title"] = dialog.windowTitle()
        seen["format"] = dialog.findChild(QComboBox, "exportFormat").currentData()
        seen["path"] = dialog.findChild(QLineEdit, "exportPath").text()
        seen["width"] = dialog.findChild(QSpinBox, "exportWidth").value()
        dialog.findChild(QLineEdit, "exportPath").setText(str(out))
        dialog.findChild(QSpinBox, "exportWidth").setValue(64)
        dialog.findChild(QSpinBox, "exportHeight").setValue(48)
        dialog.findChild(QSpinBox, "exportFirst").setValue(0)
        dialog.findChild(QSpinBox, "exportLast").setValue(2)
        box = dialog.findChild(QDialogButtonBox)
        qtbot.mouseClick(box.button(QDialogButtonBox.StandardButton.Ok), _left())

    QTimer.singleShot(50, fill_in)
    qtbot.keyClick(view, Qt.Key.Key_E, Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.ShiftModifier)
    assert seen["title"] == "Export Image Sequence"
    assert seen["format"] == "png"
    assert not str(seen["path"]).endswith(".gif") and seen["width"] == 100   # the last size kept
    files = sorted(out.glob("*.png"))
    assert [f.name for f in files] == ["frame_0000.png", "frame_0001.png", "frame_0002.png"]
    assert window.export_settings.fmt == "png"
    # S keeps setting a key in the 2D editor (issue 13): with a joint selected it keys, no dialog opens.
    window.ctx.set_frame(7.0)
    window.ctx.select("arm", window.doc.runtime["arm"].joints[1].name)
    count = window.ctx.undo_stack.count()
    window.activateWindow()   # the closed dialogs leave no active window under a bare X server
    view.setFocus()
    qtbot.waitUntil(view.hasFocus)
    qtbot.keyClick(view, Qt.Key.Key_S)
    assert window.ctx.undo_stack.count() == count + 1 and QApplication.activeModalWidget() is None
