"""Curve editor drags as gestures (ctx.begin_gesture): one undo step, exact Escape, and a
drag frame that redraws only the dragged channel (issues #12 and #17)."""

from __future__ import annotations

import math

import pytest
from curve_helpers import hover, key_pos
from docfix import set_channels
from PySide6.QtCore import QEvent, QPoint, QPointF, Qt
from PySide6.QtGui import QCursor, QMouseEvent
from PySide6.QtTest import QTest
from PySide6.QtWidgets import QApplication, QWidget

from qtanimator.core.channel import Channel, Key
from qtanimator.document import Document
from qtanimator.ui.context import EditorContext
from qtanimator.ui.curve_editor import CurveEditor

FPS = 60.0
DEG = 180.0 / math.pi
DRAGGED = "hero/arm/rz"


def make_doc() -> Document:
    doc = Document()
    for j, joint in enumerate(("arm", "leg", "head")):
        for d, dof in enumerate(("rx", "ry", "rz")):
            set_channels(doc, {f"hero/{joint}/{dof}": Channel(
                [Key(0.25 * k, 0.3 * ((k + j + d) % 3) - 0.4 + 0.05 * d) for k in range(5)], post="cycle")})
    return doc


@pytest.fixture
def editor(qtbot):
    ctx = EditorContext(make_doc())
    ed = CurveEditor(ctx)
    ed.resize(1000, 520)
    qtbot.addWidget(ed)
    ed.show()
    qtbot.waitExposed(ed)
    # Rotations are shown in degrees: the view spans ±1 radian.
    ed.view.vb.setRange(xRange=(-10, 90), yRange=(-DEG, DEG), padding=0)
    QApplication.processEvents()
    return ed




def view_pos(ed: CurveEditor, frame: float, value: float) -> QPoint:
    """Where (frame, value in radians) is drawn: the channels are rotations, shown in degrees."""
    return ed.plot.mapFromScene(ed.view.vb.mapViewToScene(QPointF(frame, value * DEG)))


def move(qtbot, ed: CurveEditor, pos: QPoint) -> None:
    qtbot.wait(12)  # pyqtgraph drops moves closer than 10 ms apart (mouseRateLimit)
    qtbot.mouseMove(ed.plot.viewport(), pos)




def counters(ed: CurveEditor) -> dict[str, int]:
    return {cid: ed.view.drawing(cid).builds for cid in ed.view.visible}


def test_a_drag_frame_redraws_only_the_dragged_channel(qtbot, editor):
    ed = editor
    view = ed.view
    vp = ed.plot.viewport()
    changes = []
    ed.ctx.documentChanged.connect(lambda change: changes.append(set(change.channels)))
    start = key_pos(ed, DRAGGED, 2)
    qtbot.mousePress(vp, Qt.MouseButton.LeftButton, pos=start)
    move(qtbot, ed, start + QPoint(6, -4))  # the drag starts: the channel goes live
    ed.ctx.flush_changes()
    ed.plot.grab()
    assert view.dragging and ed.ctx.gesture_active
    builds = counters(ed)
    static_updates, static_paints = view.static_layer.updates, view.static_layer.paints
    live_paints = view.live_layer.paints
    for k in range(1, 7):
        move(qtbot, ed, start + QPoint(6 + 9 * k, -4 - 5 * k))
        ed.ctx.flush_changes()  # the context emits at most once per frame during a gesture
        ed.plot.grab()
    after = counters(ed)
    # Only the dragged channel's paths were built again...
    assert after[DRAGGED] > builds[DRAGGED]
    assert {c: n for c, n in after.items() if c != DRAGGED} == {c: n for c, n in builds.items() if c != DRAGGED}
    # ...only the live layer was asked to redraw, and the cached layer kept its pixels.
    assert view.static_layer.updates == static_updates
    assert view.static_layer.paints == static_paints
    assert view.live_layer.paints > live_paints
    # Every change the views heard of named the dragged channel only.
    assert changes and all(c == {DRAGGED} for c in changes)
    qtbot.mouseRelease(vp, Qt.MouseButton.LeftButton, pos=start + QPoint(60, -34))
    assert ed.ctx.undo_stack.count() == 1
    assert not ed.ctx.gesture_active


