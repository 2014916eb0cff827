"""Picking the clip a 3D character plays (issue 21): the "Clip" combo of the Properties dock
and of the 3D view's toolbar.

A glTF character owns every animation of its file as a clip
(:class:`~qtanimator.document.character3d.ClipSource`); the document's channels hold the
active one (asset property ``clip``). Choosing a clip pushes
:func:`~qtanimator.document.character3d.set_clip_command`: one undo step that swaps the
channels (the edits of the clip left are kept), records the choice (saved with the
project) and fits the frame range to the clip. The combos only show the document: undo,
redo and opening a project update them.
"""

from __future__ import annotations

from PySide6.QtCore import Qt, QTimer
from PySide6.QtWidgets import QComboBox, QHBoxLayout, QLabel, QWidget

from qtanimator.document import character3d
from qtanimator.document.document import Document, DocumentChange
from qtanimator.ui.context import EditorContext

#: What the toolbar's combo says when several characters have clips and none is selected.
CHOOSE_CHARACTER = "select a character"


def clip_characters(doc: Document) -> list[str]:
    """The ids of the loaded 3D characters that have clips, in document order."""
    out = []
    for aid, asset in doc.assets.items():
        runtime = doc.runtime.get(aid)
        if asset.kind == character3d.ASSET_KIND and isinstance(runtime, character3d.Character3D) and runtime.clips:
            out.append(aid)
    return out


def clip_target(doc: Document, selection: tuple[str, str]) -> str | None:
    """The character a clip picker acts on: the selected one when it has clips, else the
    only character with clips (None when there is none, or several and none selected)."""
    found = clip_characters(doc)
    if selection[0] in found:
        return selection[0]
    return found[0] if len(found) == 1 else None


def clip_label(clip: character3d.ClipSource) -> str:
    """A clip's name with its duration in the file, as the import message lists them."""
    return f"{clip.name} ({clip.end - clip.start:.3g} s)"


class ClipCombo(QComboBox):
    """The clips of one 3D character, the active one current. Choosing a clip pushes
    :func:`~qtanimator.document.character3d.set_clip_command` on the undo stack.

    ``asset`` fixes the character (the Properties dock, which rebuilds the combo when the
    asset changes); None makes the combo follow the selection and the document itself
    (:func:`clip_target`; the 3D toolbar). ``deferred`` pushes after the combo's signal has
    returned, for a parent that deletes the combo when the document changes."""

    def __init__(self, ctx: EditorContext, asset: str | None = None, deferred: bool = False,
                 parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.ctx = ctx
        self.fixed_asset = asset
        self.deferred = deferred
        self.asset: str | None = None
        self._shown: tuple[object, ...] | None = None
        self.setSizeAdjustPolicy(QComboBox.SizeAdjustPolicy.AdjustToContents)
        self.activated.connect(self._activated)
        if asset is None:
            ctx.documentChanged.connect(self._document_changed)
            ctx.documentReset.connect(self.refresh)
            ctx.selectionChanged.connect(lambda _a, _j: self.refresh())
        self.refresh()

    # ---------------------------------------------------------------- showing
    def _document_changed(self, change: DocumentChange) -> None:
        if change.assets or change.reset:
            self.refresh()

    def target(self) -> str | None:
        doc = self.ctx.doc
        if self.fixed_asset is not None:
            return self.fixed_asset if self.fixed_asset in clip_characters(doc) else None
        return clip_target(doc, self.ctx.selection)

    def refresh(self) -> None:
        """Show the target character's clips with its active one current."""
        doc = self.ctx.doc
        aid = self.target()
        self.asset = aid
        clips = character3d.character(doc, aid).clips if aid is not None else []
        active = character3d.active_clip(doc, aid) if aid is not None else None
        shown = (aid, tuple(clip_label(c) for c in clips), active.name if active is not None else None)
        if shown == self._shown:
            return
        self._shown = shown
        self.blockSignals(True)
        try:
            self.clear()
            for clip in clips:
                self.addItem(clip_label(clip), clip.name)
            if aid is None:
                several = len(clip_characters(doc)) > 1
                self.setPlaceholderText(CHOOSE_CHARACTER if several else "no clips")
                self.setToolTip("Select a 3D character to pick the clip it plays." if several else "")
            else:
                self.setPlaceholderText("none")
                self.setToolTip(f"The clip {aid} plays. Choosing one fits the frame range to it; "
                                "each clip keeps its own edits (Ctrl+Z undoes the choice).")
            self.setCurrentIndex(self.findData(active.name) if active is not None else -1)
            self.setEnabled(aid is not None and len(clips) > 0)
        finally:
            self.blockSignals(False)

    # ---------------------------------------------------------------- choosing
    def _activated(self, index: int) -> None:
        aid, name = self.asset, self.itemData(index)
        if aid is None or not isinstance(name, str):
            return
        if self.deferred:
            ctx = self.ctx
            # The push rebuilds the parent (deleting this combo): do it once the signal returned.
            QTimer.singleShot(0, ctx, lambda: choose_clip(ctx, aid, name))
        else:
            choose_clip(self.ctx, aid, name)


def choose_clip(ctx: EditorContext, asset: str, name: str) -> bool:
    """Make ``name`` the clip ``asset`` plays: one undo step (nothing when it plays it
    already or the character or clip is gone). Returns whether a command was pushed."""
    doc = ctx.doc
    if asset not in clip_characters(doc):
        return False
    active = character3d.active_clip(doc, asset)
    if active is not None and active.name == name:
        return False
    try:
        command = character3d.set_clip_command(doc, asset, name)
    except KeyError:
        return False
    ctx.push(command)
    return True


class ClipPicker(QWidget):
    """"Clip" and a :class:`ClipCombo` following the selection, for a toolbar; hidden while
    no 3D character has clips."""

    def __init__(self, ctx: EditorContext, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.ctx = ctx
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.setSpacing(4)
        self.label = QLabel("Clip", self)
        self.combo = ClipCombo(ctx, parent=self)
        self.label.setBuddy(self.combo)
        layout.addWidget(self.label)
        layout.addWidget(self.combo)
        self.label.setAlignment(Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
        ctx.documentChanged.connect(self._document_changed)
        ctx.documentReset.connect(self._update_visibility)
        self._update_visibility()

    def _document_changed(self, change: DocumentChange) -> None:
        if change.assets or change.reset:
            self._update_visibility()

    def _update_visibility(self) -> None:
        self.setVisible(bool(clip_characters(self.ctx.doc)))


__all__ = ["CHOOSE_CHARACTER", "ClipCombo", "ClipPicker", "choose_clip", "clip_characters", "clip_label",
           "clip_target"]
