"""Importing 3D files into the document and exporting 3D characters to glTF.

Every ``*_command`` function reads its files first (a :class:`FormatError` leaves the
document untouched) and returns an :class:`Import`: **one** undoable command plus notes for
the user (companion files that were picked up, approximations). The GUI's openers
(:mod:`qtanimator.ui.import3d`) push the command.

* ``.skel``: the skeleton with the companions of the same stem in its folder: ``.skin`` and
  ``.anim`` (balljoint), ``.obj`` and ``.attach`` (MIT). Without an ``.anim`` of the same stem,
  the folder's only ``.anim`` is used; among several, the one whose name starts with the
  skeleton's stem and is a prefix of every other such name (``wasp.skel`` →
  ``wasp_walk.anim`` next to ``wasp_walk_crlf.anim``).
* ``.skin``: replaces the skin of a character, or brings the ``.skel`` of the same stem.
* ``.anim``: replaces a character's channels (:func:`load_anim_command`).
* ``.obj``: an MIT mesh with its ``.skel`` (required) and ``.attach`` of the same stem.
* ``.bvh``: skeleton (a rotation order per joint) and motion as channels with linear keys.
* ``.glb`` / ``.gltf``: the first skinned mesh (all its skinned primitives), its skin's
  joints as a DOF skeleton, and the first animation sampled onto DOF channels (below).

An import that brings a clip longer than the document's frame range also lengthens the range
(in the same undo step), so the whole clip plays.

glTF joints have a rest rotation, a translation and a scale each, and may hang below
non-joint nodes; our joints are ``T(offset)·R(θ)`` with only the root translating. The
mapping: every joint's glTF world matrix ``M = [A | t]`` is split (polar decomposition) into a
rotation ``R`` and a stretch ``P = Rᵀ A``; the skeleton reproduces the rigid ``[R | t]`` and the
stretch of the rest pose goes into the inverse bind matrix (``P · IBM``), so skinning
``W · IBM`` is unchanged. This is exact as long as the joints' scales are not animated and
only the root's translation is (both true of the Khronos samples up to rounding); otherwise
the sampled pose is the nearest rigid one and the import says so in its notes. Rotations
are sampled (key times plus the document's fps grid) into Euler angles unwrapped over time,
held by channels with linear keys.
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.core.channel import Channel, Extrapolation, Interpolation, Key, Tangent
from qtanimator.core.skeleton import DEFAULT_BOXMAX, DEFAULT_BOXMIN, Joint, Skeleton
from qtanimator.core.skinning import Skin, SkinBinding
from qtanimator.document.character3d import (
    ASSET_KIND,
    BVH_POSITIONS,
    Character3D,
    _channel_ids,
    add_character3d_command,
    channel_ids,
    character,
    load_anim_command,
    load_bvh_character,
)
from qtanimator.document.commands import AddAsset, Command, Macro, SetParameter
from qtanimator.document.document import Asset, Document
from qtanimator.formats.anim import load_anim
from qtanimator.formats.errors import FormatError
from qtanimator.formats.gltf import (
    CharacterExport,
    GltfExportWarning,
    GltfScene,
    export_character_glb,
    import_gltf,
)
from qtanimator.formats.skel import load_skel
from qtanimator.formats.skin import load_skin

FloatArray = npt.NDArray[np.float64]

SUFFIXES = (".skel", ".skin", ".anim", ".obj", ".bvh", ".glb", ".gltf")
GLTF_SUFFIXES = (".glb", ".gltf")
#: Euler order of the joints built from glTF (R = Rz·Ry·Rx, the balljoint order).
GLTF_ROTATION_ORDER = "zyx"
#: Most samples taken from one glTF animation.
MAX_SAMPLES = 20_000

__all__ = [
    "GLTF_SUFFIXES", "GltfCharacter", "Import", "SUFFIXES", "anim_import", "bvh_import", "companions",
    "export_gltf", "gltf_character", "gltf_import", "import_file", "load_gltf_character_asset", "obj_import",
    "skel_import", "skin_import", "target_character",
]


@dataclass
class Import:
    """One undoable command that adds what a file brought, the asset it concerns, and notes
    for the user (files picked up alongside, approximations made)."""

    command: Command
    asset_id: str
    notes: list[str] = field(default_factory=list)


# --------------------------------------------------------------------- companions
def _same_stem(folder: Path, stem: str, suffix: str) -> Path | None:
    exact = folder / f"{stem}{suffix}"
    if exact.is_file():
        return exact
    for p in sorted(folder.iterdir()):
        if p.is_file() and p.stem.lower() == stem.lower() and p.suffix.lower() == suffix:
            return p
    return None


def _folder_anim(folder: Path, stem: str) -> Path | None:
    """The folder's ``.anim`` for a skeleton without one of its own stem (see the module doc)."""
    anims = sorted(p for p in folder.iterdir() if p.is_file() and p.suffix.lower() == ".anim")
    if len(anims) == 1:
        return anims[0]
    named = [p for p in anims if p.stem.lower().startswith(stem.lower())]
    if not named:
        return None
    shortest = min(named, key=lambda p: (len(p.stem), p.name))
    if all(p.stem.lower().startswith(shortest.stem.lower()) for p in named):
        return shortest
    return None


