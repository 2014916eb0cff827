"""The dope sheet: every key of every channel as a diamond on a row, against frames.

``install(window)`` adds the dock ``dopeSheetDock`` holding a :class:`DopeSheetPanel` (a
toolbar and the painted view ``dopeSheet``, a :class:`DopeSheetView`).

Rows: a summary row per character (asset), a summary row per joint, a row per channel.
A summary row's diamonds stand for every key below it at that frame; its arrow collapses
or expands it (joints start collapsed). Clicking a row's name selects that character or
joint in the other editors.

Mouse: click a diamond to select its keys (a summary diamond: every key under it), Shift
toggles; drag on empty space box-selects (Shift adds, Ctrl removes); drag a selected key
to retime the selection (snapped to whole frames unless Snap is off); click or drag in the
ruler to set the current frame; wheel scrolls rows, Ctrl+wheel zooms time, Shift+wheel or
middle drag pans. Keys: S scales the selected keys about the current frame (move the
mouse, click or Enter to confirm, Escape or right click to cancel), Delete / X deletes,
Ctrl+C copies, Ctrl+V pastes at the current frame (merge), Ctrl+Shift+V pastes replacing
the pasted range, Ctrl+A selects all, A frames all, F frames the selection, Escape aborts
a drag. A retime or scale is one gesture (``ctx.begin_gesture``): one undo step; a paste
or delete is one command. The edits themselves are :mod:`qtanimator.document.keying`.

The key selection is ``ctx.key_selection``, shared with the curve editor: the view paints
it and sets it (as its source); it follows selection changes from other editors.

Drawing: only the visible rows; each channel's key frames are cached per channel object
(like the timeline's FrameCache), each summary row's per tuple of channel objects; the
rows and keys are rendered into a pixmap that is kept until the content, the view or the
selection changes, so moving the playhead (playback) only draws a line over it.

Modules: this one holds the panel (toolbar, actions) and ``install``;
:mod:`~qtanimator.ui.dope_view` the view's mouse, keys and edits,
:mod:`~qtanimator.ui.dope_canvas` its geometry, rows and document wiring,
:mod:`~qtanimator.ui.dope_paint` the drawing, :mod:`~qtanimator.ui.dope_rows` the rows
and key frames (no Qt), :mod:`~qtanimator.ui.dope_drags` what presses, boxes, drags and
pastes do to keys (no Qt), :mod:`~qtanimator.ui.key_clipboard` the key clipboard.
"""

from __future__ import annotations

from typing import Any

from PySide6.QtCore import Qt
from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import QDockWidget, QLabel, QMenu, QToolBar, QVBoxLayout, QWidget

from qtanimator.ui.dope_rows import Row, build_rows
from qtanimator.ui.dope_view import DopeSheetView
from qtanimator.ui.key_clipboard import KEY_CLIP_MIME, key_clip, put_key_clip


