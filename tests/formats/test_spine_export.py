"""Spine JSON export of 2D rigs (issue 15, item 7).

* Structure: the output is checked against Spine's published JSON format (Spine 4.x "JSON
  export format", esotericsoftware.com/spine-json-format): the required keys and their types
  for the skeleton, bones, slots, skins (region attachments) and animations (bone rotate /
  translate timelines), written here as schema checks.
* Poses: an evaluator of Spine's bone transforms written here (setup pose plus timelines,
  linear keys, Spine's local transform a = cos(r + shX)·sX, b = cos(r + 90 + shY)·sY,
  c = sin(r + shX)·sX, d = sin(r + 90 + shY)·sY, world = parent world · local) re-imports the
  bone hierarchy and animation; its world bone matrices (y flipped back to the rig's y down)
  are the program's (``character2d.evaluate_pose``: joint pivots and rotations, the authored
  placement included) at frames across the range, to 1e-6 of the character's size.
* Images: every attachment is a PNG of the declared size with something drawn on it.
"""

from __future__ import annotations

import json
import math
import re
import struct
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from docfix import set_parameters

from qtanimator.document import Document, UndoStack
from qtanimator.document.character2d import (
    add_characters_command,
    character,
    evaluate_pose,
    key_joint,
    move_character,
)
from qtanimator.document.placement import set_placement_command
from qtanimator.document.spine_export import MARGIN, PIXELS_PER_UNIT, regions, spine_skeleton, write_spine_json

TOLERANCE = 1e-6
NUMBER = (int, float)
TRANSFORMS = {"normal", "onlyTranslation", "noRotationOrReflection", "noScale", "noScaleOrReflection"}
BLENDS = {"normal", "additive", "multiply", "screen"}
BONE_TIMELINES = {"rotate", "translate", "translatex", "translatey", "scale", "scalex", "scaley", "shear",
                  "shearx", "sheary"}
BONE_NUMBERS = ("length", "x", "y", "rotation", "scaleX", "scaleY", "shearX", "shearY")
ATTACHMENT_NUMBERS = ("x", "y", "scaleX", "scaleY", "rotation", "width", "height")


# --------------------------------------------------------------------------- schema
def _number(v: Any) -> bool:
    return isinstance(v, NUMBER) and not isinstance(v, bool) and math.isfinite(v)


def _check_curve(key: dict[str, Any], where: str) -> None:
    curve = key.get("curve")
    assert curve is None or curve == "stepped" or (isinstance(curve, list) and all(map(_number, curve))), where


def check_spine_json(data: dict[str, Any]) -> None:
    """Spine 4.x JSON structure: required keys, their types and cross references."""
    assert isinstance(data, dict)
    assert set(data) <= {"skeleton", "bones", "slots", "ik", "transform", "path", "physics", "skins", "events",
                         "animations"}
    sk = data["skeleton"]
    assert isinstance(sk["hash"], str) and sk["hash"]
    assert isinstance(sk["spine"], str) and re.fullmatch(r"4\.\d+(\.\d+)?", sk["spine"])
    for k in ("x", "y", "width", "height"):
        assert _number(sk[k]), k
    assert sk["width"] >= 0 and sk["height"] >= 0
    assert _number(sk.get("fps", 30)) and sk.get("fps", 30) > 0
    assert isinstance(sk.get("images", ""), str) and isinstance(sk.get("audio", ""), str)

    bones = data["bones"]
    assert isinstance(bones, list) and bones
    seen: set[str] = set()
    for i, b in enumerate(bones):
        assert isinstance(b["name"], str) and b["name"] and b["name"] not in seen
        if i == 0:
            assert "parent" not in b, "the first bone is the root"
        else:
            assert isinstance(b["parent"], str) and b["parent"] in seen, "a bone's parent comes before it"
        for k in BONE_NUMBERS:
            assert _number(b.get(k, 0.0)), (b["name"], k)
        assert b.get("length", 0.0) >= 0
        assert b.get("transform", "normal") in TRANSFORMS
        assert isinstance(b.get("skin", False), bool)
        seen.add(b["name"])

    slots = data.get("slots", [])
    assert isinstance(slots, list)
    slot_names: set[str] = set()
    for s in slots:
        assert isinstance(s["name"], str) and s["name"] not in slot_names
        assert s["bone"] in seen
        assert s.get("attachment") is None or isinstance(s["attachment"], str)
        assert re.fullmatch(r"[0-9a-fA-F]{8}", s.get("color", "ffffffff"))
        assert s.get("blend", "normal") in BLENDS
        slot_names.add(s["name"])

    skins = data.get("skins", [])
    assert isinstance(skins, list)
    default = [sk for sk in skins if sk["name"] == "default"]
    assert len(default) <= 1
    for skin in skins:
        assert isinstance(skin["name"], str)
        for slot, atts in skin.get("attachments", {}).items():
            assert slot in slot_names
            for name, att in atts.items():
                assert isinstance(name, str)
                assert att.get("type", "region") == "region"
                assert isinstance(att.get("path", name), str)
                for k in ATTACHMENT_NUMBERS:
                    assert _number(att.get(k, 0.0)), (slot, name, k)
                assert att["width"] > 0 and att["height"] > 0
    for s in slots:
        if s.get("attachment") is not None:
            assert default and s["attachment"] in default[0]["attachments"].get(s["name"], {}), s["name"]

    animations = data.get("animations", {})
    assert isinstance(animations, dict)
    for anim_name, anim in animations.items():
        assert isinstance(anim_name, str) and isinstance(anim, dict)
        assert set(anim) <= {"slots", "bones", "ik", "transform", "path", "physics", "attachments", "drawOrder",
                             "events"}
        for bone, timelines in anim.get("bones", {}).items():
            assert bone in seen
            for kind, keys in timelines.items():
                assert kind in BONE_TIMELINES and isinstance(keys, list) and keys
                times = [k.get("time", 0.0) for k in keys]
                assert all(map(_number, times)) and times == sorted(times) and times[0] >= 0
                for key in keys:
                    if kind == "rotate" or kind in ("translatex", "translatey", "scalex", "scaley", "shearx",
                                                    "sheary"):
                        assert _number(key.get("value", 0.0))
                    else:
                        assert _number(key.get("x", 0.0)) and _number(key.get("y", 0.0))
                    _check_curve(key, f"{anim_name}/{bone}/{kind}")


