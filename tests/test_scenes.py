"""The scenes bundled in ``scenes/``: they load with the program's own readers, they hold what
they claim, and the generator scripts in ``scenes/tools`` reproduce them byte for byte."""

from __future__ import annotations

import importlib.util
import json
import math
import sys
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest

from qtanimator.core.channel import Extrapolation, Interpolation
from qtanimator.core.clip import channel_count
from qtanimator.core.skinning import skin_normals, skin_positions
from qtanimator.document import open_document
from qtanimator.document.character2d import evaluate_pose, joint_angles
from qtanimator.formats.anim import load_anim
from qtanimator.formats.info import summarize
from qtanimator.formats.skel import load_skel
from qtanimator.formats.skin import load_skin
from qtanimator.formats.svg_rig import load_characters

REPO = Path(__file__).resolve().parents[1]
SCENES = REPO / "scenes"
TOOLS = SCENES / "tools"


def _tool(name: str) -> ModuleType:
    """Import a generator script from scenes/tools (they are scripts, not a package)."""
    key = f"_scene_tool_{name}"
    if key in sys.modules:
        return sys.modules[key]
    spec = importlib.util.spec_from_file_location(key, TOOLS / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[key] = module
    spec.loader.exec_module(module)
    return module


# ------------------------------------------------------------------ every scene
def _projects() -> list[Path]:
    return sorted(SCENES.rglob("*.qtanim"))


def _svgs() -> list[Path]:
    return sorted(SCENES.rglob("*.svg"))


def test_scene_folder_has_what_issue_9_asks_for() -> None:
    for rel in ("telescope_chain.svg", "flappy.svg", "pencil.svg", "pencil_path.qtanim",
                "robot/robot.svg", "robot/robot.qtanim", "arm3d/arm.skel", "arm3d/arm.skin",
                "arm3d/arm_wave.anim", "arm3d/arm3d.qtanim", "cloth/cloth.qtanim"):
        assert (SCENES / rel).is_file(), rel


@pytest.mark.parametrize("svg", _svgs(), ids=lambda p: str(p.relative_to(SCENES)))
def test_every_svg_scene_is_a_clean_rig(svg: Path) -> None:
    (ch,) = load_characters(svg)
    assert ch.warnings == []
    assert len(ch.joints) >= 1
    for j in ch.joints:
        assert j.shapes, f"{svg.name}: joint {j.name} draws nothing"
        assert np.all(np.isfinite(j.pivot))


@pytest.mark.parametrize("project", _projects(), ids=lambda p: str(p.relative_to(SCENES)))
def test_every_project_opens_with_relative_sources(project: Path) -> None:
    data = json.loads(project.read_text(encoding="utf-8"))
    for asset in data["assets"]:
        for key, value in [("source", asset.get("source")), *asset.get("properties", {}).items()]:
            if isinstance(value, str) and (key == "source" or key.endswith("_file")):
                assert not Path(value).is_absolute(), f"{project.name}: {key} is absolute, {value}"
    doc = open_document(project)
    assert doc.assets
    for aid in doc.assets:
        assert aid in doc.runtime, f"{project.name}: asset {aid} did not load"
    assert summarize(project)["assets"]


# ------------------------------------------------------------------ 2D rigs
def test_telescope_is_a_seven_joint_chain() -> None:
    (ch,) = load_characters(SCENES / "telescope_chain.svg")
    assert [j.name for j in ch.joints] == ["base", "tube1", "tube2", "tube3", "tube4", "tube5", "tube6"]
    assert [j.parent for j in ch.joints] == [None, 0, 1, 2, 3, 4, 5]
    assert not ch.dynamic.any()
    # A standing chain: each pivot is above the one before it (y down).
    ys = [j.pivot[1] for j in ch.joints[1:]]
    assert all(b < a for a, b in zip(ys, ys[1:]))


def test_flappy_has_ears_and_a_ponytail_that_swing() -> None:
    (ch,) = load_characters(SCENES / "flappy.svg")
    assert len(ch.joints) == 14
    dynamic = [j.name for j in ch.joints if j.is_dynamic]
    assert dynamic == ["ear_left", "ear_right", "ponytail", "ponytail_tip"]
    names = [j.name for j in ch.joints]
    parent = {j.name: (names[j.parent] if j.parent is not None else None) for j in ch.joints}
    assert parent["ear_left"] == parent["ear_right"] == parent["ponytail"] == "head"
    assert parent["ponytail_tip"] == "ponytail"
    assert parent["forearm_left"] == "upper_arm_left" and parent["shin_right"] == "thigh_right"
    # Every pendulum is drawn off its hanging angle, so it swings with nothing keyed.
    from qtanimator.document import Document
    from qtanimator.document.character2d import add_characters_command

    doc = Document()
    add_characters_command(doc, SCENES / "flappy.svg").do(doc)
    aid = next(iter(doc.assets))
    a = joint_angles(doc, aid, 0.5)
    assert np.all(np.isfinite(a))
    for k, j in enumerate(ch.joints):
        if j.is_dynamic:
            assert abs(a[k]) > 0.02, j.name
        else:
            assert a[k] == 0.0, j.name


def test_pencil_tip_follows_the_path() -> None:
    rigs = _tool("make_rigs2d")
    (ch,) = load_characters(SCENES / "pencil.svg")
    assert len(ch.joints) == 1 and not ch.dynamic.any()
    np.testing.assert_allclose(ch.joints[0].pivot, rigs.PENCIL_TIP)
    # The pivot is the graphite tip: the lowest-left point of the drawing.
    x0, y0, x1, y1 = ch.bounds()
    assert abs(ch.joints[0].pivot[1] - y1) < 1.0 and abs(ch.joints[0].pivot[0] - x0) < 1.0
    doc = open_document(SCENES / "pencil_path.qtanim")
    xs, ys = doc.channels["pencil//x"], doc.channels["pencil//y"]
    assert len(xs.keys) == len(ys.keys) == 12
    for t in (0.0, 0.5, 1.7, 3.3, 4.4):
        pose = evaluate_pose(doc, "pencil", t)
        want = np.array(rigs.PENCIL_TIP) + [xs.evaluate(t), ys.evaluate(t)]
        np.testing.assert_allclose(pose.pivots[0], want, atol=1e-9)
    assert float(xs.evaluate(4.4)) == 320.0  # the last key, held


# ------------------------------------------------------------------ matrix-stack robot
def test_robot_project_is_animated_with_linear_keys_like_the_lecture() -> None:
    robot = _tool("make_robot")
    doc = open_document(SCENES / "robot" / "robot.qtanim")
    assert set(doc.channels) == set(robot.KEYS)
    times = np.linspace(-1.0, 9.0, 137)
    for cid, keys in robot.KEYS.items():
        ch = doc.channels[cid]
        assert all(k.interpolation is Interpolation.LINEAR for k in ch.keys), cid
        assert ch.pre is Extrapolation.CYCLE and ch.post is Extrapolation.CYCLE
        assert [(k.time, k.value) for k in ch.keys] == keys
        want = [robot.eval_keys(keys, float(t)) for t in times]
        np.testing.assert_allclose(ch.evaluate(times), want, atol=1e-9, err_msg=cid)
    # Piecewise linear: halfway between two keys is the mean of the keys.
    ch = doc.channels["robot/arm_left/angle"]
    assert float(ch.evaluate(0.5)) == pytest.approx((-0.3 + -1.3) / 2)


def test_robot_rig_poses_like_the_matrix_stack() -> None:
    robot = _tool("make_robot")
    (ch,) = load_characters(SCENES / "robot" / "robot.svg")
    names = [j.name for j in ch.joints]
    assert len(names) == 12 and not ch.dynamic.any()
    assert names == [p.name for p in robot.robot().walk()]
    rest = robot.stack_pivots()
    for j in ch.joints:
        np.testing.assert_allclose(j.pivot, rest[j.name], atol=1e-3)  # SVG keeps 3 decimals
    doc = open_document(SCENES / "robot" / "robot.qtanim")
    for t in (0.0, 0.3, 0.75, 1.6, 2.9, 5.25):
        angles, translation = robot.pose_at(t)
        want = robot.stack_pivots(angles, translation)
        pose = evaluate_pose(doc, "robot", t)
        for k, name in enumerate(names):
            np.testing.assert_allclose(pose.pivots[k], want[name], atol=2e-3, err_msg=f"{name} at t={t}")
    # Something actually moves: the claw travels far between two poses.
    a, b = evaluate_pose(doc, "robot", 0.0), evaluate_pose(doc, "robot", 1.0)
    assert np.linalg.norm(a.pivots[names.index("claw_left")] - b.pivots[names.index("claw_left")]) > 50


# ------------------------------------------------------------------ 3D arm
def test_arm_files_load_with_the_cse169_readers() -> None:
    sk = load_skel(SCENES / "arm3d" / "arm.skel")
    assert [j.parent for j in sk.joints] == [None, 0]
    assert [j.name for j in sk.joints] == ["shoulder", "elbow"]
    elbow_z = sk.joints[1].dofs[2]
    assert (elbow_z.min, elbow_z.max) == (0.0, 2.6)
    skin = load_skin(SCENES / "arm3d" / "arm.skin", num_joints=2)
    arm = _tool("make_arm")
    rings = len(arm._profile()[0])
    assert skin.num_vertices == rings * arm.SEGMENTS + 2
    assert len(skin.triangles) == 2 * arm.SEGMENTS * (rings - 1) + 2 * arm.SEGMENTS
    assert skin.num_joints == 2 and skin.binding.max_influences == 2
    np.testing.assert_allclose(skin.binding.weight_sums(), 1.0, atol=1e-12)
    w = skin.binding.dense()
    assert ((w[:, 0] > 0) & (w[:, 1] > 0)).sum() > 3 * arm.SEGMENTS  # a real blend across the elbow
    clip = load_anim(SCENES / "arm3d" / "arm_wave.anim")
    assert len(clip.channels) == channel_count(2) == 9
    assert (clip.start, clip.end) == (0.0, 2.0)


def test_arm_bind_pose_reproduces_the_stored_mesh() -> None:
    sk = load_skel(SCENES / "arm3d" / "arm.skel")
    skin = load_skin(SCENES / "arm3d" / "arm.skin", num_joints=2)
    world = sk.world_matrices()  # the .skel's pose is the bind pose
    assert skin.bind_matrices is not None
    np.testing.assert_allclose(world, skin.bind_matrices, atol=2e-6)
    # The bind matrices carry real rotations, so a, b, c, d read as rows would differ.
    assert np.abs(skin.bind_matrices[:, :3, :3] - np.eye(3)).max() > 0.3
    np.testing.assert_allclose(skin_positions(skin, world), skin.positions, atol=1e-5)
    assert skin.normals is not None
    np.testing.assert_allclose(skin_normals(skin, world), skin.normals, atol=1e-4)
    rows = skin.bind_matrices.copy()
    rows[:, :3, :] = np.transpose(skin.bind_matrices[:, :4, :3], (0, 2, 1))  # the wrong reading
    rows[:, 3, :] = [0, 0, 0, 1]
    wrong = skin_positions(type(skin).from_bind_matrices(skin.positions, skin.triangles, skin.binding, rows), world)
    assert np.abs(wrong - skin.positions).max() > 0.1
    # Normals point out of the tube (triangles wound counter-clockwise seen from outside).
    centre_line = skin.positions.mean(axis=0)
    p = skin.positions[skin.triangles]
    face_n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    shoulder_to_face = p.mean(axis=1) - world[0, :3, 3]
    axis = world[0, :3, 0]
    radial = shoulder_to_face - np.outer(shoulder_to_face @ axis, axis)
    upper = (shoulder_to_face @ axis > 0.1) & (shoulder_to_face @ axis < 0.7)
    assert np.all(np.einsum("ij,ij->i", face_n[upper], radial[upper]) > 0)
    assert np.isfinite(centre_line).all()


def test_arm_wave_starts_in_the_bind_pose_and_bends_the_elbow() -> None:
    from qtanimator.document.character3d import pose_skeleton, skinned_mesh

    doc = open_document(SCENES / "arm3d" / "arm3d.qtanim")
    sk = load_skel(SCENES / "arm3d" / "arm.skel")
    for t in (0.0, 2.0, 4.0):
        np.testing.assert_allclose(pose_skeleton(doc, "arm", t).dof_values(), sk.dof_values(), atol=1e-12)
        pos, _ = skinned_mesh(doc, "arm", t)
        np.testing.assert_allclose(pos, load_skin(SCENES / "arm3d" / "arm.skin").positions, atol=1e-5)
    bent = pose_skeleton(doc, "arm", 0.5)
    assert bent.get_dof(1, "z") == pytest.approx(1.7)
    pos, normals = skinned_mesh(doc, "arm", 0.5)
    assert np.all(np.isfinite(pos)) and np.allclose(np.linalg.norm(normals, axis=1), 1.0)
    # The forearm end (weight 1 on the elbow) stays at its distance from the elbow joint.
    skin = load_skin(SCENES / "arm3d" / "arm.skin")
    tip = int(np.argmax(skin.binding.dense()[:, 1] * (skin.positions @ sk.world_matrices()[0, :3, 0])))
    e0 = sk.world_matrices()[1, :3, 3]
    e1 = bent.world_matrices()[1, :3, 3]
    assert np.linalg.norm(pos[tip] - e1) == pytest.approx(np.linalg.norm(skin.positions[tip] - e0), abs=1e-5)
    assert np.linalg.norm(pos[tip] - skin.positions[tip]) > 0.3


# ------------------------------------------------------------------ cloth
def test_cloth_flag_scene() -> None:
    from qtanimator.document.cloth import cloth_params, cloth_problem, cloth_state

    doc = open_document(SCENES / "cloth" / "cloth.qtanim")
    assert [a.kind for a in doc.assets.values()] == ["cloth"]
    p = cloth_params(doc, "flag")
    assert (p.rows, p.cols) == (16, 24) and p.pin_mode == "custom"
    assert p.custom_pins == [r * p.cols for r in range(p.rows)]  # the left edge, on the pole
    assert p.wind[0] > 0
    rest = cloth_state(doc, "flag", 0)
    later = cloth_state(doc, "flag", 40)
    assert cloth_problem(doc, "flag") is None
    pins = np.array(p.custom_pins)
    np.testing.assert_allclose(later[pins], rest[pins], atol=1e-9)
    assert np.abs(later - rest).max() > 0.05  # the flag moves
    assert np.all(np.isfinite(later))


# ------------------------------------------------------------------ determinism
@pytest.mark.parametrize("tool,subdir", [("make_rigs2d", ""), ("make_robot", "robot"), ("make_arm", "arm3d"),
                                         ("make_cloth", "cloth")])
def test_generators_reproduce_the_committed_files(tool: str, subdir: str, tmp_path: Path) -> None:
    module = _tool(tool)
    out = tmp_path / (subdir or "scenes")
    written = module.write(out)
    assert written
    for p in written:
        committed = SCENES / subdir / p.name
        assert committed.is_file(), f"{committed} is not in the repository; run scenes/tools/{tool}.py"
        assert p.read_bytes() == committed.read_bytes(), (
            f"{committed.relative_to(REPO)} differs from what scenes/tools/{tool}.py writes; rerun it")


def test_svg_numbers_are_short_and_clean() -> None:
    sw = _tool("svgwriter")
    assert sw.num(-0.0001) == "0" and sw.num(2.5) == "2.5" and sw.num(3.0) == "3" and sw.num(1 / 3) == "0.333"
    # The rig convention: positive angles turn counter-clockwise on a y-down screen.
    (x, y), = sw.rotate_points([(1.0, 0.0)], math.pi / 2, (0.0, 0.0))
    assert (round(x, 12), round(y, 12)) == (0.0, -1.0)


# ------------------------------------------------------------------ pixels
def _ink(rgba: np.ndarray, background: tuple[int, int, int]) -> np.ndarray:
    """Mask of pixels that differ from the background colour."""
    return np.abs(rgba[..., :3].astype(int) - np.array(background)).sum(axis=2) > 30


@pytest.mark.parametrize("scene,times", [
    ("flappy_hop.qtanim", (0.0, 0.25)), ("robot/robot.qtanim", (0.0, 1.0)), ("pencil_path.qtanim", (0.0, 2.0)),
    ("telescope_chain.svg", (0.0,)),
])
def test_2d_scenes_draw_and_move(qapp, scene: str, times: tuple[float, ...]) -> None:
    from qtanimator.render.cli_render import load_scene
    from qtanimator.render.painter2d import animation_bounds, image_to_array, render_frame

    doc = load_scene(SCENES / scene)
    view = animation_bounds(doc, [t / 10 for t in range(0, 41)])  # a steady camera, as `render` uses
    frames = [image_to_array(render_frame(doc, t, (160, 120), "white", view=view)) for t in times]
    for f in frames:
        assert 0.03 < _ink(f, (255, 255, 255)).mean() < 0.9
    if len(frames) > 1:
        assert (np.abs(frames[0].astype(int) - frames[1].astype(int)).sum(axis=2) > 30).mean() > 0.01


@pytest.mark.gl
def test_3d_scenes_render_and_move(qapp) -> None:
    from qtanimator.render.gl.renderer import ViewOptions
    from qtanimator.render.render3d import render_frames_3d

    plain = ViewOptions(show_grid=False, show_lights=False, show_skeleton=False, background=(0, 0, 0, 1))
    arm = open_document(SCENES / "arm3d" / "arm3d.qtanim")
    a0, a1 = render_frames_3d(arm, (0.0, 0.5), (160, 120), options=plain)
    cloth = open_document(SCENES / "cloth" / "cloth.qtanim")
    c0, c1 = render_frames_3d(cloth, (0.0, 0.5), (160, 120), options=plain)
    for img in (a0, a1, c0, c1):
        assert 0.01 < _ink(img, (0, 0, 0)).mean() < 0.9
    for first, later in ((a0, a1), (c0, c1)):
        assert (_ink(first, (0, 0, 0)) != _ink(later, (0, 0, 0))).mean() > 0.01
