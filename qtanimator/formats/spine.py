"""Spine JSON skeleton data (Spine 4.x "JSON export format"): the bones and the bone
animation timelines, free of Qt (issue 15, item 7: re-import what
:mod:`qtanimator.document.spine_export` writes, or a Spine editor's export).

What is read:

* ``bones``: name, parent, ``x``, ``y``, ``rotation``, ``scaleX``, ``scaleY``, ``shearX``,
  ``shearY``, ``length`` (Spine's defaults for missing fields), in file order; the first bone
  is the root and every other bone's parent is a bone before it;
* per animation, per bone, the ``rotate``, ``translate``, ``translatex`` and ``translatey``
  timelines: keys with ``time`` (seconds, default 0), ``value`` (degrees, or units for
  ``translatex`` / ``translatey``) or ``x`` / ``y`` (default 0) and ``curve``. Other bone
  timelines (scale, shear, inherit) and the other parts of the file (slots, skins,
  constraints, events) are listed as ignored but not read.

Values are Spine's: y up, degrees counter-clockwise, and a timeline's value is an offset from
the bone's setup pose (``rotation = setup rotation + value``, ``x = setup x + x``), as the
runtimes apply it. Curves: no curve is linear, ``"stepped"`` holds the key's value until the
next key, and a list is a cubic Bézier per value, four numbers each ``[cx1, cy1, cx2, cy2]``
(a translate key's list holds eight, x's then y's): control points in absolute time and value
between the key ``(t1, v1)`` and the next ``(t2, v2)``. :meth:`SpineTimeline.evaluate` solves
that Bézier exactly (the value at the parameter whose time is ``t``); Spine's runtimes
approximate the same curve by ten straight segments. Before its first key a timeline shows
the setup pose (offset 0), after its last key the last key's value.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from qtanimator.formats._tokens import read_bytes
from qtanimator.formats.errors import FormatError

#: The bone timelines read, and the value fields of their keys.
TIMELINE_FIELDS: dict[str, tuple[str, ...]] = {
    "rotate": ("value",),
    "translate": ("x", "y"),
    "translatex": ("value",),
    "translatey": ("value",),
}
#: Curve kinds of a key (the span from it to the next key).
LINEAR, STEPPED, BEZIER = "linear", "stepped", "bezier"
#: Bisection / Newton iterations solving a Bézier span's time for its parameter.
_SOLVE_ITERATIONS = 100


@dataclass(frozen=True)
class SpineBone:
    """One bone's setup pose (Spine's units: y up, degrees)."""

    name: str
    parent: str | None
    x: float = 0.0
    y: float = 0.0
    rotation: float = 0.0
    scale_x: float = 1.0
    scale_y: float = 1.0
    shear_x: float = 0.0
    shear_y: float = 0.0
    length: float = 0.0

    def local_matrix(self, rotate: float = 0.0, dx: float = 0.0, dy: float = 0.0) -> list[list[float]]:
        """The bone's 3×3 local transform (y up) with a timeline's rotation offset ``rotate``
        (degrees) and translation offset ``(dx, dy)``: Spine's ``a = cos(r + shX)·sX``,
        ``b = cos(r + 90 + shY)·sY``, ``c = sin(r + shX)·sX``, ``d = sin(r + 90 + shY)·sY``."""
        r = self.rotation + rotate
        rx, ry = math.radians(r + self.shear_x), math.radians(r + 90.0 + self.shear_y)
        return [[math.cos(rx) * self.scale_x, math.cos(ry) * self.scale_y, self.x + dx],
                [math.sin(rx) * self.scale_x, math.sin(ry) * self.scale_y, self.y + dy],
                [0.0, 0.0, 1.0]]


@dataclass(frozen=True)
class SpineKey:
    """One key: its time (seconds), its values (one, or x and y) and the curve of the span
    that starts at it. ``bezier`` holds ``(cx1, cy1, cx2, cy2)`` per value when ``curve`` is
    :data:`BEZIER`."""

    time: float
    values: tuple[float, ...]
    curve: str = LINEAR
    bezier: tuple[tuple[float, float, float, float], ...] = ()


@dataclass(frozen=True)
class SpineTimeline:
    """One bone timeline (``rotate``, ``translate``, ``translatex`` or ``translatey``)."""

    kind: str
    keys: tuple[SpineKey, ...]

    @property
    def fields(self) -> tuple[str, ...]:
        return TIMELINE_FIELDS[self.kind]

    def evaluate(self, t: float) -> tuple[float, ...]:
        """The timeline's values (offsets from the setup pose) at time ``t``."""
        keys = self.keys
        n = len(self.fields)
        if not keys or t < keys[0].time:
            return (0.0,) * n
        # The last key at or before t (Spine's search: a later key at the same time wins).
        lo, hi = 0, len(keys)
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if keys[mid].time <= t:
                lo = mid
            else:
                hi = mid
        a = keys[lo]
        if lo == len(keys) - 1 or a.curve == STEPPED:
            return a.values
        b = keys[lo + 1]
        if a.curve == BEZIER:
            return tuple(bezier_value(t, a.time, a.values[i], *a.bezier[i], b.time, b.values[i]) for i in range(n))
        u = (t - a.time) / (b.time - a.time)
        return tuple(va + u * (vb - va) for va, vb in zip(a.values, b.values))