def test_the_views_hear_of_a_drag_at_most_once_per_frame(qtbot, editor):
    ed = editor
    vp = ed.plot.viewport()
    start = key_pos(ed, DRAGGED, 1)
    qtbot.mousePress(vp, Qt.MouseButton.LeftButton, pos=start)
    before = ed.ctx.notifications
    moves = 12
    for k in range(1, moves + 1):
        move(qtbot, ed, start + QPoint(3 * k, -2 * k))
    qtbot.mouseRelease(vp, Qt.MouseButton.LeftButton, pos=start + QPoint(3 * moves, -2 * moves))
    # At least one change arrived (the last one at the latest when the drag ended), never
    # more than one per move, and the document holds the final position.
    assert 1 <= ed.ctx.notifications - before <= moves
    assert ed.ctx.undo_stack.count() == 1


def test_a_drag_that_ends_where_it_began_records_nothing(qtbot, editor):
    ed = editor
    doc = ed.ctx.doc
    before = dict(doc.channels)
    vp = ed.plot.viewport()
    start = key_pos(ed, DRAGGED, 2)
    qtbot.mousePress(vp, Qt.MouseButton.LeftButton, pos=start)
    move(qtbot, ed, start + QPoint(30, -20))
    move(qtbot, ed, start + QPoint(45, 10))
    assert doc.channels[DRAGGED] != before[DRAGGED]  # previewed in the document
    move(qtbot, ed, start)
    qtbot.mouseRelease(vp, Qt.MouseButton.LeftButton, pos=start)
    assert ed.ctx.undo_stack.count() == 0
    assert doc.channels == before
    assert not ed.ctx.gesture_active


def test_escape_puts_every_dragged_channel_back_exactly(qtbot, editor):
    ed = editor
    doc = ed.ctx.doc
    before = doc.state()
    vp = ed.plot.viewport()
    # Select a key on three channels (box), then drag them together.
    qtbot.mousePress(vp, Qt.MouseButton.LeftButton, pos=view_pos(ed, 28, 0.95))
    move(qtbot, ed, view_pos(ed, 31, 0.6))
    move(qtbot, ed, view_pos(ed, 32, -0.95))
    qtbot.mouseRelease(vp, Qt.MouseButton.LeftButton, pos=view_pos(ed, 32, -0.95))
    selected = ed.view.selected_keys()
    assert len(selected) >= 3
    cid, idx = next(iter(selected.items()))
    start = key_pos(ed, cid, idx[0])
    qtbot.mousePress(vp, Qt.MouseButton.LeftButton, pos=start)
    for k in range(1, 5):
        move(qtbot, ed, start + QPoint(11 * k, 7 * k))
    assert doc.state() != before
    qtbot.keyClick(ed.plot, Qt.Key.Key_Escape)
    assert doc.state() == before
    assert not ed.ctx.gesture_active
    qtbot.mouseRelease(vp, Qt.MouseButton.LeftButton, pos=start + QPoint(44, 28))
    assert doc.state() == before
    assert ed.ctx.undo_stack.count() == 0 and not ed.ctx.undo_stack.canRedo()
    assert ed.view.selected_keys() == selected


def test_handle_and_scale_drags_are_one_step_built_from_the_drag_start(qtbot, editor):
    ed = editor
    doc = ed.ctx.doc
    original = doc.channels[DRAGGED]
    vp = ed.plot.viewport()
    qtbot.mouseClick(vp, Qt.MouseButton.LeftButton, pos=key_pos(ed, DRAGGED, 2))
    _key, _hin, hout = ed.view.handle_positions(DRAGGED, 2)
    start = ed.plot.mapFromScene(hout)
    qtbot.mousePress(vp, Qt.MouseButton.LeftButton, pos=start)
    for k in range(1, 6):
        move(qtbot, ed, start + QPoint(0, -8 * k))
    qtbot.mouseRelease(vp, Qt.MouseButton.LeftButton, pos=start + QPoint(0, -40))
    assert ed.ctx.undo_stack.count() == 1
    top = ed.ctx.undo_stack.command(0).command
    assert top.changes[DRAGGED][0] is original  # old: the channel from before the drag
    assert top.changes[DRAGGED][1] is doc.channels[DRAGGED]
    ed.ctx.undo_stack.undo()
    assert doc.channels[DRAGGED] == original


