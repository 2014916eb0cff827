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
import re
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


def load_character(path: str | os.PathLike[str], name: str | None = None,
                   rig: dict[str, Any] | None = None) -> Character:
    """One character from one SVG file (rigged by ``rig``, a rig spec, when given)."""
    p = Path(path)
    data = read_bytes(p, _MAX_FILE_BYTES)
    return parse_character(data, name or p.stem, p, rig=rig)


def load_rigged_character(path: str | os.PathLike[str], index: int, rig: dict[str, Any]) -> Character:
    """Character ``index`` of an SVG file or folder (as :func:`load_characters` numbers them),
    rigged by the rig spec ``rig`` instead of the file's own rig rules."""
    p = Path(path)
    if p.is_dir():
        files = sorted((f for f in p.iterdir() if f.suffix.lower() == ".svg" and f.is_file()),
                       key=lambda f: f.name)
    elif p.exists():
        files = [p]
    else:
        raise FormatError("no such file or folder.", p)
    if not 0 <= index < len(files):
        raise FormatError(f"the source holds {len(files)} character(s), not {index + 1}.", p)
    return load_character(files[index], rig=rig)


def parse_character(data: bytes, name: str, path: str | os.PathLike[str] | None = None,
                    rig: dict[str, Any] | None = None) -> Character:
    """Build a character from SVG bytes; FormatError for anything that is not a rig.

    With ``rig`` (a rig spec, see :func:`_from_spec`), the joints are the spec's, cut from
    the drawing whatever rules it follows; the SVG itself is never changed.
    """
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
        _number(root)
        tagged = ET.tostring(root)
        svg = se.SVG.parse(_WholeRead(tagged), reify=False)
    except Exception as exc:  # noqa: BLE001
        raise FormatError(f"the SVG could not be read ({type(exc).__name__}: {exc}).", path) from None
    try:
        top = _elements(svg)
        if not top:
            raise FormatError("the SVG has no elements, so no character.", path)
        if all(_empty(el) for el in top):
            raise FormatError("the SVG draws nothing: every top-level element is an empty group <g>, so "
                              "no character.", path)
        refs = _element_refs(root)
        if rig is not None:
            builder = _from_spec(svg, top, root, rig, refs, path)
        else:
            builder = _rig(svg, top, path) or _whole_drawing(svg, top, root, path)
            builder.spec = _derived_spec(builder, top, refs)
        joints = builder.joints
        if any(_local(el.tag) == "marker" and (el.get("orient") or "").startswith("auto") for el in root.iter()):
            builder.warnings.append("markers with orient=\"auto\" are drawn unrotated (the SVG renderer "
                                    "does not turn them along the line).")
        frame = _matrix_of(getattr(svg, "viewbox_transform", None))
        docs = _JointDocuments(root, frame)
        for joint, (keep, drop) in zip(joints, builder.scopes):
            joint.svg = docs.document(keep, drop)
        with np.errstate(all="ignore"):  # huge coordinates are reported below, not warned about
            character = Character(name, joints, source=None if path is None else str(path),
                                  warnings=builder.warnings)
        character.joint_candidates = builder.candidates
        character.candidate_elements = dict(builder.candidate_refs)
        character.rig_spec = builder.spec
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
        if isinstance(el, (se.Group, se.Shape, se.SVGImage, se.SVGText, se.Use)):
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



def _box_centre(points: list[np.ndarray]) -> np.ndarray:
    """The centre of the bounding box of some point arrays. Halves first: the midpoint of
    coordinates near the float limit does not overflow (and equals (min + max) / 2 else)."""
    allp = np.concatenate(points)
    return np.asarray(allp.min(axis=0) / 2.0 + allp.max(axis=0) / 2.0, dtype=np.float64)

