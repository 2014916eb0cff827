"""SVG drawing to joints and shapes: the builder behind :mod:`qtanimator.formats.svg_rig`.

:class:`_Builder` walks svgelements' parsed tree (transforms and inherited styles already
applied) and makes :class:`~qtanimator.core.rig2d.Joint` and
:class:`~qtanimator.core.rig2d.Shape` objects: the joint tree rule of the rig (see
:mod:`qtanimator.formats.svg_rig`), circles and ellipses as polygons, curved paths
flattened, every flattened point counted against ``MAX_FLATTENED_POINTS``. Every XML
element carries a number (:func:`_number`, the ``data-qta-id`` attribute) that the joint
documents and the rig specs find it by.
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from typing import Any

import numpy as np
import svgelements as se

from qtanimator.core.rig2d import RGBA, Joint, Shape
from qtanimator.formats import limits
from qtanimator.formats.errors import FormatError

_ELLIPSE_SEGMENTS = 72
_QID = "data-qta-id"


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


def _empty(el: Any) -> bool:
    """A group (layer) with nothing to draw in it, however deep."""
    return isinstance(el, (se.Group, se.Use)) and all(_empty(k) for k in _elements(el))


# ---------------------------------------------------------------------- helpers
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
