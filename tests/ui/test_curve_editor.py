"""Curve editor: real widgets, real mouse and key events on the plot's viewport."""

from __future__ import annotations

import pytest
from curve_helpers import drag, hover, key_pos, view_pos, viewport_pos
from docfix import set_channels
from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtWidgets import QApplication

from qtanimator.core.channel import Channel, Extrapolation, Key, Tangent
from qtanimator.document import Document
from qtanimator.ui.context import EditorContext
from qtanimator.ui.curve_editor import CurveEditor

FPS = 60.0


def make_doc() -> Document:
    """Values in the document's units everywhere (no rotation: those show in degrees; see
    test_curve_editor_animator.py)."""
    doc = Document()
    set_channels(doc, {"hero//x": Channel([Key(0.0, 0.0), Key(0.5, 2.0), Key(1.0, 1.0, "flat", "flat")],
                                      post="cycle")})
    set_channels(doc, {"hero/arm/bend": Channel(
        [Key.make(0.25, -1.0, "linear", "linear"), Key.make(1.25, 1.5, 0.0, 3.0)], pre="linear", post="bounce")})
    set_channels(doc, {"hero//y": Channel([Key(0.1, 0.5), Key(0.6, -0.5), Key(0.9, 0.2)],
                                      pre="cycle_offset", post="cycle_offset")})
    return doc


@pytest.fixture
def editor(qtbot):
    ctx = EditorContext(make_doc())
    ed = CurveEditor(ctx)
    ed.resize(1000, 520)
    qtbot.addWidget(ed)
    ed.show()
    qtbot.waitExposed(ed)
    ed.view.vb.setRange(xRange=(-10, 90), yRange=(-1.5, 2.5), padding=0)
    QApplication.processEvents()
    return ed










def drawn_paths(ed: CurveEditor, cid: str):
    """The keyed and extrapolation paths drawn for ``cid`` in the current view (view
    coordinates before the display transform), and that display transform."""
    from qtanimator.ui.curves.items import display_transform

    d = ed.view.drawing(cid)
    display = display_transform(*ed.view.display_transform(cid))
    (x0, x1), _ = ed.view.vb.viewRange()
    keyed, ext = d.paths(display * ed.view.view_to_scene(), x0, x1)
    return keyed, ext, display




def test_drag_key_moves_it_snapped_and_is_one_undo_step(qtbot, editor):
    ed = editor
    doc = ed.ctx.doc
    before = doc.state()
    start = key_pos(ed, "hero//x", 1)
    drag(qtbot, ed, start, view_pos(ed, 40.3, 1.0))
    key = doc.channels["hero//x"].keys[1]
    assert key.time * FPS == pytest.approx(40.0)  # snapped to a whole frame
    assert key.value == pytest.approx(1.0, abs=0.03)
    assert (key.in_tangent, key.out_tangent) == (Tangent.SMOOTH, Tangent.SMOOTH)
    assert ed.ctx.undo_stack.count() == 1
    ed.ctx.undo_stack.undo()
    assert doc.state() == before
    ed.ctx.undo_stack.redo()
    assert doc.channels["hero//x"].keys[1].time * FPS == pytest.approx(40.0)


def test_escape_aborts_a_drag_without_an_undo_step(qtbot, editor):
    ed = editor
    doc = ed.ctx.doc
    before = doc.state()
    start = key_pos(ed, "hero//y", 1)
    drag(qtbot, ed, start, view_pos(ed, 60, 1.5), release=False)
    assert doc.state() != before  # the drag previews live in the document
    qtbot.keyClick(ed.plot, Qt.Key.Key_Escape)
    assert doc.state() == before
    qtbot.mouseMove(ed.plot.viewport(), view_pos(ed, 70, 2.0))
    qtbot.mouseRelease(ed.plot.viewport(), Qt.MouseButton.LeftButton, pos=view_pos(ed, 70, 2.0))
    assert doc.state() == before
    assert ed.ctx.undo_stack.count() == 0
    assert not ed.ctx.undo_stack.canRedo()


def test_shift_while_dragging_locks_to_the_main_axis(qtbot, editor):
    ed = editor
    doc = ed.ctx.doc
    start = key_pos(ed, "hero//y", 1)
    vp = ed.plot.viewport()
    qtbot.mousePress(vp, Qt.MouseButton.LeftButton, pos=start)
    qtbot.wait(12)
    qtbot.mouseMove(vp, start + QPoint(20, 2))
    end = view_pos(ed, 48, -0.45)
    qtbot.wait(12)
    qtbot.mouseMove(vp, end)
    qtbot.wait(12)
    # Shift is pressed after the drag started: the value stays, only time moves.
    qtbot.mouseRelease(vp, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.ShiftModifier, end)
    key = doc.channels["hero//y"].keys[1]
    assert key.time * FPS == pytest.approx(48.0)
    assert key.value == -0.5


