"""SVG rigs: jointed 2D characters drawn in SVG (the CMU 15-462 animator's format).

The joint tree rule (``notes/cmu-animator.md`` section 2): the first top-level group of the
``<svg>`` is the character. In a group of joints the first is the parent and the rest are
its children; a joint's last element is a circle whose centre is the pivot, and a white
fill on that circle makes the joint dynamic (a pendulum). A group whose only child is a
group stands for that group.

Unlike the reference program this reader takes full SVG through svgelements: curved paths
(flattened), transforms on groups and shapes (baked into the geometry), inherited styles,
named and 3-digit colours, opacity. A joint whose last element is not a circle uses that
element's bounding-box centre, with a warning in ``Character.warnings`` and the log.

Before svgelements sees a file, :mod:`qtanimator.formats._svg_budget` measures it as
svgelements would expand it (``<use>`` copies, inherited transforms, path points…) and
refuses what is beyond the limits of :mod:`qtanimator.formats.limits`; flattening curves
stops at ``MAX_FLATTENED_POINTS``.
"""

from __future__ import annotations

import io
import logging
import math
import os
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import numpy as np
import svgelements as se

from qtanimator.core.rig2d import RGBA, Character, Joint, Shape
from qtanimator.formats import limits
from qtanimator.formats._svg_budget import check_budget
from qtanimator.formats._tokens import read_bytes
from qtanimator.formats.errors import FormatError

log = logging.getLogger(__name__)

_ELLIPSE_SEGMENTS = 72
_MAX_FILE_BYTES = 64 * 1024 * 1024


def load_characters(path: str | os.PathLike[str]) -> list[Character]:
    """The characters in an SVG file (one) or a folder of SVG files (sorted by name)."""
    p = Path(path)
    if p.is_dir():
        files = sorted((f for f in p.iterdir() if f.suffix.lower() == ".svg" and f.is_file()),
                       key=lambda f: f.name)
        if not files:
            raise FormatError("the folder holds no .svg files.", p)
        return [load_character(f) for f in files]
    if not p.exists():
        raise FormatError("no such file or folder.", p)
    return [load_character(p)]


def load_character(path: str | os.PathLike[str], name: str | None = None) -> Character:
    """One character from one SVG file."""
    p = Path(path)
    data = read_bytes(p, _MAX_FILE_BYTES)
    return parse_character(data, name or p.stem, p)


def parse_character(data: bytes, name: str, path: str | os.PathLike[str] | None = None) -> Character:
    """Build a character from SVG bytes; FormatError for anything that is not a rig."""
    if len(data) > _MAX_FILE_BYTES:
        raise FormatError("the file is too large for an SVG character.", path)
    try:
        check_budget(data, path)
    except FormatError:
        raise
    except RecursionError:
        raise FormatError("the groups are nested too deeply.", path) from None
    except Exception as exc:  # noqa: BLE001 - nothing else may escape a reader
        raise FormatError(f"this is not a readable XML file ({type(exc).__name__}).", path) from None
    try:
        root = ET.fromstring(data)
    except ET.ParseError as exc:
        line, col = getattr(exc, "position", (None, None))
        raise FormatError(f"this is not a well-formed SVG (XML) file: {_xml_reason(exc)}.", path,
                          line, None if col is None else col + 1) from None
    except Exception as exc:  # noqa: BLE001 - nothing else may escape a reader
        raise FormatError(f"this is not a readable XML file ({type(exc).__name__}).", path) from None
    if not isinstance(root.tag, str) or root.tag.rsplit("}", 1)[-1] != "svg":
        raise FormatError(f"the root element is <{root.tag}>, not <svg>.", path)
    try:
        svg = se.SVG.parse(_WholeRead(data), reify=False)
    except Exception as exc:  # noqa: BLE001
        raise FormatError(f"the SVG could not be read ({type(exc).__name__}: {exc}).", path) from None
    builder = _Builder(path)
    try:
        top = _elements(svg)
        if not top:
            raise FormatError("the SVG has no elements, so no character.", path)
        first = top[0]
        if not isinstance(first, se.Group):
            raise FormatError(f"the first element of the SVG is a <{_tag(first)}>, but a character "
                              "must be a group <g> of joints.", path)
        builder.joint(first, None)
        joints = builder.joints
        with np.errstate(all="ignore"):  # huge coordinates are reported below, not warned about
            character = Character(name, joints, source=None if path is None else str(path),
                                  warnings=builder.warnings)
        _check_finite(character, path)
    except FormatError:
        raise
    except RecursionError:
        raise FormatError("the groups are nested too deeply.", path) from None
    except Exception as exc:  # noqa: BLE001
        raise FormatError(f"the SVG could not be turned into a character ({type(exc).__name__}: "
                          f"{exc}).", path) from None
    for w in builder.warnings:
        log.warning("%s: %s", os.path.basename(os.fspath(path)) if path else name, w)
    return character


