"""3D characters read from ``.bvh`` files: :class:`BvhCharacter`, and the position
convention they are posed with (asset property :data:`BVH_POSITIONS`,
:func:`set_bvh_positions_command`).

The skeleton has one rotation order per joint; the motion lives in the document's channels.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from qtanimator.core.channel import Channel
from qtanimator.core.skeleton import DEFAULT_BOXMAX, DEFAULT_BOXMIN
from qtanimator.document.character3d_model import ASSET_KIND, TRANSLATE_DOFS, Character3D
from qtanimator.document.commands import Command
from qtanimator.document.document import Document, channel_id
from qtanimator.formats.bvh import POSITION_CONVENTIONS, load_bvh
from qtanimator.formats.errors import FormatError


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
