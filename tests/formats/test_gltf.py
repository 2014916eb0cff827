"""glTF 2.0: Khronos samples import, character export checked by importing it back, GLB
structure, and bad input (FormatError only)."""

from __future__ import annotations

import base64
import copy
import json
import struct
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from qtanimator.core.channel import Channel, Key
from qtanimator.core.clip import apply_clip, channel_index
from qtanimator.core.skeleton import Skeleton
from qtanimator.core.skinning import Skin, SkinBinding, skin_positions
from qtanimator.document.gltf_skeleton_export import GltfExportWarning, export_character_glb
from qtanimator.formats import FormatError
from qtanimator.formats.anim import load_anim
from qtanimator.formats.attach import load_attach
from qtanimator.formats.glb import build_glb, read_glb
from qtanimator.formats.gltf import (
    GltfSampler,
    export_glb,
    glb_bytes,
    import_gltf,
    parse_gltf,
    summarize,
)
from qtanimator.formats.info import summarize as info_summarize
from qtanimator.formats.obj import load_obj
from qtanimator.formats.skel import load_skel
from qtanimator.formats.skin import load_skin

# name: vertices, triangles, joints, channels, keys per channel, first key, last key, renormalised
SAMPLES = {
    "SimpleSkin.gltf": (10, 8, 2, 1, 12, 0.0, 5.5, 0),
    "RiggedSimple.glb": (160, 188, 2, 3, 50, 0.0417, 2.0833, 0),
    "RiggedFigure.glb": (370, 256, 19, 57, 2, 0.0, 1.25, 31),
    "CesiumMan.glb": (3273, 4672, 19, 57, 49, 0.0, 2.0, 210),
}
COMPONENT_SIZE = {5120: 1, 5121: 1, 5122: 2, 5123: 2, 5125: 4, 5126: 4}
COMPONENT_DTYPE = {5121: "u1", 5123: "<u2", 5125: "<u4", 5126: "<f4"}
TYPE_WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}


def _rel_err(got: np.ndarray, ref: np.ndarray) -> float:
    return float(np.abs(got - ref).max() / max(np.abs(ref).max(), 1e-12))


# ------------------------------------------------------------------ Khronos samples
@pytest.mark.parametrize("name", list(SAMPLES))
def test_khronos_samples_import(shared_data: Path, name: str) -> None:
    nv, nt, nj, nch, nkeys, first, last, renormalized = SAMPLES[name]
    scene = import_gltf(shared_data / "gltf" / name)
    assert len(scene.meshes) == 1 and len(scene.skins) == 1 and len(scene.animations) == 1
    mesh = scene.meshes[0]
    prim = mesh.primitives[0]
    assert mesh.num_vertices == nv and mesh.num_triangles == nt
    assert len(scene.skins[0].joints) == nj
    anim = scene.animations[0]
    assert len(anim.channels) == nch
    assert all(len(anim.samplers[c.sampler].times) == nkeys for c in anim.channels)
    assert {s.interpolation for s in anim.samplers} == {"LINEAR"}
    assert anim.start == pytest.approx(first, abs=1e-4) and anim.end == pytest.approx(last, abs=1e-4)
    assert prim.renormalized_vertices == renormalized
    assert prim.weights is not None and prim.joints is not None
    np.testing.assert_allclose(prim.weights.sum(axis=1), 1.0, atol=1e-6)
    skin = scene.to_skin(0)
    for t in np.linspace(first - 0.5, last + 0.5, 6):
        got = scene.skinned_positions(0, float(t))
        assert got.shape == (nv, 3) and np.isfinite(got).all()
        ref = skin_positions(skin, scene.joint_world_matrices(0, float(t)))
        np.testing.assert_allclose(got, ref, atol=1e-12)
    info = info_summarize(shared_data / "gltf" / name)
    assert info == summarize(shared_data / "gltf" / name)
    assert info["meshes"][0]["vertices"] == nv and info["skins"][0]["joints"] == nj


