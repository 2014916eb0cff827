"""Rigging a 2D character inside the program (Spine's setup mode), as undoable commands.

The rig is data on the asset: the property ``rig`` holds a rig spec (the joints, their
parents, the SVG elements each one draws, pivots and dynamic flags; see
:mod:`qtanimator.formats.svg_rig`). The loader (``character2d.load_character_asset``)
builds the character from the unchanged SVG plus that spec, so a rig made here is saved
with the project and the SVG file is never rewritten.

Every command here replaces the asset (with the new ``rig`` property) and its runtime
character together; undo puts back the old asset object and character, so the document
is exactly as before (an unrigged asset has no ``rig`` property at all). Channels are
named by joint name, so the channels of joints that keep their names stay; removing a
joint removes its channels (undo restores them). A pivot drag is one gesture: commands
with the same gesture token merge.
"""

from __future__ import annotations

import copy
from collections.abc import Hashable, Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from qtanimator.core.channel import Channel
from qtanimator.core.rig2d import Character
from qtanimator.document.character2d_asset import ASSET_KIND, character, load_character_asset
from qtanimator.document.commands import Command
from qtanimator.document.document import Asset, Document, split_channel_id

RIG_PROPERTY = "rig"


class RigError(ValueError):
    """A rigging edit that cannot be made (the message says why, for the status bar)."""


def rig_spec(doc: Document, asset_id: str) -> dict[str, Any]:
    """A copy of the asset's rig spec: its ``rig`` property, or the rig the SVG's own
    rules made (the whole drawing as one joint for ordinary art)."""
    asset = doc.assets[asset_id]
    if asset.kind != ASSET_KIND:
        raise RigError(f"{asset_id} is not a 2D character.")
    spec = asset.properties.get(RIG_PROPERTY)
    if spec is None:
        spec = character(doc, asset_id).rig_spec
    if spec is None:
        raise RigError(f"{asset_id} cannot be rigged here.")
    return copy.deepcopy(spec)


def _row(spec: dict[str, Any], name: str) -> dict[str, Any]:
    for r in spec["joints"]:
        if r["name"] == name:
            return dict(r)
    raise RigError(f"there is no joint '{name}'.")


def _replace_row(spec: dict[str, Any], row: dict[str, Any]) -> None:
    spec["joints"] = [row if r["name"] == row["name"] else r for r in spec["joints"]]


def _descendants(spec: dict[str, Any], name: str) -> set[str]:
    out: set[str] = set()
    stack = [name]
    while stack:
        n = stack.pop()
        for r in spec["joints"]:
            if r.get("parent") == n and r["name"] not in out:
                out.add(r["name"])
                stack.append(r["name"])
    return out


def _same_elements(ch: Character, spec: dict[str, Any]) -> Character:
    """``ch`` with the pivots and dynamic flags of ``spec`` (same joints, same order): what
    the loader would build, without reading the SVG again (a pivot drag previews live)."""
    rows = {r["name"]: r for r in spec["joints"]}
    joints = []
    for j in ch.joints:
        r = rows[j.name]
        joints.append(replace(j, pivot=np.array(r["pivot"], dtype=np.float64), is_dynamic=bool(r["dynamic"]),
                              is_spring=bool(r.get("spring", False)),
                              children=[], mass_properties=None, reference_mass_properties=None))
    out = Character(ch.name, joints, source=ch.source, warnings=ch.warnings)
    out.joint_candidates = list(ch.joint_candidates)
    out.candidate_elements = dict(ch.candidate_elements)
    out.rig_spec = copy.deepcopy(spec)
    return out


