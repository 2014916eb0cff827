"""Characters with several clips (issue 21) in the window: the clip pickers of the Properties
dock and of the 3D view, and the DOF sliders of joints keyed as quaternions. Real widgets,
real clicks and key presses."""

from __future__ import annotations

import math

import gltf_gen
import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt
from PySide6.QtWidgets import QApplication, QComboBox, QSlider, QStyle, QStyleOptionSlider, QToolButton

from qtanimator.core.rotation import rotation_matrices
from qtanimator.document import character3d
from qtanimator.document.commands import UndoStack
from qtanimator.document.document import Document
from qtanimator.document.import3d import import_file

AID = "three_animations"
#: The file's clips: (start, end) seconds, and the frame range each fits (60 fps).
CLIPS = {"idle": (0.0, 1.0), "walk": (0.0, 2.0), "run": (0.25, 0.75)}
RANGES = {"idle": (0, 60), "walk": (0, 120), "run": (15, 45)}
LABELS = ["idle (1 s)", "walk (2 s)", "run (0.5 s)"]


@pytest.fixture
def clips_file(tmp_path):
    return gltf_gen.three_animations(tmp_path)


def _open(window, path):
    assert window.open_path(path)
    window.ctx.undo_stack.clear()
    assert window.ctx.selection[0] == AID
    return window


@pytest.fixture
def docks(make_window, clips_file):
    """The window without the 3D view: Properties, Joints, timeline."""
    return _open(make_window(editors=("import3d", "timeline", "joint_tree", "properties")), clips_file)


@pytest.fixture
def full(make_window, clips_file):
    """The window with the 3D view (its clip picker) as well."""
    return _open(make_window(editors=("viewport", "import3d", "timeline", "joint_tree", "properties")), clips_file)


# ------------------------------------------------------------------ helpers
def properties_combo(window) -> QComboBox:
    combo = window.properties_panel.findChild(QComboBox, "characterClip")
    assert combo is not None
    return combo


def toolbar_combo(window) -> QComboBox:
    combo = window.viewport_panel.findChild(QComboBox, "viewportClip")
    assert combo is not None
    return combo


def shown(combo: QComboBox) -> str:
    return combo.currentText() if combo.currentIndex() >= 0 else ""


def pick(qtbot, combo: QComboBox, label: str) -> None:
    """Open the combo with a click and click the item ``label`` in its list."""
    index = combo.findText(label)
    assert index >= 0, [combo.itemText(i) for i in range(combo.count())]
    qtbot.waitUntil(combo.isVisible)
    qtbot.mouseClick(combo, Qt.MouseButton.LeftButton)
    view = combo.view()
    qtbot.waitUntil(view.isVisible)
    # The popup ignores a release within a double-click interval of opening (Qt's guard
    # against the opening click choosing an item), as a user's slower hand never meets it.
    qtbot.wait(QApplication.doubleClickInterval() + 50)
    rect = view.visualRect(view.model().index(index, 0))
    qtbot.mouseMove(view.viewport(), rect.center())
    qtbot.mouseClick(view.viewport(), Qt.MouseButton.LeftButton, pos=rect.center())
    qtbot.waitUntil(lambda: not view.isVisible())


def active(window) -> str | None:
    clip = character3d.active_clip(window.doc, AID)
    return None if clip is None else clip.name


def root_position(doc, time: float) -> np.ndarray:
    skel = character3d.pose_skeleton(doc, AID, time)
    return skel.world_matrices()[skel.joint_keys().index("root"), :3, 3]


def reference_skin(path, clip: str, time: float) -> np.ndarray:
    """The skinned positions of the character playing ``clip`` at ``time``, in a document of
    its own switched without any widget."""
    doc = Document()
    stack = UndoStack(doc)
    stack.push(import_file(doc, path).command)
    if character3d.active_clip(doc, AID).name != clip:
        stack.push(character3d.set_clip_command(doc, AID, clip))
    return character3d.skinned_mesh(doc, AID, time)[0]


def undo(qtbot, window) -> None:
    qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)


def redo(qtbot, window) -> None:
    qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.ShiftModifier)


