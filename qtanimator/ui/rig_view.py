"""What the mouse and the keys do in the 2D rig editor: :class:`RigEditorView`.

Each handler finds what is under the cursor and starts a drag of
:mod:`qtanimator.ui.rig_interaction` (no Qt) inside one gesture (``ctx.begin_gesture``):
each mouse move feeds the drag and previews its command, the release commits one undo
step, Escape aborts it. Left-drag rotates a joint (moves the character on its root),
right-drag pulls with IK, Alt(+Shift)+left-drag places (scales) the character, middle-drag
pans, the wheel zooms; in rig mode a left-drag moves a pivot and a right-click opens the
rig menu (:mod:`qtanimator.document.rigging`). Also the key, copy / paste pose and delete
keys actions the editor's toolbar and menus call. What the view draws is its base class,
:class:`qtanimator.ui.rig_canvas.RigCanvas`.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from PySide6.QtCore import QPointF, Qt
from PySide6.QtGui import QKeyEvent, QMouseEvent, QWheelEvent
from PySide6.QtWidgets import QMenu, QWidget

from qtanimator.document import character2d
from qtanimator.document import pose as pose_doc
from qtanimator.document.commands import Command
from qtanimator.document.gesture import Gesture
from qtanimator.ui import rig_interaction as ri
from qtanimator.ui.context import EditorContext
from qtanimator.ui.rig_canvas import RigCanvas

ZOOM_PER_DEGREE = 1.0015  # per wheel unit (1/8 degree)


def _xy(point: np.ndarray) -> tuple[float, float]:
    """A scene point (``RigEditorView.to_scene``) as the pair the interaction functions take."""
    return float(point[0]), float(point[1])



class RigEditorView(RigCanvas):
    """The 2D rig editor's view: it owns the interaction state (the overlays: RigCanvas)."""

    def __init__(self, ctx: EditorContext, parent: QWidget | None = None) -> None:
        super().__init__(ctx, parent)
        self.ik_toggle_mode = False
        self.rig_menu: QMenu | None = None
        # Interaction state.
        self._drag: Any = None
        self._gesture: Gesture | None = None
        self._drag_button: Qt.MouseButton | None = None
        self._ik_following = False
        self._pan_from: QPointF | None = None

    # ------------------------------------------------------------------ view
    def wheelEvent(self, event: QWheelEvent) -> None:
        delta = event.angleDelta().y() or event.angleDelta().x()
        if not delta:
            return
        factor = ZOOM_PER_DEGREE ** delta  # 120 per notch: × 1.2
        anchor = self.to_scene(event.position())
        self._auto_fit = False
        self.scale(factor, factor)
        # Keep the point under the cursor fixed.
        moved = self.from_scene(anchor) - event.position()
        self._pan_by(moved)
        event.accept()

    # ------------------------------------------------------------------ mouse
    def _new_gesture(self, text: str) -> Gesture:
        return self.ctx.begin_gesture(text)

    def mousePressEvent(self, event: QMouseEvent) -> None:
        button = event.button()
        if button == Qt.MouseButton.MiddleButton:
            self._pan_from = event.position()
            self._auto_fit = False
            self.setCursor(Qt.CursorShape.ClosedHandCursor)
            event.accept()
            return
        if self._ik_following and button in (Qt.MouseButton.LeftButton, Qt.MouseButton.RightButton):
            self.finish_drag()  # the toggle's second press (or a left press) ends it
            if button == Qt.MouseButton.RightButton:
                event.accept()
                return
        if self._drag is not None:
            event.accept()
            return
        point = self.to_scene(event.position())
        time = self.ctx.time
        if self.rig_mode:
            self._rig_press(event, point)
            return
        try:
            hit = ri.pick(self.ctx.doc, time, _xy(point))
        except ModuleNotFoundError:
            hit = None
        if hit is not None and button in (Qt.MouseButton.LeftButton, Qt.MouseButton.RightButton):
            # Keys go to the frame under the cursor: stop playback first.
            playback = getattr(self.window(), "playback", None)
            if playback is not None:
                playback.pause()
            time = self.ctx.time
        alt = Qt.KeyboardModifier.AltModifier
        if button == Qt.MouseButton.LeftButton and hit is not None and event.modifiers() & alt:
            # Alt+drag places the character (issue 14), Alt+Shift+drag scales it: one undo step.
            asset = hit[0]
            self.ctx.select(asset, "")
            if event.modifiers() & Qt.KeyboardModifier.ShiftModifier:
                self._gesture = self._new_gesture(f"Scale {asset}")
                self._drag = ri.placement_scale_drag(self.ctx.doc, asset, _xy(point), self._pixel_size())
            else:
                self._gesture = self._new_gesture(f"Place {asset}")
                self._drag = ri.placement_move_drag(self.ctx.doc, asset, _xy(point))
            next(self._drag)
            self._drag_button = button
            event.accept()
            return
        if button == Qt.MouseButton.LeftButton:
            if hit is None:
                self.ctx.select("", "")
                event.accept()
                return
            asset, joint = hit
            character = self.ctx.doc.runtime[asset]
            autokey = pose_doc.autokey(self.ctx.doc)
            if joint == 0:
                self.ctx.select(asset, "")
                self._gesture = self._new_gesture(f"Move {asset}")
                self._drag = ri.move_drag(self.ctx.doc, asset, _xy(point), time, autokey)
            else:
                self.ctx.select(asset, character.joints[joint].name)
                self._gesture = self._new_gesture(f"Rotate {character.joints[joint].name}")
                self._drag = ri.rotate_drag(self.ctx.doc, asset, joint, _xy(point), time, autokey)
            next(self._drag)
            self._drag_button = button
            event.accept()
            return
        if button == Qt.MouseButton.RightButton:
            if hit is None:
                event.accept()
                return
            asset, joint = hit
            character = self.ctx.doc.runtime[asset]
            self.ctx.select(asset, character.joints[joint].name if joint else "")
            self._gesture = self._new_gesture("IK Drag")
            self._drag = ri.ik_drag(self.ctx.doc, asset, joint, _xy(point), time, pose_doc.autokey(self.ctx.doc))
            next(self._drag)
            self._ik = (asset, joint, ri.ik_source(self.ctx.doc, asset, joint, _xy(point), time))
            self._ik_target = point
            self._drag_button = button
            self._ik_following = self.ik_toggle_mode
            event.accept()
            return
        super().mousePressEvent(event)

    def mouseMoveEvent(self, event: QMouseEvent) -> None:
        if self._pan_from is not None:
            delta = event.position() - self._pan_from
            self._pan_from = event.position()
            self._pan_by(QPointF(-delta.x(), -delta.y()))
            event.accept()
            return
        point = self.to_scene(event.position())
        if self._drag is not None and (self._ik_following or (self._drag_button is not None
                                                               and event.buttons() & self._drag_button)):
            self.drag_to(point)
            event.accept()
            return
        self._update_hover(point)
        event.accept()

    def drag_to(self, point: np.ndarray) -> None:
        """Feed one cursor position (scene units) to the current drag."""
        if self._drag is None or self._gesture is None:
            return
        if self._ik is not None:
            self._ik_target = np.asarray(point, dtype=np.float64)
        self._gesture.update(self._drag.send(point))
        self._invalidate()  # the preview is drawn now; other views follow once per frame

    def mouseReleaseEvent(self, event: QMouseEvent) -> None:
        if event.button() == Qt.MouseButton.MiddleButton and self._pan_from is not None:
            self._pan_from = None
            self.unsetCursor()
            event.accept()
            return
        if self._drag is not None and event.button() == self._drag_button and not self._ik_following:
            self.finish_drag()
            event.accept()
            return
        super().mouseReleaseEvent(event)

    def finish_drag(self) -> None:
        """End the drag: its folded command goes on the undo stack as one step."""
        gesture = self._gesture
        self._reset_drag()
        if gesture is not None:
            gesture.commit()
        self._invalidate()

    def abort_drag(self) -> None:
        """Escape: take back everything the current drag did."""
        gesture = self._gesture
        self._reset_drag()
        if gesture is not None:
            gesture.abort()
        self._invalidate()

    def _reset_drag(self) -> None:
        if self._drag is not None:
            self._drag.close()
        self._drag = None
        self._gesture = None
        self._drag_button = None
        self._ik_following = False
        super()._reset_drag()


    @property
    def dragging(self) -> bool:
        return self._drag is not None

    def _update_hover(self, point: np.ndarray) -> None:
        try:
            hit = (ri.pick_rest if self.rig_mode else ri.pick)(self.ctx.doc, self.ctx.time, _xy(point))
        except ModuleNotFoundError:
            hit = None
        if hit != self.hover:
            self.hover = hit
            self.viewport().update()

    def leaveEvent(self, event: Any) -> None:
        if self.hover is not None:
            self.hover = None
            self.viewport().update()
        super().leaveEvent(event)

    # -------------------------------------------------------------- rig mode
    def set_rig_mode(self, on: bool) -> None:
        """Enter or leave rig mode (the setup pose with pivots; see the module docstring)."""
        if self._drag is not None:
            self.abort_drag()
        self.rig_mode = bool(on)
        action = getattr(self, "rig_mode_action", None)
        if action is not None and action.isChecked() != self.rig_mode:
            action.setChecked(self.rig_mode)
        self.hover = None
        self.sprites.clear()
        self._invalidate()

    def _rig_press(self, event: QMouseEvent, point: np.ndarray) -> None:
        doc, time = self.ctx.doc, self.ctx.time
        button = event.button()
        if button == Qt.MouseButton.LeftButton:
            grab = ri.pivot_at(doc, time, _xy(point), ri.PIVOT_GRAB_PX * self._pixel_size())
            if grab is not None:
                asset, joint = grab
                character = doc.runtime[asset]
                self.ctx.select(asset, character.joints[joint].name if joint else "")
                self._gesture = self._new_gesture(f"Move Pivot of {character.joints[joint].name}")
                self._drag = ri.pivot_drag(doc, asset, joint, _xy(point))
                next(self._drag)
                self._drag_button = button
            else:
                hit = ri.pick_rest(doc, time, _xy(point))
                if hit is None:
                    self.ctx.select("", "")
                else:
                    character = doc.runtime[hit[0]]
                    self.ctx.select(hit[0], character.joints[hit[1]].name if hit[1] else "")
            event.accept()
            return
        if button == Qt.MouseButton.RightButton:
            hit = ri.pick_rest(doc, time, _xy(point))
            if hit is None and self.character_ids():
                hit = (self.ctx.selection[0] or self.character_ids()[-1], 0)
            if hit is not None:
                self.show_rig_menu(hit[0], hit[1], event.position().toPoint())
            event.accept()
            return
        event.accept()

    def show_rig_menu(self, asset: str, joint: int, pos: Any) -> QMenu:
        """The rig-mode context menu of one joint, opened at viewport ``pos``."""
        from qtanimator.document import rigging

        doc = self.ctx.doc
        character = doc.runtime[asset]
        name = character.joints[joint].name
        self.ctx.select(asset, name if joint else "")
        menu = QMenu(self)
        menu.setObjectName("rigMenu")
        make = menu.addMenu("Make Joint From")
        make.setObjectName("rigMakeJointMenu")
        offered = rigging.candidates(doc, asset)
        for label in offered:
            action = make.addAction(label)
            action.triggered.connect(lambda _c=False, lb=label: self._rig_edit(
                lambda: rigging.make_joint_from_candidate(doc, asset, lb, parent=name), select=(asset, lb)))
        make.setEnabled(bool(offered))
        dynamic = menu.addAction("Mark Dynamic")
        dynamic.setObjectName("actionMarkDynamic")
        dynamic.setCheckable(True)
        dynamic.setChecked(bool(character.joints[joint].is_dynamic))
        dynamic.setEnabled(joint != 0)
        dynamic.triggered.connect(lambda on: self._rig_edit(
            lambda: rigging.set_dynamic_command(doc, asset, name, bool(on))))
        spring = menu.addAction("Spring Joint")
        spring.setObjectName("actionMarkSpring")
        spring.setToolTip("the joint follows its keys through a damped spring (secondary motion)")
        spring.setCheckable(True)
        spring.setChecked(bool(character.joints[joint].is_spring))
        spring.triggered.connect(lambda on: self._rig_edit(
            lambda: rigging.set_joint_mode_command(doc, asset, name, "spring" if on else "keyframed")))
        remove = menu.addAction("Remove Joint")
        remove.setObjectName("actionRemoveJoint")
        remove.setEnabled(joint != 0)
        remove.triggered.connect(lambda _c=False: self._rig_edit(
            lambda: rigging.remove_joint_command(doc, asset, name), select=(asset, "")))
        self.rig_menu = menu
        menu.popup(self.viewport().mapToGlobal(pos))
        return menu

    def _rig_edit(self, build: Any, select: tuple[str, str] | None = None) -> bool:
        from qtanimator.document.rigging import RigError
        from qtanimator.formats.errors import FormatError

        try:
            command = build()
        except (RigError, FormatError) as exc:
            self._say(str(exc))
            return False
        self.ctx.push(command)
        if select is not None:
            character = self.ctx.doc.runtime.get(select[0])
            if character is not None and select[1] and select[1] not in [j.name for j in character.joints]:
                select = (select[0], character.joints[-1].name)
            self.ctx.select(*select)
        return True

    # ------------------------------------------------------------------- keys
    def keyPressEvent(self, event: QKeyEvent) -> None:
        key = event.key()
        if key == Qt.Key.Key_Escape and self._drag is not None:
            self.abort_drag()
            event.accept()
            return
        if key in (Qt.Key.Key_Delete, Qt.Key.Key_Backspace):
            self.delete_keys(all_characters=bool(event.modifiers() & Qt.KeyboardModifier.ShiftModifier))
            event.accept()
            return
        if key == Qt.Key.Key_D and not event.modifiers() & ~Qt.KeyboardModifier.KeypadModifier:
            self.set_debug(not self.debug)
            event.accept()
            return
        super().keyPressEvent(event)

    # ------------------------------------------------------ set key, copy, paste
    def _say(self, text: str) -> None:
        window = self.window()
        bar = getattr(window, "statusBar", None)
        if callable(bar):
            bar().showMessage(text, 4000)

    def set_key(self, whole_character: bool = False) -> bool:
        """S / I (``whole_character`` False) or Shift+S: key the shown pose of the
        selected joint or of the whole selected character at the current frame."""
        if self._drag is not None:
            return False
        command = ri.set_key_command(self.ctx.doc, self.ctx.selection, self.ctx.time, whole_character)
        if command is None:
            self._say("Select a joint or a character to key.")
            return False
        self.ctx.push(command)
        return True

    def copy_pose(self) -> bool:
        """Ctrl+C: copy the selected joint's pose (the whole character's when it is selected)."""
        clip = ri.copy_selection(self.ctx.doc, self.ctx.selection, self.ctx.time)
        if clip is None:
            self._say("Select a joint or a character to copy its pose.")
            return False
        ri.pose_clipboard.clip = clip
        self._say(f"Copied the pose of {len(clip.values)} joint{'s' if len(clip.values) != 1 else ''}.")
        return True

    def paste_pose(self, mirrored: bool = False) -> bool:
        """Ctrl+V / Ctrl+Shift+V: key the copied pose (mirrored) at the current frame."""
        if self._drag is not None:
            return False
        command = ri.paste_command(self.ctx.doc, ri.pose_clipboard.clip, self.ctx.selection, self.ctx.time,
                                   mirrored)
        if command is None:
            self._say("Nothing to paste here: copy a pose of a character like this one first.")
            return False
        self.ctx.push(command)
        return True

    def delete_keys(self, all_characters: bool = False) -> bool:
        """Delete / Backspace: remove the selected character's keys at the current frame;
        Shift+Delete (``all_characters``): every 2D character's. In key-all mode every
        character's, as keying is. True when keys were deleted."""
        if self._drag is not None:
            return False
        asset = self.ctx.selection[0]
        if not all_characters and asset not in character2d.character_assets(self.ctx.doc):
            if not bool(self.ctx.doc.parameter(character2d.KEY_ALL_PARAMETER, False)):
                self._say("Select a character to delete its keys at this frame (Shift+Delete: every character's).")
                return False
        command: Command | None = character2d.delete_keys_at(self.ctx.doc, None if all_characters else asset,
                                                             self.ctx.time)
        if command is None:
            return False
        self.ctx.push(command)
        return True
