"""Exporting one skeleton, one skin and ``.anim``-layout channels as a glTF scene, without a
document (the older path, kept for scripts and the format tests; File ▸ Export glTF… and
``qtanimator export`` use :mod:`qtanimator.document.gltf_export`, which writes whole document
characters with every influence): joints become nodes, each vertex keeps its strongest
influences, and the animation is sampled. :class:`CharacterExport` is the result both paths
return.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from qtanimator.core.channel import Channel
from qtanimator.core.rotation import euler_quaternions_with_rates
from qtanimator.core.skeleton import ROTATION_ORDERS, Skeleton
from qtanimator.core.skinning import Skin, SkinBinding, skin_positions
from qtanimator.formats.gltf.model import (
    FloatArray,
    GltfAnimation,
    GltfAnimationChannel,
    GltfMesh,
    GltfNode,
    GltfPrimitive,
    GltfSampler,
    GltfScene,
    GltfSkin,
    IntArray,
)
from qtanimator.formats.gltf.sampling import grid_times, with_key_times
from qtanimator.formats.gltf.writer import export_glb


class GltfExportWarning(UserWarning):
    """An export had to change the character (e.g. dropping influences beyond four)."""


@dataclass
class CharacterExport:
    """What :func:`export_character_glb` (or :func:`qtanimator.document.gltf_export.character_scene`,
    which keeps every influence) wrote and what it had to change."""

    scene: GltfScene
    #: the sample times (the whole-character export: every time of its first animation)
    times: FloatArray
    #: vertices that had more influences than the export keeps
    dropped_vertices: IntArray
    #: largest vertex displacement that dropping (the whole-character export: dividing the
    #: weights by their sums) caused, relative to the mesh's bounding-box diagonal
    max_relative_error: float
    joint_nodes: list[int]
    mesh_node: int


def _channel_values(skeleton: Skeleton, channels: Sequence[Channel | None], times: FloatArray,
                    derivative: int) -> FloatArray:
    """(T, 3 + 3J) channel values (root translation, then x, y, z per joint) at ``times``;
    missing channels hold the skeleton's current value (derivative 0)."""
    nj = len(skeleton.joints)
    if derivative == 0:
        base = np.concatenate([skeleton.root_translation, skeleton.dof_values().reshape(-1)])
    else:
        base = np.zeros(3 + 3 * nj)
    out = np.broadcast_to(base, (len(times), 3 + 3 * nj)).copy()
    for i, ch in enumerate(list(channels)[: 3 + 3 * nj]):
        if ch is not None:
            out[:, i] = ch.evaluate(times, derivative)
    return out


def _channel_label(skeleton: Skeleton, index: int) -> str:
    """``root translation x`` or ``<joint> x rotation`` for an ``.anim``-layout channel."""
    if index < 3:
        return f"root translation {'xyz'[index]}"
    joint, axis = divmod(index - 3, 3)
    return f"{skeleton.joints[joint].name} {'xyz'[axis]} rotation"


def _top_influences(binding: SkinBinding, k: int) -> tuple[IntArray, FloatArray, IntArray]:
    """(V, k) strongest joints and renormalised weights, and the vertices that lost some."""
    pidx, pw = binding.padded(np.float64)
    idx: IntArray = np.asarray(pidx, dtype=np.int64)
    w: FloatArray = np.asarray(pw, dtype=np.float64)
    nonzero = (w != 0).sum(axis=1)
    order = np.argsort(-w, axis=1, kind="stable")[:, :k]
    top_j: IntArray = np.take_along_axis(idx, order, axis=1)
    top_w: FloatArray = np.take_along_axis(w, order, axis=1)
    if top_j.shape[1] < k:
        pad = k - top_j.shape[1]
        top_j = np.pad(top_j, ((0, 0), (0, pad)))
        top_w = np.pad(top_w, ((0, 0), (0, pad)))
    sums = top_w.sum(axis=1)
    top_w = np.where(sums[:, None] > 0, top_w / np.where(sums > 0, sums, 1.0)[:, None], top_w)
    top_j = np.where(top_w != 0, top_j, 0)
    dropped = np.flatnonzero(nonzero > k).astype(np.int64)
    return top_j, top_w, dropped


def _as_skin(skeleton: Skeleton, skin_or_mesh: Any) -> Skin:
    if isinstance(skin_or_mesh, Skin):
        return skin_or_mesh
    if isinstance(skin_or_mesh, tuple) and len(skin_or_mesh) == 2:
        mesh, weights = skin_or_mesh
        positions = np.asarray(getattr(mesh, "positions", getattr(mesh, "vertices", None)), dtype=np.float64)
        triangles = np.asarray(getattr(mesh, "triangles", getattr(mesh, "faces", None)), dtype=np.int64)
        if isinstance(weights, SkinBinding):
            binding = weights
        else:
            dense = np.asarray(weights, dtype=np.float64)
            if dense.shape[1] == len(skeleton.joints) - 1:  # MIT .attach: no root column
                dense = np.concatenate([np.zeros((len(dense), 1)), dense], axis=1)
            binding = SkinBinding.from_dense(dense)
        normals = getattr(mesh, "normals", None)
        if normals is not None and np.shape(normals) != positions.shape:
            normals = None  # per-corner OBJ normals, not one per vertex
        return Skin.from_bind_matrices(positions, triangles, binding, skeleton.bind_world_matrices(),
                                       normals=normals)
    raise TypeError("expected a core.skinning.Skin or a (mesh, weights) pair")


