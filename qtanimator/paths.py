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
