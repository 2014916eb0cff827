"""3D characters in the document: loading and adding them, and the one place their API is
imported from.

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

This module loads characters and adds them (:func:`add_character3d_command`,
:func:`load_anim_command`) and re-exports the rest, which lives in one module per idea:

* :mod:`~qtanimator.document.character3d_model`: the loaded data, DOF names, :func:`character`;
* :mod:`~qtanimator.document.bvh_character`: BVH characters and their position convention;
* :mod:`~qtanimator.document.channels3d`: channel ids;
* :mod:`~qtanimator.document.evaluation3d`: the posed skeleton, world matrices, skinned mesh;
* :mod:`~qtanimator.document.keys3d`: keying DOFs and IK;
* :mod:`~qtanimator.document.clips3d`: clips and the frame range;
* :mod:`~qtanimator.document.rotation_mode`: quaternion or Euler keys.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from qtanimator.core.channel import Channel
from qtanimator.core.clip import AnimationClip, channel_count
from qtanimator.core.skeleton import Joint, Skeleton
from qtanimator.core.skinning import Skin, SkinBinding, bind_to_skeleton
from qtanimator.document.bvh_character import (
    BVH_POSITIONS,
    BvhCharacter,
    bvh_positions,
    bvh_positions_note,
    load_bvh_character,
    set_bvh_positions_command,
)
from qtanimator.document.channels3d import (
    all_channel_ids,
    channel_dofs,
    channel_ids,
    clip_channels,
    dof_channel_id,
    joint_channel_names,
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
    character,
    skin_texture,
)
from qtanimator.document.clips3d import (
    active_clip,
    clip_channels_of,
    clip_duration,
    clip_from_document,
    clip_range_command,
    set_clip_command,
    set_fps_command,
)
from qtanimator.document.commands import AddAsset, Command, Macro, SetAssetProperty, SetChannels
from qtanimator.document.document import Asset, Document
from qtanimator.document.evaluation3d import (
    authored_placement,
    bounds,
    pose_channel_values,
    pose_skeleton,
    skinned_mesh,
    world_matrices,
)
from qtanimator.document.gltf_character import load_gltf_character_asset
from qtanimator.document.keys3d import dof_values, ik_values, new_key, set_dof_command, set_dofs_command
from qtanimator.document.rotation_mode import rotation_mode, set_rotation_mode_command, with_rotation_mode
from qtanimator.formats.anim import load_anim
from qtanimator.formats.attach import load_attach
from qtanimator.formats.bvh import POSITION_CONVENTIONS
from qtanimator.formats.errors import FormatError
from qtanimator.formats.obj import Mesh, load_obj
from qtanimator.formats.skel import load_skel
from qtanimator.formats.skin import load_skin

__all__ = [
    "ASSET_KIND", "BVH_POSITIONS", "BvhCharacter", "CLIP", "CLIP_STORE", "Character3D", "ClipSource", "JOINT_DOFS",
    "MeshPart", "QUAT_DOFS", "ROOT_DOFS", "ROTATION_MODE", "ROTATION_MODES", "SCALE_DOFS", "TRANSLATE_DOFS",
    "TextureImage", "active_clip", "add_character3d_command", "all_channel_ids", "authored_placement", "bounds",
    "bvh_positions", "bvh_positions_note", "channel_dofs", "channel_ids", "character", "clip_channels",
    "clip_channels_of", "clip_duration", "clip_from_document", "clip_range_command", "dof_channel_id",
    "dof_values", "ik_values", "joint_channel_names", "load_anim_command", "load_bvh_character",
    "load_character3d", "load_character3d_asset", "load_skin_character", "new_key", "pose_channel_values",
    "pose_skeleton", "rotation_mode", "set_bvh_positions_command", "set_clip_command", "set_dof_command",
    "set_dofs_command", "set_fps_command", "set_rotation_mode_command", "skin_texture", "skinned_mesh",
    "with_rotation_mode", "world_matrices",
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