class _Builder:
    def __init__(self, path: str | os.PathLike[str] | None) -> None:
        self.path = path
        self.joints: list[Joint] = []
        self.warnings: list[str] = []
        self._names: set[str] = set()
        #: per joint: (ids of the XML elements it draws, ids of those it leaves out)
        self.scopes: list[tuple[set[str], set[str]]] = []
        self.circle_markers: list[bool] = []
        self.candidates: list[str] = []
        #: candidate label -> element reference (see :func:`_element_refs`)
        self.candidate_refs: dict[str, str] = {}
        #: the rig spec that rebuilds this character (see :func:`_from_spec`)
        self.spec: dict[str, Any] = {}
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
            raise _NotARig(f"joint {len(self.joints)} is an empty group <g>; a joint needs its "
                           "shapes and a centre circle.", self.path)
        index = len(self.joints)
        if isinstance(elems[0], se.Group):
            h = _collapse(elems[0])
            own = _elements(h)
            if not own:
                raise _NotARig(f"joint {index} starts with an empty group <g>.", self.path)
            children = elems[1:]
            keep = {_qid(h)}
            name = self._name(_user_id(h), _user_id(g), _user_id(group))
        else:
            own = elems
            children = []
            keep = {_qid(g)}
            name = self._name(_user_id(g), _user_id(group))
        centre_el = own[-1]
        shapes: list[Shape] = []
        for el in own[:-1]:
            shapes.extend(self.shapes(el))
        pivot, dynamic = self.centre(centre_el, index, name)
        joint = Joint(name, parent, pivot, dynamic, shapes)
        self.joints.append(joint)
        self.scopes.append((keep, {_qid(centre_el)}))
        self.circle_markers.append(isinstance(centre_el, se.Circle))
        for child in children:
            if isinstance(child, se.Group) and _empty(child):
                self.warnings.append(f"joint '{name}': an empty group <g> among its children is skipped.")
            elif isinstance(child, se.Group):
                self.joint(child, index)
            else:
                self.warnings.append(f"joint '{name}': a <{_tag(child)}> after the joint's own group "
                                     "is drawn as part of the joint.")
                joint.shapes.extend(self.shapes(child))
                keep.add(_qid(child))

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
            raise _NotARig(f"joint {index} ('{name}') has no centre circle and its last element "
                           "has no geometry to take a centre from.", self.path)
        c = _box_centre(pts)
        self.warnings.append(f"joint {index} ('{name}'): the last element is a <{_tag(el)}>, not a "
                             f"<circle>; using its bounding-box centre ({c[0]:.3f}, {c[1]:.3f}) as the pivot.")
        return c, white

    def shapes(self, el: Any) -> list[Shape]:
        if isinstance(el, (se.Group, se.Use)):
            out: list[Shape] = []
            for kid in _elements(el):
                out.extend(self.shapes(kid))
            return out
        if not isinstance(el, se.Shape):
            self.warnings.append(f"a <{_tag(el)}> element is drawn as the SVG renderer draws it (text "
                                 "in the fonts of this computer), but it has no mass and cannot be "
                                 "picked: convert it to paths for exact, clickable shapes.")
            return []
        values = getattr(el, "values", {})
        fill = _color(el.fill, (0.0, 0.0, 0.0, 1.0))
        stroke = _color(el.stroke, (0.0, 0.0, 0.0, 0.0))
        width = _float(getattr(el, "implicit_stroke_width", None), -1.0)
        if width < 0:
            width = _float(getattr(el, "stroke_width", 1.0), 1.0)
        opacity = min(max(_float(values.get("opacity", 1.0), 1.0), 0.0), 1.0)
        # Opacity is a look, not a mass: only the element's own ``opacity`` (attribute, style
        # or CSS rule) sets its density, as in the reference program, which ignores group
        # styles; a group's opacity (owl.svg's wing feathers) changes nothing.
        attributes = values.get("attributes")
        own = attributes.get("opacity", 1.0) if isinstance(attributes, dict) else 1.0
        density_opacity = min(max(_float(own, 1.0), 0.0), 1.0)
        style: dict[str, Any] = {"fill": fill, "stroke": stroke, "stroke_width": width, "opacity": opacity,
                                 "density_opacity": density_opacity}
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


# ------------------------------------------------------- ordinary art and joint documents
_QID = "data-qta-id"
_SVG_NS = "http://www.w3.org/2000/svg"
_XLINK_NS = "http://www.w3.org/1999/xlink"
_INKSCAPE_NS = "http://www.inkscape.org/namespaces/inkscape"
_HREF = (f"{{{_XLINK_NS}}}href", "href")
#: Elements that draw nothing by themselves: kept wherever they are in a joint's document.
_RESOURCES = {"defs", "style", "linearGradient", "radialGradient", "clipPath", "mask", "pattern",
              "filter", "marker", "symbol", "title", "desc", "metadata", "script", "font",
              "font-face"}
