"""Poses: auto-key, the unkeyed (pending) pose, set key, and pose copy / paste.

Auto-key
    ``autokey(doc)``: when on (the default), posing a character keys it at once. It is
    view state (``doc.view_state["animation.autokey"]``): saved with the project (as
    Blender keeps its record button per scene), never an edit — no undo step, the
    document is not marked modified by the toggle.

The pending pose
    With auto-key off a drag poses without keying: the values go to the document's
    *pending pose* — channel values shown at one time, held in ``doc.caches`` (never in
    the channels, never saved, never in the undo history). Every evaluation at that
    time sees them (the 2D editor, the 3D view, the joint tree and the values set key
    reads), so all views agree on what is shown. The pending pose is dropped when the
    frame changes (the views call :func:`clear_pending`) or the document is replaced,
    and a channel's pending value no longer counts once that channel changes (it was
    keyed, an editor changed it; see :class:`PendingPose`). Changes of the pending pose
    are announced as the pseudo parameter :data:`PENDING_CHANGE` (views redraw; no
    cache is invalidated). Physics does not see it: pendulums keep simulating from the
    keys. An export of that very frame made while the pose is pending shows it too
    (Blender's still render does the same); a project opened from disk never has one.

Set key
    :func:`key_selection_command` keys the shown values (pending or evaluated) of one
    joint (3D: its three rotations) — or, with the character selected (joint ``""``; in
    the 2D editor a click on the root), its root and position — and
    :func:`key_character_command` every joint of a character (2D: every keyframed joint
    and the position, the per-character part of the universal keyframe; 3D: every DOF).
    Set key is explicit: it keys exactly those channels, key-all or not.

Copy / paste
    :func:`copy_pose` takes one joint's values, or the whole character's joint rotations
    (not its position: a pose is how the character bends, not where it stands);
    :func:`paste_pose_command` keys them at a time on any character of the same kind
    (joints matched by name), mirrored on request (:func:`mirror_name`,
    :func:`mirrored_value`).
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

import numpy as np

from qtanimator.core.channel import Key
from qtanimator.core.rig2d import Character
from qtanimator.core.skeleton import Skeleton
from qtanimator.document import character2d as c2d
from qtanimator.document import character3d as c3d
from qtanimator.document.commands import Command, SetKeys
from qtanimator.document.document import Document, channel_id
from qtanimator.document.pending_pose import (
    PENDING_CHANGE,
    PendingPose,
    PosePreview,
    clear_pending,
    has_pending,
    pending_store,
    pending_value,
    pending_values,
)

AUTOKEY_VIEW_STATE = "animation.autokey"


# ---------------------------------------------------------------------- auto-key
def autokey(doc: Document) -> bool:
    """True when posing keys at once (the default)."""
    return bool(doc.view_state.get(AUTOKEY_VIEW_STATE, True))


def set_autokey(doc: Document, on: bool) -> None:
    """Turn auto-key on or off for this project (view state: no undo step)."""
    doc.set_view_state(AUTOKEY_VIEW_STATE, bool(on))


# ------------------------------------------------------------------ the shown pose
def _kind(doc: Document, asset_id: str) -> str:
    return doc.assets[asset_id].kind


def shown_values_2d(doc: Document, asset_id: str, time: float,
                    cids: Iterable[str] | None = None) -> dict[str, float]:
    """Channel values of a 2D character as shown at ``time`` (``cids``, or all):
    keyframed joints' local angles and the position from the channels and the pending
    pose; dynamic joints' world angles from the exact simulation — run only when one of
    them is asked for."""
    ch = c2d.character(doc, asset_id)
    wanted = None if cids is None else set(cids)
    ids = [c2d.angle_channel_id(asset_id, j.name) for j in ch.joints]
    dynamic = [k for k, j in enumerate(ch.joints) if j.is_dynamic and (wanted is None or ids[k] in wanted)]
    angles = c2d.keyframed_angles(doc, asset_id, time)
    out: dict[str, float] = {}
    for k, j in enumerate(ch.joints):
        if not j.is_dynamic:
            out[ids[k]] = float(angles[k])
    if dynamic:
        world = c2d.evaluate_pose(doc, asset_id, time).world_angles
        for k in dynamic:
            out[ids[k]] = float(world[k])
    cx, cy = c2d.position_channel_ids(asset_id)
    t = c2d.translation(doc, asset_id, time)
    out[cx], out[cy] = float(t[0]), float(t[1])
    return out if wanted is None else {cid: v for cid, v in out.items() if cid in wanted}


def shown_values_3d(doc: Document, asset_id: str, time: float) -> dict[str, float]:
    """Every DOF channel value of a 3D character as shown at ``time`` (clamped)."""
    return c3d.pose_channel_values(doc, asset_id, time)


def shown_values(doc: Document, asset_id: str, time: float, cids: Iterable[str] | None = None) -> dict[str, float]:
    """The channel values of a character as shown at ``time`` (pending or evaluated)."""
    kind = _kind(doc, asset_id)
    if kind == c2d.ASSET_KIND:
        return shown_values_2d(doc, asset_id, time, cids)
    if kind == c3d.ASSET_KIND:
        return shown_values_3d(doc, asset_id, time)
    raise KeyError(f"{asset_id} is not a character")


def joint_channels(doc: Document, asset_id: str, joint: str) -> list[str]:
    """The channels set key keys for a selection: a joint's rotation channel(s); with
    ``joint`` "" (the character selected) its root joint and its position."""
    kind = _kind(doc, asset_id)
    if kind == c2d.ASSET_KIND:
        ch = c2d.character(doc, asset_id)
        if not joint:
            return [c2d.angle_channel_id(asset_id, ch.joints[0].name), *c2d.position_channel_ids(asset_id)]
        ch.joint_index(joint)  # KeyError for an unknown joint
        return [c2d.angle_channel_id(asset_id, joint)]
    if kind == c3d.ASSET_KIND:
        skel = c3d.character(doc, asset_id).skeleton
        keys = skel.joint_keys()
        index = keys.index(joint) if joint else 0
        ids = [channel_id(asset_id, keys[index], d) for d in c3d.joint_channel_names(skel.joints[index])]
        if index == 0:
            ids += [c3d.dof_channel_id(doc, asset_id, None, a) for a in c3d.ROOT_DOFS]
        return ids
    raise KeyError(f"{asset_id} is not a character")


def character_channels(doc: Document, asset_id: str) -> list[str]:
    """The channels "key the whole character" keys: 2D every keyframed (non-pendulum)
    joint and the position; 3D every DOF."""
    kind = _kind(doc, asset_id)
    if kind == c2d.ASSET_KIND:
        ch = c2d.character(doc, asset_id)
        ids = [c2d.angle_channel_id(asset_id, j.name) for j in ch.joints if not j.is_dynamic]
        return ids + list(c2d.position_channel_ids(asset_id))
    if kind == c3d.ASSET_KIND:
        return list(c3d.all_channel_ids(doc, asset_id))
    raise KeyError(f"{asset_id} is not a character")


def key_channels_command(doc: Document, asset_id: str, cids: Iterable[str], time: float,
                         text: str = "Set Key") -> Command:
    """Key the shown values of ``cids`` at ``time`` (one undo step)."""
    cids = list(cids)
    shown = shown_values(doc, asset_id, time, cids)
    if _kind(doc, asset_id) == c3d.ASSET_KIND:
        keys = {cid: c3d.new_key(cid, time, shown[cid]) for cid in cids}
    else:
        keys = {cid: Key(float(time), shown[cid]) for cid in cids}
    return SetKeys(doc, keys, text=text)


def key_selection_command(doc: Document, asset_id: str, joint: str, time: float) -> Command:
    """S / I: key the selected joint (or, with the character selected, its root and position)."""
    return key_channels_command(doc, asset_id, joint_channels(doc, asset_id, joint), time,
                                f"Set Key {joint or asset_id}")


def key_character_command(doc: Document, asset_id: str, time: float) -> Command:
    """Shift+S: key every joint of the character."""
    return key_channels_command(doc, asset_id, character_channels(doc, asset_id), time,
                                f"Set Key {asset_id} (all joints)")


# ------------------------------------------------------------------ mirror names
_SIDE_WORDS = {"left": "right", "right": "left"}
_SIDE_LETTERS = {"l": "r", "r": "l"}
_TOKEN = re.compile(r"[A-Za-z]+|[^A-Za-z]+")


def _match_case(word: str, like: str) -> str:
    if like.isupper():
        return word.upper()
    if like[:1].isupper():
        return word.capitalize()
    return word.lower()


def _swap_letters(letters: str, first: bool) -> str | None:
    """A mirrored run of letters, or None when it carries no side marker."""
    low = letters.lower()
    if low in _SIDE_WORDS:  # "left", "Right", "LEFT"
        return _match_case(_SIDE_WORDS[low], letters)
    if low in _SIDE_LETTERS:  # a lone "L" / "r" between separators: "L_arm", "arm.R"
        return _match_case(_SIDE_LETTERS[low], letters)
    # CamelCase: "LeftArm", "armLeft", "RightUpLeg"; a capital "L"/"R" prefix: "LHipJoint".
    m = re.fullmatch(r"(Left|Right|LEFT|RIGHT)([A-Z].*)", letters)
    if m:
        return _match_case(_SIDE_WORDS[m.group(1).lower()], m.group(1)) + m.group(2)
    m = re.fullmatch(r"(.*[a-z])(Left|Right)", letters)
    if m:
        return m.group(1) + _SIDE_WORDS[m.group(2).lower()].capitalize()
    m = re.fullmatch(r"([LR])([A-Z][a-z].*)", letters)
    if m and first:
        return ("R" if m.group(1) == "L" else "L") + m.group(2)
    return None


def mirror_name(name: str) -> str:
    """The joint name on the other side: left/right markers swapped ("arm_left" ↔
    "arm_right", "L_arm" ↔ "R_arm", "arm.L" ↔ "arm.R", "LeftArm" ↔ "RightArm",
    "LHipJoint" ↔ "RHipJoint", any case). A name without a marker is its own mirror."""
    out = []
    first = True
    for part in _TOKEN.findall(name):
        if part[:1].isalpha():
            swapped = _swap_letters(part, first)
            out.append(part if swapped is None else swapped)
            first = False
        else:
            out.append(part)
    return "".join(out)


def has_side(name: str) -> bool:
    return mirror_name(name) != name


# ----------------------------------------------------------------- copy / paste
@dataclass(frozen=True)
class PoseClip:
    """A copied pose: per joint name (3D: joint key) its values by DOF ("angle" in 2D,
    "rx" / "ry" / "rz" in 3D), from a character of ``kind``."""

    kind: str
    source: str
    values: Mapping[str, Mapping[str, float]] = field(default_factory=dict)

    @property
    def joints(self) -> list[str]:
        return list(self.values)


def copy_pose(doc: Document, asset_id: str, joint: str, time: float) -> PoseClip:
    """Ctrl+C: the shown values of the selected joint, or with the character selected
    (``joint`` "") of all its joints (2D: keyframed joints; pendulums are physics) —
    rotations only, never the position."""
    kind = _kind(doc, asset_id)
    values: dict[str, dict[str, float]] = {}
    if kind == c2d.ASSET_KIND:
        ch = c2d.character(doc, asset_id)
        names = [joint] if joint else [j.name for j in ch.joints if not j.is_dynamic]
        for name in names:
            ch.joint_index(name)  # KeyError for an unknown joint
        shown = shown_values_2d(doc, asset_id, time, [c2d.angle_channel_id(asset_id, n) for n in names])
        for name in names:
            values[name] = {"angle": shown[c2d.angle_channel_id(asset_id, name)]}
    else:
        # Euler angles whatever the joint is keyed in (a quaternion joint's are converted).
        posed = c3d.pose_skeleton(doc, asset_id, time)
        keys = posed.joint_keys()
        chosen = [joint] if joint else list(keys)
        for key in chosen:
            pose = posed.joints[keys.index(key)].pose
            values[key] = {a: float(v) for a, v in zip(c3d.JOINT_DOFS, pose)}
    return PoseClip(kind, asset_id, values)


def mirror_negates_2d(character: Character) -> bool:
    """Whether mirroring a 2D character's pose negates its angles.

    A pose mirrors about the character's own left/right plane. Seen from the front (the
    left and right joints' rest pivots lie on either side), that plane is the vertical
    screen line through the character: a mirror reverses the sense of every rotation,
    so angles negate. Seen from the side (each left/right pair shares its pivot), the
    plane is the screen itself: the limbs only trade places, angles are kept.
    """
    by_name = {j.name: j for j in character.joints}
    xs = np.array([j.pivot[0] for j in character.joints], dtype=float)
    width = float(xs.max() - xs.min()) if len(xs) else 0.0
    pairs = [(j, by_name[mirror_name(j.name)]) for j in character.joints
             if has_side(j.name) and mirror_name(j.name) in by_name]
    if not pairs:
        return True
    return any(abs(float(a.pivot[0] - b.pivot[0])) > 0.02 * max(width, 1e-9) for a, b in pairs)


def lateral_axis_3d(skeleton: Skeleton) -> int:
    """The skeleton's left-right axis (0 = x, 1 = y, 2 = z): where the rest offsets of its
    left/right joint pairs differ most (x when it has no pairs)."""
    names = [j.name for j in skeleton.joints]
    spread = np.zeros(3)
    for i, name in enumerate(names):
        other = mirror_name(name)
        if other != name and other in names:
            k = names.index(other)
            spread += np.abs(np.asarray(skeleton.joints[i].offset, dtype=float)
                             - np.asarray(skeleton.joints[k].offset, dtype=float))
    return int(np.argmax(spread)) if spread.any() else 0


def mirrored_value(kind: str, dof: str, value: float, negate_2d: bool = True, lateral: int = 0) -> float:
    """A value mirrored about the character's left/right plane.

    2D: the angle negates for a rig seen from the front and is kept for one seen from the
    side (see :func:`mirror_negates_2d`). 3D Euler DOFs: reflecting the lateral axis
    (x by default) keeps the rotation about that axis and negates the other two — each
    factor of T·Rz·Ry·Rx (any order) conjugates on its own, so this holds for every
    rotation order, for joints whose rest frames are aligned with the skeleton's axes
    (CSE 169, MIT, BVH offsets).
    """
    if kind == c2d.ASSET_KIND:
        return -value if negate_2d else value
    axis = "xyz".index(dof[-1])
    return value if axis == lateral else -value


def _name_and_rank(keys: list[str], key: str) -> tuple[str, int]:
    """A 3D joint key "name" or "name#index" as (name, how many earlier joints share it)."""
    index = keys.index(key)
    name = key.split("#", 1)[0]
    rank = sum(1 for k in keys[:index] if k.split("#", 1)[0] == name)
    return name, rank


def _key_of(keys: list[str], name: str, rank: int) -> str | None:
    seen = 0
    for k in keys:
        if k.split("#", 1)[0] == name:
            if seen == rank:
                return k
            seen += 1
    return None


def paste_values(doc: Document, clip: PoseClip, asset_id: str, mirrored: bool = False,
                 time: float | None = None) -> dict[str, float]:
    """The channel values pasting ``clip`` onto ``asset_id`` sets (joints the character
    does not have are left out). Mirrored: each joint's values go to its mirror-named
    joint (itself when it has no side), mirrored by :func:`mirrored_value`. Values are
    clamped to the target joints' limits (2D and 3D)."""
    kind = _kind(doc, asset_id)
    if kind != clip.kind:
        return {}
    out: dict[str, float] = {}
    if kind == c2d.ASSET_KIND:
        ch = c2d.character(doc, asset_id)
        names = {j.name for j in ch.joints}
        negate = mirror_negates_2d(ch)
        for name, dofs in clip.values.items():
            target = mirror_name(name) if mirrored else name
            if target not in names:
                continue
            value = float(dofs["angle"])
            out[c2d.angle_channel_id(asset_id, target)] = (
                mirrored_value(kind, "angle", value, negate_2d=negate) if mirrored else value)
        # Clamped to the target joints' limits (a pendulum's local angle at ``time``).
        return c2d.clamp_values(doc, out, 0.0 if time is None else time)
    runtime = c3d.character(doc, asset_id)
    keys = list(runtime.joint_keys)
    source_keys = keys
    if clip.source in doc.assets and doc.assets[clip.source].kind == kind and clip.source in doc.runtime:
        source_keys = list(c3d.character(doc, clip.source).joint_keys)
    lateral = lateral_axis_3d(runtime.skeleton)
    dof_values: dict[tuple[int | None, str | int], float] = {}
    for key, dofs in clip.values.items():
        found: str | None
        if mirrored:
            name, rank = _name_and_rank(source_keys, key) if key in source_keys else (key.split("#", 1)[0], 0)
            found = _key_of(keys, mirror_name(name), rank)
        else:
            found = key if key in keys else None
        if found is None:
            continue
        index = keys.index(found)
        for dof, value in dofs.items():
            v = mirrored_value(kind, dof, float(value), lateral=lateral) if mirrored else float(value)
            dof_values[(index, dof)] = v
    # Clamped to the limits; a joint keyed as a quaternion gets its four components.
    return c3d.dof_values(doc, asset_id, dof_values, time)


