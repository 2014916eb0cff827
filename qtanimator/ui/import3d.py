"""Opening 3D files (File > Open, drag and drop) and File > Export glTF….

Openers for ``.skel``, ``.skin``, ``.anim``, ``.obj``, ``.bvh``, ``.glb`` and ``.gltf`` go in
``window.openers``; each pushes the one undoable command that
:func:`qtanimator.document.import3d.import_file` builds (a FormatError leaves the document as
it is and :meth:`MainWindow.open_path` shows it), selects the character, switches to the
"3D" tab and frames it. Notes about the import (companion files picked up, approximations)
go to the status bar and :attr:`MainWindow.last_import_notes`. A clip whose frame rate differs
from a project that already has keys brings a status-bar button (``adoptClipFps``) that sets
the project to the clip's rate (:func:`offer_fps`).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from PySide6.QtCore import QTimer
from PySide6.QtGui import QAction
from PySide6.QtWidgets import QMessageBox, QPushButton

from qtanimator.document.character3d import ASSET_KIND, set_fps_command
from qtanimator.document.import3d import SUFFIXES, export_gltf, import_file, target_character
from qtanimator.formats.errors import FormatError
from qtanimator.ui.app_settings import ask_export_path

GLTF_FILTER = "glTF binary (*.glb)"
#: How long the status-bar offer to take an imported clip's frame rate stays (ms).
OFFER_MS = 60000

__all__ = ["export_gltf_dialog", "export_gltf_to", "install", "offer_fps", "open_3d", "show_character"]


def open_3d(window: Any, path: Path) -> None:
    """Import a 3D file into the window's document as one undo step."""
    try:
        result = import_file(window.doc, path, window.ctx.selection[0] or None)
    except FormatError:
        raise
    except ValueError as exc:  # a hierarchy or file the document cannot take
        raise FormatError(f"{exc}", path) from exc
    window.ctx.push(result.command)
    window.last_import_notes = list(result.notes)
    if result.notes:
        window.statusBar().showMessage(f"{Path(path).name}: {' '.join(result.notes)}", 15000)
    offer_fps(window, result.clip_fps)
    show_character(window, result.asset_id)


def offer_fps(window: Any, fps: float | None) -> None:
    """Show (or with None take away) a status-bar button that sets the project's frame rate
    to an imported clip's (one undo step, the frame range's seconds kept). Non-modal: it goes
    away when used, on the next import, or after :data:`OFFER_MS`."""
    old = getattr(window, "fps_offer_button", None)
    if old is not None:
        window.statusBar().removeWidget(old)
        old.deleteLater()
        window.fps_offer_button = None
    if fps is None:
        return
    button = QPushButton(f"Set project to {fps:g} fps", window)
    button.setObjectName("adoptClipFps")
    button.setToolTip("Play the imported clip at its own frame rate (keys stay in time; the frame range keeps "
                      "its seconds)")

    def adopt() -> None:
        if window.fps_offer_button is button:
            window.ctx.push(set_fps_command(window.doc, fps))
            offer_fps(window, None)

    def expire() -> None:
        if window.fps_offer_button is button:
            offer_fps(window, None)

    button.clicked.connect(adopt)
    window.statusBar().addPermanentWidget(button)
    window.fps_offer_button = button
    # The timer belongs to the button: it dies with it (used, replaced, or the window closed),
    # so it never fires into a deleted window.
    timer = QTimer(button)
    timer.setSingleShot(True)
    timer.timeout.connect(expire)
    timer.start(OFFER_MS)


def show_character(window: Any, asset_id: str) -> None:
    """Select a 3D character, switch to the "3D" tab and frame it."""
    if asset_id in window.doc.assets:
        window.ctx.select(asset_id, "")
    panel = getattr(window, "viewport_panel", None)
    view = getattr(window, "viewport3d", None)
    if panel is None or view is None:
        return
    window.central_tabs.setCurrentWidget(panel)
    from qtanimator.render.scene3d import scene_bounds

    try:
        items = view.build_items()
    except Exception:  # drawing data that fails is reported by the view itself
        return
    chosen = [i for i in items if getattr(i, "asset_id", None) == asset_id]
    bounds = scene_bounds(chosen or items)
    if bounds is not None:
        view.frame_bounds(bounds)
    view.update()


# ----------------------------------------------------------------------- export
def _export_target(window: Any) -> str | None:
    return target_character(window.doc, window.ctx.selection[0] or None)


def export_gltf_to(window: Any, path: str | os.PathLike[str], asset_id: str | None = None) -> bool:
    """Export a 3D character (the selected or only one by default) to ``path`` as ``.glb``.

    Messages (weights normalised, keys sampled) are shown as a message; errors through ``show_error``.
    """
    aid = asset_id or _export_target(window)
    if aid is None:
        count = sum(1 for a in window.doc.assets.values() if a.kind == ASSET_KIND)
        window.show_error("Cannot export glTF", "There is no 3D character to export." if count == 0 else
                          "Select the 3D character to export.")
        return False
    try:
        _result, messages = export_gltf(window.doc, aid, path)
    except (OSError, ValueError) as exc:
        window.show_error("Cannot export glTF", f"{Path(path).name}: {exc}")
        return False
    window.last_export_warnings = messages
    if messages:
        QMessageBox.warning(window, "glTF export", "\n\n".join(messages))
    window.statusBar().showMessage(f"Exported {aid} to {Path(path).name}", 10000)
    return True


def export_gltf_dialog(window: Any) -> None:
    aid = _export_target(window)
    if aid is None:
        export_gltf_to(window, "", None)  # explains why
        return
    path = ask_export_path(window, "Export glTF", aid, ".glb", GLTF_FILTER)
    if path:
        export_gltf_to(window, path, aid)


def install(window: Any) -> None:
    for suffix in SUFFIXES:
        window.openers[suffix] = open_3d
    window.last_import_notes = []
    window.last_export_warnings = []
    window.fps_offer_button = None
    action = QAction("Export &glTF…", window)
    action.setObjectName("actionExportGltf")
    action.setToolTip("Export the selected 3D character and its animation as a .glb file")
    action.triggered.connect(lambda _checked=False: export_gltf_dialog(window))
    window.file_menu.insertAction(window.export_separator, action)
    window.action_export_gltf = action
