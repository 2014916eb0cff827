"""Where the bundled resources and scenes are, in a checkout and in an installed wheel."""

from __future__ import annotations

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