#: The root's attributes that place the drawing in a viewport; the joint documents use the
#: reader's frame instead (``svgelements``' viewBox transform, applied as a group).
_VIEWPORT_ATTRIBUTES = {"width", "height", "viewBox", "x", "y", "preserveAspectRatio", "transform"}
_COLOR_PROPERTIES = {"fill": "fill-opacity", "stroke": "stroke-opacity", "stop-color": "stop-opacity",
                     "flood-color": "flood-opacity", "lighting-color": None, "color": None}
_FUNCTIONAL_COLOR = re.compile(r"^\s*(rgba|hsla?|rgb)\s*\(", re.IGNORECASE)
_URL_REF = re.compile(r"url\(\s*['\"]?#([^)'\"\s]+)")

ET.register_namespace("xlink", _XLINK_NS)


class _NotARig(FormatError):
    """The drawing does not follow the rig rules: it opens as one joint instead."""


def _local(tag: Any) -> str:
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else ""


def _number(root: ET.Element) -> None:
    """Give every XML element an id the joint documents find it by (root = ``0``)."""
    for k, el in enumerate(root.iter()):
        el.set(_QID, str(k))


def _qid(el: Any) -> str:
    values = getattr(el, "values", None)
    v = values.get(_QID) if isinstance(values, dict) else None
    return str(v) if v is not None else ""


def _matrix_of(value: Any) -> tuple[float, float, float, float, float, float]:
    try:
        m = se.Matrix(value) if value else se.Matrix()
        out = (float(m.a), float(m.b), float(m.c), float(m.d), float(m.e), float(m.f))
    except Exception:  # noqa: BLE001
        return (1.0, 0.0, 0.0, 1.0, 0.0, 0.0)
    return out if all(math.isfinite(v) for v in out) else (1.0, 0.0, 0.0, 1.0, 0.0, 0.0)


def _empty(el: Any) -> bool:
    """A group (layer) with nothing to draw in it, however deep."""
    return isinstance(el, (se.Group, se.Use)) and all(_empty(k) for k in _elements(el))


def _rig(svg: Any, top: list[Any], path: str | os.PathLike[str] | None) -> _Builder | None:
    """The character when the drawing follows the rig rules, else None.

    The rules: the first non-empty top-level element is a group, its joints (as the module
    docstring says) all parse, and the root joint ends with a ``<circle>``: the mark that
    tells a rig from ordinary art whose last shape happens to be anything.
    """
    drawn = [el for el in top if not _empty(el)]
    if not drawn or not isinstance(drawn[0], se.Group):
        return None
    builder = _Builder(path)
    try:
        builder.joint(drawn[0], None)
    except _NotARig:
        return None
    if not builder.circle_markers[0]:
        return None
    if len(drawn) > 1:
        builder.warnings.append(f"{len(drawn) - 1} top-level element(s) after the character's group "
                                "are not part of the character (a rig is the first group of the SVG).")
    return builder


def _whole_drawing(svg: Any, top: list[Any], root: ET.Element,
                   path: str | os.PathLike[str] | None) -> _Builder:
    """Ordinary art: one joint that draws the whole drawing, pivot at its centre."""
    builder = _Builder(path)
    shapes: list[Shape] = []
    for el in top:
        shapes.extend(builder.shapes(el))
    pts = [s.points for s in shapes if len(s.points)]
    pivot = _box_centre(pts) if pts else np.zeros(2)
    builder.joints.append(Joint(builder._name("drawing"), None, pivot, False, shapes))
    builder.scopes.append(({root.get(_QID, "0")}, set()))
    _add_candidates(builder, top, root)
    offer = (f" Its layers and top-level groups can become joints: {', '.join(builder.candidates)}."
             if builder.candidates else "")
    builder.warnings.insert(0, "this drawing is not rigged, so it opens as one joint that draws the "
                            "whole drawing." + offer + " To rig it in the SVG: make the character one "
                            "group <g>; in it, the first group is the body and the groups after it "
                            "its children (the same rule inside each); end each joint's group with a "
                            "small <circle> at its pivot (a white fill makes it a pendulum).")
    return builder


