"""3D characters in the document: a skeleton, an optional skin, and their channels.

An asset of kind :data:`ASSET_KIND` has the ``.skel`` file as its ``source`` and the
optional properties ``skin_file`` and ``anim_file`` (CSE 169) or ``obj_file`` and
``attach_file`` (MIT 6.837). The source may also be a ``.bvh`` file (skeleton with one
rotation order per joint; its motion lives in the document's channels) or a ``.glb`` /
``.gltf`` file (see :mod:`qtanimator.document.gltf_character`). The loaded :class:`Character3D`
lives in ``doc.runtime``.

Channels (document channel ids):

* ``"<asset>//tx"``, ``"<asset>//ty"``, ``"<asset>//tz"``: root translation;
* ``"<asset>/<joint key>/rx|ry|rz"``: joint rotations (radians), where the joint key is
  the joint's name, or ``name#index`` when several joints share the name (the dragon);
* for a joint whose rotation is keyed as a quaternion (glTF), ``qw|qx|qy|qz`` instead
  (evaluated as one rotation: :mod:`qtanimator.core.quaternion_channels`);
* for a joint that moves or scales (glTF), ``tx|ty|tz`` (added to its offset) and
  ``sx|sy|sz``.

A DOF with no channel keeps the value the file gave it. Channel values are clamped to the
DOF limits when the skeleton is posed.

A character from glTF may have several **clips** (the file's animations,
:class:`ClipSource`). The document's channels hold the active clip (asset property
``clip``); :func:`set_clip_command` makes another clip active, putting the edited channels
of the one left in the asset property ``clip_store`` so that they survive (and are saved).
Its meshes are :class:`MeshPart` ranges of one merged skin whose joint slots map to
skeleton joints through :attr:`Character3D.palette`.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Hashable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.core.channel import Channel, Interpolation, Key, Tangent
from qtanimator.core.clip import ROOT, AnimationClip, channel_count, channel_target
from qtanimator.core.quaternion_channels import euler_channels, quaternion_at, quaternion_channels
from qtanimator.core.rotation import euler_to_quaternions, quaternions_to_euler, same_hemisphere
from qtanimator.core.skeleton import DEFAULT_BOXMAX, DEFAULT_BOXMIN, Joint, Skeleton, axis_index
from qtanimator.core.skinning import (
    Skin,
    SkinBinding,
    bind_to_skeleton,
    skin_positions,
    skin_positions_and_normals,
    vertex_normals,
)
from qtanimator.document.character3d_model import (
    ASSET_KIND,
    CLIP,
    CLIP_STORE,
    JOINT_DOFS,
    QUAT_DOFS,
    ROOT_DOFS,
    ROTATION_MODE,
    ROTATION_MODES,
    SCALE_DOFS,
    TRANSLATE_DOFS,
    Character3D,
    ClipSource,
    MeshPart,
    TextureImage,
    skin_texture,
)
from qtanimator.document.commands import (
    AddAsset,
    Command,
    Macro,
    SetAssetProperty,
    SetChannels,
    SetKeys,
    SetParameter,
)
from qtanimator.document.document import Asset, Document, channel_id
from qtanimator.document.gltf_character import load_gltf_character_asset
from qtanimator.document.pending_pose import pending_values
from qtanimator.document.placement import PLACEMENT, matrix3d
from qtanimator.formats.anim import load_anim
from qtanimator.formats.attach import load_attach
from qtanimator.formats.bvh import POSITION_CONVENTIONS, load_bvh
from qtanimator.formats.errors import FormatError
from qtanimator.formats.obj import Mesh, load_obj
from qtanimator.formats.skel import load_skel
from qtanimator.formats.skin import load_skin

FloatArray = npt.NDArray[np.float64]


__all__ = [
    "ASSET_KIND", "BVH_POSITIONS", "BvhCharacter", "CLIP", "CLIP_STORE", "Character3D", "ClipSource", "MeshPart",
    "QUAT_DOFS", "ROTATION_MODE", "ROTATION_MODES", "SCALE_DOFS", "TRANSLATE_DOFS", "TextureImage", "active_clip",
    "add_character3d_command", "all_channel_ids", "bvh_positions", "bvh_positions_note", "channel_dofs",
    "channel_ids", "character", "clip_channels_of", "clip_from_document", "clip_range_command", "dof_channel_id",
    "dof_values", "ik_values", "joint_channel_names", "load_anim_command", "load_bvh_character", "load_character3d",
    "load_character3d_asset", "load_skin_character", "new_key", "pose_channel_values", "pose_skeleton", "rotation_mode",
    "set_bvh_positions_command", "set_clip_command", "set_dof_command", "set_dofs_command", "set_fps_command",
    "set_rotation_mode_command", "skin_texture", "skinned_mesh", "with_rotation_mode", "world_matrices",
]



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
    return Character3D(skeleton, skin, mesh, clip, faceted, texture=skin_texture(skin, skin_path))


def load_skin_character(skin_path: str | os.PathLike[str]) -> Character3D:
    """A ``.skin`` without a skeleton: its mesh as stored (the bind pose, positions in world
    space) on one still root joint at the origin, every vertex on it with identity bind."""
    stored = load_skin(skin_path)
    n = stored.num_vertices
    binding = SkinBinding(np.arange(n), np.zeros(n, dtype=np.intp), np.ones(n), n, 1)
    skin = Skin(stored.positions, stored.triangles, binding, np.eye(4)[None], normals=stored.normals,
                texcoords=stored.texcoords, material=stored.material)
    skeleton = Skeleton([Joint("root")], "zyx", name=Path(skin_path).stem, dialect="balljoint")
    return Character3D(skeleton, skin, texture=skin_texture(skin, skin_path))


@dataclass(eq=False)
class BvhCharacter(Character3D):
    """A character read from a ``.bvh`` file: the position convention it is posed with, the
    one detected in the file, and notes for the user (the convention, ignored rows)."""

    positions: str = "relative"
    detected: str = "relative"
    notes: list[str] = field(default_factory=list)
    #: Joint index → x, y, z translation channels of the joints below the root that move.
    translations: dict[int, list[Channel | None]] = field(default_factory=dict)

    def translation_channels(self, asset_id: str) -> dict[str, Channel]:
        """The translation channels of the joints that move, by document channel id."""
        keys = self.joint_keys
        return {channel_id(asset_id, keys[j], TRANSLATE_DOFS[a]): c
                for j, chans in self.translations.items() for a, c in enumerate(chans) if c is not None}


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

    The skeleton's DOFs hold the first frame's pose; joints below the root that move have
    translation channels (:attr:`BvhCharacter.translations`). Raises FormatError for a bad
    file or a hierarchy a skeleton cannot hold (several roots).
    """
    clip = load_bvh(path)
    if positions is not None and positions not in POSITION_CONVENTIONS:
        raise FormatError(f"unknown BVH position convention {positions!r}; expected 'relative' or "
                          "'absolute'.", path)
    chosen = positions or clip.positions
    try:
        skeleton, channels, moving = clip.to_skeleton(chosen)
    except ValueError as exc:
        raise FormatError(f"{exc}.", path) from exc
    skeleton.dialect = "bvh"
    for joint in skeleton.joints:
        # BVH has no boxes: default boxes make the viewport draw spheres and bones.
        joint.boxmin = np.array(DEFAULT_BOXMIN)
        joint.boxmax = np.array(DEFAULT_BOXMAX)
    notes = [bvh_positions_note(chosen, clip.positions), *clip.warnings]
    return BvhCharacter(skeleton, positions=chosen, detected=clip.positions, notes=notes,
                        translations=moving), channels


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
                               detected=runtime.detected, notes=runtime.notes, translations=runtime.translations)
    return _SetBvhPositions(doc, asset_id, value, runtime)