def _check_finite(character: Character, path: str | os.PathLike[str] | None) -> None:
    """FormatError when a joint's geometry or mass properties are not finite numbers.

    Coordinates near the float limit (``1e308``) parse, but their areas and moments overflow;
    a pendulum built on them would only produce NaN later, far from the cause.
    """
    for i, j in enumerate(character.joints):
        values = [np.asarray(j.pivot, dtype=np.float64).ravel()]
        values += [np.asarray(sh.points, dtype=np.float64).ravel() for sh in j.shapes]
        for mp in (j.mass_properties, j.reference_mass_properties):
            if mp is not None:
                values.append(np.array([mp.mass, mp.inertia, *np.ravel(mp.centroid)], dtype=np.float64))
        if not all(np.isfinite(v).all() for v in values):
            raise FormatError(f"joint {i} ('{j.name}') has coordinates too large (or not numbers), so its "
                              "size, mass or pivot cannot be computed.", path)


def summarize(path: str | os.PathLike[str]) -> dict[str, Any]:
    """``qtanimator info`` for an SVG character or a folder of them."""
    p = Path(path)
    chars = load_characters(p)
    out: dict[str, Any] = {"file": str(p), "kind": "2D SVG rig"}
    out["characters"] = [
        {
            "name": c.name,
            "joints": len(c.joints),
            "dynamic": int(c.dynamic.sum()),
            "dynamic_joints": [j.name for j in c.joints if j.is_dynamic],
            "bounds": [round(v, 3) for v in c.bounds()],
            "warnings": list(c.warnings),
        }
        for c in chars
    ]
    out["joints"] = sum(len(c.joints) for c in chars)
    out["dynamic"] = sum(int(c.dynamic.sum()) for c in chars)
    return out


# ---------------------------------------------------------------------- helpers
class _WholeRead(io.BytesIO):
    """Hands svgelements' ``iterparse`` the whole document in one read.

    ``iterparse`` feeds expat 16 KB at a time, and expat (before 2.6) scans a token that
    spans many feeds again on every feed: a 60 MB attribute then takes hours. One feed
    keeps parsing linear.
    """

    def read(self, size: int | None = -1, /) -> bytes:
        return super().read(-1)


def _xml_reason(exc: ET.ParseError) -> str:
    text = str(exc)
    return text.split(":")[0] if ":" in text else text


def _tag(el: Any) -> str:
    name = type(el).__name__
    return {"SimpleLine": "line", "SVGImage": "image", "SVGText": "text"}.get(name, name.lower())


def _elements(group: Any) -> list[Any]:
    """The child elements that matter for the rig (shapes, groups, images, text)."""
    out = []
    for el in group:
        if isinstance(el, (se.Group, se.Shape, se.SVGImage, se.SVGText)):
            out.append(el)
    return out


def _collapse(group: Any) -> Any:
    """A group whose only child is a group stands for that group (repeatedly)."""
    while True:
        kids = _elements(group)
        if len(kids) == 1 and isinstance(kids[0], se.Group):
            group = kids[0]
        else:
            return group


def _color(c: Any, default: RGBA) -> RGBA:
    if c is None:
        return default
    if getattr(c, "value", 0) is None:
        return (0.0, 0.0, 0.0, 0.0)
    try:
        return (c.red / 255.0, c.green / 255.0, c.blue / 255.0, c.alpha / 255.0)
    except Exception:  # noqa: BLE001
        return default


def _float(v: Any, default: float = 0.0) -> float:
    try:
        f = float(v)
    except (TypeError, ValueError):
        return default
    return f if math.isfinite(f) else default


def _matrix(el: Any) -> np.ndarray:
    m = getattr(el, "transform", None)
    if m is None:
        return np.eye(3)
    return np.array([[m.a, m.c, m.e], [m.b, m.d, m.f], [0.0, 0.0, 1.0]], dtype=np.float64)


def _apply(m: np.ndarray, pts: np.ndarray) -> np.ndarray:
    return np.asarray(pts @ m[:2, :2].T + m[:2, 2], dtype=np.float64)


def _user_id(el: Any) -> str | None:
    v = getattr(el, "values", {}).get("id") if hasattr(el, "values") else None
    if v is None:
        v = getattr(el, "id", None)
    return str(v) if v else None