def test_simple_skin_by_hand(shared_data: Path) -> None:
    scene = import_gltf(shared_data / "gltf" / "SimpleSkin.gltf")
    rest = scene.meshes[0].primitives[0].positions
    np.testing.assert_allclose(scene.skinned_positions(0, 0.0), rest, atol=1e-7)  # identity key at 0
    # t = 1: joint 1 (at (0, 1, 0)) has turned 90° about z; vertex 8 (-0.5, 2) is bound to it alone.
    p = scene.skinned_positions(0, 1.0)
    np.testing.assert_allclose(p[8], [-1.0, 0.5, 0.0], atol=1e-6)
    np.testing.assert_allclose(p[0], rest[0], atol=1e-7)  # bound to joint 0, which does not move
    # Vertex 4 is half joint 0, half joint 1: the average of the two rigid positions.
    np.testing.assert_allclose(p[4], 0.5 * rest[4] + 0.5 * np.array([0.0, 0.5, 0.0]), atol=1e-6)


def test_rigged_simple_clamps_before_first_key_and_mixes_matrix_and_trs(shared_data: Path) -> None:
    scene = import_gltf(shared_data / "gltf" / "RiggedSimple.glb")
    names = [n.name for n in scene.nodes]
    assert names == ["Z_UP", "Armature", "Cylinder", "Bone", "Bone.001"]
    assert scene.nodes[3].matrix is not None and scene.nodes[4].matrix is None
    assert scene.skins[0].joints == [3, 4] and scene.skins[0].skeleton == 3
    first = scene.animations[0].start
    np.testing.assert_array_equal(scene.skinned_positions(0, 0.0), scene.skinned_positions(0, first))
    assert not np.allclose(scene.skinned_positions(0, 1.0), scene.skinned_positions(0, first), atol=1e-3)


def test_step_and_cubic_spline_samplers(shared_data: Path) -> None:
    doc = _simple(shared_data)
    doc["animations"][0]["samplers"][0]["interpolation"] = "STEP"
    scene = _parse_doc(doc)
    sampler = scene.animations[0].samplers[0]
    np.testing.assert_array_equal(sampler.evaluate(0.99, rotation=True), sampler.values[1])
    np.testing.assert_array_equal(scene.skinned_positions(0, 0.75), scene.skinned_positions(0, 0.5))
    # CUBICSPLINE with zero tangents: smoothstep between the keys, renormalised.
    linear = _parse_doc(_simple(shared_data)).animations[0].samplers[0]
    cubic = GltfSampler(linear.times, np.stack([np.zeros_like(linear.values), linear.values,
                                                np.zeros_like(linear.values)], axis=1), "CUBICSPLINE")
    q = cubic.evaluate(0.25, rotation=True)
    mid = linear.values[0] + 0.5 * (linear.values[1] - linear.values[0])  # smoothstep(0.5) = 0.5
    np.testing.assert_allclose(q, mid / np.linalg.norm(mid), atol=1e-12)
    np.testing.assert_allclose(cubic.evaluate(-1.0), linear.values[0])
    np.testing.assert_allclose(cubic.evaluate(99.0), linear.values[-1])


def test_renormalised_weights_keep_the_figure_upright(shared_data: Path) -> None:
    scene = import_gltf(shared_data / "gltf" / "CesiumMan.glb")
    p = scene.skinned_positions(0, 0.0)
    # Y-up after the Z-up root; feet on the ground, head about 1.5 high.
    assert -0.05 < p[:, 1].min() < 0.05 and 1.3 < p[:, 1].max() < 1.6
    image = scene.images[0]
    assert image.mime_type == "image/jpeg" and image.data is not None and image.data[:2] == b"\xff\xd8"
    assert scene.meshes[0].primitives[0].texcoords is not None


@pytest.mark.parametrize("name", list(SAMPLES))
def test_khronos_samples_round_trip_through_export_glb(shared_data: Path, tmp_path: Path, name: str) -> None:
    scene = import_gltf(shared_data / "gltf" / name)
    out = tmp_path / "copy.glb"
    export_glb(out, scene)
    back = import_gltf(out)
    _check_glb_structure(out.read_bytes())
    anim = scene.animations[0]
    for t in np.linspace(anim.start, anim.end, 5):
        ref = scene.skinned_positions(0, float(t))
        assert _rel_err(back.skinned_positions(0, float(t)), ref) < 1e-6
    assert len(back.images) == len(scene.images)
    assert [im.data for im in back.images] == [im.data for im in scene.images]


