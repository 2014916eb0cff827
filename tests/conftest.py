"""Test session set-up: a private Xvfb for Qt (and real OpenGL through Mesa), or offscreen.

At import time we try to start ``Xvfb -displayfd``. When it starts, every Qt test runs on
the ``xcb`` platform on that private display, so QOpenGLWidget gets a real Mesa (llvmpipe)
context. When it cannot start, widgets run on the ``offscreen`` platform and the tests
marked ``gl`` are skipped with the reason; in CI (``CI=true``) they fail instead, as do the
tests that need the sample data (``$QTANIMATOR_SHARED_DATA`` or ``../shared/data``) when it is
missing (see ``tests/needs.py``). The run ends with one line that says how many tests were
skipped (or failed, in CI) for want of the sample data, and where it was looked for.

Hypothesis runs with the ``ci`` profile (fixed seeds) when ``CI=true`` and ``dev`` otherwise
(``tests/hypothesis_profiles.py``).
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import hypothesis_profiles
import pytest
from needs import SHARED_DATA_MISSING, in_ci, missing, shared_data_missing_reason, shared_data_path

from qtanimator.render.xvfb import start_private_xvfb

_xvfb_reason = ""


def _start_xvfb() -> str | None:
    """Start a private Xvfb and return its display name, or None with a reason set."""
    global _xvfb_reason
    if os.environ.get("QTANIMATOR_TEST_NO_XVFB"):
        _xvfb_reason = "QTANIMATOR_TEST_NO_XVFB is set"
        return None
    try:
        return start_private_xvfb("1920x1080x24")
    except OSError as exc:
        _xvfb_reason = str(exc)
        return None


def _configure_qt() -> None:
    os.environ.setdefault("XDG_RUNTIME_DIR", tempfile.mkdtemp(prefix="qtanimator-xdg-"))
    # Tests never read or write the user's settings or recent files.
    os.environ["QTANIMATOR_SETTINGS_DIR"] = tempfile.mkdtemp(prefix="qtanimator-settings-")
    display = _start_xvfb()
    if display is not None:
        os.environ["DISPLAY"] = display
        os.environ["QT_QPA_PLATFORM"] = "xcb"
        os.environ["QTANIMATOR_TEST_GL"] = "1"
    else:
        os.environ["QT_QPA_PLATFORM"] = "offscreen"
        os.environ.pop("QTANIMATOR_TEST_GL", None)


_configure_qt()
# Hypothesis: the "ci" profile (fixed seeds) with CI=true, "dev" otherwise; loaded here,
# before any test module builds its settings (tests/hypothesis_profiles.py).
hypothesis_profiles.load()


def pytest_runtest_setup(item: pytest.Item) -> None:
    """A test marked ``gl`` without an OpenGL context: skipped, or failed in CI."""
    if "gl" in item.keywords and not os.environ.get("QTANIMATOR_TEST_GL"):
        missing(f"no OpenGL context: {_xvfb_reason}")


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """The real public sample files; tests using this skip when they are absent (fail in CI).
    The folder is ``$QTANIMATOR_SHARED_DATA`` or ``../shared/data`` (``tests/needs.py``)."""
    return shared_data_path()


def _for_want_of_sample_data(report: pytest.TestReport | pytest.CollectReport) -> bool:
    longrepr = report.longrepr
    text = longrepr[2] if isinstance(longrepr, tuple) else str(longrepr)
    return SHARED_DATA_MISSING in text


@pytest.hookimpl(wrapper=True, tryfirst=True)
def pytest_terminal_summary(terminalreporter, exitstatus, config):  # type: ignore[no-untyped-def]
    """One line: how many tests were skipped (failed, in CI) because the sample data is missing.
    A wrapper around pytest's own summary, so that the line comes after the short test summary,
    just before the counts."""
    try:
        return (yield)
    finally:
        _sample_data_line(terminalreporter)


def _sample_data_line(terminalreporter) -> None:  # type: ignore[no-untyped-def]
    reason = shared_data_missing_reason()
    if reason is None:
        return
    # In CI a fixture that fails is counted as an error, a test body that fails as a failure.
    what, kinds = ("failed", ("failed", "error")) if in_ci() else ("skipped", ("skipped",))
    count = sum(1 for kind in kinds for report in terminalreporter.stats.get(kind, [])
                if _for_want_of_sample_data(report))
    if count:
        tests = "test" if count == 1 else "tests"
        terminalreporter.write_line(f"qtanimator: {count} {tests} {what}: {reason}")


@pytest.fixture(autouse=True)
def dialog_log(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> list[tuple[str, str]]:
    """Modal message boxes never block a test: questions answer Discard, and messages
    (critical / warning / information) are recorded here as (title, text) instead."""
    log: list[tuple[str, str]] = []
    if "qtbot" not in request.fixturenames and "qapp" not in request.fixturenames:
        return log
    from PySide6.QtWidgets import QMessageBox

    def record(_parent, title, text, *args, **kwargs):  # type: ignore[no-untyped-def]
        log.append((str(title), str(text)))
        return QMessageBox.StandardButton.Ok

    monkeypatch.setattr(QMessageBox, "critical", staticmethod(record))
    monkeypatch.setattr(QMessageBox, "warning", staticmethod(record))
    monkeypatch.setattr(QMessageBox, "information", staticmethod(record))
    monkeypatch.setattr(QMessageBox, "question",
                        staticmethod(lambda *a, **k: QMessageBox.StandardButton.Discard))
    return log
