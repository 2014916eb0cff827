"""Keys go where the user expects (issue 30): unbound Ctrl / Alt / Meta letters do nothing in
the 3D view, and a letter typed in the outliner with the pointer over a view is the view's key
(Blender's rule), never a type-ahead jump to another row."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt
from PySide6.QtGui import QCursor
from samples import BLENDER_BVH

from qtanimator.ui import viewport
from qtanimator.ui.key_routing import view_under_mouse

CTRL, ALT, META = (Qt.KeyboardModifier.ControlModifier, Qt.KeyboardModifier.AltModifier,
                   Qt.KeyboardModifier.MetaModifier)


@pytest.fixture
def cloth_view(make_window):
    from qtanimator.core.cloth import ClothParams
    from qtanimator.document.cloth import add_cloth_command

    window = make_window(editors=("viewport",), size=(640, 480))
    window.ctx.push(add_cloth_command(window.doc, ClothParams(rows=8, cols=8)))
    view = window.viewport3d
    view.setFocus()
    return view


def test_unbound_command_letters_move_no_pin_and_leave_interactive_off(cloth_view, qtbot):
    view = cloth_view
    switched: list[bool] = []
    view.liveClothChanged.connect(switched.append)
    camera = (view.camera.distance, view.camera.azimuth, view.camera.inclination)
    # (Not Ctrl+Z, Ctrl+Q …: those are the window's Undo, Quit.)
    for key, mods in ((Qt.Key.Key_A, CTRL), (Qt.Key.Key_D, CTRL), (Qt.Key.Key_W, ALT), (Qt.Key.Key_Z, ALT),
                      (Qt.Key.Key_E, META), (Qt.Key.Key_Q, ALT | Qt.KeyboardModifier.ShiftModifier),
                      (Qt.Key.Key_F, CTRL), (Qt.Key.Key_P, CTRL)):
        qtbot.keyClick(view, key, mods)
    assert not view.live.enabled and switched == [] and not view.live.paused
    assert (view.camera.distance, view.camera.azimuth, view.camera.inclination) == camera
    # With the interactive cloth on, Ctrl+A / Ctrl+D still move no pin; plain A does.
    view.set_live_cloth(True)
    view.live.paused = True
    assert view.live.settle()
    cloth = view.live.cloths["cloth"]
    before = cloth.pin_targets.copy()
    qtbot.keyClick(view, Qt.Key.Key_A, CTRL)
    qtbot.keyClick(view, Qt.Key.Key_D, CTRL)
    qtbot.keyClick(view, Qt.Key.Key_C, ALT)
    np.testing.assert_array_equal(cloth.pin_targets, before)
    qtbot.keyClick(view, Qt.Key.Key_A)
    np.testing.assert_allclose(cloth.pin_targets - before,
                               np.tile([-viewport.PIN_STEP, 0.0, 0.0], (len(before), 1)), atol=1e-12)
    view.set_live_cloth(False)


def test_plain_a_switches_the_interactive_cloth_on_and_moves_the_pins(cloth_view, qtbot):
    view = cloth_view
    qtbot.keyClick(view, Qt.Key.Key_A)
    assert view.live.enabled
    view.set_live_cloth(False)


# ------------------------------------------------------------------ the outliner
@pytest.fixture
def outliner_window(make_window, tmp_path):
    window = make_window(editors=("viewport", "import3d", "joint_tree"), size=(1000, 700))
    bvh = tmp_path / "walker.bvh"
    bvh.write_text(BLENDER_BVH.replace("Leg", "forearm_left"), encoding="utf-8")
    assert window.open_path(bvh)
    window.central_tabs.setCurrentWidget(window.viewport_panel)
    return window


def _point_at(qtbot, widget) -> None:
    QCursor.setPos(widget.mapToGlobal(widget.rect().center()))
    qtbot.wait(10)


def _count_frames(view, monkeypatch) -> list[int]:
    calls: list[int] = []
    original = view.frame_selection

    def frame_selection() -> None:
        calls.append(1)
        original()

    monkeypatch.setattr(view, "frame_selection", frame_selection)
    return calls


def test_f_after_clicking_an_outliner_row_frames_the_view(outliner_window, qtbot, monkeypatch):
    window = outliner_window
    view = window.viewport3d
    tree = window.joint_tree.tree
    row = tree.topLevelItem(0)
    assert row.text(0) == "walker"
    row.setExpanded(True)
    qtbot.mouseClick(tree.viewport(), Qt.MouseButton.LeftButton, pos=tree.visualItemRect(row).center())
    assert tree.currentItem() is row and window.ctx.selection == ("walker", "")
    tree.setFocus()
    framed = _count_frames(view, monkeypatch)
    _point_at(qtbot, view)
    if view_under_mouse() is not view:
        pytest.skip(f"the pointer cannot be moved on the '{window.windowHandle().screen().name()}' screen")
    # F (forearm_left's first letter) with the pointer over the 3D view: the view frames.
    qtbot.keyClick(tree, Qt.Key.Key_F)
    assert framed == [1]
    assert tree.currentItem() is row and tree.hasFocus()
    # Any letter goes there: the tree never jumps to "forearm_left" by type-ahead.
    qtbot.keyClick(tree, Qt.Key.Key_X)   # X: the 3D view's axes
    assert view.options.show_axes and tree.currentItem() is row
    # The pointer over the tree itself: F frames the current row's asset, still no type-ahead.
    _point_at(qtbot, tree)
    qtbot.keyClick(tree, Qt.Key.Key_F)
    assert framed == [1, 1] and tree.currentItem() is row
    qtbot.keyClick(tree, Qt.Key.Key_H)
    assert tree.currentItem() is row


def test_the_outliner_has_no_type_ahead(outliner_window, qtbot):
    tree = outliner_window.joint_tree.tree
    _point_at(qtbot, tree)
    tree.setFocus()
    tree.setCurrentItem(tree.topLevelItem(0))
    tree.keyboardSearch("forearm")
    assert tree.currentItem() is tree.topLevelItem(0)
    # The arrows still move between rows.
    tree.topLevelItem(0).setExpanded(True)
    qtbot.keyClick(tree, Qt.Key.Key_Down)
    assert tree.currentItem() is not tree.topLevelItem(0)


def test_letters_in_a_tree_away_from_the_views_stay_in_the_tree(outliner_window, qtbot, monkeypatch):
    window = outliner_window
    view = window.viewport3d
    framed = _count_frames(view, monkeypatch)
    tree = window.joint_tree.tree
    tree.setFocus()
    QCursor.setPos(window.mapToGlobal(QPoint(-50, -50)))   # outside the window
    qtbot.wait(10)
    assert view_under_mouse() is None
    qtbot.keyClick(tree, Qt.Key.Key_X)
    assert not view.options.show_axes and framed == []