# ------------------------------------------------------------------ character export
def _wasp(shared_data: Path, skin_name: str) -> tuple[Skeleton, Skin, Any]:
    d = shared_data / "cse169" / "wasp_walk"
    return load_skel(d / "wasp.skel"), load_skin(d / skin_name), load_anim(d / "wasp_walk.anim")


def _cpu_positions(skeleton: Skeleton, skin: Skin, channels: Any, t: float) -> np.ndarray:
    posed = skeleton.copy()
    apply_clip(posed, channels, t)
    return skin_positions(skin, posed.world_matrices())


@pytest.mark.parametrize("skin_name", ["wasp.skin", "wasp_4weights.skin"])
def test_wasp_walk_export_matches_cpu_skinning(shared_data: Path, tmp_path: Path, skin_name: str) -> None:
    skeleton, skin, clip = _wasp(shared_data, skin_name)
    out = tmp_path / "wasp.glb"
    with warnings.catch_warnings():
        warnings.simplefilter("error", GltfExportWarning)
        result = export_character_glb(out, skeleton, skin, clip, clip.start, clip.end, 30)
    assert len(result.dropped_vertices) == 0 and result.max_relative_error == 0.0
    assert len(result.times) >= 121 and result.times[0] == 0.0 and result.times[-1] == 4.0
    back = import_gltf(out)
    assert [back.nodes[j].name for j in back.skins[0].joints] == skeleton.names
    np.testing.assert_allclose(back.skins[0].inverse_bind_matrices, skin.inverse_bind_matrices, atol=1e-6)
    for t in (0.0, 7 / 30, 1.0, 61 / 30, 2.5, 4.0):
        ref = _cpu_positions(skeleton, skin, clip, t)
        assert _rel_err(back.skinned_positions(0, t - clip.start), ref) < 1e-4
    _check_glb_structure(out.read_bytes())


def test_wasp_cubic_spline_export_follows_the_channels_between_samples(shared_data: Path, tmp_path: Path) -> None:
    skeleton, skin, clip = _wasp(shared_data, "wasp.skin")
    out = tmp_path / "wasp_cubic.glb"
    export_character_glb(out, skeleton, skin, clip, 0.0, 4.0, 30, interpolation="CUBICSPLINE")
    back = import_gltf(out)
    assert {s.interpolation for s in back.animations[0].samplers} == {"CUBICSPLINE"}
    # hip_03_r cycles with different first and last values: it jumps right after t = 2 and
    # at t = 4, and a spline blends a jump over one sample interval; leave those out.
    times = [t for t in np.linspace(0.013, 3.95, 29) if not 2.0 <= t <= 2.0 + 1 / 30]
    for t in times:
        ref = _cpu_positions(skeleton, skin, clip, float(t))
        assert _rel_err(back.skinned_positions(0, float(t)), ref) < 1e-4


def _mit_clip(num_joints: int) -> list[Channel | None]:
    chans: list[Channel | None] = [None] * (3 + 3 * num_joints)

    def ch(*keys: tuple[float, float]) -> Channel:
        return Channel([Key(t, v) for t, v in keys])

    chans[channel_index(4, "x")] = ch((0, 0), (1, 0.3))
    chans[channel_index(4, "y")] = ch((0, 0), (1, -0.5))
    chans[channel_index(4, "z")] = ch((0, 0), (1, 0.7))
    chans[channel_index(14, "z")] = ch((0, 0), (0.5, 0.6), (1, 1.2))
    chans[channel_index(-1, "y")] = ch((0, 0), (1, 0.1))
    return chans


