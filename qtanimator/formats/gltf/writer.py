"""Writing a :class:`~qtanimator.formats.gltf.model.GltfScene` as glTF JSON and one binary
buffer (one buffer view per accessor, 4-byte aligned, min / max on every accessor), and as
``.glb`` bytes or file."""

from __future__ import annotations

import os
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.core.rotation import normalize as _normalize
from qtanimator.formats.atomic import write_atomic
from qtanimator.formats.glb import build_glb
from qtanimator.formats.gltf.constants import (
    ARRAY_BUFFER,
    COMPONENTS,
    ELEMENT_ARRAY_BUFFER,
    FLOAT,
    TRIANGLES,
    TYPES,
    UNSIGNED_BYTE,
    UNSIGNED_INT,
    UNSIGNED_SHORT,
)
from qtanimator.formats.gltf.model import GltfScene


class _Writer:
    """Collects accessors and buffer views into one binary buffer."""

    def __init__(self) -> None:
        self.chunks: list[bytes] = []
        self.size = 0
        self.views: list[dict[str, Any]] = []
        self.accessors: list[dict[str, Any]] = []
        self._dedup: dict[tuple[bytes, int, str, int | None, bool], int] = {}

    def view(self, data: bytes, target: int | None = None) -> int:
        pad = (-self.size) % 4
        if pad:
            self.chunks.append(b"\0" * pad)
            self.size += pad
        v: dict[str, Any] = {"buffer": 0, "byteOffset": self.size, "byteLength": len(data)}
        if target is not None:
            v["target"] = target
        self.chunks.append(data)
        self.size += len(data)
        self.views.append(v)
        return len(self.views) - 1

    def accessor(self, array: npt.ArrayLike, ctype: int, kind: str, target: int | None = None,
                 normalized: bool = False) -> int:
        dtype_code, _ = COMPONENTS[ctype]
        cols, rows = TYPES[kind]
        a = np.ascontiguousarray(np.asarray(array).reshape(-1, cols * rows), dtype=np.dtype(dtype_code))
        if ctype == FLOAT and not np.isfinite(a).all():
            raise ValueError(f"cannot export non-finite values to a {kind} accessor")
        if len(a) == 0:
            raise ValueError("cannot export an empty accessor")
        data = a.tobytes()
        key = (data, ctype, kind, target, normalized)
        if key in self._dedup:
            return self._dedup[key]
        acc: dict[str, Any] = {"bufferView": self.view(data, target), "componentType": ctype,
                               "count": int(len(a)), "type": kind}
        if normalized:
            acc["normalized"] = True
        if ctype == FLOAT:
            acc["min"] = [float(x) for x in a.min(axis=0)]
            acc["max"] = [float(x) for x in a.max(axis=0)]
        else:
            acc["min"] = [int(x) for x in a.min(axis=0)]
            acc["max"] = [int(x) for x in a.max(axis=0)]
        self.accessors.append(acc)
        self._dedup[key] = len(self.accessors) - 1
        return len(self.accessors) - 1

    def binary(self) -> bytes:
        return b"".join(self.chunks)


def _index_type(count: int) -> int:
    if count <= 255:
        return UNSIGNED_BYTE
    return UNSIGNED_SHORT if count <= 65535 else UNSIGNED_INT


