"""The rotation mode of 3D characters: joints keyed as quaternions or as Euler angles
(Blender's rotation mode; asset property :data:`~qtanimator.document.character3d_model.ROTATION_MODE`).
"""

from __future__ import annotations

import dataclasses
from typing import Any

from qtanimator.core.channel import Channel
from qtanimator.core.quaternion_channels import euler_channels, quaternion_channels
from qtanimator.core.rotation import euler_to_quaternions
from qtanimator.document.character3d_model import (
    CLIP_STORE,
    JOINT_DOFS,
    QUAT_DOFS,
    ROTATION_MODE,
    ROTATION_MODES,
    Character3D,
    character,
)
from qtanimator.document.commands import AddAsset, Command, Macro, SetChannels
from qtanimator.document.document import Document


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


def in_rotation_mode(ch: Character3D, rel: dict[str, Channel], fps: float) -> dict[str, Channel]:
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
    new = in_rotation_mode(new_ch, old, doc.fps)
    changes = {prefix + r: (old.get(r), new.get(r)) for r in dict.fromkeys([*old, *new])
               if old.get(r) is not new.get(r)}
    new_asset = asset.copy()
    new_asset.properties[ROTATION_MODE] = mode
    store = asset.properties.get(CLIP_STORE)
    if isinstance(store, dict):
        new_asset.properties[CLIP_STORE] = {
            name: {r: c.to_dict() for r, c in in_rotation_mode(
                new_ch, {r: Channel.from_dict(d) for r, d in kept.items()}, doc.fps).items()}
            for name, kept in store.items() if isinstance(kept, dict)}
    return Macro(f"Rotation mode: {mode}", [AddAsset(new_asset, new_ch, text="Rotation mode"),
                                             SetChannels("Convert rotations", changes)])
