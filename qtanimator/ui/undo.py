"""The QUndoStack adapter: each Qt-free command becomes one QUndoCommand."""

from __future__ import annotations

from PySide6.QtGui import QUndoCommand, QUndoStack

from qtanimator.document.commands import Command
from qtanimator.document.document import Document

_MERGE_ID = 0x51A  # any id other than -1 lets Qt ask mergeWith; Command.merge decides


class DocumentUndoCommand(QUndoCommand):
    """One Qt-free command on the QUndoStack. Each do and undo is one document batch, so
    it announces one change however many channels it touches.

    ``done``: the command is already done (a committed gesture): QUndoStack.push calls
    ``redo`` once, which then does nothing; later redos do the command again.
    """

    def __init__(self, doc: Document, command: Command, done: bool = False, mergeable: bool = True) -> None:
        super().__init__(command.text)
        self.doc = doc
        self.command = command
        self._skip_redo = done
        self._mergeable = mergeable

    def redo(self) -> None:
        if self._skip_redo:
            self._skip_redo = False
            return
        with self.doc.batch():
            self.command.do(self.doc)

    def undo(self) -> None:
        with self.doc.batch():
            self.command.undo(self.doc)

    def id(self) -> int:
        return _MERGE_ID if self._mergeable and self.command.gesture is not None else -1

    def mergeWith(self, other: QUndoCommand) -> bool:
        if not isinstance(other, DocumentUndoCommand):
            return False
        merged = self.command.merge(other.command)
        if merged:
            self.setText(self.command.text)
            # A drag that ends where it began leaves no step behind.
            self.setObsolete(self.command.is_noop())
        return merged


def push_command(stack: QUndoStack, doc: Document, command: Command) -> None:
    """Do ``command`` and record it (merging with the previous one of the same gesture), as
    the Qt-free :meth:`UndoStack.push <qtanimator.document.commands.UndoStack.push>` does.

    A command that changes nothing is done here and pushed obsolete: Qt then never does it
    again and never keeps it, but the push still drops the redo history and lets the top
    command of the same gesture merge it (a drag back to where it began).
    """
    if command.is_noop():
        with doc.batch():
            command.do(doc)
        _push_obsolete(stack, doc, command, mergeable=True)
        return
    stack.push(DocumentUndoCommand(doc, command))


def record_command(stack: QUndoStack, doc: Document, command: Command) -> None:
    """Record a command that is already done (a committed gesture) as one undo step; one
    that changes nothing is not recorded but, like any record, drops the redo history."""
    if command.is_noop():
        _push_obsolete(stack, doc, command, mergeable=False)
        return
    stack.push(DocumentUndoCommand(doc, command, done=True))


def _push_obsolete(stack: QUndoStack, doc: Document, command: Command, mergeable: bool) -> None:
    wrapper = DocumentUndoCommand(doc, command, done=True, mergeable=mergeable)
    wrapper.setObsolete(True)  # QUndoStack.push neither does nor keeps it
    stack.push(wrapper)


def drop_gesture(stack: QUndoStack, doc: Document, gesture: object) -> bool:
    """Take back the step of an aborted drag (Escape) and leave nothing to redo.

    Undoes the top command when it carries ``gesture`` and removes it from the stack.
    Returns False (and changes nothing) when the top command is another one.
    """
    top = stack.command(stack.index() - 1) if stack.index() > 0 else None
    if not isinstance(top, DocumentUndoCommand) or gesture is None or top.command.gesture != gesture:
        return False
    with doc.batch():
        top.command.undo(doc)
    top.setObsolete(True)
    stack.undo()  # an obsolete command is removed without being undone again
    return True
