"""The 2D rig editor: a QGraphicsScene of the document's 2D characters.

Mouse (the reference animator's, plus a view you can move):

* hover highlights the joint under the cursor; a click selects it (``ctx.select``);
* left-drag on a joint rotates it about its pivot, on the root moves the character;
* right-drag pulls the picked point towards the cursor with IK (or, with *IK toggle mode*,
  the reference's toggle: right-press starts following the cursor, the next press stops);
* every drag is one gesture (``ctx.begin_gesture``): each mouse move previews its command
  at once, the release records one undo step, Escape takes the drag back exactly;
* middle-drag pans, the wheel zooms about the cursor, F fits the scene in the view.
* Alt+left-drag on a character moves its placement (issue 14; ``document.placement``),
  Alt+Shift+left-drag scales it about its pivot (×2 per 100 px to the right): one undo step
  each, Escape takes it back.

Auto-key (the timeline's record button, ``document.pose``): on, every drag keys; off, a
drag only poses — the unkeyed pose is shown until the frame changes or it is keyed (the
editor says so in its corner). S or I keys the selected joint (the character selected:
its root and position), Shift+S every joint of the character. Ctrl+C copies the selected
joint's pose (the whole character's when the character — its root — is selected), Ctrl+V
pastes it as keys at the current frame, Ctrl+Shift+V pastes it mirrored (left/right
joints swap; see ``document.pose.mirrored_value``). Each is one undo step.

Keys: Delete / Backspace delete the selected character's keys at the current frame
(Shift+Delete / Shift+Backspace: every character's; in key-all mode always every
character's, as keying is); ``d`` toggles the debug
overlays (the character's path with velocity (blue) and acceleration (red) arrows at its
keys, the IK source (red) / target (blue) dots and gradient arrows, and the HUD).
Onion skin: ghosts of earlier / later frames, with counts, step and tints. The selected
joint's limits (Properties) show as an orange wedge about its pivot that turns with its
parent; a left-drag stops at a limit and follows the cursor back.

Rig mode (the toolbar's *Rig Mode*, ``actionRigMode``; Spine's setup mode) shows each
character in its setup (rest) pose with its pivots and bones: left-drag a pivot marker to
move the pivot (one undo step; Escape takes it back), click a joint to select it, right-click
for *Make Joint From* (the drawing's layers and groups that are not joints yet; the new
joint hangs from the joint clicked), *Mark Dynamic* and *Remove Joint*. Every rig edit is a
command of :mod:`qtanimator.document.rigging`, saved in the project, never in the SVG.

This module is the editor's panel (the view with its tool bar), its menu actions and the
SVG opener. The parts: :mod:`qtanimator.ui.rig_view` (``RigEditorView``: mouse and keys),
:mod:`qtanimator.ui.rig_canvas` (``RigCanvas``, its base: poses, view, overlays),
:mod:`qtanimator.ui.rig_sprites` (the character items and their sprites) and
:mod:`qtanimator.ui.rig_interaction` (the gesture logic, no Qt).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from PySide6.QtCore import Qt
from PySide6.QtGui import QAction, QColor, QKeySequence
from PySide6.QtWidgets import QCheckBox, QColorDialog, QLabel, QSpinBox, QToolBar, QToolButton, QVBoxLayout, QWidget

from qtanimator.document import character2d
from qtanimator.ui.app_settings import settings
from qtanimator.ui.context import EditorContext
from qtanimator.ui.rig_canvas import BACKGROUND, LIMIT_WEDGE_COLOR, LIMIT_WEDGE_RADIUS_PX, RigCanvas
from qtanimator.ui.rig_sprites import SCENE_LIMIT, CharacterItem, JointSprites
from qtanimator.ui.rig_view import ZOOM_PER_DEGREE, RigEditorView

if TYPE_CHECKING:
    from qtanimator.ui.main_window import MainWindow


class RigEditor(QWidget):
    """The view with its tool bar (fit, debug, onion skin, IK mode)."""

    def __init__(self, ctx: EditorContext, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("rigEditor")
        self.view = RigEditorView(ctx, self)
        self.toolbar = QToolBar("2D Editor", self)
        self.toolbar.setObjectName("rigEditorToolBar")
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.setSpacing(0)
        layout.addWidget(self.toolbar)
        layout.addWidget(self.view, 1)
        view = self.view

        self.fit_action = QAction("Fit View", self)
        self.fit_action.setObjectName("actionFitView")
        self.fit_action.setShortcut(QKeySequence("F"))
        self.fit_action.setShortcutContext(Qt.ShortcutContext.WidgetWithChildrenShortcut)
        self.fit_action.triggered.connect(lambda _c=False: view.fit_view())
        self.debug_action = QAction("Debug Overlays", self)
        self.debug_action.setObjectName("actionDebugOverlays")
        self.debug_action.setCheckable(True)
        self.debug_action.setToolTip("Paths, velocity / acceleration arrows, IK arrows and the HUD (d)")
        self.debug_action.toggled.connect(view.set_debug)
        view.debug_action = self.debug_action  # type: ignore[attr-defined]
        self.rig_mode_action = QAction("Rig Mode", self)
        self.rig_mode_action.setObjectName("actionRigMode")
        self.rig_mode_action.setCheckable(True)
        self.rig_mode_action.setToolTip("Setup pose: drag pivots; right-click a joint to make joints from "
                                        "layers, mark it dynamic or remove it")
        self.rig_mode_action.toggled.connect(view.set_rig_mode)
        view.rig_mode_action = self.rig_mode_action  # type: ignore[attr-defined]
        self.toolbar.addAction(self.fit_action)
        self.toolbar.addAction(self.debug_action)
        self.toolbar.addAction(self.rig_mode_action)
        self.addAction(self.fit_action)
        self.pose_actions = self._pose_actions()

        self.toolbar.addSeparator()
        self.onion_box = QCheckBox("Onion skin", self)
        self.onion_box.setObjectName("onionSkinCheck")
        self.toolbar.addWidget(self.onion_box)
        self.before_box = self._spin("onionBefore", "earlier", 0, 20, view.onion.before)
        self.after_box = self._spin("onionAfter", "later", 0, 20, view.onion.after)
        self.step_box = self._spin("onionStep", "step", 1, 100, view.onion.step)
        self.before_tint = self._tint_button("onionBeforeTint", "before_tint")
        self.after_tint = self._tint_button("onionAfterTint", "after_tint")
        for w in (self.onion_box,):
            w.toggled.connect(lambda _v: self._onion_changed())
        for box in (self.before_box, self.after_box, self.step_box):
            box.valueChanged.connect(lambda _v: self._onion_changed())

        self.toolbar.addSeparator()
        self.ik_toggle_box = QCheckBox("IK toggle mode", self)
        self.ik_toggle_box.setObjectName("ikToggleModeCheck")
        self.ik_toggle_box.setToolTip("Right-click starts following the cursor, the next click stops "
                                      "(the reference animator's IK)")
        self.ik_toggle_box.toggled.connect(lambda on: setattr(view, "ik_toggle_mode", on))
        self.toolbar.addWidget(self.ik_toggle_box)

    def _pose_actions(self) -> dict[str, QAction]:
        """Set key, key the character, copy / paste / paste mirrored pose: shortcuts of the
        view only (other editors bind Ctrl+C / Ctrl+V to their keys)."""
        view = self.view
        specs = (
            ("actionSetKey", "Set Key", ["S", "I"], lambda: view.set_key(False),
             "Key the selected joint (the character selected: its root and position) at this frame"),
            ("actionSetKeyCharacter", "Set Key on Whole Character", ["Shift+S"], lambda: view.set_key(True),
             "Key every joint of the selected character at this frame"),
            ("actionCopyPose", "Copy Pose", ["Ctrl+C"], view.copy_pose,
             "Copy the selected joint's pose (the whole character's when the character is selected)"),
            ("actionPastePose", "Paste Pose", ["Ctrl+V"], lambda: view.paste_pose(False),
             "Key the copied pose at this frame"),
            ("actionPasteMirrored", "Paste Pose Mirrored", ["Ctrl+Shift+V"], lambda: view.paste_pose(True),
             "Key the copied pose at this frame with left and right swapped"),
        )
        actions: dict[str, QAction] = {}
        for name, text, keys, slot, tip in specs:
            action = QAction(text, self)
            action.setObjectName(name)
            action.setShortcuts([QKeySequence(k) for k in keys])
            action.setShortcutContext(Qt.ShortcutContext.WidgetWithChildrenShortcut)
            action.setToolTip(f"{tip} ({', '.join(keys)})")
            action.triggered.connect(lambda _c=False, fn=slot: fn())
            view.addAction(action)
            actions[name] = action
        return actions

    def _spin(self, name: str, label: str, lo: int, hi: int, value: int) -> QSpinBox:
        self.toolbar.addWidget(QLabel(f" {label} ", self))
        box = QSpinBox(self)
        box.setObjectName(name)
        box.setRange(lo, hi)
        box.setValue(value)
        self.toolbar.addWidget(box)
        return box

    def _tint_button(self, name: str, field: str) -> QToolButton:
        button = QToolButton(self)
        button.setObjectName(name)
        button.setToolTip("Tint of the " + ("earlier" if field == "before_tint" else "later") + " ghosts")

        def paint() -> None:
            r, g, b = getattr(self.view.onion, field)
            button.setStyleSheet(f"background-color: rgb({r},{g},{b}); min-width: 16px;")

        def choose() -> None:
            r, g, b = getattr(self.view.onion, field)
            color = QColorDialog.getColor(QColor(r, g, b), self, "Onion skin tint")
            if color.isValid():
                self._set_onion(**{field: (color.red(), color.green(), color.blue())})
                paint()

        button.clicked.connect(choose)
        paint()
        self.toolbar.addWidget(button)
        return button

    def _set_onion(self, **changes: Any) -> None:
        from dataclasses import replace

        self.view.onion = replace(self.view.onion, **changes)
        self.view.viewport().update()

    def _onion_changed(self) -> None:
        self._set_onion(enabled=self.onion_box.isChecked(), before=self.before_box.value(),
                        after=self.after_box.value(), step=self.step_box.value())


# ---------------------------------------------------------------------- openers
def open_characters(window: MainWindow, path: Path) -> None:
    """Add the characters of an SVG file or folder (FormatError leaves the document as is)."""
    command = character2d.add_characters_command(window.doc, path, new_project_range=True)
    window.ctx.push(command)
    editor = getattr(window, "rig_editor", None)
    if editor is not None:
        editor.view.fit_view()
        window.central_tabs.setCurrentWidget(editor)


def install(window: MainWindow) -> None:
    editor = RigEditor(window.ctx)
    window.rig_editor = editor  # type: ignore[attr-defined]
    window.add_central(editor, "2D Rig")
    window.openers[".svg"] = open_characters
    window.openers["/"] = open_characters
    window.view_menu.addAction(editor.fit_action)
    window.view_menu.addAction(editor.debug_action)
    delete = QAction("Delete Keys at Current Frame", window)
    delete.setObjectName("actionDeleteFrameKeys")
    delete.setToolTip("The selected character's keys at the current frame (Delete / Backspace in the 2D editor)")
    delete.triggered.connect(lambda _c=False: editor.view.delete_keys())
    window.edit_menu.addAction(delete)
    delete_all = QAction("Delete Keys at Current Frame (All Characters)", window)
    delete_all.setObjectName("actionDeleteFrameKeysAll")
    delete_all.setToolTip("Every 2D character's keys at the current frame (Shift+Delete in the 2D editor)")
    delete_all.triggered.connect(lambda _c=False: editor.view.delete_keys(all_characters=True))
    window.edit_menu.addAction(delete_all)
    window.edit_menu.addSeparator()
    for action in editor.pose_actions.values():
        window.edit_menu.addAction(action)
    _restore_editor_settings(editor)


def _restore_editor_settings(editor: RigEditor) -> None:
    """The onion skin's counts and step are user preferences, kept in the program's settings
    (the IK mode is not: a toggle that silently persisted would surprise)."""
    s = settings()

    def stored(key: str, default: int) -> int:
        value = s.value(key, default)
        if not isinstance(value, (int, float, str)):
            raise TypeError(f"{key}: {value!r} is no number")
        return int(value)

    try:
        editor.before_box.setValue(stored("rigEditor/onionBefore", editor.before_box.value()))
        editor.after_box.setValue(stored("rigEditor/onionAfter", editor.after_box.value()))
        editor.step_box.setValue(stored("rigEditor/onionStep", editor.step_box.value()))
    except (TypeError, ValueError):
        pass

    def save() -> None:
        st = settings()
        st.setValue("rigEditor/onionBefore", editor.before_box.value())
        st.setValue("rigEditor/onionAfter", editor.after_box.value())
        st.setValue("rigEditor/onionStep", editor.step_box.value())

    for box in (editor.before_box, editor.after_box, editor.step_box):
        box.valueChanged.connect(lambda _v: save())


__all__ = ["BACKGROUND", "LIMIT_WEDGE_COLOR", "LIMIT_WEDGE_RADIUS_PX", "SCENE_LIMIT", "ZOOM_PER_DEGREE",
           "CharacterItem", "JointSprites", "RigCanvas", "RigEditor", "RigEditorView", "install", "open_characters"]
