"""Reading ``.gltf`` / ``.glb`` files into a :class:`~qtanimator.formats.gltf.model.GltfScene`.

Every malformed file raises :class:`~qtanimator.formats.FormatError` (and nothing else).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from qtanimator.core.keys import KEY_TIME_TOLERANCE, MAX_KEY_TIME, MAX_KEY_VALUE
from qtanimator.core.rotation import normalize as _normalize
from qtanimator.formats._tokens import read_bytes
from qtanimator.formats.errors import FormatError
from qtanimator.formats.glb import is_glb, parse_json_text, read_glb
from qtanimator.formats.gltf.accessors import FloatArray, Reader, short
from qtanimator.formats.gltf.buffers import load_buffers, read_uri
from qtanimator.formats.gltf.constants import (
    INTERPOLATIONS,
    PATHS,
    TRIANGLE_FAN,
    TRIANGLE_STRIP,
    TRIANGLES,
    WEIGHT_SUM_TOLERANCE,
)
from qtanimator.formats.gltf.model import (
    GltfAnimation,
    GltfAnimationChannel,
    GltfImage,
    GltfMesh,
    GltfNode,
    GltfPrimitive,
    GltfSampler,
    GltfScene,
    GltfSkin,
    IntArray,
)
from qtanimator.formats.limits import MAX_JOINTS, MAX_NODES, MAX_VERTICES, exceeded


def import_gltf(path: str | os.PathLike[str]) -> GltfScene:
    """Read a ``.gltf`` (embedded or external buffers) or ``.glb`` file.

    Raises :class:`FormatError` and nothing else on bad input.
    """
    p = Path(path)
    return parse_gltf(read_bytes(p), path, base=p.parent)


def parse_gltf(data: bytes, path: str | os.PathLike[str] | None = None, base: Path | None = None) -> GltfScene:
    """Parse glTF JSON or GLB bytes. ``base`` is the folder for external buffers."""
    spath = os.fspath(path) if path is not None else None
    if is_glb(data):
        doc, bin_chunk = read_glb(data, spath)
    else:
        doc, bin_chunk = parse_json_text(data, spath), None
    try:
        return _build_scene(doc, bin_chunk, base, spath, len(data))
    except FormatError:
        raise
    except (ValueError, TypeError, KeyError, IndexError, OverflowError, MemoryError, RecursionError) as exc:
        # A safety net: the validation above should have caught every bad input.
        raise FormatError(f"the glTF data is inconsistent ({type(exc).__name__}: {short(str(exc), 80)}).",
                          spath) from exc


def _build_scene(doc: dict[str, Any], bin_chunk: bytes | None, base: Path | None, path: str | None,
                 input_bytes: int = 0) -> GltfScene:
    asset = doc.get("asset")
    if not isinstance(asset, dict) or not isinstance(asset.get("version"), str):
        raise FormatError("the glTF has no asset.version; is this a glTF 2.0 file?", path)
    version = asset["version"]
    min_version = asset.get("minVersion")
    if not version.startswith("2.") or (isinstance(min_version, str) and not min_version.startswith("2.")):
        raise FormatError(f"glTF version {short(version)} is not supported; qtanimator reads glTF 2.0.", path)
    required = doc.get("extensionsRequired", [])
    if isinstance(required, list) and required:
        raise FormatError(f"the file requires extensions qtanimator does not support: "
                          f"{', '.join(short(x) for x in required)}.", path)
    buffers = load_buffers(doc, bin_chunk, base, path)
    r = Reader(doc, buffers, path, input_bytes)
    scene = GltfScene(path=path, generator=str(asset.get("generator", "")))
    scene.nodes = _read_nodes(r)
    scene.skins = _read_skins(r, len(scene.nodes))
    scene.meshes = [_read_mesh(r, i, m) for i, m in enumerate(r.collection("meshes"))]
    for i, node in enumerate(scene.nodes):
        if node.mesh is not None and node.mesh >= len(scene.meshes):
            raise r.error(f"nodes[{i}].mesh refers to mesh {node.mesh}, but there are {len(scene.meshes)}.")
        if node.skin is not None:
            if node.mesh is None:
                continue
            joints = len(scene.skins[node.skin].joints)
            for k, prim in enumerate(scene.meshes[node.mesh].primitives):
                if prim.joints is not None and prim.weights is not None:
                    used = prim.joints[prim.weights != 0]
                    if used.size and int(used.max()) >= joints:
                        raise r.error(f"meshes[{node.mesh}].primitives[{k}] uses joint {int(used.max())}, "
                                      f"but skins[{node.skin}] has {joints}.")
                    prim.joints = np.where(prim.weights != 0, prim.joints, 0)
    scene.animations = [_read_animation(r, i, a, len(scene.nodes)) for i, a in enumerate(r.collection("animations"))]
    scene.roots = _read_roots(r, scene.nodes)
    scene.materials = r.collection("materials")
    scene.textures = r.collection("textures")
    scene.samplers = r.collection("samplers")
    scene.images = [_read_image(r, i, im, base) for i, im in enumerate(r.collection("images"))]
    return scene


def _read_nodes(r: Reader) -> list[GltfNode]:
    raw = r.collection("nodes")
    if len(raw) > MAX_NODES:
        raise exceeded(f"the scene's {len(raw)} nodes", f"{MAX_NODES} nodes", r.path)
    nodes: list[GltfNode] = []
    for i, nd in enumerate(raw):
        w = f"nodes[{i}]"
        node = GltfNode(name=r.string(nd, "name", w))
        children = r.array(nd, "children", w)
        for ck in range(len(children)):
            node.children.append(r.item(children[ck], f"{w}.children[{ck}]", len(raw)))
        m = r.numbers(nd, "matrix", w, 16)
        if m is not None:
            node.matrix = m.reshape(4, 4).T.copy()  # column-major in the file
        t = r.numbers(nd, "translation", w, 3)
        q = r.numbers(nd, "rotation", w, 4)
        s = r.numbers(nd, "scale", w, 3)
        if t is not None:
            node.translation = t
        if q is not None:
            big = float(np.abs(q).max())
            if big == 0.0:
                raise r.error(f"{w}.rotation is the zero quaternion.")
            q = q / big
            node.rotation = q / float(np.linalg.norm(q))
        if s is not None:
            node.scale = s
        node.mesh = r.integer(nd, "mesh", w)
        node.skin = r.index(nd, "skin", w, "skins")
        nodes.append(node)
    for i, node in enumerate(nodes):
        for c in node.children:
            if nodes[c].parent is not None or c == i:
                raise r.error(f"node {c} has more than one parent (or is its own child).")
            nodes[c].parent = i
    # Every node must reach a root by walking up; a cycle never does.
    state = [0] * len(nodes)  # 0 unknown, 1 visiting, 2 fine
    for i in range(len(nodes)):
        chain = []
        k: int | None = i
        while k is not None and state[k] == 0:
            state[k] = 1
            chain.append(k)
            k = nodes[k].parent
        if k is not None and state[k] == 1:
            raise r.error(f"the node hierarchy has a cycle through node {k}.")
        for c in chain:
            state[c] = 2
    return nodes


def _read_roots(r: Reader, nodes: list[GltfNode]) -> list[int]:
    scenes = r.collection("scenes")
    default = r.integer(r.doc, "scene", "the glTF", count=len(scenes))
    if scenes:
        sc = scenes[default or 0]
        roots = []
        for k, value in enumerate(r.array(sc, "nodes", f"scenes[{default or 0}]")):
            idx = r.item(value, f"scenes[{default or 0}].nodes[{k}]", len(nodes))
            if nodes[idx].parent is not None:
                raise r.error(f"scene root node {idx} has a parent.")
            roots.append(idx)
        return roots
    return [i for i, n in enumerate(nodes) if n.parent is None]


def _read_skins(r: Reader, num_nodes: int) -> list[GltfSkin]:
    skins = []
    for i, sk in enumerate(r.collection("skins")):
        w = f"skins[{i}]"
        joints_raw = r.array(sk, "joints", w)
        if not joints_raw:
            raise r.error(f"{w} has no joints.")
        if len(joints_raw) > MAX_JOINTS:
            raise exceeded(f"{w} with {len(joints_raw)} joints", f"{MAX_JOINTS} joints per skin", r.path)
        joints = []
        for k, j in enumerate(joints_raw):
            joints.append(r.item(j, f"{w}.joints[{k}]", num_nodes))
        ibm_index = r.integer(sk, "inverseBindMatrices", w)
        if ibm_index is None:
            ibm = np.broadcast_to(np.eye(4), (len(joints), 4, 4)).copy()
        else:
            data = r.accessor(ibm_index, f"{w}.inverseBindMatrices")
            if data.shape[1] != 16:
                raise r.error(f"{w}.inverseBindMatrices must be a MAT4 accessor.")
            if len(data) < len(joints):
                raise r.error(f"{w} has {len(joints)} joints but only {len(data)} inverse bind matrices.")
            ibm = np.asarray(data[: len(joints)], dtype=np.float64).reshape(-1, 4, 4).transpose(0, 2, 1).copy()
        skins.append(GltfSkin(joints, ibm, r.integer(sk, "skeleton", w, count=num_nodes), r.string(sk, "name", w)))
    return skins


def _read_mesh(r: Reader, mi: int, mesh: dict[str, Any]) -> GltfMesh:
    w = f"meshes[{mi}]"
    prims = r.array(mesh, "primitives", w)
    if not prims:
        raise r.error(f"{w} has no primitives.")
    out = []
    for pi, praw in enumerate(prims):
        pw = f"{w}.primitives[{pi}]"
        prim = r.obj(praw, pw)
        attrs = r.obj(prim.get("attributes"), f"{pw}.attributes")
        pos_index = r.integer(attrs, "POSITION", f"{pw}.attributes", required=True)
        positions = _float_attr(r, pos_index or 0, f"{pw}.attributes.POSITION", 3)
        r.vertices += len(positions)
        if r.vertices > MAX_VERTICES:
            raise exceeded(f"the meshes' {r.vertices} vertices", f"{MAX_VERTICES} vertices per file", r.path)
        nv = len(positions)

        normals = _optional_attr(r, attrs, pw, "NORMAL", 3, nv)
        texcoords = _optional_attr(r, attrs, pw, "TEXCOORD_0", 2, nv)
        joint_sets, weight_sets = [], []
        k = 0
        while f"JOINTS_{k}" in attrs or f"WEIGHTS_{k}" in attrs:
            ji = r.integer(attrs, f"JOINTS_{k}", f"{pw}.attributes", required=True) or 0
            wi = r.integer(attrs, f"WEIGHTS_{k}", f"{pw}.attributes", required=True) or 0
            jarr = r.accessor(ji, f"{pw}.attributes.JOINTS_{k}")
            warr = r.accessor(wi, f"{pw}.attributes.WEIGHTS_{k}")
            if jarr.dtype.kind == "f" or jarr.shape[1] != 4:
                raise r.error(f"{pw}.attributes.JOINTS_{k} must be a VEC4 of unsigned integers.")
            if warr.dtype.kind != "f" or warr.shape[1] != 4:
                raise r.error(f"{pw}.attributes.WEIGHTS_{k} must be a VEC4 of floats or normalized integers.")
            if len(jarr) != nv or len(warr) != nv:
                raise r.error(f"{pw}.attributes.JOINTS_{k} / WEIGHTS_{k} do not match the {nv} vertices.")
            if (jarr < 0).any():
                raise r.error(f"{pw}.attributes.JOINTS_{k} holds a negative joint index.")
            joint_sets.append(jarr)
            weight_sets.append(warr)
            k += 1
            if k > 64:
                break
        joints = weights = None
        renormalized = 0
        if joint_sets:
            joints = np.concatenate(joint_sets, axis=1).astype(np.int64)
            weights = np.concatenate(weight_sets, axis=1).astype(np.float64)
            if (weights < 0).any():
                raise r.error(f"{pw} has negative skin weights.")
            sums = weights.sum(axis=1)
            fix = (np.abs(sums - 1.0) > WEIGHT_SUM_TOLERANCE) & (sums > 0)
            renormalized = int(fix.sum())
            weights[fix] /= sums[fix, None]
        mode = r.integer(prim, "mode", pw, default=TRIANGLES) or 0
        if mode > 6:
            raise r.error(f"{pw}.mode {mode} is not a glTF primitive mode.")
        idx_index = r.integer(prim, "indices", pw)
        if idx_index is None:
            indices = np.arange(nv, dtype=np.int64)
        else:
            ia = r.accessor(idx_index, f"{pw}.indices")
            if ia.dtype.kind == "f" or ia.shape[1] != 1:
                raise r.error(f"{pw}.indices must be a SCALAR accessor of unsigned integers.")
            indices = ia.reshape(-1)
            if indices.size and (indices.min() < 0 or indices.max() >= nv):
                raise r.error(f"{pw}.indices refers to vertex {int(indices.max())} of {nv}.")
        triangles = _triangles(indices, mode)
        material = r.index(prim, "material", pw, "materials")
        out.append(GltfPrimitive(positions, triangles, normals, texcoords, joints, weights, material, mode,
                                 renormalized))
    return GltfMesh(out, r.string(mesh, "name", w))


def _optional_attr(r: Reader, attrs: dict[str, Any], pw: str, name: str, width: int, nv: int) -> FloatArray | None:
    idx = r.integer(attrs, name, f"{pw}.attributes")
    if idx is None:
        return None
    arr = _float_attr(r, idx, f"{pw}.attributes.{name}", width)
    if len(arr) != nv:
        raise r.error(f"{pw}.attributes.{name} has {len(arr)} elements for {nv} vertices.")
    return arr


def _float_attr(r: Reader, index: int, where: str, width: int) -> FloatArray:
    arr = r.accessor(index, where)
    if arr.shape[1] != width:
        raise r.error(f"{where} must have {width} components per element, found {arr.shape[1]}.")
    return np.asarray(arr, dtype=np.float64)


def _triangles(indices: IntArray, mode: int) -> IntArray:
    if mode == TRIANGLES:
        n = len(indices) // 3 * 3
        return indices[:n].reshape(-1, 3).copy()
    if mode == TRIANGLE_STRIP and len(indices) >= 3:
        i = np.arange(len(indices) - 2)
        even = (i % 2) == 0
        a = indices[i]
        b = np.where(even, indices[i + 1], indices[i + 2])
        c = np.where(even, indices[i + 2], indices[i + 1])
        return np.stack([a, b, c], axis=1)
    if mode == TRIANGLE_FAN and len(indices) >= 3:
        i = np.arange(1, len(indices) - 1)
        return np.stack([np.full(len(i), indices[0]), indices[i], indices[i + 1]], axis=1)
    return np.zeros((0, 3), dtype=np.int64)


def _check_times(r: Reader, times: FloatArray, where: str) -> None:
    """Key times a channel can hold (the glTF spec: strictly increasing; qtanimator's bounds:
    within ±:data:`MAX_KEY_TIME` seconds and :data:`KEY_TIME_TOLERANCE` apart), else FormatError."""
    if times.size and not float(np.max(np.abs(times))) <= MAX_KEY_TIME:
        raise r.error(f"{where}.input holds a time beyond the limit of ±{MAX_KEY_TIME:g} seconds.")
    gaps = np.diff(times)
    if gaps.size and float(np.min(gaps)) < KEY_TIME_TOLERANCE:
        i = int(np.argmin(gaps))
        raise r.error(f"{where}.input times must increase by at least {KEY_TIME_TOLERANCE:g} s; keys {i} and "
                      f"{i + 1} are at {float(times[i]):g} and {float(times[i + 1]):g} s.")


def _read_animation(r: Reader, ai: int, anim: dict[str, Any], num_nodes: int) -> GltfAnimation:
    w = f"animations[{ai}]"
    samplers = []
    for si, sraw in enumerate(r.array(anim, "samplers", w)):
        sw = f"{w}.samplers[{si}]"
        s = r.obj(sraw, sw)
        interp = s.get("interpolation", "LINEAR")
        if interp not in INTERPOLATIONS:
            raise r.error(f"{sw}.interpolation must be LINEAR, STEP or CUBICSPLINE, found {short(interp)}.")
        times = r.accessor(r.integer(s, "input", sw, required=True) or 0, f"{sw}.input")
        if times.dtype.kind != "f" or times.shape[1] != 1:
            raise r.error(f"{sw}.input must be a SCALAR float accessor.")
        times = times.reshape(-1).astype(np.float64)
        _check_times(r, times, sw)
        values = r.accessor(r.integer(s, "output", sw, required=True) or 0, f"{sw}.output")
        values = np.asarray(values, dtype=np.float64)
        if values.size and float(np.max(np.abs(values))) > MAX_KEY_VALUE:
            raise r.error(f"{sw}.output holds a value beyond the limit of ±{MAX_KEY_VALUE:g}.")
        per_key = 3 if interp == "CUBICSPLINE" else 1
        if len(values) % (len(times) * per_key):
            raise r.error(f"{sw} has {len(times)} key times but {len(values)} output values.")
        width = len(values) // (len(times) * per_key) * values.shape[1]
        shaped = values.reshape(len(times), per_key, width) if per_key == 3 else values.reshape(len(times), width)
        samplers.append(GltfSampler(times, shaped, interp))
    channels = []
    for ci, craw in enumerate(r.array(anim, "channels", w)):
        cw = f"{w}.channels[{ci}]"
        c = r.obj(craw, cw)
        si = r.integer(c, "sampler", cw, required=True, count=len(samplers)) or 0
        target = r.obj(c.get("target"), f"{cw}.target")
        node = r.integer(target, "node", f"{cw}.target", count=num_nodes)
        path = target.get("path")
        if path not in PATHS:
            raise r.error(f"{cw}.target.path must be translation, rotation, scale or weights, found {short(path)}.")
        if node is None:
            continue  # targets an extension; nothing to animate here
        width = PATHS[path]
        sampler = samplers[si]
        got = sampler.values.shape[-1]
        if width and got != width:
            raise r.error(f"{cw} animates {path} with {got} numbers per key instead of {width}.")
        if path == "rotation":  # keys must be unit quaternions; tangents are left alone
            if sampler.interpolation == "CUBICSPLINE":
                sampler.values[:, 1] = _normalize(sampler.values[:, 1])
            else:
                sampler.values = _normalize(sampler.values)
        channels.append(GltfAnimationChannel(si, node, path))
    return GltfAnimation(samplers, channels, r.string(anim, "name", w))


def _read_image(r: Reader, i: int, im: dict[str, Any], base: Path | None) -> GltfImage:
    w = f"images[{i}]"
    name = r.string(im, "name", w)
    mime = im.get("mimeType")
    mime = mime if isinstance(mime, str) else None
    view = r.integer(im, "bufferView", w)
    if view is not None:
        data, start, length, _ = r.buffer_view(view, w)
        return GltfImage(bytes(data[start:start + length]), mime, None, name)
    uri = im.get("uri")
    if isinstance(uri, str) and uri.startswith("data:"):
        return GltfImage(read_uri(uri, base, w, r.path), mime or uri[5:].split(";")[0], None, name)
    return GltfImage(None, mime, uri if isinstance(uri, str) else None, name)


def summarize(path: Path) -> dict[str, Any]:
    scene = import_gltf(path)
    out: dict[str, Any] = {"file": str(path)}
    out.update(scene.summary())
    return out