def companions(skel_path: str | os.PathLike[str], dialect: str | None = None) -> dict[str, Path]:
    """The files that belong with a ``.skel``: keys ``skin``, ``anim``, ``obj``, ``attach``.

    ``dialect`` ("balljoint" or "mit", read from the file when None) decides whether a
    ``.skin`` or an ``.obj`` + ``.attach`` pair is looked for.
    """
    p = Path(skel_path)
    folder, stem = p.parent, p.stem
    if dialect is None:
        dialect = load_skel(p).dialect
    found: dict[str, Path] = {}
    kinds = ("obj", "attach") if dialect == "mit" else ("skin",)
    for kind in (*kinds, "anim"):
        c = _same_stem(folder, stem, f".{kind}")
        if c is not None:
            found[kind] = c
    if "anim" not in found and dialect != "mit":
        a = _folder_anim(folder, stem)
        if a is not None:
            found["anim"] = a
    return found


# ------------------------------------------------------------------------ helpers
def target_character(doc: Document, selected: str | None) -> str | None:
    """The selected 3D character, else the only one in the document, else None."""
    if selected and selected in doc.assets and doc.assets[selected].kind == ASSET_KIND:
        return selected
    ids = [a.id for a in doc.assets.values() if a.kind == ASSET_KIND]
    return ids[0] if len(ids) == 1 else None


def _end_frame(doc: Document, end_time: float) -> int | None:
    """The frame the document's range must end at to show ``end_time`` (None: it does)."""
    end_frame = int(math.ceil(doc.time_to_frame(end_time) - 1e-6))
    return end_frame if end_frame > doc.frame_range[1] else None


def _channels_end(channels: Sequence[Channel | None]) -> float:
    return max((float(c.keys[-1].time) for c in channels if c is not None and c.keys), default=0.0)


def _with_range(doc: Document, text: str, add: Command, end_time: float, asset_id: str,
                notes: list[str]) -> Import:
    end_frame = _end_frame(doc, end_time)
    if end_frame is not None:
        notes.append(f"Frame range extended to {doc.frame_range[0]}–{end_frame} to show the whole clip.")
        return Import(Macro(text, [add, SetParameter(doc, "frame_end", end_frame)]), asset_id, notes)
    return Import(add, asset_id, notes)


def _linear_channel(times: Sequence[float], values: Sequence[float]) -> Channel:
    keys = [Key(float(t), float(v), Tangent.LINEAR, Tangent.LINEAR, interpolation=Interpolation.LINEAR)
            for t, v in zip(times, values)]
    return Channel(keys, Extrapolation.CONSTANT, Extrapolation.CONSTANT)


