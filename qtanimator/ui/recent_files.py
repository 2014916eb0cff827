"""File ▸ Open Recent: the last projects and files opened or saved, kept in the settings."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from PySide6.QtWidgets import QMenu

from qtanimator.ui.app_settings import settings

MAX_RECENT = 10


class RecentFiles:
    """The recent-files list (newest first, at most :data:`MAX_RECENT`) and its menu, whose
    entries call ``open_path``."""

    def __init__(self, menu: QMenu, open_path: Callable[[str], object]) -> None:
        self.menu = menu
        self._open = open_path
        self.refresh_menu()

    def paths(self) -> list[str]:
        value = settings().value("recentFiles", [])
        if isinstance(value, str):
            value = [value]
        if not isinstance(value, (list, tuple)):
            return []  # nothing stored (an empty list reads back as None)
        return [str(v) for v in value]

    def remember(self, path: Path) -> None:
        """``path`` goes to the top of the list, and its folder becomes the last folder."""
        s = settings()
        full = str(path.resolve())
        recent = [full] + [r for r in self.paths() if r != full]
        s.setValue("recentFiles", recent[:MAX_RECENT])
        s.setValue("lastDir", str(path.resolve().parent))
        self.refresh_menu()

    def forget_if_gone(self, path: Path) -> None:
        """A recent file that no longer exists leaves the list."""
        if path.exists():
            return
        full = str(path.resolve())
        recent = self.paths()
        if full in recent:
            settings().setValue("recentFiles", [r for r in recent if r != full])
            self.refresh_menu()

    def refresh_menu(self) -> None:
        self.menu.clear()
        paths = self.paths()
        for path in paths:
            action = self.menu.addAction(Path(path).name)
            action.setToolTip(path)
            action.triggered.connect(lambda _c=False, p=path: self._open(p))
        self.menu.setEnabled(bool(paths))
