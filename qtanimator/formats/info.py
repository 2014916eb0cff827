"""``qtanimator info``: a short summary of any file qtanimator reads.

Each format module has a summariser for its suffixes; the summary is plain JSON data.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from pathlib import Path
from typing import Any

from qtanimator.formats.errors import FormatError

Summariser = Callable[[Path], dict[str, Any]]

#: suffix -> (module, function name); imported only when needed.
SUMMARISERS: dict[str, tuple[str, str]] = {
    ".qtanim": ("qtanimator.formats.info", "summarize_project"),
    ".json": ("qtanimator.formats.info", "summarize_json"),
    ".anim": ("qtanimator.formats.anim", "summarize"),
    ".svg": ("qtanimator.formats.svg_rig", "summarize"),
    ".skel": ("qtanimator.formats.skel", "summarize"),
    ".skin": ("qtanimator.formats.skin", "summarize"),
    ".obj": ("qtanimator.formats.obj", "summarize"),
    ".attach": ("qtanimator.formats.attach", "summarize"),
    ".morph": ("qtanimator.formats.morph", "summarize"),
    ".bvh": ("qtanimator.formats.bvh", "summarize"),
    ".glb": ("qtanimator.formats.gltf", "summarize"),
    ".gltf": ("qtanimator.formats.gltf", "summarize"),
}


def summarize(path: Path) -> dict[str, Any]:
    if not path.exists():
        raise FormatError("no such file or folder.", path)
    suffix = "/" if path.is_dir() else path.suffix.lower()
    if suffix == "/":
        suffix = ".svg"
    entry = SUMMARISERS.get(suffix)
    if entry is None:
        raise FormatError(f"qtanimator does not read '{path.suffix}' files.", path)
    fn: Summariser = getattr(importlib.import_module(entry[0]), entry[1])
    return fn(path)


def channel_summary(channels: dict[str, Any]) -> dict[str, Any]:
    """Counts and time range of a set of channels (``Channel`` objects by name)."""
    keys = sum(len(ch.keys) for ch in channels.values())
    times = [k.time for ch in channels.values() for k in ch.keys]
    return {
        "channels": len(channels),
        "keys": keys,
        "key_time_range": [min(times), max(times)] if times else None,
    }


def summarize_json(path: Path) -> dict[str, Any]:
    """A ``.json`` file: a Spine skeleton when it looks like one, else a project."""
    from qtanimator.formats.spine import looks_like_spine
    from qtanimator.formats.spine import summarize as summarize_spine

    if looks_like_spine(path):
        return summarize_spine(path)
    return summarize_project(path)


def summarize_project(path: Path) -> dict[str, Any]:
    from qtanimator.formats.project import load_project

    data = load_project(path)
    out: dict[str, Any] = {"file": str(path), "kind": "qtanimator project"}
    out["assets"] = [{"id": a.id, "kind": a.kind, "source": a.source} for a in data.assets]
    out.update(channel_summary(data.channels))
    out["parameters"] = data.parameters
    return out
