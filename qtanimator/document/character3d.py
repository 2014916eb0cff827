"""3D characters in the document: a skeleton, an optional skin, and their channels.

An asset of kind :data:`ASSET_KIND` has the ``.skel`` file as its ``source`` and the
optional properties ``skin_file`` and ``anim_file`` (CSE 169) or ``obj_file`` and
``attach_file`` (MIT 6.837). The source may also be a ``.bvh`` file (skeleton with one
rotation order per joint; its motion lives in the document's channels) or a ``.glb`` /
``.gltf`` file (see :mod:`qtanimator.document.import3d`). The loaded :class:`Character3D`
lives in ``doc.runtime``.

Channels (document channel ids):

* ``"<asset>//tx"``, ``"<asset>//ty"``, ``"<asset>//tz"``: root translation;
* ``"<asset>/<joint key>/rx|ry|rz"``: joint rotations (radians), where the joint key is
  the joint's name, or ``name#index`` when several joints share the name (the dragon).

A DOF with no channel keeps the value the ``.skel`` file gave it. Channel values are
clamped to the DOF limits when the skeleton is posed.
"""

from __future__ import annotations

import os
from collections.abc import Hashable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.core.channel import Channel, Key
from qtanimator.core.clip import ROOT, AnimationClip, channel_count, channel_target
from qtanimator.core.skeleton import DEFAULT_BOXMAX, DEFAULT_BOXMIN, Skeleton, axis_index
from qtanimator.core.skinning import (
    Skin,
    SkinBinding,
    bind_to_skeleton,
    skin_positions,
    skin_positions_and_normals,
    vertex_normals,
)
from qtanimator.document.commands import AddAsset, Command, Macro, SetAssetProperty, SetChannels, SetKeys
from qtanimator.document.document import Asset, Document, channel_id
from qtanimator.document.pose import pending_values
from qtanimator.formats.anim import load_anim
from qtanimator.formats.attach import load_attach
from qtanimator.formats.bvh import POSITION_CONVENTIONS, load_bvh
from qtanimator.formats.errors import FormatError
from qtanimator.formats.obj import Mesh, load_obj
from qtanimator.formats.skel import load_skel
from qtanimator.formats.skin import load_skin

FloatArray = npt.NDArray[np.float64]

ASSET_KIND = "character3d"
ROOT_DOFS = ("tx", "ty", "tz")
JOINT_DOFS = ("rx", "ry", "rz")

__all__ = [
    "ASSET_KIND", "BVH_POSITIONS", "BvhCharacter", "Character3D", "add_character3d_command", "bvh_positions",
    "bvh_positions_note", "channel_dofs", "channel_ids", "character", "clip_from_document", "dof_channel_id",
    "dof_values", "ik_values", "load_anim_command", "load_bvh_character", "load_character3d",
    "load_character3d_asset", "pose_skeleton", "set_bvh_positions_command", "set_dof_command",
    "set_dofs_command", "skinned_mesh", "world_matrices",
]


@dataclass(eq=False)
class Character3D:
    """What a 3D character asset loads: skeleton (rest pose from the file), skin, clip."""

    skeleton: Skeleton
    skin: Skin | None = None
    mesh: Mesh | None = None
    clip: AnimationClip | None = None
    #: MIT meshes are drawn with per-face normals by default.
    faceted: bool = False

    @property
    def joint_keys(self) -> list[str]:
        return self.skeleton.joint_keys()


def load_character3d(skel_path: str | os.PathLike[str], skin_path: str | os.PathLike[str] | None = None,
                     anim_path: str | os.PathLike[str] | None = None,
                     obj_path: str | os.PathLike[str] | None = None,
                     attach_path: str | os.PathLike[str] | None = None) -> Character3D:
    """Load the files of a 3D character. Raises FormatError for any bad file."""
    skeleton = load_skel(skel_path)
    skin: Skin | None = None
    mesh: Mesh | None = None
    faceted = False
    if skin_path:
        skin = load_skin(skin_path, num_joints=len(skeleton.joints))
    elif obj_path:
        mesh = load_obj(obj_path)
        if attach_path:
            weights = load_attach(attach_path, mesh.num_vertices, len(skeleton.joints))
            binding = SkinBinding.from_dense(weights)
        else:
            # Without an attachment the mesh rides on the root joint.
            n = mesh.num_vertices
            binding = SkinBinding(np.arange(n), np.zeros(n, dtype=np.intp), np.ones(n), n, len(skeleton.joints))
        skin = bind_to_skeleton(mesh.positions, mesh.triangles, binding, skeleton.bind_world_matrices())
        faceted = True
    elif attach_path:
        raise FormatError("an .attach file needs the .obj mesh it belongs to.", attach_path)
    clip = load_anim(anim_path) if anim_path else None
    if clip is not None and len(clip.channels) > channel_count(len(skeleton.joints)):
        raise FormatError(f"the animation has {len(clip.channels)} channels, but a skeleton of "
                          f"{len(skeleton.joints)} joints takes at most {channel_count(len(skeleton.joints))} "
                          "(3 for the root position, then 3 per joint).", anim_path)
    return Character3D(skeleton, skin, mesh, clip, faceted)


