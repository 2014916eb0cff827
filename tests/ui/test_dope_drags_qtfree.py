"""The dope sheet's drag and selection logic without Qt (:mod:`qtanimator.ui.dope_drags`,
:mod:`qtanimator.ui.dope_rows`), driven through the Qt-free gesture protocol and undo
stack. Expected values are computed by hand in the comments."""

from __future__ import annotations

import sys

import pytest

from qtanimator.core.channel import Channel, Key
from qtanimator.document import Document
from qtanimator.document.commands import UndoStack
from qtanimator.document.gesture import Gesture
from qtanimator.document.keying import copy_keys
from qtanimator.ui import dope_drags as drags
from qtanimator.ui.dope_rows import KeyFrames, build_rows, nearest_frame, tick_step, visible_rows

FPS = 24.0
X, ARM = "hero//x", "hero/arm/angle"


def channel(*frames: float) -> Channel:
    return Channel([Key(f / FPS, float(i)) for i, f in enumerate(frames)])


def key_frames(ch: Channel) -> list[float]:
    return [round(k.time * FPS, 9) for k in ch.keys]


@pytest.fixture
def doc() -> Document:
    return Document(channels={X: channel(0, 10, 20), ARM: channel(0, 5, 10, 15)}, parameters={"fps": FPS})


def test_no_qt_imported() -> None:
    # Run alone, importing the dope sheet's logic pulls in no Qt.
    import subprocess

    code = ("import sys, qtanimator.ui.dope_drags, qtanimator.ui.dope_rows; "
            "sys.exit(any(m.startswith(('PySide6', 'shiboken6')) for m in sys.modules))")
    assert subprocess.run([sys.executable, "-c", code], check=False).returncode == 0


# ------------------------------------------------------------------ selection
def test_press_key() -> None:
    # Unselected diamond: select its keys; the press may become a drag.
    p = drags.press_key({}, {X: {1}}, toggle=False)
    assert (p.selection, p.reselect, p.drag) == ({X: {1}}, None, True)
    # Selected diamond: nothing changes now; a click (no drag) selects only its keys.
    p = drags.press_key({X: {1, 2}, ARM: {0}}, {X: {1}}, toggle=False)
    assert (p.selection, p.reselect, p.drag) == (None, {X: {1}}, True)
    # Shift on a selected diamond removes its keys and does not drag.
    p = drags.press_key({X: {1, 2}}, {X: {1}}, toggle=True)
    assert (p.selection, p.reselect, p.drag) == ({X: {2}}, None, False)
    # Shift on an unselected diamond adds its keys.
    p = drags.press_key({X: {2}}, {X: {1}, ARM: {3}}, toggle=True)
    assert (p.selection, p.reselect, p.drag) == ({X: {1, 2}, ARM: {3}}, None, True)


def test_box_select() -> None:
    sel = {X: {0}, ARM: {1, 2}}
    hits = {ARM: {2, 3}}
    assert drags.box_select(sel, hits) == {ARM: {2, 3}}
    assert drags.box_select(sel, hits, add=True) == {X: {0}, ARM: {1, 2, 3}}
    assert drags.box_select(sel, hits, remove=True) == {X: {0}, ARM: {1}}
    assert sel == {X: {0}, ARM: {1, 2}}  # not changed in place


def test_remap_selection() -> None:
    old = channel(0, 10, 20)
    assert drags.remap_selection({X: {1}}, {X: old}, {X: old}) is None  # same object
    # Same key count: by index. One more key in front (frame 5): by time, frame 10 is now index 2.
    assert drags.remap_selection({X: {1}}, {X: old}, {X: channel(0, 11, 20)}) == {X: {1}}
    assert drags.remap_selection({X: {1, 2}}, {X: old}, {X: channel(0, 5, 10, 20)}) == {X: {2, 3}}
    # Key at frame 20 deleted: frame 10 stays index 1, frame 20 is gone.
    assert drags.remap_selection({X: {1, 2}}, {X: old}, {X: channel(0, 10)}) == {X: {1}}
    # Channel removed: dropped.
    assert drags.remap_selection({X: {1}}, {X: old}, {}) == {}