# ----------------------------------------------------------------------- panel
class DopeSheetPanel(QWidget):
    """Toolbar, message line and the view; owns the dope sheet's actions."""

    def __init__(self, ctx: Any, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("dopeSheetPanel")
        self.ctx = ctx
        self.view = DopeSheetView(ctx, self)
        self.status = QLabel(self)
        self.status.setObjectName("dopeSheetMessage")
        self.status.setStyleSheet("color: #aaa; padding-left: 8px;")
        self._build_actions()
        self.toolbar = QToolBar("Dope Sheet", self)
        self.toolbar.setObjectName("dopeSheetToolBar")
        for a in (self.action_frame_all, self.action_snap, None, self.action_scale, self.action_copy,
                  self.action_paste, self.action_paste_replace, self.action_delete):
            if a is None:
                self.toolbar.addSeparator()
            else:
                self.toolbar.addAction(a)
        self.toolbar.addWidget(self.status)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.setSpacing(0)
        layout.addWidget(self.toolbar)
        layout.addWidget(self.view, 1)
        self.view.message.connect(self.status.setText)
        ctx.key_selection.changed.connect(lambda _s: self._update_enabled())
        ctx.documentChanged.connect(lambda _c: self._update_enabled())
        self._update_enabled()

    def _action(self, name: str, text: str, slot: Any, keys: list[str] | None = None, tip: str = "",
                checkable: bool = False) -> QAction:
        action = QAction(text, self)
        action.setObjectName(name)
        action.setToolTip(tip or text)
        if keys:
            action.setShortcuts([QKeySequence(k) for k in keys])
            action.setShortcutContext(Qt.ShortcutContext.WidgetWithChildrenShortcut)
            action.setToolTip(f"{tip or text} ({', '.join(keys)})")
        action.setCheckable(checkable)
        if checkable:
            action.toggled.connect(slot)
        else:
            action.triggered.connect(lambda _c=False: slot())
        self.addAction(action)
        return action

    def _build_actions(self) -> None:
        v = self.view
        self.action_copy = self._action("actionDopeSheetCopyKeys", "Copy Keys", v.copy_selected, ["Ctrl+C"])
        self.action_paste = self._action("actionDopeSheetPasteKeys", "Paste (Merge)", lambda: v.paste("merge"),
                                         ["Ctrl+V"], "Paste keys at the current frame, replacing keys on "
                                         "the same frames")
        self.action_paste_replace = self._action(
            "actionDopeSheetPasteKeysReplace", "Paste (Replace)", lambda: v.paste("replace"), ["Ctrl+Shift+V"],
            "Paste keys at the current frame, clearing the pasted range first")
        self.action_delete = self._action("actionDopeSheetDeleteKeys", "Delete Keys", v.delete_selected,
                                          ["Delete", "X", "Backspace"])
        self.action_scale = self._action("actionDopeSheetScaleKeys", "Scale", self._scale, ["S"],
                                         "Scale the selected keys about the current frame: move the mouse, "
                                         "click to confirm")
        self.action_select_all = self._action("actionDopeSheetSelectAll", "Select All Keys", v.select_all,
                                              ["Ctrl+A"])
        self.action_frame_all = self._action("actionDopeSheetFrameAll", "Frame All", v.frame_all, ["A"])
        self.action_frame_selected = self._action("actionDopeSheetFrameSelected", "Frame Selected",
                                                  v.frame_selected, ["F"])
        self.action_snap = self._action("actionDopeSheetSnap", "Snap", self._set_snap, None,
                                        "Snap retimed and scaled keys to whole frames", checkable=True)
        self.action_snap.setChecked(True)

    def _scale(self) -> None:
        if self.view.begin_scale():
            self.view.update_scale(self.view._scale_origin)

    def _set_snap(self, on: bool) -> None:
        self.view.snap = on

    def _update_enabled(self) -> None:
        has = bool(self.ctx.key_selection)
        for a in (self.action_copy, self.action_delete, self.action_scale):
            a.setEnabled(has)

    def context_menu(self) -> QMenu:
        menu = QMenu(self)
        menu.setObjectName("dopeSheetMenu")
        for a in (self.action_copy, self.action_paste, self.action_paste_replace, None, self.action_delete,
                  self.action_scale, None, self.action_select_all, self.action_frame_all,
                  self.action_frame_selected):
            if a is None:
                menu.addSeparator()
            else:
                menu.addAction(a)
        return menu


def install(window: Any) -> DopeSheetPanel:
    panel = DopeSheetPanel(window.ctx, window)
    window.dope_sheet = panel
    dock: QDockWidget = window.add_dock("dopeSheetDock", "Dope Sheet", panel, Qt.DockWidgetArea.BottomDockWidgetArea)
    # Beside the curve editor as a tab (both show keys), else above the timeline.
    curve = window.findChild(QDockWidget, "curveEditorDock")
    timeline = window.findChild(QDockWidget, "timelineDock")
    if curve is not None:
        window.tabifyDockWidget(curve, dock)
        curve.raise_()
    elif timeline is not None:
        window.splitDockWidget(timeline, dock, Qt.Orientation.Vertical)
        window.splitDockWidget(dock, timeline, Qt.Orientation.Vertical)
    panel.view.message.connect(lambda text: window.statusBar().showMessage(text, 5000))
    from qtanimator.ui.timeline import add_timeline_keys

    add_timeline_keys(window, panel.view)  # ←/→, Home/End… while the dope sheet has focus
    return panel


__all__ = ["DopeSheetPanel", "DopeSheetView", "KEY_CLIP_MIME", "Row", "build_rows", "install", "key_clip",
           "put_key_clip"]
