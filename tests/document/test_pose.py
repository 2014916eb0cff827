"""Poses without Qt: the pending (unkeyed) pose, set key, IK keys under key-all whatever the
solver settings, pose copy / paste and the mirror rules."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from qtanimator.document import character2d as c2d
from qtanimator.document import pose
from qtanimator.document.commands import SetParameter, UndoStack
from qtanimator.document.document import Document
from qtanimator.document.gesture import Gesture
from qtanimator.ui import rig_interaction as ri

SCENES = Path(__file__).resolve().parents[2] / "scenes"
PIP_SVG = SCENES / "demo" / "pip.svg"

#: The channels the universal keyframe (key-all) keys for a document holding only Pip:
#: every keyframed (non-pendulum) joint and the position.
PIP_KEY_ALL = {
    "pip/torso/angle", "pip/head/angle", "pip/leg_left/angle", "pip/leg_right/angle",
    "pip/upper_arm_left/angle", "pip/forearm_left/angle", "pip/hand_left/angle",
    "pip/upper_arm_right/angle", "pip/forearm_right/angle", "pip/hand_right/angle",
    "pip//x", "pip//y",
}


def pip_doc() -> tuple[Document, UndoStack]:
    doc = Document()
    stack = UndoStack(doc)
    stack.push(c2d.add_characters_command(doc, PIP_SVG))
    assert list(doc.assets) == ["pip"]
    return doc, stack


def hand_grab(doc: Document, time: float) -> tuple[np.ndarray, np.ndarray]:
    """A point on Pip's right hand (scene units) and a target 40 units left and 25 up."""
    ch = doc.runtime["pip"]
    j = ch.joint_index("hand_right")
    press = c2d.evaluate_pose(doc, "pip", time).to_world(j, ch.joints[j].shapes[0].points.mean(axis=0))
    return press, press + np.array([-40.0, -25.0])


def ik_drag_keys(doc: Document, stack: UndoStack, time: float) -> set[str]:
    """Drive the editor's IK drag (auto-key on) and return the channels it keyed."""
    before = {cid: ch for cid, ch in doc.channels.items()}
    press, target = hand_grab(doc, time)
    j = doc.runtime["pip"].joint_index("hand_right")
    gesture = Gesture(doc, "IK", stack.record)
    drag = ri.ik_drag(doc, "pip", j, press, time, autokey=True)
    next(drag)
    for f in (0.3, 0.6, 1.0):
        gesture.update(drag.send(press + f * (target - press)))
    assert gesture.commit() is not None
    return {cid for cid, ch in doc.channels.items() if before.get(cid) is not ch}


# ---------------------------------------------------------------- item 6: IK keys
@pytest.mark.parametrize("settings", [
    {},
    {"ik.damping": 0.05},
    {"ik.damping": 0.05, "ik.max_iterations": 7},
    {"ik.freeze_root": False},
    {"ik.solver": "handout"},
])
def test_key_all_ik_drag_keys_the_same_channels_whatever_the_solver_settings(settings):
    doc, stack = pip_doc()
    stack.push(SetParameter(doc, c2d.KEY_ALL_PARAMETER, True))
    for name, value in settings.items():
        stack.push(SetParameter(doc, name, value))
    assert ik_drag_keys(doc, stack, 0.5) == PIP_KEY_ALL


def test_without_key_all_an_ik_drag_keys_only_the_joints_it_moved():
    doc, stack = pip_doc()
    keyed = ik_drag_keys(doc, stack, 0.5)
    assert keyed and keyed <= {"pip/upper_arm_right/angle", "pip/forearm_right/angle", "pip/hand_right/angle"}


# ------------------------------------------------------------------ pending pose
def test_auto_key_is_view_state_on_by_default():
    doc = Document()
    assert pose.autokey(doc)
    before = doc.state()
    pose.set_autokey(doc, False)
    assert not pose.autokey(doc) and doc.view_state[pose.AUTOKEY_VIEW_STATE] is False
    assert doc.state() == before  # not an edit