def paste_pose_command(doc: Document, clip: PoseClip, asset_id: str, time: float,
                       mirrored: bool = False) -> Command | None:
    """Ctrl+V / Ctrl+Shift+V: key the clip's values at ``time`` (one undo step); None
    when nothing of the clip fits the character."""
    values = paste_values(doc, clip, asset_id, mirrored, time)
    if not values:
        return None
    if _kind(doc, asset_id) == c3d.ASSET_KIND:
        keys = {cid: c3d.new_key(cid, time, v) for cid, v in values.items()}
    else:
        keys = {cid: Key(float(time), v) for cid, v in values.items()}
    return SetKeys(doc, keys, text="Paste Pose Mirrored" if mirrored else "Paste Pose")


def is_character(doc: Document, asset_id: str) -> bool:
    asset = doc.assets.get(asset_id)
    if asset is None or asset_id not in doc.runtime:
        return False
    return asset.kind in (c2d.ASSET_KIND, c3d.ASSET_KIND)


__all__ = [
    "AUTOKEY_VIEW_STATE", "PENDING_CHANGE", "PendingPose", "PoseClip", "PosePreview", "autokey",
    "character_channels", "clear_pending", "copy_pose", "has_pending", "is_character", "joint_channels",
    "key_channels_command", "key_character_command", "key_selection_command", "mirror_name",
    "mirrored_value", "paste_pose_command", "paste_values", "pending_store", "pending_value",
    "pending_values", "set_autokey", "shown_values",
]