def test_axis_lock_toggle_keeps_time(qtbot, editor):
    ed = editor
    ed.axis_lock.setCurrentIndex(ed.axis_lock.findData("value"))
    drag(qtbot, ed, key_pos(ed, "hero//y", 1), view_pos(ed, 50, 0.0))
    key = ed.ctx.doc.channels["hero//y"].keys[1]
    assert key.time == 0.6
    assert key.value == pytest.approx(0.0, abs=0.03)


def test_drag_handle_sets_fixed_slope_on_both_sides(qtbot, editor):
    ed = editor
    doc = ed.ctx.doc
    before = doc.state()
    qtbot.mouseClick(ed.plot.viewport(), Qt.MouseButton.LeftButton, pos=key_pos(ed, "hero//x", 1))
    assert ed.view.selected_keys() == {"hero//x": [1]}
    _key, _hin, hout = ed.view.handle_positions("hero//x", 1)
    start = viewport_pos(ed, hout)
    # Drag the out handle to a point 10 frames right and 0.5 up of the key (30, 2).
    drag(qtbot, ed, start, view_pos(ed, 40, 2.5), steps=8)
    key = doc.channels["hero//x"].keys[1]
    assert key.in_tangent is Tangent.FIXED and key.out_tangent is Tangent.FIXED
    assert key.out_slope == pytest.approx(0.5 / 10 * FPS, rel=0.05)
    assert key.in_slope == key.out_slope
    assert (key.time, key.value) == (0.5, 2.0)
    assert ed.ctx.undo_stack.count() == 1
    ed.ctx.undo_stack.undo()
    assert doc.state() == before


def test_broken_key_handle_moves_one_side(qtbot, editor):
    ed = editor
    doc = ed.ctx.doc
    qtbot.mouseClick(ed.plot.viewport(), Qt.MouseButton.LeftButton, pos=key_pos(ed, "hero//x", 1))
    ed.action_break.trigger()
    assert doc.channels["hero//x"].keys[1].broken
    _key, hin, _hout = ed.view.handle_positions("hero//x", 1)
    drag(qtbot, ed, viewport_pos(ed, hin), view_pos(ed, 20, 1.0), steps=8)
    key = doc.channels["hero//x"].keys[1]
    assert key.in_tangent is Tangent.FIXED
    assert key.in_slope == pytest.approx(1.0 / 10 * FPS, rel=0.05)  # from (20, 1) up to (30, 2)
    assert key.out_tangent is Tangent.SMOOTH
    ed.action_unify.trigger()
    key = doc.channels["hero//x"].keys[1]
    assert not key.broken
    s_in, s_out = doc.channels["hero//x"].slopes()
    assert s_in[1] == pytest.approx(s_out[1])
    assert ed.ctx.undo_stack.count() == 3


def test_click_shift_click_and_box_select(qtbot, editor):
    ed = editor
    vp = ed.plot.viewport()
    qtbot.mouseClick(vp, Qt.MouseButton.LeftButton, pos=key_pos(ed, "hero//y", 0))
    assert ed.view.selected_keys() == {"hero//y": [0]}
    qtbot.mouseClick(vp, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.ShiftModifier, key_pos(ed, "hero//x", 2))
    assert ed.view.selected_keys() == {"hero//y": [0], "hero//x": [2]}
    qtbot.mouseClick(vp, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.ShiftModifier, key_pos(ed, "hero//y", 0))
    assert ed.view.selected_keys() == {"hero//x": [2]}
    # Box from (-5, -0.8) to (40, 0.7) holds x[0] (0, 0), y[0] (6, .5), y[1] (36, -.5).
    drag(qtbot, ed, view_pos(ed, -5, 0.7), view_pos(ed, 40, -0.8))
    assert ed.view.selected_keys() == {"hero//x": [0], "hero//y": [0, 1]}
    drag(qtbot, ed, view_pos(ed, 70, 1.7), view_pos(ed, 80, 1.3), mods=Qt.KeyboardModifier.ShiftModifier)
    assert ed.view.selected_keys() == {"hero//x": [0], "hero//y": [0, 1], "hero/arm/bend": [1]}
    qtbot.mouseClick(vp, Qt.MouseButton.LeftButton, pos=view_pos(ed, 85, -1.3))
    assert ed.view.selected_keys() == {}


