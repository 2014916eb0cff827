"""The ``character2d`` asset kind: loading a 2D character, finding it in the document, and
its channel ids.

One asset of kind ``character2d`` per character (``source`` = the SVG file or folder,
property ``index`` = which character of a folder); the loaded
:class:`~qtanimator.core.rig2d.Character` lives in ``doc.runtime``. Channels:
``"<asset>/<joint name>/angle"`` per joint and ``"<asset>//x"``, ``"<asset>//y"`` for the
translation (see :mod:`qtanimator.document.character2d`).
"""

from __future__ import annotations

from typing import Any

from qtanimator.core.channel import Channel
from qtanimator.core.rig2d import Character
from qtanimator.document.document import Asset, Document, channel_id

ASSET_KIND = "character2d"


def load_character_asset(asset: Asset) -> Character:
    """Loader for ``character2d`` assets (registered in :mod:`qtanimator.document.loaders`)."""
    from qtanimator.formats.errors import FormatError
    from qtanimator.formats.svg_rig import load_characters, load_rigged_character

    if asset.source is None:
        raise FormatError(f"the 2D character '{asset.id}' has no source file.")
    index = int(asset.properties.get("index", 0))
    rig = asset.properties.get("rig")
    if rig is not None:  # rigged in the program (qtanimator.document.rigging): the SVG is unchanged
        return load_rigged_character(asset.source, index, rig)
    chars = load_characters(asset.source)
    if not 0 <= index < len(chars):
        raise FormatError(f"the 2D character '{asset.id}' refers to character {index + 1}, but the "
                          f"source holds {len(chars)}.", asset.source)
    return chars[index]


def character(doc: Document, asset_id: str) -> Character:
    ch = doc.runtime.get(asset_id)
    if ch is None:
        asset = doc.assets[asset_id]
        if asset.kind != ASSET_KIND:
            raise KeyError(f"{asset_id} is not a 2D character")
        ch = load_character_asset(asset)
        doc.runtime[asset_id] = ch
    if not isinstance(ch, Character):
        raise KeyError(f"{asset_id} is not a 2D character")
    return ch


def character_assets(doc: Document) -> list[str]:
    return [a.id for a in doc.assets.values() if a.kind == ASSET_KIND]


def angle_channel_id(asset_id: str, joint_name: str) -> str:
    return channel_id(asset_id, joint_name, "angle")


def position_channel_ids(asset_id: str) -> tuple[str, str]:
    return channel_id(asset_id, "", "x"), channel_id(asset_id, "", "y")


def channel_for(doc: Document, asset_id: str, joint_index: int) -> Channel | None:
    ch = character(doc, asset_id)
    return doc.channels.get(angle_channel_id(asset_id, ch.joints[joint_index].name))


def summary(doc: Document, asset_id: str) -> dict[str, Any]:
    ch = character(doc, asset_id)
    return {"joints": len(ch.joints), "dynamic": int(ch.dynamic.sum())}
