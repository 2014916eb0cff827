"""The outliner (the jointTreeDock's tree) with real clicks and keys: eye and lock toggles,
rename (F2), delete, the context menu, and selection of cloths and lights."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt
from PySide6.QtWidgets import QApplication, QDockWidget, QGraphicsView, QLineEdit, QMenu

from qtanimator.document import character2d as c2d
from qtanimator.document import outliner
from qtanimator.document.cloth import add_cloth_command
from qtanimator.document.commands import UndoStack
from qtanimator.document.document import Asset, Document
from qtanimator.render.painter2d import image_to_array, render_frame
from qtanimator.ui.joint_tree import EYE_COLUMN, LOCK_COLUMN
from qtanimator.ui.rig_interaction import pick


@pytest.fixture
def arm(make_window, qtbot, shared_data):
    window = make_window()
    assert window.open_path(shared_data / "cmu-animator" / "scenes" / "arm.svg")
    view = window.findChild(QGraphicsView, "rigEditorView")
    view.fit_view()
    qtbot.wait(10)
    asset = next(iter(window.doc.assets))
    # Some keys and a limit, so that a rename has channels and parameters to carry.
    window.ctx.push(c2d.key_joint(window.doc, asset, 1, 0.4, 0.0))
    window.ctx.push(c2d.key_joint(window.doc, asset, 2, -0.3, 0.5))
    name = window.doc.runtime[asset].joints[1].name
    window.ctx.push(c2d.set_joint_limits_command(window.doc, asset, name, -1.0, 1.0))
    window.ctx.undo_stack.clear()
    return window, view, asset


def click(qtbot, tree, item, column: int = 0, button=Qt.MouseButton.LeftButton) -> None:
    rect = tree.toggle_rect(item, column)
    qtbot.mouseClick(tree.viewport(), button, pos=rect.center())


def view_pixels(view) -> np.ndarray:
    return image_to_array(view.viewport().grab().toImage())


def test_eye_hides_a_character_everywhere_and_undo_is_exact(qtbot, arm):
    window, view, asset = arm
    doc, tree = window.doc, window.joint_tree.tree
    before, pixels = doc.state(), view_pixels(view)
    rendered = image_to_array(render_frame(doc, 0.0, (200, 150)))
    point = np.array(doc.runtime[asset].rest_pivots[1])
    row = tree.item_for(asset, "")
    click(qtbot, tree, row, EYE_COLUMN)
    assert doc.assets[asset].properties["hidden"] is True
    assert window.ctx.undo_stack.count() == 1
    qtbot.wait(20)
    hidden_pixels = view_pixels(view)
    assert (hidden_pixels != pixels).any()
    # Only the background is left: the 2D view is one colour, a render is blank.
    assert len(np.unique(hidden_pixels.reshape(-1, 4), axis=0)) < len(np.unique(pixels.reshape(-1, 4), axis=0))
    blank = image_to_array(render_frame(doc, 0.0, (200, 150)))
    assert (blank == 255).all() and not (rendered == 255).all()
    assert outliner.is_hidden(doc, asset) and pick(doc, 0.0, point) is None
    row = tree.item_for(asset, "")  # the tree was rebuilt
    assert "hidden" in row.toolTip(EYE_COLUMN)
    window.ctx.undo_stack.undo()
    assert doc.state() == before
    qtbot.wait(20)
    assert (view_pixels(view) == pixels).all()


def test_lock_keeps_a_character_from_being_picked_or_dragged(qtbot, arm):
    window, view, asset = arm
    doc, tree = window.doc, window.joint_tree.tree
    click(qtbot, tree, tree.item_for(asset, ""), LOCK_COLUMN)
    assert outliner.is_locked(doc, asset)
    window.ctx.select("", "")
    locked = doc.state()
    pose = c2d.evaluate_pose(doc, asset, 0.0)
    start_xy = pose.to_world(0, doc.runtime[asset].joints[0].shapes[0].points.mean(axis=0))
    start = view.from_scene(start_xy).toPoint()
    vp = view.viewport()
    qtbot.mousePress(vp, Qt.MouseButton.LeftButton, pos=start)
    qtbot.mouseMove(vp, start + QPoint(30, 10))
    qtbot.mouseMove(vp, start + QPoint(60, 20))
    qtbot.mouseRelease(vp, Qt.MouseButton.LeftButton, pos=start + QPoint(60, 20))
    assert doc.state() == locked and window.ctx.selection == ("", "")
    # Unlocked, the same drag poses the character.
    window.ctx.undo_stack.undo()
    locked = doc.state()
    assert not outliner.is_locked(doc, asset)
    qtbot.mousePress(vp, Qt.MouseButton.LeftButton, pos=start)
    qtbot.mouseMove(vp, start + QPoint(30, 10))
    qtbot.mouseMove(vp, start + QPoint(60, 20))
    qtbot.mouseRelease(vp, Qt.MouseButton.LeftButton, pos=start + QPoint(60, 20))
    assert window.ctx.selection[0] == asset and doc.state() != locked


def _rename_editor(qtbot, tree) -> QLineEdit:
    qtbot.waitUntil(lambda: isinstance(QApplication.focusWidget(), QLineEdit))
    editor = QApplication.focusWidget()
    assert tree.isAncestorOf(editor)
    return editor


def test_f2_renames_the_asset_its_channels_and_selection_with_exact_undo(qtbot, arm):
    window, _view, asset = arm
    doc, tree = window.doc, window.joint_tree.tree
    joint = doc.runtime[asset].joints[1].name
    old_channels = sorted(cid for cid, _ in doc.channels_of(asset))
    assert old_channels
    click(qtbot, tree, tree.item_for(asset, joint))
    assert window.ctx.selection == (asset, joint)
    before = doc.state()
    qtbot.keyClick(tree, Qt.Key.Key_F2)  # the joint's row: only assets are renamed
    assert tree.state() != tree.State.EditingState
    click(qtbot, tree, tree.item_for(asset, ""))
    qtbot.keyClick(tree, Qt.Key.Key_F2)
    editor = _rename_editor(qtbot, tree)
    editor.selectAll()
    qtbot.keyClicks(editor, "limb")
    qtbot.keyClick(editor, Qt.Key.Key_Return)
    qtbot.waitUntil(lambda: "limb" in doc.assets)
    assert asset not in doc.assets and list(doc.assets) == ["limb"]
    assert sorted(cid for cid, _ in doc.channels_of("limb")) == ["limb/" + c.split("/", 1)[1] for c in old_channels]
    assert not list(doc.channels_of(asset))
    assert f"limb.limits.{joint}" in doc.parameters and f"{asset}.limits.{joint}" not in doc.parameters
    assert window.ctx.selection == ("limb", "")
    assert tree.item_for("limb", joint) is not None
    assert window.ctx.undo_stack.count() == 1
    after = doc.state()
    window.ctx.undo_stack.undo()
    assert doc.state() == before
    window.ctx.undo_stack.redo()
    assert doc.state() == after


def test_a_name_in_use_is_refused(qtbot, arm):
    window, _view, asset = arm
    doc, tree = window.doc, window.joint_tree.tree
    window.ctx.push(add_cloth_command(doc, asset_id="cloth"))
    before, steps = doc.state(), window.ctx.undo_stack.count()
    row = tree.item_for(asset, "")
    qtbot.mouseDClick(tree.viewport(), Qt.MouseButton.LeftButton, pos=tree.toggle_rect(row, 0).center())
    editor = _rename_editor(qtbot, tree)
    editor.selectAll()
    qtbot.keyClicks(editor, "cloth")
    qtbot.keyClick(editor, Qt.Key.Key_Return)
    qtbot.waitUntil(lambda: "already in use" in tree.last_message)
    assert doc.state() == before and window.ctx.undo_stack.count() == steps
    assert tree.item_for(asset, "").text(0) == asset
    for bad in ("", "a/b", "light1"):
        assert not tree.rename(asset, bad)
    assert doc.state() == before


def test_delete_removes_the_asset_and_undo_is_exact(qtbot, arm):
    window, _view, asset = arm
    doc, tree = window.doc, window.joint_tree.tree
    before = doc.state()
    click(qtbot, tree, tree.item_for(asset, ""))
    qtbot.keyClick(tree, Qt.Key.Key_Delete)
    assert asset not in doc.assets and not list(doc.channels_of(asset))
    assert window.ctx.selection == ("", "") and tree.item_for(asset, "") is None
    window.ctx.undo_stack.undo()
    assert doc.state() == before
    assert tree.item_for(asset, "") is not None


def _menu_action(qtbot, tree, item, name: str):
    """Right-click ``item`` and click the menu action ``name`` with the mouse."""
    click(qtbot, tree, item, 0, Qt.MouseButton.RightButton)
    qtbot.waitUntil(lambda: tree.menu is not None and tree.menu.isVisible())
    menu: QMenu = tree.menu
    action = next(a for a in menu.actions() if a.objectName() == name)
    qtbot.mouseClick(menu, Qt.MouseButton.LeftButton, pos=menu.actionGeometry(action).center())


def test_context_menu_frames_hides_and_removes(qtbot, arm):
    window, view, asset = arm
    doc, tree = window.doc, window.joint_tree.tree
    view.scale(0.2, 0.2)
    view.horizontalScrollBar().setValue(view.horizontalScrollBar().value() + 200)
    zoomed = view.transform()
    _menu_action(qtbot, tree, tree.item_for(asset, ""), "outlinerFrame")
    qtbot.waitUntil(lambda: view.transform() != zoomed)
    assert view.transform().m11() > zoomed.m11() * 2
    # The character now fills the view: its bounds lie inside the viewport.
    x0, y0, x1, y1 = doc.runtime[asset].bounds(c2d.evaluate_pose(doc, asset, 0.0))
    shown = view.viewport().rect()
    for corner in ((x0, y0), (x1, y1)):
        assert shown.adjusted(-2, -2, 2, 2).contains(view.from_scene(corner).toPoint())
    before = doc.state()
    _menu_action(qtbot, tree, tree.item_for(asset, ""), "outlinerHide")
    assert outliner.is_hidden(doc, asset)
    _menu_action(qtbot, tree, tree.item_for(asset, ""), "outlinerHide")  # now "Show"
    assert doc.state() == before
    _menu_action(qtbot, tree, tree.item_for(asset, ""), "outlinerRemove")
    assert asset not in doc.assets
    window.ctx.undo_stack.undo()
    assert doc.state() == before


def test_cloth_and_light_rows(qtbot, make_window):
    from qtanimator.render.gl.lights import lights_of
    from qtanimator.render.scene3d import scene_items

    window = make_window(editors=("rig_editor", "timeline", "joint_tree", "properties", "light_panel"))
    doc, tree = window.doc, window.joint_tree.tree
    window.ctx.push(add_cloth_command(doc, asset_id="cloth"))
    row = tree.item_for("cloth", "")
    assert row is not None
    click(qtbot, tree, row)
    assert window.ctx.selection == ("cloth", "")
    window.ctx.select("", "")
    assert tree.currentItem() is None
    window.ctx.select("cloth", "")
    assert tree.currentItem() is tree.item_for("cloth", "")
    # Hiding the cloth takes it out of the 3D scene; its simulation cache stays valid.
    assert [getattr(i, "asset_id", None) for i in scene_items(doc, 0.0)] == ["cloth"]
    cache = doc.runtime["cloth"]
    click(qtbot, tree, tree.item_for("cloth", ""), EYE_COLUMN)
    assert scene_items(doc, 0.0) == []
    assert cache.matches(doc.assets["cloth"].properties, doc.fps, doc.frame_range[0])
    # The lights: the eye switches one off, the lock keeps its gizmo from being picked.
    before = doc.state()
    light = tree.light_item("light1")
    click(qtbot, tree, light, EYE_COLUMN)
    assert doc.parameters["light1.hidden"] is True and lights_of(doc)[0].intensity == 0.0
    assert "hidden" in tree.light_item("light1").toolTip(EYE_COLUMN)
    click(qtbot, tree, tree.light_item("light2"), LOCK_COLUMN)
    assert outliner.is_locked(doc, "light2")
    window.ctx.undo_stack.undo()
    window.ctx.undo_stack.undo()
    assert doc.state() == before
    # Selecting a light's row shows the Lights dock; a light cannot be removed.
    click(qtbot, tree, tree.light_item("light2"))
    dock = window.findChild(QDockWidget, "lightDock")
    assert dock is not None and dock.isVisible()
    qtbot.keyClick(tree, Qt.Key.Key_Delete)
    assert "cannot be removed" in tree.last_message and doc.state() == before


def test_rename_command_is_exact_without_qt():
    doc = Document()
    stack = UndoStack(doc)
    for aid in ("a", "a.b", "c"):
        doc.apply_asset(aid, Asset(aid, "thing", None, {"x": 1}))
    from qtanimator.core.channel import Channel, Key

    doc.apply_channel("a/j/angle", Channel().set_key(Key(0.0, 1.0)))
    doc.apply_channel("a.b/j/angle", Channel().set_key(Key(0.0, 2.0)))
    doc.apply_parameter("a.limits.j", [0, 1])
    doc.apply_parameter("a.b.limits.j", [0, 2])
    before = doc.state()
    stack.push(outliner.rename_command(doc, "a", "z"))
    assert list(doc.assets) == ["z", "a.b", "c"] and doc.assets["z"].id == "z"
    assert set(doc.channels) == {"z/j/angle", "a.b/j/angle"}
    assert set(doc.parameters) >= {"z.limits.j", "a.b.limits.j"} and "a.limits.j" not in doc.parameters
    stack.undo()
    assert doc.state() == before
    with pytest.raises(ValueError, match="in use"):
        outliner.rename_command(doc, "a", "c")
