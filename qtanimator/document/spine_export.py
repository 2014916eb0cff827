"""Spine JSON export of a 2D character (issue 15, item 7): the skeleton data a Spine runtime
plays (Spine 4.x "JSON export format"), free of Qt; the PNG attachments are rasterised by
:mod:`qtanimator.render.spine_images`.

Mapping (rig coordinates are SVG units, y down; Spine's are y up, angles in degrees,
counter-clockwise):

* a bone ``root`` (named ``root_2``… when a joint is called ``root``) holds the character's
  authored placement (identity when it has none) as x, y, rotation, scaleX, scaleY, shearY;
* one bone per joint, in the rig's pre-order, at the joint's rest pivot: ``x``, ``y`` = the pivot
  minus the parent's pivot (y negated), ``rotation`` 0 (every rest angle is 0), ``length`` = the
  distance to the first child's pivot (0 for a leaf). The root joint's bone sits at its pivot
  under ``root``. A rig angle θ (counter-clockwise on screen) is a Spine rotation of
  degrees(θ): y down with R(θ) = [[c, s], [−s, c]] is the ordinary counter-clockwise rotation
  once y points up;
* one slot per joint that draws something (draw order = joint order), holding one region
  attachment named as the joint: ``images/<joint>.png``, the joint's rest drawing over its
  shapes' bounds (strokes included) plus a margin, at ``pixels_per_unit``; ``scaleX`` /
  ``scaleY`` = 1 / ``pixels_per_unit`` so one pixel is one rig unit over that, centred where
  the drawing's centre is relative to the pivot;
* one animation (named as the asset) sampled at every frame of the document's range at its
  fps, time 0 at the range's start: each joint's bone a ``rotate`` timeline of its local
  angle (what :func:`character2d.evaluate_pose` shows: keys, pendulums, springs and limits
  included) and the root joint's bone a ``translate`` timeline of the character's
  translation. Keys are linear (Spine's default), so the runtime shows exactly the program's
  pose at every frame.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import re
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.core.rig2d import Character
from qtanimator.document.character2d_asset import character
from qtanimator.document.document import Document
from qtanimator.document.evaluation2d import evaluate_pose, placement_matrix
from qtanimator.formats.atomic import write_text_atomic

FloatArray = npt.NDArray[np.float64]

#: The Spine editor version the JSON follows (its data format is that of 4.x).
SPINE_VERSION = "4.1.24"
#: Pixels per rig unit of the PNG attachments by default.
PIXELS_PER_UNIT = 2.0
#: Rig units added on each side of a joint's drawing (antialiasing).
MARGIN = 1.0


@dataclass(frozen=True)
class Region:
    """One joint's PNG attachment: the rest-frame rectangle it covers (rig units, y down) and
    its size in pixels."""

    joint: int
    name: str
    file: str
    x0: float
    y0: float
    x1: float
    y1: float
    width: int
    height: int


def _r(v: float) -> float:
    """A float for the JSON (plain Python float, -0.0 as 0.0)."""
    return float(v) + 0.0


def image_name(joint_name: str) -> str:
    """A joint's attachment file name stem: letters, digits, ``-``, ``_`` and ``.`` kept."""
    return re.sub(r"[^A-Za-z0-9_.-]", "_", joint_name) or "joint"


def regions(ch: Character, pixels_per_unit: float = PIXELS_PER_UNIT, margin: float = MARGIN) -> list[Region]:
    """The PNG attachment of every joint that has shapes, in joint (draw) order."""
    out: list[Region] = []
    used: set[str] = set()
    for i, j in enumerate(ch.joints):
        boxes = [s.bounds() for s in j.shapes if len(s.points)]
        if not boxes:
            continue
        b = np.array(boxes)
        x0, y0 = float(b[:, 0].min()) - margin, float(b[:, 1].min()) - margin
        x1, y1 = float(b[:, 2].max()) + margin, float(b[:, 3].max()) + margin
        w = max(1, math.ceil((x1 - x0) * pixels_per_unit))
        h = max(1, math.ceil((y1 - y0) * pixels_per_unit))
        # The rectangle is widened to whole pixels so that the image maps one to one onto it.
        x1, y1 = x0 + w / pixels_per_unit, y0 + h / pixels_per_unit
        stem = image_name(j.name)
        name, k = stem, 2
        while name.lower() in used:
            name, k = f"{stem}_{k}", k + 1
        used.add(name.lower())
        out.append(Region(i, j.name, name, x0, y0, x1, y1, w, h))
    return out


def _decompose(m: FloatArray) -> dict[str, float]:
    """A y-up 3×3 affine matrix as Spine's bone x, y, rotation, scaleX, scaleY, shearY."""
    a = m[:2, :2]
    col0, col1 = a[:, 0], a[:, 1]
    rot = math.degrees(math.atan2(col0[1], col0[0]))
    shear = math.degrees(math.atan2(col1[1], col1[0])) - rot - 90.0
    shear = (shear + 180.0) % 360.0 - 180.0
    return {"x": _r(m[0, 2]), "y": _r(m[1, 2]), "rotation": _r(rot), "scaleX": _r(np.hypot(*col0)),
            "scaleY": _r(np.hypot(*col1)), "shearY": _r(shear)}


