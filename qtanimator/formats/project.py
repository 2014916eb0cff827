"""JSON projects: a versioned schema with asset files referenced by relative path.

::

    {
      "format": "qtanimator-project",
      "version": 2,
      "parameters": {"fps": 60.0, "frame_start": 0, "frame_end": 240, ...},
      "assets": [{"id": "clock", "kind": "character2d", "source": "clock.svg",
                  "properties": {...}}, ...],
      "channels": {
        "clock/pendulum/angle": {
          "pre": "constant",
          "post": "constant",
          "in": "smooth",
          "out": "smooth",
          "times": [0.0, 0.5, 1.0],
          "values": [0.5, -0.5, 0.5]
        }
      }
    }

A channel's keys are columns (version 2): ``times`` and ``values``, and the tangent rules
``in`` / ``out`` (a rule name or a fixed slope), the span shape ``interp`` (left out when
cubic) and ``broken`` (left out when false), each written once when every key shares it
and as one entry per key otherwise. Handle lengths of weighted tangents (issue 13) are the
columns ``in_weight`` / ``out_weight`` (seconds; ``null`` for a key without one), written
only when some key of the channel has one, so a project without weights is written exactly
as before; the Kochanek–Bartels columns ``tension`` / ``continuity`` / ``bias`` (issue 18)
likewise only when some key has one that is not 0. Number columns are written
:data:`NUMBERS_PER_LINE` to a line. Version 1 wrote
one object per key, ``"keys": [{"t": 0.0, "v": 0.5, "in": "smooth", "out": "smooth"},
...]``; that form is still read.

Asset ``source`` paths and asset properties whose name ends in ``_file`` are stored
relative to the project file and made absolute on load. This module knows the schema only;
:mod:`qtanimator.document.io` turns a :class:`ProjectData` into a live document and back.

A path that leads out of the project folder is listed in the asset's ``"outside"`` (the
keys: ``"source"`` or a property name), written only when there is one. Every path in a
document is there by the user's choice (a file opened or dropped, a missing file located,
Save As without Collect Assets), so the writer records those choices; the reader keeps the
list (:attr:`AssetRecord.outside`) so that a reader confined to the project folder (issue 19)
can allow exactly these and refuse any other path out of the folder. Older readers ignore
the field, so it needs no new format version.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from qtanimator.core.channel import Channel
from qtanimator.core.keys import bounds_problem
from qtanimator.formats._tokens import read_bytes
from qtanimator.formats.atomic import write_chunks_atomic
from qtanimator.formats.errors import FormatError

FORMAT_NAME = "qtanimator-project"
FORMAT_VERSION = 2

#: How many numbers a line of a ``times`` / ``values`` column holds.
NUMBERS_PER_LINE = 10


@dataclass
class AssetRecord:
    id: str
    kind: str
    source: str | None = None  # absolute once loaded
    properties: dict[str, Any] = field(default_factory=dict)
    #: The references (``"source"`` or ``*_file`` property names) the project recorded as
    #: leading out of its folder by the user's choice (read from the file; the writer
    #: computes it afresh).
    outside: list[str] = field(default_factory=list)


@dataclass
class ProjectData:
    parameters: dict[str, Any] = field(default_factory=dict)
    assets: list[AssetRecord] = field(default_factory=list)
    channels: dict[str, Channel] = field(default_factory=dict)
    #: View state (e.g. the 3D camera): saved with the project, but not authored content.
    view: dict[str, Any] = field(default_factory=dict)


def project_to_json(data: ProjectData, base_dir: str | os.PathLike[str]) -> str:
    """Serialise deterministically: save, load, save gives identical bytes."""
    return "".join(project_json_parts(data, base_dir))


def project_json_parts(data: ProjectData, base_dir: str | os.PathLike[str]) -> Iterator[str]:
    """:func:`project_to_json` in pieces of at most a few hundred kB, so that a writer can
    stream them to disk and stop between them, and no single step of a background save
    holds the GIL for long. Raises ValueError for a value JSON cannot store.
    """
    base = Path(base_dir).resolve()
    assets = []
    for a in data.assets:
        source = a.source
        outside = []
        if source is not None:
            source = _relative(Path(source), base)
            if _leaves(source):
                outside.append("source")
        props = {k: (_relative(Path(v), base) if _is_path_key(k, v) else v) for k, v in a.properties.items()}
        outside += [k for k, v in props.items() if _is_path_key(k, v) and _leaves(v)]
        record: dict[str, Any] = {"id": a.id, "kind": a.kind, "source": source, "properties": props}
        if outside:
            record["outside"] = outside
        assets.append(record)
    yield "{\n"
    yield f'  "format": {_json(FORMAT_NAME, 1)},\n'
    yield f'  "version": {_json(FORMAT_VERSION, 1)},\n'
    yield f'  "parameters": {_json(data.parameters, 1)},\n'
    yield f'  "assets": {_json(assets, 1)},\n'
    if not data.channels:
        yield '  "channels": {}'
    else:
        yield '  "channels": {'
        sep = "\n"
        for cid, ch in data.channels.items():
            yield f"{sep}    {_INLINE.encode(cid)}: {{\n"
            yield from _channel_parts(ch)
            yield "\n    }"
            sep = ",\n"
        yield "\n  }"
    if data.view:
        yield f',\n  "view": {_json(data.view, 1)}'
    yield "\n}\n"


def _json(value: Any, level: int) -> str:
    """``json.dumps(value, indent=2)`` as it reads nested ``level`` objects deep."""
    try:
        text = json.dumps(value, indent=2, allow_nan=False, ensure_ascii=False)
    except (TypeError, ValueError) as exc:  # NaN, infinity or a non-JSON object in the parameters
        raise ValueError(f"the project holds a value JSON cannot store: {exc}") from exc
    # JSON text holds no raw newline inside a string, so every newline starts a line.
    return text.replace("\n", "\n" + "  " * level) if level else text


#: Encodes one line of a column (the C encoder: no indent).
_INLINE = json.JSONEncoder(allow_nan=False, ensure_ascii=False)
_COLUMN_INDENT = "\n" + " " * 8
_ROW_SEPARATOR = "," + _COLUMN_INDENT
#: A long column is yielded this many lines at a time.
_ROWS_PER_PART = 1000


def _channel_parts(channel: Channel) -> Iterator[str]:
    """The fields of one channel, one a line; columns wrapped, long ones in several parts."""
    sep = ""
    for name, value in channel.to_dict(columns=True).items():
        yield f"{sep}      {_INLINE.encode(name)}: "
        if isinstance(value, list):
            yield from _column_parts(value)
        else:
            yield _INLINE.encode(value)
        sep = ",\n"


def _column_parts(values: list[Any]) -> Iterator[str]:
    """A column, :data:`NUMBERS_PER_LINE` entries a line (a short one stays on its line)."""
    step = NUMBERS_PER_LINE
    if len(values) <= step:
        yield ("[" + _row_texts(values)[0] + "]") if values else "[]"
        return
    yield "[" + _COLUMN_INDENT
    block = step * _ROWS_PER_PART
    for start in range(0, len(values), block):
        text = _ROW_SEPARATOR.join(_row_texts(values[start:start + block]))
        yield text if start == 0 else _ROW_SEPARATOR + text
    yield "\n      ]"


def _row_texts(values: list[Any]) -> list[str]:
    """The lines of (part of) a column, without brackets.

    The ``times`` and ``values`` of keys are finite floats, which ``float.__repr__`` writes
    exactly as JSON does, only faster; anything else goes through the JSON encoder. Short
    lines keep each call into C short, so that a background save lets the UI thread take
    the GIL often.
    """
    step = NUMBERS_PER_LINE
    try:
        try:
            # A sum of finite floats is NaN or infinite only after an overflow (then the
            # encoder below decides); a text or None raises TypeError here, an int or a
            # bool in float.__repr__.
            if not math.isfinite(sum(values)):
                raise TypeError("not only finite numbers")
            return [", ".join(map(float.__repr__, values[i:i + step])) for i in range(0, len(values), step)]
        except TypeError:
            return [_INLINE.encode(values[i:i + step])[1:-1] for i in range(0, len(values), step)]
    except (TypeError, ValueError) as exc:  # keys are always finite; keep the reader's promise anyway
        raise ValueError(f"the project holds a value JSON cannot store: {exc}") from exc


def _is_path_key(key: str, value: Any) -> bool:
    """Asset properties named ``*_file`` hold file paths, saved relative to the project."""
    return key.endswith("_file") and isinstance(value, str) and bool(value)


def _inside(path: Path, folder: Path) -> bool:
    """True when ``path`` (after ``..`` and symbolic links) lies in ``folder``."""
    try:
        return path.resolve().is_relative_to(folder.resolve())
    except (OSError, RuntimeError, ValueError):
        return False


def _leaves(relative: str) -> bool:
    """True for a stored path that leads out of the project folder."""
    return relative == ".." or relative.startswith("../") or Path(relative).is_absolute()


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
    write_chunks_atomic(target, (json_utf8(part) for part in project_json_parts(data, target.parent)))


def json_utf8(part: str) -> bytes:
    """Part of a project's JSON text as UTF-8. A file name that is not UTF-8 (legal on
    Linux) reaches us as ``os.fsdecode`` gives it: each undecodable byte a lone surrogate
    U+DC80…U+DCFF, which UTF-8 cannot store. It is written as the JSON escape ``\\udcXX``
    (only ever inside a JSON string), which ``json.loads`` gives back as the same
    character, so ``os.fsencode`` of the loaded path yields the file's exact bytes."""
    try:
        return part.encode("utf-8")
    except UnicodeEncodeError:
        return part.encode("utf-8", "backslashreplace")


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
        outside = a.get("outside", [])
        if not isinstance(outside, list) or not all(isinstance(k, str) for k in outside):
            raise FormatError(f"asset {a['id']!r}: \"outside\" must be a list of names.", p)
        abs_source = _absolute(base, source, p) if source else None
        props = {k: (_absolute(base, v, p) if _is_path_key(k, v) else v) for k, v in props.items()}
        # Containment (issue 19): a reference out of the project folder must be one the
        # user chose, recorded in "outside"; a project cannot make us read /etc/passwd.
        refs: list[tuple[str, str, str]] = [("source", source, abs_source)] if source and abs_source else []
        refs += [(k, a.get("properties", {})[k], v) for k, v in props.items() if _is_path_key(k, v)]
        for key, stored, absolute in refs:
            if key not in outside and not _inside(Path(absolute), base):
                raise FormatError(f"asset {a['id']!r}: its {key} {stored!r} lies outside the project's folder, "
                                  "and the project does not record that file as chosen (\"outside\"). Move the "
                                  "file into the project's folder, or add it again with File ▸ Open.", p)
        _check_asset_properties(a["id"], a.get("properties", {}), p)
        data.assets.append(AssetRecord(a["id"], a["kind"], abs_source, props, list(outside)))
    channels = obj.get("channels", {})
    if not isinstance(channels, dict):
        raise FormatError("\"channels\" must be an object.", p)
    for cid, ch in channels.items():
        if cid.count("/") < 2 or not isinstance(ch, dict):
            raise FormatError(f"channel {cid!r} is not of the form asset/joint/dof with an object value.", p)
        try:
            data.channels[cid] = _check_channel_bounds(_channel_from_json(ch))
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


