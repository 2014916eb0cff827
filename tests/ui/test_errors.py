"""Unexpected errors in the GUI: the exception hook logs them and shows a dialog with the
traceback and a "Copy details" button (offscreen; the dialog's exec is patched not to block)."""

from __future__ import annotations

import logging
import sys
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest

from qtanimator import applog
from qtanimator.ui import errors


@pytest.fixture
def hook(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, qapp) -> Iterator[list[errors.ErrorDialog]]:  # type: ignore[no-untyped-def]
    """The hook installed, logging under a temporary XDG state folder; yields the dialogs shown."""
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
    level = logging.getLogger().level
    applog.setup_logging()
    shown: list[errors.ErrorDialog] = []

    def fake_exec(dialog: errors.ErrorDialog) -> int:
        shown.append(dialog)
        return 0

    monkeypatch.setattr(errors.ErrorDialog, "exec", fake_exec)
    errors.install_excepthook()
    yield shown
    errors.uninstall_excepthook()
    applog.close_logging()
    logging.getLogger().setLevel(level)


def _log_text(tmp_path: Path) -> str:
    for handler in logging.getLogger().handlers:
        handler.flush()
    return (tmp_path / "state" / "qtanimator" / "qtanimator.log").read_text(encoding="utf-8")


def _raise_in_a_function() -> None:
    raise RuntimeError("the rig exploded")


def test_the_hook_logs_the_traceback_and_shows_it_with_copy_details(hook, tmp_path, qtbot):
    from PySide6.QtGui import QGuiApplication
    from PySide6.QtWidgets import QLabel, QPlainTextEdit, QPushButton

    assert sys.excepthook is errors.handle_exception
    try:
        _raise_in_a_function()
    except RuntimeError:
        sys.excepthook(*sys.exc_info())
    log = _log_text(tmp_path)
    assert "unexpected error" in log and "Traceback" in log
    assert "RuntimeError: the rig exploded" in log and "_raise_in_a_function" in log
    (dialog,) = hook
    qtbot.addWidget(dialog)
    details = dialog.findChild(QPlainTextEdit, "errorDetails").toPlainText()
    assert "RuntimeError: the rig exploded" in details and "_raise_in_a_function" in details
    assert details.startswith("qtanimator ")  # version and platform head the report
    copy = dialog.findChild(QPushButton, "copyDetailsButton")
    assert copy.text() == "Copy details"
    copy.click()
    assert QGuiApplication.clipboard().text() == details
    message = dialog.findChild(QLabel, "errorMessage").text()
    assert "the rig exploded" in message and str(applog.log_path()) in message
    assert dialog.findChild(QPushButton, "openLogFolderButton") is not None


@pytest.mark.qt_no_exception_capture
def test_an_error_in_a_slot_reaches_the_dialog(hook, tmp_path, qtbot):
    from PySide6.QtCore import QTimer

    QTimer.singleShot(0, _raise_in_a_function)
    qtbot.waitUntil(lambda: len(hook) == 1)
    assert "the rig exploded" in _log_text(tmp_path)


@pytest.mark.qt_no_exception_capture
def test_an_error_in_a_worker_thread_is_shown_on_the_ui_thread(hook, tmp_path, qtbot):
    shown_on: list[bool] = []
    original = errors.ErrorDialog.exec

    def record(dialog: errors.ErrorDialog) -> int:
        shown_on.append(threading.current_thread() is threading.main_thread())
        return original(dialog)

    errors.ErrorDialog.exec = record  # type: ignore[method-assign]
    try:
        worker = threading.Thread(target=_raise_in_a_function)
        worker.start()
        worker.join()
        qtbot.waitUntil(lambda: len(hook) == 1)
    finally:
        errors.ErrorDialog.exec = original  # type: ignore[method-assign]
    assert shown_on == [True]
    assert "the rig exploded" in _log_text(tmp_path)


def test_one_dialog_at_a_time(hook, tmp_path, monkeypatch):
    # An error raised while the dialog is open (a paint event failing every frame) is logged only.
    def reentrant(dialog: errors.ErrorDialog) -> int:
        hook.append(dialog)
        try:
            _raise_in_a_function()
        except RuntimeError:
            errors.handle_exception(*sys.exc_info())
        return 0

    monkeypatch.setattr(errors.ErrorDialog, "exec", reentrant)
    try:
        _raise_in_a_function()
    except RuntimeError:
        errors.handle_exception(*sys.exc_info())
    assert len(hook) == 1
    assert _log_text(tmp_path).count("ERROR qtanimator.errors: unexpected error") == 2


def test_the_log_rotates(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path))
    monkeypatch.setattr(applog, "MAX_BYTES", 2000)
    level = logging.getLogger().level
    try:
        path = applog.setup_logging(verbose=True)
        assert path == tmp_path / "qtanimator" / "qtanimator.log"
        log = logging.getLogger("qtanimator.test")
        for i in range(200):
            log.debug("line %d of a long session", i)
        names = sorted(p.name for p in path.parent.iterdir())
        assert names == ["qtanimator.log", "qtanimator.log.1", "qtanimator.log.2", "qtanimator.log.3"]
    finally:
        applog.close_logging()
        logging.getLogger().setLevel(level)


def test_the_state_folder_follows_xdg(monkeypatch, tmp_path):
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "s"))
    assert applog.log_path() == tmp_path / "s" / "qtanimator" / "qtanimator.log"
    monkeypatch.setenv("XDG_STATE_HOME", "relative/is/ignored")
    assert applog.log_dir() == Path.home() / ".local" / "state" / "qtanimator"
    monkeypatch.delenv("XDG_STATE_HOME")
    assert applog.log_dir() == Path.home() / ".local" / "state" / "qtanimator"


def test_the_gui_start_installs_the_hook_the_log_and_the_desktop_identity(qapp, tmp_path, monkeypatch):
    from PySide6.QtGui import QGuiApplication
    from PySide6.QtWidgets import QApplication

    from qtanimator.cli import main
    from qtanimator.paths import APP_ID
    from qtanimator.ui.main_window import MainWindow

    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
    monkeypatch.setattr(QApplication, "exec", lambda *a: 0)
    windows: list[MainWindow] = []
    real_show = MainWindow.show
    monkeypatch.setattr(MainWindow, "show", lambda self: (windows.append(self), real_show(self))[1])
    project = tmp_path / "empty.qtanim"
    from qtanimator.document import Document, save_document

    save_document(Document(), project)
    interval, level = sys.getswitchinterval(), logging.getLogger().level
    try:
        assert main([str(project), "--verbose"]) == 0
        assert sys.excepthook is errors.handle_exception
        assert QGuiApplication.desktopFileName() == APP_ID
        assert not QGuiApplication.windowIcon().isNull()
        (window,) = windows
        assert window.doc.path == str(project.resolve())
        assert "starting" in _log_text(tmp_path)
    finally:
        errors.uninstall_excepthook()
        applog.close_logging()
        logging.getLogger().setLevel(level)
        sys.setswitchinterval(interval)
        for w in windows:
            w.close()
            w.deleteLater()
