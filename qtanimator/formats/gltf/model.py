"""The glTF scene model: nodes, meshes, skins, animations and images as dataclasses, and
:class:`GltfScene`'s pose evaluation (local, world and joint matrices, skinned positions)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.core.rotation import normalize as _normalize
from qtanimator.core.rotation import slerp as _slerp
from qtanimator.core.rotation import trs_matrix
from qtanimator.core.skinning import Skin, SkinBinding
from qtanimator.formats.gltf.constants import TRIANGLES

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]


@dataclass(eq=False)
class GltfNode:
    """A node. ``matrix`` (4×4, column vectors) when the file gave one, else TRS."""

    name: str = ""
    children: list[int] = field(default_factory=list)
    parent: int | None = None
    translation: FloatArray = field(default_factory=lambda: np.zeros(3))
    rotation: FloatArray = field(default_factory=lambda: np.array([0.0, 0.0, 0.0, 1.0]))
    scale: FloatArray = field(default_factory=lambda: np.ones(3))
    matrix: FloatArray | None = None
    mesh: int | None = None
    skin: int | None = None

    def local_matrix(self) -> FloatArray:
        if self.matrix is not None:
            return self.matrix.copy()
        return trs_matrix(self.translation, self.rotation, self.scale)


@dataclass(eq=False)
class GltfSkin:
    """``joints`` are node indices; ``inverse_bind_matrices`` (J, 4, 4)."""

    joints: list[int]
    inverse_bind_matrices: FloatArray
    skeleton: int | None = None
    name: str = ""


@dataclass(eq=False)
class GltfPrimitive:
    """One primitive. ``joints`` / ``weights`` are (V, K) with K a multiple of 4 (or 0)."""

    positions: FloatArray
    triangles: IntArray
    normals: FloatArray | None = None
    texcoords: FloatArray | None = None
    joints: IntArray | None = None
    weights: FloatArray | None = None
    material: int | None = None
    mode: int = TRIANGLES
    #: vertices whose weights were divided by their sum on import
    renormalized_vertices: int = 0

    @property
    def num_vertices(self) -> int:
        return int(len(self.positions))


@dataclass(eq=False)
class GltfMesh:
    primitives: list[GltfPrimitive]
    name: str = ""

    @property
    def num_vertices(self) -> int:
        return sum(p.num_vertices for p in self.primitives)

    @property
    def num_triangles(self) -> int:
        return sum(len(p.triangles) for p in self.primitives)


@dataclass(eq=False)
class GltfSampler:
    """Key times (K,) and values: (K, n) for LINEAR / STEP, (K, 3, n) (in-tangent, value,
    out-tangent) for CUBICSPLINE."""

    times: FloatArray
    values: FloatArray
    interpolation: str = "LINEAR"

    def evaluate(self, t: float, rotation: bool = False) -> FloatArray:
        times = self.times
        cubic = self.interpolation == "CUBICSPLINE"
        vals = self.values[:, 1] if cubic else self.values
        n = len(times)
        if t <= times[0] or n == 1:
            out = vals[0].copy()
        elif t >= times[-1]:
            out = vals[-1].copy()
        else:
            i = int(np.searchsorted(times, t, side="right")) - 1
            i = min(max(i, 0), n - 2)
            dt = float(times[i + 1] - times[i])
            u = (t - float(times[i])) / dt if dt > 0 else 0.0
            if self.interpolation == "STEP":
                out = vals[i].copy()
            elif cubic:
                p0, p1 = self.values[i, 1], self.values[i + 1, 1]
                m0, m1 = self.values[i, 2] * dt, self.values[i + 1, 0] * dt
                u2, u3 = u * u, u * u * u
                out = ((2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * m0
                       + (-2 * u3 + 3 * u2) * p1 + (u3 - u2) * m1)
            elif rotation:
                out = _slerp(vals[i], vals[i + 1], u)
            else:
                out = vals[i] * (1 - u) + vals[i + 1] * u
        if rotation:
            out = _normalize(out)
        return out


@dataclass(eq=False)
class GltfAnimationChannel:
    sampler: int
    node: int
    path: str


@dataclass(eq=False)
class GltfAnimation:
    samplers: list[GltfSampler]
    channels: list[GltfAnimationChannel]
    name: str = ""

    @property
    def start(self) -> float:
        return min((float(s.times[0]) for s in self.samplers), default=0.0)

    @property
    def end(self) -> float:
        return max((float(s.times[-1]) for s in self.samplers), default=0.0)


@dataclass(eq=False)
class GltfImage:
    """An image: embedded bytes (from a buffer view or a data URI) or an external ``uri``."""

    data: bytes | None = None
    mime_type: str | None = None
    uri: str | None = None
    name: str = ""


@dataclass(eq=False)
class GltfScene:
    """Everything :func:`import_gltf` reads; :func:`export_glb` writes it back."""

    nodes: list[GltfNode] = field(default_factory=list)
    meshes: list[GltfMesh] = field(default_factory=list)
    skins: list[GltfSkin] = field(default_factory=list)
    animations: list[GltfAnimation] = field(default_factory=list)
    roots: list[int] = field(default_factory=list)
    materials: list[dict[str, Any]] = field(default_factory=list)
    textures: list[dict[str, Any]] = field(default_factory=list)
    samplers: list[dict[str, Any]] = field(default_factory=list)
    images: list[GltfImage] = field(default_factory=list)
    generator: str = ""
    path: str | None = None

    # ------------------------------------------------------------------ structure
    def _order(self) -> list[int]:
        """Node indices with every parent before its children."""
        order: list[int] = []
        for i, n in enumerate(self.nodes):
            if n.parent is None:
                stack = [i]
                while stack:
                    k = stack.pop()
                    order.append(k)
                    stack.extend(reversed(self.nodes[k].children))
        return order

    def mesh_node(self, mesh_index: int) -> int | None:
        """The node that instantiates mesh ``mesh_index`` (one with a skin preferred)."""
        found = None
        for i, n in enumerate(self.nodes):
            if n.mesh == mesh_index:
                if n.skin is not None:
                    return i
                if found is None:
                    found = i
        return found

    # ------------------------------------------------------------------ pose
    def local_matrices(self, time: float | None = None, animation: int | None = 0) -> FloatArray:
        """(N, 4, 4) node local matrices at ``time`` seconds of ``animation`` (rest pose
        when ``time`` is None or there is no such animation)."""
        n = len(self.nodes)
        t = np.array([node.translation for node in self.nodes], dtype=np.float64).reshape(n, 3)
        r = np.array([node.rotation for node in self.nodes], dtype=np.float64).reshape(n, 4)
        s = np.array([node.scale for node in self.nodes], dtype=np.float64).reshape(n, 3)
        animated = np.zeros(n, dtype=bool)
        if time is not None and animation is not None and 0 <= animation < len(self.animations):
            anim = self.animations[animation]
            for ch in anim.channels:
                if ch.path == "weights":
                    continue
                value = anim.samplers[ch.sampler].evaluate(float(time), rotation=ch.path == "rotation")
                {"translation": t, "rotation": r, "scale": s}[ch.path][ch.node] = value
                animated[ch.node] = True
        out = trs_matrix(t, r, s) if n else np.zeros((0, 4, 4))
        for i, node in enumerate(self.nodes):
            if node.matrix is not None and not animated[i]:
                out[i] = node.matrix
        return out

    def world_matrices(self, time: float | None = None, animation: int | None = 0) -> FloatArray:
        """(N, 4, 4) node world matrices."""
        local = self.local_matrices(time, animation)
        world = np.empty_like(local)
        for i in self._order():
            p = self.nodes[i].parent
            world[i] = local[i] if p is None else world[p] @ local[i]
        return world

    def joint_world_matrices(self, skin_index: int, time: float | None = None,
                             animation: int | None = 0) -> FloatArray:
        """(J, 4, 4) world matrices of a skin's joints (what :mod:`core.skinning` expects)."""
        return self.world_matrices(time, animation)[self.skins[skin_index].joints]

    def joint_matrices(self, skin_index: int, time: float | None = None, animation: int | None = 0) -> FloatArray:
        """(J, 4, 4) skinning matrices ``global(joint) · inverseBind``."""
        skin = self.skins[skin_index]
        result: FloatArray = self.joint_world_matrices(skin_index, time, animation) @ skin.inverse_bind_matrices
        return result

    def skinned_positions(self, mesh_index: int, time: float | None = None, animation: int | None = 0,
                          primitive: int | None = None) -> FloatArray:
        """World-space positions of a mesh at ``time`` (all primitives stacked, or one).

        A skinned mesh uses linear blend skinning with the renormalised weights; an unskinned
        one is moved by its node's world matrix.
        """
        mesh = self.meshes[mesh_index]
        prims = mesh.primitives if primitive is None else [mesh.primitives[primitive]]
        node_index = self.mesh_node(mesh_index)
        node = self.nodes[node_index] if node_index is not None else None
        world = self.world_matrices(time, animation)
        out = []
        for prim in prims:
            p = prim.positions
            if node is not None and node.skin is not None and prim.joints is not None and prim.weights is not None:
                skin = self.skins[node.skin]
                mats = world[skin.joints] @ skin.inverse_bind_matrices  # (J, 4, 4)
                blended = np.einsum("vk,vkij->vij", prim.weights, mats[prim.joints][:, :, :3, :])
                out.append(np.einsum("vij,vj->vi", blended[:, :, :3], p) + blended[:, :, 3])
            else:
                m = world[node_index] if node_index is not None else np.eye(4)
                out.append(p @ m[:3, :3].T + m[:3, 3])
        return np.concatenate(out, axis=0) if out else np.zeros((0, 3))

    def to_skin(self, mesh_index: int, primitive: int = 0) -> Skin:
        """One primitive as a :class:`~qtanimator.core.skinning.Skin` over its node's skin.

        Pose it with ``core.skinning.skin_positions(skin, scene.joint_world_matrices(s, t))``.
        """
        node_index = self.mesh_node(mesh_index)
        if node_index is None or self.nodes[node_index].skin is None:
            raise ValueError(f"mesh {mesh_index} is not skinned")
        sk = self.skins[self.nodes[node_index].skin or 0]
        prim = self.meshes[mesh_index].primitives[primitive]
        if prim.joints is None or prim.weights is None:
            raise ValueError(f"mesh {mesh_index} primitive {primitive} has no JOINTS_0 / WEIGHTS_0")
        binding = SkinBinding.from_padded(prim.joints, prim.weights, len(sk.joints))
        return Skin(prim.positions.copy(), prim.triangles.copy(), binding, sk.inverse_bind_matrices.copy(),
                    normals=None if prim.normals is None else prim.normals.copy(),
                    texcoords=None if prim.texcoords is None else prim.texcoords.copy())

    def summary(self) -> dict[str, Any]:
        return {
            "kind": "glTF 2.0 scene",
            "generator": self.generator,
            "nodes": len(self.nodes),
            "meshes": [{"name": m.name, "primitives": len(m.primitives), "vertices": m.num_vertices,
                        "triangles": m.num_triangles,
                        "renormalized_vertices": sum(p.renormalized_vertices for p in m.primitives)}
                       for m in self.meshes],
            "skins": [{"name": s.name, "joints": len(s.joints)} for s in self.skins],
            "animations": [{"name": a.name, "channels": len(a.channels), "start": a.start, "end": a.end,
                            "interpolations": sorted({s.interpolation for s in a.samplers}),
                            "keys": int(sum(len(a.samplers[c.sampler].times) for c in a.channels))}
                           for a in self.animations],
            "materials": len(self.materials),
            "images": len(self.images),
        }