def load_character3d_asset(asset: Asset) -> Character3D:
    """The registered loader for :data:`ASSET_KIND` (a project being opened), in the
    rotation mode the asset keeps (:data:`ROTATION_MODE`)."""
    return with_rotation_mode(_load_character3d_asset(asset), asset.properties.get(ROTATION_MODE))


def _load_character3d_asset(asset: Asset) -> Character3D:
    if not asset.source:
        raise FormatError(f"3D character {asset.id!r} has no skeleton file.")
    suffix = Path(asset.source).suffix.lower()
    if suffix == ".bvh":
        value = asset.properties.get(BVH_POSITIONS)
        return load_bvh_character(asset.source, value if value in POSITION_CONVENTIONS else None)[0]
    if suffix == ".skin":
        return load_skin_character(asset.source)
    if suffix in (".glb", ".gltf"):
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


def _dof_kind(joint_index: int | None, axis: str | int) -> tuple[str, int]:
    """``("root" | "rotate" | "translate" | "scale", axis 0..2)`` of a DOF: ``(None, "tx")``
    is the root translation, ``(j, "x" | "rx")`` a rotation, ``(j, "tx")`` / ``(j, "sx")``
    a joint's translation / scale."""
    if joint_index is not None and joint_index != ROOT and isinstance(axis, str) and len(axis) == 2:
        if axis[0] == "t":
            return "translate", axis_index(axis[1])
        if axis[0] == "s":
            return "scale", axis_index(axis[1])
    root, a = _dof_name(joint_index, axis)
    return ("root" if root else "rotate"), a


