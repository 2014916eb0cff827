"""Shared fixtures for widget tests."""

from __future__ import annotations

from collections.abc import Callable, Collection

import pytest

from qtanimator.ui.main_window import MainWindow

#: The application editors of issue 6 (the 2D animator), installed by default in its tests.
ANIMATOR_EDITORS = ("rig_editor", "timeline", "joint_tree", "properties", "export_dialog", "recovery")


@pytest.fixture(autouse=True)
def first_run_layout() -> None:
    """Every widget test opens its windows as a first run: the window and dock layout a
    previous test's window saved on closing would otherwise be restored (after a dope-sheet
    test the 2D view of a 1200x800 window was 105 px tall and IK drags missed their targets)."""
    from qtanimator.ui.app_settings import settings

    s = settings()
    s.remove("window/geometry")
    s.remove("window/state")
    s.sync()


@pytest.fixture
def make_window(qtbot) -> Callable[..., MainWindow]:  # type: ignore[no-untyped-def]
    """Build a real, shown main window: ``make_window(full=False, editors=ANIMATOR_EDITORS,
    size=(1200, 800), active=True)``. ``full`` installs every editor."""

    def build(full: bool = False, editors: Collection[str] = ANIMATOR_EDITORS,
              size: tuple[int, int] | None = (1200, 800), active: bool = True) -> MainWindow:
        window = MainWindow(install_editors=True if full else editors)
        qtbot.addWidget(window)
        if size is not None:
            window.resize(*size)
        window.show()
        qtbot.waitExposed(window)
        if active:
            window.activateWindow()
            qtbot.waitUntil(window.isActiveWindow)
        return window

    return build