@dataclass(frozen=True)
class SpineAnimation:
    """One animation: the timelines read, by bone name then kind, and the ones ignored
    (``"bone/kind"`` for bone timelines, the section name for other sections)."""

    name: str
    bones: dict[str, dict[str, SpineTimeline]]
    ignored: tuple[str, ...] = ()

    @property
    def duration(self) -> float:
        """The last key time of the timelines read (0 without keys)."""
        return max((tl.keys[-1].time for tls in self.bones.values() for tl in tls.values() if tl.keys),
                   default=0.0)


@dataclass(frozen=True)
class SpineData:
    """A Spine skeleton file: its version, the editor's frame rate (``skeleton.fps``, 30 by
    default: only the dopesheet's; key times are seconds), the bones in file order and the
    animations in file order."""

    path: str
    version: str | None
    fps: float
    bones: tuple[SpineBone, ...]
    animations: dict[str, SpineAnimation] = field(default_factory=dict)

    def bone(self, name: str) -> SpineBone | None:
        return next((b for b in self.bones if b.name == name), None)

    def ancestors(self, name: str) -> list[SpineBone]:
        """The bones above ``name``, its parent first."""
        out: list[SpineBone] = []
        b = self.bone(name)
        while b is not None and b.parent is not None:
            b = self.bone(b.parent)
            if b is not None:
                out.append(b)
        return out


# --------------------------------------------------------------------------- Bézier spans
def bezier_value(t: float, t1: float, v1: float, cx1: float, cy1: float, cx2: float, cy2: float,
                 t2: float, v2: float) -> float:
    """A Spine Bézier span's value at time ``t``: the cubic Bézier through ``(t1, v1)``,
    ``(cx1, cy1)``, ``(cx2, cy2)``, ``(t2, v2)`` in (time, value), at the parameter whose time
    is ``t`` (solved to full precision; handle times are kept within the span, as the editor
    keeps them)."""
    span = t2 - t1
    if not span > 0.0:
        return v2
    x1 = min(max(cx1 - t1, 0.0), span)
    x2 = min(max(cx2 - t1, 0.0), span)
    u = bezier_parameter(t - t1, x1, x2, span)
    w = 1.0 - u
    return w * w * w * v1 + 3.0 * w * w * u * cy1 + 3.0 * w * u * u * cy2 + u * u * u * v2


def bezier_parameter(x: float, x1: float, x2: float, span: float) -> float:
    """The parameter ``u`` in [0, 1] where the Bézier ``0, x1, x2, span`` reaches ``x``
    (Newton inside a shrinking bracket, bisection when a step leaves it)."""
    if not x > 0.0:
        return 0.0
    if not x < span:
        return 1.0
    lo, hi = 0.0, 1.0
    u = x / span
    for _ in range(_SOLVE_ITERATIONS):
        w = 1.0 - u
        f = 3.0 * w * w * u * x1 + 3.0 * w * u * u * x2 + u * u * u * span - x
        if f == 0.0:
            return u
        if f > 0.0:
            hi = u
        else:
            lo = u
        d = 3.0 * w * w * x1 + 6.0 * w * u * (x2 - x1) + 3.0 * u * u * (span - x2)
        nxt = u - f / d if d > 0.0 else -1.0
        if not lo < nxt < hi:
            nxt = 0.5 * (lo + hi)
        if abs(nxt - u) <= 1e-16:
            return nxt
        u = nxt
    return u


# --------------------------------------------------------------------------- reading
def _reject_constant(name: str) -> Any:
    raise ValueError(f"the file contains {name}, which is not a number")