# ---------------------------------------------------------------------- drags
def test_retime_drag_is_one_undo_step(doc: Document) -> None:
    stack = UndoStack(doc)
    before = doc.channels[X]
    drag = drags.RetimeDrag(doc, {X: {1}}, snap=True)
    g = Gesture(doc, drag.text, stack.record)
    # 2.4 frames snaps to 2: the key at 10 goes to 12.
    edit = drag.move(2.4)
    assert edit is not None
    g.update(edit.command)
    assert key_frames(doc.channels[X]) == [0, 12, 20]
    assert edit.selection == {X: frozenset({1})}
    assert drag.move(1.6) is None  # rounds to 2 again: nothing new
    # 6.5 rounds to 6 (from the press, not from 12): 10 → 16.
    edit = drag.move(6.5)
    assert edit is not None
    g.update(edit.command)
    assert key_frames(doc.channels[X]) == [0, 16, 20]
    assert g.commit() is not None
    assert len(stack.done) == 1 and stack.done[0].text == "Retime Keys"
    assert stack.undo()
    assert doc.channels[X] is before


def test_retime_onto_a_key_replaces_it_and_abort_is_exact(doc: Document) -> None:
    stack = UndoStack(doc)
    before = dict(doc.channels)
    drag = drags.RetimeDrag(doc, {X: {1}}, snap=False)
    g = Gesture(doc, drag.text, stack.record)
    # Unsnapped: 10 + 0.5 = 10.5.
    edit = drag.move(0.5)
    assert edit is not None
    g.update(edit.command)
    assert key_frames(doc.channels[X]) == [0, 10.5, 20]
    # 10 + 10 = 20: the moved key wins over the key at 20 (two keys left, the moved one is index 1).
    edit = drag.move(10.0)
    assert edit is not None
    g.update(edit.command)
    assert key_frames(doc.channels[X]) == [0, 20]
    assert [k.value for k in doc.channels[X].keys] == [0.0, 1.0]
    assert edit.selection == {X: frozenset({1})}
    g.abort()
    assert all(doc.channels[c] is ch for c, ch in before.items())
    assert stack.done == []


def test_scale_drag(doc: Document) -> None:
    stack = UndoStack(doc)
    drag = drags.ScaleDrag(doc, {X: {1, 2}, ARM: {1, 2, 3}}, snap=True)
    g = Gesture(doc, drag.text, stack.record)
    pivot = 10 / FPS
    # Factor 1.5 about frame 10: X 10 → 10, 20 → 25; ARM 5 → 2.5 → 3 (halves round up),
    # 10 → 10, 15 → 17.5 → 18.
    edit = drag.move(1.5, pivot)
    assert edit is not None
    g.update(edit.command)
    assert key_frames(doc.channels[X]) == [0, 10, 25]
    assert key_frames(doc.channels[ARM]) == [0, 3, 10, 18]
    assert drag.move(1.5, pivot) is None
    # Factor 0.5 (from the press): X 20 → 15; ARM 5 → 7.5 → 8, 15 → 12.5 → 13.
    edit = drag.move(0.5, pivot)
    assert edit is not None
    g.update(edit.command)
    assert key_frames(doc.channels[X]) == [0, 10, 15]
    assert key_frames(doc.channels[ARM]) == [0, 8, 10, 13]
    g.commit()
    assert len(stack.done) == 1 and stack.done[0].text == "Scale Keys"
    stack.undo()
    assert key_frames(doc.channels[X]) == [0, 10, 20]
    assert key_frames(doc.channels[ARM]) == [0, 5, 10, 15]


