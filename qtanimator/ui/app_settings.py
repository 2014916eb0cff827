"""The program's settings file (QSettings: recent files, the last folder, window layout) and
the export dialogs that start in the last folder."""

from __future__ import annotations

import os
from pathlib import Path

from PySide6.QtCore import QSettings, QStandardPaths
from PySide6.QtWidgets import QFileDialog, QWidget

from qtanimator.paths import is_sample


def settings() -> QSettings:
    """The program's settings; tests point QTANIMATOR_SETTINGS_DIR at a temporary folder."""
    folder = os.environ.get("QTANIMATOR_SETTINGS_DIR")
    if folder:
        return QSettings(str(Path(folder) / "qtanimator.ini"), QSettings.Format.IniFormat)
    return QSettings("qtanimator", "qtanimator")


def last_dir() -> str:
    """The folder of the last file opened or saved (the home folder at first)."""
    return str(settings().value("lastDir", str(Path.home())))


def documents_dir() -> str:
    """The user's documents folder (the home folder where the platform names none, or it
    does not exist)."""
    folder = QStandardPaths.writableLocation(QStandardPaths.StandardLocation.DocumentsLocation)
    return folder if folder and Path(folder).is_dir() else str(Path.home())


def save_dir() -> str:
    """Where a Save dialog starts: the last folder, unless that is inside the bundled
    samples (the program's own files, maybe in site-packages): then the documents folder."""
    folder = last_dir()
    return documents_dir() if is_sample(folder) else folder


def ask_export_path(parent: QWidget, title: str, name: str, suffix: str, filters: str) -> str:
    """A Save dialog for an export named ``name`` + ``suffix`` in the last folder
    (:func:`save_dir`): the path
    chosen, with ``suffix`` added when the user typed none; "" when cancelled."""
    start = str(Path(save_dir()) / f"{name}{suffix}")
    path, _ = QFileDialog.getSaveFileName(parent, title, start, filters)
    if path and not Path(path).suffix:
        path += suffix
    return path