def test_a_pending_pose_shows_without_keys_or_undo_steps_and_escape_restores_it():
    doc, stack = pip_doc()
    t = 0.5
    j = doc.runtime["pip"].joint_index("forearm_left")
    state = doc.state()
    angles0 = c2d.joint_angles(doc, "pip", t)
    seen = []
    doc.subscribe(seen.append)

    gesture = Gesture(doc, "Rotate", stack.record)
    pivot = c2d.evaluate_pose(doc, "pip", t).pivots[j]
    press = pivot + np.array([30.0, 0.0])
    drag = ri.rotate_drag(doc, "pip", j, press, t, autokey=False)
    next(drag)
    gesture.update(drag.send(pivot + np.array([0.0, -30.0])))  # a quarter turn counter-clockwise
    assert doc.state() == state  # no channel changed
    angles1 = c2d.joint_angles(doc, "pip", t)
    assert angles1[j] == pytest.approx(angles0[j] + math.pi / 2)
    np.testing.assert_array_equal(np.delete(angles1, j), np.delete(angles0, j))
    assert pose.PENDING_CHANGE in seen[-1].parameters and not seen[-1].channels
    # Other times are not touched.
    assert c2d.joint_angles(doc, "pip", t + 1 / 60)[j] == 0.0  # Pip's forearm has no channel yet
    assert gesture.commit() is None and len(stack.done) == 1  # only the import
    assert pose.has_pending(doc, t)

    # A second drag, aborted (Escape), puts the first pending pose back.
    gesture = Gesture(doc, "Rotate", stack.record)
    drag = ri.rotate_drag(doc, "pip", j, press, t, autokey=False)
    next(drag)
    gesture.update(drag.send(pivot + np.array([-30.0, 0.0])))
    assert c2d.joint_angles(doc, "pip", t)[j] != pytest.approx(angles1[j])
    gesture.abort()
    assert c2d.joint_angles(doc, "pip", t)[j] == pytest.approx(angles1[j])

    assert pose.clear_pending(doc)
    np.testing.assert_array_equal(c2d.joint_angles(doc, "pip", t), angles0)
    assert not pose.clear_pending(doc)


def test_set_key_keys_exactly_the_selection_with_the_shown_values_and_undo_is_exact():
    doc, stack = pip_doc()
    t = 37 / 60
    values = {"pip/forearm_left/angle": 0.7, "pip/head/angle": -0.2}
    pose.PosePreview(doc, values, t).do(doc)
    before = doc.state()
    stack.push(pose.key_selection_command(doc, "pip", "forearm_left", t))
    assert set(doc.channels) == {"pip/forearm_left/angle"}
    assert [(k.time, k.value) for k in doc.channels["pip/forearm_left/angle"].keys] == [(t, 0.7)]
    # The head is still posed but not keyed; the keyed forearm shows its key.
    assert c2d.joint_angles(doc, "pip", t)[doc.runtime["pip"].joint_index("head")] == pytest.approx(-0.2)
    stack.undo()
    assert doc.state() == before
    # Undoing set key shows the unkeyed value again, as before the key.
    assert c2d.joint_angles(doc, "pip", t)[doc.runtime["pip"].joint_index("forearm_left")] == pytest.approx(0.7)

    stack.push(pose.key_character_command(doc, "pip", t))
    assert set(doc.channels) == PIP_KEY_ALL
    assert doc.channels["pip/head/angle"].keys[0].value == pytest.approx(-0.2)
    assert doc.channels["pip/torso/angle"].keys[0].value == 0.0
    # The character selected (joint ""): its root and its position.
    stack.undo()
    stack.push(pose.key_selection_command(doc, "pip", "", t))
    assert set(doc.channels) == {"pip/torso/angle", "pip//x", "pip//y"}


def test_a_channel_edit_ends_its_pending_value_and_a_reset_ends_all():
    doc, stack = pip_doc()
    t = 0.25
    pose.PosePreview(doc, {"pip/head/angle": 0.4, "pip/leg_left/angle": 0.3}, t).do(doc)
    stack.push(c2d.key_joint(doc, "pip", doc.runtime["pip"].joint_index("head"), -0.1, t))
    angles = c2d.joint_angles(doc, "pip", t)
    assert angles[doc.runtime["pip"].joint_index("head")] == pytest.approx(-0.1)
    assert angles[doc.runtime["pip"].joint_index("leg_left")] == pytest.approx(0.3)
    doc.replace_all(Document())
    assert not pose.has_pending(doc)


