"""The editing context every editor shares: document, undo stack, current frame, selection.

Editors talk to each other only through this object: they read the document, push
commands with :meth:`EditorContext.push`, and listen to the signals below.
"""

from __future__ import annotations

from PySide6.QtCore import QObject, Signal
from PySide6.QtGui import QUndoStack

from qtanimator.document.commands import Command
from qtanimator.document.document import ChangeEvent, Document
from qtanimator.ui.undo import push_command


class EditorContext(QObject):
    #: The current frame changed (float frames; the UI shows whole frames).
    frameChanged = Signal(float)
    #: The selected asset / joint changed: (asset id or "", joint name or "").
    selectionChanged = Signal(str, str)
    #: The selected channels changed (list of channel ids).
    channelSelectionChanged = Signal(list)
    #: A document change (a ChangeEvent).
    documentChanged = Signal(object)
    #: The whole document was replaced (New / Open / Recover).
    documentReset = Signal()
    #: Playback started (True) or stopped (False).
    playingChanged = Signal(bool)

    def __init__(self, doc: Document | None = None, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self.doc = doc if doc is not None else Document()
        self.undo_stack = QUndoStack(self)
        self._frame = 0.0
        self._selection: tuple[str, str] = ("", "")
        self._channel_selection: list[str] = []
        self.doc.subscribe(self._on_document_event)

    # ---------------------------------------------------------------- document
    def _on_document_event(self, event: ChangeEvent) -> None:
        if event.kind == "reset":
            self.documentReset.emit()
        else:
            self.documentChanged.emit(event)

    def push(self, command: Command) -> None:
        """Do a command and put it on the undo stack (merging drags into one step)."""
        push_command(self.undo_stack, self.doc, command)

    def replace_document(self, new: Document) -> None:
        """Take over ``new`` (already fully loaded) and clear the undo history."""
        self.undo_stack.clear()
        self._selection = ("", "")
        had_channels = bool(self._channel_selection)
        self._channel_selection = []
        self.doc.replace_all(new)
        self.undo_stack.setClean()
        start, _end = self.doc.frame_range
        self.set_frame(float(start))
        self.selectionChanged.emit("", "")
        if had_channels:
            self.channelSelectionChanged.emit([])

    # ------------------------------------------------------------------- time
    @property
    def frame(self) -> float:
        return self._frame

    @property
    def time(self) -> float:
        """Current time in seconds."""
        return self.doc.frame_to_time(self._frame)

    def set_frame(self, frame: float) -> None:
        if frame != self._frame:
            self._frame = float(frame)
            self.frameChanged.emit(self._frame)

    # -------------------------------------------------------------- selection
    @property
    def selection(self) -> tuple[str, str]:
        return self._selection

    def select(self, asset: str, joint: str = "") -> None:
        if (asset, joint) != self._selection:
            self._selection = (asset, joint)
            self.selectionChanged.emit(asset, joint)

    @property
    def channel_selection(self) -> list[str]:
        return list(self._channel_selection)

    def select_channels(self, cids: list[str]) -> None:
        if cids != self._channel_selection:
            self._channel_selection = list(cids)
            self.channelSelectionChanged.emit(list(cids))
