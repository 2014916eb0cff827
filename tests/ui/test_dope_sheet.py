"""The dope sheet driven by real mouse and key events: selection (click, Shift, box, summary
diamonds) shared with ``ctx.key_selection``, retime and scale gestures (one undo step each,
exact undo, Escape aborts), copy / paste / delete through the dock's shortcuts, collapse."""

from __future__ import annotations

from pathlib import Path

import pytest
from docfix import set_channels
from PySide6.QtCore import QEvent, QPoint, QPointF, Qt
from PySide6.QtGui import QMouseEvent
from PySide6.QtTest import QTest
from PySide6.QtWidgets import QApplication, QDockWidget

from qtanimator.core.channel import Channel, Key
from qtanimator.document import Document, InsertKey
from qtanimator.document.io import to_project_data
from qtanimator.formats.project import project_to_json
from qtanimator.ui import dope_sheet
from qtanimator.ui.dope_sheet import DopeSheetPanel, DopeSheetView

FPS = 60.0
X, ARM, LEG = "hero//x", "hero/arm/angle", "hero/leg/angle"
DEMO = Path(__file__).resolve().parents[2] / "scenes" / "demo" / "demo.qtanim"
LEFT = Qt.MouseButton.LeftButton
NO_MODS = Qt.KeyboardModifier.NoModifier
SHIFT = Qt.KeyboardModifier.ShiftModifier
CTRL = Qt.KeyboardModifier.ControlModifier


def f(frame: float) -> float:
    return frame / FPS


def frames(ch: Channel) -> list[float]:
    return [round(k.time * FPS, 9) for k in ch.keys]


def make_doc() -> Document:
    doc = Document()
    set_channels(doc, {X: Channel([Key(f(fr), v) for fr, v in ((0, 0.0), (10, 1.0), (20, 2.0), (30, 3.0))])})
    set_channels(doc, {ARM: Channel([Key(f(fr), v) for fr, v in ((0, 0.5), (10, 1.5), (40, 2.5))])})
    set_channels(doc, {LEG: Channel([Key(f(fr), v) for fr, v in ((10, -1.0), (20, -2.0))])})
    return doc


@pytest.fixture
def sheet(qtbot, make_window) -> DopeSheetPanel:  # type: ignore[no-untyped-def]
    window = make_window(editors=("timeline",), size=(1200, 800))
    panel = dope_sheet.install(window)
    dock = window.findChild(QDockWidget, "dopeSheetDock")
    assert dock is not None and dock.widget() is panel
    timeline = window.findChild(QDockWidget, "timelineDock")
    window.ctx.replace_document(make_doc())
    QApplication.processEvents()
    window.resizeDocks([dock, timeline], [560, 120], Qt.Orientation.Vertical)
    QApplication.processEvents()
    view = panel.view
    assert view.objectName() == "dopeSheet" and view.height() > 200
    view.frame_range(-5, 125)
    view.setFocus()
    qtbot.waitUntil(view.hasFocus)
    return panel


def saved(doc: Document, tmp_path: Path) -> str:
    return project_to_json(to_project_data(doc), tmp_path)


def row(view: DopeSheetView, kind: str, joint: str = "", dof: str = "", asset: str = "hero") -> int:
    i = view.row_index(kind, asset, joint, dof)
    assert i is not None, (kind, joint, dof)
    return i


def hover(view: DopeSheetView, pos: QPoint) -> None:
    """A mouse move with no button down, delivered now (QTest's would move the real pointer,
    whose window-system event may come late)."""
    QApplication.processEvents()
    ev = QMouseEvent(QEvent.Type.MouseMove, QPointF(pos), QPointF(view.mapToGlobal(pos)), Qt.MouseButton.NoButton,
                     Qt.MouseButton.NoButton, NO_MODS)
    QApplication.sendEvent(view, ev)


def drag(qtbot, view: DopeSheetView, start: QPoint, end: QPoint, steps: int = 4,  # type: ignore[no-untyped-def]
         mods: Qt.KeyboardModifier = NO_MODS, release: bool = True) -> None:
    qtbot.mousePress(view, LEFT, mods, start)
    for i in range(1, steps + 1):
        qtbot.mouseMove(view, start + (end - start) * i / steps)
    if release:
        qtbot.mouseRelease(view, LEFT, mods, end)