class _JointDocuments:
    """Standalone SVG documents of the joints, cut from the numbered XML tree."""

    def __init__(self, root: ET.Element, frame: tuple[float, float, float, float, float, float]) -> None:
        self.root = root
        self.frame = frame
        self.parent = {c: p for p in root.iter() for c in p}
        self.by_qid = {el.get(_QID): el for el in root.iter()}
        refs: set[str] = set()
        for el in root.iter():
            for key, value in el.attrib.items():
                if key in _HREF and value.startswith("#"):
                    refs.add(value[1:])
                refs.update(_URL_REF.findall(value))
            if _local(el.tag) == "style" and el.text:
                refs.update(_URL_REF.findall(el.text))
        self.referenced = refs

    def _holds_reference(self, el: ET.Element) -> bool:
        return any(e.get("id") in self.referenced for e in el.iter())

    def document(self, keep: set[str], drop: set[str]) -> str:
        ancestors: set[str] = set()
        for q in keep:
            el = self.by_qid.get(q)
            while el is not None:
                ancestors.add(el.get(_QID, ""))
                el = self.parent.get(el)
        root = ET.Element("svg", {k: v for k, v in self.root.attrib.items()
                                  if k not in _VIEWPORT_ATTRIBUTES and k != _QID})
        root.set("xmlns", _SVG_NS)
        root.set("viewBox", "0 0 1 1")
        root.set("width", "1")
        root.set("height", "1")
        moved = ET.SubElement(root, "defs")
        frame = ET.SubElement(root, "g", {"transform": "matrix({:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g})"
                                                       .format(*self.frame)})
        if self.root.get(_QID) in keep:
            keep = keep | {c.get(_QID, "") for c in self.root}

        def copy(src: ET.Element, dst: ET.Element, inside: bool) -> None:
            q = src.get(_QID, "")
            tag = _local(src.tag)
            if q in drop or not tag:
                return
            if inside or q in keep or q in ancestors or tag in _RESOURCES:
                node = _shallow(src, dst)
                inner = inside or q in keep or tag in _RESOURCES
                for child in src:
                    copy(child, node, inner)
            elif self._holds_reference(src):
                _clone(src, moved)

        for child in self.root:
            copy(child, frame, False)
        _inline_symbols(root)
        _clips_as_masks(root)
        _plain_colors(root)
        return ET.tostring(root, encoding="unicode")


def _shallow(src: ET.Element, parent: ET.Element) -> ET.Element:
    tag = src.tag
    if isinstance(tag, str) and tag.startswith(f"{{{_SVG_NS}}}"):
        tag = tag[len(_SVG_NS) + 2:]
    node = ET.SubElement(parent, tag, {k: v for k, v in src.attrib.items() if k != _QID})
    node.text = src.text
    node.tail = src.tail
    return node


def _clone(src: ET.Element, parent: ET.Element) -> None:
    node = _shallow(src, parent)
    for child in src:
        if isinstance(child.tag, str):
            _clone(child, node)


def _href(el: ET.Element) -> str | None:
    for key in _HREF:
        v = el.get(key)
        if v:
            return v
    return None


def _inline_symbols(root: ET.Element) -> None:
    """``<use>`` of a ``<symbol>`` becomes a group holding the symbol's content, with the
    symbol's viewBox fitted into the use's size (xMidYMid meet), as SVG specifies."""
    symbols = {el.get("id"): el for el in root.iter() if _local(el.tag) == "symbol" and el.get("id")}
    if not symbols:
        return
    for parent in list(root.iter()):
        for i, use in enumerate(list(parent)):
            href = _href(use) if _local(use.tag) == "use" else None
            sym = symbols.get(href[1:]) if href and href.startswith("#") else None
            if sym is None:
                continue
            x, y = _float(_strip_px(use.get("x")), 0.0), _float(_strip_px(use.get("y")), 0.0)
            parts = [use.get("transform") or "", f"translate({x!r},{y!r})"]
            vb = [_float(v, math.nan) for v in (sym.get("viewBox") or "").replace(",", " ").split()]
            w, h = _float(_strip_px(use.get("width")), math.nan), _float(_strip_px(use.get("height")), math.nan)
            if len(vb) == 4 and all(math.isfinite(v) for v in vb) and vb[2] > 0 and vb[3] > 0:
                w = vb[2] if not math.isfinite(w) else w
                h = vb[3] if not math.isfinite(h) else h
                k = min(w / vb[2], h / vb[3])
                parts.append(f"translate({(w - vb[2] * k) / 2!r},{(h - vb[3] * k) / 2!r}) scale({k!r}) "
                             f"translate({-vb[0]!r},{-vb[1]!r})")
            attrs = {k: v for k, v in use.attrib.items()
                     if k not in ("x", "y", "width", "height", "transform", *_HREF)}
            attrs.update({k: v for k, v in sym.attrib.items()
                          if k not in ("id", "viewBox", "preserveAspectRatio", "x", "y", "width", "height")})
            attrs["transform"] = " ".join(p for p in parts if p)
            group = ET.Element("g", attrs)
            group.tail = use.tail
            for child in sym:
                _clone(child, group)
            parent[i] = group
    for parent in list(root.iter()):
        for child in list(parent):
            if _local(child.tag) == "symbol":
                parent.remove(child)


