import numpy as np
import pytest

from qtanimator.core.clip import apply_clip
from qtanimator.core.skinning import skin_positions
from qtanimator.document import Document, UndoStack, open_document, save_document
from qtanimator.document.character3d import (
    ASSET_KIND,
    Character3D,
    add_character3d_command,
    channel_dofs,
    dof_channel_id,
    load_anim_command,
    pose_skeleton,
    set_dof_command,
    set_dofs_command,
    skinned_mesh,
    world_matrices,
)
from qtanimator.formats import FormatError
from qtanimator.formats.anim import load_anim

SKEL = """balljoint root {
  offset 0 0 0
  balljoint arm {
    offset 0 1 0
    rotxlimit -1 1
    pose 0.5 0 0
  }
  balljoint arm {
    offset 0 -1 0
  }
}
"""


@pytest.fixture
def small(tmp_path):
    p = tmp_path / "toy.skel"
    p.write_text(SKEL)
    return p


def test_add_undo_redo_and_channel_ids(small):
    doc = Document()
    stack = UndoStack(doc)
    stack.push(add_character3d_command(doc, small))
    assert list(doc.assets) == ["toy"] and doc.assets["toy"].kind == ASSET_KIND
    assert isinstance(doc.runtime["toy"], Character3D)
    assert dof_channel_id(doc, "toy", None, "x") == "toy//tx"
    assert dof_channel_id(doc, "toy", 1, "z") == "toy/arm#1/rz"
    assert dof_channel_id(doc, "toy", 2, "rx") == "toy/arm#2/rx"
    assert channel_dofs(doc, "toy")["toy/arm#2/ry"] == (2, "y")
    stack.undo()
    assert not doc.assets and not doc.runtime
    stack.redo()
    assert "toy" in doc.runtime


def test_set_dof_keys_clamps_merges_and_undoes(small):
    doc = Document()
    stack = UndoStack(doc)
    stack.push(add_character3d_command(doc, small))
    # with no channel the file's pose applies
    assert pose_skeleton(doc, "toy", 0.0).get_dof(1, "x") == 0.5
    g = object()
    stack.push(set_dof_command(doc, "toy", 1, "x", 0.2, time=1.0, gesture=g))
    stack.push(set_dof_command(doc, "toy", 1, "x", 5.0, time=1.0, gesture=g))  # clamped to 1
    assert len(stack.done) == 2  # the drag merged into one step
    ch = doc.channels["toy/arm#1/rx"]
    assert [(k.time, k.value) for k in ch.keys] == [(1.0, 1.0)]
    assert pose_skeleton(doc, "toy", 3.0).get_dof(1, "x") == 1.0
    stack.push(set_dofs_command(doc, "toy", {(None, "y"): 2.0, (2, "z"): 0.25}, time=0.0))
    s = pose_skeleton(doc, "toy", 0.0)
    assert s.root_translation.tolist() == [0.0, 2.0, 0.0] and s.get_dof(2, "z") == 0.25
    assert np.allclose(world_matrices(doc, "toy", 0.0)[0][:3, 3], [0, 2, 0])
    # the runtime skeleton is never posed in place
    assert doc.runtime["toy"].skeleton.get_dof(2, "z") == 0.0
    stack.undo()
    stack.undo()
    assert "toy/arm#1/rx" not in doc.channels


def test_bad_files_raise_format_error_and_leave_the_document(tmp_path, small):
    bad = tmp_path / "bad.anim"
    bad.write_text("animation { channel {")
    doc = Document()
    with pytest.raises(FormatError):
        add_character3d_command(doc, small, anim_path=bad)
    too_many = tmp_path / "many.anim"
    chans = "".join("channel { extrapolate constant constant keys 0 { } }" for _ in range(13))
    too_many.write_text(f"animation {{ range 0 1 numchannels 13 {chans} }}")
    with pytest.raises(FormatError, match="at most 12"):
        add_character3d_command(doc, small, anim_path=too_many)
    assert not doc.assets and not doc.channels


@pytest.fixture(scope="module")
def wasp_doc(shared_data):
    d = shared_data / "cse169/wasp_walk"
    doc = Document()
    UndoStack(doc).push(add_character3d_command(doc, d / "wasp.skel", skin_path=d / "wasp.skin",
                                                anim_path=d / "wasp_walk.anim"))
    return doc, d