def test_scale_factor() -> None:
    # Began 50 px right of the playhead at 100: at 200 twice as far.
    assert drags.scale_factor(200.0, 100.0, 150.0) == 2.0
    assert drags.scale_factor(125.0, 100.0, 150.0) == 0.5
    # Past the playhead: clamped to the smallest factor.
    assert drags.scale_factor(90.0, 100.0, 150.0) == drags.MIN_SCALE
    # Began 10 px from the playhead (< 24): by travel, 48 px / 96 px = +0.5.
    assert drags.scale_factor(158.0, 100.0, 110.0) == 1.5
    # Rounded to 3 decimals: 1 + 1/96 = 1.0104… → 1.01.
    assert drags.scale_factor(111.0, 100.0, 110.0) == 1.01


# ------------------------------------------------------------------ clipboard
def test_copy_and_paste(doc: Document) -> None:
    stack = UndoStack(doc)
    clip = copy_keys(doc, {X: {1, 2}})
    assert drags.copy_message(clip) == "Copied 2 keys from 1 channel."
    # The clip starts at its first key (frame 10): pasted at frame 30 → keys at 30 and 40.
    edit = drags.paste_edit(doc, clip, 30 / FPS, "merge", "")
    stack.push(edit.command)
    assert key_frames(doc.channels[X]) == [0, 10, 20, 30, 40]
    assert edit.selection == {X: frozenset({3, 4})}
    assert drags.paste_message(edit, 30.0) == "Pasted 2 keys at frame 30."
    # Replace at frame 5: clears 5…15 (the key at 10), puts 5 and 15.
    edit = drags.paste_edit(doc, clip, 5 / FPS, "replace")
    stack.push(edit.command)
    assert key_frames(doc.channels[X]) == [0, 5, 15, 20, 30, 40]


def test_paste_skips_channels_not_in_the_document(doc: Document) -> None:
    other = Document(channels={"ghost//x": channel(3)}, parameters={"fps": FPS})
    clip = copy_keys(other, {"ghost//x": {0}})
    edit = drags.paste_edit(doc, clip, 0.0, "merge", "")
    assert edit.skipped == ("ghost//x",)
    assert edit.is_noop()
    assert drags.paste_message(edit, 0.0) == ("Pasted 0 keys at frame 0; skipped 1 channel not in this document "
                                              "(select a character to paste onto it).")


# ----------------------------------------------------------------------- rows
def test_rows_and_key_frames(doc: Document) -> None:
    tree = build_rows(doc.channels)
    assert [(r.kind, r.label, r.depth) for r in tree] == [
        ("asset", "hero", 0), ("channel", "x", 1), ("joint", "arm", 1), ("channel", "angle", 2)]
    # Joints start collapsed.
    rows = visible_rows(tree, lambda path: not path[1])
    assert [r.label for r in rows] == ["hero", "x", "arm"]
    frames = KeyFrames(lambda: doc)
    # The asset summary: every key under it (X: 0 10 20, ARM: 0 5 10 15).
    assert list(frames.row_frames(tree[0])) == [0, 5, 10, 15, 20]
    assert frames.row_frames(tree[0]) is frames.row_frames(tree[0])  # cached
    assert frames.keys_at(tree[0], 10.0) == {X: {1}, ARM: {2}}
    assert frames.keys_in([tree[1], tree[3]], 5.0, 15.0) == {X: {1}, ARM: {1, 2, 3}}
    sel = {X: frozenset({2}), ARM: frozenset({0})}
    assert list(frames.selected_frames(tree[0], sel)) == [0, 20]
    # Nearest diamond within 6 px at 4 px per frame (1.5 frames): 11.2 → 10; 12 is 2 frames off.
    row = frames.row_frames(tree[0])
    assert nearest_frame(row, 11.2, 4.0, 6.0) == 10.0
    assert nearest_frame(row, 12.5, 4.0, 6.0) is None
    assert tick_step(4.0) == 20   # 60 px at 4 px per frame: 15 frames → 20
    assert tick_step(100.0) == 1
