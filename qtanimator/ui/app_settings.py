"""The program's settings file (QSettings: recent files, the last folder, window layout) and
the export dialogs that start in the last folder."""

from __future__ import annotations

import os
from pathlib import Path

from PySide6.QtCore import QSettings
from PySide6.QtWidgets import QFileDialog, QWidget


def settings() -> QSettings:
    """The program's settings; tests point QTANIMATOR_SETTINGS_DIR at a temporary folder."""
    folder = os.environ.get("QTANIMATOR_SETTINGS_DIR")
    if folder:
        return QSettings(str(Path(folder) / "qtanimator.ini"), QSettings.Format.IniFormat)
    return QSettings("qtanimator", "qtanimator")


def last_dir() -> str:
    """The folder of the last file opened or saved (the home folder at first)."""
    return str(settings().value("lastDir", str(Path.home())))


def ask_export_path(parent: QWidget, title: str, name: str, suffix: str, filters: str) -> str:
    """A Save dialog for an export named ``name`` + ``suffix`` in the last folder: the path
    chosen, with ``suffix`` added when the user typed none; "" when cancelled."""
    start = str(Path(last_dir()) / f"{name}{suffix}")
    path, _ = QFileDialog.getSaveFileName(parent, title, start, filters)
    if path and not Path(path).suffix:
        path += suffix
    return path