def _strip_px(v: str | None) -> str | None:
    return v[:-2] if v is not None and v.endswith("px") else v


def _plain_color(value: str) -> tuple[str, float] | None:
    """``rgba()`` / ``hsl()`` / ``hsla()`` as ``#rrggbb`` and an alpha (Qt reads neither)."""
    if not _FUNCTIONAL_COLOR.match(value):
        return None
    try:
        c = se.Color(value.strip())
        if c.value is None:
            return None
        return f"#{c.red:02x}{c.green:02x}{c.blue:02x}", c.alpha / 255.0
    except Exception:  # noqa: BLE001
        return None


def _plain_colors(root: ET.Element) -> None:
    for el in root.iter():
        for prop, opacity_prop in _COLOR_PROPERTIES.items():
            v = el.get(prop)
            plain = _plain_color(v) if v else None
            if plain is not None:
                el.set(prop, plain[0])
                if opacity_prop and plain[1] < 1.0:
                    el.set(opacity_prop, repr(_float(el.get(opacity_prop), 1.0) * plain[1]))
        style = el.get("style")
        if style and "(" in style:
            decls = [d.split(":", 1) for d in style.split(";") if ":" in d]
            out: dict[str, str] = {k.strip(): v.strip() for k, v in decls}
            for prop, opacity_prop in _COLOR_PROPERTIES.items():
                plain = _plain_color(out[prop]) if prop in out else None
                if plain is not None:
                    out[prop] = plain[0]
                    if opacity_prop and plain[1] < 1.0:
                        out[opacity_prop] = repr(_float(out.get(opacity_prop, el.get(opacity_prop)), 1.0)
                                                 * plain[1])
            el.set("style", ";".join(f"{k}:{v}" for k, v in out.items()))


_SHAPE_TAGS = {"path", "rect", "circle", "ellipse", "line", "polyline", "polygon", "text", "use"}


def _clips_as_masks(root: ET.Element) -> None:
    """``clip-path`` (which QtSvg does not draw) becomes a mask of the same shapes filled
    white: the same area, with antialiased edges as renderers draw clips."""
    clips = {el.get("id"): el for el in root.iter() if _local(el.tag) == "clipPath" and el.get("id")}
    if not clips:
        return
    defs = next((el for el in root if _local(el.tag) == "defs"), None) or ET.SubElement(root, "defs")
    made: dict[str, str] = {}
    for el in list(root.iter()):
        style = el.get("style") or ""
        value = el.get("clip-path") or next((d.split(":", 1)[1].strip() for d in style.split(";")
                                             if d.split(":", 1)[0].strip() == "clip-path"), "")
        ref = _URL_REF.findall(value)
        clip = clips.get(ref[0]) if ref else None
        if clip is None or el.get("mask"):
            continue
        cid = str(clip.get("id"))
        if cid not in made:
            mid = made[cid] = f"{cid}__qta_clip"
            units = clip.get("clipPathUnits") == "objectBoundingBox"
            mask = ET.SubElement(defs, "mask", {"id": mid, "maskUnits": "userSpaceOnUse", "x": "-1e4",
                                                "y": "-1e4", "width": "2e4", "height": "2e4"})
            if units:
                mask.set("maskContentUnits", "objectBoundingBox")
            holder = ET.SubElement(mask, "g", {"transform": clip.get("transform", "")} if clip.get("transform") else {})
            for child in clip:
                _clone(child, holder)
            rule = clip.get("clip-rule")
            for node in holder.iter():
                if _local(node.tag) in _SHAPE_TAGS:
                    node.set("fill", "#ffffff")
                    node.set("fill-opacity", "1")
                    node.set("stroke", "none")
                    node.set("opacity", "1")
                    node.set("fill-rule", node.get("clip-rule") or rule or "nonzero")
                    node.attrib.pop("style", None)
        el.attrib.pop("clip-path", None)
        if style:
            el.set("style", ";".join(d for d in style.split(";") if d.split(":", 1)[0].strip() != "clip-path"))
        el.set("mask", f"url(#{made[cid]})")