def test_mit_model_export_keeps_four_influences_and_warns(shared_data: Path, tmp_path: Path) -> None:
    d = shared_data / "mit6837"
    skeleton = load_skel(d / "Model1.skel")
    mesh = load_obj(d / "Model1.obj")
    weights = load_attach(d / "Model1.attach", mesh.num_vertices, len(skeleton.joints))
    chans = _mit_clip(len(skeleton.joints))
    out = tmp_path / "model1.glb"
    with pytest.warns(GltfExportWarning, match="strongest 4"):
        result = export_character_glb(out, skeleton, (mesh, weights), chans, 0.0, 1.0, 24)
    counts = (weights > 0).sum(axis=1)
    np.testing.assert_array_equal(result.dropped_vertices, np.flatnonzero(counts > 4))
    assert result.max_relative_error > 1e-4
    back = import_gltf(out)
    prim = back.meshes[0].primitives[0]
    assert prim.joints is not None and prim.weights is not None and prim.joints.shape[1] == 4
    skin = Skin.from_bind_matrices(mesh.positions, mesh.triangles, SkinBinding.from_dense(weights),
                                   skeleton.bind_world_matrices())
    keep = counts <= 4
    sums = weights.sum(axis=1)
    for t in (0.0, 0.25, 12 / 24, 1.0):
        # The export renormalises: with no influence dropped, that is our skinning / Σw.
        ref = _cpu_positions(skeleton, skin, chans, t) / sums[:, None]
        got = back.skinned_positions(0, t)
        assert _rel_err(got[keep], ref[keep]) < 1e-4
        # The regression pose of the notes: R hip (0.3, -0.5, 0.7) moves the R foot there.
    posed = skeleton.copy()
    apply_clip(posed, chans, 1.0)
    np.testing.assert_allclose(back.world_matrices(1.0)[7, :3, 3], posed.world_matrices()[7, :3, 3], atol=1e-6)
    posed.root_translation[:] = 0
    np.testing.assert_allclose(posed.world_matrices()[7, :3, 3], [0.64567, 0.10592, 0.49948], atol=1e-5)
    _check_glb_structure(out.read_bytes())


def _check_glb_structure(data: bytes) -> None:
    magic, version, length = struct.unpack_from("<4sII", data, 0)
    assert (magic, version, length) == (b"glTF", 2, len(data))
    json_len, json_type = struct.unpack_from("<II", data, 12)
    assert json_type == 0x4E4F534A and json_len % 4 == 0
    text = data[20:20 + json_len]
    stripped = text.rstrip(b" ")
    assert len(text) - len(stripped) < 4
    doc = json.loads(stripped)
    assert doc["asset"]["version"] == "2.0"
    offset = 20 + json_len
    bin_len, bin_type = struct.unpack_from("<II", data, offset)
    assert bin_type == 0x004E4942 and bin_len % 4 == 0 and offset + 8 + bin_len == len(data)
    binary = data[offset + 8:]
    (buffer,) = doc["buffers"]
    assert "uri" not in buffer and buffer["byteLength"] <= bin_len < buffer["byteLength"] + 4
    assert set(binary[buffer["byteLength"]:]) <= {0}
    views = doc["bufferViews"]
    for v in views:
        assert v["byteOffset"] % 4 == 0 and v["byteOffset"] + v["byteLength"] <= buffer["byteLength"]
    for acc in doc["accessors"]:
        v = views[acc["bufferView"]]
        size = COMPONENT_SIZE[acc["componentType"]]
        width = TYPE_WIDTH[acc["type"]]
        start = v["byteOffset"] + acc.get("byteOffset", 0)
        assert start % size == 0
        assert acc.get("byteOffset", 0) + acc["count"] * size * width <= v["byteLength"]
        values = np.frombuffer(binary, COMPONENT_DTYPE[acc["componentType"]], acc["count"] * width, start)
        values = values.reshape(acc["count"], width)
        assert acc["min"] == values.min(axis=0).tolist() and acc["max"] == values.max(axis=0).tolist()
    for mesh in doc["meshes"]:
        for prim in mesh["primitives"]:
            pos = doc["accessors"][prim["attributes"]["POSITION"]]
            assert pos["componentType"] == 5126 and pos["type"] == "VEC3" and "min" in pos and "max" in pos
            for name, index in prim["attributes"].items():
                acc = doc["accessors"][index]
                assert views[acc["bufferView"]].get("target") == 34962
                assert (COMPONENT_SIZE[acc["componentType"]] * TYPE_WIDTH[acc["type"]]) % 4 == 0
                if name.startswith("WEIGHTS"):
                    v = views[acc["bufferView"]]
                    w = np.frombuffer(binary, "<f4", acc["count"] * 4, v["byteOffset"]).reshape(-1, 4)
                    np.testing.assert_allclose(w.sum(axis=1), 1.0, atol=1e-6)
    for anim in doc.get("animations", []):
        for s in anim["samplers"]:
            times = doc["accessors"][s["input"]]
            assert times["type"] == "SCALAR" and times["componentType"] == 5126 and times["min"][0] >= 0


