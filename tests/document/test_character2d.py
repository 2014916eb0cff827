"""2D characters in the document: commands, evaluation, keys, IK drags, the pendulum cache."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from docfix import set_parameters

from qtanimator.core.channel import Key
from qtanimator.core.ik import ik_error
from qtanimator.document import Document, SetKeys, SetParameter, UndoStack, open_document, save_document
from qtanimator.document.character2d import (
    ASSET_KIND,
    add_characters_command,
    angle_channel_id,
    character,
    delete_keys_at,
    evaluate_pose,
    ik_drag,
    joint_angles,
    key_joint,
    move_character,
    pendulum_params,
    set_pendulum_preset,
    simulation,
)
from qtanimator.formats.errors import FormatError

SCENES = Path(__file__).resolve().parents[2] / "scenes"
CLOCK = SCENES / "pendulum_clock.svg"
PIP = SCENES / "demo" / "pip.svg"


def make(path: Path = PIP) -> tuple[Document, UndoStack, str]:
    doc = Document()
    stack = UndoStack(doc)
    stack.push(add_characters_command(doc, path))
    return doc, stack, next(iter(doc.assets))


def test_add_characters_is_undoable(shared_data: Path) -> None:
    doc = Document()
    stack = UndoStack(doc)
    stack.push(add_characters_command(doc, shared_data / "cmu-animator" / "scenes" / "testscene"))
    assert list(doc.assets) == ["bunny", "cloud", "ground", "strange", "telescope", "tree"]
    assert all(a.kind == ASSET_KIND and a.properties["index"] == i for i, a in enumerate(doc.assets.values()))
    assert len(character(doc, "tree").joints) == 19
    stack.undo()
    assert doc.assets == {}
    with pytest.raises(FormatError):
        add_characters_command(doc, shared_data / "cmu-animator" / "SOURCE.md")


def test_a_new_project_of_svg_characters_spans_the_cmu_300_frames() -> None:
    # Issue 18: opened as a new project (the GUI, qtanimator render), SVG characters get the
    # CMU animator's 300 frames, in the same undo step as the import.
    doc = Document()
    stack = UndoStack(doc)
    stack.push(add_characters_command(doc, PIP, new_project_range=True))
    assert doc.frame_range == (0, 300) and len(stack.done) == 1
    stack.push(add_characters_command(doc, CLOCK, new_project_range=True))  # added to a project
    assert doc.frame_range == (0, 300) and len(stack.done) == 2
    stack.undo()
    stack.undo()
    assert doc.frame_range == (0, 240) and not doc.assets
    edited = Document()
    set_parameters(edited, {"frame_end": 90})
    add_characters_command(edited, PIP, new_project_range=True).do(edited)
    assert edited.frame_range == (0, 90)  # a range the user set is kept
    assert make()[0].frame_range == (0, 240)  # scripts (scene generators) keep their own range


def test_key_joint_and_move_character() -> None:
    doc, stack, aid = make()
    ch = character(doc, aid)
    fore = ch.joint_index("forearm_right")
    stack.push(key_joint(doc, aid, fore, 0.5, 1.0))
    assert angle_channel_id(aid, "forearm_right") == "pip/forearm_right/angle"
    assert doc.channels["pip/forearm_right/angle"].evaluate(1.0) == pytest.approx(0.5)
    assert joint_angles(doc, aid, 1.0)[fore] == pytest.approx(0.5)
    stack.push(move_character(doc, aid, (30.0, -5.0), 1.0))
    pose = evaluate_pose(doc, aid, 1.0)
    np.testing.assert_allclose(pose.translation, (30, -5))
    np.testing.assert_allclose(pose.pivots[0], ch.rest_pivots[0] + (30, -5))
    assert set(doc.channels) == {"pip/forearm_right/angle", "pip//x", "pip//y"}
    stack.undo()
    stack.undo()
    assert doc.channels == {}


def test_gesture_merges_into_one_undo_step() -> None:
    doc, stack, aid = make()
    fore = character(doc, aid).joint_index("forearm_right")
    for a in np.linspace(0, 1, 5):
        stack.push(key_joint(doc, aid, fore, float(a), 0.0, gesture="drag-1"))
    assert doc.channels["pip/forearm_right/angle"].evaluate(0.0) == pytest.approx(1.0)
    stack.undo()
    assert doc.channels == {}


def test_catmull_rom_between_keys() -> None:
    doc, stack, aid = make()
    j = character(doc, aid).joint_index("head")
    for t, v in [(0.0, 0.0), (1.0, 1.0), (2.0, 0.0)]:
        stack.push(key_joint(doc, aid, j, v, t))
    ch = doc.channels["pip/head/angle"]
    assert ch.evaluate(0.5) == pytest.approx(0.625)  # Hermite with chord end slope 1 and middle slope 0
    assert ch.evaluate(-1.0) == 0.0 and ch.evaluate(5.0) == 0.0  # constant extrapolation


def test_key_all_sets_the_universal_keyframe() -> None:
    doc, stack, aid = make()
    stack.push(add_characters_command(doc, CLOCK))
    stack.push(SetParameter(doc, "animation.key_all", True))
    head = character(doc, aid).joint_index("head")
    stack.push(key_joint(doc, aid, head, 0.3, 0.5))
    keyed = {cid for cid, ch in doc.channels.items() if any(abs(k.time - 0.5) < 1e-9 for k in ch.keys)}
    expected = {angle_channel_id(a, j.name) for a in ("pip", "pendulum_clock")
                for j in character(doc, a).joints if not j.is_dynamic}
    expected |= {"pip//x", "pip//y", "pendulum_clock//x", "pendulum_clock//y"}
    assert keyed == expected
    assert doc.channels["pip/head/angle"].evaluate(0.5) == pytest.approx(0.3)
    # delete removes the keyframe from every character within 0.1 frame
    assert delete_keys_at(doc, aid, 0.5 + 0.2 / 60) is None
    cmd = delete_keys_at(doc, aid, 0.5 + 0.05 / 60)
    assert cmd is not None
    stack.push(cmd)
    assert all(len(ch.keys) == 0 for ch in doc.channels.values())


def test_delete_keys_only_touches_that_time() -> None:
    doc, stack, aid = make()
    head = character(doc, aid).joint_index("head")
    stack.push(key_joint(doc, aid, head, 0.1, 0.0))
    stack.push(key_joint(doc, aid, head, 0.2, 1.0))
    cmd = delete_keys_at(doc, aid, 1.0)
    assert cmd is not None
    stack.push(cmd)
    assert [k.time for k in doc.channels["pip/head/angle"].keys] == [0.0]


def test_ik_drag_keys_the_moved_joints() -> None:
    doc, stack, aid = make()
    ch = character(doc, aid)
    hand = ch.joint_index("hand_left")
    lp = ch.joints[hand].pivot + np.array([-10.0, 0.0])
    before = evaluate_pose(doc, aid, 0.5)
    start = before.to_world(hand, lp)
    target = start + np.array([20.0, -50.0])
    for frac in np.linspace(0.2, 1.0, 5):
        stack.push(ik_drag(doc, aid, hand, lp, start + frac * (target - start), 0.5, gesture="ik"))
    angles = joint_angles(doc, aid, 0.5)
    assert ik_error(ch, angles, np.zeros(2), hand, lp, target) < 1e-3
    keyed = {cid.split("/")[1] for cid in doc.channels}
    assert keyed <= {"upper_arm_left", "forearm_left", "hand_left"} and keyed
    assert len(stack.done) == 2  # add + one merged drag


def test_pendulum_cache_steps_reads_and_invalidates() -> None:
    doc, stack, aid = make(CLOCK)
    for t in (0.0, 0.05, 0.1, 0.25):
        stack.push(move_character(doc, aid, (0, 0), t))
    sim = simulation(doc)
    p = character(doc, aid).joint_index("pendulum")
    a30 = evaluate_pose(doc, aid, 30 / 60).world_angles[p]
    assert sim.cached_frames(aid) == 31
    a2 = evaluate_pose(doc, aid, 2 / 60).world_angles[p]
    assert sim.cached_frames(aid) == 31  # scrubbing back reads the cache
    assert evaluate_pose(doc, aid, 0.0).world_angles[p] == 0.0
    assert a30 < a2 < 0  # drawn swung out to +x by 25°, it swings back clockwise (θ falls)
    assert evaluate_pose(doc, aid, 30 / 60).world_angles[p] == a30
    # playing forward one frame steps the simulation by one frame (10 steps of 1/600 s)
    before = sim.steps_taken
    evaluate_pose(doc, aid, 31 / 60)
    assert sim.steps_taken - before == 10 and sim.cached_frames(aid) == 32
    # a key added at 0.4 s changes the channel from the key two before it (0.05 s) on
    stack.push(move_character(doc, aid, (300, 0), 0.4))
    assert sim.cached_frames(aid) == 3
    assert evaluate_pose(doc, aid, 2 / 60).world_angles[p] == a2
    assert evaluate_pose(doc, aid, 30 / 60).world_angles[p] != a30
    sim.invalidate(aid, 0.2)
    assert sim.cached_frames(aid) == 12
    # parameters of this character invalidate it
    stack.push(SetParameter(doc, f"{aid}.pendulum.damping", 2.0))
    assert sim.cached_frames(aid) == 0
    assert pendulum_params(doc, aid).damping == 2.0


def test_handout_preset() -> None:
    doc, stack, aid = make(CLOCK)
    stack.push(set_pendulum_preset(doc, aid, "handout"))
    params = pendulum_params(doc, aid)
    assert params.g == 5000 and params.length_scale == 0.001 and params.inertia == "reference"
    pose = evaluate_pose(doc, aid, 1.0)
    assert np.all(np.isfinite(pose.world))
    stack.undo()
    assert pendulum_params(doc, aid).g == 3000
    with pytest.raises(ValueError):
        set_pendulum_preset(doc, aid, "nope")


def test_dynamic_joint_key_poses_the_pendulum() -> None:
    doc, stack, aid = make(CLOCK)
    p = character(doc, aid).joint_index("pendulum")
    stack.push(key_joint(doc, aid, p, 0.4, 0.0))
    assert evaluate_pose(doc, aid, 0.0).world_angles[p] == pytest.approx(0.4)
    stack.push(key_joint(doc, aid, p, -0.2, 1.0))
    assert evaluate_pose(doc, aid, 1.0).world_angles[p] == pytest.approx(-0.2)


def test_translation_swings_a_hanging_pendulum() -> None:
    doc, stack, aid = make(CLOCK)
    p = character(doc, aid).joint_index("pendulum")
    rest = simulation(doc)
    eq = rest._sim(doc, aid).system.equilibrium()[p]
    stack.push(key_joint(doc, aid, p, float(eq), 0.0))
    still = evaluate_pose(doc, aid, 0.5).world_angles[p]
    assert still == pytest.approx(eq, abs=1e-6)  # hanging at rest stays at rest
    # x = 1000 t² (fixed slopes 0 and 1000 make the Hermite span exactly that parabola)
    stack.push(SetKeys(doc, {f"{aid}//x": Key.make(0.0, 0.0, 0.0, 0.0)}))
    stack.push(SetKeys(doc, {f"{aid}//x": Key.make(0.5, 250.0, 1000.0, 1000.0)}))
    assert doc.channels[f"{aid}//x"].evaluate(0.1, 2) == pytest.approx(2000.0)
    # accelerating towards +x: the bob lags (θ decreases, clockwise on screen)
    assert evaluate_pose(doc, aid, 0.1).world_angles[p] < eq - 1e-3


def test_project_round_trip(tmp_path: Path) -> None:
    doc, stack, aid = make()
    stack.push(key_joint(doc, aid, 1, 0.25, 0.5))
    save_document(doc, tmp_path / "p.qtanim")
    again = open_document(tmp_path / "p.qtanim")
    assert isinstance(again.runtime[aid], type(character(doc, aid)))
    np.testing.assert_allclose(evaluate_pose(again, aid, 0.5).world, evaluate_pose(doc, aid, 0.5).world)


def test_demo_project_opens_and_animates() -> None:
    from qtanimator.paths import demo_project

    doc = open_document(demo_project())
    # Pip, the clock and Robo in 2D; the 3D arm and a cloth flag (issue 9: one combined demo);
    # the walker with its cape (issue 14: cloth on a character).
    assert {a.id: a.kind for a in doc.assets.values()} == {
        "pip": ASSET_KIND, "pendulum_clock": ASSET_KIND, "robot": ASSET_KIND, "arm": "character3d", "flag": "cloth",
        "walker": "character3d", "cape": "cloth"}
    pip = character(doc, "pip")
    a, b = evaluate_pose(doc, "pip", 0.0), evaluate_pose(doc, "pip", 1.0)
    assert not np.allclose(a.world, b.world)
    lantern = pip.joint_index("lantern")
    assert b.world_angles[lantern] != 0.0 and math.isfinite(b.world_angles[lantern])
