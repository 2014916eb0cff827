"""The keys of the 3D view and the pose edits they make.

F frames the selection (or everything), X shows the axes (the MIT viewer's ``a``), B the
skeleton (its ``s``); S / I key the selected joint (Shift+S its whole character), Ctrl+C /
Ctrl+V (Ctrl+Shift+V mirrored) copy and paste a pose, R resets the selected character's
pose; W/A/S/D/Q/E and Z/C move a live cloth's pins, P pauses it, Shift+R resets it; Escape
cancels an IK, light or placement drag. The view sees these keys from the GL surface too.
Letters with Ctrl, Alt or Meta do nothing here unless bound above (Ctrl+A moves no pin).
"""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtGui import QKeyEvent

from qtanimator.document.character3d import ASSET_KIND
from qtanimator.ui.joint_tree import reset_pose_command
from qtanimator.ui.rig_interaction import copy_selection, paste_command, pose_clipboard, set_key_command
from qtanimator.ui.view3d_cloth import PIN_KEYS, PIN_TURNS
from qtanimator.ui.view3d_drags import EDIT_DRAGS, ViewDrags


class ViewKeys(ViewDrags):
    """``keyPressEvent`` of the 3D view, and set key, copy, paste and reset pose."""

    def _say(self, text: str) -> None:
        bar = getattr(self.window(), "statusBar", None)
        if callable(bar):
            bar().showMessage(text, 4000)

    def _selects_character(self) -> bool:
        asset = self.ctx.doc.assets.get(self.ctx.selection[0])
        return asset is not None and asset.kind == ASSET_KIND

    def set_key(self, whole_character: bool = False) -> bool:
        """S / I: key the selected joint's DOFs; Shift+S every DOF of its character."""
        if self._drag is not None and self._drag.get("gesture") is not None:
            return False
        command = set_key_command(self.ctx.doc, self.ctx.selection, self.ctx.time, whole_character)
        if command is None:
            self._say("Select a joint to key.")
            return False
        self.ctx.push(command)
        return True

    def copy_pose(self) -> bool:
        """Ctrl+C: copy the selected joint's rotation (the whole character's when the
        character is selected)."""
        clip = copy_selection(self.ctx.doc, self.ctx.selection, self.ctx.time)
        if clip is None:
            self._say("Select a joint or a character to copy its pose.")
            return False
        pose_clipboard.clip = clip
        self._say(f"Copied the pose of {len(clip.values)} joint{'s' if len(clip.values) != 1 else ''}.")
        return True

    def paste_pose(self, mirrored: bool = False) -> bool:
        """Ctrl+V / Ctrl+Shift+V: key the copied pose (mirrored) at the current frame.
        (Keys of :meth:`keyPressEvent`, which sees them from the GL surface too.)"""
        if self._drag is not None and self._drag.get("gesture") is not None:
            return False
        command = paste_command(self.ctx.doc, pose_clipboard.clip, self.ctx.selection, self.ctx.time, mirrored)
        if command is None:
            self._say("Nothing to paste here: copy a pose of a character like this one first.")
            return False
        self.ctx.push(command)
        return True

    def reset_pose(self) -> bool:
        """R: the selected character back to its rest pose, keyed now (as the joint tree's
        Reset Pose; one undo step)."""
        asset = self.ctx.selection[0]
        command = reset_pose_command(self.ctx.doc, asset, self.ctx.time) if asset else None
        if command is None:
            self._say("Select a character to reset its pose.")
            return False
        self.ctx.push(command)
        return True

    def toggle_skeleton(self) -> None:
        """B (the MIT viewer's ``s``): show or hide the skeleton; hiding it shows the skin."""
        if self.options.show_skeleton:
            self.set_display(show_skeleton=False, show_skin=True)
        else:
            self.set_display(show_skeleton=True)

    def keyPressEvent(self, event: QKeyEvent) -> None:
        """The view's keys. Letters act only without Ctrl, Alt and Meta (Shift is part of some
        keys: Shift+S, Shift+R); a Ctrl / Alt / Meta combination that is not bound here
        (Ctrl+A, Ctrl+D, Alt+W …) does nothing and goes on to the parent as unhandled."""
        key = event.key()
        mods = event.modifiers() & ~Qt.KeyboardModifier.KeypadModifier
        ctrl, shift = Qt.KeyboardModifier.ControlModifier, Qt.KeyboardModifier.ShiftModifier
        plain = mods in (Qt.KeyboardModifier.NoModifier, shift)
        if key in (Qt.Key.Key_S, Qt.Key.Key_I) and plain and self._selects_character():
            # Set key (S / I; Shift+S the whole character) when a 3D character is selected;
            # otherwise S keeps moving the live cloth's pins.
            self.set_key(whole_character=bool(mods & shift))
        elif key == Qt.Key.Key_C and mods == ctrl:
            self.copy_pose()
        elif key == Qt.Key.Key_V and mods in (ctrl, ctrl | shift):
            self.paste_pose(mirrored=bool(mods & shift))
        elif key == Qt.Key.Key_F and plain:
            self.frame_selection()
        elif key == Qt.Key.Key_X and mods == Qt.KeyboardModifier.NoModifier:
            # the MIT viewer's ``a`` (A moves the cloth pins here)
            self.set_display(show_axes=not self.options.show_axes)
        elif key == Qt.Key.Key_B and mods == Qt.KeyboardModifier.NoModifier:
            # the MIT viewer's ``s`` (S sets a key here)
            self.toggle_skeleton()
        elif (key in PIN_KEYS or key in PIN_TURNS) and plain:
            self.pin_key(key)
        elif key == Qt.Key.Key_P and plain:
            self.live.paused = not self.live.paused
        elif key == Qt.Key.Key_R and mods == shift:
            self.reset_cloth()
        elif key == Qt.Key.Key_R and mods == Qt.KeyboardModifier.NoModifier:
            self.reset_pose()
        elif key == Qt.Key.Key_Escape and self._drag is not None and self._drag.get("mode") in EDIT_DRAGS:
            self.abort_drag()
        else:
            super().keyPressEvent(event)


__all__ = ["ViewKeys"]