# --------------------------------------------------------------------------- evaluator
def _linear(keys: list[dict[str, Any]], t: float, fields: tuple[str, ...]) -> list[float]:
    """A timeline's value at ``t``: linear between keys, held outside (Spine's default curve)."""
    times = [k.get("time", 0.0) for k in keys]
    if t <= times[0]:
        return [keys[0].get(f, 0.0) for f in fields]
    if t >= times[-1]:
        return [keys[-1].get(f, 0.0) for f in fields]
    i = int(np.searchsorted(times, t, side="right")) - 1
    a, b = keys[i], keys[i + 1]
    u = (t - times[i]) / (times[i + 1] - times[i])
    if a.get("curve") == "stepped":
        return [a.get(f, 0.0) for f in fields]
    return [a.get(f, 0.0) + u * (b.get(f, 0.0) - a.get(f, 0.0)) for f in fields]


def spine_world(data: dict[str, Any], animation: str, t: float) -> dict[str, np.ndarray]:
    """Each bone's 3×3 world matrix (y up) at time ``t`` of an animation."""
    timelines = data["animations"][animation].get("bones", {})
    world: dict[str, np.ndarray] = {}
    for b in data["bones"]:
        x, y, r = b.get("x", 0.0), b.get("y", 0.0), b.get("rotation", 0.0)
        sx, sy, shx, shy = b.get("scaleX", 1.0), b.get("scaleY", 1.0), b.get("shearX", 0.0), b.get("shearY", 0.0)
        tl = timelines.get(b["name"], {})
        if "rotate" in tl:
            r += _linear(tl["rotate"], t, ("value",))[0]
        if "translate" in tl:
            dx, dy = _linear(tl["translate"], t, ("x", "y"))
            x, y = x + dx, y + dy
        rx, ry = math.radians(r + shx), math.radians(r + 90.0 + shy)
        local = np.array([[math.cos(rx) * sx, math.cos(ry) * sy, x],
                          [math.sin(rx) * sx, math.sin(ry) * sy, y],
                          [0.0, 0.0, 1.0]])
        world[b["name"]] = local if "parent" not in b else world[b["parent"]] @ local
    return world


# --------------------------------------------------------------------------- cases
FLIP = np.diag([1.0, -1.0, 1.0])


def _posed(shared_data: Path, name: str, placed: bool) -> tuple[Document, str]:
    doc = Document()
    stack = UndoStack(doc)
    stack.push(add_characters_command(doc, shared_data / "cmu-animator" / "scenes" / name))
    aid = next(iter(doc.assets))
    ch = character(doc, aid)
    set_parameters(doc, {"frame_start": 5, "frame_end": 65})
    rng = np.random.default_rng(7)
    for frame in (5, 20, 40, 65):
        t = doc.frame_to_time(frame)
        for j in range(len(ch.joints)):
            if not ch.joints[j].is_dynamic:
                stack.push(key_joint(doc, aid, j, float(rng.uniform(-1.2, 1.2)), t))
        stack.push(move_character(doc, aid, rng.uniform(-40, 40, 2), t))
    if placed:
        stack.push(set_placement_command(doc, aid, {"translate": [30.0, -12.0], "rotate": 25.0, "scale": 0.8}))
    return doc, aid


def _size(doc: Document, aid: str) -> float:
    x0, y0, x1, y1 = character(doc, aid).bounds()
    return math.hypot(x1 - x0, y1 - y0)


@pytest.mark.parametrize(("name", "placed"), [("character.svg", False), ("character.svg", True),
                                              ("clock.svg", True)])
