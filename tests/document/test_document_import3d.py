"""Importing 3D files into the document (Qt-free) and exporting characters to glTF."""

from __future__ import annotations

import shutil

import numpy as np
import pytest
from docfix import set_parameters

from qtanimator.core.skeleton import rotation_matrices
from qtanimator.document import Document, UndoStack, open_document, save_document
from qtanimator.document.character3d import ASSET_KIND, character, skinned_mesh, world_matrices
from qtanimator.document.commands import AddAsset
from qtanimator.document.document import Asset
from qtanimator.document.gltf_character import character_from_gltf
from qtanimator.document.import3d import (
    companions,
    euler_from_matrices,
    export_gltf,
    import_file,
)
from qtanimator.formats import FormatError
from qtanimator.formats.bvh import load_bvh
from qtanimator.formats.gltf import import_gltf


def _imported(path, doc=None, selected=None):
    doc = doc or Document()
    stack = UndoStack(doc)
    before = doc.state()
    result = import_file(doc, path, selected)
    stack.push(result.command)
    return doc, stack, result, before


@pytest.mark.parametrize("order", ["xyz", "xzy", "yxz", "yzx", "zxy", "zyx"])
def test_euler_extraction_inverts_rotation_matrices(order):
    rng = np.random.default_rng(3)
    angles = rng.uniform(-1.4, 1.4, size=(50, 3))
    back = euler_from_matrices(rotation_matrices(angles, order), order)
    assert np.allclose(rotation_matrices(back, order), rotation_matrices(angles, order), atol=1e-12)
    assert np.allclose(back, angles, atol=1e-9)


def test_wasp_skel_brings_its_skin_and_the_folders_walk(shared_data):
    folder = shared_data / "cse169" / "wasp_walk"
    found = companions(folder / "wasp.skel")
    assert found["skin"].name == "wasp.skin"
    assert found["anim"].name == "wasp_walk.anim"  # the prefix of wasp_walk_crlf / _unnumbered
    doc, stack, result, before = _imported(folder / "wasp.skel")
    aid = result.asset_id
    asset = doc.assets[aid]
    assert asset.kind == ASSET_KIND
    assert asset.properties["skin_file"].endswith("wasp.skin")
    assert asset.properties["anim_file"].endswith("wasp_walk.anim")
    assert character(doc, aid).skin is not None
    assert any(cid.startswith(f"{aid}/") for cid in doc.channels)
    assert stack.undo()
    assert doc.state() == before
    assert aid not in doc.runtime


def test_only_anim_in_folder_is_used(shared_data, tmp_path):
    shutil.copy(shared_data / "cse169" / "wasp_walk" / "wasp.skel", tmp_path / "bug.skel")
    shutil.copy(shared_data / "cse169" / "wasp_walk" / "wasp_walk.anim", tmp_path / "walk.anim")
    assert companions(tmp_path / "bug.skel")["anim"].name == "walk.anim"
    doc, _stack, result, _ = _imported(tmp_path / "bug.skel")
    assert doc.assets[result.asset_id].properties["anim_file"].endswith("walk.anim")


def test_a_guessed_anim_that_does_not_fit_is_left_out(shared_data, tmp_path):
    shutil.copy(shared_data / "cse169" / "skeleton" / "tube.skel", tmp_path / "tube.skel")
    shutil.copy(shared_data / "cse169" / "wasp_walk" / "wasp_walk.anim", tmp_path / "walk.anim")
    doc, _stack, result, _ = _imported(tmp_path / "tube.skel")
    assert "anim_file" not in doc.assets[result.asset_id].properties
    assert any("walk.anim" in n for n in result.notes)


def test_mit_skel_and_obj(shared_data):
    for name in ("Model1.skel", "Model1.obj"):
        doc, stack, result, before = _imported(shared_data / "mit6837" / name)
        props = doc.assets[result.asset_id].properties
        assert props["obj_file"].endswith("Model1.obj") and props["attach_file"].endswith("Model1.attach")
        ch = character(doc, result.asset_id)
        assert ch.faceted and ch.skin is not None and ch.skin.num_vertices > 0
        stack.undo()
        assert doc.state() == before


def test_obj_without_skeleton_is_an_error(shared_data, tmp_path):
    shutil.copy(shared_data / "mit6837" / "Model1.obj", tmp_path / "lonely.obj")
    doc = Document()
    before = doc.state()
    with pytest.raises(FormatError, match="lonely.skel"):
        import_file(doc, tmp_path / "lonely.obj")
    assert doc.state() == before