@pytest.mark.parametrize("text", ["", "a", "ab", "abc"])
def test_glb_container_padding(text: str) -> None:
    obj = {"asset": {"version": "2.0"}, "x": "é" + text}
    raw = json.dumps(obj, separators=(",", ":"), ensure_ascii=False).encode()
    data = build_glb(obj, b"\x01\x02\x03")
    assert len(data) % 4 == 0
    json_len = struct.unpack_from("<I", data, 12)[0]
    assert json_len % 4 == 0 and data[20:20 + json_len] == raw + b" " * ((-len(raw)) % 4)
    doc, binary = read_glb(data)
    assert doc == obj and binary == b"\x01\x02\x03\x00"


# ------------------------------------------------------------------ bad input
def _simple(shared_data: Path) -> dict[str, Any]:
    doc: dict[str, Any] = json.loads((shared_data / "gltf" / "SimpleSkin.gltf").read_text())
    return doc


def _parse_doc(doc: Any) -> Any:
    return parse_gltf(json.dumps(doc).encode(), "bad.gltf")


@pytest.mark.parametrize(("change", "words"), [
    (lambda d: d.pop("asset"), "asset.version"),
    (lambda d: d["asset"].update(version="1.0"), "version"),
    (lambda d: d["nodes"][0].update(mesh=3), "mesh 3"),
    (lambda d: d["nodes"][1].update(children=[1]), "parent"),
    (lambda d: d["nodes"][2].update(children=[1]), "cycle"),
    (lambda d: d["accessors"][1].update(count=1000), "needs"),
    (lambda d: d["accessors"][1].update(componentType=7), "componentType"),
    (lambda d: d["accessors"][1].update(type="VEC5"), "type"),
    (lambda d: d["bufferViews"][0].update(byteLength=10 ** 6), "covers bytes"),
    (lambda d: d["buffers"][0].update(uri="data:application/octet-stream;base64,@@@"), "base64"),
    (lambda d: d["buffers"][0].update(uri="missing.bin"), "cannot be read"),
    (lambda d: d["buffers"][0].update(byteLength=100000), "only"),
    (lambda d: d["animations"][0]["samplers"][0].update(interpolation="CUBIC"), "interpolation"),
    (lambda d: d["animations"][0]["channels"][0]["target"].update(path="colour"), "path"),
    (lambda d: d["animations"][0]["samplers"][0].update(output=1), "output values"),
    (lambda d: d["skins"][0].update(joints=[1]), "uses joint 1"),
    (lambda d: d["meshes"][0]["primitives"][0].update(indices=1), "SCALAR"),
    (lambda d: d["nodes"][2].update(rotation=[0, 0, 0]), "4 numbers"),
    (lambda d: d["nodes"][2].update(translation=[0, "a", 0]), "3 numbers"),
    (lambda d: d.update(nodes={"a": 1}), "array"),
    (lambda d: d["accessors"][1].update(count=-1), "at least 1"),
    (lambda d: d["accessors"][1].update(count=2.5), "whole number"),
])
def test_broken_gltf_raises_format_error(shared_data: Path, tmp_path: Path, change: Any, words: str) -> None:
    doc = _simple(shared_data)
    change(doc)
    path = tmp_path / "bad.gltf"
    path.write_text(json.dumps(doc))
    with pytest.raises(FormatError, match=words) as info:
        import_gltf(path)
    assert str(info.value).startswith("bad.gltf")


