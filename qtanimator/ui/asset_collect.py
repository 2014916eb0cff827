"""File ▸ Collect Assets, and finding the files of a project that moved: the dialogs around
:mod:`qtanimator.document.asset_files`."""

from __future__ import annotations

from pathlib import Path

from PySide6.QtWidgets import QFileDialog, QMessageBox, QWidget

from qtanimator.document.asset_files import ASSETS_FOLDER, FileRef, collect_assets, file_refs
from qtanimator.document.io import Relink
from qtanimator.ui.app_settings import last_dir
from qtanimator.ui.context import EditorContext


def collect_into(parent: QWidget, ctx: EditorContext, folder: Path) -> bool:
    """Copy the project's files into ``folder``/assets (one undo step on ``ctx``); False, with
    a sentence shown, when copying fails (the project then still uses the files where they were)."""
    doc = ctx.doc
    try:
        result = collect_assets(doc, folder)
    except OSError as exc:
        where = f" ({exc.filename})" if exc.filename else ""
        QMessageBox.critical(parent, "Cannot collect assets", f"Copying into {folder / ASSETS_FOLDER} failed{where}: "
                             f"{exc.strerror or exc}. The project still uses the files where they were.")
        return False
    if result.command is not None:
        ctx.push(result.command)
    missing = [r for r in file_refs(doc.assets.values()) if not Path(r.path).exists()]
    if missing:
        names = ", ".join(sorted({Path(r.path).name for r in missing}))
        QMessageBox.warning(parent, "Collect Assets", f"These files are missing and were not copied: {names}.")
    return True


def locate_missing_file(parent: QWidget, ref: FileRef) -> str | None:
    """Asked while opening a project whose file ``ref`` is not where it was and not found
    beside the project: a file dialog to point at it (None when cancelled)."""
    old = Path(ref.path)
    title = f"Locate {old.name} (missing, used by {ref.asset_id})"
    start = last_dir()
    if not old.suffix:  # a folder of SVG characters
        chosen = QFileDialog.getExistingDirectory(parent, title, start)
    else:
        chosen, _ = QFileDialog.getOpenFileName(parent, title, start, f"{old.name} (*{old.suffix});;All files (*)")
    return chosen or None


def tell_relinked(parent: QWidget, relinks: list[Relink]) -> None:
    """Say which files of the opened project were found at new places."""
    lines = [f"{r.ref.asset_id}: {Path(r.ref.path).name} → {r.new_path}"
             + ("" if r.how == "chosen" else " (found beside the project)") for r in relinks]
    QMessageBox.information(
        parent, "Assets found at new places",
        "Some files of this project had moved; it now uses:\n\n" + "\n".join(lines)
        + "\n\nSave the project to keep these locations.")