class _Builder:
    def __init__(self, path: str | os.PathLike[str] | None) -> None:
        self.path = path
        self.joints: list[Joint] = []
        self.warnings: list[str] = []
        self._names: set[str] = set()
        self.points = 0  # flattened points so far, against MAX_FLATTENED_POINTS

    def spend(self, n: int) -> None:
        """Count ``n`` more flattened points; FormatError beyond the limit."""
        self.points += n
        if self.points > limits.MAX_FLATTENED_POINTS:
            err = limits.exceeded(f"the number of points after curves are flattened ({self.points:,}+)",
                                  f"{limits.MAX_FLATTENED_POINTS:,} (MAX_FLATTENED_POINTS)", self.path)
            raise err

    def _name(self, *candidates: str | None) -> str:
        base = next((c for c in candidates if c), None)
        if base is None:
            base = "root" if not self.joints else f"joint{len(self.joints)}"
        base = base.strip() or f"joint{len(self.joints)}"
        name, k = base, 2
        while name in self._names:
            name = f"{base}_{k}"
            k += 1
        self._names.add(name)
        return name

    def joint(self, group: Any, parent: int | None) -> None:
        g = _collapse(group)
        elems = _elements(g)
        if not elems:
            raise FormatError(f"joint {len(self.joints)} is an empty group <g>; a joint needs its "
                              "shapes and a centre circle.", self.path)
        index = len(self.joints)
        if isinstance(elems[0], se.Group):
            h = _collapse(elems[0])
            own = _elements(h)
            if not own:
                raise FormatError(f"joint {index} starts with an empty group <g>.", self.path)
            children = elems[1:]
            name = self._name(_user_id(h), _user_id(g), _user_id(group))
        else:
            own = elems
            children = []
            name = self._name(_user_id(g), _user_id(group))
        centre_el = own[-1]
        shapes: list[Shape] = []
        for el in own[:-1]:
            shapes.extend(self.shapes(el))
        pivot, dynamic = self.centre(centre_el, index, name)
        joint = Joint(name, parent, pivot, dynamic, shapes)
        self.joints.append(joint)
        for child in children:
            if isinstance(child, se.Group):
                self.joint(child, index)
            else:
                self.warnings.append(f"joint '{name}': a <{_tag(child)}> after the joint's own group "
                                     "is drawn as part of the joint.")
                joint.shapes.extend(self.shapes(child))

    def centre(self, el: Any, index: int, name: str) -> tuple[np.ndarray, bool]:
        white = False
        if isinstance(el, se.Shape):
            fill = _color(el.fill, (0.0, 0.0, 0.0, 1.0))
            white = fill[0] == 1.0 and fill[1] == 1.0 and fill[2] == 1.0 and fill[3] > 0
        if isinstance(el, se.Circle) or (isinstance(el, se.Ellipse) and type(el).__name__ == "Circle"):
            c = _apply(_matrix(el), np.array([[_float(el.cx), _float(el.cy)]]))[0]
            return c, white
        shapes = self.shapes(el)
        pts = [s.points for s in shapes if len(s.points)]
        if not pts:
            raise FormatError(f"joint {index} ('{name}') has no centre circle and its last element "
                              "has no geometry to take a centre from.", self.path)
        allp = np.concatenate(pts)
        c = (allp.min(axis=0) + allp.max(axis=0)) / 2.0
        self.warnings.append(f"joint {index} ('{name}'): the last element is a <{_tag(el)}>, not a "
                             f"<circle>; using its bounding-box centre ({c[0]:.3f}, {c[1]:.3f}) as the pivot.")
        return c, white

    def shapes(self, el: Any) -> list[Shape]:
        if isinstance(el, se.Group):
            out: list[Shape] = []
            for kid in _elements(el):
                out.extend(self.shapes(kid))
            return out
        if not isinstance(el, se.Shape):
            self.warnings.append(f"a <{_tag(el)}> element is not drawn (only shapes are supported).")
            return []
        values = getattr(el, "values", {})
        fill = _color(el.fill, (0.0, 0.0, 0.0, 1.0))
        stroke = _color(el.stroke, (0.0, 0.0, 0.0, 0.0))
        width = _float(getattr(el, "implicit_stroke_width", None), -1.0)
        if width < 0:
            width = _float(getattr(el, "stroke_width", 1.0), 1.0)
        opacity = min(max(_float(values.get("opacity", 1.0), 1.0), 0.0), 1.0)
        style: dict[str, Any] = {"fill": fill, "stroke": stroke, "stroke_width": width, "opacity": opacity}
        m = _matrix(el)
        if isinstance(el, se.Ellipse) or type(el).__name__ == "Circle":
            rx, ry = _float(getattr(el, "rx", 0.0)), _float(getattr(el, "ry", 0.0))
            centre = np.array([_float(el.cx), _float(el.cy)])
            if rx <= 0 or ry <= 0:
                return []
            c = _apply(m, centre[None, :])[0]
            axes = m[:2, :2] @ np.diag([rx, ry])
            self.spend(_ELLIPSE_SEGMENTS)
            t = np.linspace(0.0, 2 * math.pi, _ELLIPSE_SEGMENTS, endpoint=False)
            pts = c + np.stack([np.cos(t), np.sin(t)], axis=1) @ axes.T
            return [_checked(Shape(pts, True, kind="ellipse", ellipse=(c, axes), **style), self.path)]
        if isinstance(el, se.Rect):
            x, y = _float(el.x), _float(el.y)
            w, h = _float(el.width), _float(el.height)
            rx, ry = _float(getattr(el, "rx", 0.0)), _float(getattr(el, "ry", 0.0))
            if (rx > 0 or ry > 0) and w > 0 and h > 0:
                return [_checked(s, self.path) for s in _path_shapes(el, style, self)]
            if w == 0 and h == 0:
                pts = _apply(m, np.array([[x, y]]))
                return [_checked(Shape(pts, False, kind="point", **style), self.path)]
            corners = np.array([[x, y], [x + w, y], [x + w, y + h], [x, y + h]])
            return [_checked(Shape(_apply(m, corners), True, kind="rect", **style), self.path)]
        if isinstance(el, se.SimpleLine):
            pts = np.array([[_float(el.x1), _float(el.y1)], [_float(el.x2), _float(el.y2)]])
            return [_checked(Shape(_apply(m, pts), False, kind="line", **style), self.path)]
        if isinstance(el, (se.Polygon, se.Polyline)):
            self.spend(len(el.points))
            pts = np.array([[_float(p.x), _float(p.y)] for p in el.points], dtype=np.float64).reshape(-1, 2)
            if len(pts) == 0:
                return []
            closed = isinstance(el, se.Polygon)
            return [_checked(Shape(_apply(m, pts), closed, kind="polygon" if closed else "polyline",
                                   **style), self.path)]
        return [_checked(s, self.path) for s in _path_shapes(el, style, self)]