#: The largest ``index`` (which character of an SVG folder) a project may name.
MAX_ASSET_INDEX = 100_000


def _check_asset_properties(asset_id: str, props: dict[str, Any], p: Path) -> None:
    """Properties whose type every loader relies on: ``*_file`` names are paths (text or
    null), ``index`` a whole number from 0 to :data:`MAX_ASSET_INDEX`."""
    for name, value in props.items():
        if name.endswith("_file") and value is not None and not isinstance(value, str):
            raise FormatError(f"asset {asset_id!r}: the property \"{name}\" must be a file path (text), "
                              f"not {_kind_of(value)}.", p)
    if "index" in props:
        index = props["index"]
        if isinstance(index, bool) or not isinstance(index, int) or not 0 <= index <= MAX_ASSET_INDEX:
            raise FormatError(f"asset {asset_id!r}: the property \"index\" must be a whole number from 0 to "
                              f"{MAX_ASSET_INDEX}, not {_kind_of(index)}.", p)


def _kind_of(value: Any) -> str:
    """A short description of a JSON value for an error (never a long quote)."""
    if isinstance(value, bool) or value is None:
        return json.dumps(value)
    if isinstance(value, (int, float)):
        return repr(value) if len(repr(value)) <= 24 else "a number"
    if isinstance(value, str):
        return repr(value) if len(value) <= 24 else "a long text"
    return "a list" if isinstance(value, list) else "an object"