def _channel_ids(asset_id: str, keys: list[str]) -> list[str]:
    ids = [channel_id(asset_id, "", d) for d in ROOT_DOFS]
    for key in keys:
        ids.extend(channel_id(asset_id, key, d) for d in JOINT_DOFS)
    return ids


def channel_ids(doc: Document, asset_id: str) -> list[str]:
    """The ``.anim`` layout's channel ids (root tx, ty, tz, then rx, ry, rz per joint).
    Joints keyed as quaternions, and translations and scales, are not in it: see
    :func:`all_channel_ids`."""
    return _channel_ids(asset_id, character(doc, asset_id).joint_keys)


def joint_channel_names(joint: Joint) -> list[str]:
    """The channel names a joint can have: its rotation (Euler or quaternion), then its
    translation and scale where it moves or scales."""
    names = list(QUAT_DOFS if joint.quaternion else JOINT_DOFS)
    if joint.translates:
        names += TRANSLATE_DOFS
    if joint.scales:
        names += SCALE_DOFS
    return names


def all_channel_ids(doc: Document, asset_id: str) -> list[str]:
    """Every channel id the character can have: the root translation, then per joint
    :func:`joint_channel_names`."""
    skel = character(doc, asset_id).skeleton
    ids = [channel_id(asset_id, "", d) for d in ROOT_DOFS]
    for key, joint in zip(skel.joint_keys(), skel.joints):
        ids.extend(channel_id(asset_id, key, d) for d in joint_channel_names(joint))
    return ids


def dof_channel_id(doc: Document, asset_id: str, joint_index: int | None, axis: str | int) -> str:
    """Channel id of one DOF. ``joint_index`` None (or −1) means the root translation.

    A joint's rotation axis ("x" or "rx") names its Euler channel; for a joint keyed as a
    quaternion, whose rotation lives in four channels, it names the ``q`` channel of that
    axis (``qx``), the one a key at this time shows up on."""
    kind, a = _dof_kind(joint_index, axis)
    if kind == "root":
        return channel_id(asset_id, "", ROOT_DOFS[a])
    ch = character(doc, asset_id)
    keys = ch.joint_keys
    if joint_index is None or not 0 <= joint_index < len(keys):
        raise IndexError(f"joint {joint_index} does not exist in {asset_id!r}")
    if kind == "translate":
        return channel_id(asset_id, keys[joint_index], TRANSLATE_DOFS[a])
    if kind == "scale":
        return channel_id(asset_id, keys[joint_index], SCALE_DOFS[a])
    if ch.skeleton.joints[joint_index].quaternion:
        return channel_id(asset_id, keys[joint_index], QUAT_DOFS[1 + a])
    return channel_id(asset_id, keys[joint_index], JOINT_DOFS[a])