def scene_to_gltf(scene: GltfScene) -> tuple[dict[str, Any], bytes]:
    """The glTF JSON object and the binary buffer of ``scene``."""
    w = _Writer()
    doc: dict[str, Any] = {"asset": {"version": "2.0", "generator": "qtanimator"}}
    nodes_json = []
    for node in scene.nodes:
        nj: dict[str, Any] = {}
        if node.name:
            nj["name"] = node.name
        if node.children:
            nj["children"] = [int(c) for c in node.children]
        if node.matrix is not None:
            nj["matrix"] = [float(x) for x in np.asarray(node.matrix, dtype=np.float64).T.reshape(16)]
        else:
            if np.any(node.translation != 0):
                nj["translation"] = [float(x) for x in node.translation]
            if not np.array_equal(node.rotation, [0.0, 0.0, 0.0, 1.0]):
                nj["rotation"] = [float(x) for x in _normalize(np.asarray(node.rotation, dtype=np.float64))]
            if np.any(node.scale != 1):
                nj["scale"] = [float(x) for x in node.scale]
        if node.mesh is not None:
            nj["mesh"] = int(node.mesh)
        if node.skin is not None:
            nj["skin"] = int(node.skin)
        nodes_json.append(nj)
    doc["nodes"] = nodes_json
    doc["scene"] = 0
    doc["scenes"] = [{"nodes": [int(i) for i in scene.roots]}]
    meshes_json = []
    for mesh in scene.meshes:
        prims = []
        for prim in mesh.primitives:
            nv = prim.num_vertices
            attrs: dict[str, int] = {"POSITION": w.accessor(prim.positions, FLOAT, "VEC3", ARRAY_BUFFER)}
            if prim.normals is not None:
                n = np.asarray(prim.normals, dtype=np.float64)
                length = np.linalg.norm(n, axis=1, keepdims=True)
                n = np.where(length > 0, n / np.where(length > 0, length, 1.0), [0.0, 0.0, 1.0])
                attrs["NORMAL"] = w.accessor(n, FLOAT, "VEC3", ARRAY_BUFFER)
            if prim.texcoords is not None:
                attrs["TEXCOORD_0"] = w.accessor(prim.texcoords, FLOAT, "VEC2", ARRAY_BUFFER)
            if prim.joints is not None and prim.weights is not None and prim.joints.shape[1]:
                k = prim.joints.shape[1]
                sets = (k + 3) // 4
                jj = np.zeros((nv, sets * 4), dtype=np.int64)
                ww = np.zeros((nv, sets * 4))
                jj[:, :k] = prim.joints
                ww[:, :k] = prim.weights
                jt = UNSIGNED_BYTE if int(jj.max()) <= 255 else UNSIGNED_SHORT
                for si in range(sets):
                    attrs[f"JOINTS_{si}"] = w.accessor(jj[:, 4 * si:4 * si + 4], jt, "VEC4", ARRAY_BUFFER)
                    attrs[f"WEIGHTS_{si}"] = w.accessor(ww[:, 4 * si:4 * si + 4], FLOAT, "VEC4", ARRAY_BUFFER)
            pj: dict[str, Any] = {"attributes": attrs, "mode": TRIANGLES}
            if len(prim.triangles):
                pj["indices"] = w.accessor(prim.triangles.reshape(-1), _index_type(nv - 1), "SCALAR",
                                           ELEMENT_ARRAY_BUFFER)
            if prim.material is not None:
                pj["material"] = int(prim.material)
            prims.append(pj)
        mj: dict[str, Any] = {"primitives": prims}
        if mesh.name:
            mj["name"] = mesh.name
        meshes_json.append(mj)
    if meshes_json:
        doc["meshes"] = meshes_json
    skins_json = []
    for skin in scene.skins:
        ibm = np.asarray(skin.inverse_bind_matrices, dtype=np.float64).transpose(0, 2, 1)
        sj: dict[str, Any] = {"joints": [int(j) for j in skin.joints],
                              "inverseBindMatrices": w.accessor(ibm, FLOAT, "MAT4")}
        if skin.skeleton is not None:
            sj["skeleton"] = int(skin.skeleton)
        if skin.name:
            sj["name"] = skin.name
        skins_json.append(sj)
    if skins_json:
        doc["skins"] = skins_json
    anims_json = []
    for anim in scene.animations:
        samplers = []
        for s in anim.samplers:
            values = np.asarray(s.values, dtype=np.float64)
            width = values.shape[-1]
            kind = {1: "SCALAR", 3: "VEC3", 4: "VEC4"}.get(width, "SCALAR")
            flat = values.reshape(-1, width) if kind != "SCALAR" else values.reshape(-1, 1)
            samplers.append({"input": w.accessor(s.times, FLOAT, "SCALAR"),
                             "output": w.accessor(flat, FLOAT, kind),
                             "interpolation": s.interpolation})
        channels = [{"sampler": int(c.sampler), "target": {"node": int(c.node), "path": c.path}}
                    for c in anim.channels]
        aj: dict[str, Any] = {"samplers": samplers, "channels": channels}
        if anim.name:
            aj["name"] = anim.name
        anims_json.append(aj)
    if anims_json:
        doc["animations"] = anims_json
    images_json = []
    for im in scene.images:
        ij: dict[str, Any] = {}
        if im.name:
            ij["name"] = im.name
        if im.data is not None:
            ij["bufferView"] = w.view(im.data)
            ij["mimeType"] = im.mime_type or "image/png"
        elif im.uri is not None:
            ij["uri"] = im.uri
        images_json.append(ij)
    for key, items in (("materials", scene.materials), ("textures", scene.textures), ("samplers", scene.samplers),
                       ("images", images_json)):
        if items:
            doc[key] = items
    binary = w.binary()
    if binary:
        doc["buffers"] = [{"byteLength": len(binary)}]
        doc["bufferViews"] = w.views
    if w.accessors:
        doc["accessors"] = w.accessors
    return doc, binary


def glb_bytes(scene: GltfScene) -> bytes:
    """``scene`` as the bytes of a ``.glb`` file."""
    doc, binary = scene_to_gltf(scene)
    return build_glb(doc, binary if binary else None)


def export_glb(path: str | os.PathLike[str], scene: GltfScene) -> None:
    """Write ``scene`` to a ``.glb`` file atomically."""
    write_atomic(path, glb_bytes(scene))