def _check_channel_bounds(channel: Channel) -> Channel:
    """``channel``, or ValueError naming the property unless every number of it is one the
    views and the evaluation can use (:func:`qtanimator.core.keys.bounds_problem`;
    docs/formats.md, "Projects")."""
    problem = bounds_problem(channel.keys)
    if problem is not None:
        raise ValueError(problem)
    return channel


def _parse_float(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(f"the number {text} is too large for a project.")
    return value


def _channel_from_json(d: dict[str, Any]) -> Channel:
    if "times" in d or "values" in d:  # format 2: columns
        for name in ("times", "values"):
            column = d[name]
            if not isinstance(column, list) or not all(_is_finite_number(x) for x in column):
                raise ValueError(f"\"{name}\" must be a list of finite numbers")
        return Channel.from_dict(d)
    keys = d.get("keys", [])
    if not isinstance(keys, list) or not all(isinstance(k, dict) for k in keys):
        raise ValueError("\"keys\" must be a list of objects")
    for k in keys:
        for name in ("t", "v"):
            if not _is_finite_number(k[name]):
                raise ValueError(f"key field {name!r} must be a finite number")
    return Channel.from_dict(d)


def _is_finite_number(value: Any) -> bool:
    return not isinstance(value, bool) and isinstance(value, (int, float)) and math.isfinite(value)


def _reject_constant(name: str) -> Any:
    raise ValueError(f"the file contains {name}, which is not a number a project may hold.")