def channel_dofs(doc: Document, asset_id: str) -> dict[str, tuple[int | None, str]]:
    """Channel id → ``(joint index or None for the root, axis "x"|"y"|"z")`` (``.anim`` layout)."""
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


def set_dof_command(doc: Document, asset_id: str, joint_index: int | None, axis: str | int, value: float,
                    time: float, gesture: Hashable | None = None) -> Command:
    """Key one DOF at ``time`` (value clamped to the DOF's limits)."""
    return set_dofs_command(doc, asset_id, {(joint_index, axis): value}, time, gesture)


def dof_values(doc: Document, asset_id: str, values: Mapping[tuple[int | None, str | int], float],
               time: float | None = None) -> dict[str, float]:
    """Channel values for DOF values: what a key or an unkeyed pose of those DOFs holds.

    ``values`` maps ``(joint, axis)`` to a value (see :func:`_dof_kind`): rotations in
    radians (Euler, clamped to the DOF's limits), translations and scales as they are. A
    joint keyed as a quaternion gets all four components: its Euler angles are the given
    ones over the pose shown at ``time`` (the rest pose when None), and the quaternion is
    kept on the side of the one shown (so cubic spans do not flip)."""
    ch = character(doc, asset_id)
    skel = ch.skeleton
    keys = ch.joint_keys
    out: dict[str, float] = {}
    turned: dict[int, dict[int, float]] = {}
    for (joint, axis), v in values.items():
        kind, a = _dof_kind(joint, axis)
        if kind == "root":
            out[channel_id(asset_id, "", ROOT_DOFS[a])] = float(v)
            continue
        assert joint is not None
        if not 0 <= joint < len(keys):
            raise IndexError(f"joint {joint} does not exist in {asset_id!r}")
        if kind == "translate":
            out[channel_id(asset_id, keys[joint], TRANSLATE_DOFS[a])] = float(v)
        elif kind == "scale":
            out[channel_id(asset_id, keys[joint], SCALE_DOFS[a])] = float(v)
        elif skel.joints[joint].quaternion:
            turned.setdefault(joint, {})[a] = float(v)
        else:
            out[channel_id(asset_id, keys[joint], JOINT_DOFS[a])] = skel.joints[joint].dofs[a].clamp(v)
    if turned:
        shown = skel if time is None else pose_skeleton(doc, asset_id, time)
        for joint, axes in turned.items():
            j = shown.joints[joint]
            euler = j.pose
            for a, v in axes.items():
                euler[a] = j.dofs[a].clamp(v)
            q = euler_to_quaternions(euler, j.rotation_order or shown.rotation_order)[0]
            ref = _shown_quaternion(doc, asset_id, joint, time)
            q = same_hemisphere(q, ref)
            for slot, name in zip((3, 0, 1, 2), QUAT_DOFS):
                out[channel_id(asset_id, keys[joint], name)] = float(q[slot])
    return out


def _shown_quaternion(doc: Document, asset_id: str, joint: int, time: float | None) -> FloatArray:
    """The quaternion components a joint's channels hold at ``time`` (not normalised, sign
    as keyed); the rest rotation where there are none."""
    ch = character(doc, asset_id)
    rest = ch.rest_quaternions()[joint]
    if time is None:
        return rest
    key = ch.joint_keys[joint]
    out = rest.copy()
    for slot, name in zip((3, 0, 1, 2), QUAT_DOFS):
        c = doc.channels.get(channel_id(asset_id, key, name))
        if c is not None and c.keys:
            out[slot] = c.evaluate(float(time))
    return out


def new_key(cid: str, time: float, value: float) -> Key:
    """A new key; quaternion components are keyed linear (a slerp span, as glTF's LINEAR)."""
    if cid.rsplit("/", 1)[-1] in QUAT_DOFS:
        return Key(float(time), value, Tangent.LINEAR, Tangent.LINEAR, interpolation=Interpolation.LINEAR)
    return Key(float(time), value)