def selected(ctx) -> dict[str, set[int]]:  # type: ignore[no-untyped-def]
    return {cid: set(idx) for cid, idx in ctx.key_selection.keys.items()}


# ------------------------------------------------------------------ rows
def test_rows_group_channels_and_summary_rows_collapse(qtbot, sheet):
    view = sheet.view
    labels = [(r.kind, r.label) for r in view.rows]
    # Joints start collapsed: their summary rows stand for their channels.
    assert labels == [("asset", "hero"), ("channel", "x"), ("joint", "arm"), ("joint", "leg")]
    arm = row(view, "joint", "arm")
    qtbot.mouseClick(view, LEFT, NO_MODS, QPoint(14 + 4, view.row_y(arm) + 10))  # the arrow
    assert [(r.kind, r.label) for r in view.rows][2:4] == [("joint", "arm"), ("channel", "angle")]
    # The asset's arrow collapses everything under it into one row of summary diamonds.
    qtbot.mouseClick(view, LEFT, NO_MODS, QPoint(10, view.row_y(row(view, "asset")) + 10))
    assert [(r.kind, r.label) for r in view.rows] == [("asset", "hero")]
    assert list(view.row_frames(view.rows[0])) == [0, 10, 20, 30, 40]
    # Clicking a row's name selects that character / joint for the other editors.
    qtbot.mouseClick(view, LEFT, NO_MODS, QPoint(120, view.row_y(0) + 10))
    assert sheet.ctx.selection == ("hero", "")


# ------------------------------------------------------------- selection
def test_click_shift_click_and_summary_diamonds_select_shared_keys(qtbot, sheet):
    view, ctx = sheet.view, sheet.ctx
    x = row(view, "channel", dof="x")
    qtbot.mouseClick(view, LEFT, NO_MODS, view.key_pos(x, 10))
    assert selected(ctx) == {X: {1}}
    qtbot.mouseClick(view, LEFT, SHIFT, view.key_pos(x, 20))
    assert selected(ctx) == {X: {1, 2}}
    qtbot.mouseClick(view, LEFT, SHIFT, view.key_pos(x, 10))  # Shift toggles
    assert selected(ctx) == {X: {2}}
    # A summary diamond stands for every key under it at that frame.
    qtbot.mouseClick(view, LEFT, NO_MODS, view.key_pos(row(view, "asset"), 10))
    assert selected(ctx) == {X: {1}, ARM: {1}, LEG: {0}}
    qtbot.mouseClick(view, LEFT, NO_MODS, view.key_pos(row(view, "joint", "leg"), 20))
    assert selected(ctx) == {LEG: {1}}
    # Empty space clears.
    qtbot.mouseClick(view, LEFT, NO_MODS, QPoint(int(view.x_of(70)), view.row_y(x) + 10))
    assert selected(ctx) == {}


def test_selection_from_another_editor_is_shown_and_kept_through_an_undo(qtbot, sheet):
    view, ctx = sheet.view, sheet.ctx
    other = object()
    view.repaint()
    renders = view.renders
    ctx.key_selection.set({ARM: [2]}, ctx.doc.channels, other)
    view.repaint()
    assert view.renders == renders + 1
    assert view.selection() == {ARM: {2}}
    arm = view.rows[row(view, "joint", "arm")]
    assert list(view._selected_frames(arm, ctx.key_selection.valid(ctx.doc.channels))) == [40]


def test_box_select_adds_with_shift_and_removes_with_ctrl(qtbot, sheet):
    view, ctx = sheet.view, sheet.ctx
    x, arm, leg = row(view, "channel", dof="x"), row(view, "joint", "arm"), row(view, "joint", "leg")
    # Frames 5…25 across the x row and the arm summary row (row centres inside the box).
    start = QPoint(int(view.x_of(5)), view.row_y(x) + 2)
    end = QPoint(int(view.x_of(25)), view.row_y(arm) + 18)
    drag(qtbot, view, start, end)
    assert selected(ctx) == {X: {1, 2}, ARM: {1}}
    # Shift adds the leg row's keys in 15…45; Ctrl removes x's keys in 15…35.
    drag(qtbot, view, QPoint(int(view.x_of(15)), view.row_y(leg) + 2),
         QPoint(int(view.x_of(45)), view.row_y(leg) + 18), mods=SHIFT)
    assert selected(ctx) == {X: {1, 2}, ARM: {1}, LEG: {1}}
    drag(qtbot, view, QPoint(int(view.x_of(15)), view.row_y(x) + 2),
         QPoint(int(view.x_of(35)), view.row_y(x) + 18), mods=CTRL)
    assert selected(ctx) == {X: {1}, ARM: {1}, LEG: {1}}