# -------------------------------------------------------------------- .skel / .obj
def skel_import(doc: Document, path: str | os.PathLike[str]) -> Import:
    """A ``.skel`` with its companions (see :func:`companions`)."""
    p = Path(path)
    skeleton = load_skel(p)
    found = companions(p, skeleton.dialect)
    notes = [f"Also loaded {', '.join(found[k].name for k in sorted(found))}."] if found else []
    try:
        cmd = add_character3d_command(doc, p, found.get("skin"), found.get("anim"), found.get("obj"),
                                      found.get("attach"))
    except FormatError:
        anim = found.get("anim")
        if anim is None or _same_stem(p.parent, p.stem, ".anim") is not None:
            raise
        # An animation guessed from the folder that does not fit is left out, not an error.
        cmd = add_character3d_command(doc, p, found.get("skin"), None, found.get("obj"), found.get("attach"))
        notes = [f"{anim.name} does not fit {p.name} and was not loaded."]
    assert isinstance(cmd, AddAsset)
    clip = cmd.runtime.clip
    return _with_range(doc, cmd.text, cmd, clip.end if clip is not None else 0.0, cmd.asset.id, notes)


def obj_import(doc: Document, path: str | os.PathLike[str]) -> Import:
    """An MIT ``.obj`` mesh: needs the ``.skel`` of the same stem; uses its ``.attach``."""
    p = Path(path)
    skel = _same_stem(p.parent, p.stem, ".skel")
    if skel is None:
        raise FormatError(f"an .obj mesh is imported with its skeleton: {p.stem}.skel was not found next "
                          "to it.", p)
    attach = _same_stem(p.parent, p.stem, ".attach")
    notes = [f"Loaded with {skel.name}" + (f" and {attach.name}." if attach else
                                           f"; no {p.stem}.attach, so the mesh rides on the root joint.")]
    cmd = add_character3d_command(doc, skel, obj_path=p, attach_path=attach)
    assert isinstance(cmd, AddAsset)
    return Import(cmd, cmd.asset.id, notes)


def skin_import(doc: Document, path: str | os.PathLike[str], selected: str | None = None) -> Import:
    """A ``.skin``: on the selected 3D character, else with the ``.skel`` of the same stem,
    else on the document's only 3D character."""
    p = Path(path)
    skel = _same_stem(p.parent, p.stem, ".skel")
    target = selected if selected and selected in doc.assets and doc.assets[selected].kind == ASSET_KIND else None
    if target is None and skel is not None:
        anim = _same_stem(p.parent, p.stem, ".anim")
        cmd = add_character3d_command(doc, skel, p, anim)
        assert isinstance(cmd, AddAsset)
        notes = [f"Loaded with {skel.name}" + (f" and {anim.name}." if anim else ".")]
        clip = cmd.runtime.clip
        return _with_range(doc, cmd.text, cmd, clip.end if clip is not None else 0.0, cmd.asset.id, notes)
    target = target or target_character(doc, None)
    if target is None:
        raise FormatError(f"a skin needs a skeleton: select a 3D character, or put {p.stem}.skel next to "
                          "the skin.", p)
    asset = doc.assets[target]
    if not asset.source or Path(asset.source).suffix.lower() != ".skel":
        raise FormatError(f"a .skin file can only dress a character loaded from a .skel file; "
                          f"{target!r} comes from {Path(asset.source or '?').name}.", p)
    old = character(doc, target)
    skin = load_skin(p, num_joints=len(old.skeleton.joints))
    runtime = Character3D(old.skeleton, skin, None, old.clip, False)
    props = dict(asset.properties)
    for name in ("obj_file", "attach_file"):
        props.pop(name, None)
    props["skin_file"] = str(p.resolve())
    new_asset = Asset(asset.id, asset.kind, asset.source, props)
    return Import(AddAsset(new_asset, runtime, text=f"Load skin {p.name}"), target, [])


def anim_import(doc: Document, path: str | os.PathLike[str], selected: str | None = None) -> Import:
    """An ``.anim`` on the selected (or only) 3D character."""
    p = Path(path)
    target = target_character(doc, selected)
    if target is None:
        have = sum(1 for a in doc.assets.values() if a.kind == ASSET_KIND)
        why = "there is no 3D character to animate" if have == 0 else f"there are {have} 3D characters"
        raise FormatError(f"an .anim file animates the selected 3D character, and {why}: open or select "
                          "a skeleton first.", p)
    clip = load_anim(p)
    cmd = load_anim_command(doc, target, p, clip)
    return _with_range(doc, cmd.text, cmd, clip.end, target, [f"Applied to {target}."])