def test_anim_channels_enter_the_document(wasp_doc):
    doc, d = wasp_doc
    ids = list(doc.channels)
    assert len(ids) == 72
    assert ids[:4] == ["wasp//tx", "wasp//ty", "wasp//tz", "wasp/root/rx"]
    clip = load_anim(d / "wasp_walk.anim")
    skel = doc.runtime["wasp"].skeleton.copy()
    for t in (-0.5, 0.0, 0.7, 1.33, 3.9, 5.2):
        apply_clip(skel, clip, t)
        posed = pose_skeleton(doc, "wasp", t)
        assert np.array_equal(posed.dof_values(), skel.dof_values())
        assert np.array_equal(posed.root_translation, skel.root_translation)
        p, n = skinned_mesh(doc, "wasp", t)
        assert np.allclose(p, skin_positions(doc.runtime["wasp"].skin, skel.world_matrices()))
        assert np.allclose(np.linalg.norm(n, axis=1), 1.0)


def test_project_round_trip_reloads_the_character(wasp_doc, tmp_path):
    doc, _ = wasp_doc
    path = tmp_path / "scene.qtanim"
    save_document(doc, path)
    again = open_document(path)
    assert isinstance(again.runtime["wasp"], Character3D)
    assert again.channels == doc.channels
    assert np.array_equal(skinned_mesh(again, "wasp", 1.25)[0], skinned_mesh(doc, "wasp", 1.25)[0])


def test_load_anim_command_replaces_channels(shared_data, tmp_path):
    d = shared_data / "cse169/wasp_walk"
    doc = Document()
    stack = UndoStack(doc)
    stack.push(add_character3d_command(doc, d / "wasp.skel", skin_path=d / "wasp.skin"))
    assert not doc.channels
    stack.push(load_anim_command(doc, "wasp", d / "wasp_walk_crlf.anim"))
    assert len(doc.channels) == 72 and doc.assets["wasp"].properties["anim_file"].endswith("crlf.anim")
    stack.undo()
    assert not doc.channels and "anim_file" not in doc.assets["wasp"].properties


def test_dragon_duplicate_names(shared_data):
    doc = Document()
    UndoStack(doc).push(add_character3d_command(doc, shared_data / "cse169/skeleton/dragon.skel"))
    ids = [dof_channel_id(doc, "dragon", j, "x") for j in range(81)]
    assert len(set(ids)) == 81
    assert any("#" in i for i in ids)


def test_mit_character(shared_data):
    d = shared_data / "mit6837"
    doc = Document()
    UndoStack(doc).push(add_character3d_command(doc, d / "Model1.skel", obj_path=d / "Model1.obj",
                                                attach_path=d / "Model1.attach"))
    ch = doc.runtime["Model1"]
    assert ch.faceted and ch.skeleton.rotation_order == "xyz"
    p, n = skinned_mesh(doc, "Model1", 0.0)
    assert np.abs(p - ch.mesh.positions).max() < 2.8e-4
    UndoStack(doc).push(set_dofs_command(doc, "Model1", {(4, "x"): 0.3, (4, "y"): -0.5, (4, "z"): 0.7}, 0.0))
    assert np.allclose(world_matrices(doc, "Model1", 0.0)[7][:3, 3], [0.64567, 0.10592, 0.49948], atol=1e-5)
    with pytest.raises(FormatError):
        add_character3d_command(doc, d / "Model1.skel", obj_path=d / "Model2.obj", attach_path=d / "Model1.skel")


def test_clip_from_document_round_trips_through_anim(wasp_doc, tmp_path):
    from qtanimator.document.character3d import clip_from_document
    from qtanimator.formats.anim import save_anim

    doc, d = wasp_doc
    clip = clip_from_document(doc, "wasp", 0.0, 4.0)
    assert clip == load_anim(d / "wasp_walk.anim")
    save_anim(clip, tmp_path / "out.anim")
    assert load_anim(tmp_path / "out.anim") == clip


def test_clip_from_document_fills_missing_dofs_with_the_pose(small):
    from qtanimator.document.character3d import clip_from_document

    doc = Document()
    UndoStack(doc).push(add_character3d_command(doc, small))
    clip = clip_from_document(doc, "toy")
    assert len(clip.channels) == 12
    assert clip.channels[3 + 3].evaluate(10.0) == 0.5  # joint 1 x from the file's pose
    assert (clip.start, clip.end) == (0.0, 4.0)