# ---------------------------------------------------------------- retime
def test_drag_retime_snaps_is_one_undo_step_and_undoes_exactly(qtbot, sheet, tmp_path):
    view, ctx = sheet.view, sheet.ctx
    doc = ctx.doc
    before = saved(doc, tmp_path)
    old = dict(doc.channels)
    steps = ctx.undo_stack.index()
    asset = row(view, "asset")
    qtbot.mouseClick(view, LEFT, NO_MODS, view.key_pos(asset, 10))  # x, arm and leg at 10
    qtbot.mouseClick(view, LEFT, SHIFT, view.key_pos(row(view, "channel", dof="x"), 30))
    start = view.key_pos(asset, 10)
    # 6.4 frames to the right (through 35 on the way): snapped to 6.
    drag(qtbot, view, start, start + QPoint(int(round(6.4 * view.px_per_frame)), 3), steps=6)
    assert ctx.undo_stack.index() == steps + 1
    assert ctx.undo_stack.text(steps) == "Retime Keys"
    assert frames(doc.channels[X]) == [0, 16, 20, 36]
    assert frames(doc.channels[ARM]) == [0, 16, 40]
    assert frames(doc.channels[LEG]) == [16, 20]
    assert doc.channels[X].keys[1].time == 16 / 60
    assert selected(ctx) == {X: {1, 3}, ARM: {1}, LEG: {0}}  # the moved keys stay selected
    ctx.undo_stack.undo()
    assert all(doc.channels[c] is old[c] for c in old)
    assert saved(doc, tmp_path) == before
    ctx.undo_stack.redo()
    assert frames(doc.channels[X]) == [0, 16, 20, 36]


def test_a_retimed_key_replaces_the_key_it_lands_on_and_escape_aborts(qtbot, sheet, tmp_path):
    view, ctx = sheet.view, sheet.ctx
    doc = ctx.doc
    x = row(view, "channel", dof="x")
    qtbot.mouseClick(view, LEFT, NO_MODS, view.key_pos(x, 10))
    before = saved(doc, tmp_path)
    steps = ctx.undo_stack.index()
    start = view.key_pos(x, 10)
    drag(qtbot, view, start, view.key_pos(x, 20), release=False)
    assert frames(doc.channels[X]) == [0, 20, 30]  # the preview: the moved key wins
    assert doc.channels[X].keys[1].value == 1.0
    QTest.keyClick(view, Qt.Key.Key_Escape)
    qtbot.mouseRelease(view, LEFT, NO_MODS, view.key_pos(x, 20))
    assert saved(doc, tmp_path) == before
    assert ctx.undo_stack.index() == steps
    assert selected(ctx) == {X: {1}}
    drag(qtbot, view, start, view.key_pos(x, 20))
    assert frames(doc.channels[X]) == [0, 20, 30] and ctx.undo_stack.index() == steps + 1