# ---------------------------------------------------------------------------- BVH
def bvh_import(doc: Document, path: str | os.PathLike[str]) -> Import:
    """A ``.bvh`` file as a 3D character with its motion in the document's channels."""
    p = Path(path)
    runtime, chans = load_bvh_character(p)
    aid = doc.unique_asset_id(_asset_base(p))
    ids = _channel_ids(aid, runtime.skeleton.joint_keys())
    channels = {cid: ch for cid, ch in zip(ids, chans) if ch is not None}
    # The root-position convention detected (or chosen later in Properties) is saved with
    # the asset; the notes say which one was used and what was ignored.
    asset = Asset(aid, ASSET_KIND, str(p.resolve()), {BVH_POSITIONS: runtime.positions})
    add = AddAsset(asset, runtime, channels, text=f"Add 3D character {aid}")
    n = max((len(c.keys) for c in channels.values()), default=0)
    notes = [f"{len(runtime.skeleton.joints)} joints, {n} frames.", *runtime.notes]
    return _with_range(doc, add.text, add, _channels_end(list(channels.values())), aid, notes)


def _asset_base(p: Path) -> str:
    base = p.stem.replace("/", "_") or "character"
    return base


# --------------------------------------------------------------------------- glTF
@dataclass
class GltfCharacter:
    """What a glTF file maps to: the character, its sampled channels (``.anim`` layout,
    None where a DOF does not move) and notes on approximations."""

    character: Character3D
    channels: list[Channel | None]
    times: FloatArray
    mesh: int | None
    skin: int
    notes: list[str]


def _polar(m: FloatArray) -> tuple[FloatArray, FloatArray]:
    """(…, 3, 3) → rotation R and stretch P with m = R · P."""
    u, _s, vt = np.linalg.svd(m)
    d = np.sign(np.linalg.det(u @ vt))
    u = u.copy()
    u[..., :, 2] *= d[..., None]
    r = u @ vt
    return r, np.swapaxes(r, -1, -2) @ m


def euler_from_matrices(r: FloatArray, order: str) -> FloatArray:
    """(N, 3, 3) rotations → (N, 3) angles (x, y, z) with ``r = R_a·R_b·R_c`` for ``order`` "abc"."""
    a, b, c = ("xyz".index(ch) for ch in order)
    # r = Ra·Rb·Rc: the standard Tait–Bryan extraction, signed by the order's parity.
    sign = 1.0 if (b - a) % 3 == 1 else -1.0
    sb = np.clip(sign * r[:, a, c], -1.0, 1.0)
    angle_b = np.arcsin(sb)
    angle_a = np.arctan2(-sign * r[:, b, c], r[:, c, c])
    angle_c = np.arctan2(-sign * r[:, a, b], r[:, a, a])
    lock = np.abs(sb) > 1.0 - 1e-12
    if np.any(lock):
        # Gimbal lock: put the whole turn on the first axis.
        angle_c = np.where(lock, 0.0, angle_c)
        angle_a = np.where(lock, np.arctan2(sign * r[:, c, b], r[:, b, b]), angle_a)
    out = np.zeros((len(r), 3))
    out[:, a], out[:, b], out[:, c] = angle_a, angle_b, angle_c
    return out


def _skinned_mesh_index(scene: GltfScene) -> int | None:
    for mi, mesh in enumerate(scene.meshes):
        node = scene.mesh_node(mi)
        if node is None or scene.nodes[node].skin is None:
            continue
        if any(prim.joints is not None and prim.weights is not None for prim in mesh.primitives):
            return mi
    return None


