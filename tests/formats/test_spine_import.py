"""Spine JSON import onto a 2D character (issue 15, item 7: re-import the bone hierarchy and
animation here to compare poses): :mod:`qtanimator.formats.spine` and
:mod:`qtanimator.document.spine_import`.

* Round trip: a posed character exported with ``spine_export.write_spine_json`` and imported
  onto a fresh copy of the same character shows the same pose
  (``character2d.evaluate_pose``: joint pivots and world rotations) at every frame of the
  range, to 1e-6 of the character's size, unplaced and placed (the placement given to the
  copy, or taken from the file's placement bone).
* A hand-written file with a step, a Bézier span with handles at the thirds (a Hermite span),
  one with handles at the halves (weighted tangents) and one whose handles overlap (sampled):
  values at chosen times computed here in closed form.
* FormatError cases name the file; undo restores channels, range and placement exactly.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from qtanimator.document import Document, UndoStack
from qtanimator.document.character2d import (
    add_characters_command,
    angle_channel_id,
    character,
    evaluate_pose,
    key_joint,
    move_character,
    position_channel_ids,
)
from qtanimator.document.commands import SetParameter
from qtanimator.document.placement import PLACEMENT, set_placement_command
from qtanimator.document.spine_export import spine_skeleton, write_spine_json
from qtanimator.document.spine_import import spine_import_command
from qtanimator.formats import FormatError
from qtanimator.formats.info import summarize
from qtanimator.formats.spine import read_spine

TOLERANCE = 1e-6
PLACEMENT_VALUE: dict[str, Any] = {"translate": [30.0, -12.0], "rotate": 25.0, "scale": 0.8}


def _fresh(shared_data: Path, name: str) -> tuple[Document, UndoStack, str]:
    doc = Document()
    stack = UndoStack(doc)
    stack.push(add_characters_command(doc, shared_data / "cmu-animator" / "scenes" / name))
    return doc, stack, next(iter(doc.assets))


def _set_range(stack: UndoStack, doc: Document, first: int, last: int) -> None:
    """The frame range through commands (the document's parameters are read only)."""
    stack.push(SetParameter(doc, "frame_end", max(last, doc.frame_range[1])))
    stack.push(SetParameter(doc, "frame_start", first))
    stack.push(SetParameter(doc, "frame_end", last))


def _posed(shared_data: Path, name: str, placed: bool) -> tuple[Document, str]:
    """As tests/formats/test_spine_export.py poses its characters."""
    doc, stack, aid = _fresh(shared_data, name)
    ch = character(doc, aid)
    _set_range(stack, doc, 5, 65)
    rng = np.random.default_rng(7)
    for frame in (5, 20, 40, 65):
        t = doc.frame_to_time(frame)
        for j in range(len(ch.joints)):
            if not ch.joints[j].is_dynamic:
                stack.push(key_joint(doc, aid, j, float(rng.uniform(-1.2, 1.2)), t))
        stack.push(move_character(doc, aid, rng.uniform(-40, 40, 2), t))
    if placed:
        stack.push(set_placement_command(doc, aid, PLACEMENT_VALUE))
    return doc, aid


def _size(doc: Document, aid: str) -> float:
    x0, y0, x1, y1 = character(doc, aid).bounds()
    return math.hypot(x1 - x0, y1 - y0)


# --------------------------------------------------------------------------- round trip
@pytest.mark.parametrize(("name", "placed", "from_file"), [
    ("arm.svg", False, False), ("arm.svg", True, False), ("arm.svg", True, True),
    ("character.svg", False, False), ("character.svg", True, True)])
def test_round_trip_poses_match(shared_data: Path, tmp_path: Path, name: str, placed: bool,
                                from_file: bool) -> None:
    doc, aid = _posed(shared_data, name, placed)
    write_spine_json(doc, aid, tmp_path / "out.json")
    ch = character(doc, aid)

    copy, stack, cid = _fresh(shared_data, name)
    _set_range(stack, copy, 5, 30)  # grown by the import
    if placed and not from_file:
        stack.push(set_placement_command(copy, cid, PLACEMENT_VALUE))
    cmd = spine_import_command(copy, cid, tmp_path / "out.json", placement=from_file)
    stack.push(cmd)
    assert copy.frame_range == doc.frame_range
    assert cmd.animation == aid and cmd.unmatched == []
    assert cmd.matched == [j.name for j in ch.joints]
    dynamic = [j.name for j in ch.joints if j.is_dynamic]
    assert cmd.skipped == dynamic
    if from_file:
        got = copy.assets[cid].properties[PLACEMENT]
        np.testing.assert_allclose(got["translate"], PLACEMENT_VALUE["translate"], atol=1e-9)
        assert got["rotate"] == pytest.approx(PLACEMENT_VALUE["rotate"], abs=1e-9)
        assert got["scale"] == pytest.approx(PLACEMENT_VALUE["scale"], abs=1e-12)
    # Pendulum joints follow the simulation (driven by slightly different parent curves
    # between frames); every other joint is compared.
    compared = [k for k in range(len(ch.joints)) if not ch.dynamic[ch.ancestors(k) + [k]].any()]
    assert len(compared) >= 6
    limit = TOLERANCE * _size(doc, aid)
    start, end = doc.frame_range
    for frame in range(start, end + 1):
        t = doc.frame_to_time(frame)
        want, got_pose = evaluate_pose(doc, aid, t), evaluate_pose(copy, cid, t)
        for k in compared:
            assert np.abs(got_pose.pivots[k] - want.pivots[k]).max() <= limit, (frame, ch.joints[k].name)
            np.testing.assert_allclose(got_pose.world[k][:2, :2], want.world[k][:2, :2], atol=1e-9,
                                       err_msg=f"{frame} {ch.joints[k].name}")


def test_keys_are_radians_and_y_down(shared_data: Path, tmp_path: Path) -> None:
    """Read data (a SpineData, not a path) is accepted; each frame's key holds the angle in
    radians and the translation with y down, at the document's time of that frame."""
    doc, aid = _posed(shared_data, "arm.svg", False)
    data = spine_skeleton(doc, aid)
    path = tmp_path / "arm.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    copy, stack, cid = _fresh(shared_data, "arm.svg")
    _set_range(stack, copy, 5, 65)
    stack.push(spine_import_command(copy, cid, read_spine(path)))
    ch = character(doc, aid)
    start = doc.frame_range[0]
    for frame in (5, 6, 20, 64, 65):
        t = doc.frame_to_time(frame)
        i = frame - start
        for j in ch.joints:
            key = copy.channels[angle_channel_id(cid, j.name)].keys[i]
            assert key.time == pytest.approx(t, abs=1e-12)
            assert key.value == pytest.approx(math.radians(data["animations"][aid]["bones"][j.name]["rotate"][i]
                                                           ["value"]), abs=1e-15)
            assert key.value == pytest.approx(doc.channels[angle_channel_id(aid, j.name)].evaluate(t), abs=1e-12)
        cx, cy = (copy.channels[c].keys[i] for c in position_channel_ids(cid))
        want = doc.channels[position_channel_ids(aid)[1]].evaluate(t)
        assert cy.value == pytest.approx(want, abs=1e-9) and want != 0.0
        assert cx.value == pytest.approx(doc.channels[position_channel_ids(aid)[0]].evaluate(t), abs=1e-9)


# --------------------------------------------------------------------------- hand-written curves
T0_FRAME = 10  # the document's range start: Spine time 0


def _bernstein(u: float, p0: float, p1: float, p2: float, p3: float) -> float:
    w = 1.0 - u
    return w ** 3 * p0 + 3 * w * w * u * p1 + 3 * w * u * u * p2 + u ** 3 * p3


def _hand_file(tmp_path: Path) -> Path:
    data: dict[str, Any] = {
        "skeleton": {"hash": "x", "spine": "4.1.24", "fps": 30},
        "bones": [{"name": "root_2"}, {"name": "root", "parent": "root_2", "x": 3.0, "y": -4.0},
                  {"name": "joint1", "parent": "root", "x": 10.0, "length": 5.0},
                  {"name": "extra", "parent": "root"}],
        "animations": {"wave": {"bones": {
            "joint1": {
                "rotate": [
                    {"time": 0.25, "value": 10.0, "curve": "stepped"},
                    # handles at the thirds of 0.75 … 1.25: a Hermite span
                    {"time": 0.75, "value": 40.0, "curve": [0.75 + 0.5 / 3, 70.0, 0.75 + 1.0 / 3, 0.0]},
                    # handles at the halves of 1.25 … 1.75: weighted tangents
                    {"time": 1.25, "value": -20.0, "curve": [1.5, 0.0, 1.5, 50.0]},
                    {"time": 1.75, "value": 30.0}],
                "scale": [{"time": 0, "x": 2.0}]},
            "root": {"translate": [
                {"time": 0.0},
                {"time": 1.0, "x": 10.0, "y": 20.0, "curve": "stepped"},
                # x: handles overlapping in time (sampled); y: handles at the thirds
                {"time": 1.5, "x": -5.0, "y": -5.0,
                 "curve": [1.9, 0.0, 1.6, 10.0, 1.5 + 0.5 / 3, 0.0, 1.5 + 1.0 / 3, 0.0]},
                {"time": 2.0, "x": 5.0, "y": 5.0}]},
            "extra": {"rotate": [{"time": 0.0, "value": 5.0}]},
        }, "slots": {}}},
    }
    path = tmp_path / "hand.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    return path


def _expected_rotation(s: float) -> float:
    """joint1's rotation (degrees) at Spine time ``s``, in closed form."""
    if s < 0.25:
        return 0.0  # the setup pose before the first key
    if s < 0.75:
        return 10.0  # stepped
    if s < 1.25:  # x linear in u: u = (s − 0.75) / 0.5
        return _bernstein((s - 0.75) / 0.5, 40.0, 70.0, 0.0, -20.0)
    raise AssertionError("use the chosen times below")


# Handles at the halves: x(u)/Δ = 1.5u − 1.5u² + u³, so u = 1/4 at x/Δ = 0.296875 and u = 1/2 at 1/2.
HALVES = [(1.25 + 0.5 * 0.296875, (27 * -20.0 + 27 * 0.0 + 9 * 50.0 + 30.0) / 64),
          (1.5, (-20.0 + 0.0 + 150.0 + 30.0) / 8), (1.75, 30.0), (3.0, 30.0)]
CHOSEN = [0.0, 0.1, 0.25, 0.5, 0.74, 0.75, 0.8, 0.875, 1.0, 1.2]


def test_hand_written_curves(shared_data: Path, tmp_path: Path) -> None:
    path = _hand_file(tmp_path)
    data = read_spine(path)
    assert [b.name for b in data.bones] == ["root_2", "root", "joint1", "extra"]
    assert data.bones[2].parent == "root" and data.bones[2].x == 10.0 and data.bones[2].length == 5.0
    anim = data.animations["wave"]
    assert anim.duration == 2.0
    assert set(anim.ignored) == {"slots", "joint1/scale"}
    rot = anim.bones["joint1"]["rotate"]
    cases = [(s, _expected_rotation(s)) for s in CHOSEN] + HALVES
    for s, want in cases:
        assert rot.evaluate(s)[0] == pytest.approx(want, abs=1e-9), s

    doc, stack, aid = _fresh(shared_data, "simple.svg")
    assert [j.name for j in character(doc, aid).joints] == ["root", "joint1"]
    _set_range(stack, doc, T0_FRAME, 50)
    cmd = spine_import_command(doc, aid, path)
    stack.push(cmd)
    assert cmd.animation == "wave" and cmd.unmatched == ["extra"] and cmd.skipped == []
    assert any("'extra'" in n for n in cmd.notes) and any("sampled" in n for n in cmd.notes)
    assert any("joint1/scale" in n for n in cmd.notes)
    fps = doc.fps
    assert doc.frame_range == (T0_FRAME, T0_FRAME + math.ceil(2.0 * fps))
    t0 = doc.frame_to_time(T0_FRAME)
    channel = doc.channels[angle_channel_id(aid, "joint1")]
    for s, want in cases:
        assert channel.evaluate(t0 + s) == pytest.approx(math.radians(want), abs=1e-9), s
        assert evaluate_pose(doc, aid, t0 + s).angles[1] == pytest.approx(math.radians(want), abs=1e-9), s
    cx, cy = (doc.channels[c] for c in position_channel_ids(aid))
    for s, x, y in [(0.0, 0.0, 0.0), (0.5, 5.0, 10.0), (0.9, 9.0, 18.0), (1.0, 10.0, 20.0), (1.2, 10.0, 20.0),
                    (1.5, -5.0, -5.0), (2.0, 5.0, 5.0), (2.5, 5.0, 5.0)]:
        assert cx.evaluate(t0 + s) == pytest.approx(x, abs=1e-9), s
        assert cy.evaluate(t0 + s) == pytest.approx(-y, abs=1e-9), s  # y down
    # y between 1.5 and 2.0: handles at the thirds with values 0, 0 → closed form.
    tl = anim.bones["root"]["translate"]
    for u in (0.1, 0.4, 0.75):
        s = 1.5 + 0.5 * u
        want_y = _bernstein(u, -5.0, 0.0, 0.0, 5.0)
        assert tl.evaluate(s)[1] == pytest.approx(want_y, abs=1e-9)
        assert cy.evaluate(t0 + s) == pytest.approx(-want_y, abs=1e-9)
        # x: handles overlapping in time are sampled densely (close, not exact).
        assert cx.evaluate(t0 + s) == pytest.approx(tl.evaluate(s)[0], abs=0.05)


def test_no_matching_bone_is_refused(shared_data: Path, tmp_path: Path) -> None:
    path = tmp_path / "other.json"
    path.write_text(json.dumps({"skeleton": {"spine": "4.2.0"}, "bones": [{"name": "hip"}, {"name": "knee",
                                "parent": "hip"}], "animations": {"walk": {}}}), encoding="utf-8")
    doc, _stack, aid = _fresh(shared_data, "arm.svg")
    with pytest.raises(ValueError, match="hip, knee"):
        spine_import_command(doc, aid, path)
    with pytest.raises(ValueError, match="no animation 'run'"):
        spine_import_command(doc, aid, _hand_file(tmp_path), animation="run")


# --------------------------------------------------------------------------- errors
GOOD_BONES = [{"name": "root"}, {"name": "a", "parent": "root"}]


@pytest.mark.parametrize(("content", "message"), [
    ("{\"bones\": [", "not valid JSON"),
    ("[1, 2]", "not an object"),
    (json.dumps({"skeleton": {"spine": "4.1"}}), "no \"bones\""),
    (json.dumps({"bones": [{"name": "root"}, {"name": "a", "parent": "nope"}]}), "'nope', which is not a bone"),
    (json.dumps({"bones": [{"name": "root"}, {"name": "a", "parent": "b"}, {"name": "b", "parent": "root"}]}),
     "comes after it"),
    (json.dumps({"bones": [{"name": "root", "x": "abc"}]}), "\"x\" must be a number"),
    (json.dumps({"bones": [{"name": "root", "rotation": True}]}), "\"rotation\" must be a number"),
    (json.dumps({"bones": GOOD_BONES, "animations": {"w": {"bones": {"a": {"rotate": [
        {"time": 1.0, "value": 1}, {"time": 0.5, "value": 2}]}}}}}), "key times must be in order"),
    (json.dumps({"bones": GOOD_BONES, "animations": {"w": {"bones": {"a": {"rotate": [
        {"time": 0.0, "value": "9"}]}}}}}), "\"value\" must be a number"),
    (json.dumps({"bones": GOOD_BONES, "animations": {"w": {"bones": {"a": {"translate": [
        {"time": 0.0, "curve": [0.1, 0, 0.2, 0]}, {"time": 1.0}]}}}}}), "needs 8 numbers"),
    (json.dumps({"bones": GOOD_BONES, "animations": {"w": {"bones": {"zz": {"rotate": []}}}}}),
     "the bone 'zz'"),
    (json.dumps({"skeleton": {"spine": "3.8.99"}, "bones": GOOD_BONES}), "Spine 3.8.99"),
    ("NaN", "NaN"),
])
def test_format_errors_name_the_file(tmp_path: Path, content: str, message: str) -> None:
    path = tmp_path / "broken_rig.json"
    path.write_text(content, encoding="utf-8")
    with pytest.raises(FormatError) as info:
        read_spine(path)
    assert info.value.path == str(path)
    assert str(info.value).startswith("broken_rig.json")
    assert message in str(info.value)


def test_format_error_line_of_bad_json(tmp_path: Path) -> None:
    path = tmp_path / "cut.json"
    path.write_text("{\n \"bones\": [\n  {\"name\": \"root\"},\n", encoding="utf-8")
    with pytest.raises(FormatError) as info:
        read_spine(path)
    assert info.value.line is not None and "cut.json, line" in str(info.value)


def test_info_summarizes_spine_and_still_projects(shared_data: Path, tmp_path: Path) -> None:
    out = summarize(_hand_file(tmp_path))
    assert out["kind"] == "Spine skeleton" and out["bones"] == 4 and out["spine"] == "4.1.24"
    assert out["animations"]["wave"]["duration"] == 2.0
    from qtanimator.document import save_document

    doc, _stack, _aid = _fresh(shared_data, "arm.svg")
    save_document(doc, tmp_path / "project.json")
    assert summarize(tmp_path / "project.json")["kind"] == "qtanimator project"
    (tmp_path / "plain.json").write_text("{\"bones\": []}", encoding="utf-8")
    with pytest.raises(FormatError, match="not a qtanimator project"):
        summarize(tmp_path / "plain.json")


# --------------------------------------------------------------------------- undo
def test_undo_restores_channels_exactly(shared_data: Path, tmp_path: Path) -> None:
    src, aid = _posed(shared_data, "arm.svg", True)
    write_spine_json(src, aid, tmp_path / "out.json")
    doc, stack, cid = _fresh(shared_data, "arm.svg")
    _set_range(stack, doc, 5, 30)
    stack.push(key_joint(doc, cid, 2, 0.7, doc.frame_to_time(12)))
    stack.push(move_character(doc, cid, [3.0, 4.0], doc.frame_to_time(7)))
    before = dict(doc.channels)
    params = dict(doc.parameters)
    props = dict(doc.assets[cid].properties)
    stack.push(spine_import_command(doc, cid, tmp_path / "out.json", placement=True))
    after = dict(doc.channels)
    assert after != before and doc.frame_range == (5, 65) and PLACEMENT in doc.assets[cid].properties
    stack.undo()
    assert dict(doc.channels) == before
    assert all(doc.channels[c] is before[c] for c in before)
    assert dict(doc.parameters) == params and dict(doc.assets[cid].properties) == props
    stack.redo()
    assert dict(doc.channels) == after
