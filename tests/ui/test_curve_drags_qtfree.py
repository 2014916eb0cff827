"""The curve editor's drag state machines (qtanimator.ui.curves.drags) without Qt.

Each drag is fed plot points (frame, value as shown) and its commands go through the
Qt-free gesture protocol (Gesture(doc, text, UndoStack.record)); the expected results are
worked out by hand.
"""

from __future__ import annotations

import math
import subprocess
import sys

import pytest
from docfix import set_channels, set_parameters

from qtanimator.core.channel import Channel, Key, Tangent
from qtanimator.document import Document, UndoStack
from qtanimator.document.gesture import Gesture
from qtanimator.ui.curves.drags import (
    BoxSelect,
    Cursor,
    HandleDrag,
    MoveKeysDrag,
    ScaleKeysDrag,
    box_selection,
    click_selection,
    handle_extents,
    press_selection,
)

FPS = 24.0
A = "hero/arm/angle"
B = "hero//x"


def frame(f: float) -> float:
    return f / FPS


def make_doc() -> tuple[Document, UndoStack]:
    doc = Document()
    set_parameters(doc, fps=FPS)
    set_channels(doc, {
        A: Channel([Key(frame(0), 0.0), Key(frame(12), 1.0), Key(frame(24), 0.5), Key(frame(36), 2.0)]),
        B: Channel([Key(frame(6), 10.0), Key(frame(18), 20.0)]),
    })
    return doc, UndoStack(doc)


def key_tv(doc: Document, cid: str) -> list[tuple[float, float]]:
    return [(k.time * FPS, k.value) for k in doc.channels[cid].keys]


# ------------------------------------------------------------------ key moves
def test_a_key_drag_moves_the_selected_keys_by_the_cursor_offset_as_one_undo_step() -> None:
    doc, stack = make_doc()
    before = {A: doc.channels[A], B: doc.channels[B]}
    g = Gesture(doc, "Move Keys", stack.record)
    drag = MoveKeysDrag(doc, {A: [1], B: [0]}, (A, 1), Cursor(12.0, 1.0))
    assert drag.move(Cursor(12.0, 1.0)) is None  # not moved yet: nothing to preview
    for f, v in ((13.0, 1.1), (14.6, 1.3), (15.0, 1.25)):  # several moves, the last one counts
        g.update(drag.move(Cursor(f, v)))
    g.commit()
    # Δ = (3 frames, +0.25): the anchor lands on frame 15 (12 + 3), value 1.25.
    assert key_tv(doc, A)[1] == pytest.approx((15.0, 1.25))
    assert key_tv(doc, B)[0] == pytest.approx((9.0, 10.25))
    # The other keys stay where they were.
    assert key_tv(doc, A)[0] == (0.0, 0.0)
    assert key_tv(doc, A)[2] == pytest.approx((24.0, 0.5)) and key_tv(doc, A)[3] == pytest.approx((36.0, 2.0))
    assert key_tv(doc, B)[1] == pytest.approx((18.0, 20.0))
    assert len(stack.done) == 1 and stack.done[0].text == "Move Keys"
    stack.undo()
    assert doc.channels[A] == before[A] and doc.channels[B] == before[B]


def test_snapping_puts_the_pressed_key_on_whole_frames() -> None:
    doc, stack = make_doc()
    g = Gesture(doc, "Move Keys", stack.record)
    drag = MoveKeysDrag(doc, {A: [1]}, (A, 1), Cursor(12.2, 1.0))
    g.update(drag.move(Cursor(14.9, 1.0)))  # Δ 2.7 frames: 12 + 2.7 rounds to 15
    assert key_tv(doc, A)[1] == pytest.approx((15.0, 1.0))
    free = MoveKeysDrag(doc, {A: [2]}, (A, 2), Cursor(24.0, 0.5), snap=False)
    g.update(free.move(Cursor(26.5, 0.5)))
    assert key_tv(doc, A)[2] == pytest.approx((26.5, 0.5))
    g.commit()