@dataclass(eq=False)
class BvhCharacter(Character3D):
    """A character read from a ``.bvh`` file: the position convention it is posed with, the
    one detected in the file, and notes for the user (the convention, ignored rows)."""

    positions: str = "relative"
    detected: str = "relative"
    notes: list[str] = field(default_factory=list)


#: The asset property holding a BVH character's position convention (absent: detected).
BVH_POSITIONS = "bvh_positions"


def load_bvh_character(path: str | os.PathLike[str],
                       positions: str | None = None) -> tuple[BvhCharacter, list[Channel | None]]:
    """A character from a ``.bvh`` file and its motion as channels in the ``.anim`` layout
    (root x, y, z, then x, y, z rotation per joint; None where the file has no channel).

    ``positions`` is the position convention (``"relative"`` or ``"absolute"``, see
    :mod:`qtanimator.formats.bvh`); None uses the one detected in the file. The channels hold
    the file's numbers either way: the convention only sets the offsets (absolute: the
    root's OFFSET is 0 on its position axes, so the channel replaces it).

    The skeleton's DOFs hold the first frame's pose. Raises FormatError for a bad file or a
    hierarchy a skeleton cannot hold (several roots, a joint below the root that moves).
    """
    clip = load_bvh(path)
    if positions is not None and positions not in POSITION_CONVENTIONS:
        raise FormatError(f"unknown BVH position convention {positions!r}; expected 'relative' or "
                          "'absolute'.", path)
    chosen = positions or clip.positions
    try:
        skeleton, channels = clip.to_skeleton(chosen)
    except ValueError as exc:
        raise FormatError(f"{exc}.", path) from exc
    skeleton.dialect = "bvh"
    for joint in skeleton.joints:
        # BVH has no boxes: default boxes make the viewport draw spheres and bones.
        joint.boxmin = np.array(DEFAULT_BOXMIN)
        joint.boxmax = np.array(DEFAULT_BOXMAX)
    notes = [bvh_positions_note(chosen, clip.positions), *clip.warnings]
    return BvhCharacter(skeleton, positions=chosen, detected=clip.positions, notes=notes), channels


def bvh_positions_note(chosen: str, detected: str) -> str:
    """The import message's sentence on the position convention."""
    what = ("root positions replace the root's OFFSET (absolute, as Blender writes them)" if chosen == "absolute"
            else "root positions are added to the root's OFFSET (relative)")
    how = "detected in the file" if chosen == detected else f"chosen; the file looks {detected}"
    return f"BVH positions: {what}, {how}; switch in Properties."


def bvh_positions(doc: Document, asset_id: str) -> str | None:
    """The position convention a BVH character is posed with, None for other characters."""
    asset = doc.assets.get(asset_id)
    if asset is None or asset.kind != ASSET_KIND or Path(asset.source or "").suffix.lower() != ".bvh":
        return None
    value = asset.properties.get(BVH_POSITIONS)
    if value in POSITION_CONVENTIONS:
        return str(value)
    rt = doc.runtime.get(asset_id)
    return rt.positions if isinstance(rt, BvhCharacter) else None