def test_ctrl_click_inserts_key_on_curve_and_delete_removes(qtbot, editor):
    ed = editor
    doc = ed.ctx.doc
    value = doc.channels["hero//x"].evaluate(45 / FPS)
    qtbot.mouseClick(ed.plot.viewport(), Qt.MouseButton.LeftButton, Qt.KeyboardModifier.ControlModifier,
                     view_pos(ed, 45.2, value))
    ch = doc.channels["hero//x"]
    assert len(ch.keys) == 4
    assert ch.keys[2].time == pytest.approx(45 / FPS)
    assert ch.keys[2].value == pytest.approx(value)
    assert ed.view.selected_keys() == {"hero//x": [2]}
    qtbot.keyClick(ed.plot, Qt.Key.Key_Delete)
    assert len(doc.channels["hero//x"].keys) == 3
    assert ed.view.selected_keys() == {}
    ed.ctx.undo_stack.undo()
    assert len(doc.channels["hero//x"].keys) == 4
    ed.ctx.undo_stack.undo()
    assert doc.channels["hero//x"] == make_doc().channels["hero//x"]


def test_moving_several_keys_keeps_rules_and_slopes(qtbot, editor):
    ed = editor
    doc = ed.ctx.doc
    set_channels(doc, {"hero//y": Channel([Key.make(0.1, 0.5, "flat", 2.0), Key.make(0.6, -0.5, -1.5, "clamped"),
                                       Key.make(0.9, 0.2, "linear", "smooth", broken=True)])})
    ed.view.refresh_all()
    old = doc.channels["hero//y"]
    drag(qtbot, ed, view_pos(ed, 3, 0.8), view_pos(ed, 58, -0.8))  # box: all three y keys
    assert ed.view.selected_keys() == {"hero//y": [0, 1, 2]}
    drag(qtbot, ed, key_pos(ed, "hero//y", 1), view_pos(ed, 46, 0.0))
    new = doc.channels["hero//y"]
    for a, b in zip(old.keys, new.keys):
        assert b.time == pytest.approx(a.time + 10 / FPS)
        assert b.value == pytest.approx(a.value + 0.5, abs=0.03)
        assert (b.in_tangent, b.out_tangent, b.in_slope, b.out_slope, b.broken) == \
            (a.in_tangent, a.out_tangent, a.in_slope, a.out_slope, a.broken)
    ed.ctx.undo_stack.undo()
    assert doc.channels["hero//y"] == old


def test_catmull_rom_and_tcb_rules_in_the_menu_and_the_tcb_fields(qtbot, editor):
    # Issue 18: centripetal, chordal and TCB tangents per key; T / C / B fields for a TCB key.
    ed = editor
    doc = ed.ctx.doc
    fields = ed.fields
    qtbot.mouseClick(ed.plot.viewport(), Qt.MouseButton.LeftButton, pos=key_pos(ed, "hero//y", 1))
    assert all(fields.tcb[n].isHidden() for n in fields.tcb)  # a smooth key has none
    for rule in ("centripetal", "chordal"):
        ed.tangent_actions[("both", rule)].trigger()
        key = doc.channels["hero//y"].keys[1]
        assert (key.in_tangent, key.out_tangent) == (Tangent(rule), Tangent(rule))
    assert ed.tangent_actions[("both", "tcb")].text().startswith("TCB")
    ed.tangent_actions[("out", "tcb")].trigger()
    key = doc.channels["hero//y"].keys[1]
    assert (key.in_tangent, key.out_tangent) == (Tangent.CHORDAL, Tangent.TCB)
    ed.show_current_rules()
    assert ed.tangent_actions[("out", "tcb")].isChecked() and ed.tangent_actions[("in", "chordal")].isChecked()
    assert not any(fields.tcb[n].isHidden() for n in fields.tcb)
    steps = ed.ctx.undo_stack.count()
    fields.tcb["tension"].setValue(0.5)
    fields.tcb["bias"].setValue(-0.25)
    key = doc.channels["hero//y"].keys[1]
    assert (key.tension, key.continuity, key.bias) == (0.5, 0.0, -0.25)
    assert ed.ctx.undo_stack.count() == steps + 2  # one step per edit
    s_in, s_out = doc.channels["hero//y"].slopes()
    assert fields.out_slope.value() == pytest.approx(float(s_out[1]), abs=1e-5)
    ed.ctx.undo_stack.undo()
    assert doc.channels["hero//y"].keys[1].bias == 0.0 and fields.tcb["bias"].value() == 0.0
    ed.tangent_actions[("both", "smooth")].trigger()
    assert all(fields.tcb[n].isHidden() for n in fields.tcb)