def test_external_buffer_and_json_errors(shared_data: Path, tmp_path: Path) -> None:
    doc = _simple(shared_data)
    uri = doc["buffers"][0]["uri"]
    (tmp_path / "data 0.bin").write_bytes(base64.b64decode(uri.split(",", 1)[1]))
    doc["buffers"][0]["uri"] = "data%200.bin"
    (tmp_path / "ext.gltf").write_text(json.dumps(doc))
    ext = import_gltf(tmp_path / "ext.gltf")
    np.testing.assert_array_equal(ext.skinned_positions(0, 1.0),
                                  import_gltf(shared_data / "gltf" / "SimpleSkin.gltf").skinned_positions(0, 1.0))
    with pytest.raises(FormatError) as info:
        parse_gltf(b'{\n  "asset": {"version": "2.0"},\n  "nodes": [,]\n}', "x.gltf")
    assert info.value.line == 3
    for text in (b"[1, 2]", b"", b"{\"asset\": NaN}", b"\xff\xfe", b"[" * 100000):
        with pytest.raises(FormatError):
            parse_gltf(text)
    with pytest.raises(FormatError, match="cannot read"):
        import_gltf(tmp_path / "nope.glb")


def test_broken_glb_containers(shared_data: Path) -> None:
    data = (shared_data / "gltf" / "RiggedSimple.glb").read_bytes()
    for cut in (0, 5, 12, 19, 30, 4000, len(data) - 1):
        with pytest.raises(FormatError):
            parse_gltf(data[:cut] if cut > 4 else b"glTF" + data[4:cut])
    for bad, words in ((b"glTF" + struct.pack("<II", 1, len(data)) + data[12:], "version 1"),
                       (data[:8] + struct.pack("<I", len(data) + 8) + data[12:], "truncated"),
                       (data[:16] + b"BIN\0" + data[20:], "first GLB chunk")):
        with pytest.raises(FormatError, match=words):
            parse_gltf(bad)


_JSON_VALUES = st.one_of(
    st.none(), st.booleans(), st.integers(-3, 300), st.sampled_from([10 ** 12, -(10 ** 12), 1.5, 1e308, ""]),
    st.text(max_size=5), st.lists(st.integers(-2, 20), max_size=5), st.just({}),
    st.sampled_from(["SCALAR", "VEC4", "MAT4", "CUBICSPLINE", "STEP", "rotation", "weights"]),
)


def _paths(obj: Any, prefix: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    out = [prefix]
    if isinstance(obj, dict):
        for k, v in obj.items():
            if k != "uri":
                out += _paths(v, prefix + (k,))
    elif isinstance(obj, list) and len(obj) < 40:
        for i, v in enumerate(obj):
            out += _paths(v, prefix + (i,))
    return out


def _loads_or_format_error(data: bytes) -> None:
    try:
        scene = parse_gltf(data, "fuzz.gltf")
    except FormatError:
        return
    for m in range(len(scene.meshes)):
        for t in (None, 0.0, 0.7, 100.0):
            p = scene.skinned_positions(m, t)
            assert p.shape == (scene.meshes[m].num_vertices, 3)
    glb_bytes(scene)


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                 HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_fuzzed_gltf_json_raises_only_format_error(shared_data: Path, data: st.DataObject) -> None:
    doc = _simple(shared_data)
    for _ in range(data.draw(st.integers(1, 3))):
        paths = [p for p in _paths(doc) if p]
        path = data.draw(st.sampled_from(paths))
        target = doc
        for k in path[:-1]:
            target = target[k]
        if data.draw(st.booleans()):
            target[path[-1]] = data.draw(_JSON_VALUES)
        elif isinstance(target, dict):
            del target[path[-1]]
        else:
            target[path[-1]] = copy.deepcopy(data.draw(_JSON_VALUES))
    _loads_or_format_error(json.dumps(doc).encode())


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_fuzzed_glb_bytes_raise_only_format_error(shared_data: Path, data: st.DataObject) -> None:
    blob = bytearray((shared_data / "gltf" / "RiggedSimple.glb").read_bytes())
    for _ in range(data.draw(st.integers(1, 6))):
        i = data.draw(st.integers(0, len(blob) - 1))
        blob[i] = data.draw(st.integers(0, 255))
    _loads_or_format_error(bytes(blob))
