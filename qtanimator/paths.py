"""Where the bundled resources and scenes are, in a checkout and in an installed wheel."""

from __future__ import annotations

import os
from pathlib import Path

_PACKAGE = Path(__file__).resolve().parent


def _first_existing(*candidates: Path) -> Path:
    for c in candidates:
        if c.exists():
            return c
    return candidates[-1]


def resources_dir() -> Path:
    return _first_existing(_PACKAGE / "resources", _PACKAGE.parent / "resources")


def scenes_dir() -> Path:
    return _first_existing(_PACKAGE / "scenes", _PACKAGE.parent / "scenes")


def sample_dirs() -> list[Path]:
    """The folders of bundled sample scenes: the installed package's ``qtanimator/scenes``
    and, in a checkout, the repository's ``scenes/`` (resolved; only those that exist)."""
    candidates = [_PACKAGE / "scenes"]
    if (_PACKAGE.parent / "pyproject.toml").is_file():  # a checkout, not site-packages
        candidates.append(_PACKAGE.parent / "scenes")
    return [c.resolve() for c in candidates if c.is_dir()]


def is_sample(path: str | os.PathLike[str]) -> bool:
    """True for a file or folder inside a bundled samples folder (:func:`sample_dirs`):
    the program opens such a project as an untitled copy and never writes into it."""
    try:
        resolved = Path(path).resolve()
    except (OSError, RuntimeError, ValueError):
        return False
    return any(resolved.is_relative_to(folder) for folder in sample_dirs())


def shader_path(name: str) -> Path:
    return resources_dir() / "shaders" / name


def demo_project() -> Path:
    """The project ``qtanimator`` opens when started with no argument."""
    return scenes_dir() / "demo" / "demo.qtanim"


def docs_dir() -> Path:
    """The user documentation (user guide, keyboard reference, formats) with its pictures."""
    return _first_existing(_PACKAGE / "docs", _PACKAGE.parent / "docs")


def desktop_dir() -> Path:
    """The icon, ``.desktop`` entry, AppStream metainfo and MIME type (``resources/desktop``)."""
    return resources_dir() / "desktop"


#: The application id: the ``.desktop`` file's name, the icon's name, the AppStream id.
APP_ID = "io.github.qtanimator.qtanimator"


def app_icon_path() -> Path:
    return desktop_dir() / f"{APP_ID}.svg"