def test_tangent_and_extrapolation_menus(qtbot, editor):
    ed = editor
    doc = ed.ctx.doc
    vp = ed.plot.viewport()
    qtbot.mouseClick(vp, Qt.MouseButton.LeftButton, pos=key_pos(ed, "hero//y", 1))
    ed.tangent_actions[("in", "flat")].trigger()
    key = doc.channels["hero//y"].keys[1]
    assert (key.in_tangent, key.out_tangent) == (Tangent.FLAT, Tangent.SMOOTH)
    s_in, s_out = doc.channels["hero//y"].slopes()
    ed.tangent_actions[("out", "fixed")].trigger()
    key = doc.channels["hero//y"].keys[1]
    assert key.out_tangent is Tangent.FIXED and key.out_slope == pytest.approx(s_out[1])
    ed.tangent_actions[("both", "clamped")].trigger()
    key = doc.channels["hero//y"].keys[1]
    assert (key.in_tangent, key.out_tangent) == (Tangent.CLAMPED, Tangent.CLAMPED)
    ed.extrap_actions[("pre", "bounce")].trigger()
    ch = doc.channels["hero//y"]
    assert (ch.pre, ch.post) == (Extrapolation.BOUNCE, Extrapolation.CYCLE_OFFSET)
    ed.extrap_actions[("both", "linear")].trigger()
    ch = doc.channels["hero//y"]
    assert (ch.pre, ch.post) == (Extrapolation.LINEAR, Extrapolation.LINEAR)
    # The dashed extrapolation reaches both view edges, on the extrapolated lines.
    _keyed, ext, _display = drawn_paths(ed, "hero//y")
    (x0, x1), _ = ed.view.vb.viewRange()
    r = ext.boundingRect()
    assert r.left() <= x0 and r.right() >= x1
    for k in (0, ext.elementCount() - 1):
        e = ext.elementAt(k)
        assert e.y == pytest.approx(ch.evaluate(e.x / FPS))
    assert ed.ctx.undo_stack.count() == 5
    for _ in range(5):
        ed.ctx.undo_stack.undo()
    assert doc.state() == make_doc().state()


def test_numeric_fields_edit_the_active_key(qtbot, editor):
    ed = editor
    doc = ed.ctx.doc
    qtbot.mouseClick(ed.plot.viewport(), Qt.MouseButton.LeftButton, pos=key_pos(ed, "hero//y", 2))
    f = ed.fields
    assert f.frame.value() == pytest.approx(54.0)
    assert f.value.value() == pytest.approx(0.2)
    f.value.setValue(0.75)
    assert doc.channels["hero//y"].keys[2].value == 0.75
    f.frame.setValue(57)
    assert doc.channels["hero//y"].keys[2].time == pytest.approx(57 / FPS)
    f.out_slope.setValue(-2.0)
    key = doc.channels["hero//y"].keys[2]
    assert (key.in_slope, key.out_slope) == (-2.0, -2.0)
    assert key.in_tangent is Tangent.FIXED
    f.frame.setValue(36)  # another key is there: refused, field restored
    assert f.frame.value() == pytest.approx(57.0)
    assert ed.ctx.undo_stack.count() == 3


def test_current_frame_line_follows_and_scrubs(qtbot, editor):
    ed = editor
    ed.ctx.set_frame(25.0)
    assert ed.view.frame_line.value() == 25.0
    vp = ed.plot.viewport()
    start = viewport_pos(ed, ed.view.frame_line.handle_scene_pos())  # the playhead's handle
    drag(qtbot, ed, start, QPoint(view_pos(ed, 61.3, 2.2).x(), start.y()))
    assert ed.ctx.frame == 61.0
    assert ed.ctx.doc.state() == make_doc().state()
    assert vp is not None


def test_frame_all_frame_selected_and_normalise(qtbot, editor):
    ed = editor
    ed.view.vb.setRange(xRange=(500, 600), yRange=(50, 60), padding=0)
    qtbot.keyClick(ed.plot, Qt.Key.Key_A)
    (x0, x1), (y0, y1) = ed.view.vb.viewRange()
    assert x0 <= 0 and x1 >= 75 and x1 < 100
    assert y0 <= -1 and y1 >= 2 and y1 < 3
    qtbot.mouseClick(ed.plot.viewport(), Qt.MouseButton.LeftButton, pos=key_pos(ed, "hero//y", 1))
    qtbot.keyClick(ed.plot, Qt.Key.Key_F)
    (x0, x1), (y0, y1) = ed.view.vb.viewRange()
    assert x0 < 36 < x1 and x1 - x0 < 30
    assert y0 < -0.5 < y1
    before = ed.ctx.doc.state()
    qtbot.keyClick(ed.plot, Qt.Key.Key_N)
    assert ed.action_normalise.isChecked()
    for cid in ed.view.visible:
        keyed, _ext, display = drawn_paths(ed, cid)
        r = display.map(keyed).boundingRect()
        assert r.top() == pytest.approx(-1.0, abs=1e-3) and r.bottom() == pytest.approx(1.0, abs=1e-3)
    assert ed.ctx.doc.state() == before
    # Dragging in the normalised view moves by display units times the channel's range.
    start = key_pos(ed, "hero//x", 2)  # (60, 1.0) -> normalised 0.0 for x, whose range is 0…2
    drag(qtbot, ed, start, start + (view_pos(ed, 0, 0.5) - view_pos(ed, 0, 0.0)))
    assert ed.ctx.doc.channels["hero//x"].keys[2].value == pytest.approx(1.5, abs=0.03)


