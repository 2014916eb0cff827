"""glTF export round trip (issue 21) and the Khronos validator (issue 15).

Importing a file, exporting it with ``import3d.export_gltf`` and importing the export gives the
same character back: the same parts (vertex counts, triangles, skinned flag, colour, texture
coordinates), the same clips (names and ``(start, end)``), the same rest pose (joint names and
rest world matrices, the placement included) and the same skinned positions and normals at every
key time of every clip and 1/4, 1/2 and 3/4 of the way between keys (where the export had to
sample, at the sample times). Every export passes the Khronos glTF validator with no error; its
warnings are reported as test warnings.

Cases: the shared samples (CesiumMan, RiggedFigure, RiggedSimple, SimpleSkin), the generated rows
of ``tests/gltf_gen.py`` (several meshes, a rigid mesh, several clips, cubic and stepped keys,
scale keys, two moving roots, nodes above the skeleton, unnamed joints), a course character
(wasp) and MIT Model1 (up to 13 influences a vertex, all kept).
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import gltf_gen
import gltf_validator
import numpy as np
import pytest
from docfix import set_parameters

from qtanimator.core.channel import Channel, Interpolation, Key
from qtanimator.core.skinning import Skin, skin_positions
from qtanimator.document import Document, SetChannels, UndoStack
from qtanimator.document.character3d import (
    QUAT_DOFS,
    MeshPart,
    character,
    clip_channels_of,
    clip_duration,
    set_clip_command,
    set_dofs_command,
    skinned_mesh,
    world_matrices,
)
from qtanimator.document.gltf_skeleton_export import export_character_glb
from qtanimator.document.import3d import export_gltf, import_file
from qtanimator.formats.gltf import import_gltf

#: Positions may differ by this fraction of the model's size (the rest mesh's bounding-box diagonal).
TOLERANCE = 1e-6
#: At most this many comparison times per clip.
MAX_TIMES = 40
SAMPLES = ("CesiumMan.glb", "RiggedFigure.glb", "RiggedSimple.glb", "SimpleSkin.gltf")
GENERATORS = {make.__name__: make for make in gltf_gen.ROWS}


# --------------------------------------------------------------------------- helpers
def _import(path: Path) -> tuple[Document, UndoStack, str]:
    doc = Document()
    stack = UndoStack(doc)
    imp = import_file(doc, path)
    stack.push(imp.command)
    return doc, stack, imp.asset_id


def _validated(path: Path) -> None:
    """The Khronos validator finds no error; its warnings become test warnings."""
    report = gltf_validator.validate(path)
    assert not report.errors, f"{path.name}: " + "; ".join(str(e) for e in report.errors[:10])
    for issue in report.warnings:
        warnings.warn(f"glTF validator {report.version}, {path.name}: {issue}", stacklevel=2)


def _export(doc: Document, aid: str, out: Path) -> tuple[list[str], Document, UndoStack, str]:
    """Export, validate, import the export: (messages, document, undo stack, asset id)."""
    _result, messages = export_gltf(doc, aid, out)
    _validated(out)
    return (messages, *_import(out))


def _size(doc: Document, aid: str) -> float:
    skin = character(doc, aid).skin
    assert skin is not None
    return float(np.linalg.norm(np.ptp(skin.positions, axis=0)))


def _key_times(doc: Document, aid: str, clip: str) -> np.ndarray:
    start, end = clip_duration(doc, aid, clip)
    keys = [c.times for c in clip_channels_of(doc, aid, clip).values() if c.keys]
    return np.unique(np.concatenate([[start, end], *keys]))


def _times(doc: Document, aid: str, clip: str, grid_fps: float | None = None) -> np.ndarray:
    """Key times and the points 1/4, 1/2 and 3/4 between them; with ``grid_fps`` (a clip the
    export sampled), key times and the sample grid instead. At most MAX_TIMES, evenly thinned."""
    keys = _key_times(doc, aid, clip)
    if grid_fps is None:
        extra = [keys[:-1] + f * np.diff(keys) for f in (0.25, 0.5, 0.75)]
    else:
        extra = [keys[0] + np.arange(int((keys[-1] - keys[0]) * grid_fps + 1e-9) + 1) / grid_fps]
    times = np.unique(np.concatenate([keys, *extra]))
    if len(times) > MAX_TIMES:
        times = times[np.unique(np.linspace(0, len(times) - 1, MAX_TIMES).round().astype(int))]
    return times


def _assert_same_rest_pose(a: Document, aid: str, b: Document, bid: str, ordered: bool = True) -> None:
    ska, skb = character(a, aid).skeleton, character(b, bid).skeleton
    if ordered:
        assert ska.names == skb.names
    assert sorted(ska.names) == sorted(skb.names)
    wa = dict(zip(ska.names, ska.world_matrices()))
    wb = dict(zip(skb.names, skb.world_matrices()))
    size = _size(a, aid)
    for name, m in wa.items():
        assert np.abs(m[:3, :3] - wb[name][:3, :3]).max() <= 1e-6, f"joint {name}: rest rotation / scale"
        assert np.abs(m[:3, 3] - wb[name][:3, 3]).max() <= TOLERANCE * size, f"joint {name}: rest position"


def _assert_same_parts(a: Document, aid: str, b: Document, bid: str) -> None:
    ca, cb = character(a, aid), character(b, bid)
    sa, sb = ca.skin, cb.skin
    assert sa is not None and sb is not None
    # A course character's skin is one mesh (no parts): it comes back as one part named as the asset.
    parts_a = ca.parts or [MeshPart(aid, 0, sa.num_vertices, 0, len(sa.triangles))]
    assert [(p.name, p.count, p.triangle_count, p.skinned) for p in parts_a] == \
           [(p.name, p.count, p.triangle_count, p.skinned) for p in cb.parts]
    for pa, pb in zip(parts_a, cb.parts):
        np.testing.assert_allclose(pa.color, pb.color, atol=1e-7, err_msg=pa.name)
        ta = sa.triangles[pa.triangle_start:pa.triangle_start + pa.triangle_count] - pa.start
        tb = sb.triangles[pb.triangle_start:pb.triangle_start + pb.triangle_count] - pb.start
        np.testing.assert_array_equal(ta, tb, err_msg=pa.name)
    assert (sa.texcoords is None) == (sb.texcoords is None)
    if sa.texcoords is not None and sb.texcoords is not None:
        np.testing.assert_allclose(sa.texcoords, sb.texcoords, atol=1e-7)


def _assert_same_motion(a: Document, aid: str, b: Document, bid: str, times: np.ndarray, what: str,
                        shift: float = 0.0) -> None:
    """Skinned positions (and normals) of ``a`` at ``times`` and of ``b`` at ``times − shift``."""
    limit = TOLERANCE * _size(a, aid)
    for t in times:
        pa, na = skinned_mesh(a, aid, float(t))
        pb, nb = skinned_mesh(b, bid, float(t - shift))
        err = float(np.abs(pa - pb).max())
        assert err <= limit, f"{what} t={t:.4f}: positions off by {err:.3g} (limit {limit:.3g})"
        assert float(np.abs(na - nb).max()) <= 1e-5, f"{what} t={t:.4f}: normals"


def _assert_round_trip(a: Document, sa: UndoStack, aid: str, b: Document, sb: UndoStack, bid: str,
                       sampled: frozenset[str] = frozenset()) -> None:
    _assert_same_parts(a, aid, b, bid)
    _assert_same_rest_pose(a, aid, b, bid)
    clips = [c.name for c in character(a, aid).clips]
    assert [c.name for c in character(b, bid).clips] == clips
    for name in clips:
        assert clip_duration(b, bid, name) == pytest.approx(clip_duration(a, aid, name), abs=1e-7), name
        sa.push(set_clip_command(a, aid, name))
        sb.push(set_clip_command(b, bid, name))
        grid = a.fps if name in sampled else None
        _assert_same_motion(a, aid, b, bid, _times(a, aid, name, grid), f"clip {name!r}")


# --------------------------------------------------------------------------- cases
@pytest.fixture(scope="module")
def generated(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("gltf_roundtrip")
    return {name: make(folder) for name, make in GENERATORS.items()}


@pytest.mark.parametrize("name", SAMPLES)
def test_samples_round_trip(shared_data: Path, tmp_path: Path, name: str) -> None:
    a, sa, aid = _import(shared_data / "gltf" / name)
    messages, b, sb, bid = _export(a, aid, tmp_path / "out.glb")
    assert messages == []
    _assert_round_trip(a, sa, aid, b, sb, bid)


@pytest.mark.parametrize("name", sorted(GENERATORS))
def test_generated_round_trip(generated: dict[str, Path], tmp_path: Path, name: str) -> None:
    a, sa, aid = _import(generated[name])
    messages, b, sb, bid = _export(a, aid, tmp_path / "out.glb")
    assert messages == []
    _assert_round_trip(a, sa, aid, b, sb, bid)


def test_export_structure(generated: dict[str, Path], tmp_path: Path) -> None:
    """One mesh per glTF mesh node, the rigid hat on its joint's node without a skin, skinned
    meshes on nodes at the scene root, every clip an animation with its keys as they were."""
    a, _sa, aid = _import(generated["three_meshes_and_rigid"])
    export_gltf(a, aid, tmp_path / "out.glb")
    scene = import_gltf(tmp_path / "out.glb")
    assert [m.name for m in scene.meshes] == ["hands", "body", "head", "hat"]
    assert [len(m.primitives) for m in scene.meshes] == [2, 2, 1, 1]
    hat = next(n for n in scene.nodes if n.mesh == 3)
    assert hat.name == "hat" and hat.skin is None and hat.parent is not None
    assert scene.nodes[hat.parent].name == "head"
    for node in scene.nodes:
        if node.skin is not None:
            assert node.parent is None and node.mesh is not None
    names = {n.name for n in scene.nodes}
    assert {"pelvis", "chest", "neck", "head", "arm_l", "hand_l", "arm_r", "hand_r", "hat"} <= names
    (anim,) = scene.animations
    assert anim.name == "wave" and {s.interpolation for s in anim.samplers} == {"LINEAR"}
    source = import_gltf(generated["three_meshes_and_rigid"])
    assert sorted(len(s.times) for s in anim.samplers) == sorted(len(s.times) for s in source.animations[0].samplers)

    a, _sa, aid = _import(generated["cubic_and_step"])
    export_gltf(a, aid, tmp_path / "cubic.glb")
    anim = import_gltf(tmp_path / "cubic.glb").animations[0]
    assert sorted(s.interpolation for s in anim.samplers) == ["CUBICSPLINE", "CUBICSPLINE", "CUBICSPLINE", "STEP"]


def test_parent_above_skeleton_keeps_its_placement(generated: dict[str, Path], tmp_path: Path) -> None:
    a, _sa, aid = _import(generated["parent_above_skeleton"])
    _m, b, _sb, bid = _export(a, aid, tmp_path / "out.glb")
    pa, pb = character(a, aid).skeleton.placement, character(b, bid).skeleton.placement
    assert pa is not None and pb is not None
    np.testing.assert_allclose(pb, gltf_gen.PARENT_ABOVE_PLACEMENT, atol=1e-7)


# --------------------------------------------------------------------------- edits
def test_edited_clips_round_trip(generated: dict[str, Path], tmp_path: Path) -> None:
    """Edits of the active clip and of a clip left (kept in clip_store) are exported; a
    translation keyed on one component only cannot stay exact: sampled, and said so."""
    a, sa, aid = _import(generated["three_animations"])
    skel = character(a, aid).skeleton
    spine, root = skel.index_of("spine"), skel.index_of("root")
    sa.push(set_dofs_command(a, aid, {(spine, "z"): 0.3}, 0.25))  # idle: a quaternion key, LINEAR
    sa.push(set_clip_command(a, aid, "run"))
    sa.push(set_dofs_command(a, aid, {(root, "tx"): 0.5}, 0.5))  # run: tx only
    messages, b, sb, bid = _export(a, aid, tmp_path / "out.glb")
    assert len(messages) == 1 and messages[0].startswith("run: ") and "root translation" in messages[0], messages
    assert "different times" in messages[0]
    _assert_round_trip(a, sa, aid, b, sb, bid, sampled=frozenset({"run"}))


def _replace(stack: UndoStack, doc: Document, changes: dict[str, Channel]) -> None:
    stack.push(SetChannels("edit", {cid: (doc.channels.get(cid), c) for cid, c in changes.items()}))


@pytest.mark.parametrize("edit", ["mixed interpolation", "different times"])
def test_quaternion_keys_glTF_cannot_hold_are_sampled(generated: dict[str, Path], tmp_path: Path,
                                                      edit: str) -> None:
    a, sa, aid = _import(generated["cubic_and_step"])
    ids = [f"{aid}/lower/{d}" for d in QUAT_DOFS]
    chans = [a.channels[cid] for cid in ids]
    if edit == "mixed interpolation":  # the second span of all four becomes linear
        new = [c.with_keys([k if i != 1 else Key(k.time, k.value, k.in_tangent, k.out_tangent, k.in_slope,
                                                  k.out_slope, Interpolation.LINEAR)
                            for i, k in enumerate(c.keys)]) for c in chans]
    else:  # qx loses a key
        new = [c.remove_keys([2]) if d == "qx" else c for c, d in zip(chans, QUAT_DOFS)]
    _replace(sa, a, dict(zip(ids, new)))
    messages, b, sb, bid = _export(a, aid, tmp_path / "out.glb")
    why = "its components are keyed at different times" if edit == "different times" else edit
    assert messages == [f"spline: glTF cannot hold the keys of lower rotation ({why}) as they are: sampled at 60 fps."]
    _assert_round_trip(a, sa, aid, b, sb, bid, sampled=frozenset({"spline"}))


@pytest.mark.parametrize("case", ["one key and no keys", "cubic keys inside the clip"])
def test_clips_keep_their_length(generated: dict[str, Path], tmp_path: Path, case: str) -> None:
    """A clip whose keys do not reach its start or end (one key; none at all; cubic keys well
    inside) keeps its length: a key holding the end value is added there, changing nothing."""
    if case == "one key and no keys":
        a, sa, aid = _import(generated["three_animations"])
        _replace(sa, a, {cid: c.with_keys(c.keys[:1]) for cid, c in a.channels_of(aid)})  # idle
        sa.push(set_clip_command(a, aid, "run"))
        sa.push(SetChannels("clear", {cid: (c, None) for cid, c in list(a.channels_of(aid))}))
    else:
        a, sa, aid = _import(generated["cubic_and_step"])
        sa.push(SetChannels("tip only", {cid: (c, None) for cid, c in list(a.channels_of(aid))
                                         if not cid.startswith(f"{aid}/tip/")}))
        assert _key_times(a, aid, "spline").tolist() == pytest.approx([0.0, 0.3, 1.7, 2.0])
    messages, b, sb, bid = _export(a, aid, tmp_path / "out.glb")
    assert messages == []
    _assert_round_trip(a, sa, aid, b, sb, bid)


def test_keys_before_time_zero_shift_the_clip(generated: dict[str, Path], tmp_path: Path) -> None:
    a, sa, aid = _import(generated["three_animations"])
    ids = [f"{aid}/spine/{d}" for d in QUAT_DOFS]
    _replace(sa, a, {cid: a.channels[cid].with_keys([k.moved(k.time - 0.5, k.value) for k in a.channels[cid].keys])
                     for cid in ids})
    assert clip_duration(a, aid, "idle") == (-0.5, 1.0)
    messages, b, _sb, bid = _export(a, aid, tmp_path / "out.glb")
    assert messages == ["idle: keys before time 0, which glTF cannot hold: the clip starts at 0."]
    _assert_same_motion(a, aid, b, bid, _times(a, aid, "idle"), "idle", shift=-0.5)


def test_one_joint_through_two_slots_gets_a_helper_node(tmp_path: Path) -> None:
    """A merged skin whose palette binds a joint through two slots with different inverse bind
    matrices: a mesh using both gets a helper node below the joint for the second, and a mesh
    whose slot clashes with the first skin's gets a second skin. Positions survive."""
    from qtanimator.core.skeleton import Joint, Skeleton
    from qtanimator.core.skinning import SkinBinding
    from qtanimator.document import AddAsset, Asset
    from qtanimator.document.character3d import ASSET_KIND, CLIP, Character3D, ClipSource

    skeleton = Skeleton([Joint("root", None, quaternion=True),
                         Joint("child", 0, translation=[0.0, 1.0, 0.0], quaternion=True)], dialect="gltf")
    world = skeleton.world_matrices()
    shifted = np.eye(4)
    shifted[:3, 3] = [0.2, 0.0, 0.1]
    ibm = np.array([np.linalg.inv(world[0]), np.linalg.inv(world[1]), shifted @ np.linalg.inv(world[1]),
                    shifted @ np.linalg.inv(world[0])])
    positions = np.array([[0, 0, 0], [0.3, 1.0, 0], [0, 1.5, 0], [1, 0, 0], [1, 1, 0], [1.5, 1.2, 0.0]])
    binding = SkinBinding([0, 1, 1, 2, 3, 4, 4, 5], [0, 1, 2, 2, 3, 3, 1, 1], [1, 0.5, 0.5, 1, 1, 0.4, 0.6, 1], 6, 4)
    skin = Skin(positions, np.array([[0, 1, 2], [3, 4, 5]]), binding, ibm, normals=np.tile([0.0, 0.0, 1.0], (6, 1)))
    parts = [MeshPart("a", 0, 3, 0, 1), MeshPart("b", 3, 3, 1, 1, color=(0.9, 0.2, 0.1, 1.0))]
    half = np.sqrt(0.5)
    keys = {"child/qw": [1.0, half], "child/qx": [0.0, 0.0], "child/qy": [0.0, 0.0], "child/qz": [0.0, half]}
    channels = {rel: Channel([Key(t, v, "linear", "linear", interpolation="linear") for t, v in zip((0.0, 1.0), vs)])
                for rel, vs in keys.items()}
    ch = Character3D(skeleton, skin, parts=parts, clips=[ClipSource("bend", 0.0, 1.0, channels)],
                     palette=np.array([0, 1, 1, 0]))
    a = Document()
    sa = UndoStack(a)
    sa.push(AddAsset(Asset("x", ASSET_KIND, str(tmp_path / "x.glb"), {CLIP: "bend"}), ch,
                     {f"x/{rel}": c for rel, c in channels.items()}))
    messages, b, _sb, bid = _export(a, "x", tmp_path / "out.glb")
    assert messages == []
    scene = import_gltf(tmp_path / "out.glb")
    assert [[scene.nodes[j].name for j in s.joints] for s in scene.skins] == [["root", "child", "child.slot2"],
                                                                               ["child", "root"]]
    assert character(b, bid).skeleton.names == ["root", "child", "child.slot2"]
    _assert_same_motion(a, "x", b, bid, np.linspace(0.0, 1.0, 9), "bend")


