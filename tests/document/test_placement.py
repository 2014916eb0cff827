"""Authored placement of characters (issue 14 item 2): the model, undo, saving, imports."""

from __future__ import annotations

import math

import numpy as np

from qtanimator.core.skinning import skin_positions
from qtanimator.document import Document, UndoStack, open_document, save_document
from qtanimator.document import character2d as c2d
from qtanimator.document import character3d as c3d
from qtanimator.document.import3d import import_file
from qtanimator.document.placement import (
    CHARACTER_HEIGHT,
    PLACEMENT,
    boxes_overlap,
    matrix2d,
    matrix3d,
    set_field_command,
    set_placement_command,
)

PLACED_3D = {"translate": [1.0, 2.0, -3.0], "rotate": [10.0, -20.0, 30.0], "scale": 0.5}


def _rot(axis: int, deg: float) -> np.ndarray:
    a = math.radians(deg)
    c, s = math.cos(a), math.sin(a)
    return [np.array([[1, 0, 0], [0, c, -s], [0, s, c]]), np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
            np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])][axis]


def test_matrix3d_closed_form() -> None:
    m = matrix3d(PLACED_3D)
    r = _rot(2, 30.0) @ _rot(1, -20.0) @ _rot(0, 10.0)
    assert np.allclose(m[:3, :3], 0.5 * r, atol=1e-15)
    assert np.allclose(m[:3, 3], [1.0, 2.0, -3.0])
    assert np.allclose(matrix3d(None), np.eye(4)) and np.allclose(matrix3d({"scale": "x"}), np.eye(4))


def test_3d_placement_goes_on_top_of_everything(shared_data) -> None:
    doc = Document()
    stack = UndoStack(doc)
    stack.push(import_file(doc, shared_data / "gltf" / "CesiumMan.glb").command)
    aid = next(iter(doc.assets))
    assert PLACEMENT not in doc.assets[aid].properties  # alone and of human size: as the file has it
    t = 0.3
    world0 = c3d.world_matrices(doc, aid, t)
    skin0 = c3d.skinned_mesh(doc, aid, t)[0]
    before = doc.state()
    stack.push(set_placement_command(doc, aid, PLACED_3D))
    a = matrix3d(PLACED_3D)
    # world = A · (file placement · …): every joint and every skinned vertex moves by A exactly
    assert np.allclose(c3d.world_matrices(doc, aid, t), a @ world0, atol=1e-12)
    skin1 = c3d.skinned_mesh(doc, aid, t)[0]
    assert np.allclose(skin1, skin0 @ a[:3, :3].T + a[:3, 3], atol=1e-9)
    ch = c3d.character(doc, aid)
    assert ch.skeleton.placement is not None  # the file's placement is kept as it is
    assert np.allclose(skin_positions(ch.skin, ch.skinning_world(c3d.world_matrices(doc, aid, t))), skin1)
    # IK sees it: the posed skeleton carries the product
    assert np.allclose(c3d.pose_skeleton(doc, aid, t).placement, a @ ch.skeleton.placement)
    stack.undo()
    assert doc.state() == before
    assert np.allclose(c3d.world_matrices(doc, aid, t), world0)
    stack.redo()
    assert np.allclose(c3d.world_matrices(doc, aid, t), a @ world0, atol=1e-12)


def test_one_field_is_one_undo_step_and_saved(shared_data, tmp_path) -> None:
    doc = Document()
    stack = UndoStack(doc)
    stack.push(import_file(doc, shared_data / "cse169" / "wasp_walk" / "wasp.skel").command)
    stack.push(set_field_command(doc, "wasp", 3, "translate", 0, 2.5))
    stack.push(set_field_command(doc, "wasp", 3, "scale", None, 2.0))
    p = doc.assets["wasp"].properties[PLACEMENT]
    assert p == {"translate": [2.5, 0.0, 0.0], "rotate": [0.0, 0.0, 0.0], "scale": 2.0}
    stack.undo()
    assert doc.assets["wasp"].properties[PLACEMENT]["scale"] == 1.0
    stack.redo()
    path = tmp_path / "placed.qtanim"
    save_document(doc, path)
    again = open_document(path)
    assert again.assets["wasp"].properties[PLACEMENT] == p
    assert np.allclose(c3d.world_matrices(again, "wasp", 0.5), c3d.world_matrices(doc, "wasp", 0.5))


def _height(box: tuple[np.ndarray, np.ndarray]) -> float:
    return float(box[1][1] - box[0][1])


def test_imports_land_beside_each_other_at_one_size(shared_data) -> None:
    doc = Document()
    stack = UndoStack(doc)
    files = [shared_data / "cse169" / "wasp_walk" / "wasp.skel", shared_data / "gltf" / "CesiumMan.glb",
             shared_data / "bvh" / "cmu_12_01_walk.bvh"]
    ids = []
    for f in files:
        result = import_file(doc, f)
        stack.push(result.command)
        ids.append(result.asset_id)
    boxes = [c3d.bounds(doc, aid, 0.0) for aid in ids]
    for i in range(len(boxes)):
        for j in range(i + 1, len(boxes)):
            assert not boxes_overlap(boxes[i], boxes[j]), (ids[i], ids[j], boxes[i], boxes[j])
    # the first (alone, of human size) keeps its file's size; the next are scaled to it
    # (about CHARACTER_HEIGHT) and stand on the floor
    assert abs(_height(boxes[0]) - CHARACTER_HEIGHT) < 0.15 * CHARACTER_HEIGHT
    for box in boxes[1:]:
        assert abs(_height(box) - _height(boxes[0])) < 1e-6
        assert abs(float(box[0][1])) < 1e-6
    stack.undo()
    assert ids[2] not in doc.assets