class SetRig(Command):
    """Replace an asset's rig spec (and its character); channels may change with it."""

    def __init__(self, doc: Document, asset_id: str, spec: dict[str, Any], text: str,
                 runtime: Character | None = None, channels: dict[str, Channel | None] | None = None,
                 gesture: Hashable | None = None) -> None:
        self.asset_id = asset_id
        self.text = text
        self.gesture = gesture
        self.old_asset = doc.assets[asset_id]
        self.old_runtime = doc.runtime.get(asset_id)
        new = self.old_asset.copy()
        new.properties[RIG_PROPERTY] = copy.deepcopy(spec)
        self.new_asset: Asset = new
        self.new_runtime = runtime if runtime is not None else load_character_asset(new)
        self.channels = {cid: (doc.channels.get(cid), ch) for cid, ch in (channels or {}).items()}

    def do(self, doc: Document) -> None:
        for cid, (_old, new) in self.channels.items():
            doc.apply_channel(cid, new)
        doc.apply_asset(self.asset_id, self.new_asset, self.new_runtime)

    def undo(self, doc: Document) -> None:
        if self.old_runtime is None:
            doc.runtime.pop(self.asset_id, None)
        doc.apply_asset(self.asset_id, self.old_asset, self.old_runtime)
        for cid, (old, _new) in reversed(list(self.channels.items())):
            doc.apply_channel(cid, old)

    def merge(self, other: Command) -> bool:
        if (self.gesture is None or not isinstance(other, SetRig) or other.gesture != self.gesture
                or other.asset_id != self.asset_id):
            return False
        self.new_asset, self.new_runtime = other.new_asset, other.new_runtime
        for cid, (old, new) in other.channels.items():
            self.channels[cid] = (self.channels[cid][0] if cid in self.channels else old, new)
        return True

    def is_noop(self) -> bool:
        return bool(self.old_asset.properties == self.new_asset.properties
                    and all(a is b for a, b in self.channels.values()))


# ------------------------------------------------------------------- commands
def candidates(doc: Document, asset_id: str) -> list[str]:
    """The drawing's layers and top-level groups that are not joints yet (menu order)."""
    ch = character(doc, asset_id)
    spec = rig_spec(doc, asset_id)
    claimed = {e for r in spec["joints"] for e in r.get("elements", [])}
    return [c for c in ch.joint_candidates if ch.candidate_elements.get(c) not in claimed]


def _unique(spec: dict[str, Any], base: str) -> str:
    names = {r["name"] for r in spec["joints"]}
    base = base.strip().replace("/", "_") or "joint"
    name, k = base, 2
    while name in names:
        name = f"{base}_{k}"
        k += 1
    return name


def make_joint_command(doc: Document, asset_id: str, elements: Sequence[str], name: str,
                       parent: str | None = None) -> SetRig:
    """A new joint drawing the SVG ``elements`` (refs), child of ``parent`` (the root by
    default), its pivot at the centre of its box."""
    spec = rig_spec(doc, asset_id)
    refs = [str(e) for e in elements]
    if not refs:
        raise RigError("a joint needs at least one element of the drawing.")
    claimed = {e for r in spec["joints"] for e in r.get("elements", [])}
    if any(e in claimed for e in refs):
        raise RigError("that part of the drawing is a joint already.")
    root = next(r["name"] for r in spec["joints"] if r.get("parent") is None)
    parent = parent or root
    _row(spec, parent)
    name = _unique(spec, name)
    spec["joints"].append({"name": name, "parent": parent, "elements": refs, "pivot": None, "dynamic": False})
    asset = doc.assets[asset_id].copy()
    asset.properties[RIG_PROPERTY] = spec
    built = load_character_asset(asset)
    assert built.rig_spec is not None
    return SetRig(doc, asset_id, built.rig_spec, f"Make Joint {name}", runtime=built)


def make_joint_from_candidate(doc: Document, asset_id: str, label: str, parent: str | None = None) -> SetRig:
    """Make a joint of one of ``Character.joint_candidates`` (a layer or top-level group)."""
    ch = character(doc, asset_id)
    ref = ch.candidate_elements.get(label)
    if ref is None:
        raise RigError(f"the drawing has no layer or group '{label}'.")
    return make_joint_command(doc, asset_id, [ref], label, parent)


def set_pivot_command(doc: Document, asset_id: str, joint: str, xy: Sequence[float],
                      gesture: Hashable | None = None) -> SetRig:
    """Move a joint's rest-pose pivot to ``xy`` (drawing units)."""
    spec = rig_spec(doc, asset_id)
    row = _row(spec, joint)
    row["pivot"] = [float(xy[0]), float(xy[1])]
    _replace_row(spec, row)
    return SetRig(doc, asset_id, spec, f"Move Pivot of {joint}",
                  runtime=_same_elements(character(doc, asset_id), spec), gesture=gesture)