def test_wheel_with_ctrl_zooms_time_only(qtbot, editor):
    from PySide6.QtGui import QWheelEvent

    ed = editor
    (x0, x1), yr = ed.view.vb.viewRange()
    vp = ed.plot.viewport()
    pos = QPointF(vp.width() / 2, vp.height() / 2)
    ev = QWheelEvent(pos, vp.mapToGlobal(pos), QPoint(0, 0), QPoint(0, 120), Qt.MouseButton.NoButton,
                     Qt.KeyboardModifier.ControlModifier, Qt.ScrollPhase.NoScrollPhase, False)
    QApplication.sendEvent(vp, ev)
    (nx0, nx1), nyr = ed.view.vb.viewRange()
    assert nx1 - nx0 < x1 - x0
    assert nyr == pytest.approx(yr)


def test_tree_filter_visibility_and_selection_sync(qtbot, editor):
    ed = editor
    tree = ed.tree
    assert ed.view.visible == ["hero//x", "hero/arm/bend", "hero//y"]
    tree.search.setText("arm")
    assert ed.view.visible == ["hero/arm/bend"]
    tree.search.setText("")
    tree.set_checked(["hero//y"], False)
    assert ed.view.visible == ["hero//x", "hero/arm/bend"]
    assert tree._groups[("hero", "")].checkState() == Qt.CheckState.PartiallyChecked
    tree._groups[("hero", "")].setCheckState(Qt.CheckState.Unchecked)
    assert ed.view.visible == []
    tree._groups[("hero", "")].setCheckState(Qt.CheckState.Checked)
    assert ed.view.visible == ["hero//x", "hero/arm/bend", "hero//y"]
    # Another editor selects a joint: the tree row is selected and its channels highlighted.
    ed.ctx.select("hero", "arm")
    assert tree.selected_channels() == ["hero/arm/bend"]
    assert ed.view.highlighted == {"hero/arm/bend"}
    # Clicking a DOF row selects its joint and channel in the context.
    leaf = tree.proxy.mapFromSource(tree._leaves["hero//y"].index())
    rect = tree.view.visualRect(leaf)
    qtbot.mouseClick(tree.view.viewport(), Qt.MouseButton.LeftButton, pos=rect.center())
    assert ed.ctx.selection == ("hero", "")
    assert ed.ctx.channel_selection == ["hero//y"]
    assert ed.view.highlighted == {"hero//y"}
    ed.ctx.select_channels(["hero//x"])
    assert tree.selected_channels() == ["hero//x"]
    ed.action_only_selected.trigger()
    assert ed.view.visible == ["hero//x"]
    ed.ctx.select("hero", "arm")
    assert ed.view.visible == ["hero/arm/bend"]
    ed.ctx.select("hero", "")
    assert ed.view.visible == ["hero//x", "hero/arm/bend", "hero//y"]  # the asset: all of its channels
    ed.action_only_selected.trigger()
    assert ed.view.visible == ["hero//x", "hero/arm/bend", "hero//y"]


def test_only_the_edited_channel_is_rebuilt(qtbot, editor):
    from qtanimator.document import InsertKey

    ed = editor
    ed.plot.grab()
    builds = {cid: ed.view.drawing(cid).builds for cid in ed.view.visible}
    ed.ctx.push(InsertKey(ed.ctx.doc, "hero/arm/bend", Key(0.5, 0.0)))
    ed.plot.grab()
    after = {cid: ed.view.drawing(cid).builds for cid in ed.view.visible}
    assert after["hero/arm/bend"] > builds["hero/arm/bend"]
    assert {c: n for c, n in after.items() if c != "hero/arm/bend"} == \
        {c: n for c, n in builds.items() if c != "hero/arm/bend"}
    ed.view.refresh_all()  # a redraw with nothing changed builds nothing
    ed.plot.grab()
    assert {cid: ed.view.drawing(cid).builds for cid in ed.view.visible} == after


