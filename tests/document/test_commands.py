"""Commands one by one: do / undo / merge, gestures, change events."""

from __future__ import annotations

import math

import pytest

from qtanimator.core.channel import Channel, Key, Tangent
from qtanimator.document import (
    AddAsset,
    Asset,
    DeleteKeys,
    Document,
    DocumentChange,
    EditKey,
    InsertKey,
    Macro,
    MoveKeys,
    RemoveAsset,
    SetAssetProperty,
    SetExtrapolation,
    SetParameter,
    SetTangents,
    UndoStack,
    channel_id,
    split_channel_id,
)


def doc_with_keys() -> tuple[Document, UndoStack]:
    doc = Document()
    stack = UndoStack(doc)
    for t, v in [(0.0, 0.0), (1.0, 2.0), (2.0, 1.0), (3.0, 4.0)]:
        stack.push(InsertKey(doc, "hero//x", Key(t, v)))
    return doc, stack


def test_channel_ids_round_trip():
    assert channel_id("hero", "", "x") == "hero//x"
    assert split_channel_id("hero//x") == ("hero", "", "x")
    assert split_channel_id(channel_id("wasp", "leg/upper", "rz")) == ("wasp", "leg/upper", "rz")
    with pytest.raises(ValueError):
        channel_id("a/b", "", "x")


def test_a_drag_is_one_undo_step_and_the_last_offset_wins():
    doc, stack = doc_with_keys()
    base = dict(doc.channels)
    steps = len(stack.done)
    for i in range(1, 6):
        stack.push(MoveKeys(base, {"hero//x": [1, 2]}, 0.1 * i, -0.5 * i, gesture="drag"))
    assert len(stack.done) == steps + 1
    keys = doc.channels["hero//x"].keys
    assert keys[1].time == pytest.approx(1.5) and keys[1].value == pytest.approx(-0.5)
    assert keys[2].time == pytest.approx(2.5) and keys[2].value == pytest.approx(-1.5)
    stack.undo()
    assert doc.channels["hero//x"] == base["hero//x"]


def test_a_drag_back_to_the_start_leaves_no_step():
    doc, stack = doc_with_keys()
    base = dict(doc.channels)
    steps = len(stack.done)
    stack.push(MoveKeys(base, {"hero//x": [1]}, 0.2, 1.0, gesture="drag"))
    stack.push(MoveKeys(base, {"hero//x": [1]}, 0.0, 0.0, gesture="drag"))
    assert len(stack.done) == steps
    assert doc.channels == base


def test_commands_without_a_gesture_do_not_merge():
    doc = Document()
    stack = UndoStack(doc)
    stack.push(SetParameter(doc, "fps", 24))
    stack.push(SetParameter(doc, "fps", 30))
    assert len(stack.done) == 2
    stack.undo()
    assert doc.fps == 24
    stack.push(SetParameter(doc, "fps", 25, gesture="slider"))
    stack.push(SetParameter(doc, "fps", 26, gesture="slider"))
    assert len(stack.done) == 2 and doc.fps == 26
    stack.undo()
    assert doc.fps == 24


def test_a_command_that_changes_nothing_is_not_recorded():
    doc = Document()
    stack = UndoStack(doc)
    stack.push(SetParameter(doc, "fps", 60.0))
    stack.push(DeleteKeys(doc, {"nothing//x": [0]}))
    assert stack.done == []


def test_move_onto_another_key_is_refused():
    doc, _ = doc_with_keys()
    with pytest.raises(ValueError):
        MoveKeys(dict(doc.channels), {"hero//x": [1]}, 1.0, 0.0)


def test_move_keys_past_each_other_and_scale_time():
    doc, stack = doc_with_keys()
    stack.push(MoveKeys(dict(doc.channels), {"hero//x": [0]}, 1.5, 0.0))
    assert [k.time for k in doc.channels["hero//x"].keys] == [1.0, 1.5, 2.0, 3.0]
    stack.push(MoveKeys(dict(doc.channels), {"hero//x": [0, 1, 2, 3]}, 0.0, 0.0, time_scale=(1.0, 2.0)))
    assert [k.time for k in doc.channels["hero//x"].keys] == [1.0, 2.0, 3.0, 5.0]


def test_edit_key_tangents_and_extrapolation():
    doc, stack = doc_with_keys()
    before = doc.state()
    stack.push(EditKey(doc, "hero//x", 1, Key.make(1.0, 5.0, "flat", 2.0)))
    assert doc.channels["hero//x"].evaluate(1.0) == 5.0
    stack.push(SetTangents(doc, {"hero//x": [2]}, "fixed", side="out"))
    k = doc.channels["hero//x"].keys[2]
    assert k.in_tangent is Tangent.SMOOTH and k.out_tangent is Tangent.FIXED
    # Fixing a tangent keeps the slope it had, so the curve does not jump.
    assert stack.done[-1].changes["hero//x"][0].slopes()[1][2] == pytest.approx(k.out_slope)
    stack.push(SetExtrapolation(doc, ["hero//x"], post="cycle"))
    assert doc.channels["hero//x"].evaluate(3.5) == pytest.approx(doc.channels["hero//x"].evaluate(0.5))
    while stack.undo():
        pass
    stack.redo(), stack.redo(), stack.redo(), stack.redo()  # the four inserts
    assert doc.state() == before