def set_dynamic_command(doc: Document, asset_id: str, joint: str, dynamic: bool) -> SetRig:
    """Mark a joint dynamic (a pendulum) or keyframed. The root cannot swing."""
    spec = rig_spec(doc, asset_id)
    row = _row(spec, joint)
    if row.get("parent") is None and dynamic:
        raise RigError("the root joint cannot be dynamic: a pendulum hangs from a parent.")
    row["dynamic"] = bool(dynamic)
    row.pop("spring", None)
    _replace_row(spec, row)
    return SetRig(doc, asset_id, spec, f"Mark {joint} {'Dynamic' if dynamic else 'Keyframed'}",
                  runtime=_same_elements(character(doc, asset_id), spec))


#: What drives a joint: its keys, a pendulum, or a spring that follows its keys.
JOINT_MODES = ("keyframed", "dynamic", "spring")


def joint_mode(doc: Document, asset_id: str, joint: str) -> str:
    """``keyframed``, ``dynamic`` or ``spring``."""
    ch = character(doc, asset_id)
    j = ch.joints[ch.joint_index(joint)]
    return "dynamic" if j.is_dynamic else "spring" if j.is_spring else "keyframed"


def set_joint_mode_command(doc: Document, asset_id: str, joint: str, mode: str) -> SetRig:
    """Make a joint keyframed, dynamic (a pendulum; not the root) or a spring joint (its
    local angle follows its keys through a damped spring). The rig spec row gets
    ``"spring": true`` for a spring joint, as ``"dynamic"`` marks a pendulum; the joint's
    channel is kept as it is."""
    if mode not in JOINT_MODES:
        raise RigError(f"unknown joint mode '{mode}' (known: {', '.join(JOINT_MODES)}).")
    if mode != "spring":
        return set_dynamic_command(doc, asset_id, joint, mode == "dynamic")
    spec = rig_spec(doc, asset_id)
    row = _row(spec, joint)
    row["dynamic"] = False
    row["spring"] = True
    _replace_row(spec, row)
    return SetRig(doc, asset_id, spec, f"Make {joint} a Spring", runtime=_same_elements(character(doc, asset_id), spec))


def reparent_command(doc: Document, asset_id: str, joint: str, parent: str) -> SetRig:
    """Make ``parent`` the parent of ``joint`` (RigError for the root or a cycle)."""
    spec = rig_spec(doc, asset_id)
    row = _row(spec, joint)
    _row(spec, parent)
    if row.get("parent") is None:
        raise RigError("the root joint has no parent to change.")
    if parent == joint or parent in _descendants(spec, joint):
        raise RigError(f"'{parent}' is '{joint}' or hangs from it: a joint cannot hang from itself.")
    row["parent"] = parent
    _replace_row(spec, row)
    asset = doc.assets[asset_id].copy()
    asset.properties[RIG_PROPERTY] = spec
    built = load_character_asset(asset)
    assert built.rig_spec is not None
    return SetRig(doc, asset_id, built.rig_spec, f"Re-parent {joint} to {parent}", runtime=built)


def remove_joint_command(doc: Document, asset_id: str, joint: str) -> SetRig:
    """Remove a joint: its elements go back to the root, its children to its parent, its
    channels are removed."""
    spec = rig_spec(doc, asset_id)
    row = _row(spec, joint)
    if row.get("parent") is None:
        raise RigError("the root joint cannot be removed.")
    spec["joints"] = [r for r in spec["joints"] if r["name"] != joint]
    for r in spec["joints"]:
        if r.get("parent") == joint:
            r["parent"] = row["parent"]
    asset = doc.assets[asset_id].copy()
    asset.properties[RIG_PROPERTY] = spec
    built = load_character_asset(asset)
    assert built.rig_spec is not None
    gone: dict[str, Channel | None] = {cid: None for cid, _ch in doc.channels_of(asset_id)
                                       if split_channel_id(cid)[1] == joint}
    return SetRig(doc, asset_id, built.rig_spec, f"Remove Joint {joint}", runtime=built, channels=gone)
