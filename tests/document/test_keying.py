"""Key copy / paste, retime, scale and delete (qtanimator.document.keying), without Qt.

Expected times are written out by hand in frames (the document runs at 60 fps)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from docfix import set_channels

from qtanimator.core.channel import Channel, Key, Tangent
from qtanimator.document import Document, UndoStack
from qtanimator.document.gesture import Gesture
from qtanimator.document.io import open_document, to_project_data
from qtanimator.document.keying import (
    KeyClip,
    animatable_channel_ids,
    copy_keys,
    delete_keys_command,
    paste_keys_command,
    retarget,
    retime_keys_command,
    scale_keys_command,
)
from qtanimator.formats.project import project_to_json

FPS = 60.0
A, B = "hero/arm/angle", "hero//x"
DEMO = Path(__file__).resolve().parents[2] / "scenes" / "demo" / "demo.qtanim"


def f(frame: float) -> float:
    return frame / FPS


def frames(ch: Channel) -> list[float]:
    return [round(k.time * FPS, 9) for k in ch.keys]


def make_doc() -> tuple[Document, UndoStack]:
    doc = Document()
    set_channels(doc, {A: Channel([Key(f(0), 0.0), Key(f(10), 1.0, Tangent.FLAT, Tangent.LINEAR), Key(f(14), 2.0),
                               Key(f(34), 3.0), Key(f(40), 4.0)])})
    set_channels(doc, {B: Channel([Key(f(12), 10.0), Key(f(20), 20.0)])})
    return doc, UndoStack(doc)


def saved(doc: Document, tmp_path: Path) -> str:
    return project_to_json(to_project_data(doc), tmp_path)


# ---------------------------------------------------------------- copy / paste
def test_copy_keeps_timing_relative_to_the_earliest_key():
    doc, _ = make_doc()
    clip = copy_keys(doc, {A: [1, 2], B: [0]})
    assert set(clip.channels) == {A, B}
    assert [round(k.time * FPS, 9) for k in clip.channels[A]] == [0.0, 4.0]
    assert [round(k.time * FPS, 9) for k in clip.channels[B]] == [2.0]
    assert [k.value for k in clip.channels[A]] == [1.0, 2.0]
    assert clip.channels[A][0].in_tangent is Tangent.FLAT and clip.channels[A][0].out_tangent is Tangent.LINEAR
    assert clip.key_count == 3 and round(clip.span * FPS, 9) == 4.0
    assert KeyClip.from_dict(json.loads(json.dumps(clip.to_dict()))) == clip


def test_paste_merge_replaces_keys_on_the_same_frames_and_keeps_the_others(tmp_path):
    doc, stack = make_doc()
    clip = copy_keys(doc, {A: [1, 2], B: [0]})
    before = saved(doc, tmp_path)
    edit = paste_keys_command(doc, clip, f(30), "merge")
    stack.push(edit.command)
    assert len(stack.done) == 1
    a = doc.channels[A]
    # Pasted at 30 and 34 (the old key at 34, value 3, is replaced); 0, 10, 14, 40 kept.
    assert frames(a) == [0, 10, 14, 30, 34, 40]
    assert [k.value for k in a.keys] == [0.0, 1.0, 2.0, 1.0, 2.0, 4.0]
    assert a.keys[3].in_tangent is Tangent.FLAT  # the whole key is pasted, rules included
    assert a.keys[3].time == 30 / 60  # exactly on the frame
    assert frames(doc.channels[B]) == [12, 20, 32]
    assert edit.selection == {A: frozenset({3, 4}), B: frozenset({2})}
    stack.undo()
    assert saved(doc, tmp_path) == before


def test_paste_replace_clears_the_pasted_range_first(tmp_path):
    doc, stack = make_doc()
    stack.push(paste_keys_command(doc, KeyClip({A: (Key(0.0, 7.0),)}), f(31)).command)  # a key at 31
    stack.push(paste_keys_command(doc, KeyClip({A: (Key(0.0, 8.0),)}), f(33)).command)  # and at 33
    clip = copy_keys(doc, {A: [1, 2], B: [0]})  # frames 10, 14 (A) and 12 (B): range 0…4
    before = saved(doc, tmp_path)
    edit = paste_keys_command(doc, clip, f(30), "replace")
    stack.push(edit.command)
    # A had 0, 10, 14, 31, 33, 34, 40: 31, 33 and 34 lie in 30…34 and go; 40 stays.
    assert frames(doc.channels[A]) == [0, 10, 14, 30, 34, 40]
    assert [k.value for k in doc.channels[A].keys][3:] == [1.0, 2.0, 4.0]
    # B's range is the clip's (30…34), not only B's own key: nothing of B lay there.
    assert frames(doc.channels[B]) == [12, 20, 32]
    stack.undo()
    assert saved(doc, tmp_path) == before


def test_paste_skips_missing_channels_unless_mapped():
    doc, stack = make_doc()
    clip = KeyClip({"villain/arm/angle": (Key(0.0, 1.0), Key(f(5), 2.0)), A: (Key(0.0, 9.0),)})
    edit = paste_keys_command(doc, clip, f(50))
    assert edit.skipped == ("villain/arm/angle",)
    assert "villain/arm/angle" not in edit.command.changes
    mapped = paste_keys_command(doc, clip, f(50), target={"villain/arm/angle": "hero/leg/angle"})
    stack.push(mapped.command)
    assert mapped.skipped == ()
    assert frames(doc.channels["hero/leg/angle"]) == [50, 55]
    assert frames(doc.channels[A])[-1] == 50
    stack.undo()
    assert "hero/leg/angle" not in doc.channels
    assert retarget(clip, "hero", valid=["hero/arm/angle"]) == {"villain/arm/angle": A, A: A}


def test_bad_paste_mode_and_scale_factor_are_refused():
    doc, _ = make_doc()
    with pytest.raises(ValueError):
        paste_keys_command(doc, KeyClip({A: (Key(0.0, 1.0),)}), 0.0, "overwrite")
    for factor in (0.0, -1.0, float("nan")):
        with pytest.raises(ValueError):
            scale_keys_command(doc, {A: [1]}, 0.0, factor)


# --------------------------------------------------------------------- retime
def test_retime_snaps_the_offset_to_whole_frames():
    doc, stack = make_doc()
    set_channels(doc, {B: Channel([Key(f(10.5), 1.0), Key(f(20), 2.0)])})  # a key between frames
    edit = retime_keys_command(doc, {A: [1, 2], B: [0]}, f(2.4), snap_fps=FPS)
    stack.push(edit.command)
    assert frames(doc.channels[A]) == [0, 12, 16, 34, 40]
    assert doc.channels[A].keys[1].time == 12 / 60  # exactly on the frame, not 10/60 + 2/60
    assert frames(doc.channels[B]) == [12.5, 20]  # keeps its place between frames
    assert edit.selection == {A: frozenset({1, 2}), B: frozenset({0})}
    # Without snapping the offset is used as given.
    doc2, _ = make_doc()
    free = retime_keys_command(doc2, {A: [1]}, f(2.4))
    assert free.command.changes[A][1].keys[1].time == pytest.approx(f(12.4), abs=1e-12)
    # An offset that snaps to zero changes nothing.
    assert retime_keys_command(doc2, {A: [1, 2]}, f(0.4), snap_fps=FPS).is_noop()


def test_a_retimed_key_wins_over_the_key_it_lands_on(tmp_path):
    doc, stack = make_doc()
    before = saved(doc, tmp_path)
    old = doc.channels[A]
    edit = retime_keys_command(doc, {A: [2]}, f(20), snap_fps=FPS)  # 14 → 34, onto the key at 34
    stack.push(edit.command)
    a = doc.channels[A]
    assert frames(a) == [0, 10, 34, 40]
    assert a.keys[2].value == 2.0  # the moved key, not the one that was there (3.0)
    assert edit.selection == {A: frozenset({2})}
    stack.undo()
    assert doc.channels[A] is old
    assert saved(doc, tmp_path) == before


def test_a_drag_of_many_retimes_is_one_undo_step_and_the_last_wins(tmp_path):
    doc, stack = make_doc()
    before = saved(doc, tmp_path)
    base = dict(doc.channels)
    gesture = Gesture(doc, "Retime Keys", stack.record)
    for step in (1, 2, 30, 3):  # passes over 34 and 40 on the way, then comes back
        gesture.update(retime_keys_command(doc, {A: [1, 2]}, f(step), FPS, base=base).command)
    gesture.commit()
    assert len(stack.done) == 1
    assert frames(doc.channels[A]) == [0, 13, 17, 34, 40]  # the keys passed over are back
    stack.undo()
    assert doc.channels[A] is base[A] and doc.channels[B] is base[B]
    assert saved(doc, tmp_path) == before


# ---------------------------------------------------------------------- scale
def test_scale_about_a_pivot_with_snapping(tmp_path):
    doc, stack = make_doc()
    set_channels(doc, {A: Channel([Key(f(10), 1.0), Key(f(20), 2.0, Tangent.FIXED, Tangent.FIXED, 4.5, 3.0),
                               Key(f(31), 3.0), Key(f(50), 5.0)])})
    before = saved(doc, tmp_path)
    # Pivot 12, factor 1.5: 10 → 12 − 2·1.5 = 9, 20 → 12 + 8·1.5 = 24, 31 → 12 + 19·1.5 =
    # 40.5 → 41 (halves round up); 50 is not selected.
    edit = scale_keys_command(doc, {A: [0, 1, 2]}, f(12), 1.5, snap_fps=FPS)
    stack.push(edit.command)
    a = doc.channels[A]
    assert frames(a) == [9, 24, 41, 50]
    assert a.keys[2].time == 41 / 60
    # A fixed slope (value per second) shrinks by the factor so the handle keeps its shape.
    assert (a.keys[1].in_slope, a.keys[1].out_slope) == (pytest.approx(3.0), pytest.approx(2.0))
    assert edit.selection == {A: frozenset({0, 1, 2})}
    stack.undo()
    assert saved(doc, tmp_path) == before
    # Without snapping: 31 → 40.5 exactly.
    free = scale_keys_command(doc, {A: [2]}, f(12), 1.5)
    assert free.command.changes[A][1].keys[2].time == pytest.approx(f(40.5), abs=1e-12)


def test_scaled_keys_snapped_onto_one_frame_keep_the_nearest():
    doc = Document()
    set_channels(doc, {A: Channel([Key(f(10), 1.0), Key(f(11), 2.0), Key(f(12), 3.0), Key(f(1), 9.0)])})
    # About frame 0 by 0.1: 10 → 1.0, 11 → 1.1, 12 → 1.2, all on frame 1; 10 lands exactly
    # there and wins; the unselected key at frame 1 gives way to it.
    edit = scale_keys_command(doc, {A: [1, 2, 3]}, 0.0, 0.1, snap_fps=FPS)
    new = edit.command.changes[A][1]
    assert new is not None
    assert frames(new) == [1] and new.keys[0].value == 1.0
    assert edit.selection == {A: frozenset({0})}


def test_delete_is_one_step_with_exact_undo(tmp_path):
    doc, stack = make_doc()
    before = saved(doc, tmp_path)
    stack.push(delete_keys_command(doc, {A: [0, 4], B: [1]}).command)
    assert frames(doc.channels[A]) == [10, 14, 34] and frames(doc.channels[B]) == [12]
    assert len(stack.done) == 1 and stack.done[0].text == "Delete 3 Keys"
    stack.undo()
    assert saved(doc, tmp_path) == before


# ------------------------------------------------------------------ real data
def test_copy_paste_retime_scale_on_the_demo_project_undo_byte_for_byte(tmp_path):
    doc = open_document(DEMO)
    stack = UndoStack(doc)
    original = saved(doc, tmp_path)
    pip = {cid: range(len(ch.keys)) for cid, ch in doc.channels_of("pip")}
    clip = copy_keys(doc, pip)
    first = min(k.time for ch in doc.channels_of("pip") for k in ch[1].keys)
    assert clip.key_count == sum(len(ch.keys) for _cid, ch in doc.channels_of("pip"))
    stack.push(paste_keys_command(doc, clip, first + clip.span + f(30), "replace").command)
    stack.push(retime_keys_command(doc, pip, f(5), FPS).command)
    stack.push(scale_keys_command(doc, {cid: [0] for cid in pip}, f(60), 0.5, FPS).command)
    assert len(stack.done) == 3
    assert saved(doc, tmp_path) != original
    while stack.undo():
        pass
    assert saved(doc, tmp_path) == original
    assert "pip/head/angle" in animatable_channel_ids(doc, "pip")