def park_pointer_outside(qtbot, ed: CurveEditor) -> None:  # type: ignore[no-untyped-def]
    """Put the real (Xvfb) pointer far from the editor and let its events arrive now.

    Earlier tests leave the window system's pointer wherever their last no-button QTest
    move put it (``QTest.mouseMove`` without a button moves the real pointer with
    ``QCursor.setPos``; its motion event arrives later). If it sits over this plot, the
    window system's Enter / Motion events at *that* spot can be handled in the middle of
    this test and overwrite the hover our own moves set: the flake of busy full runs."""
    corner = ed.mapToGlobal(QPoint(ed.width() + 300, ed.height() + 300))
    QCursor.setPos(corner)
    qtbot.waitUntil(lambda: QCursor.pos() == corner, timeout=2000)
    qtbot.wait(20)  # the Leave / Motion events of the move are handled here, not later
    QApplication.processEvents()


def move_with_buttons(ed: CurveEditor, pos: QPoint, buttons: Qt.MouseButton) -> None:
    """One mouse move on the plot carrying ``buttons``, delivered synchronously (events
    already queued are handled first, so no late one lands after it)."""
    QApplication.processEvents()
    vp = ed.plot.viewport()
    ev = QMouseEvent(QEvent.Type.MouseMove, QPointF(pos), QPointF(vp.mapToGlobal(pos)), Qt.MouseButton.NoButton,
                     buttons, Qt.KeyboardModifier.NoModifier)
    QApplication.sendEvent(vp, ev)


def test_hover_ignores_a_button_held_down_elsewhere(qtbot, editor):
    """QTest remembers pressed buttons across widgets and tests: after a press whose
    release never came (a test that failed mid-drag), every later QTest mouse move says
    that button is down. Hover goes by the presses this plot saw, so it still works.

    The moves are sent directly (with the stale button in ``buttons()``, as QTest's would
    carry it) after parking the real pointer away from the plot: ``qtbot.mouseMove`` only
    sends a synchronous event while QTest believes a button is down (else it moves the
    real pointer and the hover changes a move late), and a real pointer left over the plot
    by an earlier test could move the hover behind the test's back."""
    ed = editor
    park_pointer_outside(qtbot, ed)
    other = QWidget()
    qtbot.addWidget(other)
    QTest.mousePress(other, Qt.MouseButton.RightButton, Qt.KeyboardModifier.NoModifier, QPoint(2, 2))
    try:
        vp = ed.plot.viewport()
        stale = Qt.MouseButton.RightButton
        move_with_buttons(ed, key_pos(ed, DRAGGED, 3) + QPoint(1, 1), stale)
        assert ed.view.hover == ("key", DRAGGED, 3)
        assert vp.cursor().shape() == Qt.CursorShape.SizeAllCursor
        move_with_buttons(ed, view_pos(ed, 80, -0.9), stale)
        assert ed.view.hover is None
        assert vp.cursor().shape() == Qt.CursorShape.ArrowCursor
        # QTest's own move (synchronous while it remembers the button) agrees
        qtbot.mouseMove(vp, key_pos(ed, DRAGGED, 3) + QPoint(1, 1))
        assert ed.view.hover == ("key", DRAGGED, 3)
        move_with_buttons(ed, view_pos(ed, 80, -0.9), stale)
        assert ed.view.hover is None
    finally:
        QTest.mouseRelease(other, Qt.MouseButton.RightButton, Qt.KeyboardModifier.NoModifier, QPoint(2, 2))


def test_hover_repaints_only_the_hover_layer(qtbot, editor):
    ed = editor
    view = ed.view
    ed.plot.grab()
    static = view.static_layer.paints
    hover(ed, key_pos(ed, DRAGGED, 3))
    assert view.hover == ("key", DRAGGED, 3)
    ed.plot.grab()
    hover(ed, view_pos(ed, 80, -0.9))
    ed.plot.grab()
    assert view.static_layer.paints == static
