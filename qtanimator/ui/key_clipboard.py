"""The one key clipboard, shared by the editors that copy keys (dope sheet, curve editor).

Copied keys travel as JSON of :meth:`~qtanimator.document.keying.KeyClip.to_dict` under
:data:`KEY_CLIP_MIME`; without a system clipboard the last clip is kept here.
"""

from __future__ import annotations

import json

from PySide6.QtCore import QMimeData
from PySide6.QtGui import QGuiApplication

from qtanimator.document.keying import KeyClip

#: The clipboard format of copied keys (JSON of :meth:`KeyClip.to_dict`).
KEY_CLIP_MIME = "application/x-qtanimator-keys"
_clip_fallback: list[KeyClip] = []


def put_key_clip(clip: KeyClip) -> None:
    """Put copied keys on the clipboard (any editor that copies keys calls this)."""
    _clip_fallback[:] = [clip]
    mime = QMimeData()
    mime.setData(KEY_CLIP_MIME, json.dumps(clip.to_dict()).encode())
    clipboard = QGuiApplication.clipboard()
    if clipboard is not None:
        clipboard.setMimeData(mime)


def key_clip() -> KeyClip | None:
    """The keys on the clipboard, or None when it holds something else."""
    clipboard = QGuiApplication.clipboard()
    mime = clipboard.mimeData() if clipboard is not None else None
    if mime is None:
        return _clip_fallback[0] if _clip_fallback else None
    if not mime.hasFormat(KEY_CLIP_MIME):
        return None
    try:
        return KeyClip.from_dict(json.loads(bytes(mime.data(KEY_CLIP_MIME).data()).decode()))
    except (ValueError, KeyError, TypeError):
        return None


__all__ = ["KEY_CLIP_MIME", "key_clip", "put_key_clip"]