def test_skin_and_anim_go_on_the_selected_character(shared_data):
    folder = shared_data / "cse169" / "wasp_walk"
    doc = Document()
    stack = UndoStack(doc)
    with pytest.raises(FormatError, match="no 3D character"):
        import_file(doc, folder / "wasp_walk.anim")
    stack.push(import_file(doc, shared_data / "cse169" / "skeleton" / "wasp.skel").command)
    assert character(doc, "wasp").skin is None and not doc.channels
    before = doc.state()
    stack.push(import_file(doc, folder / "wasp.skin", "wasp").command)
    assert character(doc, "wasp").skin is not None
    stack.push(import_file(doc, folder / "wasp_walk.anim", "wasp").command)
    assert doc.assets["wasp"].properties["anim_file"].endswith("wasp_walk.anim")
    assert len(doc.channels) > 0
    stack.undo()
    stack.undo()
    assert doc.state() == before
    assert character(doc, "wasp").skin is None


def test_skin_with_the_skel_of_its_stem(shared_data):
    doc, stack, result, before = _imported(shared_data / "cse169" / "wasp_walk" / "wasp.skin")
    assert doc.assets[result.asset_id].source.endswith("wasp.skel")
    stack.undo()
    assert doc.state() == before


def test_bvh_import_matches_the_file_and_survives_save(shared_data, tmp_path):
    path = shared_data / "bvh" / "cmu_12_01_walk.bvh"
    doc, stack, result, before = _imported(path)
    aid = result.asset_id
    clip = load_bvh(path)
    for frame in (0, 100, clip.frame_count - 1):
        t = frame * clip.frame_time
        assert np.allclose(world_matrices(doc, aid, t), clip.world_matrices(frame=frame), atol=1e-9)
    # the range grew to show the whole clip
    assert doc.frame_to_time(doc.frame_range[1]) >= clip.duration - 1e-9
    project = tmp_path / "bvh.qtanim"
    save_document(doc, project)
    again = open_document(project)
    assert again.state() == doc.state()
    assert np.allclose(world_matrices(again, aid, 0.5), world_matrices(doc, aid, 0.5))
    stack.undo()
    assert doc.state() == before


@pytest.mark.parametrize("name", ["CesiumMan.glb", "RiggedFigure.glb", "RiggedSimple.glb", "SimpleSkin.gltf"])
def test_gltf_import_follows_the_files_animation(shared_data, tmp_path, name):
    path = shared_data / "gltf" / name
    doc, stack, result, before = _imported(path)
    aid = result.asset_id
    scene = import_gltf(path)
    anim = scene.animations[0]
    (part,) = character(doc, aid).parts
    # Joints that move (CesiumMan's hips), slerp between keys: exact, not nearly.
    for t in np.linspace(anim.start, anim.end, 7):
        ref = scene.skinned_positions(part.mesh, t)
        ours, _normals = skinned_mesh(doc, aid, t)
        size = np.linalg.norm(np.ptp(ref, axis=0))
        assert np.abs(ours - ref).max() <= 1e-9 * size
    assert any("1 clips" in n for n in result.notes)
    project = tmp_path / "g.qtanim"
    save_document(doc, project)
    again = open_document(project)
    assert again.state() == doc.state()
    t = 0.5 * (anim.start + anim.end)
    assert np.allclose(skinned_mesh(again, aid, t)[0], skinned_mesh(doc, aid, t)[0])
    stack.undo()
    assert doc.state() == before


def test_gltf_mapping_in_rest_pose_is_exact(shared_data):
    scene = import_gltf(shared_data / "gltf" / "CesiumMan.glb")
    ch = character_from_gltf(scene).character
    from qtanimator.core.skinning import skin_positions

    ours = skin_positions(ch.skin, ch.skinning_world(ch.skeleton.world_matrices()))
    assert np.allclose(ours, scene.skinned_positions(ch.parts[0].mesh, None), atol=1e-9)


def test_bad_files_are_format_errors_and_change_nothing(tmp_path):
    doc = Document()
    before = doc.state()
    for name, text in (("bad.skel", "balljoint root { offset 0 0 }"), ("bad.bvh", "HIERARCHY\nROOT x {"),
                       ("bad.glb", "not a glb"), ("bad.gltf", "{"), ("bad.skin", "positions 1 {")):
        (tmp_path / name).write_text(text)
        with pytest.raises(FormatError):
            import_file(doc, tmp_path / name)
        assert doc.state() == before


