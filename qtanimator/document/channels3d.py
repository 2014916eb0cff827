"""The channel ids of 3D characters: which channels a character and each of its DOFs have.

Root translation ``"<asset>//tx|ty|tz"``; per joint ``rx|ry|rz`` (or ``qw|qx|qy|qz`` for a
joint keyed as a quaternion), and ``tx|ty|tz`` / ``sx|sy|sz`` where it moves or scales. The
``.anim`` layout (:func:`channel_ids`) is the root translation, then three rotations per joint.
"""

from __future__ import annotations

from qtanimator.core.channel import Channel
from qtanimator.core.clip import ROOT, AnimationClip, channel_target
from qtanimator.core.skeleton import Joint, Skeleton, axis_index
from qtanimator.document.character3d_model import (
    JOINT_DOFS,
    QUAT_DOFS,
    ROOT_DOFS,
    SCALE_DOFS,
    TRANSLATE_DOFS,
    character,
)
from qtanimator.document.document import Document, channel_id
from qtanimator.formats.errors import FormatError


def _dof_name(joint_index: int | None, axis: str | int) -> tuple[bool, int]:
    """(is_root, axis 0..2) from ``(None | -1, "x"|"tx")`` or ``(j, "x"|"rx")``."""
    if isinstance(axis, str) and len(axis) == 2 and axis[0] in "tr":
        a = axis_index(axis[1])
        root = axis[0] == "t"
        if root != (joint_index is None or joint_index == ROOT):
            raise ValueError(f"axis {axis!r} does not fit joint {joint_index!r}")
        return root, a
    return (joint_index is None or joint_index == ROOT), axis_index(axis)


def dof_kind(joint_index: int | None, axis: str | int) -> tuple[str, int]:
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


def anim_channel_ids(asset_id: str, keys: list[str]) -> list[str]:
    """The ``.anim`` layout's channel ids for joints of these keys (see :func:`channel_ids`)."""
    ids = [channel_id(asset_id, "", d) for d in ROOT_DOFS]
    for key in keys:
        ids.extend(channel_id(asset_id, key, d) for d in JOINT_DOFS)
    return ids


def channel_ids(doc: Document, asset_id: str) -> list[str]:
    """The ``.anim`` layout's channel ids (root tx, ty, tz, then rx, ry, rz per joint).
    Joints keyed as quaternions, and translations and scales, are not in it: see
    :func:`all_channel_ids`."""
    return anim_channel_ids(asset_id, character(doc, asset_id).joint_keys)


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
    kind, a = dof_kind(joint_index, axis)
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
    ids = anim_channel_ids(asset_id, skeleton.joint_keys())
    if len(clip.channels) > len(ids):
        raise FormatError(f"the animation has {len(clip.channels)} channels, but the skeleton takes at most "
                          f"{len(ids)}.")
    return dict(zip(ids, clip.channels))
