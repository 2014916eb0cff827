"""2D joint limits in the document (issue 18, item 2): stored as parameters, one undo step,
saved, and respected by evaluation, keying, IK, paste, mirror and the pendulum inputs."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from qtanimator.core.channel import Key
from qtanimator.document import Document, SetKeys, SetParameter, UndoStack, open_document, save_document
from qtanimator.document import pose as pose_doc
from qtanimator.document.character2d import (
    add_characters_command,
    angle_channel_id,
    character,
    clamp_values,
    evaluate_pose,
    ik_drag,
    ik_values,
    joint_angles,
    joint_limits,
    key_joint,
    keyframed_angles,
    limits_parameter,
    set_joint_limits_command,
    simulation,
)

SCENES = Path(__file__).resolve().parents[2] / "scenes"
PIP = SCENES / "demo" / "pip.svg"
CLOCK = SCENES / "pendulum_clock.svg"


def make(path: Path = PIP) -> tuple[Document, UndoStack, str]:
    doc = Document()
    stack = UndoStack(doc)
    stack.push(add_characters_command(doc, path))
    stack.done.clear()
    return doc, stack, next(iter(doc.assets))


def rot(a: float) -> np.ndarray:
    """R(a) of the architecture (counter-clockwise on a y-down screen)."""
    return np.array([[math.cos(a), math.sin(a)], [-math.sin(a), math.cos(a)]])


# ------------------------------------------------------------------ the parameters
def test_limits_are_one_parameter_per_joint_and_one_undo_step() -> None:
    doc, stack, aid = make()
    ch = character(doc, aid)
    fore = ch.joint_index("forearm_right")
    assert joint_limits(doc, aid) == [None] * len(ch.joints)
    stack.push(set_joint_limits_command(doc, aid, fore, -0.25, 1.5))
    assert len(stack.done) == 1
    assert doc.parameters["pip.limits.forearm_right"] == [-0.25, 1.5]
    assert limits_parameter(aid, "forearm_right") == "pip.limits.forearm_right"
    expected: list[tuple[float, float] | None] = [None] * len(ch.joints)
    expected[fore] = (-0.25, 1.5)
    assert joint_limits(doc, aid) == expected
    # By name, clearing with None: each its own step.
    stack.push(set_joint_limits_command(doc, aid, "head", -0.1, 0.1))
    stack.push(set_joint_limits_command(doc, aid, "forearm_right", None, None))
    assert len(stack.done) == 3
    assert joint_limits(doc, aid)[fore] is None
    assert joint_limits(doc, aid)[ch.joint_index("head")] == (-0.1, 0.1)
    assert "pip.limits.forearm_right" not in doc.parameters
    stack.undo()
    assert joint_limits(doc, aid)[fore] == (-0.25, 1.5)
    stack.undo()
    stack.undo()
    assert joint_limits(doc, aid) == [None] * len(ch.joints)
    assert not any(".limits." in p for p in doc.parameters)


@pytest.mark.parametrize("lo, hi", [(1.0, 0.5), (math.nan, 1.0), (0.0, math.inf), (-math.inf, 0.0),
                                    (None, 1.0), (0.0, None)])
def test_invalid_limits_are_refused(lo, hi) -> None:
    doc, _stack, aid = make()
    with pytest.raises(ValueError):
        set_joint_limits_command(doc, aid, 1, lo, hi)


def test_unknown_joints_are_refused() -> None:
    doc, _stack, aid = make()
    for joint in ("no_such_joint", 99, -1):
        with pytest.raises(ValueError):
            set_joint_limits_command(doc, aid, joint, 0.0, 1.0)


def test_a_locked_joint_is_allowed() -> None:
    doc, stack, aid = make()
    stack.push(set_joint_limits_command(doc, aid, 1, 0.3, 0.3))
    assert joint_limits(doc, aid)[1] == (0.3, 0.3)
    assert joint_angles(doc, aid, 0.0)[1] == 0.3


def test_malformed_stored_limits_leave_the_joint_free() -> None:
    doc, stack, aid = make()
    for bad in ([1.0], [2.0, 1.0], ["a", 1.0], [True, 2.0], "0..1", [0.0, math.nan], None):
        stack.push(SetParameter(doc, "pip.limits.head", bad))
        assert joint_limits(doc, aid)[1] is None, bad
        assert math.isfinite(joint_angles(doc, aid, 0.0)[1])


def test_limits_are_saved_and_reopened(tmp_path: Path) -> None:
    doc, stack, aid = make()
    stack.push(set_joint_limits_command(doc, aid, "forearm_right", math.radians(-20), math.radians(135)))
    stack.push(set_joint_limits_command(doc, aid, "earring", -0.5, 0.5))  # a pendulum may have limits
    save_document(doc, tmp_path / "limits.qtanim")
    again = open_document(tmp_path / "limits.qtanim")
    assert joint_limits(again, aid) == joint_limits(doc, aid)
    assert joint_limits(again, aid)[character(again, aid).joint_index("forearm_right")] == (
        math.radians(-20), math.radians(135))


# ------------------------------------------------------------------ evaluation and keys
def test_evaluation_clamps_a_keyframed_joint_and_keeps_its_keys() -> None:
    doc, stack, aid = make()
    fore = character(doc, aid).joint_index("forearm_right")
    cid = angle_channel_id(aid, "forearm_right")
    stack.push(SetKeys(doc, {cid: Key(0.0, -1.0)}))
    stack.push(SetKeys(doc, {cid: Key(1.0, 2.0)}))
    stack.push(set_joint_limits_command(doc, aid, fore, -0.5, 0.75))
    assert joint_angles(doc, aid, 0.0)[fore] == -0.5
    assert joint_angles(doc, aid, 1.0)[fore] == 0.75
    assert evaluate_pose(doc, aid, 1.0).angles[fore] == 0.75
    raw = float(doc.channels[cid].evaluate(0.5))
    assert -0.5 < raw < 0.75  # the middle of the span is inside: as keyed
    assert joint_angles(doc, aid, 0.5)[fore] == raw
    assert keyframed_angles(doc, aid, 0.5, 1)[fore] == pytest.approx(float(doc.channels[cid].evaluate(0.5, 1)))
    assert keyframed_angles(doc, aid, 1.0, 1)[fore] == 0.0  # held at the limit: still
    assert [k.value for k in doc.channels[cid].keys] == [-1.0, 2.0]  # the keys are kept
    stack.undo()
    assert joint_angles(doc, aid, 1.0)[fore] == 2.0


def test_key_joint_and_set_key_stay_within_the_limits() -> None:
    doc, stack, aid = make()
    fore = character(doc, aid).joint_index("forearm_right")
    cid = angle_channel_id(aid, "forearm_right")
    stack.push(set_joint_limits_command(doc, aid, fore, -0.5, 0.75))
    stack.push(key_joint(doc, aid, fore, 3.0, 0.0))
    assert doc.channels[cid].keys[0].value == 0.75
    stack.push(key_joint(doc, aid, fore, -3.0, 1.0))
    assert doc.channels[cid].keys[1].value == -0.5
    # A key made before the limits: S keys what is shown, the clamped value.
    stack.push(set_joint_limits_command(doc, aid, fore, None, None))
    stack.push(SetKeys(doc, {cid: Key(2.0, 1.4)}))
    stack.push(set_joint_limits_command(doc, aid, fore, 0.0, 1.0))
    stack.push(pose_doc.key_selection_command(doc, aid, "forearm_right", 2.0))
    assert doc.channels[cid].keys[2].value == 1.0


def test_clamp_values_only_touches_limited_2d_angles() -> None:
    doc, stack, aid = make()
    stack.push(set_joint_limits_command(doc, aid, "head", -0.2, 0.2))
    values = {"pip/head/angle": 1.0, "pip/neck_missing/angle": 5.0, "pip//x": 40.0, "pip/torso/angle": 3.0}
    assert clamp_values(doc, values, 0.0) == {"pip/head/angle": 0.2, "pip/neck_missing/angle": 5.0,
                                               "pip//x": 40.0, "pip/torso/angle": 3.0}


def test_a_pendulum_key_holds_its_world_angle_with_the_local_angle_clamped() -> None:
    doc, stack, aid = make(CLOCK)
    ch = character(doc, aid)
    bob = ch.joint_index("pendulum")
    assert ch.joints[bob].is_dynamic
    stack.push(key_joint(doc, aid, 0, 0.3, 0.0))  # the clock (the pendulum's parent) turns 0.3
    stack.push(set_joint_limits_command(doc, aid, bob, -0.4, 0.4))
    stack.push(key_joint(doc, aid, bob, 1.0, 0.0))
    # A dynamic joint's channel holds its world angle: the parent's 0.3 plus the local 0.4.
    assert doc.channels[angle_channel_id(aid, "pendulum")].keys[0].value == pytest.approx(0.7, abs=1e-12)


def test_changing_limits_drops_the_pendulum_frames() -> None:
    doc, stack, aid = make(CLOCK)
    cache = simulation(doc)
    evaluate_pose(doc, aid, 0.5)
    assert cache.cached_frames(aid) > 0
    stack.push(set_joint_limits_command(doc, aid, 0, -0.1, 0.1))
    assert cache.cached_frames(aid) == 0


def test_pendulums_feel_the_clamped_parent() -> None:
    """A keyed parent clamped to its limit swings a pendulum exactly as a parent keyed at
    that limit does (the simulation reads the clamped angle and its zero rates)."""
    def run(keys: list[Key], limit: tuple[float, float] | None) -> np.ndarray:
        doc, stack, aid = make()
        cid = angle_channel_id(aid, "hand_right")
        for k in keys:
            stack.push(SetKeys(doc, {cid: k}))
        if limit is not None:
            stack.push(set_joint_limits_command(doc, aid, "hand_right", *limit))
        lantern = character(doc, aid).joint_index("lantern")
        return np.array([evaluate_pose(doc, aid, t).world_angles[lantern] for t in (0.25, 0.5, 1.0)])

    clamped = run([Key(0.0, 1.0), Key(0.5, 2.0)], (-0.5, 0.5))
    at_limit = run([Key(0.0, 0.5)], None)
    free = run([Key(0.0, 1.0), Key(0.5, 2.0)], None)
    np.testing.assert_array_equal(clamped, at_limit)
    assert np.abs(free - at_limit).max() > 1e-3  # the test can tell them apart


# ------------------------------------------------------------------ IK
@pytest.mark.parametrize("solver", ["dls", "handout"])
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_ik_towards_a_target_past_the_limit_stops_at_the_limit(solver: str, sign: float) -> None:
    doc, stack, aid = make()
    ch = character(doc, aid)
    upper, fore = ch.joint_index("upper_arm_right"), ch.joint_index("forearm_right")
    stack.push(SetParameter(doc, "ik.solver", solver))
    if solver == "handout":  # big enough steps to get past the limit in one move
        stack.push(SetParameter(doc, "ik.handout_step", 1e-3))
        stack.push(SetParameter(doc, "ik.handout_iterations", 200))
    stack.push(set_joint_limits_command(doc, aid, upper, 0.0, 0.0))  # locked: only the forearm turns
    stack.push(set_joint_limits_command(doc, aid, fore, -0.3, 0.3))
    pose = evaluate_pose(doc, aid, 0.0)
    local = ch.joints[fore].centroid + (ch.joints[fore].centroid - ch.joints[fore].pivot)  # past the centre
    grabbed = pose.to_world(fore, local)
    pivot = pose.pivots[fore]
    target = pivot + rot(sign * 1.0) @ (grabbed - pivot)  # the forearm turned 1 rad: beyond 0.3
    stack.push(ik_drag(doc, aid, fore, local, target, 0.0))
    angles = joint_angles(doc, aid, 0.0)
    assert angles[fore] == pytest.approx(sign * 0.3, abs=1e-9)
    assert angles[upper] == 0.0
    assert doc.channels[angle_channel_id(aid, "forearm_right")].keys[0].value == pytest.approx(sign * 0.3, abs=1e-9)


def test_ik_within_the_limits_reaches_the_target() -> None:
    doc, stack, aid = make()
    ch = character(doc, aid)
    upper, fore = ch.joint_index("upper_arm_right"), ch.joint_index("forearm_right")
    stack.push(set_joint_limits_command(doc, aid, upper, 0.0, 0.0))
    stack.push(set_joint_limits_command(doc, aid, fore, -0.3, 0.3))
    pose = evaluate_pose(doc, aid, 0.0)
    local = ch.joints[fore].centroid
    target = pose.pivots[fore] + rot(0.2) @ (pose.to_world(fore, local) - pose.pivots[fore])
    values = ik_values(doc, aid, fore, local, target, 0.0)
    assert values[angle_channel_id(aid, "forearm_right")] == pytest.approx(0.2, abs=1e-4)


def test_ik_chain_respects_every_limit() -> None:
    doc, stack, aid = make()
    ch = character(doc, aid)
    hand = ch.joint_index("hand_right")
    limits = {"upper_arm_right": (-0.2, 0.4), "forearm_right": (0.0, 0.5), "hand_right": (-0.1, 0.1)}
    for name, (lo, hi) in limits.items():
        stack.push(set_joint_limits_command(doc, aid, name, lo, hi))
    pose = evaluate_pose(doc, aid, 0.0)
    local = ch.joints[hand].centroid
    for target in ([-500.0, -500.0], [500.0, 500.0], [0.0, 1000.0], [900.0, -100.0]):
        values = ik_values(doc, aid, hand, local, np.array(target), 0.0)
        for name, (lo, hi) in limits.items():
            v = values.get(angle_channel_id(aid, name), 0.0)
            assert lo <= v <= hi, (target, name, v)
    assert pose.angles[hand] == 0.0


# ------------------------------------------------------------------ paste and mirror
def test_paste_and_paste_mirrored_are_clamped() -> None:
    doc, stack, aid = make()
    ch = character(doc, aid)
    right, left = ch.joint_index("forearm_right"), ch.joint_index("forearm_left")
    stack.push(key_joint(doc, aid, right, 0.9, 0.0))
    clip = pose_doc.copy_pose(doc, aid, "forearm_right", 0.0)
    assert clip.values["forearm_right"]["angle"] == 0.9
    stack.push(set_joint_limits_command(doc, aid, right, -0.2, 0.6))
    stack.push(set_joint_limits_command(doc, aid, left, -0.3, 0.25))
    stack.push(pose_doc.paste_pose_command(doc, clip, aid, 1.0))
    assert doc.channels[angle_channel_id(aid, "forearm_right")].evaluate(1.0) == 0.6
    stack.push(pose_doc.paste_pose_command(doc, clip, aid, 1.0, mirrored=True))
    # Pip is drawn from the front: a mirrored angle negates (-0.9), clamped to -0.3.
    assert pose_doc.mirror_negates_2d(ch)
    assert doc.channels[angle_channel_id(aid, "forearm_left")].evaluate(1.0) == -0.3