def _gltf_skin(scene: GltfScene, mesh: int) -> Skin:
    """All skinned primitives of ``mesh`` as one skin (joint indices of the glTF skin)."""
    parts = [scene.to_skin(mesh, k) for k, prim in enumerate(scene.meshes[mesh].primitives)
             if prim.joints is not None and prim.weights is not None]
    if len(parts) == 1:
        return parts[0]
    offsets = np.cumsum([0] + [s.num_vertices for s in parts])
    nv = int(offsets[-1])
    binding = SkinBinding(np.concatenate([s.binding.vertex + o for s, o in zip(parts, offsets)]),
                          np.concatenate([s.binding.joint for s in parts]),
                          np.concatenate([s.binding.weight for s in parts]), nv, parts[0].binding.num_joints)
    normals = (np.concatenate([s.normals for s in parts]) if all(s.normals is not None for s in parts)
               else None)
    return Skin(np.concatenate([s.positions for s in parts]),
                np.concatenate([s.triangles + o for s, o in zip(parts, offsets)]), binding,
                parts[0].inverse_bind_matrices, normals=normals)


def _joint_name(scene: GltfScene, node: int, k: int) -> str:
    name = scene.nodes[node].name.strip()
    return name or f"joint{k}"


def gltf_character(scene: GltfScene, fps: float = 30.0, *, sample: bool = True,
                   mesh: int | None = None) -> GltfCharacter:
    """Map a glTF scene to a character (see the module doc). ``mesh`` None picks the first
    skinned mesh; a file with skins but no skinned mesh gives a skeleton alone."""
    path = scene.path
    if mesh is None:
        mesh = _skinned_mesh_index(scene)
    if mesh is not None:
        node = scene.mesh_node(mesh)
        if node is None or scene.nodes[node].skin is None:
            raise FormatError(f"mesh {mesh} of the glTF file is not skinned.", path)
        skin_index = int(scene.nodes[node].skin or 0)
    elif scene.skins:
        skin_index = 0
    else:
        raise FormatError("the glTF file has no skin (no skeleton), so it cannot be imported as a 3D "
                          "character.", path)
    gskin = scene.skins[skin_index]
    jnodes = list(gskin.joints)
    if not jnodes:
        raise FormatError("the glTF skin has no joints.", path)
    in_skin = {n: k for k, n in enumerate(jnodes)}
    if len(in_skin) != len(jnodes):
        raise FormatError("the glTF skin lists a joint twice.", path)

    # The joint forest: each joint's parent is its nearest ancestor that is a joint.
    parent_of: dict[int, int | None] = {}
    for n in jnodes:
        a = scene.nodes[n].parent
        while a is not None and a not in in_skin:
            a = scene.nodes[a].parent
        parent_of[n] = a
    children: dict[int | None, list[int]] = {}
    for n in jnodes:
        children.setdefault(parent_of[n], []).append(n)
    roots = children.get(None, [])
    synthetic = len(roots) != 1
    order: list[int] = []  # glTF node per skeleton joint (-1 = synthetic root)
    parents: list[int | None] = []
    if synthetic:
        order.append(-1)
        parents.append(None)
    stack: list[tuple[int, int | None]] = [(r, 0 if synthetic else None) for r in reversed(roots)]
    while stack:
        n, p = stack.pop()
        order.append(n)
        parents.append(p)
        idx = len(order) - 1
        stack.extend((c, idx) for c in reversed(children.get(n, [])))
    nj = len(order)
    perm = np.array([order.index(n) for n in jnodes], dtype=np.intp)

    def rigid_locals(world_nodes: FloatArray) -> tuple[FloatArray, FloatArray]:
        """(T, N, 4, 4) node worlds → (T, J, 4, 4) rigid joint locals and (T, J, 3, 3) stretches."""
        t = world_nodes.shape[0]
        w = np.tile(np.eye(4), (t, nj, 1, 1))
        stretch = np.tile(np.eye(3), (t, nj, 1, 1))
        real = [i for i, n in enumerate(order) if n >= 0]
        nodes_idx = [order[i] for i in real]
        r, pmat = _polar(world_nodes[:, nodes_idx, :3, :3])
        w[:, real, :3, :3] = r
        w[:, real, :3, 3] = world_nodes[:, nodes_idx, :3, 3]
        stretch[:, real] = pmat
        local = w.copy()
        for i, p in enumerate(parents):
            if p is not None:
                local[:, i] = np.linalg.inv(w[:, p]) @ w[:, i]
        return local, stretch

    rest_local, rest_stretch = rigid_locals(scene.world_matrices(None)[None])
    rest_local, rest_stretch = rest_local[0], rest_stretch[0]
    joints: list[Joint] = []
    names = [("root" if n < 0 else _joint_name(scene, n, k)) for k, n in enumerate(order)]
    rest_angles = euler_from_matrices(rest_local[:, :3, :3], GLTF_ROTATION_ORDER)
    for i in range(nj):
        offset = np.zeros(3) if parents[i] is None else rest_local[i, :3, 3].copy()
        joints.append(Joint(names[i], parents[i], offset, boxmin=np.array(DEFAULT_BOXMIN),
                            boxmax=np.array(DEFAULT_BOXMAX), rotation_order=GLTF_ROTATION_ORDER))
    skeleton = Skeleton(joints, rotation_order=GLTF_ROTATION_ORDER,
                        name=Path(path).stem if path else "", dialect="gltf")
    skeleton.root_translation = rest_local[0, :3, 3].copy()
    for i in range(nj):
        for a in range(3):
            skeleton.set_dof(i, a, float(rest_angles[i, a]))

    notes: list[str] = []
    skin: Skin | None = None
    if mesh is not None:
        gs = _gltf_skin(scene, mesh)
        ibm = np.tile(np.eye(4), (nj, 1, 1))
        stretch4 = np.tile(np.eye(4), (len(jnodes), 1, 1))
        stretch4[:, :3, :3] = rest_stretch[perm]
        ibm[perm] = stretch4 @ gs.inverse_bind_matrices[: len(jnodes)]
        binding = SkinBinding(gs.binding.vertex, perm[gs.binding.joint], gs.binding.weight, gs.num_vertices, nj)
        skin = Skin(gs.positions, gs.triangles, binding, ibm, normals=gs.normals, texcoords=gs.texcoords)
    else:
        notes.append("The file has no skinned mesh: only its skeleton was imported.")
    if synthetic:
        notes.append(f"The skin has {len(roots)} root joints; they hang below an added joint 'root' "
                     "and only its translation is animated.")

    channels: list[Channel | None] = [None] * (3 + 3 * nj)
    times = np.zeros(0)
    if sample and scene.animations:
        anim = scene.animations[0]
        times = _gltf_sample_times(anim.samplers, anim.start, anim.end, fps)
        worlds = np.stack([scene.world_matrices(float(t), 0) for t in times])
        local, stretch = rigid_locals(worlds)
        angles = euler_from_matrices(local[:, :, :3, :3].reshape(-1, 3, 3), GLTF_ROTATION_ORDER)
        angles = np.unwrap(angles.reshape(len(times), nj, 3), axis=0)
        # Keep the sampled angles on the same turn as the rest pose.
        angles -= 2 * np.pi * np.round((angles[0] - rest_angles) / (2 * np.pi))[None]
        values = np.concatenate([local[:, 0, :3, 3], angles.reshape(len(times), -1)], axis=1)
        rest = np.concatenate([skeleton.root_translation, rest_angles.reshape(-1)])
        tl = times.tolist()
        for c in range(values.shape[1]):
            col = values[:, c]
            if np.max(np.abs(col - rest[c])) > 1e-9:
                channels[c] = _linear_channel(tl, col.tolist())
        moved = np.abs(local[:, 1:, :3, 3] - rest_local[None, 1:, :3, 3]).max() if nj > 1 else 0.0
        size = float(np.ptp(rest_local[:, :3, 3], axis=0).max()) or 1.0
        if moved > 1e-4 * size:
            notes.append(f"Joints below the root move (up to {moved:.3g}) in the animation; our joints only "
                         "rotate, so that motion is left out.")
        if np.abs(stretch - rest_stretch[None]).max() > 1e-4:
            notes.append("The animation scales joints; scaling is left out (the pose is the nearest rigid one).")
        notes.append(f"Animation {anim.name or 0!s} sampled onto joint channels at {len(times)} times "
                     f"with linear keys ({anim.start:g}–{anim.end:g} s).")
        if len(scene.animations) > 1:
            notes.append(f"Only the first of {len(scene.animations)} animations was imported.")
    ch = Character3D(skeleton, skin, None, None, False)
    return GltfCharacter(ch, channels, times, mesh, skin_index, notes)