def test_a_gltf_character_in_euler_mode_is_sampled(generated: dict[str, Path], tmp_path: Path) -> None:
    """Rotations keyed as Euler angles (the rotation mode) are sampled like a course file's,
    without a message; the samples come back exactly."""
    from qtanimator.document.character3d import set_rotation_mode_command

    a, sa, aid = _import(generated["three_animations"])
    sa.push(set_rotation_mode_command(a, aid, "euler"))
    messages, b, sb, bid = _export(a, aid, tmp_path / "out.glb")
    assert messages == []
    _assert_round_trip(a, sa, aid, b, sb, bid, sampled=frozenset({"idle", "walk", "run"}))


# --------------------------------------------------------------------------- course files
def test_course_character_exports_and_validates(shared_data: Path, tmp_path: Path) -> None:
    """wasp.skel (+ .skin, .anim): Euler joints and the root translation are sampled at the
    document's fps over its frame range (time 0 at its start); the samples come back exactly."""
    a, _sa, aid = _import(shared_data / "cse169" / "wasp_walk" / "wasp.skel")
    set_parameters(a, {"frame_start": 6, "frame_end": 120})
    result, messages = export_gltf(a, aid, tmp_path / "wasp.glb")
    assert messages == []
    _validated(tmp_path / "wasp.glb")
    b, _sb, bid = _import(tmp_path / "wasp.glb")
    _assert_same_parts(a, aid, b, bid)
    _assert_same_rest_pose(a, aid, b, bid)
    start = a.frame_to_time(6)
    assert [(c.name, c.start, c.end) for c in character(b, bid).clips] == [(aid, 0.0, pytest.approx(2.0 - start))]
    times = result.times[np.unique(np.linspace(0, len(result.times) - 1, MAX_TIMES).round().astype(int))]
    _assert_same_motion(a, aid, b, bid, times + start, "wasp", shift=start)


