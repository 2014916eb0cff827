"""JSON projects: a versioned schema with asset files referenced by relative path.

::

    {
      "format": "qtanimator-project",
      "version": 1,
      "parameters": {"fps": 60.0, "frame_start": 0, "frame_end": 240, ...},
      "assets": [{"id": "clock", "kind": "character2d", "source": "clock.svg",
                  "properties": {...}}, ...],
      "channels": {"clock/pendulum/angle": {"pre": "constant", "post": "constant",
                                            "keys": [{"t": 0.0, "v": 0.5, "in": "smooth",
                                                      "out": "smooth"}]}}
    }

Asset ``source`` paths and asset properties whose name ends in ``_file`` are stored
relative to the project file and made absolute on load. This module knows the schema only;
:mod:`qtanimator.document.io` turns a :class:`ProjectData` into a live document and back.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from qtanimator.core.channel import Channel
from qtanimator.formats._tokens import read_bytes
from qtanimator.formats.atomic import write_text_atomic
from qtanimator.formats.errors import FormatError

FORMAT_NAME = "qtanimator-project"
FORMAT_VERSION = 1


@dataclass
class AssetRecord:
    id: str
    kind: str
    source: str | None = None  # absolute once loaded
    properties: dict[str, Any] = field(default_factory=dict)


@dataclass
class ProjectData:
    parameters: dict[str, Any] = field(default_factory=dict)
    assets: list[AssetRecord] = field(default_factory=list)
    channels: dict[str, Channel] = field(default_factory=dict)
    #: View state (e.g. the 3D camera): saved with the project, but not authored content.
    view: dict[str, Any] = field(default_factory=dict)


def project_to_json(data: ProjectData, base_dir: str | os.PathLike[str]) -> str:
    """Serialise deterministically: save, load, save gives identical bytes."""
    base = Path(base_dir).resolve()
    assets = []
    for a in data.assets:
        source = a.source
        if source is not None:
            source = _relative(Path(source), base)
        props = {k: (_relative(Path(v), base) if _is_path_key(k, v) else v) for k, v in a.properties.items()}
        assets.append({"id": a.id, "kind": a.kind, "source": source, "properties": props})
    doc = {
        "format": FORMAT_NAME,
        "version": FORMAT_VERSION,
        "parameters": data.parameters,
        "assets": assets,
        "channels": {cid: ch.to_dict() for cid, ch in data.channels.items()},
    }
    if data.view:
        doc["view"] = data.view
    try:
        return json.dumps(doc, indent=2, allow_nan=False, ensure_ascii=False) + "\n"
    except (TypeError, ValueError) as exc:  # NaN, infinity or a non-JSON object in the parameters
        raise ValueError(f"the project holds a value JSON cannot store: {exc}") from exc


def _is_path_key(key: str, value: Any) -> bool:
    """Asset properties named ``*_file`` hold file paths, saved relative to the project."""
    return key.endswith("_file") and isinstance(value, str) and bool(value)


def _relative(path: Path, base: Path) -> str:
    try:
        return Path(os.path.relpath(path.resolve(), base)).as_posix()
    except ValueError:  # another drive on Windows
        return path.resolve().as_posix()


def save_project(data: Any, path: str | os.PathLike[str]) -> None:
    """Save atomically. ``data`` is a :class:`ProjectData` or has ``to_project_data()``."""
    if not isinstance(data, ProjectData):
        data = data.to_project_data()
    target = Path(path)
    write_text_atomic(target, project_to_json(data, target.parent))


def load_project(path: str | os.PathLike[str]) -> ProjectData:
    """Read a project file. Raises FormatError, never anything else, on bad input."""
    p = Path(path)
    raw = read_bytes(p)
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise FormatError("the file is not UTF-8 text, so it is not a qtanimator project.", p) from exc
    return parse_project(text, p)


def parse_project(text: str, path: str | os.PathLike[str]) -> ProjectData:
    p = Path(path)
    try:
        obj = json.loads(text, parse_constant=_reject_constant, parse_float=_parse_float)
    except json.JSONDecodeError as exc:
        raise FormatError(f"the file is not valid JSON ({exc.msg}); it may be truncated.",
                          p, exc.lineno, exc.colno) from exc
    except ValueError as exc:
        raise FormatError(str(exc), p) from exc
    except RecursionError as exc:
        raise FormatError("the JSON is nested too deeply.", p) from exc
    if not isinstance(obj, dict) or obj.get("format") != FORMAT_NAME:
        raise FormatError("this is JSON but not a qtanimator project (no \"format\": "
                          f"\"{FORMAT_NAME}\").", p)
    version = obj.get("version")
    if not isinstance(version, int) or isinstance(version, bool):
        raise FormatError("the project has no version number.", p)
    if version > FORMAT_VERSION:
        raise FormatError(f"the project was written by a newer qtanimator (format version {version}; "
                          f"this one reads up to {FORMAT_VERSION}). Update qtanimator to open it.", p)
    if version < 1:
        raise FormatError(f"unknown project format version {version}.", p)
    base = p.resolve().parent
    data = ProjectData()
    params = obj.get("parameters", {})
    if not isinstance(params, dict):
        raise FormatError("\"parameters\" must be an object.", p)
    _check_parameters(params, p)
    data.parameters = params
    view = obj.get("view", {})
    if not isinstance(view, dict):
        raise FormatError("\"view\" must be an object.", p)
    _check_parameters(view, p)
    data.view = view
    assets = obj.get("assets", [])
    if not isinstance(assets, list):
        raise FormatError("\"assets\" must be a list.", p)
    seen: set[str] = set()
    for i, a in enumerate(assets):
        if not isinstance(a, dict) or not isinstance(a.get("id"), str) or not isinstance(a.get("kind"), str):
            raise FormatError(f"asset {i + 1} needs a text \"id\" and \"kind\".", p)
        if a["id"] in seen or not a["id"] or "/" in a["id"]:
            raise FormatError(f"asset id {a['id']!r} is empty, repeated or contains '/'.", p)
        seen.add(a["id"])
        source = a.get("source")
        if source is not None and not isinstance(source, str):
            raise FormatError(f"asset {a['id']!r}: \"source\" must be a path.", p)
        props = a.get("properties", {})
        if not isinstance(props, dict):
            raise FormatError(f"asset {a['id']!r}: \"properties\" must be an object.", p)
        abs_source = _absolute(base, source, p) if source else None
        props = {k: (_absolute(base, v, p) if _is_path_key(k, v) else v) for k, v in props.items()}
        data.assets.append(AssetRecord(a["id"], a["kind"], abs_source, props))
    channels = obj.get("channels", {})
    if not isinstance(channels, dict):
        raise FormatError("\"channels\" must be an object.", p)
    for cid, ch in channels.items():
        if cid.count("/") < 2 or not isinstance(ch, dict):
            raise FormatError(f"channel {cid!r} is not of the form asset/joint/dof with an object value.", p)
        try:
            data.channels[cid] = _channel_from_json(ch)
        except (KeyError, TypeError, ValueError, OverflowError) as exc:
            raise FormatError(f"channel {cid!r} is malformed: {exc}.", p) from exc
    return data


def _absolute(base: Path, relative: str, p: Path) -> str:
    try:
        return str((base / relative).resolve())
    except (OSError, ValueError, RuntimeError) as exc:  # NUL bytes, symlink loops
        raise FormatError(f"the asset path {relative!r} is not a usable path ({exc}).", p) from exc


def _check_parameters(params: dict[str, Any], p: Path) -> None:
    """The parameters every document relies on must make sense."""
    fps = params.get("fps", 60.0)
    if isinstance(fps, bool) or not isinstance(fps, (int, float)) or not 0 < fps <= 10000:
        raise FormatError(f"\"fps\" must be a positive number of frames per second, not {fps!r}.", p)
    for name in ("frame_start", "frame_end"):
        value = params.get(name, 0)
        if isinstance(value, bool) or not isinstance(value, int) or abs(value) > 10**9:
            raise FormatError(f"\"{name}\" must be a whole frame number, not {value!r}.", p)


def _parse_float(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(f"the number {text} is too large for a project.")
    return value


def _channel_from_json(d: dict[str, Any]) -> Channel:
    keys = d.get("keys", [])
    if not isinstance(keys, list) or not all(isinstance(k, dict) for k in keys):
        raise ValueError("\"keys\" must be a list of objects")
    for k in keys:
        for name in ("t", "v"):
            value = k[name]
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ValueError(f"key field {name!r} must be a finite number")
    return Channel.from_dict(d)


def _reject_constant(name: str) -> Any:
    raise ValueError(f"the file contains {name}, which is not a number a project may hold.")
