"""File > Export Animation…: a PNG sequence, a GIF or an MP4 of the 2D or 3D view, or a glTF file.

File > Export Image Sequence… (``Ctrl+Shift+E``, the CMU animator's ``s``) opens the same
dialog set to PNG frames.

The dialog picks the view (the 2D view; the 3D view as the viewport shows it: its camera, the
lights, cloth; or the selected 3D character as a glTF file, written as File > Export glTF does),
the format, the output, the image size, the frame rate and the frame range; the frames are
rendered with the shared 2D or 3D renderer (as ``qtanimator render``) and written by
``qtanimator.render.export.write_frames`` while a QProgressDialog shows progress and
offers Cancel.
"""

from __future__ import annotations

import copy
import inspect
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from PySide6.QtCore import Qt
from PySide6.QtGui import QAction, QColor, QKeySequence
from PySide6.QtWidgets import (
    QApplication,
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QDoubleSpinBox,
    QFileDialog,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QProgressDialog,
    QPushButton,
    QSpinBox,
    QWidget,
)

from qtanimator.document.document import Document
from qtanimator.document.parameters import RENDER
from qtanimator.ui.param_fields import spin_for

if TYPE_CHECKING:
    from qtanimator.ui.main_window import MainWindow

FORMATS = {
    "png": ("PNG sequence", ""),
    "gif": ("Animated GIF", ".gif"),
    "mp4": ("MP4 video (H.264)", ".mp4"),
}

#: What the export shows: its label and the ``qtanimator`` command that does the same.
VIEWS = {
    "2d": "2D view",
    "3d": "3D view",
    "gltf": "glTF file (.glb)",
}

#: The reference program's export background (0.6, 0.6, 0.95) (2D; 3D keeps the viewport's):
#: the schema's ``render.background``.
DEFAULT_BACKGROUND = QColor.fromRgbF(*(float(c) for c in RENDER["render.background"].default))
assert set(FORMATS) == set(RENDER["render.format"].choices) and set(VIEWS) == set(RENDER["render.view"].choices)


@dataclass
class ExportSettings:
    """What to export: ``out`` is a folder or ``…%04d.png`` pattern for PNG, else a file."""

    out: str
    fmt: str = RENDER["render.format"].default
    width: int = RENDER["render.width"].default
    height: int = RENDER["render.height"].default
    fps: float = RENDER["render.fps"].default
    first: int = RENDER["render.first"].default
    last: int = RENDER["render.last"].default
    background: QColor | None = None
    #: "2d", "3d" or "gltf" (see :data:`VIEWS`)
    view: str = RENDER["render.view"].default
    #: the 3D view's camera (an OrbitCamera; None: framed as ``qtanimator render`` does)
    camera: Any = None


def default_view(doc: Document) -> str:
    """2D when the scene has 2D characters, else 3D when it has 3D characters or cloth."""
    kinds = {a.kind for a in doc.assets.values()}
    if "character2d" not in kinds and kinds & {"character3d", "cloth"}:
        return "3d"
    return "2d"


def default_settings(doc: Document) -> ExportSettings:
    first, last = doc.frame_range
    base = Path(doc.path).with_suffix("") if doc.path else Path.cwd() / "animation"
    return ExportSettings(out=str(base.parent / f"{base.name}_frames"), fmt="png", fps=doc.fps,
                          first=first, last=last, view=default_view(doc))


def output_target(settings: ExportSettings) -> str:
    """The path ``write_frames`` receives: the extension decides the format."""
    out = settings.out
    if settings.view == "gltf":
        return out if out.lower().endswith(".glb") else out + ".glb"
    if settings.fmt == "png":
        return out
    suffix = FORMATS[settings.fmt][1]
    return out if out.lower().endswith(suffix) else out + suffix