def _centimetre_bvh(shared_data, tmp_path):
    """fairmotion_sinusoidal.bvh with every offset ×100 (the same figure in centimetres)."""
    lines = []
    for line in (shared_data / "bvh" / "fairmotion_sinusoidal.bvh").read_text().splitlines():
        s = line.strip()
        if s.startswith("OFFSET"):
            nums = [float(v) * 100.0 for v in s.split()[1:]]
            line = line[: len(line) - len(line.lstrip())] + "OFFSET " + " ".join(f"{v:.6f}" for v in nums)
        lines.append(line)
    cm = tmp_path / "centimetres.bvh"
    cm.write_text("\n".join(lines) + "\n")
    return cm


def test_centimetres_and_metres_look_the_same(shared_data, tmp_path) -> None:
    """The same BVH written in centimetres lands at the size of the glTF in metres."""
    cm = _centimetre_bvh(shared_data, tmp_path)
    doc = Document()
    stack = UndoStack(doc)
    for f in (shared_data / "gltf" / "CesiumMan.glb", shared_data / "bvh" / "fairmotion_sinusoidal.bvh", cm):
        stack.push(import_file(doc, f).command)
    heights = [_height(c3d.bounds(doc, aid, 0.0)) for aid in doc.assets]
    for h in heights[1:]:
        assert abs(h - heights[0]) / heights[0] < 0.1, heights


def test_a_centimetre_file_alone_is_scaled(shared_data, tmp_path) -> None:
    doc = Document()
    result = import_file(doc, _centimetre_bvh(shared_data, tmp_path))
    result.command.do(doc)
    box = c3d.bounds(doc, result.asset_id, 0.0)
    assert abs(_height(box) - CHARACTER_HEIGHT) < 1e-6 and abs(float(box[0][1])) < 1e-6


def test_matrix2d_rotates_about_the_pivot() -> None:
    m = matrix2d({"translate": [10.0, 0.0], "rotate": 90.0, "scale": 2.0}, (5.0, 5.0))
    assert np.allclose(m @ [5.0, 5.0, 1.0], [15.0, 5.0, 1.0])  # the pivot only moves by t
    # R(90°) = [[0, 1], [-1, 0]] (counter-clockwise on a y-down screen), times 2
    assert np.allclose(m @ [6.0, 5.0, 1.0], [15.0, 3.0, 1.0])


def test_2d_placement_draws_picks_and_solves_in_place(shared_data) -> None:
    doc = Document()
    stack = UndoStack(doc)
    stack.push(c2d.add_characters_command(doc, shared_data / "cmu-animator" / "scenes" / "arm.svg"))
    aid = c2d.character_assets(doc)[0]
    ch = c2d.character(doc, aid)
    pose0 = c2d.evaluate_pose(doc, aid, 0.0)
    value = {"translate": [40.0, -10.0], "rotate": 30.0, "scale": 1.5}
    stack.push(set_placement_command(doc, aid, value))
    p = matrix2d(value, ch.rest_pivots[0])
    pose1 = c2d.evaluate_pose(doc, aid, 0.0)
    assert np.allclose(pose1.world, p @ pose0.world)
    assert np.allclose(pose1.pivots, pose0.pivots @ p[:2, :2].T + p[:2, 2])
    assert np.allclose(pose1.world_angles, pose0.world_angles)  # physics stays in the character's frame
    # a point on the last joint maps back to the same rest point
    j = len(ch.joints) - 1
    local = ch.joints[j].pivot + np.array([3.0, 1.0])
    assert np.allclose(pose1.to_local(j, pose1.to_world(j, local)), local)
    # IK reaches a scene target
    tip = pose1.to_world(j, local)
    target = tip + np.array([5.0, 5.0])
    values = c2d.ik_values(doc, aid, j, local, target, 0.0)
    stack.push(c2d.key_values(doc, values, 0.0, "IK"))
    reached = c2d.evaluate_pose(doc, aid, 0.0).to_world(j, local)
    assert np.linalg.norm(reached - target) < np.linalg.norm(tip - target)


def test_second_svg_lands_to_the_right(shared_data) -> None:
    doc = Document()
    stack = UndoStack(doc)
    for name in ("arm.svg", "pencil.svg"):
        stack.push(c2d.add_characters_command(doc, shared_data / "cmu-animator" / "scenes" / name))
    a, b = c2d.character_assets(doc)
    assert PLACEMENT not in doc.assets[a].properties
    ba, bb = c2d.shown_bounds(doc, a), c2d.shown_bounds(doc, b)
    assert bb[0] > ba[2]  # disjoint: entirely to the right
    assert abs(bb[3] - ba[3]) < 1e-9  # bottoms aligned
    stack.undo()
    assert c2d.character_assets(doc) == [a]
