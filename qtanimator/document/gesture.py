"""The one gesture protocol: begin / update / commit / abort.

Every interactive edit that follows the mouse or a slider (a joint rotation, an IK drag, a
key or handle drag, a light drag, a slider drag) is a :class:`Gesture`:

* ``update(command)`` previews: the command is done on the document at once (one change
  notification) and folded into the gesture's one command;
* ``commit()`` records that one command as one undo step, without doing it again;
* ``abort()`` (Escape) undoes the preview exactly and records nothing.

Each update's command is built from the document as it is *now* (during the gesture), so
folding keeps the state from before the gesture as "old" and the last update as "new".
The editor context (``qtanimator.ui.context.EditorContext.begin_gesture``) records on the
QUndoStack; scripts and tests record on the Qt-free :class:`UndoStack`.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Hashable

from qtanimator.document.commands import Command, Macro
from qtanimator.document.document import Document

_tokens = itertools.count(1)


class Gesture:
    """One drag or slider movement, folded into one undoable command."""

    def __init__(self, doc: Document, text: str, record: Callable[[Command], None],
                 on_end: Callable[[Gesture], None] | None = None) -> None:
        self.doc = doc
        self.text = text
        self.token: Hashable = ("gesture", next(_tokens))
        self.command: Command | None = None
        self.updates = 0
        self._record = record
        self._on_end = on_end
        self._ended = False

    @property
    def active(self) -> bool:
        """True until the gesture is committed or aborted."""
        return not self._ended

    def update(self, command: Command | None) -> None:
        """Preview ``command`` (do it on the document now) and fold it into the gesture."""
        if self._ended:
            raise RuntimeError(f"the gesture '{self.text}' has ended")
        if command is None:
            return
        command.gesture = self.token
        with self.doc.batch():
            command.do(self.doc)
        self.updates += 1
        if self.command is None:
            self.command = command
        elif not self.command.merge(command):
            self.command = Macro(self.command.text, [self.command, command], gesture=self.token)

    def commit(self) -> Command | None:
        """End the gesture: its folded command becomes one undo step (not done again).

        A gesture that ends where it began records nothing. Returns the recorded command.
        """
        if self._ended:
            return None
        self._end()
        command, self.command = self.command, None
        if command is None or command.is_noop():
            return None
        command.text = self.text or command.text
        self._record(command)
        return command

    def abort(self) -> None:
        """End the gesture and put the document back exactly as it was before it began."""
        if self._ended:
            return
        self._end()
        command, self.command = self.command, None
        if command is not None:
            with self.doc.batch():
                command.undo(self.doc)

    def discard(self) -> None:
        """End the gesture without recording or undoing anything: the document it edited
        was replaced (File ▸ Open), so there is nothing left to put back."""
        if not self._ended:
            self._end()
            self.command = None

    def _end(self) -> None:
        self._ended = True
        if self._on_end is not None:
            self._on_end(self)