def _load_json(path: Path) -> Any:
    raw = read_bytes(path)
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise FormatError("the file is not UTF-8 text, so it is not Spine JSON.", path) from exc
    try:
        return json.loads(text, parse_constant=_reject_constant)
    except json.JSONDecodeError as exc:
        raise FormatError(f"the file is not valid JSON ({exc.msg}).", path, exc.lineno, exc.colno) from exc
    except ValueError as exc:
        raise FormatError(f"{exc}.", path) from exc
    except RecursionError as exc:
        raise FormatError("the JSON is nested too deeply.", path) from exc


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _number(obj: dict[str, Any], key: str, default: float, where: str, path: Path) -> float:
    v = obj.get(key, default)
    if not _is_number(v):
        raise FormatError(f"{where}: \"{key}\" must be a number, not {json.dumps(v)[:40]}.", path)
    return float(v)


def _bones(obj: dict[str, Any], path: Path) -> tuple[SpineBone, ...]:
    bones = obj.get("bones")
    if bones is None:
        raise FormatError("the file has no \"bones\" list, so it is not a Spine skeleton.", path)
    if not isinstance(bones, list) or not bones:
        raise FormatError("\"bones\" must be a list of at least one bone.", path)
    out: list[SpineBone] = []
    seen: set[str] = set()
    for i, b in enumerate(bones):
        if not isinstance(b, dict):
            raise FormatError(f"bone {i + 1} is not an object.", path)
        name = b.get("name")
        if not isinstance(name, str) or not name:
            raise FormatError(f"bone {i + 1} has no name.", path)
        where = f"bone {i + 1} ('{name}')"
        if name in seen:
            raise FormatError(f"{where}: another bone before it has the same name.", path)
        parent = b.get("parent")
        if parent is not None:
            if not isinstance(parent, str):
                raise FormatError(f"{where}: \"parent\" must be a bone name.", path)
            if parent not in seen:
                later = any(isinstance(o, dict) and o.get("name") == parent for o in bones[i + 1:])
                raise FormatError(f"{where} has the parent '{parent}', which "
                                  + ("comes after it; a parent must come before its children."
                                     if later else "is not a bone of the skeleton."), path)
        elif i > 0:
            raise FormatError(f"{where} has no parent; only the first bone may be the root.", path)
        out.append(SpineBone(
            name, parent,
            x=_number(b, "x", 0.0, where, path), y=_number(b, "y", 0.0, where, path),
            rotation=_number(b, "rotation", 0.0, where, path),
            scale_x=_number(b, "scaleX", 1.0, where, path), scale_y=_number(b, "scaleY", 1.0, where, path),
            shear_x=_number(b, "shearX", 0.0, where, path), shear_y=_number(b, "shearY", 0.0, where, path),
            length=_number(b, "length", 0.0, where, path)))
        seen.add(name)
    return tuple(out)


def _timeline(keys: Any, kind: str, where: str, path: Path) -> SpineTimeline:
    if not isinstance(keys, list):
        raise FormatError(f"{where} must be a list of keys.", path)
    fields = TIMELINE_FIELDS[kind]
    out: list[SpineKey] = []
    for i, k in enumerate(keys):
        kw = f"{where}, key {i + 1}"
        if not isinstance(k, dict):
            raise FormatError(f"{kw} is not an object.", path)
        time = _number(k, "time", 0.0, kw, path)
        if time < 0.0:
            raise FormatError(f"{kw}: the time {time:g} is negative.", path)
        if out and time < out[-1].time:
            raise FormatError(f"{kw}: the time {time:g} comes before the previous key's "
                              f"{out[-1].time:g}; key times must be in order.", path)
        values = tuple(_number(k, f, 0.0, kw, path) for f in fields)
        curve = k.get("curve")
        if curve is None or curve == LINEAR:
            out.append(SpineKey(time, values))
        elif curve == STEPPED:
            out.append(SpineKey(time, values, STEPPED))
        elif isinstance(curve, list):
            need = 4 * len(fields)
            if len(curve) < need or not all(_is_number(c) for c in curve[:need]):
                raise FormatError(f"{kw}: a Bézier \"curve\" needs {need} numbers "
                                  "(cx1, cy1, cx2, cy2 per value).", path)
            c = [float(v) for v in curve[:need]]
            handles = tuple((c[4 * j], c[4 * j + 1], c[4 * j + 2], c[4 * j + 3]) for j in range(len(fields)))
            out.append(SpineKey(time, values, BEZIER, handles))
        else:
            raise FormatError(f"{kw}: \"curve\" must be \"stepped\" or a list of numbers, "
                              f"not {json.dumps(curve)[:40]}.", path)
    return SpineTimeline(kind, tuple(out))


