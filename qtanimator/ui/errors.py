"""Unexpected errors in the GUI: logged, and shown in a dialog the user can copy from.

:func:`install_excepthook` (called by the command line's GUI start) replaces
``sys.excepthook`` and ``threading.excepthook``: every uncaught exception is written to the
log (:mod:`qtanimator.applog`) with its traceback, and an :class:`ErrorDialog` shows it with
a "Copy details" button and a button that opens the log folder. A program started from its
desktop entry has no terminal, so without this the error would vanish.

Only one dialog is shown at a time: an error repeated while it is open (a paint event that
fails every frame) is logged, not stacked up as more dialogs. Exceptions raised in worker
threads are logged and shown on the UI thread.
"""

from __future__ import annotations

import logging
import sys
import threading
import traceback
from collections.abc import Callable
from types import TracebackType

from PySide6.QtCore import QObject, Qt, QUrl, Signal
from PySide6.QtGui import QDesktopServices, QGuiApplication
from PySide6.QtWidgets import (
    QApplication,
    QDialog,
    QDialogButtonBox,
    QLabel,
    QPlainTextEdit,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from qtanimator import __version__, applog

log = logging.getLogger("qtanimator.errors")

ExceptHook = Callable[[type[BaseException], BaseException, TracebackType | None], object]


def format_details(exc_type: type[BaseException], exc: BaseException, tb: TracebackType | None) -> str:
    """The text a user copies into a problem report: version, platform and traceback."""
    lines = traceback.format_exception(exc_type, exc, tb)
    qt = ""
    try:
        from PySide6 import __version__ as pyside_version

        qt = f", PySide6 {pyside_version}"
    except ImportError:  # pragma: no cover - PySide6 is imported above
        pass
    header = f"qtanimator {__version__} (Python {sys.version.split()[0]}{qt}, {sys.platform})\n\n"
    return header + "".join(lines)


class ErrorDialog(QDialog):
    """The error, its traceback (read-only, selectable) and Copy details / Open Log Folder."""

    def __init__(self, summary: str, details: str, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("errorDialog")
        self.setWindowTitle("qtanimator — unexpected error")
        self.details = details
        layout = QVBoxLayout(self)
        message = QLabel(
            f"<b>Something went wrong:</b> {_escape(summary)}<br><br>"
            "Your work is still open; saving it under a new name is a good idea. "
            f"The details below are also in the log file:<br><code>{_escape(str(applog.log_path()))}</code>")
        message.setObjectName("errorMessage")
        message.setWordWrap(True)
        message.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        layout.addWidget(message)
        text = QPlainTextEdit(details)
        text.setObjectName("errorDetails")
        text.setReadOnly(True)
        text.setLineWrapMode(QPlainTextEdit.LineWrapMode.NoWrap)
        text.setMinimumSize(640, 240)
        layout.addWidget(text)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Close)
        self.copy_button = QPushButton("Copy details")
        self.copy_button.setObjectName("copyDetailsButton")
        self.copy_button.clicked.connect(self.copy_details)
        buttons.addButton(self.copy_button, QDialogButtonBox.ButtonRole.ActionRole)
        folder = QPushButton("Open Log Folder")
        folder.setObjectName("openLogFolderButton")
        folder.clicked.connect(open_log_folder)
        buttons.addButton(folder, QDialogButtonBox.ButtonRole.ActionRole)
        buttons.rejected.connect(self.reject)
        layout.addWidget(buttons)

    def copy_details(self) -> None:
        clipboard = QGuiApplication.clipboard()
        if clipboard is not None:
            clipboard.setText(self.details)
        self.copy_button.setText("Copied")


def _escape(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def open_log_folder() -> bool:
    """Open the folder of the log files in the desktop's file manager (made if missing)."""
    folder = applog.log_dir()
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        log.warning("cannot make the log folder %s: %s", folder, exc.strerror or exc)
    return bool(QDesktopServices.openUrl(QUrl.fromLocalFile(str(folder))))


class _Reporter(QObject):
    """Brings errors from any thread to the UI thread (a queued signal) and shows them."""

    errorRaised = Signal(str, str)

    def __init__(self) -> None:
        super().__init__()
        self.showing = False
        self.shown = 0
        self.errorRaised.connect(self._show, Qt.ConnectionType.QueuedConnection)

    def _show(self, summary: str, details: str) -> None:
        if self.showing:
            return  # already logged; one dialog at a time
        app = QApplication.instance()
        if app is None:
            return
        self.showing = True
        try:
            parent = QApplication.activeWindow()
            dialog = ErrorDialog(summary, details, parent)
            self.shown += 1
            dialog.exec()
            dialog.deleteLater()
        finally:
            self.showing = False


_reporter: _Reporter | None = None
_previous: tuple[ExceptHook, Callable[[threading.ExceptHookArgs], object]] | None = None


def handle_exception(exc_type: type[BaseException], exc: BaseException, tb: TracebackType | None) -> None:
    """Log an uncaught exception and show it (on the UI thread, when a QApplication exists)."""
    if issubclass(exc_type, KeyboardInterrupt):
        QApplication.quit()
        return
    details = format_details(exc_type, exc, tb)
    log.error("unexpected error\n%s", details)
    summary = f"{exc_type.__name__}: {exc}".splitlines()[0][:300]
    if _reporter is None or QApplication.instance() is None:
        sys.stderr.write(details)
        return
    if threading.current_thread() is threading.main_thread():
        _reporter._show(summary, details)
    else:
        _reporter.errorRaised.emit(summary, details)


def _thread_hook(args: threading.ExceptHookArgs) -> None:
    if args.exc_value is None or args.exc_type is SystemExit:
        return
    handle_exception(args.exc_type, args.exc_value, args.exc_traceback)


def install_excepthook() -> None:
    """Route uncaught exceptions (UI thread and worker threads) to :func:`handle_exception`."""
    global _reporter, _previous
    if _reporter is None:
        _reporter = _Reporter()
    if _previous is None:
        _previous = (sys.excepthook, threading.excepthook)
    sys.excepthook = handle_exception
    threading.excepthook = _thread_hook


def uninstall_excepthook() -> None:
    """Put back the hooks :func:`install_excepthook` replaced (tests)."""
    global _previous
    if _previous is not None:
        sys.excepthook, threading.excepthook = _previous
        _previous = None


def dialogs_shown() -> int:
    """How many error dialogs were shown (tests)."""
    return _reporter.shown if _reporter is not None else 0