class _SetBvhPositions(Command):
    """Switch a BVH character's position convention: the asset property and the loaded
    skeleton's offsets change together; the channels (the file's numbers) stay."""

    def __init__(self, doc: Document, asset_id: str, value: str, runtime: BvhCharacter) -> None:
        self.asset_id = asset_id
        self.old_asset = doc.assets[asset_id]
        self.old_runtime = doc.runtime.get(asset_id)
        self.new_asset = self.old_asset.copy()
        self.new_asset.properties[BVH_POSITIONS] = value
        self.new_runtime = runtime
        self.text = f"BVH positions: {value}"

    def do(self, doc: Document) -> None:
        doc.apply_asset(self.asset_id, self.new_asset, self.new_runtime)

    def undo(self, doc: Document) -> None:
        doc.apply_asset(self.asset_id, self.old_asset, self.old_runtime)


def set_bvh_positions_command(doc: Document, asset_id: str, value: str) -> Command:
    """One undo step that poses a BVH character with the position convention ``value``
    (``"relative"`` or ``"absolute"``). Reads the file again (FormatError if it is gone)."""
    if value not in POSITION_CONVENTIONS:
        raise ValueError(f"unknown BVH position convention {value!r}")
    asset = doc.assets[asset_id]
    if asset.kind != ASSET_KIND or not asset.source or Path(asset.source).suffix.lower() != ".bvh":
        raise ValueError(f"{asset_id!r} is not a BVH character")
    runtime, _ = load_bvh_character(asset.source, value)
    old = doc.runtime.get(asset_id)
    if isinstance(old, Character3D):
        # Keep what the user gave the character since (a skin): only the offsets change.
        skeleton = old.skeleton.copy()
        for joint, new in zip(skeleton.joints, runtime.skeleton.joints):
            joint.offset = new.offset.copy()
        runtime = BvhCharacter(skeleton, old.skin, old.mesh, old.clip, old.faceted, positions=value,
                               detected=runtime.detected, notes=runtime.notes)
    return _SetBvhPositions(doc, asset_id, value, runtime)


def load_character3d_asset(asset: Asset) -> Character3D:
    """The registered loader for :data:`ASSET_KIND` (a project being opened)."""
    if not asset.source:
        raise FormatError(f"3D character {asset.id!r} has no skeleton file.")
    suffix = Path(asset.source).suffix.lower()
    if suffix == ".bvh":
        value = asset.properties.get(BVH_POSITIONS)
        return load_bvh_character(asset.source, value if value in POSITION_CONVENTIONS else None)[0]
    if suffix in (".glb", ".gltf"):
        from qtanimator.document.import3d import load_gltf_character_asset

        return load_gltf_character_asset(asset)
    p = asset.properties
    return load_character3d(asset.source, p.get("skin_file") or None, p.get("anim_file") or None,
                            p.get("obj_file") or None, p.get("attach_file") or None)


def character(doc: Document, asset_id: str) -> Character3D:
    rt = doc.runtime.get(asset_id)
    if not isinstance(rt, Character3D):
        raise KeyError(f"{asset_id!r} is not a loaded 3D character")
    return rt


# ------------------------------------------------------------------- channel ids
def _dof_name(joint_index: int | None, axis: str | int) -> tuple[bool, int]:
    """(is_root, axis 0..2) from ``(None | -1, "x"|"tx")`` or ``(j, "x"|"rx")``."""
    if isinstance(axis, str) and len(axis) == 2 and axis[0] in "tr":
        a = axis_index(axis[1])
        root = axis[0] == "t"
        if root != (joint_index is None or joint_index == ROOT):
            raise ValueError(f"axis {axis!r} does not fit joint {joint_index!r}")
        return root, a
    return (joint_index is None or joint_index == ROOT), axis_index(axis)


def _channel_ids(asset_id: str, keys: list[str]) -> list[str]:
    ids = [channel_id(asset_id, "", d) for d in ROOT_DOFS]
    for key in keys:
        ids.extend(channel_id(asset_id, key, d) for d in JOINT_DOFS)
    return ids


def channel_ids(doc: Document, asset_id: str) -> list[str]:
    """Every DOF's channel id in ``.anim`` order (root tx, ty, tz, then rx, ry, rz per joint)."""
    return _channel_ids(asset_id, character(doc, asset_id).joint_keys)


def dof_channel_id(doc: Document, asset_id: str, joint_index: int | None, axis: str | int) -> str:
    """Channel id of one DOF. ``joint_index`` None (or −1) means the root translation."""
    root, a = _dof_name(joint_index, axis)
    if root:
        return channel_id(asset_id, "", ROOT_DOFS[a])
    keys = character(doc, asset_id).joint_keys
    if joint_index is None or not 0 <= joint_index < len(keys):
        raise IndexError(f"joint {joint_index} does not exist in {asset_id!r}")
    return channel_id(asset_id, keys[joint_index], JOINT_DOFS[a])


