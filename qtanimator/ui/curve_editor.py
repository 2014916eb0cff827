"""The curve editor dock: every channel as a curve with keys, handles, rules and extrapolation.

``install(window)`` adds the dock ``curveEditorDock`` holding a :class:`CurveEditor`: a
channel tree (asset → joint → DOF, visibility check boxes, filter) beside a toolbar, the
plot (``curvePlot``) and numeric fields for the active key. The parts live in
:mod:`qtanimator.ui.curves`; gestures and shortcuts are described in
:mod:`qtanimator.ui.curves.view`.

Selection is shared through the editor context: selecting rows calls
``ctx.select(asset, joint)`` and ``ctx.select_channels(ids)``; ``selectionChanged`` and
``channelSelectionChanged`` from other editors select rows here and highlight curves.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from PySide6.QtCore import QPoint, Qt
from PySide6.QtGui import QAction
from PySide6.QtWidgets import (
    QComboBox,
    QLabel,
    QMenu,
    QSplitter,
    QToolBar,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from qtanimator.core.channel import Extrapolation, Tangent
from qtanimator.document.commands import SetExtrapolation, SetTangents
from qtanimator.document.curve_commands import SetKeysBroken
from qtanimator.document.document import DocumentChange, split_channel_id
from qtanimator.ui.curves.fields import KeyFields
from qtanimator.ui.curves.tree import ChannelTree
from qtanimator.ui.curves.view import CurveView

TANGENT_RULES = (Tangent.FLAT, Tangent.LINEAR, Tangent.SMOOTH, Tangent.CLAMPED, Tangent.FIXED)
EXTRAPOLATIONS = (Extrapolation.CONSTANT, Extrapolation.LINEAR, Extrapolation.CYCLE,
                  Extrapolation.CYCLE_OFFSET, Extrapolation.BOUNCE)
_EXTRAP_TEXT = {"constant": "Constant", "linear": "Linear", "cycle": "Cycle",
                "cycle_offset": "Cycle with Offset", "bounce": "Bounce"}


class CurveEditor(QWidget):
    """The whole curve editor widget (tree, toolbar, plot, key fields)."""

    def __init__(self, ctx: Any, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("curveEditor")
        self.ctx = ctx
        self._echo = False
        self.view = CurveView(ctx, self)
        self.plot = self.view.widget
        self.tree = ChannelTree(self)
        self.fields = KeyFields(self.view, self)
        self._build_actions()
        self.toolbar = self._build_toolbar()

        right = QWidget(self)
        rl = QVBoxLayout(right)
        rl.setContentsMargins(0, 0, 0, 0)
        rl.setSpacing(0)
        rl.addWidget(self.toolbar)
        rl.addWidget(self.plot, 1)
        rl.addWidget(self.fields)
        self.splitter = QSplitter(Qt.Orientation.Horizontal, self)
        self.splitter.addWidget(self.tree)
        self.splitter.addWidget(right)
        self.splitter.setStretchFactor(1, 1)
        self.splitter.setSizes([200, 800])
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.splitter)

        self.tree.visibleChanged.connect(lambda _cids: self._apply_visibility())
        self.tree.selectionEdited.connect(self._tree_selection)
        ctx.selectionChanged.connect(self._context_selection)
        ctx.channelSelectionChanged.connect(self._context_channels)
        ctx.documentChanged.connect(self._document_changed)
        ctx.documentReset.connect(self._document_reset)
        self.view.context_menu_requested.connect(self._show_context_menu)
        self.view.normalisedChanged.connect(self.action_normalise.setChecked)
        self.view.keySelectionChanged.connect(self._update_enabled)
        self.plot.setContextMenuPolicy(Qt.ContextMenuPolicy.PreventContextMenu)
        self._document_reset()

    # ---------------------------------------------------------------- actions
    def _action(self, name: str, text: str, slot: Any, tip: str = "", checkable: bool = False) -> QAction:
        action = QAction(text, self)
        action.setObjectName(name)
        action.setIconText(text.split("\t")[0])
        action.setToolTip(tip or text.split("\t")[0])
        action.setCheckable(checkable)
        if checkable:
            action.toggled.connect(slot)
        else:
            action.triggered.connect(lambda _c=False: slot())
        return action

    def _build_actions(self) -> None:
        v = self.view
        # Shortcuts are handled by the plot's key handler (they only apply while it has focus);
        # the text after the tab shows them in menus.
        self.action_frame_all = self._action("actionCurveFrameAll", "Frame All\tA", v.frame_all)
        self.action_frame_selected = self._action("actionCurveFrameSelected", "Frame Selected\tF",
                                                  v.frame_selected)
        self.action_normalise = self._action("actionCurveNormalize", "Normalize\tN", v.set_normalised,
                                             "Display every curve scaled to −1…1 (does not change values)",
                                             checkable=True)
        self.action_snap = self._action("actionCurveSnap", "Snap", self._set_snap,
                                        "Snap dragged keys to whole frames", checkable=True)
        self.action_snap.setChecked(True)
        self.action_only_selected = self._action(
            "actionCurveOnlySelected", "Only Selected", lambda _on: self._apply_visibility(),
            "Show only the curves of the selected joints or channels", checkable=True)
        self.action_delete = self._action("actionCurveDeleteKeys", "Delete Keys\tDel", v.delete_selected)
        self.action_break = self._action("actionCurveBreakTangents", "Break Tangents",
                                         lambda: self.set_broken(True))
        self.action_unify = self._action("actionCurveUnifyTangents", "Unify Tangents",
                                         lambda: self.set_broken(False))

        self.tangent_menu = QMenu("Tangents", self)
        self.tangent_menu.setObjectName("curveTangentMenu")
        self.tangent_actions: dict[tuple[str, str], QAction] = {}
        for side, label in (("both", "In and Out"), ("in", "In"), ("out", "Out")):
            sub = self.tangent_menu.addMenu(label) if side != "both" else self.tangent_menu
            if side == "both":
                sub.addSection("In and Out")
            for rule in TANGENT_RULES:
                act = sub.addAction(rule.value.capitalize())
                act.setObjectName(f"actionCurveTangent_{side}_{rule.value}")
                act.triggered.connect(lambda _c=False, r=rule, s=side: self.set_tangents(r, s))
                self.tangent_actions[(side, rule.value)] = act
        self.tangent_menu.addSeparator()
        self.tangent_menu.addAction(self.action_break)
        self.tangent_menu.addAction(self.action_unify)

        self.extrap_menu = QMenu("Extrapolation", self)
        self.extrap_menu.setObjectName("curveExtrapolationMenu")
        self.extrap_actions: dict[tuple[str, str], QAction] = {}
        for side, label in (("both", "Pre and Post"), ("pre", "Pre"), ("post", "Post")):
            sub = self.extrap_menu.addMenu(label) if side != "both" else self.extrap_menu
            if side == "both":
                sub.addSection("Pre and Post")
            for mode in EXTRAPOLATIONS:
                act = sub.addAction(_EXTRAP_TEXT[mode.value])
                act.setObjectName(f"actionCurveExtrapolation_{side}_{mode.value}")
                act.triggered.connect(lambda _c=False, m=mode, s=side: self.set_extrapolation(m, s))
                self.extrap_actions[(side, mode.value)] = act

    def _build_toolbar(self) -> QToolBar:
        bar = QToolBar("Curve Editor", self)
        bar.setObjectName("curveEditorToolBar")
        bar.addAction(self.action_frame_all)
        bar.addAction(self.action_frame_selected)
        bar.addAction(self.action_normalise)
        bar.addAction(self.action_only_selected)
        bar.addSeparator()
        bar.addAction(self.action_snap)
        bar.addWidget(QLabel(" Lock "))
        self.axis_lock = QComboBox(bar)
        self.axis_lock.setObjectName("curveAxisLock")
        self.axis_lock.addItem("Free", "none")
        self.axis_lock.addItem("Time only", "time")
        self.axis_lock.addItem("Value only", "value")
        self.axis_lock.setToolTip("Constrain key drags (or hold Shift while dragging)")
        self.axis_lock.currentIndexChanged.connect(
            lambda _i: setattr(self.view, "axis_lock", self.axis_lock.currentData()))
        bar.addWidget(self.axis_lock)
        bar.addSeparator()
        for menu, name in ((self.tangent_menu, "curveTangentButton"), (self.extrap_menu, "curveExtrapolationButton")):
            button = QToolButton(bar)
            button.setObjectName(name)
            button.setText(menu.title())
            button.setMenu(menu)
            button.setPopupMode(QToolButton.ToolButtonPopupMode.InstantPopup)
            bar.addWidget(button)
        bar.addAction(self.action_delete)
        return bar

    def _set_snap(self, on: bool) -> None:
        self.view.snap = on

    def _update_enabled(self) -> None:
        has_keys = bool(self.view.selected_keys())
        self.action_delete.setEnabled(has_keys)
        self.action_break.setEnabled(has_keys)
        self.action_unify.setEnabled(has_keys)
        for act in self.tangent_actions.values():
            act.setEnabled(has_keys)

    def _show_context_menu(self, screen_pos: Any) -> None:
        menu = QMenu(self)
        menu.addMenu(self.tangent_menu)
        menu.addMenu(self.extrap_menu)
        menu.addSeparator()
        menu.addAction(self.action_delete)
        menu.addSeparator()
        menu.addAction(self.action_frame_all)
        menu.addAction(self.action_frame_selected)
        menu.addAction(self.action_normalise)
        menu.popup(QPoint(int(screen_pos.x()), int(screen_pos.y())))

    # ------------------------------------------------------------------ edits
    def set_tangents(self, rule: Tangent | str, side: str = "both") -> None:
        """Tangent rule for the selected keys on the in side, the out side, or both."""
        sel = self.view.selected_keys()
        if sel:
            self.ctx.push(SetTangents(self.ctx.doc, sel, rule, side))

    def set_broken(self, broken: bool) -> None:
        sel = self.view.selected_keys()
        if sel:
            self.ctx.push(SetKeysBroken(self.ctx.doc, sel, broken))

    def extrapolation_targets(self) -> list[str]:
        """Channels of the selected keys, else the highlighted (selected) visible channels."""
        sel = list(self.view.selected_keys())
        if sel:
            return sel
        return [c for c in self.view.visible if c in self.view.highlighted]

    def set_extrapolation(self, mode: Extrapolation | str, side: str = "both") -> None:
        cids = self.extrapolation_targets()
        if not cids:
            return
        pre = mode if side in ("pre", "both") else None
        post = mode if side in ("post", "both") else None
        self.ctx.push(SetExtrapolation(self.ctx.doc, cids, pre, post,
                                       text=f"Extrapolation: {Extrapolation(mode).value}"))

    # -------------------------------------------------------------- syncing
    def _document_changed(self, change: DocumentChange) -> None:
        listed = set(self.tree.channel_ids())
        channels = self.ctx.doc.channels
        if any((cid in channels) != (cid in listed) for cid in change.channels):
            self.tree.set_channels(list(channels))

    def _document_reset(self) -> None:
        self.view.reset()
        self.tree.set_channels(list(self.ctx.doc.channels))
        self._apply_visibility()
        # Positions in hundreds of units beside rotations in radians would flatten the
        # rotations to a line: open such a document normalised (every curve to -1…1).
        if _ranges_differ(self.ctx.doc.channels, self.view.visible) and not self.view.normalised:
            self.view.set_normalised(True)
        self.view.frame_all()
        self._update_enabled()

    def _apply_visibility(self) -> None:
        """Plot the checked channels that pass the filter (only the selected ones if asked)."""
        cids = self.tree.visible_channels()
        if self.action_only_selected.isChecked() and self.view.highlighted:
            cids = [c for c in cids if c in self.view.highlighted]
        if cids != self.view.visible:
            self.view.set_visible(cids)

    def _highlight(self, cids: list[str]) -> None:
        self.view.set_highlighted(cids)
        if self.action_only_selected.isChecked():
            self._apply_visibility()

    def _tree_selection(self, cids: list[str], asset: str, joint: str) -> None:
        self._highlight(cids)
        self._echo = True
        try:
            if asset:
                self.ctx.select(asset, joint)
            self.ctx.select_channels(cids)
        finally:
            self._echo = False

    def _context_selection(self, asset: str, joint: str) -> None:
        if self._echo:
            return
        prefix = f"{asset}/{joint}/" if joint else f"{asset}/"
        cids = [c for c in self.tree.channel_ids() if c.startswith(prefix)] if asset else []
        self.tree.show_selection(asset, joint)
        self._highlight(cids)
        if cids and not self.view.selected_keys():
            self.view.frame_selected()  # like Maya's auto frame: the joint's curves fill the view

    def _context_channels(self, cids: list[str]) -> None:
        if self._echo:
            return
        if self.tree.selected_channels() != list(cids):
            self.tree.show_selection("", "", cids)
        self._highlight(cids)


#: A document opens normalised when its position curves span this many times more than its
#: rotation curves (medians over the visible channels).
NORMALISE_RANGE_RATIO = 20.0
POSITION_DOFS = frozenset({"x", "y", "z", "tx", "ty", "tz"})


def _ranges_differ(channels: Any, visible: Any) -> bool:
    """True when position and rotation curves are both visible and the positions' spans
    dwarf the rotations' (pixels, SVG units or metres beside radians)."""
    spans: dict[bool, list[float]] = {True: [], False: []}
    for cid in visible:
        ch = channels.get(cid)
        if ch is None or len(ch.keys) < 2:
            continue
        values = ch.values
        span = float(values.max() - values.min())
        if span > 0:
            spans[split_channel_id(cid)[2] in POSITION_DOFS].append(span)
    if not spans[True] or not spans[False]:
        return False
    return float(np.median(spans[True])) > NORMALISE_RANGE_RATIO * float(np.median(spans[False]))


def install(window: Any) -> CurveEditor:
    editor = CurveEditor(window.ctx, window)
    window.curve_editor = editor
    window.add_dock("curveEditorDock", "Curve Editor", editor, Qt.DockWidgetArea.BottomDockWidgetArea)
    from qtanimator.ui.timeline import add_timeline_keys

    add_timeline_keys(window, editor.plot)  # the timeline is installed before this editor
    return editor