def test_mit_model_keeps_every_influence(shared_data: Path, tmp_path: Path) -> None:
    """Model1 binds vertices to up to 13 joints: all are written (JOINTS_0..3), so the round
    trip moves every vertex as the document does once the weights are divided by their sums
    (which glTF requires; the export says how far that moves the mesh)."""
    a, sa, aid = _import(shared_data / "mit6837" / "Model1.skel")
    sa.push(set_dofs_command(a, aid, {(j, "x"): 0.6 for j in range(1, 10)}, 0.5))
    set_parameters(a, {"frame_end": 30})
    result, messages = export_gltf(a, aid, tmp_path / "model1.glb")
    assert len(messages) == 1 and "do not sum to 1" in messages[0]
    _validated(tmp_path / "model1.glb")
    ch = character(a, aid)
    assert ch.skin is not None
    prim = import_gltf(tmp_path / "model1.glb").meshes[0].primitives[0]
    assert prim.joints is not None and prim.joints.shape[1] == 16
    b, _sb, bid = _import(tmp_path / "model1.glb")
    _assert_same_rest_pose(a, aid, b, bid, ordered=False)  # MIT joints are not in depth-first order
    back = character(b, bid).skin
    assert back is not None and back.binding.max_influences == ch.skin.binding.max_influences == 13
    normalised = Skin(ch.skin.positions, ch.skin.triangles, ch.skin.binding.renormalized(),
                      ch.skin.inverse_bind_matrices)
    size = _size(a, aid)
    for t in (0.0, 0.25, 0.5):
        assert t in result.times
        want = skin_positions(normalised, ch.skinning_world(world_matrices(a, aid, t)))
        got = skinned_mesh(b, bid, t)[0]
        assert np.abs(got - want).max() <= TOLERANCE * size, t
        assert np.abs(got - skinned_mesh(a, aid, t)[0]).max() <= 1e-3 * size, t