def handle_center(slider: QSlider) -> QPoint:
    opt = QStyleOptionSlider()
    slider.initStyleOption(opt)
    rect = slider.style().subControlRect(QStyle.ComplexControl.CC_Slider, opt,
                                         QStyle.SubControl.SC_SliderHandle, slider)
    return rect.center()


def drag(qtbot, slider: QSlider, dx: int) -> None:
    qtbot.waitUntil(slider.isVisible)
    start = handle_center(slider)
    qtbot.mousePress(slider, Qt.MouseButton.LeftButton, pos=start)
    for k in (1, 2, 3, 4):
        qtbot.mouseMove(slider, start + QPoint(dx * k // 4, 0))
    qtbot.mouseRelease(slider, Qt.MouseButton.LeftButton, pos=start + QPoint(dx, 0))


def select_joint(qtbot, window, joint: str) -> None:
    tree = window.joint_tree.tree
    item = tree.item_for(AID, joint)
    tree.scrollToItem(item)
    qtbot.mouseClick(tree.viewport(), Qt.MouseButton.LeftButton, pos=tree.visualItemRect(item).center())
    assert window.ctx.selection == (AID, joint)


def local_rotation(doc, joint: str, time: float) -> np.ndarray:
    skel = character3d.pose_skeleton(doc, AID, time)
    j = skel.joint_keys().index(joint)
    world = skel.world_matrices()
    parent = skel.joints[j].parent
    local = world[j] if parent is None else np.linalg.inv(world[parent]) @ world[j]
    return local[:3, :3]


def row(window, label: str):
    """The DOF panel's row ``label`` (by the panel's rows: rows replaced when the selection
    changed are deleted only later, so a search by object name could find one of those)."""
    rows = {r.spec.label: r for r in window.joint_tree.dofs.rows}
    assert label in rows, list(rows)
    assert rows[label].slider.objectName() == f"dofSlider_{label.replace(' ', '_')}"
    return rows[label]


def slider(window, label: str) -> QSlider:
    return row(window, label).slider


# ------------------------------------------------------------- the pickers
def test_properties_lists_the_clips_and_picking_one_plays_it(qtbot, docks, clips_file):
    window, doc = docks, docks.doc
    combo = properties_combo(window)
    assert [combo.itemText(i) for i in range(combo.count())] == LABELS
    assert shown(combo) == "idle (1 s)" and doc.frame_range == RANGES["idle"]
    before = character3d.skinned_mesh(doc, AID, 0.5)[0]
    assert root_position(doc, 0.5) == pytest.approx([0.0, 0.0, 0.0])

    pick(qtbot, combo, "walk (2 s)")
    qtbot.waitUntil(lambda: active(window) == "walk")
    assert doc.frame_range == RANGES["walk"]
    assert doc.assets[AID].properties["clip"] == "walk"
    assert window.ctx.undo_stack.count() == 1       # one undo step
    # the shown pose is the walk's: the root travels 2 along z over 2 s
    assert root_position(doc, 0.5) == pytest.approx([0.0, 0.0, 0.5])
    walking = character3d.skinned_mesh(doc, AID, 0.5)[0]
    assert np.abs(walking - before).max() > 0.3
    assert np.allclose(walking, reference_skin(clips_file, "walk", 0.5))
    assert shown(properties_combo(window)) == "walk (2 s)"   # the rebuilt dock shows it

    undo(qtbot, window)
    assert active(window) == "idle" and doc.frame_range == RANGES["idle"]
    assert np.array_equal(character3d.skinned_mesh(doc, AID, 0.5)[0], before)
    assert shown(properties_combo(window)) == "idle (1 s)"
    redo(qtbot, window)
    assert active(window) == "walk" and shown(properties_combo(window)) == "walk (2 s)"


def test_picking_the_clip_shown_pushes_nothing(qtbot, docks):
    combo = properties_combo(docks)
    pick(qtbot, combo, "idle (1 s)")
    qtbot.wait(20)
    assert docks.ctx.undo_stack.count() == 0 and active(docks) == "idle"


@pytest.mark.gl
def test_toolbar_picker_plays_a_clip_over_its_own_range_and_both_pickers_follow_undo(qtbot, full, clips_file):
    window, doc = full, full.doc
    bar = toolbar_combo(window)
    assert bar.isVisibleTo(window) and bar.isEnabled()
    assert [bar.itemText(i) for i in range(bar.count())] == LABELS
    assert shown(bar) == "idle (1 s)"

    pick(qtbot, bar, "run (0.5 s)")
    assert active(window) == "run"
    # the run starts late: the range is its own, 0.25 … 0.75 s
    assert doc.frame_range == RANGES["run"]
    assert root_position(doc, 0.5) == pytest.approx([0.0, 0.1, 0.75])
    assert np.allclose(character3d.skinned_mesh(doc, AID, 0.5)[0], reference_skin(clips_file, "run", 0.5))
    assert shown(bar) == "run (0.5 s)" and shown(properties_combo(window)) == "run (0.5 s)"

    pick(qtbot, properties_combo(window), "walk (2 s)")
    qtbot.waitUntil(lambda: active(window) == "walk")
    assert shown(bar) == "walk (2 s)"        # the toolbar follows the Properties dock
    assert window.ctx.undo_stack.count() == 2

    undo(qtbot, window)
    assert active(window) == "run" and doc.frame_range == RANGES["run"]
    assert shown(bar) == "run (0.5 s)" and shown(properties_combo(window)) == "run (0.5 s)"
    undo(qtbot, window)
    assert active(window) == "idle" and doc.frame_range == RANGES["idle"]
    assert shown(bar) == "idle (1 s)" and shown(properties_combo(window)) == "idle (1 s)"
    assert root_position(doc, 0.5) == pytest.approx([0.0, 0.0, 0.0])


@pytest.mark.gl
def test_toolbar_picker_acts_on_the_selected_character(qtbot, full, clips_file):
    window, doc = full, full.doc
    picker = window.viewport_panel.findChild(QComboBox, "viewportClip").parentWidget()
    assert window.open_path(clips_file)         # a second character with the same clips
    second = [a for a in doc.assets if a != AID][0]
    bar = toolbar_combo(window)
    window.ctx.select(second, "")
    pick(qtbot, bar, "walk (2 s)")
    assert character3d.active_clip(doc, second).name == "walk" and active(window) == "idle"
    window.ctx.select(AID, "")
    assert shown(bar) == "idle (1 s)"
    window.ctx.select("", "")                   # two characters, none selected: nothing to pick for
    assert not bar.isEnabled() and shown(bar) == ""
    window.ctx.select(second, "spine")          # a joint selects its character
    assert bar.isEnabled() and shown(bar) == "walk (2 s)"
    # no character with clips: the picker is hidden
    window.ctx.undo_stack.setClean()
    window.new_document()
    assert not picker.isVisibleTo(window)


@pytest.mark.gl
def test_the_choice_and_each_clips_edits_are_saved_with_the_project(qtbot, full, tmp_path):
    window, doc = full, full.doc
    pick(qtbot, toolbar_combo(window), "walk (2 s)")
    # key the spine in the walk (typed in the DOF panel), then leave the walk and come back
    window.ctx.set_frame(30.0)
    window.ctx.select(AID, "spine")
    spin = row(window, "rotate x").spin
    spin.lineEdit().selectAll()
    qtbot.keyClicks(spin.lineEdit(), "30")
    qtbot.keyClick(spin.lineEdit(), Qt.Key.Key_Return)
    spine = character3d.pose_skeleton(doc, AID, 0.5).joints[1]
    assert math.degrees(spine.dofs[0].value) == pytest.approx(30.0)
    pick(qtbot, toolbar_combo(window), "idle (1 s)")
    assert math.degrees(character3d.pose_skeleton(doc, AID, 0.5).joints[1].dofs[0].value) == pytest.approx(0.0)
    pick(qtbot, toolbar_combo(window), "walk (2 s)")
    assert math.degrees(character3d.pose_skeleton(doc, AID, 0.5).joints[1].dofs[0].value) == pytest.approx(30.0)
    pick(qtbot, toolbar_combo(window), "idle (1 s)")

    project = tmp_path / "clips.qtanim"
    assert window.save_to(project)
    pick(qtbot, toolbar_combo(window), "run (0.5 s)")   # changed after saving: the project has idle
    assert window.open_path(project)
    doc = window.doc
    assert active(window) == "idle" and doc.frame_range == RANGES["idle"]
    window.ctx.select(AID, "")
    assert shown(toolbar_combo(window)) == "idle (1 s)" and shown(properties_combo(window)) == "idle (1 s)"
    # the walk's edit was saved with it
    pick(qtbot, properties_combo(window), "walk (2 s)")
    qtbot.waitUntil(lambda: active(window) == "walk")
    assert shown(toolbar_combo(window)) == "walk (2 s)"
    assert math.degrees(character3d.pose_skeleton(doc, AID, 0.5).joints[1].dofs[0].value) == pytest.approx(30.0)


# ------------------------------------------------------- quaternion joints
def test_dof_sliders_of_a_quaternion_joint_key_the_euler_angles_as_a_quaternion(qtbot, docks):
    window, doc = docks, docks.doc
    window.ctx.set_frame(15.0)                  # 0.25 s: between the idle's keys (0°, 8°, 0° about z)
    select_joint(qtbot, window, "spine")
    assert doc.runtime[AID].skeleton.joints[1].quaternion
    labels = [row.spec.label for row in window.joint_tree.dofs.rows]
    assert labels == ["rotate x", "rotate y", "rotate z"]
    values = {row.spec.label: row.spin.value() for row in window.joint_tree.dofs.rows}
    assert values == pytest.approx({"rotate x": 0.0, "rotate y": 0.0, "rotate z": 4.0}, abs=1e-6)
    assert slider(window, "rotate y").maximum() == 900   # the middle angle of Rz·Ry·Rx is within ±90°
    channels = {c: ch for c, ch in doc.channels.items() if "/spine/" in c}
    assert sorted(c.rsplit("/", 1)[1] for c in channels) == ["qw", "qx", "qy", "qz"]

    s = slider(window, "rotate x")
    drag(qtbot, s, 30)
    x = s.value() / 10.0
    assert x > 5
    assert window.ctx.undo_stack.count() == 1             # the drag is one undo step
    # every component got a key at 0.25 s, and no Euler channel appeared
    for cid in channels:
        assert any(abs(k.time - 0.25) < 1e-9 for k in doc.channels[cid].keys), cid
    assert not any(c.endswith(("/rx", "/ry", "/rz")) for c in doc.channels if "/spine/" in c)
    expected = rotation_matrices([math.radians(x), 0.0, math.radians(4.0)], "zyx")[0]
    assert np.allclose(local_rotation(doc, "spine", 0.25), expected, atol=1e-9)
    assert window.joint_tree.dofs.rows[0].spin.value() == pytest.approx(x)
    assert window.joint_tree.dofs.rows[2].spin.value() == pytest.approx(4.0)
    # keyboard: Page Up turns y by 10°, one step of its own
    y_slider = slider(window, "rotate y")
    y_slider.setFocus()
    qtbot.keyClick(y_slider, Qt.Key.Key_PageUp)
    assert window.ctx.undo_stack.count() == 2
    expected = rotation_matrices([math.radians(x), math.radians(10.0), math.radians(4.0)], "zyx")[0]
    assert np.allclose(local_rotation(doc, "spine", 0.25), expected, atol=1e-9)
    undo(qtbot, window)
    undo(qtbot, window)
    assert all(doc.channels[cid] is ch for cid, ch in channels.items())


def test_with_auto_key_off_a_quaternion_joint_is_posed_without_keys(qtbot, docks):
    window, doc = docks, docks.doc
    button = window.findChild(QToolButton, "autoKeyButton")
    assert button.isChecked()
    qtbot.mouseClick(button, Qt.MouseButton.LeftButton)
    assert not button.isChecked()
    window.ctx.set_frame(15.0)
    select_joint(qtbot, window, "spine")
    channels = dict(doc.channels)
    s = slider(window, "rotate y")
    drag(qtbot, s, -30)
    y = s.value() / 10.0
    assert y < -5
    assert dict(doc.channels) == channels and all(doc.channels[c] is ch for c, ch in channels.items())
    assert window.ctx.undo_stack.count() == 0
    # the preview shows the Euler angle (not an angle written into a quaternion component)
    expected = rotation_matrices([0.0, math.radians(y), math.radians(4.0)], "zyx")[0]
    assert np.allclose(local_rotation(doc, "spine", 0.25), expected, atol=1e-9)
    assert s.value() / 10.0 == pytest.approx(y)
    # another frame drops the unkeyed pose
    window.ctx.set_frame(16.0)
    window.ctx.set_frame(15.0)
    expected = rotation_matrices([0.0, 0.0, math.radians(4.0)], "zyx")[0]
    assert np.allclose(local_rotation(doc, "spine", 0.25), expected, atol=1e-9)


def test_a_moving_joint_has_translate_sliders(qtbot, docks):
    window, doc = docks, docks.doc
    pick(qtbot, properties_combo(window), "walk (2 s)")
    qtbot.waitUntil(lambda: active(window) == "walk")
    window.ctx.set_frame(30.0)
    select_joint(qtbot, window, "root")       # the walk moves the root joint
    labels = [row.spec.label for row in window.joint_tree.dofs.rows]
    assert labels == ["rotate x", "rotate y", "rotate z", "translate x", "translate y", "translate z"]
    spin = row(window, "translate y").spin
    assert spin.value() == pytest.approx(0.0)
    spin.lineEdit().selectAll()
    qtbot.keyClicks(spin.lineEdit(), "0.25")
    qtbot.keyClick(spin.lineEdit(), Qt.Key.Key_Return)
    assert doc.channels[f"{AID}/root/ty"].evaluate(0.5) == pytest.approx(0.25)
    assert root_position(doc, 0.5) == pytest.approx([0.0, 0.25, 0.5])
    s = slider(window, "translate y")
    assert s.value() == round(0.25 * window.joint_tree.dofs.rows[4].steps)


def test_a_scaling_joint_has_scale_sliders(qtbot, make_window, tmp_path):
    window = make_window(editors=("import3d", "timeline", "joint_tree", "properties"))
    assert window.open_path(gltf_gen.scale_keys(tmp_path))
    aid = window.ctx.selection[0]
    window.ctx.select(aid, "stretch")
    rows = {row.spec.label: row for row in window.joint_tree.dofs.rows}
    assert {"scale x", "scale y", "scale z"} <= set(rows)
    spin = rows["scale x"].spin
    spin.lineEdit().selectAll()
    qtbot.keyClicks(spin.lineEdit(), "2")
    qtbot.keyClick(spin.lineEdit(), Qt.Key.Key_Return)
    skel = character3d.pose_skeleton(window.doc, aid, window.ctx.time)
    assert skel.joints[skel.joint_keys().index("stretch")].scale[0] == pytest.approx(2.0)


def rotation_combo(window) -> QComboBox:
    combo = window.properties_panel.findChild(QComboBox, "rotationMode")
    assert combo is not None
    return combo


def test_rotation_keys_switch_to_euler_curves_in_properties_and_undo(qtbot, docks, clips_file):
    window = docks
    doc = window.doc
    combo = rotation_combo(window)
    assert shown(combo) == "quaternion"
    before = character3d.skinned_mesh(doc, AID, 0.5)[0]
    pick(qtbot, combo, "euler")
    qtbot.waitUntil(lambda: not any(j.quaternion for j in character3d.character(doc, AID).skeleton.joints))
    ids = [cid.rsplit("/", 1)[1] for cid, _ in doc.channels_of(AID)]
    assert "rx" in ids and not any(d.startswith("q") for d in ids)
    # 0.5 s is a frame: the Euler keys pose the character exactly as the quaternion keys did
    assert np.allclose(character3d.skinned_mesh(doc, AID, 0.5)[0], before, atol=1e-9)
    qtbot.waitUntil(lambda: shown(rotation_combo(window)) == "euler")
    undo(qtbot, window)
    qtbot.waitUntil(lambda: all(j.quaternion for j in character3d.character(doc, AID).skeleton.joints))
    qtbot.waitUntil(lambda: shown(rotation_combo(window)) == "quaternion")


def test_reset_pose_puts_a_gltf_character_back_in_the_files_rest_pose(qtbot, docks):
    from qtanimator.ui.joint_tree import reset_pose_command

    window = docks
    doc = window.doc
    rest = character3d.character(doc, AID).skeleton.world_matrices()
    window.ctx.push(reset_pose_command(doc, AID, 0.5))
    assert np.allclose(character3d.pose_skeleton(doc, AID, 0.5).world_matrices(), rest, atol=1e-9)