def test_shift_locks_the_drag_to_the_axis_moved_most_along_on_screen() -> None:
    doc, stack = make_doc()
    # In plot units the time offset is larger, but on screen (pixels) the value offset is.
    g = Gesture(doc, "Move Keys", stack.record)
    drag = MoveKeysDrag(doc, {A: [1]}, (A, 1), Cursor(12.0, 1.0, pixel=(100.0, 100.0)))
    g.update(drag.move(Cursor(16.0, 1.5, shift=True, pixel=(110.0, 60.0))))
    assert key_tv(doc, A)[1] == pytest.approx((12.0, 1.5))  # the value axis only
    g.update(drag.move(Cursor(16.0, 1.5, shift=True, pixel=(180.0, 95.0))))
    assert key_tv(doc, A)[1] == pytest.approx((16.0, 1.0))  # the time axis only
    g.update(drag.move(Cursor(16.0, 1.5)))  # Shift released: both
    assert key_tv(doc, A)[1] == pytest.approx((16.0, 1.5))
    g.commit()
    assert len(stack.done) == 1


@pytest.mark.parametrize(("lock", "expected"), [("time", (17.0, 1.0)), ("value", (12.0, 1.75))])
def test_an_axis_lock_keeps_the_other_axis(lock: str, expected: tuple[float, float]) -> None:
    doc, stack = make_doc()
    g = Gesture(doc, "Move Keys", stack.record)
    drag = MoveKeysDrag(doc, {A: [1]}, (A, 1), Cursor(12.0, 1.0), axis_lock=lock)
    g.update(drag.move(Cursor(17.0, 1.75)))
    g.commit()
    assert key_tv(doc, A)[1] == pytest.approx(expected)
    with pytest.raises(ValueError):
        MoveKeysDrag(doc, {A: [1]}, (A, 1), Cursor(0, 0), axis_lock="diagonal")


def test_each_channel_moves_by_the_shown_offset_over_its_display_scale() -> None:
    doc, stack = make_doc()
    g = Gesture(doc, "Move Keys", stack.record)
    degrees = 180.0 / math.pi
    # A is shown in degrees; B normalised with offset 15 and scale 0.1 (display = (v − 15)·0.1).
    display = {A: (0.0, degrees), B: (15.0, 0.1)}
    drag = MoveKeysDrag(doc, {A: [1], B: [1]}, (A, 1), Cursor(12.0, 1.0 * degrees), display=display)
    g.update(drag.move(Cursor(12.0, 1.0 * degrees + 90.0)))  # 90 shown units up
    g.commit()
    assert doc.channels[A].keys[1].value == pytest.approx(1.0 + math.pi / 2)
    assert doc.channels[B].keys[1].value == pytest.approx(20.0 + 90.0 / 0.1)


def test_a_key_cannot_land_on_another_keys_time_the_last_valid_place_stays() -> None:
    doc, stack = make_doc()
    g = Gesture(doc, "Move Keys", stack.record)
    drag = MoveKeysDrag(doc, {A: [1]}, (A, 1), Cursor(12.0, 1.0))
    g.update(drag.move(Cursor(20.0, 1.0)))
    assert drag.move(Cursor(24.0, 1.0)) is None  # frame 24 holds another key
    g.commit()
    assert key_tv(doc, A)[1] == pytest.approx((20.0, 1.0))


def test_keys_passing_others_are_found_again_at_their_new_indices() -> None:
    doc, stack = make_doc()
    g = Gesture(doc, "Move Keys", stack.record)
    drag = MoveKeysDrag(doc, {A: [1]}, (A, 1), Cursor(12.0, 1.0))
    g.update(drag.move(Cursor(30.0, 1.0)))  # past the key at frame 24
    selection, active = drag.remap(doc.channels)
    assert selection == {A: {2}} and active == (A, 2)
    assert key_tv(doc, A)[2] == pytest.approx((30.0, 1.0))
    assert drag.moved[A] == [((frame(12), 1.0), (doc.channels[A].keys[2].time, 1.0))]
    g.commit()


def test_escape_aborts_a_key_drag_exactly_and_records_nothing() -> None:
    doc, stack = make_doc()
    before = dict(doc.channels)
    g = Gesture(doc, "Move Keys", stack.record)
    drag = MoveKeysDrag(doc, {A: [0, 1, 3], B: [0]}, (A, 1), Cursor(12.0, 1.0))
    for f in (13.0, 15.0, 18.0):
        g.update(drag.move(Cursor(f, 3.0)))
    assert doc.channels[A] != before[A]
    g.abort()
    assert doc.channels == before
    assert all(doc.channels[c] is before[c] for c in before)
    assert stack.done == []