# ----------------------------------------------------------------- scale
def test_s_scales_about_the_playhead_in_one_undo_step(qtbot, sheet, tmp_path):
    view, ctx = sheet.view, sheet.ctx
    doc = ctx.doc
    x = row(view, "channel", dof="x")
    drag(qtbot, view, QPoint(int(view.x_of(5)), view.row_y(x) + 2), QPoint(int(view.x_of(35)), view.row_y(x) + 18))
    assert selected(ctx) == {X: {1, 2, 3}}
    ctx.set_frame(10)
    before = saved(doc, tmp_path)
    steps = ctx.undo_stack.index()
    hover(view, view.key_pos(x, 30))       # 20 frames right of the playhead…
    QTest.keyClick(view, Qt.Key.Key_S)
    hover(view, view.key_pos(x, 70))
    hover(view, view.key_pos(x, 50))       # …now 40: twice as far
    assert view.scale_factor_at(view.key_pos(x, 50).x()) == pytest.approx(2.0, abs=0.02)
    qtbot.mouseClick(view, LEFT, NO_MODS, view.key_pos(x, 50))
    # About 10 by 2: 10 → 10, 20 → 30, 30 → 50 (computed by hand).
    assert frames(doc.channels[X]) == [0, 10, 30, 50]
    assert ctx.undo_stack.index() == steps + 1 and ctx.undo_stack.text(steps) == "Scale Keys"
    assert selected(ctx) == {X: {1, 2, 3}}
    ctx.undo_stack.undo()
    assert saved(doc, tmp_path) == before
    # Escape (or a right click) cancels: nothing changes, nothing is recorded.
    hover(view, view.key_pos(x, 30))
    QTest.keyClick(view, Qt.Key.Key_S)
    hover(view, view.key_pos(x, 20))
    assert frames(doc.channels[X]) == [0, 10, 15, 20]
    QTest.keyClick(view, Qt.Key.Key_Escape)
    assert saved(doc, tmp_path) == before and ctx.undo_stack.index() == steps
    QTest.keyClick(view, Qt.Key.Key_S)
    hover(view, view.key_pos(x, 100))
    qtbot.mouseClick(view, Qt.MouseButton.RightButton, NO_MODS, view.key_pos(x, 100))
    assert saved(doc, tmp_path) == before and ctx.undo_stack.index() == steps


# ------------------------------------------------------ copy, paste, delete
def test_ctrl_c_ctrl_v_paste_keys_at_the_current_frame(qtbot, sheet, tmp_path):
    view, ctx = sheet.view, sheet.ctx
    doc = ctx.doc
    x, arm = row(view, "channel", dof="x"), row(view, "joint", "arm")
    drag(qtbot, view, QPoint(int(view.x_of(5)), view.row_y(x) + 2), QPoint(int(view.x_of(25)), view.row_y(arm) + 18))
    assert selected(ctx) == {X: {1, 2}, ARM: {1}}
    QTest.keyClick(view, Qt.Key.Key_C, CTRL)
    assert "Copied 3 keys" in sheet.status.text()
    ctx.set_frame(100)
    before = saved(doc, tmp_path)
    steps = ctx.undo_stack.index()
    QTest.keyClick(view, Qt.Key.Key_V, CTRL)
    assert ctx.undo_stack.index() == steps + 1
    assert frames(doc.channels[X]) == [0, 10, 20, 30, 100, 110]
    assert frames(doc.channels[ARM]) == [0, 10, 40, 100]
    assert selected(ctx) == {X: {4, 5}, ARM: {3}}  # the pasted keys
    ctx.undo_stack.undo()
    assert saved(doc, tmp_path) == before
    # Replace clears the pasted range (100…110) first; merge would keep the key at 105.
    ctx.key_selection.clear()
    ctx.push(InsertKey(doc, X, Key(f(105), 9.0)))
    QTest.keyClick(view, Qt.Key.Key_V, CTRL | SHIFT)
    assert frames(doc.channels[X]) == [0, 10, 20, 30, 100, 110]
    ctx.undo_stack.undo()
    QTest.keyClick(view, Qt.Key.Key_V, CTRL)
    assert frames(doc.channels[X]) == [0, 10, 20, 30, 100, 105, 110]
    menu = [a.text() for a in sheet.context_menu().actions() if a.text()]
    assert "Paste (Merge)" in menu and "Paste (Replace)" in menu


def test_delete_and_x_delete_selected_keys_in_one_step(qtbot, sheet, tmp_path):
    view, ctx = sheet.view, sheet.ctx
    doc = ctx.doc
    before = saved(doc, tmp_path)
    steps = ctx.undo_stack.index()
    qtbot.mouseClick(view, LEFT, NO_MODS, view.key_pos(row(view, "asset"), 10))
    QTest.keyClick(view, Qt.Key.Key_Delete)
    assert frames(doc.channels[X]) == [0, 20, 30] and frames(doc.channels[LEG]) == [20]
    assert ctx.undo_stack.index() == steps + 1 and selected(ctx) == {}
    qtbot.mouseClick(view, LEFT, NO_MODS, view.key_pos(row(view, "channel", dof="x"), 30))
    QTest.keyClick(view, Qt.Key.Key_X)
    assert frames(doc.channels[X]) == [0, 20]
    ctx.undo_stack.undo()
    ctx.undo_stack.undo()
    assert saved(doc, tmp_path) == before