def set_dofs_command(doc: Document, asset_id: str, values: Mapping[tuple[int | None, str | int], float],
                     time: float, gesture: Hashable | None = None) -> Command:
    """Key several DOFs at ``time`` in one undo step; ``values`` maps (joint, axis) to a value."""
    keys = {cid: new_key(cid, time, v) for cid, v in dof_values(doc, asset_id, values, time).items()}
    text = "Set Joint" if len(values) == 1 else "Set Pose"
    return SetKeys(doc, keys, text=text, gesture=gesture)


def ik_values(doc: Document, asset_id: str, joint: int, target: npt.ArrayLike, time: float,
              dofs: list[tuple[int, int]], offset: npt.ArrayLike | None = None
              ) -> dict[tuple[int | None, str | int], float]:
    """Solve IK for ``joint`` towards ``target`` over ``dofs`` from the pose shown at
    ``time`` with the document's IK settings (:mod:`qtanimator.document.ik_settings`: the
    solver, two-bone for a two-joint chain): the new DOF values by (joint, axis). Both 3D
    IK paths (keying and posing without keys) get their values here. ``offset``: the
    point of ``joint``'s frame to move (a clicked skin point; None: its origin)."""
    from qtanimator.document.ik_settings import solve_skeleton

    skel = pose_skeleton(doc, asset_id, time)
    result = solve_skeleton(doc, skel, joint, np.asarray(target, dtype=np.float64), dofs, offset)
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


# ------------------------------------------------------------------------- clips
def active_clip(doc: Document, asset_id: str) -> ClipSource | None:
    """The clip whose channels the document holds (None: the character has no clips)."""
    ch = character(doc, asset_id)
    name = doc.assets[asset_id].properties.get(CLIP)
    found = ch.clip_named(name) if isinstance(name, str) else None
    return found


def clip_channels_of(doc: Document, asset_id: str, name: str) -> dict[str, Channel]:
    """A clip's channels by document channel id: the document's for the active clip, the
    edited ones kept in ``clip_store`` for a clip left, else the file's."""
    ch = character(doc, asset_id)
    clip = ch.clip_named(name)
    if clip is None:
        raise KeyError(f"{asset_id!r} has no clip {name!r}")
    active = active_clip(doc, asset_id)
    if active is not None and active.name == name:
        return dict(doc.channels_of(asset_id))
    stored = (doc.assets[asset_id].properties.get(CLIP_STORE) or {}).get(name)
    if isinstance(stored, dict):
        rel = {r: Channel.from_dict(d) for r, d in stored.items()}
    else:
        rel = dict(clip.channels)
    # The file's keys are quaternions; joints switched to Euler get them converted.
    rel = _in_rotation_mode(ch, rel, doc.fps)
    return {f"{asset_id}/{r}": c for r, c in rel.items()}


def clip_duration(doc: Document, asset_id: str, name: str) -> tuple[float, float]:
    """``(start, end)`` of a clip: the file's, or its keys' where the user keyed beyond them."""
    ch = character(doc, asset_id)
    clip = ch.clip_named(name)
    if clip is None:
        raise KeyError(f"{asset_id!r} has no clip {name!r}")
    start, end = clip.start, clip.end
    for c in clip_channels_of(doc, asset_id, name).values():
        if c.keys:
            start, end = min(start, c.keys[0].time), max(end, c.keys[-1].time)
    return start, end


def clip_range_command(doc: Document, start: float, end: float, fps: float | None = None) -> Command | None:
    """The document's frame range set to the frames covering ``start … end`` seconds (None:
    it is that already). ``fps`` counts the frames at another rate than the document's (a
    command that also changes it)."""
    rate = doc.fps if fps is None else float(fps)
    first = int(np.floor(start * rate + 1e-6))
    last = max(first, int(np.ceil(end * rate - 1e-6)))
    commands: list[Command] = []
    if doc.frame_range[0] != first:
        commands.append(SetParameter(doc, "frame_start", first))
    if doc.frame_range[1] != last:
        commands.append(SetParameter(doc, "frame_end", last))
    if first > doc.frame_range[1]:
        commands.reverse()  # the end moves first, so that start never passes end
    if not commands:
        return None
    return commands[0] if len(commands) == 1 else Macro("Frame range", commands)