def test_change_events_say_from_when_a_channel_changed():
    doc, stack = doc_with_keys()
    events: list[DocumentChange] = []
    doc.subscribe(events.append)
    stack.push(EditKey(doc, "hero//x", 3, Key(3.0, 9.0)))
    assert dict(events[-1].channels) == {"hero//x": 1.0}  # smooth tangents reach back one span further
    stack.push(SetExtrapolation(doc, ["hero//x"], post="linear"))
    assert events[-1].time_from == 3.0
    stack.push(SetExtrapolation(doc, ["hero//x"], pre="cycle"))
    assert events[-1].time_from == -math.inf
    stack.push(EditKey(doc, "hero//x", 3, Key(3.0, 1.0)))
    assert events[-1].time_from == -math.inf  # the cycle before t0 repeats every key
    stack.push(SetParameter(doc, "fps", 30))
    assert events[-1] == DocumentChange(parameters=frozenset({"fps"}))
    doc.unsubscribe(events.append)
    stack.undo()
    assert len(events) == 5


def test_add_and_remove_assets_keep_order_and_channels():
    doc = Document()
    stack = UndoStack(doc)
    for name in ("a", "b", "c"):
        stack.push(AddAsset(Asset(name, "light", None, {"i": 1}), runtime=name.upper(),
                            channels={f"{name}//x": Channel([Key(0, 1)])}))
    assert list(doc.assets) == ["a", "b", "c"] and doc.runtime["b"] == "B"
    stack.push(RemoveAsset(doc, "b"))
    assert list(doc.assets) == ["a", "c"] and "b//x" not in doc.channels and "b" not in doc.runtime
    stack.undo()
    assert list(doc.assets) == ["a", "b", "c"] and "b//x" in doc.channels and doc.runtime["b"] == "B"
    # Adding over an existing asset replaces it; undo brings the old one back in place.
    stack.push(AddAsset(Asset("b", "character2d"), runtime="new"))
    assert doc.assets["b"].kind == "character2d" and list(doc.assets) == ["a", "b", "c"]
    stack.undo()
    assert doc.assets["b"].kind == "light" and doc.runtime["b"] == "B"


def test_asset_properties_are_undoable_and_not_shared():
    doc = Document()
    stack = UndoStack(doc)
    asset = Asset("hero", "character2d", None, {"scale": 1})
    stack.push(AddAsset(asset))
    stack.push(SetAssetProperty(doc, "hero", "scale", 2))
    assert doc.assets["hero"].properties == {"scale": 2}
    assert asset.properties == {"scale": 1}  # the AddAsset command's copy is untouched
    stack.push(SetAssetProperty(doc, "hero", "scale", None))
    assert doc.assets["hero"].properties == {}
    stack.undo(), stack.undo()
    assert doc.assets["hero"].properties == {"scale": 1}


def test_macro_is_one_step_and_merges_into_its_last_command():
    doc = Document()
    stack = UndoStack(doc)
    a = InsertKey(doc, "hero//x", Key(0, 1), gesture="ik")
    b = InsertKey(doc, "hero//y", Key(0, 2), gesture="ik")
    stack.push(Macro("IK", [a, b], gesture="ik"))
    c = InsertKey(doc, "hero//x", Key(0, 5), gesture="ik")
    d = InsertKey(doc, "hero//y", Key(0, 6), gesture="ik")
    stack.push(Macro("IK", [c, d], gesture="ik"))
    assert len(stack.done) == 1
    assert doc.channels["hero//x"].evaluate(0.0) == 5.0 and doc.channels["hero//y"].evaluate(0.0) == 6.0
    stack.undo()
    assert doc.channels == {}
    stack.redo()
    assert doc.channels["hero//x"].evaluate(0.0) == 5.0 and doc.channels["hero//y"].evaluate(0.0) == 6.0


def test_scaling_time_stretches_a_weighted_curve_without_changing_its_shape():
    """Scaling key times by f about a pivot p: the new curve at p + f·(t − p) equals the
    old one at t (fixed slopes divided by f, handle weights, in seconds, multiplied by f)."""
    import numpy as np

    from qtanimator.core.channel import Channel, Key, Tangent
    from qtanimator.document.commands import moved_key

    keys = [Key(0.0, 0.0, Tangent.FIXED, Tangent.FIXED, 0.0, 3.0, out_weight=0.5),
            Key(1.0, 2.0, Tangent.FIXED, Tangent.FIXED, -1.0, -1.0, in_weight=0.1, out_weight=0.2),
            Key(2.5, 1.0, Tangent.FIXED, Tangent.FIXED, 0.5, 0.0, in_weight=0.7)]
    old = Channel(keys)
    pivot, factor = 0.4, 1.7
    new = Channel([moved_key(k, 0.0, 0.0, (pivot, factor)) for k in keys])
    t = np.linspace(0.0, 2.5, 201)
    np.testing.assert_allclose(new.evaluate(pivot + (t - pivot) * factor), old.evaluate(t), atol=1e-9)