def _gltf_sample_times(samplers: Sequence[Any], start: float, end: float, fps: float) -> FloatArray:
    keys = [np.asarray(s.times, dtype=np.float64) for s in samplers]
    n = int(math.floor((end - start) * fps + 1e-9)) + 1 if end > start else 1
    grid = start + np.arange(min(n, MAX_SAMPLES), dtype=np.float64) / fps
    allt = np.concatenate([grid, *keys, [start, end]])
    allt = np.unique(allt[(allt >= start) & (allt <= end)])
    keep = np.concatenate([[True], np.diff(allt) > 1e-6])
    times: FloatArray = allt[keep][:MAX_SAMPLES]
    return times


def load_gltf_character_asset(asset: Asset) -> Character3D:
    """The runtime of a character whose source is a ``.glb`` / ``.gltf`` (a project being opened)."""
    if not asset.source:
        raise FormatError(f"3D character {asset.id!r} has no source file.")
    mesh = asset.properties.get("gltf_mesh")
    scene = import_gltf(asset.source)
    if mesh is not None and not (isinstance(mesh, int) and 0 <= mesh < len(scene.meshes)):
        raise FormatError(f"3D character {asset.id!r}: the glTF file has no mesh {mesh!r}.", asset.source)
    return gltf_character(scene, sample=False, mesh=mesh).character