FLIP = np.diag([1.0, -1.0, 1.0])


def _root_name(ch: Character) -> str:
    names = {j.name for j in ch.joints}
    name, k = "root", 2
    while name in names:
        name, k = f"root_{k}", k + 1
    return name


def frame_times(doc: Document) -> list[float]:
    """Document times of every frame of its range."""
    start, end = doc.frame_range
    return [doc.frame_to_time(f) for f in range(start, max(start, end) + 1)]


def spine_skeleton(doc: Document, asset_id: str, pixels_per_unit: float = PIXELS_PER_UNIT,
                   margin: float = MARGIN, images: str = "./images/") -> dict[str, Any]:
    """The Spine JSON data (a dict ready for :func:`json.dumps`) of one 2D character."""
    ch = character(doc, asset_id)
    pivots = ch.rest_pivots
    root = _root_name(ch)
    placement = placement_matrix(doc, asset_id)
    p_up = FLIP @ (np.eye(3) if placement is None else placement) @ FLIP
    root_bone: dict[str, Any] = {"name": root}
    root_bone.update({k: v for k, v in _decompose(p_up).items()
                      if abs(v - (1.0 if k.startswith("scale") else 0.0)) > 1e-12})
    bones: list[dict[str, Any]] = [root_bone]
    for i, j in enumerate(ch.joints):
        parent = root if j.parent is None else ch.joints[j.parent].name
        base = np.zeros(2) if j.parent is None else pivots[j.parent]
        d = pivots[i] - base
        length = float(np.hypot(*(pivots[j.children[0]] - pivots[i]))) if j.children else 0.0
        bones.append({"name": j.name, "parent": parent, "length": _r(length), "x": _r(d[0]), "y": _r(-d[1]),
                      "rotation": 0.0})
    regs = regions(ch, pixels_per_unit, margin)
    slots = [{"name": r.name, "bone": ch.joints[r.joint].name, "attachment": r.file} for r in regs]
    attachments: dict[str, Any] = {}
    for r in regs:
        c = pivots[r.joint]
        attachments[r.name] = {r.file: {
            "x": _r((r.x0 + r.x1) / 2 - c[0]), "y": _r(-((r.y0 + r.y1) / 2 - c[1])),
            "scaleX": _r(1.0 / pixels_per_unit), "scaleY": _r(1.0 / pixels_per_unit),
            "width": r.width, "height": r.height}}
    # Setup-pose bounds of the attachments (y up, through the placement).
    corners = []
    for r in regs:
        for x, y in ((r.x0, r.y0), (r.x1, r.y0), (r.x1, r.y1), (r.x0, r.y1)):
            corners.append(p_up @ np.array([x, -y, 1.0]))
    if corners:
        cs = np.array(corners)
        lo, hi = cs.min(axis=0), cs.max(axis=0)
    else:
        lo = hi = p_up @ np.array([pivots[0, 0], -pivots[0, 1], 1.0])
    start = doc.frame_range[0]
    t0 = doc.frame_to_time(start)
    rotate: list[list[dict[str, float]]] = [[] for _ in ch.joints]
    translate: list[dict[str, float]] = []
    for t in frame_times(doc):
        pose = evaluate_pose(doc, asset_id, t)
        st = _r(t - t0)
        for i, a in enumerate(pose.angles):
            rotate[i].append({"time": st, "value": _r(math.degrees(float(a)))})
        translate.append({"time": st, "x": _r(pose.translation[0]), "y": _r(-pose.translation[1])})
    timelines: dict[str, Any] = {}
    for i, j in enumerate(ch.joints):
        timelines[j.name] = {"rotate": rotate[i]}
    timelines[ch.joints[0].name]["translate"] = translate
    text = json.dumps([bones, slots, attachments], sort_keys=True)
    return {
        "skeleton": {"hash": hashlib.sha1(text.encode("utf-8")).hexdigest()[:16], "spine": SPINE_VERSION,
                     "x": _r(lo[0]), "y": _r(lo[1]), "width": _r(hi[0] - lo[0]), "height": _r(hi[1] - lo[1]),
                     "fps": _r(doc.fps), "images": images, "audio": ""},
        "bones": bones,
        "slots": slots,
        "skins": [{"name": "default", "attachments": attachments}],
        "animations": {asset_id: {"bones": timelines}},
    }


def write_spine_json(doc: Document, asset_id: str, path: str | os.PathLike[str],
                     pixels_per_unit: float = PIXELS_PER_UNIT, margin: float = MARGIN) -> dict[str, Any]:
    """Write the JSON part only (``NAME.json``); returns the data written."""
    data = spine_skeleton(doc, asset_id, pixels_per_unit, margin)
    write_text_atomic(path, json.dumps(data, indent=1) + "\n")  # atomic; a pipe or a device is refused
    return data