def channel_dofs(doc: Document, asset_id: str) -> dict[str, tuple[int | None, str]]:
    """Channel id → ``(joint index or None for the root, axis "x"|"y"|"z")``."""
    out: dict[str, tuple[int | None, str]] = {}
    for i, cid in enumerate(channel_ids(doc, asset_id)):
        joint, axis = channel_target(i)
        out[cid] = (None if joint == ROOT else joint, axis)
    return out


def clip_channels(asset_id: str, skeleton: Skeleton, clip: AnimationClip) -> dict[str, Channel]:
    ids = _channel_ids(asset_id, skeleton.joint_keys())
    if len(clip.channels) > len(ids):
        raise FormatError(f"the animation has {len(clip.channels)} channels, but the skeleton takes at most "
                          f"{len(ids)}.")
    return dict(zip(ids, clip.channels))


# ---------------------------------------------------------------------- commands
def add_character3d_command(doc: Document, skel_path: str | os.PathLike[str],
                            skin_path: str | os.PathLike[str] | None = None,
                            anim_path: str | os.PathLike[str] | None = None,
                            obj_path: str | os.PathLike[str] | None = None,
                            attach_path: str | os.PathLike[str] | None = None,
                            asset_id: str | None = None) -> Command:
    """Load the files (FormatError on bad input, document untouched) and return the command
    that adds the character and, with an ``.anim``, its channels."""
    runtime = load_character3d(skel_path, skin_path, anim_path, obj_path, attach_path)
    aid = asset_id or doc.unique_asset_id(Path(skel_path).stem)
    if aid in doc.assets:
        raise ValueError(f"there is already an asset {aid!r}")
    props: dict[str, Any] = {}
    for name, value in (("skin_file", skin_path), ("anim_file", anim_path), ("obj_file", obj_path),
                        ("attach_file", attach_path)):
        if value:
            props[name] = str(Path(value).resolve())
    asset = Asset(aid, ASSET_KIND, str(Path(skel_path).resolve()), props)
    channels = clip_channels(aid, runtime.skeleton, runtime.clip) if runtime.clip is not None else {}
    return AddAsset(asset, runtime, channels, text=f"Add 3D character {aid}")


def load_anim_command(doc: Document, asset_id: str, anim_path: str | os.PathLike[str],
                      clip: AnimationClip | None = None) -> Command:
    """Replace the character's DOF channels with an ``.anim`` file's (one undo step);
    ``clip`` is the file's content when the caller has read it already."""
    ch = character(doc, asset_id)
    if clip is None:
        clip = load_anim(anim_path)
    new = clip_channels(asset_id, ch.skeleton, clip)
    changes: dict[str, tuple[Channel | None, Channel | None]] = {}
    for cid in channel_ids(doc, asset_id):
        old = doc.channels.get(cid)
        nxt = new.get(cid)
        if old is not None or nxt is not None:
            changes[cid] = (old, nxt)
    return Macro(f"Load animation {Path(anim_path).name}", [
        SetAssetProperty(doc, asset_id, "anim_file", str(Path(anim_path).resolve())),
        SetChannels("Load animation", changes),
    ])


def _clamped(doc: Document, asset_id: str, joint_index: int | None, axis: str | int, value: float) -> float:
    root, a = _dof_name(joint_index, axis)
    if root or joint_index is None:
        return float(value)
    return character(doc, asset_id).skeleton.joints[joint_index].dofs[a].clamp(value)


def set_dof_command(doc: Document, asset_id: str, joint_index: int | None, axis: str | int, value: float,
                    time: float, gesture: Hashable | None = None) -> Command:
    """Key one DOF at ``time`` (value clamped to the DOF's limits)."""
    return set_dofs_command(doc, asset_id, {(joint_index, axis): value}, time, gesture)


def dof_values(doc: Document, asset_id: str,
               values: Mapping[tuple[int | None, str | int], float]) -> dict[str, float]:
    """Channel values for DOF values: ``values`` maps (joint, axis) to a value, clamped
    to the DOF's limits. What a key or an unkeyed pose of those DOFs holds."""
    return {dof_channel_id(doc, asset_id, joint, axis): _clamped(doc, asset_id, joint, axis, v)
            for (joint, axis), v in values.items()}