def test_spine_poses_match_the_program(shared_data: Path, tmp_path: Path, name: str, placed: bool) -> None:
    doc, aid = _posed(shared_data, name, placed)
    data = write_spine_json(doc, aid, tmp_path / "out.json")
    data = json.loads((tmp_path / "out.json").read_text(encoding="utf-8"))
    check_spine_json(data)
    ch = character(doc, aid)
    # The bone hierarchy comes back: one bone per joint, same parents, under the placement bone.
    root = data["bones"][0]["name"]
    parents = {b["name"]: b.get("parent") for b in data["bones"]}
    for j in ch.joints:
        assert parents[j.name] == (root if j.parent is None else ch.joints[j.parent].name)
    assert list(data["animations"]) == [aid]
    limit = TOLERANCE * _size(doc, aid)
    start, end = doc.frame_range
    for frame in sorted({start, 11, 20, 33, 47, 58, end}):
        t = doc.frame_to_time(frame)
        pose = evaluate_pose(doc, aid, t)
        world = spine_world(data, aid, t - doc.frame_to_time(start))
        for k, j in enumerate(ch.joints):
            frame_at_pivot = pose.world[k] @ np.array([[1.0, 0.0, ch.rest_pivots[k, 0]],
                                                      [0.0, 1.0, ch.rest_pivots[k, 1]], [0.0, 0.0, 1.0]])
            want = FLIP @ frame_at_pivot @ FLIP
            got = world[j.name]
            assert np.abs(got[:2, 2] - want[:2, 2]).max() <= limit, (frame, j.name, got[:2, 2], want[:2, 2])
            np.testing.assert_allclose(got[:2, 2], [pose.pivots[k, 0], -pose.pivots[k, 1]], atol=limit)
            np.testing.assert_allclose(got[:2, :2], want[:2, :2], atol=1e-9, err_msg=f"{frame} {j.name}")


def test_attachments_sit_on_the_drawing(shared_data: Path) -> None:
    """A region attachment's centre, carried by its bone's world matrix, is where the program
    puts the centre of the joint's image rectangle, which covers its drawing."""
    doc, aid = _posed(shared_data, "character.svg", True)
    data = spine_skeleton(doc, aid)
    check_spine_json(data)
    ch = character(doc, aid)
    t = doc.frame_to_time(33)
    pose = evaluate_pose(doc, aid, t)
    world = spine_world(data, aid, t - doc.frame_to_time(doc.frame_range[0]))
    atts = data["skins"][0]["attachments"]
    assert [s["name"] for s in data["slots"]] == [j.name for j in ch.joints if j.shapes]
    rects = {r.name: r for r in regions(ch)}
    limit = TOLERANCE * _size(doc, aid)
    for s in data["slots"]:
        k = ch.joint_index(s["bone"])
        att = atts[s["name"]][s["attachment"]]
        b = np.array([sh.bounds() for sh in ch.joints[k].shapes])
        r = rects[s["name"]]
        # The image covers the drawing with its margin, widened to whole pixels (under one).
        assert r.x0 < b[:, 0].min() and r.y0 < b[:, 1].min() and r.x1 > b[:, 2].max() and r.y1 > b[:, 3].max()
        assert att["width"] * att["scaleX"] == pytest.approx(r.x1 - r.x0)
        assert att["height"] * att["scaleY"] == pytest.approx(r.y1 - r.y0)
        assert (r.x1 - r.x0) - (b[:, 2].max() - b[:, 0].min()) < 2 * MARGIN + 1.0 / PIXELS_PER_UNIT
        centre = np.array([(r.x0 + r.x1) / 2, (r.y0 + r.y1) / 2])
        got = world[s["bone"]] @ np.array([att["x"], att["y"], 1.0])
        want = pose.to_world(k, centre)
        assert np.abs(got[:2] - [want[0], -want[1]]).max() <= limit, s["name"]


def _png_size(path: Path) -> tuple[int, int]:
    head = path.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n" and head[12:16] == b"IHDR"
    w, h = struct.unpack(">II", head[16:24])
    return int(w), int(h)


def test_export_writes_png_attachments(qapp, shared_data: Path, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    from PySide6.QtGui import QImage

    from qtanimator.render.spine_images import export_spine

    doc, aid = _posed(shared_data, "character.svg", False)
    data = export_spine(doc, aid, tmp_path / "character.json")
    check_spine_json(data)
    assert json.loads((tmp_path / "character.json").read_text(encoding="utf-8")) == data
    for slot, atts in data["skins"][0]["attachments"].items():
        for name, att in atts.items():
            png = tmp_path / "images" / f"{att.get('path', name)}.png"
            assert _png_size(png) == (att["width"], att["height"]), slot
            image = QImage(str(png))
            alpha = [image.pixelColor(x, y).alpha() for y in range(0, image.height(), 3)
                     for x in range(0, image.width(), 3)]
            assert max(alpha) > 0, f"{slot}: nothing drawn"
