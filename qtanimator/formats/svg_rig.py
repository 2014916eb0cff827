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

The reader is split by idea: :mod:`~qtanimator.formats.svg_builder` turns the drawing's
elements into joints and shapes, :mod:`~qtanimator.formats.svg_joint_documents` cuts each
joint's own SVG document for the renderer, :mod:`~qtanimator.formats.svg_rig_spec` reads
and writes rig specs (the asset property ``rig``). This module reads files and picks the
rule that rigs a drawing.
"""

from __future__ import annotations

import io
import logging
import os
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import numpy as np
import svgelements as se

from qtanimator.core.rig2d import Character, Joint, Shape
from qtanimator.formats._svg_budget import check_budget
from qtanimator.formats._tokens import read_bytes
from qtanimator.formats.errors import FormatError
from qtanimator.formats.svg_builder import _QID, _box_centre, _Builder, _elements, _empty, _local, _NotARig, _number
from qtanimator.formats.svg_images import ImageGate
from qtanimator.formats.svg_joint_documents import _JointDocuments, _matrix_of
from qtanimator.formats.svg_rig_spec import _add_candidates, _derived_spec, _element_refs, _from_spec

log = logging.getLogger(__name__)

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
        tagged = _without_image_data(root)
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
        images = ImageGate(None if path is None else Path(os.path.abspath(path)).parent)
        docs = _JointDocuments(root, frame, images)
        for joint, (keep, drop) in zip(joints, builder.scopes):
            joint.svg = docs.document(keep, drop)
        builder.warnings.extend(images.warnings)
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


# ------------------------------------------------------- XML reading and the rig rules
class _WholeRead(io.BytesIO):
    """Hands svgelements' ``iterparse`` the whole document in one read.

    ``iterparse`` feeds expat 16 KB at a time, and expat (before 2.6) scans a token that
    spans many feeds again on every feed: a 60 MB attribute then takes hours. One feed
    keeps parsing linear.
    """

    def read(self, size: int | None = -1, /) -> bytes:
        return super().read(-1)


def _without_image_data(root: ET.Element) -> bytes:
    """The document as svgelements reads it: ``<image>`` references emptied.

    svgelements opens no image, but it decodes an image's ``data:`` URI again for every
    ``<use>`` copy (200 copies of 4 MB: 880 MB); the geometry needs none of it. The joint
    documents take the images from ``root`` (:mod:`qtanimator.formats.svg_images`)."""
    saved: list[tuple[ET.Element, str, str]] = []
    for el in root.iter():
        if _local(el.tag) == "image":
            for key, value in el.attrib.items():
                if _local(key) == "href" and value:
                    saved.append((el, key, value))
    try:
        for el, key, _ in saved:
            el.set(key, "")
        return ET.tostring(root)
    finally:
        for el, key, value in saved:
            el.set(key, value)


def _xml_reason(exc: ET.ParseError) -> str:
    text = str(exc)
    return text.split(":")[0] if ":" in text else text


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