def test_a_drag_back_to_where_it_began_records_nothing() -> None:
    doc, stack = make_doc()
    g = Gesture(doc, "Move Keys", stack.record)
    drag = MoveKeysDrag(doc, {A: [1]}, (A, 1), Cursor(12.0, 1.0))
    g.update(drag.move(Cursor(16.0, 2.0)))
    g.update(drag.move(Cursor(12.0, 1.0)))  # back: an update once moving, a no-op change
    assert g.commit() is None and stack.done == []
    assert key_tv(doc, A)[1] == (12.0, 1.0)


# --------------------------------------------------------------------- scaling
def test_ctrl_drag_scales_key_times_about_the_pivot_frame() -> None:
    doc, stack = make_doc()
    g = Gesture(doc, "Scale Keys", stack.record)
    drag = ScaleKeysDrag(doc, {A: [1, 2]}, (A, 2), Cursor(24.0, 0.5), pivot=6.0)
    assert drag.move(Cursor(24.0, 0.5)) is None  # factor 1 before any move
    g.update(drag.move(Cursor(33.0, 0.9)))  # the anchor 24 → 33: factor (33 − 6) / (24 − 6) = 1.5
    g.commit()
    assert [t for t, _v in key_tv(doc, A)] == pytest.approx([0.0, 6.0 + 6.0 * 1.5, 33.0, 36.0])
    assert [v for _t, v in key_tv(doc, A)] == [0.0, 1.0, 0.5, 2.0]  # values unchanged
    assert len(stack.done) == 1 and stack.done[0].text == "Scale Keys"


def test_scaling_through_or_from_the_pivot_does_nothing() -> None:
    doc, _stack = make_doc()
    drag = ScaleKeysDrag(doc, {A: [1, 2]}, (A, 2), Cursor(24.0, 0.5), pivot=6.0)
    assert drag.move(Cursor(0.0, 0.5)) is None  # factor < 0
    on_pivot = ScaleKeysDrag(doc, {A: [1]}, (A, 1), Cursor(12.0, 1.0), pivot=12.0)
    assert on_pivot.move(Cursor(20.0, 1.0)) is None


# ---------------------------------------------------------------- tangent handles
def test_a_handle_drag_sets_the_slope_of_the_handle_direction_on_both_sides() -> None:
    doc, stack = make_doc()
    g = Gesture(doc, "Tangent Handle", stack.record)
    drag = HandleDrag(doc, A, 1, "out")  # the key at frame 12, value 1
    g.update(drag.move(Cursor(18.0, 4.0)))
    g.commit()
    # Δvalue 3 over 6 frames = 0.25 s: 12 per second, fixed, on both sides (not broken).
    key = doc.channels[A].keys[1]
    assert key.out_tangent is Tangent.FIXED and key.in_tangent is Tangent.FIXED
    assert key.out_slope == pytest.approx(12.0) and key.in_slope == pytest.approx(12.0)
    s_in, s_out = doc.channels[A].slopes()
    assert float(s_in[1]) == pytest.approx(12.0) and float(s_out[1]) == pytest.approx(12.0)
    assert len(stack.done) == 1 and stack.done[0].text == "Tangent Handle"


def test_a_broken_keys_in_handle_moves_its_side_only_in_shown_units() -> None:
    doc, stack = make_doc()
    set_channels(doc, {A: doc.channels[A].replace_keys({1: Key(frame(12), 1.0, broken=True)})})
    out_before = float(doc.channels[A].slopes()[1][1])
    degrees = 180.0 / math.pi
    g = Gesture(doc, "Tangent Handle", stack.record)
    drag = HandleDrag(doc, A, 1, "in", display=(0.0, degrees))
    # The handle end 4 frames left of the key and 30 shown degrees below it.
    g.update(drag.move(Cursor(8.0, 1.0 * degrees - 30.0)))
    g.commit()
    key = doc.channels[A].keys[1]
    expected = (-30.0 / degrees) / (-4.0 / FPS)  # rise over run in document units per second
    assert key.in_tangent is Tangent.FIXED and key.in_slope == pytest.approx(expected)
    assert key.out_tangent is Tangent.SMOOTH
    assert float(doc.channels[A].slopes()[1][1]) == pytest.approx(out_before)