def set_dofs_command(doc: Document, asset_id: str, values: Mapping[tuple[int | None, str | int], float],
                     time: float, gesture: Hashable | None = None) -> Command:
    """Key several DOFs at ``time`` in one undo step; ``values`` maps (joint, axis) to a value."""
    keys = {cid: Key(float(time), v) for cid, v in dof_values(doc, asset_id, values).items()}
    text = "Set Joint" if len(keys) == 1 else "Set Pose"
    return SetKeys(doc, keys, text=text, gesture=gesture)


def ik_values(doc: Document, asset_id: str, joint: int, target: npt.ArrayLike, time: float,
              dofs: list[tuple[int, int]]) -> dict[tuple[int | None, str | int], float]:
    """Solve IK for ``joint`` towards ``target`` over ``dofs`` from the pose shown at
    ``time``: the new DOF values by (joint, axis). Both 3D IK paths (keying and posing
    without keys) get their values here."""
    from qtanimator.core.ik3d import solve_ik

    skel = pose_skeleton(doc, asset_id, time)
    result = solve_ik(skel, joint, np.asarray(target, dtype=np.float64), dofs=dofs)
    return {(j, axis): v for (j, axis), v in result.by_axis_name().items()}


def clip_from_document(doc: Document, asset_id: str, start: float | None = None,
                       end: float | None = None) -> AnimationClip:
    """The character's channels as an ``.anim`` clip (for :func:`qtanimator.formats.anim.save_anim`).

    A DOF without a channel becomes a one-key constant channel holding the file's pose
    value (root translation: the skeleton's). The range defaults to the document's.
    """
    ch = character(doc, asset_id)
    first, last = doc.frame_range
    t0 = doc.frame_to_time(first) if start is None else float(start)
    t1 = doc.frame_to_time(last) if end is None else float(end)
    rest = [*ch.skeleton.root_translation.tolist(), *ch.skeleton.dof_values().reshape(-1).tolist()]
    channels = []
    for cid, value in zip(channel_ids(doc, asset_id), rest):
        existing = doc.channels.get(cid)
        channels.append(existing if existing is not None and existing.keys else Channel([Key(t0, value)]))
    return AnimationClip(channels, t0, max(t0, t1))


# -------------------------------------------------------------------- evaluation
def pose_skeleton(doc: Document, asset_id: str, time: float) -> Skeleton:
    """A posed copy of the character's skeleton at ``time`` (channel values clamped; a
    pending, unkeyed pose at ``time`` is shown: see :mod:`qtanimator.document.pose`)."""
    ch = character(doc, asset_id)
    skel = ch.skeleton.copy()
    ids = _channel_ids(asset_id, skel.joint_keys())
    t = float(time)
    held = pending_values(doc, t)  # an unkeyed pose shown at this time (document.pose)
    for i, cid in enumerate(ids):
        v = held.get(cid) if held else None
        if v is None:
            channel = doc.channels.get(cid)
            if channel is None or not channel.keys:
                continue
            v = channel.evaluate(t)
        if i < 3:
            skel.root_translation[i] = v
        else:
            j, a = divmod(i - 3, 3)
            skel.joints[j].dofs[a].value = v
    return skel


def world_matrices(doc: Document, asset_id: str, time: float) -> FloatArray:
    """(J, 4, 4) joint-to-world matrices at ``time``."""
    return pose_skeleton(doc, asset_id, time).world_matrices()


def skinned_mesh(doc: Document, asset_id: str, time: float) -> tuple[FloatArray, FloatArray]:
    """(V, 3) positions and unit normals of the skinned mesh at ``time``.

    Skins with normals transform them; meshes without (MIT) get smooth normals of the
    skinned surface (the renderer may draw them faceted instead).
    """
    ch = character(doc, asset_id)
    if ch.skin is None:
        raise ValueError(f"3D character {asset_id!r} has no skin or mesh")
    w = world_matrices(doc, asset_id, time)
    if ch.skin.normals is not None:
        return skin_positions_and_normals(ch.skin, w)
    positions = skin_positions(ch.skin, w)
    return positions, vertex_normals(positions, ch.skin.triangles)