def build_character_scene(skeleton: Skeleton, skin_or_mesh_with_weights: Any,
                          channels: Sequence[Channel | None] | Any, start: float, end: float, fps: float,
                          *, interpolation: str = "LINEAR", max_influences: int = 4,
                          weight_tolerance: float = 1e-4, name: str = "character",
                          key_times: bool = True) -> CharacterExport:
    """The glTF scene :func:`export_character_glb` writes (see there)."""
    if interpolation not in ("LINEAR", "CUBICSPLINE"):
        raise ValueError("interpolation must be LINEAR or CUBICSPLINE")
    if not 1 <= max_influences <= 4:
        raise ValueError("max_influences must be 1 to 4")
    skin = _as_skin(skeleton, skin_or_mesh_with_weights)
    chans: list[Channel | None] = list(getattr(channels, "channels", channels))
    nj = len(skeleton.joints)
    if skin.num_joints < nj and skin.binding.num_joints > skin.num_joints:
        raise ValueError("the skin has fewer bind matrices than the skeleton has joints")
    times = grid_times(start, end, fps)
    for i, chan in enumerate(chans[: 3 + 3 * nj]):
        if chan is not None and chan.is_weighted:
            warnings.warn(f"{name}: channel {i} ({_channel_label(skeleton, i)}) has weighted tangents, which glTF "
                          f"cannot hold: sampled at {fps:g} fps ({interpolation}).", GltfExportWarning, stacklevel=3)
    if key_times:
        times = with_key_times(times, [c for c in chans[: 3 + 3 * nj] if c is not None], start, end)
    lo, hi = skeleton.dof_limits()
    raw = _channel_values(skeleton, chans, times, 0)
    root_t = raw[:, :3]
    dofs = raw[:, 3:].reshape(len(times), nj, 3)
    clamped = np.clip(dofs, lo, hi)
    free = clamped == dofs
    cubic = interpolation == "CUBICSPLINE"
    rates_in = rates_out = root_in = root_out = None
    if cubic:
        # One-sided derivatives, so a key with different in and out slopes (a kink) that
        # falls on a sample keeps both.
        delta = 1e-7 * max(1.0, abs(start), abs(end))
        d_in = _channel_values(skeleton, chans, times - delta, 1)
        d_out = _channel_values(skeleton, chans, times + delta, 1)
        root_in, root_out = d_in[:, :3], d_out[:, :3]
        rates_in = np.where(free, d_in[:, 3:].reshape(len(times), nj, 3), 0.0)
        rates_out = np.where(free, d_out[:, 3:].reshape(len(times), nj, 3), 0.0)

    scene = GltfScene(generator="qtanimator")
    offsets = np.array([j.offset for j in skeleton.joints], dtype=np.float64).reshape(nj, 3)
    samplers: list[GltfSampler] = []
    anim_channels: list[GltfAnimationChannel] = []
    out_times = times - start
    for ji, joint in enumerate(skeleton.joints):
        order = joint.rotation_order or skeleton.rotation_order
        if order not in ROTATION_ORDERS:
            raise ValueError(f"unknown rotation order {order!r}")
        q, dq_in = euler_quaternions_with_rates(clamped[:, ji], None if rates_in is None else rates_in[:, ji], order)
        _, dq_out = euler_quaternions_with_rates(clamped[:, ji], None if rates_out is None else rates_out[:, ji], order)
        # Keep consecutive keys in one hemisphere so slerp takes the short way.
        sign = np.ones(len(q))
        for k in range(1, len(q)):
            sign[k] = sign[k - 1] * (-1.0 if np.dot(q[k], q[k - 1]) * sign[k - 1] < 0 else 1.0)
        q = q * sign[:, None]
        translation = offsets[ji] + (root_t if joint.parent is None else np.zeros_like(root_t))
        node = GltfNode(name=joint.name, translation=translation[0].copy(), rotation=q[0].copy())
        if joint.parent is not None:
            scene.nodes[joint.parent].children.append(ji)
            node.parent = joint.parent
        scene.nodes.append(node)
        if cubic:
            assert dq_in is not None and dq_out is not None
            rot_vals = np.stack([dq_in * sign[:, None], q, dq_out * sign[:, None]], axis=1)
        else:
            rot_vals = q
        samplers.append(GltfSampler(out_times, rot_vals, interpolation))
        anim_channels.append(GltfAnimationChannel(len(samplers) - 1, ji, "rotation"))
        if joint.parent is None:
            if cubic:
                assert root_in is not None and root_out is not None
                t_vals = np.stack([root_in, translation, root_out], axis=1)
            else:
                t_vals = translation
            samplers.append(GltfSampler(out_times, t_vals, interpolation))
            anim_channels.append(GltfAnimationChannel(len(samplers) - 1, ji, "translation"))

    top_j, top_w, dropped = _top_influences(skin.binding, max_influences)
    max_rel = 0.0
    if len(dropped):
        # How much does dropping influences move the animated mesh? Compare with all the
        # influences (renormalised, so unnormalised source weights do not count as a change).
        full = Skin(skin.positions, skin.triangles, skin.binding.renormalized(), skin.inverse_bind_matrices)
        reduced = Skin(skin.positions, skin.triangles, SkinBinding.from_padded(top_j, top_w, skin.binding.num_joints),
                       skin.inverse_bind_matrices)
        diag = float(np.linalg.norm(np.ptp(skin.positions, axis=0))) or 1.0
        step = max(1, len(times) // 64)
        for k in range(0, len(times), step):
            world = skeleton.world_matrices(clamped[k], root_t[k])
            err = np.linalg.norm(skin_positions(full, world) - skin_positions(reduced, world), axis=1)
            max_rel = max(max_rel, float(err.max()) / diag)
        if max_rel > weight_tolerance:
            warnings.warn(f"{name}: {len(dropped)} vertices have more than {max_influences} influences; keeping "
                          f"the strongest {max_influences} moves the animated mesh by up to {max_rel:.2e} of its "
                          f"size.", GltfExportWarning, stacklevel=3)
    normals = None if skin.normals is None else np.asarray(skin.normals, dtype=np.float64)
    texcoords = None
    if skin.texcoords is not None and np.shape(skin.texcoords)[1] >= 2:
        # Our texture coordinates follow OpenGL (v up from the bottom of the image);
        # glTF puts the origin at the top left.
        texcoords = np.asarray(skin.texcoords, dtype=np.float64)[:, :2].copy()
        texcoords[:, 1] = 1.0 - texcoords[:, 1]
    prim = GltfPrimitive(np.asarray(skin.positions, dtype=np.float64), np.asarray(skin.triangles, dtype=np.int64),
                         normals, texcoords, top_j, top_w)
    scene.meshes.append(GltfMesh([prim], name))
    roots = [i for i, j in enumerate(skeleton.joints) if j.parent is None]
    scene.skins.append(GltfSkin(list(range(nj)), np.asarray(skin.inverse_bind_matrices[:nj], dtype=np.float64),
                                roots[0] if roots else None, name))
    mesh_node = len(scene.nodes)
    scene.nodes.append(GltfNode(name=name, mesh=0, skin=0))
    scene.roots = roots + [mesh_node]
    scene.animations.append(GltfAnimation(samplers, anim_channels, name))
    return CharacterExport(scene, times, dropped, max_rel, list(range(nj)), mesh_node)


def export_character_glb(path: str | os.PathLike[str], skeleton: Skeleton, skin_or_mesh_with_weights: Any,
                         channels: Sequence[Channel | None] | Any, start: float, end: float, fps: float,
                         *, interpolation: str = "LINEAR", max_influences: int = 4,
                         weight_tolerance: float = 1e-4, name: str = "character",
                         key_times: bool = True) -> CharacterExport:
    """Write a skinned, animated character to ``.glb``.

    ``skin_or_mesh_with_weights`` is a :class:`~qtanimator.core.skinning.Skin`, or a pair
    ``(mesh, weights)`` with a mesh that has ``positions`` / ``triangles`` (or ``vertices`` /
    ``faces``) and weights as a :class:`SkinBinding` or a dense (V, J) or MIT (V, J − 1)
    array; such a mesh is bound in the skeleton's zero pose. ``channels`` use the ``.anim``
    layout (root translation x, y, z, then x, y, z per joint; an :class:`AnimationClip`
    works too); missing channels hold the skeleton's current values and DOFs are clamped to
    their limits. The clip is sampled at ``fps`` from ``start`` to ``end`` (both included);
    exported time 0 is ``start``. With ``key_times`` the channels' key times (cycled ones
    too) are sampled as well, so keys and kinks are not cut off by the grid.
    ``interpolation="CUBICSPLINE"`` stores the channels' one-sided derivatives as in / out
    tangents, so the curve between samples follows the channels closely.

    Vertices keep their ``max_influences`` strongest joints, renormalised; when that moves the
    animated mesh by more than ``weight_tolerance`` × its bounding-box diagonal, a
    :class:`GltfExportWarning` is issued.
    """
    result = build_character_scene(skeleton, skin_or_mesh_with_weights, channels, start, end, fps,
                                   interpolation=interpolation, max_influences=max_influences,
                                   weight_tolerance=weight_tolerance, name=name, key_times=key_times)
    export_glb(path, result.scene)
    return result
