"""Rigging an ordinary drawing inside the program: Qt-free commands, undo, save and reopen."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from samples import PLAIN_DRAWING

from qtanimator.core.channel import Key
from qtanimator.document import Document, SetKeys, UndoStack, open_document, save_document
from qtanimator.document.character2d import add_characters_command, angle_channel_id, character
from qtanimator.document.rigging import (
    RIG_PROPERTY,
    RigError,
    candidates,
    make_joint_from_candidate,
    remove_joint_command,
    reparent_command,
    set_dynamic_command,
    set_pivot_command,
)
from qtanimator.formats.svg_rig import parse_character

DRAWING = PLAIN_DRAWING  # a <path> first, an empty first layer, then three layers


def make(tmp_path: Path) -> tuple[Document, UndoStack, str]:
    path = tmp_path / "plain.svg"
    path.write_text(DRAWING)
    doc = Document()
    stack = UndoStack(doc)
    stack.push(add_characters_command(doc, path))
    return doc, stack, next(iter(doc.assets))


def shape(doc: Document, aid: str) -> list[tuple[str, str | None, tuple[float, float], bool]]:
    ch = character(doc, aid)
    return [(j.name, None if j.parent is None else ch.joints[j.parent].name,
             (round(float(j.pivot[0]), 6), round(float(j.pivot[1]), 6)), j.is_dynamic) for j in ch.joints]


def test_the_plain_drawing_opens_as_one_joint_with_its_layers_offered(tmp_path: Path) -> None:
    doc, _stack, aid = make(tmp_path)
    assert [j.name for j in character(doc, aid).joints] == ["drawing"]
    assert candidates(doc, aid) == ["Body", "Arm", "Hat"]  # the empty layer is not offered


def test_rigging_undo_save_and_reopen(tmp_path: Path) -> None:
    doc, stack, aid = make(tmp_path)
    save_document(doc, tmp_path / "before.qtanim")
    unrigged = doc.state()
    stack.push(make_joint_from_candidate(doc, aid, "Body"))
    stack.push(make_joint_from_candidate(doc, aid, "Arm"))
    # New joints hang from the root, pivots at the centre of their boxes; the root keeps the
    # centre of the whole drawing (x 10..150, y 10..130).
    assert shape(doc, aid) == [("drawing", None, (80.0, 70.0), False), ("Body", "drawing", (70.0, 90.0), False),
                               ("Arm", "drawing", (120.0, 65.0), False)]
    assert candidates(doc, aid) == ["Hat"]
    ch = character(doc, aid)
    # The root keeps what no joint claims: the triangle and the hat (area 200 + 200).
    assert ch.joints[0].mass == pytest.approx(200.0 + 200.0)
    assert ch.joints[1].mass == pytest.approx(40 * 80) and ch.joints[2].mass == pytest.approx(60 * 10)
    assert "layer1" in (ch.joints[1].svg or "") and "layer1" not in (ch.joints[0].svg or "")
    stack.push(SetKeys(doc, {angle_channel_id(aid, "Arm"): Key(0.0, 0.5)}))
    stack.push(set_pivot_command(doc, aid, "Arm", (92.0, 65.0)))
    stack.push(reparent_command(doc, aid, "Arm", "Body"))
    stack.push(set_dynamic_command(doc, aid, "Arm", True))
    rigged = shape(doc, aid)
    assert rigged == [("drawing", None, (80.0, 70.0), False), ("Body", "drawing", (70.0, 90.0), False),
                      ("Arm", "Body", (92.0, 65.0), True)]
    assert angle_channel_id(aid, "Arm") in doc.channels  # the channel of a joint keeping its name stays
    # Save, reopen: the same rig, and the SVG file is untouched.
    save_document(doc, tmp_path / "rigged.qtanim")
    assert (tmp_path / "plain.svg").read_text() == DRAWING
    again = open_document(tmp_path / "rigged.qtanim")
    assert shape(again, aid) == rigged
    np.testing.assert_allclose([j.mass for j in character(again, aid).joints],
                               [j.mass for j in character(doc, aid).joints])
    # Undo everything: the unrigged document, byte for byte once saved.
    while stack.undo():
        if not doc.assets:
            stack.redo()
            break
    assert doc.state() == unrigged
    assert RIG_PROPERTY not in doc.assets[aid].properties
    assert shape(doc, aid) == [("drawing", None, (80.0, 70.0), False)]
    save_document(doc, tmp_path / "after.qtanim")
    assert (tmp_path / "after.qtanim").read_bytes() == (tmp_path / "before.qtanim").read_bytes()


def test_each_command_undoes_exactly(tmp_path: Path) -> None:
    doc, stack, aid = make(tmp_path)
    stack.push(make_joint_from_candidate(doc, aid, "Body"))
    stack.push(make_joint_from_candidate(doc, aid, "Arm", parent="Body"))
    stack.push(SetKeys(doc, {angle_channel_id(aid, "Arm"): Key(0.0, 0.5)}))
    for command in (lambda: set_pivot_command(doc, aid, "Body", (1.0, 2.0)),
                    lambda: set_dynamic_command(doc, aid, "Arm", True),
                    lambda: reparent_command(doc, aid, "Arm", "drawing"),
                    lambda: remove_joint_command(doc, aid, "Body"),
                    lambda: make_joint_from_candidate(doc, aid, "Hat", parent="Arm")):
        before, joints = doc.state(), shape(doc, aid)
        stack.push(command())
        assert doc.state() != before
        stack.undo()
        assert doc.state() == before and shape(doc, aid) == joints
        stack.redo()
        stack.undo()
    stack.push(remove_joint_command(doc, aid, "Body"))
    assert shape(doc, aid)[1][:2] == ("Arm", "drawing")  # Body's child hangs from its parent now
    stack.push(remove_joint_command(doc, aid, "Arm"))
    assert angle_channel_id(aid, "Arm") not in doc.channels
    stack.undo()
    assert [(k.time, k.value) for k in doc.channels[angle_channel_id(aid, "Arm")].keys] == [(0.0, 0.5)]


def test_a_pivot_drag_is_one_step_and_refusals_say_why(tmp_path: Path) -> None:
    doc, stack, aid = make(tmp_path)
    stack.push(make_joint_from_candidate(doc, aid, "Body"))
    stack.push(make_joint_from_candidate(doc, aid, "Arm", parent="Body"))
    steps = len(stack.done)
    for x in (71.0, 72.0, 75.0):
        stack.push(set_pivot_command(doc, aid, "Body", (x, 90.0), gesture="drag"))
    assert len(stack.done) == steps + 1 and shape(doc, aid)[1][2] == (75.0, 90.0)
    stack.undo()
    assert shape(doc, aid)[1][2] == (70.0, 90.0)
    with pytest.raises(RigError, match="hang from itself"):
        reparent_command(doc, aid, "Body", "Arm")
    with pytest.raises(RigError, match="root"):
        set_dynamic_command(doc, aid, "drawing", True)
    with pytest.raises(RigError, match="root"):
        remove_joint_command(doc, aid, "drawing")
    with pytest.raises(RigError, match="already"):
        make_joint_from_candidate(doc, aid, "Body")


def test_a_rigged_scene_rebuilds_the_same_from_its_derived_spec(shared_data: Path) -> None:
    path = shared_data / "cmu-animator" / "scenes" / "owl.svg"
    if not path.exists():
        path = next((shared_data / "cmu-animator").rglob("owl.svg"))
    data = path.read_bytes()
    ch = parse_character(data, "owl", path)
    again = parse_character(data, "owl", path, rig=ch.rig_spec)
    assert [(j.name, j.parent, j.is_dynamic) for j in again.joints] == [(j.name, j.parent, j.is_dynamic)
                                                                           for j in ch.joints]
    np.testing.assert_allclose(again.rest_pivots, ch.rest_pivots)
    np.testing.assert_allclose([j.mass for j in again.joints], [j.mass for j in ch.joints])