def set_fps_command(doc: Document, fps: float) -> Command:
    """One undo step that sets the project's frame rate (the ``fps`` parameter) and keeps
    the frame range's time: keys are in seconds and stay, ``frame_start`` / ``frame_end``
    are rescaled to the frames covering the same seconds at the new rate (the start rounded
    down, the end up). Raises ValueError for a rate that is not a positive number."""
    rate = float(fps)
    if not (np.isfinite(rate) and rate > 0):
        raise ValueError(f"frame rate must be a positive number, not {fps!r}")
    value: float | int = int(rate) if rate.is_integer() else rate
    first, last = doc.frame_range
    commands: list[Command] = [SetParameter(doc, "fps", value)]
    rng = clip_range_command(doc, doc.frame_to_time(first), doc.frame_to_time(last), rate)
    if rng is not None:
        commands.append(rng)
    return Macro(f"Frame rate {rate:g} fps", commands)


def set_clip_command(doc: Document, asset_id: str, name: str) -> Command:
    """One undo step that makes the clip ``name`` the character's active one: the
    document's channels of the character become that clip's, the channels of the clip
    left are kept (edits included) in ``clip_store``, and the frame range fits the clip.

    Raises KeyError for an unknown clip."""
    ch = character(doc, asset_id)
    if ch.clip_named(name) is None:
        raise KeyError(f"{asset_id!r} has no clip {name!r}")
    asset = doc.assets[asset_id]
    current = active_clip(doc, asset_id)
    new_channels = clip_channels_of(doc, asset_id, name)
    store = {k: v for k, v in (asset.properties.get(CLIP_STORE) or {}).items() if k != name}
    if current is not None and current.name != name:
        store[current.name] = {cid[len(asset_id) + 1:]: c.to_dict() for cid, c in doc.channels_of(asset_id)}
    old = dict(doc.channels_of(asset_id))
    changes = {cid: (old.get(cid), new_channels.get(cid)) for cid in dict.fromkeys([*old, *new_channels])}
    commands: list[Command] = [
        SetChannels(f"Clip {name}", changes),
        SetAssetProperty(doc, asset_id, CLIP, name),
        SetAssetProperty(doc, asset_id, CLIP_STORE, store or None),
    ]
    start, end = clip_duration(doc, asset_id, name)
    rng = clip_range_command(doc, start, end)
    if rng is not None:
        commands.append(rng)
    return Macro(f"Play clip {name}", commands)


# ----------------------------------------------------------------- rotation mode
def rotation_mode(ch: Character3D) -> str:
    """"quaternion" when the character's joints are keyed as quaternions, else "euler"."""
    return "quaternion" if any(j.quaternion for j in ch.skeleton.joints) else "euler"


def with_rotation_mode(ch: Character3D, mode: Any) -> Character3D:
    """``ch`` with every joint keyed in ``mode`` ("quaternion" / "euler"); ``ch`` itself
    when it is so already or ``mode`` is not one of :data:`ROTATION_MODES`."""
    if mode not in ROTATION_MODES or rotation_mode(ch) == mode and all(
            j.quaternion == (mode == "quaternion") for j in ch.skeleton.joints):
        return ch
    rest = ch.rest_quaternions().copy()
    skel = ch.skeleton.copy()
    for i, j in enumerate(skel.joints):
        if not ch.skeleton.joints[i].quaternion:
            rest[i] = euler_to_quaternions(j.pose, j.rotation_order or skel.rotation_order)[0]
        j.quaternion = mode == "quaternion"
    new = dataclasses.replace(ch, skeleton=skel)
    new._rest_quaternions = rest
    return new