def test_install_adds_the_dock(qtbot):
    from PySide6.QtWidgets import QDockWidget

    from qtanimator.ui import curve_editor
    from qtanimator.ui.main_window import MainWindow

    window = MainWindow(make_doc(), install_editors=False)
    qtbot.addWidget(window)
    curve_editor.install(window)
    dock = window.findChild(QDockWidget, "curveEditorDock")
    assert dock is not None
    plot = window.findChild(type(window.curve_editor.plot), "curvePlot")
    assert plot is window.curve_editor.plot
    assert window.curve_editor.view.visible == list(window.doc.channels)


def test_ctrl_drag_scales_keys_in_time_keeping_handles(qtbot, editor):
    ed = editor
    doc = ed.ctx.doc
    set_channels(doc, {"hero//y": Channel([Key.make(0.1, 0.5, "flat", 2.0), Key.make(0.6, -0.5, -1.5, "clamped"),
                                       Key.make(0.9, 0.2, "linear", "smooth", broken=True)])})
    ed.view.refresh_all()
    old = doc.channels["hero//y"]
    ed.ctx.set_frame(6.0)  # the pivot: the first key
    drag(qtbot, ed, view_pos(ed, 3, 0.8), view_pos(ed, 58, -0.8))
    assert ed.view.selected_keys() == {"hero//y": [0, 1, 2]}
    # The last key goes from frame 54 to 78: factor (78 - 6) / (54 - 6) = 1.5.
    drag(qtbot, ed, key_pos(ed, "hero//y", 2), view_pos(ed, 78, 0.2), mods=Qt.KeyboardModifier.ControlModifier)
    new = doc.channels["hero//y"]
    assert [k.time * FPS for k in new.keys] == pytest.approx([6, 6 + 30 * 1.5, 78])
    for a, b in zip(old.keys, new.keys):
        assert (b.value, b.in_tangent, b.out_tangent, b.broken) == (a.value, a.in_tangent, a.out_tangent, a.broken)
    assert new.keys[0].out_slope == pytest.approx(2.0 / 1.5)
    assert new.keys[1].in_slope == pytest.approx(-1.5 / 1.5)
    assert ed.ctx.undo_stack.count() == 1
    ed.ctx.undo_stack.undo()
    assert doc.channels["hero//y"] == old


def test_escape_aborts_a_handle_drag(qtbot, editor):
    ed = editor
    doc = ed.ctx.doc
    before = doc.state()
    qtbot.mouseClick(ed.plot.viewport(), Qt.MouseButton.LeftButton, pos=key_pos(ed, "hero//y", 1))
    _key, _hin, hout = ed.view.handle_positions("hero//y", 1)
    drag(qtbot, ed, viewport_pos(ed, hout), view_pos(ed, 50, 1.0), release=False)
    assert doc.channels["hero//y"].keys[1].out_tangent is Tangent.FIXED
    qtbot.keyClick(ed.plot, Qt.Key.Key_Escape)
    qtbot.mouseRelease(ed.plot.viewport(), Qt.MouseButton.LeftButton, pos=view_pos(ed, 50, 1.0))
    assert doc.state() == before
    assert ed.ctx.undo_stack.count() == 0


def test_new_channels_appear_and_reset_rebuilds(qtbot, editor):
    from qtanimator.document import InsertKey

    ed = editor
    ed.ctx.push(InsertKey(ed.ctx.doc, "wasp/knee_01_l/rz", Key(0.2, 0.01)))  # 0.57°: in view
    assert "wasp/knee_01_l/rz" in ed.tree.channel_ids()
    assert "wasp/knee_01_l/rz" in ed.view.visible
    qtbot.mouseClick(ed.plot.viewport(), Qt.MouseButton.LeftButton, pos=key_pos(ed, "wasp/knee_01_l/rz", 0))
    assert ed.view.selected_keys() == {"wasp/knee_01_l/rz": [0]}
    ed.ctx.undo_stack.undo()
    assert "wasp/knee_01_l/rz" not in ed.tree.channel_ids()
    assert ed.view.selected_keys() == {}
    fresh = Document()
    set_channels(fresh, {"bob//y": Channel([Key(0, 1.0)])})
    ed.ctx.replace_document(fresh)
    assert ed.tree.channel_ids() == ["bob//y"]
    assert ed.view.visible == ["bob//y"]
    assert ed.view.drawing("bob//y") is not None


