"""The project document, its Qt-free commands, and evaluation of the scene at a time."""

from qtanimator.document.commands import (
    AddAsset,
    Command,
    DeleteKeys,
    EditKey,
    InsertKey,
    Macro,
    MoveKeys,
    RemoveAsset,
    SetAssetProperty,
    SetChannels,
    SetExtrapolation,
    SetKeys,
    SetParameter,
    SetTangents,
    UndoStack,
)
from qtanimator.document.document import Asset, Document, DocumentChange, channel_id, split_channel_id
from qtanimator.document.io import open_document, save_document

__all__ = [
    "AddAsset", "Asset", "Command", "DeleteKeys", "Document", "DocumentChange", "EditKey",
    "InsertKey", "Macro", "MoveKeys", "RemoveAsset", "SetAssetProperty", "SetChannels",
    "SetExtrapolation", "SetKeys", "SetParameter", "SetTangents", "UndoStack", "channel_id",
    "open_document", "save_document", "split_channel_id",
]