def test_export_gltf_round_trip(shared_data, tmp_path):
    doc, _stack, result, _ = _imported(shared_data / "cse169" / "wasp_walk" / "wasp.skel")
    aid = result.asset_id
    set_parameters(doc, {"frame_end": 60})
    out = tmp_path / "wasp.glb"
    export, warned = export_gltf(doc, aid, out)
    assert warned == [] or all("influences" in w for w in warned)
    scene = import_gltf(out)
    for frame in (0, 17, 60):
        t = doc.frame_to_time(frame)
        ours, _ = skinned_mesh(doc, aid, t)
        theirs = scene.skinned_positions(0, t - doc.frame_to_time(doc.frame_range[0]))
        size = np.linalg.norm(np.ptp(ours, axis=0))
        assert np.abs(ours - theirs).max() <= 1e-4 * size
    # and back in through the importer
    doc2, _s, r2, _ = _imported(out)
    for frame in (0, 30):
        t = doc.frame_to_time(frame)
        a = skinned_mesh(doc, aid, t)[0]
        b = skinned_mesh(doc2, r2.asset_id, t)[0]
        assert np.abs(a - b).max() <= 1e-4 * np.linalg.norm(np.ptp(a, axis=0))


def test_export_without_skin_is_an_error(shared_data, tmp_path):
    doc, _stack, result, _ = _imported(shared_data / "bvh" / "fairmotion_sinusoidal.bvh")
    with pytest.raises(ValueError, match="no skin"):
        export_gltf(doc, result.asset_id, tmp_path / "x.glb")


def test_gltf_skin_with_two_root_joints_and_a_scaled_parent():
    from qtanimator.core.skinning import skin_positions
    from qtanimator.formats.gltf import (
        GltfAnimation,
        GltfAnimationChannel,
        GltfMesh,
        GltfNode,
        GltfPrimitive,
        GltfSampler,
        GltfScene,
        GltfSkin,
        quaternion_to_matrix,
    )

    half = np.sqrt(0.5)
    nodes = [GltfNode("armature", [1, 2], scale=np.array([2.0, 2.0, 2.0])),
             GltfNode("left", [], 0, translation=np.array([1.0, 0, 0])),
             GltfNode("right", [], 0, translation=np.array([-1.0, 0, 0]), rotation=np.array([0, 0, half, half])),
             GltfNode("body", mesh=0, skin=0)]
    positions = np.array([[2.0, 0, 0], [2.0, 1, 0], [-2.0, 0, 0], [-2.0, 1, 0]])
    joints = np.array([[0, 0, 0, 0], [0, 0, 0, 0], [1, 0, 0, 0], [1, 0, 0, 0]])
    weights = np.array([[1.0, 0, 0, 0]] * 4)
    world = GltfScene(nodes=nodes, roots=[0, 3]).world_matrices()
    ibm = np.linalg.inv(world[[1, 2]])
    prim = GltfPrimitive(positions, np.array([[0, 1, 2], [1, 3, 2]]), joints=joints, weights=weights)
    q = np.array([[0, 0, 0, 1.0], [half, 0, 0, half]])
    anim = GltfAnimation([GltfSampler(np.array([0.0, 1.0]), q)], [GltfAnimationChannel(0, 1, "rotation")])
    scene = GltfScene(nodes=nodes, meshes=[GltfMesh([prim])], skins=[GltfSkin([1, 2], ibm)],
                      animations=[anim], roots=[0, 3])
    assert np.allclose(quaternion_to_matrix(q[1])[:3, :3] @ [0, 1, 0], [0, 0, 1])
    g = character_from_gltf(scene)
    ch = g.character
    skel = ch.skeleton
    # The still, scaled armature above both roots is the placement; the roots stay roots.
    assert [j.name for j in skel.joints] == ["left", "right"]
    assert [j.parent for j in skel.joints] == [None, None]
    assert np.allclose(skel.placement, np.diag([2.0, 2.0, 2.0, 1.0]))
    assert np.allclose(skin_positions(ch.skin, ch.skinning_world(skel.world_matrices())),
                       scene.skinned_positions(0, None))
    doc = Document()
    channels = {f"two/{rel}": c for rel, c in ch.clips[0].channels.items()}
    UndoStack(doc).push(AddAsset(Asset("two", ASSET_KIND, None, {"clip": ch.clips[0].name}), ch, channels))
    for t in (0.0, 0.3, 0.35, 0.5, 1.0):
        ref = scene.skinned_positions(0, t)
        assert np.allclose(skinned_mesh(doc, "two", t)[0], ref, atol=1e-12), t
