"""The curve editor for animators (issue 13, item 4): degrees for rotations, right click
selects, a key on the playhead drags, the rule menus show the current rule, the fields
clear, the key selection is shared, copy / paste, and weighted tangents.

Real mouse and key events on the real widgets (the plot's viewport, its menus, the fields).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from curve_helpers import drag, hover, key_pos, view_pos, viewport_pos
from docfix import set_channels
from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtGui import QPainterPath
from PySide6.QtWidgets import QApplication, QMenu

from qtanimator.core.channel import Channel, Key, Tangent
from qtanimator.document import Document
from qtanimator.ui.context import EditorContext
from qtanimator.ui.curve_editor import CurveEditor

FPS = 60.0
DEG = 180.0 / math.pi
ANGLE = "hero/arm/angle"   # a rotation: radians in the document, degrees on screen
X = "hero//x"              # a position: its own units


def make_doc() -> Document:
    doc = Document()
    set_channels(doc, {ANGLE: Channel([Key(0.25, -0.9), Key(0.75, 0.6), Key(1.25, 0.2, "flat", "flat")])})
    set_channels(doc, {X: Channel([Key(0.0, 0.0), Key(0.5, 40.0), Key(1.0, 20.0)])})
    return doc


@pytest.fixture
def editor(qtbot):
    ctx = EditorContext(make_doc())
    ed = CurveEditor(ctx)
    ed.resize(1000, 560)
    qtbot.addWidget(ed)
    ed.show()
    qtbot.waitExposed(ed)
    assert not ed.view.normalised  # degrees and these positions share the axis readably
    ed.view.vb.setRange(xRange=(-10, 90), yRange=(-70.0, 60.0), padding=0)
    QApplication.processEvents()
    return ed












def click(qtbot, ed: CurveEditor, pos: QPoint, mods=Qt.KeyboardModifier.NoModifier) -> None:
    qtbot.mouseClick(ed.plot.viewport(), Qt.MouseButton.LeftButton, mods, pos)


def right_click_menu(qtbot, ed: CurveEditor, pos: QPoint) -> QMenu:
    qtbot.mouseClick(ed.plot.viewport(), Qt.MouseButton.RightButton, pos=pos)
    qtbot.waitUntil(lambda: isinstance(QApplication.activePopupWidget(), QMenu), timeout=2000)
    menu = QApplication.activePopupWidget()
    assert isinstance(menu, QMenu)
    return menu


def click_action(qtbot, menu: QMenu, text: str) -> None:
    """Click a menu entry by its text (the part before a tab)."""
    action = next(a for a in menu.actions() if a.text().split("\t")[0] == text)
    qtbot.mouseClick(menu, Qt.MouseButton.LeftButton, pos=menu.actionGeometry(action).center())


def open_submenu(qtbot, ed: CurveEditor, pos: QPoint, title: str, sub: str | None = None) -> QMenu:
    """Right click at ``pos`` and open the menu ``title`` (and its submenu ``sub``)."""
    menu = right_click_menu(qtbot, ed, pos)
    click_action(qtbot, menu, title)
    target = ed.tangent_menu if title == "Tangents" else ed.extrap_menu
    qtbot.waitUntil(target.isVisible, timeout=2000)
    if sub is not None:
        click_action(qtbot, target, sub)
        inner = target.findChild(QMenu, f"{target.objectName()}_{sub.lower()}")
        qtbot.waitUntil(inner.isVisible, timeout=2000)
        return inner
    return target


def close_menus() -> None:
    while (popup := QApplication.activePopupWidget()) is not None:
        popup.close()


# ------------------------------------------------------------------ display units
def test_rotations_are_shown_in_degrees_like_the_dof_fields(qtbot, editor):
    ed = editor
    # Drawn at −51.57° (−0.9 rad), where the position channel's 40 would be 40.
    drawn = ed.view.handle_positions(ANGLE, 0)[0]
    assert drawn.y() == pytest.approx(ed.view.vb.mapViewToScene(QPointF(15, -51.566)).y(), abs=0.5)
    assert ed.view.handle_positions(X, 1)[0].y() == pytest.approx(
        ed.view.vb.mapViewToScene(QPointF(30, 40.0)).y(), abs=0.5)
    click(qtbot, ed, key_pos(ed, ANGLE, 0))
    f = ed.fields
    assert f.value.value() == pytest.approx(-51.566, abs=1e-3)
    assert f.value.suffix() == "°" and f.in_slope.suffix() == "°/s"
    s_in, _s_out = ed.ctx.doc.channels[ANGLE].slopes()
    assert f.in_slope.value() == pytest.approx(math.degrees(s_in[0]), abs=1e-4)
    click(qtbot, ed, key_pos(ed, X, 1))
    assert f.value.value() == pytest.approx(40.0) and f.value.suffix() == ""
    # Typing degrees stores radians.
    click(qtbot, ed, key_pos(ed, ANGLE, 1))
    f.value.setFocus()
    qtbot.keyClick(f.value, Qt.Key.Key_A, Qt.KeyboardModifier.ControlModifier)
    qtbot.keyClicks(f.value, "30")
    qtbot.keyClick(f.value, Qt.Key.Key_Return)
    assert ed.ctx.doc.channels[ANGLE].keys[1].value == pytest.approx(math.pi / 6, rel=1e-9)
    # Dragging a rotation key by 10° on screen moves it by 10° (0.1745 rad).
    before = ed.ctx.doc.channels[ANGLE].keys[0].value
    drag(qtbot, ed, key_pos(ed, ANGLE, 0), view_pos(ed, 15, before * DEG + 10.0))
    assert ed.ctx.doc.channels[ANGLE].keys[0].value - before == pytest.approx(math.radians(10.0), abs=0.01)


# ---------------------------------------------------------------------- right click
def test_right_click_selects_the_key_under_the_cursor_and_the_menu_acts_on_it(qtbot, editor):
    ed = editor
    doc = ed.ctx.doc
    click(qtbot, ed, key_pos(ed, X, 1))
    assert ed.view.selected_keys() == {X: [1]}
    menu = right_click_menu(qtbot, ed, key_pos(ed, ANGLE, 2))
    assert ed.view.selected_keys() == {ANGLE: [2]}
    assert ed.ctx.key_selection.keys == {ANGLE: frozenset({2})}
    click_action(qtbot, menu, "Delete Keys")
    assert [k.time for k in doc.channels[ANGLE].keys] == [0.25, 0.75]   # the clicked key went
    assert len(doc.channels[X].keys) == 3                                # the old selection stayed
    assert ed.ctx.undo_stack.count() == 1


def test_right_click_on_a_selected_key_keeps_the_selection(qtbot, editor):
    ed = editor
    click(qtbot, ed, key_pos(ed, X, 0))
    click(qtbot, ed, key_pos(ed, ANGLE, 1), Qt.KeyboardModifier.ShiftModifier)
    right_click_menu(qtbot, ed, key_pos(ed, ANGLE, 1))
    close_menus()
    assert ed.view.selected_keys() == {X: [0], ANGLE: [1]}
    assert ed.view.active == (ANGLE, 1)   # the fields show the key clicked
    right_click_menu(qtbot, ed, view_pos(ed, 80, -60))  # empty space: the selection stays
    close_menus()
    assert ed.view.selected_keys() == {X: [0], ANGLE: [1]}


# ------------------------------------------------------------------------ playhead
def test_a_key_on_the_playhead_drags_and_the_playhead_moves_only_by_its_handle(qtbot, editor):
    ed = editor
    doc = ed.ctx.doc
    ed.ctx.set_frame(45.0)                       # through the angle key at 0.75 s
    start = key_pos(ed, ANGLE, 1)
    hover(ed, start)                             # hovering first: the line must not claim the drag
    drag(qtbot, ed, start, view_pos(ed, 60, 34.4))
    key = doc.channels[ANGLE].keys[1]
    assert key.time * FPS == pytest.approx(60.0)
    assert ed.ctx.frame == 45.0
    # Dragging the line away from keys box-selects; only its handle moves it.
    hover(ed, view_pos(ed, 45, -40))
    drag(qtbot, ed, view_pos(ed, 45, -40), view_pos(ed, 70, -50))
    assert ed.ctx.frame == 45.0
    handle = viewport_pos(ed, ed.view.frame_line.handle_scene_pos())
    hover(ed, handle)
    assert ed.plot.viewport().cursor().shape() == Qt.CursorShape.SizeHorCursor  # says it drags sideways
    drag(qtbot, ed, handle, QPoint(view_pos(ed, 20.2, 0).x(), handle.y()))
    assert ed.ctx.frame == 20.0
    assert doc.channels[X] == make_doc().channels[X]


# ---------------------------------------------------------------------- rule menus
def test_the_tangent_menu_shows_the_current_rule(qtbot, editor):
    ed = editor
    pos = key_pos(ed, ANGLE, 1)                   # smooth in and out
    both = open_submenu(qtbot, ed, pos, "Tangents")
    checked = [a.text() for a in both.actions() if a.isCheckable() and a.isChecked()]
    assert checked == ["Smooth"]
    click_action(qtbot, both, "Flat")
    close_menus()
    key = ed.ctx.doc.channels[ANGLE].keys[1]
    assert (key.in_tangent, key.out_tangent) == (Tangent.FLAT, Tangent.FLAT)
    out = open_submenu(qtbot, ed, pos, "Tangents", "Out")
    assert [a.text() for a in out.actions() if a.isChecked()] == ["Flat"]
    close_menus()
    # Keys with different rules: nothing is checked for both sides.
    click(qtbot, ed, key_pos(ed, X, 1), Qt.KeyboardModifier.ShiftModifier)
    both = open_submenu(qtbot, ed, pos, "Tangents")
    assert ed.view.selected_keys() == {ANGLE: [1], X: [1]}
    assert not any(a.isChecked() for a in both.actions() if a.isCheckable() and a.text() != "Weighted Tangents")
    close_menus()


def test_the_extrapolation_menu_shows_the_current_mode(qtbot, editor):
    ed = editor
    pos = key_pos(ed, X, 2)
    menu = open_submenu(qtbot, ed, pos, "Extrapolation")
    assert [a.text() for a in menu.actions() if a.isChecked()] == ["Constant"]
    close_menus()
    post = open_submenu(qtbot, ed, pos, "Extrapolation", "Post")
    click_action(qtbot, post, "Cycle")
    close_menus()
    assert ed.ctx.doc.channels[X].post.value == "cycle"
    post = open_submenu(qtbot, ed, pos, "Extrapolation", "Post")
    assert [a.text() for a in post.actions() if a.isChecked()] == ["Cycle"]
    close_menus()
    pre = open_submenu(qtbot, ed, pos, "Extrapolation", "Pre")
    assert [a.text() for a in pre.actions() if a.isChecked()] == ["Constant"]
    close_menus()
    both = open_submenu(qtbot, ed, pos, "Extrapolation")
    assert not any(a.isChecked() for a in both.actions())   # pre and post differ
    close_menus()


# --------------------------------------------------------------------------- fields
def test_key_fields_clear_when_no_key_is_selected(qtbot, editor):
    ed = editor
    f = ed.fields
    boxes = (f.frame, f.value, f.in_slope, f.out_slope)
    click(qtbot, ed, key_pos(ed, X, 1))
    assert f.frame.text() == "30.000" and all(b.isEnabled() and b.text() for b in boxes)
    qtbot.keyClick(ed.plot, Qt.Key.Key_Delete)
    assert len(ed.ctx.doc.channels[X].keys) == 2
    assert [b.text() for b in boxes] == ["", "", "", ""]
    assert not any(b.isEnabled() for b in boxes)
    assert f.label.text() == "No key selected"
    click(qtbot, ed, key_pos(ed, X, 1))          # the key now at 1.0 s: filled again
    assert f.frame.text() == "60.000" and f.value.value() == pytest.approx(20.0)
    click(qtbot, ed, view_pos(ed, 80, -60))      # empty space deselects: empty again
    assert [b.text() for b in boxes] == ["", "", "", ""]


# ----------------------------------------------------------------- shared selection
def test_the_key_selection_is_shared_both_ways(qtbot, editor):
    ed = editor
    shared = ed.ctx.key_selection
    sources = []
    shared.changed.connect(sources.append)
    click(qtbot, ed, key_pos(ed, ANGLE, 2))
    assert shared.keys == {ANGLE: frozenset({2})} and sources == [ed.view]
    other = object()   # another editor (the dope sheet)
    shared.set({X: [0, 2]}, ed.ctx.doc.channels, other)
    assert ed.view.selected_keys() == {X: [0, 2]}
    assert sources == [ed.view, other]        # taking it did not send it back
    assert ed.fields.value.value() == pytest.approx(0.0) and ed.fields.label.text().startswith(X)
    # A drag keeps it shared with the moved keys' new indices.
    drag(qtbot, ed, key_pos(ed, X, 0), view_pos(ed, 6, 0))
    assert shared.keys == {X: frozenset({0, 2})}
    assert shared.channel(X) is ed.ctx.doc.channels[X]


def test_keys_another_editor_selected_on_hidden_channels_stay_selected(qtbot, editor):
    ed = editor
    ed.tree.set_checked([X], False)             # the curve editor hides x
    assert ed.view.visible == [ANGLE]
    shared = ed.ctx.key_selection
    shared.set({X: [1], ANGLE: [0]}, ed.ctx.doc.channels, object())
    assert ed.view.selected_keys() == {ANGLE: [0]}
    click(qtbot, ed, key_pos(ed, ANGLE, 2), Qt.KeyboardModifier.ShiftModifier)
    assert shared.keys == {X: frozenset({1}), ANGLE: frozenset({0, 2})}
    ed.tree.set_checked([X], True)              # shown again: its selected key shows selected
    assert ed.view.selected_keys() == {X: [1], ANGLE: [0, 2]}


# ----------------------------------------------------------------------- copy, paste
def test_ctrl_c_ctrl_v_paste_the_selected_keys_at_the_current_frame(qtbot, editor):
    ed = editor
    doc = ed.ctx.doc
    ed.activateWindow()
    qtbot.waitUntil(ed.isActiveWindow)      # shortcuts go to the active window's focus
    click(qtbot, ed, key_pos(ed, ANGLE, 1))
    click(qtbot, ed, key_pos(ed, ANGLE, 2), Qt.KeyboardModifier.ShiftModifier)
    assert ed.plot.hasFocus()
    qtbot.keyClick(ed.plot, Qt.Key.Key_C, Qt.KeyboardModifier.ControlModifier)
    ed.ctx.set_frame(120.0)
    qtbot.keyClick(ed.plot, Qt.Key.Key_V, Qt.KeyboardModifier.ControlModifier)
    keys = doc.channels[ANGLE].keys
    assert [(k.time, k.value) for k in keys[3:]] == [(2.0, 0.6), (2.5, 0.2)]
    assert keys[4].in_tangent is Tangent.FLAT
    assert ed.view.selected_keys() == {ANGLE: [3, 4]}
    assert ed.ctx.undo_stack.count() == 1
    ed.ctx.undo_stack.undo()
    assert doc.channels[ANGLE] == make_doc().channels[ANGLE]


# ------------------------------------------------------------------ weighted tangents
def _segments(path: QPainterPath) -> list[list[tuple[float, float]]]:
    out, cur, i = [], None, 0
    while i < path.elementCount():
        e = path.elementAt(i)
        if e.type == QPainterPath.ElementType.CurveToElement:
            c2, end = path.elementAt(i + 1), path.elementAt(i + 2)
            out.append([cur, (e.x, e.y), (c2.x, c2.y), (end.x, end.y)])
            cur = (end.x, end.y)
            i += 3
        else:
            if e.type == QPainterPath.ElementType.LineToElement:
                out.append([cur, (e.x, e.y)])
            cur = (e.x, e.y)
            i += 1
    return out


def _check_drawn(ed: CurveEditor, cid: str) -> None:
    """Every cubic drawn for ``cid`` is the channel (evaluated at the time its x gives)."""
    d = ed.view.drawing(cid)
    from qtanimator.ui.curves.paths import bezier_path

    ch = ed.ctx.doc.channels[cid]
    u = np.linspace(0.02, 0.98, 13)
    w = np.stack([(1 - u) ** 3, 3 * u * (1 - u) ** 2, 3 * u ** 2 * (1 - u), u ** 3]).T
    cubics = [np.array(seg) for seg in _segments(bezier_path(ch, FPS, d.spans)) if len(seg) == 4]
    assert cubics
    for p in cubics:
        x, y = w @ p[:, 0], w @ p[:, 1]
        np.testing.assert_allclose(y, ch.evaluate(x / FPS), rtol=1e-9, atol=1e-9)


def test_weighted_tangents_keep_the_curve_then_a_handle_drag_sets_slope_and_length(qtbot, editor):
    ed = editor
    doc = ed.ctx.doc
    original = doc.channels[ANGLE]
    pos = key_pos(ed, ANGLE, 1)
    menu = open_submenu(qtbot, ed, pos, "Tangents")
    weighted = next(a for a in menu.actions() if a.text() == "Weighted Tangents")
    assert not weighted.isChecked()
    click_action(qtbot, menu, "Weighted Tangents")
    close_menus()
    key = doc.channels[ANGLE].keys[1]
    assert (key.in_weight, key.out_weight) == (pytest.approx(0.5 / 3), pytest.approx(0.5 / 3))
    t = np.linspace(0.0, 1.5, 301)
    np.testing.assert_allclose(doc.channels[ANGLE].evaluate(t), original.evaluate(t), rtol=1e-9, atol=1e-12)
    assert ed.ctx.undo_stack.count() == 1
    menu = open_submenu(qtbot, ed, pos, "Tangents")
    assert next(a for a in menu.actions() if a.text() == "Weighted Tangents").isChecked()
    close_menus()

    # The out handle is drawn at its real length: at the Bézier control point.
    _s_in, s_out = doc.channels[ANGLE].slopes()
    w = key.out_weight
    _k, _hin, hout = ed.view.handle_positions(ANGLE, 1)
    control = ed.view.vb.mapViewToScene(QPointF((key.time + w) * FPS, (key.value + w * s_out[1]) * DEG))
    assert (hout.x(), hout.y()) == (pytest.approx(control.x(), abs=0.01), pytest.approx(control.y(), abs=0.01))

    # Dragging it 20 frames right and 15° up of the key: 1/3 s long, slope 15°/(1/3 s).
    start = viewport_pos(ed, hout)
    hover(ed, start)
    drag(qtbot, ed, start, view_pos(ed, key.time * FPS + 20, key.value * DEG + 15.0), steps=8)
    new = doc.channels[ANGLE].keys[1]
    assert new.out_weight == pytest.approx(20 / FPS, abs=0.004)
    assert new.out_slope == pytest.approx(math.radians(15.0) / (20 / FPS), rel=0.03)
    assert new.in_slope == new.out_slope and new.in_tangent is Tangent.FIXED   # unbroken: both slopes
    assert new.in_weight == pytest.approx(0.5 / 3)                              # the other length stays
    assert (new.time, new.value) == (key.time, key.value)
    assert ed.ctx.undo_stack.count() == 2
    _check_drawn(ed, ANGLE)
    ed.ctx.undo_stack.undo()
    assert doc.channels[ANGLE].keys[1] == key


def test_a_handle_of_a_key_without_weights_keeps_its_length(qtbot, editor):
    ed = editor
    doc = ed.ctx.doc
    click(qtbot, ed, key_pos(ed, ANGLE, 1))
    _k, _hin, hout = ed.view.handle_positions(ANGLE, 1)
    start = viewport_pos(ed, hout)
    k0 = doc.channels[ANGLE].keys[1]
    drag(qtbot, ed, start, view_pos(ed, k0.time * FPS + 30, k0.value * DEG + 10.0), steps=8)
    key = doc.channels[ANGLE].keys[1]
    assert key.out_weight is None and key.in_weight is None
    assert key.out_slope == pytest.approx(math.radians(10.0) / (30 / FPS), rel=0.05)


def test_weighted_spans_are_drawn_exactly_and_per_column(qtbot, editor):
    from qtanimator.ui.curves.paths import reduced_path

    ed = editor
    doc = ed.ctx.doc
    ch = Channel([Key(0.0, 0.0, "flat", "flat", out_weight=0.45), Key(0.5, 1.0, in_weight=0.05, out_weight=0.2),
                  Key(1.0, -0.5, "linear", "linear", in_weight=0.1), Key(1.5, 0.3)])
    assert ch.is_weighted
    set_channels(doc, {ANGLE: ch})
    ed.view.refresh_all()
    _check_drawn(ed, ANGLE)
    # Per-column drawing (a dense view) stays within its tolerance of the curve.
    column, tolerance = 0.25, 1e-3
    path = reduced_path(ch, FPS, column, tolerance)
    pts = np.array([(path.elementAt(i).x, path.elementAt(i).y) for i in range(path.elementCount())])
    x = np.linspace(0.0, 90.0, 2001)
    np.testing.assert_allclose(np.interp(x, pts[:, 0], pts[:, 1]), ch.evaluate(x / FPS), atol=4 * tolerance)