def test_an_out_handle_stays_right_of_its_key() -> None:
    doc, _stack = make_doc()
    drag = HandleDrag(doc, A, 1, "out")
    slope, dx = drag.slope(Cursor(10.0, 2.0), span=100.0)  # cursor left of the key
    assert dx == pytest.approx(1e-6 * 100.0) and slope > 0.0 and math.isfinite(slope)
    with pytest.raises(ValueError):
        HandleDrag(doc, A, 1, "up")


def test_a_weighted_handle_drag_sets_its_length_too() -> None:
    doc, stack = make_doc()
    set_channels(doc, {A: doc.channels[A].replace_keys({1: Key(frame(12), 1.0, out_weight=frame(3))})})
    assert handle_extents(doc.channels[A]) is not None
    g = Gesture(doc, "Tangent Handle", stack.record)
    drag = HandleDrag(doc, A, 1, "out")
    g.update(drag.move(Cursor(20.0, 3.0)))  # 8 frames right, 2 up
    g.commit()
    key = doc.channels[A].keys[1]
    assert key.out_weight == pytest.approx(8.0 / FPS)
    assert key.out_slope == pytest.approx(2.0 / (8.0 / FPS))
    assert key.in_weight is None


def test_escape_aborts_a_handle_drag_exactly() -> None:
    doc, stack = make_doc()
    before = doc.channels[A]
    g = Gesture(doc, "Tangent Handle", stack.record)
    drag = HandleDrag(doc, A, 2, "in")
    for f, v in ((20.0, 0.0), (18.0, -3.0)):
        g.update(drag.move(Cursor(f, v)))
    assert doc.channels[A] != before
    g.abort()
    assert doc.channels[A] is before and stack.done == []


# ------------------------------------------------------------------ selection
def test_box_select_takes_the_keys_inside_the_box() -> None:
    doc, _stack = make_doc()
    box = BoxSelect(Cursor(30.0, 25.0))
    assert box.rect(Cursor(5.0, 0.75)) == pytest.approx((5.0, 0.75, 25.0, 24.25))
    # Edges count: the box from (5, 0.75) to (30, 25) holds A's key 1 (12, 1) and B's keys (6, 10), (18, 20).
    assert box.finish(doc, Cursor(5.0, 0.75), [A, B]) == {A: {1}, B: {0, 1}}
    assert box.finish(doc, Cursor(5.0, 0.75), [A]) == {A: {1}}  # only the channels shown
    additive = BoxSelect(Cursor(30.0, 25.0), additive=True)
    assert additive.finish(doc, Cursor(5.0, 0.75), [A], selection={A: {3}}) == {A: {1, 3}}
    # Shown values: B normalised (v − 15)·0.1 puts its keys at −0.5 and 0.5.
    assert box_selection(doc, (0.0, -0.6), (20.0, 0.0), [B], {B: (15.0, 0.1)}) == {B: {0}}


def test_press_and_click_selection_rules() -> None:
    sel = {A: {0}}
    assert press_selection(sel, (A, 0), additive=False) is None  # already selected: kept
    assert press_selection(sel, (B, 1), additive=False) == {B: {1}}
    assert press_selection(sel, (B, 1), additive=True) == {A: {0}, B: {1}}
    assert click_selection(sel, (A, 2), toggle=False) == {A: {2}}
    assert click_selection(sel, (A, 0), toggle=True) == {A: set()}
    assert click_selection(sel, (A, 2), toggle=True) == {A: {0, 2}}
    assert sel == {A: {0}}  # the given selection is not changed


def test_the_drags_module_imports_no_qt() -> None:
    code = ("import sys, qtanimator.ui.curves.drags; "
            "print(sorted(m for m in sys.modules if m.split('.')[0] in "
            "('PySide6', 'pyqtgraph', 'shiboken6', 'OpenGL')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