# --------------------------------------------------------------------------- validator
def test_course_exports_of_the_format_api_validate(shared_data: Path, tmp_path: Path) -> None:
    """export_character_glb (one skeleton, one skin, .anim channels) passes the validator too."""
    from qtanimator.formats.anim import load_anim
    from qtanimator.formats.skel import load_skel
    from qtanimator.formats.skin import load_skin

    d = shared_data / "cse169" / "wasp_walk"
    skeleton, skin, clip = load_skel(d / "wasp.skel"), load_skin(d / "wasp.skin"), load_anim(d / "wasp_walk.anim")
    for interpolation in ("LINEAR", "CUBICSPLINE"):
        out = tmp_path / f"wasp_{interpolation}.glb"
        export_character_glb(out, skeleton, skin, clip, clip.start, clip.end, 30, interpolation=interpolation)
        _validated(out)


def test_the_validator_reports_errors(tmp_path: Path) -> None:
    """The helper does report a broken file (so the checks above are not vacuous)."""
    bad = tmp_path / "bad.gltf"
    bad.write_text(json.dumps({"asset": {"version": "2.0"}, "nodes": [{"mesh": 3}], "scenes": [{"nodes": [0]}]}))
    errors, _warnings = gltf_validator.issues(bad)
    assert any(e.code == "UNRESOLVED_REFERENCE" for e in errors), errors