def render_frames(doc: Document, settings: ExportSettings) -> Iterator[Any]:
    """RGBA arrays of the range, rendered in order (so pendulums simulate forward), with
    one camera for the whole range (the union of the characters' bounds; in 3D the settings'
    camera)."""
    from qtanimator.render.painter2d import animation_bounds, image_to_array, render_frame

    frames = list(range(settings.first, settings.last + 1))
    if settings.view == "3d":
        yield from _render_frames_3d(doc, settings, frames)
        return
    background = settings.background or DEFAULT_BACKGROUND
    sample = frames[::max(len(frames) // 24, 1)] + frames[-1:]
    view = animation_bounds(doc, [doc.frame_to_time(f) for f in sample])
    size = (settings.width, settings.height)
    for frame in frames:
        image = render_frame(doc, doc.frame_to_time(frame), size, background,
                             view=view if not view.isEmpty() else None)
        yield image_to_array(image)


def _render_frames_3d(doc: Document, settings: ExportSettings, frames: list[int]) -> Iterator[Any]:
    from qtanimator.render.gl.renderer import ViewOptions
    from qtanimator.render.render3d import render_frames_3d

    options = ViewOptions(show_skeleton=False, show_lights=False)
    if settings.background is not None:
        c = settings.background
        options.background = (c.redF(), c.greenF(), c.blueF(), c.alphaF())
    camera = copy.deepcopy(settings.camera) if settings.camera is not None else None
    yield from render_frames_3d(doc, [doc.frame_to_time(f) for f in frames], (settings.width, settings.height),
                                camera=camera, options=options)


def _call_progress(progress: Callable[[int, int], bool] | None, done: int, total: int) -> bool:
    return True if progress is None else bool(progress(done, total))


def export_animation(doc: Document, settings: ExportSettings,
                     progress: Callable[[int, int], bool] | None = None) -> int:
    """Render and write the frames; ``progress(done, total)`` returning False cancels.

    Returns the number of frames written.
    """
    from qtanimator.render.export import write_frames

    total = max(settings.last - settings.first + 1, 0)
    cancelled = False

    def on_progress(*args: Any) -> None:
        nonlocal cancelled
        done = int(args[0]) if args else 0
        if not _call_progress(progress, done, total):
            cancelled = True

    def cancel() -> bool:
        return cancelled

    frames = render_frames(doc, settings)
    params = inspect.signature(write_frames).parameters
    kwargs: dict[str, Any] = {}
    if "progress" in params:
        kwargs["progress"] = on_progress
    if "cancel" in params:
        kwargs["cancel"] = cancel
    target = output_target(settings)
    if settings.fmt == "png":
        Path(target if "%" not in target else Path(target).parent).mkdir(parents=True, exist_ok=True)
    return int(write_frames(frames, target, settings.fps, **kwargs))


class ExportDialog(QDialog):
    """The settings form; ``settings()`` reads it back."""

    def __init__(self, doc: Document, parent: QWidget | None = None,
                 initial: ExportSettings | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("exportDialog")
        self.setWindowTitle("Export Animation")
        s = initial or default_settings(doc)
        form = QFormLayout(self)
        self.view_box = QComboBox(self)
        self.view_box.setObjectName("exportView")
        self.view_box.setToolTip("The 2D view, the 3D view (with the viewport's camera, the lights and cloth), "
                                 "or the selected 3D character and its animation as a glTF file")
        for key, label in VIEWS.items():
            self.view_box.addItem(label, key)
        self.view_box.setCurrentIndex(list(VIEWS).index(s.view if s.view in VIEWS else "2d"))
        form.addRow("View", self.view_box)
        self.format_box = QComboBox(self)
        self.format_box.setObjectName("exportFormat")
        for key, (label, _suffix) in FORMATS.items():
            self.format_box.addItem(label, key)
        self.format_box.setCurrentIndex(list(FORMATS).index(s.fmt))
        form.addRow("Format", self.format_box)
        row = QHBoxLayout()
        self.path_edit = QLineEdit(s.out, self)
        self.path_edit.setObjectName("exportPath")
        browse = QPushButton("Browse…", self)
        browse.clicked.connect(self._browse)
        row.addWidget(self.path_edit, 1)
        row.addWidget(browse)
        form.addRow("Output", row)
        self.width_box = _spin(self, "exportWidth", "render.width", s.width)
        self.height_box = _spin(self, "exportHeight", "render.height", s.height)
        size_row = QHBoxLayout()
        size_row.addWidget(self.width_box)
        size_row.addWidget(self.height_box)
        form.addRow("Size", size_row)
        fps_box = spin_for(RENDER["render.fps"], self, "exportFps")
        assert isinstance(fps_box, QDoubleSpinBox)
        fps_box.setKeyboardTracking(True)  # the GIF note follows the typing
        fps_box.setValue(s.fps)
        self.fps_box = fps_box
        form.addRow("Frame rate", self.fps_box)
        self.first_box = _spin(self, "exportFirst", "render.first", s.first)
        self.last_box = _spin(self, "exportLast", "render.last", s.last)
        range_row = QHBoxLayout()
        range_row.addWidget(self.first_box)
        range_row.addWidget(self.last_box)
        form.addRow("Frames", range_row)
        self.gif_note = QLabel(self)
        self.gif_note.setObjectName("exportGifNote")
        self.gif_note.setWordWrap(True)
        form.addRow(self.gif_note)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Ok | QDialogButtonBox.StandardButton.Cancel,
                                   self)
        buttons.button(QDialogButtonBox.StandardButton.Ok).setText("Export")
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        form.addRow(buttons)
        self.image_widgets = [self.format_box, self.width_box, self.height_box, self.fps_box, self.first_box,
                              self.last_box]
        self.view_box.currentIndexChanged.connect(self._view_changed)
        self._view_changed()
        self.format_box.currentIndexChanged.connect(self._format_changed)
        self.format_box.currentIndexChanged.connect(self._update_gif_note)
        self.fps_box.valueChanged.connect(self._update_gif_note)
        self._update_gif_note()

    def _update_gif_note(self) -> None:
        """Say at what rate a GIF is written (a GIF holds at most 50 fps, in whole centiseconds)."""
        from qtanimator.render.export import gif_timing_note

        gif = self.format_box.currentData() == "gif" and self.view_box.currentData() != "gltf"
        note = gif_timing_note(self.fps_box.value()) if gif else None
        self.gif_note.setText(note[0].upper() + note[1:] + "." if note else "")
        self.gif_note.setVisible(bool(note))

    def _view_changed(self) -> None:
        """glTF has no images: the image settings are off and the output becomes a .glb."""
        gltf = self.view_box.currentData() == "gltf"
        for widget in self.image_widgets:
            widget.setEnabled(not gltf)
        self._format_changed()
        self._update_gif_note()

    def _format_changed(self) -> None:
        fmt = self.format_box.currentData()
        out = self.path_edit.text()
        stem = out
        for suffix in [s for _label, s in FORMATS.values()] + [".glb"]:
            if suffix and stem.lower().endswith(suffix):
                stem = stem[: -len(suffix)]
        if self.view_box.currentData() == "gltf":
            self.path_edit.setText(stem + ".glb")
        else:
            self.path_edit.setText(stem + FORMATS[fmt][1])

    def _browse(self) -> None:
        fmt = self.format_box.currentData()
        if self.view_box.currentData() == "gltf":
            path, _ = QFileDialog.getSaveFileName(self, "Export to", self.path_edit.text(), "glTF binary (*.glb)")
        elif fmt == "png":
            path = QFileDialog.getExistingDirectory(self, "Folder for the frames", self.path_edit.text())
        else:
            suffix = FORMATS[fmt][1]
            path, _ = QFileDialog.getSaveFileName(self, "Export to", self.path_edit.text(),
                                                  f"{FORMATS[fmt][0]} (*{suffix})")
        if path:
            self.path_edit.setText(path)

    def settings(self) -> ExportSettings:
        return ExportSettings(out=self.path_edit.text(), fmt=str(self.format_box.currentData()),
                              width=self.width_box.value(), height=self.height_box.value(),
                              fps=self.fps_box.value(), first=self.first_box.value(),
                              last=max(self.last_box.value(), self.first_box.value()),
                              view=str(self.view_box.currentData()))


def _spin(parent: QWidget, name: str, path: str, value: int) -> QSpinBox:
    """The field of the render setting ``path`` (range and label from the schema)."""
    box = spin_for(RENDER[path], parent, name)
    assert isinstance(box, QSpinBox)
    box.setKeyboardTracking(True)
    box.setValue(value)
    return box


def run_export(window: MainWindow, settings: ExportSettings) -> int:
    """Export with a progress dialog (Cancel stops after the current frame); a glTF file as
    File > Export glTF does (1 when written)."""
    if settings.view == "gltf":
        from qtanimator.ui.import3d import export_gltf_to

        return 1 if export_gltf_to(window, output_target(settings)) else 0
    total = max(settings.last - settings.first + 1, 1)
    dialog = QProgressDialog("Exporting animation…", "Cancel", 0, total, window)
    dialog.setObjectName("exportProgress")
    dialog.setWindowTitle("Export Animation")
    dialog.setWindowModality(Qt.WindowModality.WindowModal)
    dialog.setMinimumDuration(0)
    dialog.setValue(0)
    window.export_progress = dialog  # type: ignore[attr-defined]

    def progress(done: int, n: int) -> bool:
        dialog.setValue(min(done, total))
        QApplication.processEvents()
        return not dialog.wasCanceled()

    try:
        written = export_animation(window.doc, settings, progress)
    except (OSError, ValueError, RuntimeError) as exc:
        dialog.close()
        window.show_error("Cannot export", str(exc))
        return 0
    finally:
        cancelled = dialog.wasCanceled()
        dialog.reset()
        dialog.deleteLater()
        window.export_progress = None  # type: ignore[attr-defined]
    if cancelled:
        window.statusBar().showMessage(f"Export cancelled after {written} frames.", 5000)
    else:
        window.statusBar().showMessage(f"Exported {written} frames to {output_target(settings)}.", 5000)
    return written


def viewport_camera(window: Any) -> Any:
    """A copy of the 3D viewport's camera (None when the window has no 3D view)."""
    view = getattr(window, "viewport3d", None)
    camera = getattr(view, "camera", None)
    return copy.deepcopy(camera) if camera is not None else None


def open_export_dialog(window: MainWindow) -> int:
    previous = getattr(window, "export_settings", None)
    dialog = ExportDialog(window.doc, window, previous)
    if dialog.exec() != QDialog.DialogCode.Accepted:
        return 0
    settings = dialog.settings()
    settings.camera = viewport_camera(window)
    window.export_settings = settings  # type: ignore[attr-defined]
    return run_export(window, settings)


def image_sequence_settings(window: MainWindow) -> ExportSettings:
    """The last export's settings (or the defaults) switched to a PNG sequence: a GIF or video
    target becomes the default frames folder."""
    from dataclasses import replace

    previous = getattr(window, "export_settings", None)
    if isinstance(previous, ExportSettings) and previous.fmt == "png" and previous.view != "gltf":
        return previous
    defaults = default_settings(window.doc)
    if isinstance(previous, ExportSettings):
        view = defaults.view if previous.view == "gltf" else previous.view
        return replace(previous, fmt="png", out=defaults.out, view=view)
    return defaults


def open_image_sequence_dialog(window: MainWindow) -> int:
    """File > Export Image Sequence…: the export dialog set to PNG frames (the CMU key ``s``)."""
    dialog = ExportDialog(window.doc, window, image_sequence_settings(window))
    dialog.setWindowTitle("Export Image Sequence")
    if dialog.exec() != QDialog.DialogCode.Accepted:
        return 0
    settings = dialog.settings()
    settings.camera = viewport_camera(window)
    window.export_settings = settings  # type: ignore[attr-defined]
    return run_export(window, settings)


def install(window: MainWindow) -> None:
    action = QAction("&Export Animation…", window)
    action.setObjectName("actionExport")
    action.setShortcut(QKeySequence("Ctrl+E"))
    action.triggered.connect(lambda _checked=False: open_export_dialog(window))
    window.file_menu.insertAction(window.export_separator, action)
    window.action_export = action  # type: ignore[attr-defined]
    frames = QAction("Export &Image Sequence…", window)
    frames.setObjectName("actionExportImageSequence")
    frames.setShortcut(QKeySequence("Ctrl+Shift+E"))
    frames.setStatusTip("Write the 2D animation as numbered PNG frames (the reference animator's s key)")
    frames.triggered.connect(lambda _checked=False: open_image_sequence_dialog(window))
    window.file_menu.insertAction(window.export_separator, frames)
    window.action_export_frames = frames  # type: ignore[attr-defined]