def test_curve_editor_in_the_full_main_window(qtbot):
    from PySide6.QtWidgets import QDockWidget

    from qtanimator.ui.main_window import MainWindow

    window = MainWindow(make_doc())
    qtbot.addWidget(window)
    window.show()
    dock = window.findChild(QDockWidget, "curveEditorDock")
    assert dock is not None
    plot = dock.findChild(type(window.curve_editor.plot), "curvePlot")
    assert plot is not None and plot.isVisible()


def test_plot_keys_win_over_window_shortcuts(qtbot, editor):
    from PySide6.QtGui import QAction, QKeySequence

    ed = editor
    fired = []
    other = QAction("Delete something else", ed)
    other.setShortcut(QKeySequence(Qt.Key.Key_Delete))
    other.triggered.connect(lambda: fired.append(True))
    ed.addAction(other)
    try:
        with qtbot.waitActive(ed, timeout=2000):
            ed.activateWindow()
    except Exception:
        pytest.skip("the window cannot be activated here (no window manager), so no shortcuts")
    qtbot.mouseClick(ed.plot.viewport(), Qt.MouseButton.LeftButton, pos=key_pos(ed, "hero//y", 1))
    assert ed.plot.hasFocus()
    qtbot.keyClick(ed, Qt.Key.Key_Delete)  # elsewhere in the window the shortcut works
    assert fired == [True]
    fired.clear()
    qtbot.keyClick(ed.plot, Qt.Key.Key_Delete)
    assert len(ed.ctx.doc.channels["hero//y"].keys) == 2
    assert fired == []


def test_keys_under_the_frame_line_take_the_mouse_and_axis_click_sets_frame(qtbot, editor):
    ed = editor
    ed.ctx.set_frame(36.0)  # the line passes through hero//y key 1
    drag(qtbot, ed, key_pos(ed, "hero//y", 1), view_pos(ed, 40, -0.5))
    assert ed.ctx.doc.channels["hero//y"].keys[1].time * FPS == pytest.approx(40.0)
    assert ed.ctx.frame == 36.0
    x = view_pos(ed, 12.2, 0).x()
    y = ed.plot.mapFromScene(ed.view.vb.sceneBoundingRect().bottomLeft()).y() + 12  # on the time axis
    qtbot.mouseClick(ed.plot.viewport(), Qt.MouseButton.LeftButton, pos=QPoint(x, y))
    assert ed.ctx.frame == 12.0


def test_right_click_opens_the_edit_menu(qtbot, editor):
    from PySide6.QtWidgets import QMenu

    ed = editor
    qtbot.mouseClick(ed.plot.viewport(), Qt.MouseButton.LeftButton, pos=key_pos(ed, "hero//y", 1))
    qtbot.mouseClick(ed.plot.viewport(), Qt.MouseButton.RightButton, pos=view_pos(ed, 50, 1.5))
    qtbot.waitUntil(lambda: isinstance(QApplication.activePopupWidget(), QMenu), timeout=2000)
    menu = QApplication.activePopupWidget()
    titles = [a.text() for a in menu.actions()]
    assert "Tangents" in titles and "Extrapolation" in titles
    menu.close()
    assert ed.view.selected_keys() == {"hero//y": [1]}  # a right click keeps the selection


# ----------------------------------------------------------- polish (issue: rough edges)
def _open_rows(tree) -> set[tuple[str, str]]:
    view = tree.view
    return {path for path, item in tree._groups.items()
            if view.isExpanded(tree.proxy.mapFromSource(item.index()))}