# ----------------------------------------------------------------- mirror names
@pytest.mark.parametrize("name, mirrored", [
    ("arm_left", "arm_right"), ("upper_arm_right", "upper_arm_left"), ("L_arm", "R_arm"),
    ("arm.L", "arm.R"), ("arm.r", "arm.l"), ("Left_Hand", "Right_Hand"), ("LEFT_FOOT", "RIGHT_FOOT"),
    ("LeftUpLeg", "RightUpLeg"), ("RightHandIndex", "LeftHandIndex"), ("LHipJoint", "RHipJoint"),
    ("handLeft", "handRight"), ("shoulder_right_1", "shoulder_left_1"), ("hip_03_r", "hip_03_l"),
    ("torso", "torso"), ("Lantern", "Lantern"), ("LowerBack", "LowerBack"), ("lantern_chain", "lantern_chain"),
    ("Root", "Root"), ("elbow", "elbow"),
])
def test_mirror_names(name, mirrored):
    assert pose.mirror_name(name) == mirrored
    assert pose.mirror_name(mirrored) == name


# ------------------------------------------------------------------ copy / paste
def test_paste_and_paste_mirrored_on_pip():
    from qtanimator.document.io import open_document

    doc = open_document(SCENES / "demo" / "demo.qtanim")
    stack = UndoStack(doc)
    t1, t2 = 45 / 60, 100 / 60

    def channel_value(cid: str, t: float) -> float:
        ch = doc.channels.get(cid)
        return 0.0 if ch is None or not ch.keys else float(ch.evaluate(t))

    clip = pose.copy_pose(doc, "pip", "", t1)
    names = ["torso", "head", "leg_left", "leg_right", "upper_arm_left", "forearm_left", "hand_left",
             "upper_arm_right", "forearm_right", "hand_right"]
    assert clip.joints == names  # the pendulums (earring, lantern) are physics, not pose
    source = {n: channel_value(f"pip/{n}/angle", t1) for n in names}
    assert source["upper_arm_left"] != source["upper_arm_right"]

    before = doc.state()
    stack.push(pose.paste_pose_command(doc, clip, "pip", t2))
    for n in names:
        assert channel_value(f"pip/{n}/angle", t2) == pytest.approx(source[n], abs=1e-12)
    after = doc.state()["channels"]
    assert after["pip//x"] == before["channels"]["pip//x"]  # a pose is not a position
    assert after["pip//y"] == before["channels"]["pip//y"]
    stack.undo()
    assert doc.state() == before

    # Pip is drawn from the front: a mirror swaps left and right and negates every angle.
    assert pose.mirror_negates_2d(doc.runtime["pip"])
    mirror = {"torso": "torso", "head": "head", "leg_left": "leg_right", "leg_right": "leg_left",
              "upper_arm_left": "upper_arm_right", "forearm_left": "forearm_right", "hand_left": "hand_right",
              "upper_arm_right": "upper_arm_left", "forearm_right": "forearm_left", "hand_right": "hand_left"}
    stack.push(pose.paste_pose_command(doc, clip, "pip", t2, mirrored=True))
    for n, m in mirror.items():
        assert channel_value(f"pip/{m}/angle", t2) == pytest.approx(-source[n], abs=1e-12)
    stack.undo()
    assert doc.state() == before

    # One joint, mirrored: only its partner is keyed.
    one = pose.copy_pose(doc, "pip", "forearm_left", t1)
    stack.push(pose.paste_pose_command(doc, one, "pip", t2, mirrored=True))
    changed = {cid for cid in doc.channels if doc.state()["channels"][cid] != before["channels"].get(cid)}
    assert changed == {"pip/forearm_right/angle"}
    assert channel_value("pip/forearm_right/angle", t2) == pytest.approx(-source["forearm_left"])


def rig(joints):
    """A stand-in with what the mirror rule reads: joint names and rest pivots."""
    from types import SimpleNamespace

    return SimpleNamespace(joints=[SimpleNamespace(name=n, pivot=np.array([100.0 + dx, 50.0])) for n, dx in joints])


def test_a_side_view_rig_mirrors_by_swapping_only():
    front = rig([("body", 0.0), ("leg_left", -10.0), ("leg_right", 10.0)])
    side = rig([("body", 0.0), ("leg_left", 0.0), ("leg_right", 0.0)])
    assert pose.mirror_negates_2d(front)
    assert not pose.mirror_negates_2d(side)
    assert pose.mirrored_value(c2d.ASSET_KIND, "angle", 0.3, negate_2d=False) == 0.3
    assert pose.mirrored_value(c2d.ASSET_KIND, "angle", 0.3, negate_2d=True) == -0.3


