"""Rig specs: a character's joints named as data, apart from the SVG they cut up.

The asset property ``rig`` holds one (``docs/decisions.md``, "Rigging inside the program");
:func:`_from_spec` builds the character a spec makes of a drawing whatever rules the
drawing follows, and :func:`_derived_spec` writes the spec of a character the rig rules
(or the whole-drawing rule) made, so the rig editor can start from it.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from typing import Any

import numpy as np
import svgelements as se

from qtanimator.core.rig2d import Joint, Shape
from qtanimator.formats.errors import FormatError
from qtanimator.formats.svg_builder import _QID, _box_centre, _Builder, _elements, _empty, _float, _qid

_INKSCAPE_NS = "http://www.inkscape.org/namespaces/inkscape"

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