def _in_rotation_mode(ch: Character3D, rel: dict[str, Channel], fps: float) -> dict[str, Channel]:
    """Asset-relative channels with each joint's rotation keyed the way the joint is:
    quaternion channels of an Euler joint become Euler ones and the other way round (both
    sampled at the keys and ``fps``; see :mod:`qtanimator.core.quaternion_channels`)."""
    skel = ch.skeleton
    out = dict(rel)
    for j, (key, joint) in enumerate(zip(skel.joint_keys(), skel.joints)):
        order = joint.rotation_order or skel.rotation_order
        q_ids = [f"{key}/{d}" for d in QUAT_DOFS]
        r_ids = [f"{key}/{d}" for d in JOINT_DOFS]
        if not joint.quaternion and any(i in out for i in q_ids):
            new = euler_channels([out.pop(i, None) for i in q_ids], ch.rest_quaternions()[j], order, fps)
            out.update({i: c for i, c in zip(r_ids, new) if c is not None})
        elif joint.quaternion and any(i in out for i in r_ids):
            new = quaternion_channels([out.pop(i, None) for i in r_ids], joint.pose, order, fps)
            out.update({i: c for i, c in zip(q_ids, new) if c is not None})
    return out


def set_rotation_mode_command(doc: Document, asset_id: str, mode: str) -> Command:
    """One undo step that keys the character's rotations as quaternions or Euler angles
    (Blender's rotation mode): the joints switch, and the rotation channels of the active
    clip and of the clips kept in ``clip_store`` are converted (sampled at their keys and
    the frame rate; exact there, blended in the new form between). Raises ValueError for an
    unknown mode."""
    if mode not in ROTATION_MODES:
        raise ValueError(f"unknown rotation mode {mode!r}; expected one of {', '.join(ROTATION_MODES)}")
    ch = character(doc, asset_id)
    new_ch = with_rotation_mode(ch, mode)
    asset = doc.assets[asset_id]
    prefix = f"{asset_id}/"
    old = {cid[len(prefix):]: c for cid, c in doc.channels_of(asset_id)}
    new = _in_rotation_mode(new_ch, old, doc.fps)
    changes = {prefix + r: (old.get(r), new.get(r)) for r in dict.fromkeys([*old, *new])
               if old.get(r) is not new.get(r)}
    new_asset = asset.copy()
    new_asset.properties[ROTATION_MODE] = mode
    store = asset.properties.get(CLIP_STORE)
    if isinstance(store, dict):
        new_asset.properties[CLIP_STORE] = {
            name: {r: c.to_dict() for r, c in _in_rotation_mode(
                new_ch, {r: Channel.from_dict(d) for r, d in kept.items()}, doc.fps).items()}
            for name, kept in store.items() if isinstance(kept, dict)}
    return Macro(f"Rotation mode: {mode}", [AddAsset(new_asset, new_ch, text="Rotation mode"),
                                             SetChannels("Convert rotations", changes)])


# -------------------------------------------------------------------- evaluation
def authored_placement(doc: Document, asset_id: str) -> FloatArray | None:
    """The 4×4 authored placement of the character (asset property ``placement``,
    :mod:`qtanimator.document.placement`), None when it has none."""
    asset = doc.assets.get(asset_id)
    value = asset.properties.get(PLACEMENT) if asset is not None else None
    return None if value is None else matrix3d(value)