def test_ruler_click_sets_the_frame_and_edits_elsewhere_repaint_only_when_shown(qtbot, sheet):
    view, ctx = sheet.view, sheet.ctx
    qtbot.mouseClick(view, LEFT, NO_MODS, QPoint(int(view.x_of(42)), 10))
    assert ctx.frame == 42
    view.repaint()
    renders = view.renders
    ctx.set_frame(43)  # the playhead is drawn over the kept rows
    view.repaint()
    assert view.renders == renders
    ctx.push(InsertKey(ctx.doc, "other/j/angle", Key(0.0, 1.0)))  # a new channel: new rows
    view.repaint()
    assert view.renders == renders + 1 and view.row_index("asset", "other") is not None


def test_an_edit_redraws_the_rows_only_when_a_shown_row_draws_it(qtbot, sheet):
    view, ctx = sheet.view, sheet.ctx
    doc = make_doc()
    for j in range(60):  # rows that push "zz" below the visible ones
        set_channels(doc, {f"fill/j{j:02d}/angle": Channel([Key(0.0, 0.0), Key(1.0, float(j))])})
    set_channels(doc, {"zz/j59/angle": Channel([Key(0.0, 0.0), Key(1.0, 1.0)])})
    ctx.replace_document(doc)
    view.repaint()
    _first, last = view._visible_range()
    assert view.row_index("asset", "zz") >= last
    renders = view.renders
    ctx.push(InsertKey(ctx.doc, "zz/j59/angle", Key(0.5, 3.0)))
    view.repaint()
    assert view.renders == renders
    ctx.push(InsertKey(ctx.doc, ARM, Key(f(50), 3.0)))
    view.repaint()
    assert view.renders == renders + 1
    view.scrollbar.setValue(view.scrollbar.maximum())  # scrolled down, the new key is drawn
    view.repaint()
    assert view.renders == renders + 2
    assert list(view.row_frames(view.rows[view.row_index("joint", "zz", "j59")])) == [0, 30, 60]


# ------------------------------------------------------------------ demo
def test_demo_project_box_retime_and_undo_byte_for_byte(qtbot, sheet, tmp_path):
    window = sheet.window()
    assert window.open_path(DEMO)
    view, ctx = sheet.view, sheet.ctx
    doc = ctx.doc
    QApplication.processEvents()
    view.frame_range(-5, 245)
    pip = row(view, "asset", asset="pip")
    assert [r.label for r in view.rows[:3]] == ["pip", "x", "y"]
    before = saved(doc, tmp_path)
    # Box-select every pip key in frames 50…130 on the pip summary row.
    drag(qtbot, view, QPoint(int(view.x_of(50)), view.row_y(pip) + 2),
         QPoint(int(view.x_of(130)), view.row_y(pip) + 18))
    chosen = selected(ctx)
    expected = {cid: {i for i, k in enumerate(ch.keys) if 50 <= round(k.time * FPS, 6) <= 130}
                for cid, ch in doc.channels_of("pip")}
    assert chosen == {c: s for c, s in expected.items() if s} and chosen
    old = {cid: frames(doc.channels[cid]) for cid in chosen}
    steps = ctx.undo_stack.index()
    key = view.key_pos(pip, min(old[c][i] for c, idx in chosen.items() for i in idx))
    drag(qtbot, view, key, key + QPoint(int(round(3 * view.px_per_frame)), 0), steps=3)
    assert ctx.undo_stack.index() == steps + 1
    for cid, idx in chosen.items():
        moved = sorted(old[cid][i] + 3 for i in idx)
        assert sorted(frames(doc.channels[cid])[i] for i in selected(ctx)[cid]) == moved
    ctx.undo_stack.undo()
    assert saved(doc, tmp_path) == before