# ------------------------------------------------------------------ rig specs
#: Rig spec (the asset property ``rig``; ``docs/decisions.md``, "Rigging inside the program"):
#:
#:     {"joints": [{"name": str, "parent": str | None, "elements": [ref, ...],
#:                  "pivot": [x, y] | None, "dynamic": bool, "spring": bool (optional)}, ...],
#:      "hidden": [ref, ...]}
#:
#: A ref names an element of the SVG: its ``id`` when that id is unique in the file, else
#: its path of child indices from the root ``<svg>`` ("#/2/0": the first child of the third
#: child), counting elements only. Exactly one joint has no parent (the root); it draws its
#: listed elements and every element no other joint claims. Elements in ``hidden`` are drawn
#: by nobody (a rigged file's pivot circles). A null pivot is the centre of the joint's box.


def _element_refs(root: ET.Element) -> dict[str, str]:
    """qid -> ref for every XML element (see the rig spec above)."""
    counts: dict[str, int] = {}
    for el in root.iter():
        i = el.get("id")
        if i:
            counts[i] = counts.get(i, 0) + 1
    out: dict[str, str] = {}

    def walk(el: ET.Element, path: str) -> None:
        i = el.get("id")
        out[el.get(_QID, "")] = "#" if not path else (i if i and counts[i] == 1 else path)
        for k, child in enumerate(c for c in el if isinstance(c.tag, str)):
            walk(child, f"{path or '#'}/{k}")

    walk(root, "")
    return out


def _add_candidates(builder: _Builder, top: list[Any], root: ET.Element) -> None:
    by_qid = {el.get(_QID): el for el in root.iter()}
    refs = _element_refs(root)
    for k, el in enumerate(top):
        if isinstance(el, se.Group) and not _empty(el):
            xml = by_qid.get(_qid(el))
            label = None if xml is None else (xml.get(f"{{{_INKSCAPE_NS}}}label") or xml.get("id"))
            text = str(label) if label else f"group {k + 1}"
            while text in builder.candidate_refs:
                text += "'"
            builder.candidates.append(text)
            builder.candidate_refs[text] = refs.get(_qid(el), "")


def _derived_spec(builder: _Builder, top: list[Any], refs: dict[str, str]) -> dict[str, Any]:
    """The rig spec that rebuilds what the rig rules (or the whole-drawing rule) made."""
    joints = []
    hidden: list[str] = []
    for j, (keep, drop) in zip(builder.joints, builder.scopes):
        parent = None if j.parent is None else builder.joints[j.parent].name
        root_all = j.parent is None and any(refs.get(q) == "#" for q in keep)
        joints.append({"name": j.name, "parent": parent,
                       "elements": [] if root_all else [refs[q] for q in sorted(keep, key=int) if q in refs],
                       "pivot": [float(j.pivot[0]), float(j.pivot[1])], "dynamic": bool(j.is_dynamic)})
        hidden += [refs[q] for q in sorted(drop, key=int) if q in refs]
    if builder.scopes and not any(refs.get(q) == "#" for q in builder.scopes[0][0]):
        claimed = {q for keep, drop in builder.scopes for q in keep | drop}
        # A rigged file: what is outside the character's group is not part of it.
        for el in top:
            q = _qid(el)
            if not _contains_any(el, claimed) and q in refs:
                hidden.append(refs[q])
    return {"joints": joints, "hidden": hidden}


def _contains_any(el: Any, qids: set[str]) -> bool:
    if _qid(el) in qids:
        return True
    return isinstance(el, se.Group) and any(_contains_any(k, qids) for k in _elements(el))


def _walk(el: Any, out: dict[str, Any]) -> None:
    q = _qid(el)
    if q:
        out.setdefault(q, el)
    if isinstance(el, se.Group):
        for kid in el:
            if isinstance(kid, (se.Group, se.Shape, se.SVGImage, se.SVGText, se.Use)):
                _walk(kid, out)


def _shapes_except(builder: _Builder, el: Any, skip: set[str]) -> list[Shape]:
    if _qid(el) in skip:
        return []
    if isinstance(el, se.Group):
        out: list[Shape] = []
        for kid in _elements(el):
            out.extend(_shapes_except(builder, kid, skip))
        return out
    return builder.shapes(el)