def pose_skeleton(doc: Document, asset_id: str, time: float) -> Skeleton:
    """A posed copy of the character's skeleton at ``time`` (channel values clamped; a
    pending, unkeyed pose at ``time`` is shown: see :mod:`qtanimator.document.pose`).

    A joint keyed as a quaternion is interpolated as one
    (:func:`~qtanimator.core.quaternion_channels.quaternions_at`) and posed with the
    equivalent Euler angles."""
    ch = character(doc, asset_id)
    skel = ch.skeleton.copy()
    placed = authored_placement(doc, asset_id)
    if placed is not None:  # the authored placement goes on top of the file's (issue 14)
        skel.placement = placed if skel.placement is None else placed @ skel.placement
    t = float(time)
    held = pending_values(doc, t)  # an unkeyed pose shown at this time (document.pose)
    channels = doc.channels

    def value(cid: str) -> float | None:
        v = held.get(cid) if held else None
        if v is None:
            channel = channels.get(cid)
            if channel is None or not channel.keys:
                return None
            v = channel.evaluate(t)
        return float(v)

    for a, dof in enumerate(ROOT_DOFS):
        v = value(channel_id(asset_id, "", dof))
        if v is not None:
            skel.root_translation[a] = v
    quat_joints: list[int] = []
    quats: list[FloatArray] = []
    for j, (key, joint) in enumerate(zip(skel.joint_keys(), skel.joints)):
        prefix = f"{asset_id}/{key}/"
        if joint.quaternion:
            cids = [prefix + d for d in QUAT_DOFS]
            pending = [held.get(c) for c in cids] if held else [None] * 4
            chans = [channels.get(c) for c in cids]
            if any(p is not None for p in pending):
                rest = ch.rest_quaternions()[j]
                comps = [p if p is not None else (c.evaluate(t) if c is not None and c.keys else rest[slot])
                         for p, c, slot in zip(pending, chans, (3, 0, 1, 2))]
                q = np.array([comps[1], comps[2], comps[3], comps[0]], dtype=np.float64)
                quat_joints.append(j)
                quats.append(q / (np.linalg.norm(q) or 1.0))
            elif any(c is not None and c.keys for c in chans):
                quat_joints.append(j)
                quats.append(quaternion_at(chans, ch.rest_quaternions()[j], t))
        else:
            for a, dof in enumerate(JOINT_DOFS):
                v = value(prefix + dof)
                if v is not None:
                    joint.dofs[a].value = v
        if joint.translates:
            for a, dof in enumerate(TRANSLATE_DOFS):
                v = value(prefix + dof)
                if v is not None:
                    joint.translation[a] = v
        if joint.scales:
            for a, dof in enumerate(SCALE_DOFS):
                v = value(prefix + dof)
                if v is not None:
                    joint.scale[a] = v
    if quat_joints:
        q_all = np.array(quats)
        orders = [skel.joints[j].rotation_order or skel.rotation_order for j in quat_joints]
        for order in set(orders):
            sel = [k for k, o in enumerate(orders) if o == order]
            euler = quaternions_to_euler(q_all[sel], order)
            for k, e in zip(sel, euler):
                for a in range(3):
                    skel.joints[quat_joints[k]].dofs[a].value = float(e[a])
    return skel


def pose_channel_values(doc: Document, asset_id: str, time: float) -> dict[str, float]:
    """Every channel of :func:`all_channel_ids` with the value the pose shown at ``time``
    gives it (what "key the whole character" keys)."""
    skel = pose_skeleton(doc, asset_id, time)
    out = {channel_id(asset_id, "", d): float(v) for d, v in zip(ROOT_DOFS, skel.root_translation)}
    for j, (key, joint) in enumerate(zip(skel.joint_keys(), skel.joints)):
        prefix = f"{asset_id}/{key}/"
        if joint.quaternion:
            q = euler_to_quaternions(joint.pose, joint.rotation_order or skel.rotation_order)[0]
            q = same_hemisphere(q, _shown_quaternion(doc, asset_id, j, time))
            out.update({prefix + d: float(q[slot]) for d, slot in zip(QUAT_DOFS, (3, 0, 1, 2))})
        else:
            out.update({prefix + d: float(v) for d, v in zip(JOINT_DOFS, joint.pose)})
        if joint.translates:
            out.update({prefix + d: float(v) for d, v in zip(TRANSLATE_DOFS, joint.translation)})
        if joint.scales:
            out.update({prefix + d: float(v) for d, v in zip(SCALE_DOFS, joint.scale)})
    return out


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
    w = ch.skinning_world(world_matrices(doc, asset_id, time))
    if ch.skin.normals is not None:
        return skin_positions_and_normals(ch.skin, w)
    positions = skin_positions(ch.skin, w)
    return positions, vertex_normals(positions, ch.skin.triangles)


def bounds(doc: Document, asset_id: str, time: float) -> tuple[FloatArray, FloatArray]:
    """(lo, hi) world-space box of the character at ``time``: its joints and its skinned mesh."""
    world = world_matrices(doc, asset_id, time)
    points = [world[:, :3, 3]]
    ch = character(doc, asset_id)
    if ch.skin is not None:
        points.append(skinned_mesh(doc, asset_id, time)[0])
    pts = np.concatenate(points, axis=0)
    return pts.min(axis=0), pts.max(axis=0)
