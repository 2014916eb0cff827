"""Standalone SVG documents of the joints of an SVG character (what the renderer draws).

Each joint's document is cut from the numbered XML tree (see
:func:`qtanimator.formats.svg_builder._number`): the elements the joint draws, their
ancestors, and the resources they refer to, in the reader's frame. Qt's SVG renderer
misses some SVG, so the documents also inline ``<symbol>`` uses, turn clip paths into
masks and write functional colours (``rgba()``, ``hsl()``) as ``#rrggbb`` and an opacity.
Every ``<image>`` is checked and inlined (:mod:`qtanimator.formats.svg_images`): QtSvg gets
only ``data:`` URIs and never opens a file.
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from typing import Any

import svgelements as se

from qtanimator.formats.svg_builder import _QID, _float, _local
from qtanimator.formats.svg_images import ImageGate

_SVG_NS = "http://www.w3.org/2000/svg"
_XLINK_NS = "http://www.w3.org/1999/xlink"
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


def _matrix_of(value: Any) -> tuple[float, float, float, float, float, float]:
    try:
        m = se.Matrix(value) if value else se.Matrix()
        out = (float(m.a), float(m.b), float(m.c), float(m.d), float(m.e), float(m.f))
    except Exception:  # noqa: BLE001
        return (1.0, 0.0, 0.0, 1.0, 0.0, 0.0)
    return out if all(math.isfinite(v) for v in out) else (1.0, 0.0, 0.0, 1.0, 0.0, 0.0)


class _JointDocuments:
    """Standalone SVG documents of the joints, cut from the numbered XML tree."""

    def __init__(self, root: ET.Element, frame: tuple[float, float, float, float, float, float],
                 images: ImageGate | None = None) -> None:
        self.root = root
        self.frame = frame
        #: Checks and inlines every ``<image>`` of each document (QtSvg gets only ``data:``
        #: URIs); without one, images lose their references.
        self.images = images if images is not None else ImageGate(None)
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
        self.images.clean(root)
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