def _from_spec(svg: Any, top: list[Any], root: ET.Element, spec: Any, refs: dict[str, str],
               path: str | os.PathLike[str] | None) -> _Builder:
    """The character a rig spec makes of the drawing (FormatError for a broken spec)."""
    if not isinstance(spec, dict) or not isinstance(spec.get("joints"), list) or not spec["joints"]:
        raise FormatError("the rig has no joints.", path)
    builder = _Builder(path)
    qid_of = {r: q for q, r in refs.items()}
    rows: list[dict[str, Any]] = []
    names: set[str] = set()
    for row in spec["joints"]:
        if not isinstance(row, dict) or not isinstance(row.get("name"), str) or not row["name"]:
            raise FormatError("a joint of the rig has no name.", path)
        if row["name"] in names:
            raise FormatError(f"the rig has two joints named '{row['name']}'.", path)
        names.add(row["name"])
        rows.append(row)
    roots = [r for r in rows if r.get("parent") is None]
    if len(roots) != 1:
        raise FormatError(f"the rig has {len(roots)} root joints (joints without a parent), not one.", path)
    for r in rows:
        if r.get("parent") is not None and r["parent"] not in names:
            raise FormatError(f"joint '{r['name']}' has the parent '{r['parent']}', which is not a joint.", path)

    def qids(refs_: Any, what: str) -> list[str]:
        out = []
        for ref in refs_ or []:
            q = qid_of.get(str(ref))
            if q is None:
                builder.warnings.append(f"{what}: the drawing has no element '{ref}'; it is left out.")
            else:
                out.append(q)
        return out

    hidden = set(qids(spec.get("hidden"), "the rig's hidden elements"))
    own: dict[str, list[str]] = {}
    taken: set[str] = set()
    for r in rows:
        mine = [q for q in qids(r.get("elements"), f"joint '{r['name']}'") if q not in taken]
        taken.update(mine)
        own[r["name"]] = mine
    # Pre-order; siblings in the order of their first element in the file (draw order).
    kids: dict[str | None, list[dict[str, Any]]] = {}
    for r in rows:
        kids.setdefault(r.get("parent"), []).append(r)
    order: list[dict[str, Any]] = []

    def visit(r: dict[str, Any], depth: int) -> None:
        if depth > len(rows):
            raise FormatError("the rig's parents make a cycle.", path)
        order.append(r)
        for c in sorted(kids.get(r["name"], []), key=lambda c: min((int(q) for q in own[c["name"]]),
                                                                    default=1 << 60)):
            visit(c, depth + 1)

    visit(roots[0], 0)
    if len(order) != len(rows):
        raise FormatError("the rig's parents make a cycle.", path)
    by_qid: dict[str, Any] = {}
    for el in top:
        _walk(el, by_qid)
    index = {r["name"]: k for k, r in enumerate(order)}
    root_q = root.get(_QID, "0")
    for k, r in enumerate(order):
        name = r["name"]
        others = (taken - set(own[name])) | hidden
        shapes: list[Shape] = []
        if k == 0:
            keep = set(own[name]) | {root_q}
            for el in top:
                shapes.extend(_shapes_except(builder, el, others))
        else:
            keep = set(own[name])
            for q in own[name]:
                el = by_qid.get(q)
                if el is not None:
                    shapes.extend(_shapes_except(builder, el, others))
        pivot_v = r.get("pivot")
        if isinstance(pivot_v, (list, tuple)) and len(pivot_v) == 2:
            pivot = np.array([_float(pivot_v[0]), _float(pivot_v[1])], dtype=np.float64)
        else:
            pts = [s.points for s in shapes if len(s.points)]
            pivot = _box_centre(pts) if pts else np.zeros(2)
        parent = None if r.get("parent") is None else index[r["parent"]]
        builder._names.add(name)
        builder.joints.append(Joint(name, parent, pivot, bool(r.get("dynamic", False)), shapes,
                                    is_spring=bool(r.get("spring", False))))
        builder.scopes.append((keep, others))
    _add_candidates(builder, top, root)
    builder.spec = {"joints": [{"name": r["name"], "parent": r.get("parent"),
                                "elements": [refs[q] for q in own[r["name"]]],
                                "pivot": [float(j.pivot[0]), float(j.pivot[1])],
                                "dynamic": bool(j.is_dynamic), **({"spring": True} if j.is_spring else {})}
                               for r, j in zip(order, builder.joints)],
                    "hidden": [refs[q] for q in sorted(hidden, key=int)]}
    return builder
