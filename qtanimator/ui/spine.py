"""Spine JSON in the window: File ▸ Import Spine Animation…, opening a Spine ``.json`` (File ▸
Open, drag and drop), and File ▸ Export Spine….

Export writes the selected (or only) 2D character as a Spine skeleton with its animation and
PNG attachments (:func:`qtanimator.render.spine_images.export_spine`), for game runtimes.

A Spine 4.x skeleton's animation goes onto a 2D character of the document (the selected one,
or the only one), its bones matched to the character's joints by name, as one undo step
(:func:`qtanimator.document.spine_import.spine_import_command`: the inverse of the Spine
export). What could not be matched or imported is said in the status bar and kept in
:attr:`MainWindow.last_import_notes`. A ``.json`` that is not Spine data opens as a project,
as before.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from PySide6.QtGui import QAction
from PySide6.QtWidgets import QFileDialog

from qtanimator.document.character2d import ASSET_KIND, character_assets
from qtanimator.document.spine_import import spine_import_command
from qtanimator.formats.errors import FormatError
from qtanimator.formats.spine import looks_like_spine
from qtanimator.ui.app_settings import ask_export_path, last_dir

SPINE_FILTER = "Spine JSON (*.json)"

__all__ = ["export_spine_to", "import_spine", "install", "open_json", "target_character"]


def target_character(window: Any) -> str | None:
    """The 2D character a Spine animation goes onto: the selected one, else the only one."""
    selected = window.ctx.selection[0]
    asset = window.doc.assets.get(selected) if selected else None
    if asset is not None and asset.kind == ASSET_KIND:
        return str(selected)
    characters = character_assets(window.doc)
    return characters[0] if len(characters) == 1 else None


def import_spine(window: Any, path: str | Path, asset_id: str | None = None) -> None:
    """Put the first animation of the Spine file ``path`` onto a 2D character (one undo
    step). Raises FormatError (shown by the caller, the document unchanged) when the file
    cannot be read or the animation cannot go onto any character."""
    p = Path(path)
    aid = asset_id or target_character(window)
    if aid is None:
        if not character_assets(window.doc):
            raise FormatError("a Spine animation goes onto a 2D character, and the document has none; "
                              "open the character's SVG first.", p)
        raise FormatError("select the 2D character the Spine animation goes onto.", p)
    try:
        command = spine_import_command(window.doc, aid, p)
    except ValueError as exc:  # no such animation, no bone matches a joint
        raise FormatError(str(exc), p) from exc
    window.ctx.push(command)
    notes = [f"Spine animation '{command.animation}' on {aid}: {len(command.matched)} joints keyed."]
    if command.unmatched:
        notes.append("Bones with no joint of that name: " + ", ".join(command.unmatched) + ".")
    if command.skipped:
        notes.append("Left to the simulation: " + ", ".join(command.skipped) + ".")
    notes.extend(command.notes)
    window.last_import_notes = notes
    window.statusBar().showMessage(f"{p.name}: {' '.join(notes)}", 15000)


def open_json(window: Any, path: Path) -> None:
    """The opener of ``.json``: Spine data is imported, anything else opens as a project."""
    if looks_like_spine(path):
        import_spine(window, path)
    else:
        window.open_project(path)


def import_spine_dialog(window: Any) -> None:
    path, _ = QFileDialog.getOpenFileName(window, "Import Spine Animation", last_dir(), SPINE_FILTER)
    if not path:
        return
    try:
        import_spine(window, path)
    except FormatError as exc:
        window.show_error("Cannot import the Spine animation", str(exc))


def export_spine_to(window: Any, path: str | Path, asset_id: str | None = None) -> bool:
    """Export a 2D character (the selected or only one) to ``path`` (``NAME.json`` and
    ``images/``); errors are shown and False returned."""
    from qtanimator.render.spine_images import export_spine

    aid = asset_id or target_character(window)
    if aid is None:
        window.show_error("Cannot export Spine", "There is no 2D character to export."
                          if not character_assets(window.doc) else "Select the 2D character to export.")
        return False
    try:
        export_spine(window.doc, aid, path)
    except (OSError, ValueError) as exc:
        window.show_error("Cannot export Spine", f"{Path(path).name}: {exc}")
        return False
    window.statusBar().showMessage(f"Exported {aid} to {Path(path).name} and its images/ folder", 10000)
    return True


def export_spine_dialog(window: Any) -> None:
    aid = target_character(window)
    if aid is None:
        export_spine_to(window, "", None)  # explains why
        return
    path = ask_export_path(window, "Export Spine", aid, ".json", SPINE_FILTER)
    if path:
        export_spine_to(window, path, aid)


def install(window: Any) -> None:
    window.openers[".json"] = open_json
    action = QAction("Import &Spine Animation…", window)
    action.setObjectName("actionImportSpine")
    action.setToolTip("Put an animation from a Spine JSON file onto the selected 2D character "
                      "(bones matched to joints by name)")
    action.triggered.connect(lambda _checked=False: import_spine_dialog(window))
    window.file_menu.insertAction(window.export_separator, action)
    window.action_import_spine = action
    export = QAction("Export S&pine…", window)
    export.setObjectName("actionExportSpine")
    export.setToolTip("Export the selected 2D character as a Spine skeleton (JSON and PNG images) "
                      "with its animation")
    export.triggered.connect(lambda _checked=False: export_spine_dialog(window))
    window.file_menu.insertAction(window.export_separator, export)
    window.action_export_spine = export