def gltf_import(doc: Document, path: str | os.PathLike[str]) -> Import:
    """A ``.glb`` / ``.gltf``: first skinned mesh, its skeleton and first animation."""
    p = Path(path)
    scene = import_gltf(p)
    g = gltf_character(scene, doc.fps)
    aid = doc.unique_asset_id(_asset_base(p))
    ids = _channel_ids(aid, g.character.skeleton.joint_keys())
    channels = {cid: ch for cid, ch in zip(ids, g.channels) if ch is not None}
    props: dict[str, Any] = {}
    if g.mesh is not None:
        props["gltf_mesh"] = g.mesh
    asset = Asset(aid, ASSET_KIND, str(p.resolve()), props)
    add = AddAsset(asset, g.character, channels, text=f"Add 3D character {aid}")
    return _with_range(doc, add.text, add, _channels_end(list(channels.values())), aid, list(g.notes))


# --------------------------------------------------------------------------- any
def import_file(doc: Document, path: str | os.PathLike[str], selected: str | None = None) -> Import:
    """Import any 3D file by its suffix (FormatError for an unknown one)."""
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix == ".skel":
        return skel_import(doc, p)
    if suffix == ".skin":
        return skin_import(doc, p, selected)
    if suffix == ".anim":
        return anim_import(doc, p, selected)
    if suffix == ".obj":
        return obj_import(doc, p)
    if suffix == ".bvh":
        return bvh_import(doc, p)
    if suffix in GLTF_SUFFIXES:
        return gltf_import(doc, p)
    raise FormatError("not a 3D file qtanimator can import.", p)


# ------------------------------------------------------------------------- export
def export_gltf(doc: Document, asset_id: str, path: str | os.PathLike[str]) -> tuple[CharacterExport, list[str]]:
    """Write a 3D character and its channels to ``.glb`` over the document's frame range at
    its fps. Returns the export and the warnings it gave (:class:`GltfExportWarning`).

    Raises ValueError when the character has no skin or mesh; OSError when writing fails.
    """
    ch = character(doc, asset_id)
    if ch.skin is None:
        raise ValueError(f"3D character {asset_id!r} has no skin or mesh to export.")
    chans: list[Channel | None] = [doc.channels.get(cid) for cid in channel_ids(doc, asset_id)]
    first, last = doc.frame_range
    start, end = doc.frame_to_time(first), doc.frame_to_time(last)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", GltfExportWarning)
        result = export_character_glb(path, ch.skeleton, ch.skin, chans, start, max(start, end), doc.fps,
                                      name=asset_id)
    messages = [str(w.message) for w in caught if issubclass(w.category, GltfExportWarning)]
    for w in caught:
        if not issubclass(w.category, GltfExportWarning):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return result, messages