def test_3d_mirror_reproduces_the_dragons_own_left_side(shared_data):
    """The dragon's file poses its left side as the mirror of its right: (rx, −ry, −rz)
    across x. Paste-mirroring the right side's rest pose must give the file's left side."""
    from qtanimator.document import character3d as c3d

    doc = Document()
    stack = UndoStack(doc)
    stack.push(c3d.add_character3d_command(doc, shared_data / "cse169" / "skeleton" / "dragon.skel",
                                           asset_id="dragon"))
    skel = c3d.character(doc, "dragon").skeleton
    keys = skel.joint_keys()
    assert pose.lateral_axis_3d(skel) == 0
    right = ["shoulder_right_1", "elbow_right_1", "wrist_right_1"]
    clip = pose.PoseClip(c3d.ASSET_KIND, "dragon", {
        k: {a: float(skel.joints[keys.index(k)].dofs["xyz".index(a[-1])].value) for a in c3d.JOINT_DOFS}
        for k in right})
    stack.push(pose.paste_pose_command(doc, clip, "dragon", 0.0, mirrored=True))
    posed = c3d.pose_skeleton(doc, "dragon", 0.0)
    expected = {"shoulder_left_1": (0.0, 0.0, -0.06), "elbow_left_1": (0.0, 0.66, -0.66),
                "wrist_left_1": (-0.41, -0.5, 0.87)}  # the file's left-side pose lines
    for k, (x, y, z) in expected.items():
        j = keys.index(k)
        np.testing.assert_allclose([posed.joints[j].dofs[a].value for a in range(3)], [x, y, z], atol=1e-12)
        assert {f"dragon/{k}/rx", f"dragon/{k}/ry", f"dragon/{k}/rz"} <= set(doc.channels)
    assert not any("right" in cid for cid in doc.channels)


def test_3d_set_key_and_pending_pose(shared_data):
    from qtanimator.document import character3d as c3d

    doc = Document()
    stack = UndoStack(doc)
    stack.push(c3d.add_character3d_command(doc, SCENES / "arm3d" / "arm.skel", asset_id="arm"))
    t = 0.4
    values = c3d.dof_values(doc, "arm", {(1, "z"): 0.9, (0, "y"): 0.2})
    assert values == {"arm/elbow/rz": 0.9, "arm/shoulder/ry": 0.2}
    pose.PosePreview(doc, values, t).do(doc)
    assert not doc.channels
    skel = c3d.pose_skeleton(doc, "arm", t)
    assert skel.joints[1].dofs[2].value == 0.9 and skel.joints[0].dofs[1].value == 0.2
    stack.push(pose.key_selection_command(doc, "arm", "elbow", t))
    assert set(doc.channels) == {"arm/elbow/rx", "arm/elbow/ry", "arm/elbow/rz"}
    assert doc.channels["arm/elbow/rz"].keys[0].value == 0.9
    stack.push(pose.key_character_command(doc, "arm", t))
    assert set(doc.channels) == {"arm//tx", "arm//ty", "arm//tz", "arm/shoulder/rx", "arm/shoulder/ry",
                                 "arm/shoulder/rz", "arm/elbow/rx", "arm/elbow/ry", "arm/elbow/rz"}
    assert doc.channels["arm/shoulder/ry"].keys[0].value == 0.2


def test_a_pendulum_posed_without_a_key_shows_its_world_angle_and_s_keys_it():
    doc, stack = pip_doc()
    t = 20 / 60
    ch = doc.runtime["pip"]
    k = ch.joint_index("earring")
    parent = ch.joints[k].parent
    pose.PosePreview(doc, {"pip/earring/angle": 0.8}, t).do(doc)
    shown = c2d.evaluate_pose(doc, "pip", t)
    assert shown.world_angles[k] == pytest.approx(0.8)
    assert shown.angles[k] == pytest.approx(0.8 - shown.world_angles[parent])
    stack.push(pose.key_selection_command(doc, "pip", "earring", t))
    assert set(doc.channels) == {"pip/earring/angle"}
    assert doc.channels["pip/earring/angle"].keys[0].value == pytest.approx(0.8)