def test_channel_tree_keeps_expansion_and_scroll_when_channels_change(qtbot, editor):
    from qtanimator.document import InsertKey

    ed = editor
    tree = ed.tree
    for j in range(12):  # enough rows to scroll
        set_channels(ed.ctx.doc, {f"hero/bone{j:02d}/angle": Channel([Key(0.0, 0.0), Key(1.0, 0.1 * j)])})
    ed.ctx.replace_document(ed.ctx.doc)
    ed.splitter.setSizes([200, 800])
    ed.resize(1000, 260)
    QApplication.processEvents()
    view = tree.view
    # Open the arm and three bones: click the row, Right opens it.
    for joint in ("arm", "bone03", "bone07", "bone10"):
        index = tree.proxy.mapFromSource(tree._groups[("hero", joint)].index())
        view.scrollTo(index)
        qtbot.mouseClick(view.viewport(), Qt.MouseButton.LeftButton, pos=view.visualRect(index).center())
        qtbot.keyClick(view, Qt.Key.Key_Right)
        assert view.isExpanded(index)
    bar = view.verticalScrollBar()
    bar.setValue(bar.maximum() // 2 + 1)
    opened, scroll = _open_rows(tree), bar.value()
    assert {("hero", "arm"), ("hero", "bone07")} <= opened and scroll > 0
    # A new channel (another joint keyed) rebuilds the tree: nothing collapses or jumps.
    ed.ctx.push(InsertKey(ed.ctx.doc, "hero/tail/angle", Key(0.2, 0.3)))
    assert "hero/tail/angle" in tree.channel_ids()
    assert _open_rows(tree) == opened
    assert bar.value() == scroll
    ed.ctx.undo_stack.undo()
    assert "hero/tail/angle" not in tree.channel_ids()
    assert _open_rows(tree) == opened and bar.value() == scroll


def test_selection_stays_on_the_same_keys_after_undoing_a_move_past_others(qtbot, editor):
    ed = editor
    cid = "hero//x"
    keys = ed.ctx.doc.channels[cid].keys  # frames 0, 30, 60
    qtbot.mouseClick(ed.plot.viewport(), Qt.MouseButton.LeftButton, pos=key_pos(ed, cid, 0))
    assert ed.view.selected_keys() == {cid: [0]}
    # Drag the first key past the second one: it becomes key 1.
    drag(qtbot, ed, key_pos(ed, cid, 0), view_pos(ed, 45, 0.0))
    moved = ed.ctx.doc.channels[cid].keys
    assert moved[1].time * FPS == pytest.approx(45.0) and ed.view.selected_keys() == {cid: [1]}
    ed.ctx.undo_stack.undo()
    assert ed.ctx.doc.channels[cid].keys == keys
    assert ed.view.selected_keys() == {cid: [0]}  # the key that moved, not the one now at index 1
    assert ed.view.active == (cid, 0)
    assert ed.fields.frame.value() == pytest.approx(0.0)
    ed.ctx.undo_stack.redo()
    assert ed.view.selected_keys() == {cid: [1]} and ed.view.active == (cid, 1)
    # A change that removes the selected key clears the selection.
    from qtanimator.document import DeleteKeys

    ed.ctx.push(DeleteKeys(ed.ctx.doc, {cid: [1]}))
    assert ed.view.selected_keys() == {}


def test_dragging_on_the_time_axis_scrubs(qtbot, editor):
    ed = editor
    ed.ctx.set_frame(5.0)
    y = ed.plot.mapFromScene(ed.view.vb.sceneBoundingRect().bottomLeft()).y() + 12  # on the time axis
    seen = []
    ed.ctx.frameChanged.connect(seen.append)
    range_before = ed.view.vb.viewRange()
    drag(qtbot, ed, QPoint(view_pos(ed, 10, 0).x(), y), QPoint(view_pos(ed, 70.2, 0).x(), y), steps=6)
    assert ed.ctx.frame == 70.0
    assert len(seen) >= 3 and all(f == round(f) for f in seen)  # followed the mouse, whole frames
    assert ed.view.vb.viewRange() == range_before  # the axis did not pan
    assert ed.ctx.doc.state() == make_doc().state()


def test_hover_highlights_keys_and_handles_and_sets_the_cursor(qtbot, editor):
    ed = editor
    vp = ed.plot.viewport()
    cid = "hero//y"
    hover(ed, view_pos(ed, 20, -1.2))
    assert ed.view.hover is None and vp.cursor().shape() == Qt.CursorShape.ArrowCursor
    hover(ed, key_pos(ed, cid, 1) + QPoint(2, 1))
    assert ed.view.hover == ("key", cid, 1)
    assert vp.cursor().shape() == Qt.CursorShape.SizeAllCursor
    mark = ed.view.hover_mark()
    assert (mark.kind, mark.x, mark.y) == ("key", pytest.approx(36.0), -0.5)
    # Select it: its handles show; hovering one highlights it with a pointing hand.
    qtbot.mouseClick(vp, Qt.MouseButton.LeftButton, pos=key_pos(ed, cid, 1))
    _key, _hin, hout = ed.view.handle_positions(cid, 1)
    hover(ed, ed.plot.mapFromScene(hout))
    assert ed.view.hover == ("handle", cid, 1, "out")
    assert vp.cursor().shape() == Qt.CursorShape.PointingHandCursor
    mark = ed.view.hover_mark()
    assert (mark.kind, mark.side, mark.x) == ("handle", "out", pytest.approx(36.0))
    image_hover = ed.plot.grab().toImage()
    hover(ed, view_pos(ed, 20, -1.2))
    assert ed.view.hover is None and vp.cursor().shape() == Qt.CursorShape.ArrowCursor
    assert ed.plot.grab().toImage() != image_hover  # the highlight is drawn
