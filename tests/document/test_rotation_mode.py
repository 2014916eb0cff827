"""Switching a character's rotations between quaternion and Euler keys (Blender's rotation
mode): the Euler curves pose the character as the quaternion keys did at every sample, the
switch is one undo step, clips picked later arrive in the mode, and the project keeps it."""

from __future__ import annotations

import numpy as np
import pytest
from gltf_gen import three_animations
from gltf_spec import world_positions

from qtanimator.document import Document, UndoStack, open_document, save_document
from qtanimator.document.character3d import (
    character,
    set_clip_command,
    set_rotation_mode_command,
    skinned_mesh,
)
from qtanimator.document.import3d import import_file


def _open(path):
    doc = Document()
    stack = UndoStack(doc)
    imp = import_file(doc, path)
    stack.push(imp.command)
    return doc, stack, imp.asset_id


def _spec(path, clip_index, t, ch):
    parts = world_positions(path, clip_index, t)
    out = np.zeros((sum(p.count for p in ch.parts), 3))
    by_node = {}
    for pos, part in zip(parts, sorted(ch.parts, key=lambda p: (p.node, p.primitive))):
        by_node[(part.node, part.primitive)] = pos
    for part in ch.parts:
        out[part.start:part.start + part.count] = by_node[(part.node, part.primitive)]
    return out


def test_euler_mode_keys_every_frame_exactly_and_survives_clip_switch_undo_and_save(tmp_path):
    path = three_animations(tmp_path)
    doc, stack, aid = _open(path)
    ch = character(doc, aid)
    before = doc.state()
    stack.push(set_rotation_mode_command(doc, aid, "euler"))
    euler = character(doc, aid)
    assert not any(j.quaternion for j in euler.skeleton.joints)
    ids = [cid for cid, _ in doc.channels_of(aid)]
    assert ids and not any(cid.rsplit("/", 1)[1].startswith("q") for cid in ids)
    assert any(cid.endswith("/rx") for cid in ids)
    size = np.linalg.norm(np.ptp(skinned_mesh(doc, aid, 0.0)[0], axis=0))
    frames = np.arange(0, 61) / doc.fps  # "idle" 0–1 s: the samples are the frames
    for t in frames:
        assert np.abs(skinned_mesh(doc, aid, t)[0] - _spec(path, 0, t, ch)).max() < 1e-9 * size
    # a clip picked in Euler mode arrives converted, exact at its frames
    stack.push(set_clip_command(doc, aid, "walk"))
    assert not any(cid.rsplit("/", 1)[1].startswith("q") for cid, _ in doc.channels_of(aid))
    for t in np.arange(0, 121, 7) / doc.fps:
        assert np.abs(skinned_mesh(doc, aid, t)[0] - _spec(path, 1, t, ch)).max() < 1e-9 * size
    project = tmp_path / "mode.qtanim"
    save_document(doc, project)
    again = open_document(project)
    assert not any(j.quaternion for j in character(again, aid).skeleton.joints)
    assert np.allclose(skinned_mesh(again, aid, 0.55)[0], skinned_mesh(doc, aid, 0.55)[0], atol=1e-12)
    stack.undo()
    stack.undo()
    assert doc.state() == before
    assert all(j.quaternion for j in character(doc, aid).skeleton.joints)


def test_back_to_quaternions_and_unknown_modes(tmp_path):
    path = three_animations(tmp_path)
    doc, stack, aid = _open(path)
    stack.push(set_rotation_mode_command(doc, aid, "euler"))
    stack.push(set_rotation_mode_command(doc, aid, "quaternion"))
    assert all(j.quaternion for j in character(doc, aid).skeleton.joints)
    ch = character(doc, aid)
    size = np.linalg.norm(np.ptp(skinned_mesh(doc, aid, 0.0)[0], axis=0))
    for t in np.arange(0, 61, 5) / doc.fps:
        assert np.abs(skinned_mesh(doc, aid, t)[0] - _spec(path, 0, t, ch)).max() < 1e-9 * size
    with pytest.raises(ValueError, match="rotation mode"):
        set_rotation_mode_command(doc, aid, "matrix")


def test_a_bvh_character_keyed_as_quaternions_poses_the_same_at_its_frames(shared_data):
    from qtanimator.document.character3d import world_matrices
    from qtanimator.formats.bvh import load_bvh

    path = shared_data / "bvh" / "fairmotion_sinusoidal.bvh"
    doc, stack, aid = _open(path)
    clip = load_bvh(path)
    times = np.arange(0, clip.frame_count, 9) * clip.frame_time
    before = [world_matrices(doc, aid, t) for t in times]
    stack.push(set_rotation_mode_command(doc, aid, "quaternion"))
    assert all(j.quaternion for j in character(doc, aid).skeleton.joints)
    assert any(cid.endswith("/qw") for cid, _ in doc.channels_of(aid))
    for t, w in zip(times, before):
        assert np.allclose(world_matrices(doc, aid, t), w, atol=1e-9)


def test_ik_slider_keys_and_key_all_on_quaternion_joints(shared_data):
    from qtanimator.core.ik3d import chain_dofs
    from qtanimator.core.rotation import rotation_matrices
    from qtanimator.document.character3d import (
        ik_values,
        pose_skeleton,
        set_dof_command,
        set_dofs_command,
        world_matrices,
    )
    from qtanimator.document.pose import key_character_command

    doc, stack, aid = _open(shared_data / "gltf" / "CesiumMan.glb")
    skel = character(doc, aid).skeleton
    end, t = len(skel.joints) - 1, 0.5
    goal = world_matrices(doc, aid, t)[end, :3, 3] + np.array([0.05, 0.05, 0.0])
    stack.push(set_dofs_command(doc, aid, ik_values(doc, aid, end, goal, t, chain_dofs(skel, end, 3)), t))
    assert np.linalg.norm(world_matrices(doc, aid, t)[end, :3, 3] - goal) < 1e-4
    # a slider sets one Euler angle of a quaternion joint: the joint turns to exactly that
    before = pose_skeleton(doc, aid, t).joints[3].pose
    stack.push(set_dof_command(doc, aid, 3, "y", 0.4, t))
    after = pose_skeleton(doc, aid, t).joints[3]
    expected = before.copy()
    expected[1] = 0.4
    order = after.rotation_order or "zyx"
    assert np.allclose(rotation_matrices([after.pose], order), rotation_matrices([expected], order), atol=1e-9)
    # key all: every channel keyed at the frame, the pose unchanged
    shown = world_matrices(doc, aid, 1.3)
    stack.push(key_character_command(doc, aid, 1.3))
    assert np.allclose(world_matrices(doc, aid, 1.3), shown, atol=1e-9)
    qw = [c for cid, c in doc.channels_of(aid) if cid.endswith("/qw")]
    assert qw and all(c.key_index(1.3) is not None for c in qw)