def _checked(shape: Shape, path: str | os.PathLike[str] | None) -> Shape:
    if not np.all(np.isfinite(shape.points)):
        raise FormatError("a shape has coordinates that are not finite numbers.", path)
    return shape


def _path_shapes(el: Any, style: dict[str, Any], budget: _Builder) -> list[Shape]:
    """Flatten a path (or any other shape) into one Shape per subpath.

    Curves are sampled with svgelements' vectorised ``npoint`` (``point`` calls it with one
    position, so the points are the same) and counted against MAX_FLATTENED_POINTS.
    """
    out: list[Shape] = []
    current: list[tuple[float, float]] = []
    closed = False

    def flush() -> None:
        nonlocal current, closed
        if len(current) >= 1:
            pts = np.array(current, dtype=np.float64)
            if closed and len(pts) > 1 and np.allclose(pts[0], pts[-1]):
                pts = pts[:-1]
            is_closed = closed and len(pts) >= 3
            out.append(Shape(pts, is_closed, kind="path", **style))
        current = []
        closed = False

    for seg in el.segments(transformed=True):
        budget.spend(1)
        if isinstance(seg, se.Move):
            flush()
            if seg.end is not None:
                current.append((float(seg.end.x), float(seg.end.y)))
        elif isinstance(seg, se.Close):
            closed = True
        elif isinstance(seg, se.Line):
            if not current and seg.start is not None:
                current.append((float(seg.start.x), float(seg.start.y)))
            current.append((float(seg.end.x), float(seg.end.y)))
        elif isinstance(seg, (se.CubicBezier, se.QuadraticBezier, se.Arc)):
            if not current and seg.start is not None:
                current.append((float(seg.start.x), float(seg.start.y)))
            n = _samples(seg)
            budget.spend(n)
            xy = np.asarray(seg.npoint(np.linspace(0.0, 1.0, n + 1)[1:]), dtype=np.float64).reshape(n, 2)
            current.extend((x, y) for x, y in xy.tolist())
    flush()
    return out


def _samples(seg: Any) -> int:
    try:
        if isinstance(seg, se.Arc):
            sweep = abs(float(seg.sweep)) if seg.sweep is not None else math.pi
            r = max(abs(float(seg.rx or 0)), abs(float(seg.ry or 0)))
            est = r * sweep
        else:
            pts = [seg.start, *([seg.control1, seg.control2] if isinstance(seg, se.CubicBezier)
                                else [seg.control]), seg.end]
            est = sum(math.hypot(b.x - a.x, b.y - a.y) for a, b in zip(pts[:-1], pts[1:]))
    except Exception:  # noqa: BLE001
        est = 16.0
    if not math.isfinite(est):
        return 16
    return int(min(max(est / 2.0, 4), 64))