def _animations(obj: dict[str, Any], bones: tuple[SpineBone, ...], path: Path) -> dict[str, SpineAnimation]:
    anims = obj.get("animations", {})
    if not isinstance(anims, dict):
        raise FormatError("\"animations\" must be an object of animations by name.", path)
    names = {b.name for b in bones}
    out: dict[str, SpineAnimation] = {}
    for name, anim in anims.items():
        if not isinstance(anim, dict):
            raise FormatError(f"animation '{name}' is not an object.", path)
        ignored = [k for k in anim if k != "bones"]
        timelines: dict[str, dict[str, SpineTimeline]] = {}
        by_bone = anim.get("bones", {})
        if not isinstance(by_bone, dict):
            raise FormatError(f"animation '{name}': \"bones\" must be an object of timelines by bone.", path)
        for bone, tls in by_bone.items():
            if bone not in names:
                raise FormatError(f"animation '{name}' animates the bone '{bone}', which the skeleton "
                                  "does not have.", path)
            if not isinstance(tls, dict):
                raise FormatError(f"animation '{name}', bone '{bone}': the timelines must be an object.", path)
            for kind, keys in tls.items():
                if kind in TIMELINE_FIELDS:
                    tl = _timeline(keys, kind, f"animation '{name}', bone '{bone}', {kind}", path)
                    timelines.setdefault(bone, {})[kind] = tl
                else:
                    ignored.append(f"{bone}/{kind}")
        out[name] = SpineAnimation(name, timelines, tuple(ignored))
    return out


def read_spine(path: str | os.PathLike[str]) -> SpineData:
    """Read a Spine 4.x JSON skeleton's bones and bone animations. Raises FormatError
    (never anything else) on bad input."""
    p = Path(path)
    obj = _load_json(p)
    if not isinstance(obj, dict):
        raise FormatError("the JSON is not an object, so it is not a Spine skeleton.", p)
    sk = obj.get("skeleton", {})
    if not isinstance(sk, dict):
        raise FormatError("\"skeleton\" must be an object.", p)
    version = sk.get("spine")
    if version is not None and not isinstance(version, str):
        raise FormatError("\"skeleton\".\"spine\" must be a version text such as \"4.1.24\".", p)
    major = version.split(".")[0] if version is not None else ""
    # isdigit() is true of "²" and other digits int() does not read: ASCII digits only.
    if version is not None and major.isascii() and major.isdigit() and len(major) < 6 and int(major) < 4:
        raise FormatError(f"the file is Spine {version} data; qtanimator reads the Spine 4 format "
                          "(export it again from Spine 4).", p)
    fps = _number(sk, "fps", 30.0, "\"skeleton\"", p)
    if not fps > 0.0:
        raise FormatError("\"skeleton\".\"fps\" must be positive.", p)
    bones = _bones(obj, p)
    return SpineData(str(p), version, fps, bones, _animations(obj, bones, p))


def looks_like_spine(path: str | os.PathLike[str]) -> bool:
    """True for a ``.json`` file that is a Spine skeleton: a top-level ``"skeleton"`` object
    with a ``"spine"`` version and a ``"bones"`` list (never raises)."""
    try:
        obj = json.loads(read_bytes(Path(path)).decode("utf-8-sig"))
    except (FormatError, ValueError, RecursionError):
        return False
    return (isinstance(obj, dict) and isinstance(obj.get("skeleton"), dict)
            and isinstance(obj["skeleton"].get("spine"), str) and isinstance(obj.get("bones"), list))


def summarize(path: Path) -> dict[str, Any]:
    """``qtanimator info`` for a Spine skeleton."""
    data = read_spine(path)
    anims = {}
    for name, a in data.animations.items():
        tls = [tl for tls in a.bones.values() for tl in tls.values()]
        anims[name] = {"bones": len(a.bones), "timelines": len(tls), "keys": sum(len(tl.keys) for tl in tls),
                       "duration": a.duration, "ignored": list(a.ignored)}
    return {"file": str(path), "kind": "Spine skeleton", "spine": data.version, "fps": data.fps,
            "bones": len(data.bones), "root": data.bones[0].name, "animations": anims}
