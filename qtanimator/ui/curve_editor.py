"""The curve editor dock: every channel as a curve with keys, handles, rules and extrapolation.

``install(window)`` adds the dock ``curveEditorDock`` holding a :class:`CurveEditor`: a
channel tree (asset → joint → DOF, visibility check boxes, filter) beside a toolbar, the
plot (``curvePlot``) and numeric fields for the active key. The parts live in
:mod:`qtanimator.ui.curves`; gestures and shortcuts are described in
:mod:`qtanimator.ui.curves.view`, and what a drag does (without Qt) in
:mod:`qtanimator.ui.curves.drags`.

Ctrl+C / Ctrl+V / Ctrl+Shift+V (while the editor has the focus) copy the selected keys and
paste them at the current frame (merging, or replacing the pasted range), on the one key
clipboard the dope sheet uses. The Tangents and Extrapolation menus check the rule the
selection has; "Weighted Tangents" gives the selected keys handle lengths of their own.

Selection is shared through the editor context: selecting rows calls
``ctx.select(asset, joint)`` and ``ctx.select_channels(ids)``; ``selectionChanged`` and
``channelSelectionChanged`` from other editors select rows here and highlight curves.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import replace
from typing import Any

import numpy as np
from PySide6.QtCore import QPoint, Qt
from PySide6.QtGui import QAction, QActionGroup, QKeySequence
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

from qtanimator.core.channel import Channel, Extrapolation, Key, Tangent
from qtanimator.document.commands import SetChannels, SetExtrapolation, SetTangents
from qtanimator.document.curve_commands import SetKeysBroken
from qtanimator.document.document import DocumentChange, split_channel_id
from qtanimator.document.keying import (
    KeyClip,
    KeyEdit,
    animatable_channel_ids,
    copy_keys,
    paste_keys_command,
    retarget,
)
from qtanimator.ui.curves.fields import KeyFields
from qtanimator.ui.curves.normalisation import unit_scale
from qtanimator.ui.curves.tree import ChannelTree
from qtanimator.ui.curves.view import CurveView

TANGENT_RULES = (Tangent.FLAT, Tangent.LINEAR, Tangent.SMOOTH, Tangent.CLAMPED, Tangent.CENTRIPETAL,
                 Tangent.CHORDAL, Tangent.TCB, Tangent.FIXED)
_TANGENT_TEXT = {"centripetal": "Centripetal (Catmull-Rom)", "chordal": "Chordal (Catmull-Rom)",
                 "tcb": "TCB (Kochanek–Bartels)"}
_TANGENT_TIPS = {
    "smooth": "Catmull-Rom: the slope between the two neighbouring keys",
    "centripetal": "Catmull-Rom through the keys as points in time and value, knots spaced by the square "
                   "root of their distance: follows uneven keys without loops or overshoot spikes",
    "chordal": "Catmull-Rom through the keys as points in time and value, knots spaced by their distance",
    "tcb": "Kochanek–Bartels: the key's Tension, Continuity and Bias (fields under the plot) shape its slopes",
}
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

        self.action_weighted = self._action(
            "actionCurveWeightedTangents", "Weighted Tangents", self.set_weighted,
            "Weighted keys keep handles of their own length: dragging a handle then sets its slope "
            "and its length", checkable=True)
        self.action_copy = self._action("actionCurveCopyKeys", "Copy Keys\tCtrl+C", self.copy_keys)
        self.action_copy.setShortcut(QKeySequence.StandardKey.Copy)
        self.action_paste = self._action("actionCurvePasteKeys", "Paste Keys\tCtrl+V", self.paste_keys,
                                         "Paste the copied keys at the current frame")
        self.action_paste.setShortcut(QKeySequence.StandardKey.Paste)
        self.action_paste_replace = self._action(
            "actionCurvePasteKeysReplace", "Paste Keys (Replace)\tCtrl+Shift+V", lambda: self.paste_keys("replace"),
            "Paste the copied keys at the current frame, clearing the pasted range first")
        self.action_paste_replace.setShortcut(QKeySequence("Ctrl+Shift+V"))
        for act in (self.action_copy, self.action_paste, self.action_paste_replace):
            act.setShortcutContext(Qt.ShortcutContext.WidgetWithChildrenShortcut)
            self.addAction(act)

        # The rule menus show the selection's current rule as a check mark (none when the
        # selected keys differ), refreshed each time a menu opens.
        self.tangent_menu = QMenu("Tangents", self)
        self.tangent_menu.setObjectName("curveTangentMenu")
        self.tangent_actions: dict[tuple[str, str], QAction] = {}
        self.tangent_groups: dict[str, QActionGroup] = {}
        for side, label in (("both", "In and Out"), ("in", "In"), ("out", "Out")):
            sub = self.tangent_menu.addMenu(label) if side != "both" else self.tangent_menu
            sub.setToolTipsVisible(True)
            if side == "both":
                sub.addSection("In and Out")
            else:
                sub.setObjectName(f"curveTangentMenu_{side}")
            group = self.tangent_groups[side] = QActionGroup(self)
            group.setExclusionPolicy(QActionGroup.ExclusionPolicy.ExclusiveOptional)
            for rule in TANGENT_RULES:
                act = sub.addAction(_TANGENT_TEXT.get(rule.value, rule.value.capitalize()))
                act.setObjectName(f"actionCurveTangent_{side}_{rule.value}")
                if rule.value in _TANGENT_TIPS:
                    act.setToolTip(_TANGENT_TIPS[rule.value])
                act.setCheckable(True)
                group.addAction(act)
                act.triggered.connect(lambda _c=False, r=rule, s=side: self.set_tangents(r, s))
                self.tangent_actions[(side, rule.value)] = act
            sub.aboutToShow.connect(self.show_current_rules)
        self.tangent_menu.addSeparator()
        self.tangent_menu.addAction(self.action_break)
        self.tangent_menu.addAction(self.action_unify)
        self.tangent_menu.addAction(self.action_weighted)

        self.extrap_menu = QMenu("Extrapolation", self)
        self.extrap_menu.setObjectName("curveExtrapolationMenu")
        self.extrap_actions: dict[tuple[str, str], QAction] = {}
        self.extrap_groups: dict[str, QActionGroup] = {}
        for side, label in (("both", "Pre and Post"), ("pre", "Pre"), ("post", "Post")):
            sub = self.extrap_menu.addMenu(label) if side != "both" else self.extrap_menu
            if side == "both":
                sub.addSection("Pre and Post")
            else:
                sub.setObjectName(f"curveExtrapolationMenu_{side}")
            group = self.extrap_groups[side] = QActionGroup(self)
            group.setExclusionPolicy(QActionGroup.ExclusionPolicy.ExclusiveOptional)
            for mode in EXTRAPOLATIONS:
                act = sub.addAction(_EXTRAP_TEXT[mode.value])
                act.setObjectName(f"actionCurveExtrapolation_{side}_{mode.value}")
                act.setCheckable(True)
                group.addAction(act)
                act.triggered.connect(lambda _c=False, m=mode, s=side: self.set_extrapolation(m, s))
                self.extrap_actions[(side, mode.value)] = act
            sub.aboutToShow.connect(self.show_current_rules)

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
        for act in (self.action_delete, self.action_break, self.action_unify, self.action_weighted,
                    self.action_copy):
            act.setEnabled(has_keys)
        for act in self.tangent_actions.values():
            act.setEnabled(has_keys)

    # ------------------------------------------------------------ rule menus
    def current_rules(self) -> dict[str, str | None]:
        """What the rule menus check: ``{"both" | "in" | "out": tangent rule}`` of the
        selected keys and ``{"extrapolation_both" | "_pre" | "_post": mode}`` of the
        extrapolation targets; None where they differ (or nothing is selected).
        ``"weighted"`` is "yes" when every selected key is weighted."""
        doc = self.ctx.doc
        ins: set[str] = set()
        outs: set[str] = set()
        weighted = True
        for cid, idx in self.view.selected_keys().items():
            keys = doc.channels[cid].keys
            for i in idx:
                k = keys[i]
                ins.add(k.in_tangent.value)
                outs.add(k.out_tangent.value)
                weighted = weighted and _is_weighted(k)
        one_in = next(iter(ins)) if len(ins) == 1 else None
        one_out = next(iter(outs)) if len(outs) == 1 else None
        pres = {doc.channels[c].pre.value for c in self.extrapolation_targets() if c in doc.channels}
        posts = {doc.channels[c].post.value for c in self.extrapolation_targets() if c in doc.channels}
        pre = next(iter(pres)) if len(pres) == 1 else None
        post = next(iter(posts)) if len(posts) == 1 else None
        return {"both": one_in if one_in == one_out else None, "in": one_in, "out": one_out,
                "extrapolation_both": pre if pre == post else None, "extrapolation_pre": pre,
                "extrapolation_post": post, "weighted": "yes" if weighted and (ins or outs) else None}

    def show_current_rules(self) -> None:
        """Check, in the Tangents and Extrapolation menus, the rule the selection has now."""
        rules = self.current_rules()
        for (side, rule), act in self.tangent_actions.items():
            act.setChecked(rules[side] == rule)
        for (side, mode), act in self.extrap_actions.items():
            act.setChecked(rules[f"extrapolation_{side}"] == mode)
        self.action_weighted.blockSignals(True)
        self.action_weighted.setChecked(rules["weighted"] == "yes")
        self.action_weighted.blockSignals(False)

    def _show_context_menu(self, screen_pos: Any) -> None:
        menu = QMenu(self)
        menu.setObjectName("curveContextMenu")
        menu.setAttribute(Qt.WidgetAttribute.WA_DeleteOnClose)
        menu.addMenu(self.tangent_menu)
        menu.addMenu(self.extrap_menu)
        menu.addSeparator()
        menu.addAction(self.action_copy)
        menu.addAction(self.action_paste)
        menu.addAction(self.action_paste_replace)
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
            keys: dict[str, Iterable[int]] = dict(sel)  # SetTangents takes any iterable of indices
            self.ctx.push(SetTangents(self.ctx.doc, keys, rule, side))

    def set_broken(self, broken: bool) -> None:
        sel = self.view.selected_keys()
        if sel:
            self.ctx.push(SetKeysBroken(self.ctx.doc, sel, broken))

    def set_weighted(self, on: bool = True) -> None:
        """Make the selected keys weighted (their handles keep their current length, one
        third of the span on each side, so the curve does not change) or not weighted
        (handles back to one third of the span)."""
        sel = self.view.selected_keys()
        if not sel:
            return
        doc = self.ctx.doc
        changes: dict[str, tuple[Channel | None, Channel | None]] = {}
        for cid, idx in sel.items():
            old = doc.channels[cid]
            edits = {i: weighted_key(old, i) if on else replace(old.keys[i], in_weight=None, out_weight=None)
                     for i in idx}
            new = old.replace_keys(edits)
            if new != old:
                changes[cid] = (old, new)
        if changes:
            self.ctx.push(SetChannels("Weighted Tangents" if on else "Non-weighted Tangents", changes))

    # ---------------------------------------------------------- copy, paste
    def copy_keys(self) -> KeyClip | None:
        """Ctrl+C: the selected keys go to the clipboard (the dope sheet pastes them too)."""
        sel = self.view.selected_keys()
        if not sel:
            return None
        from qtanimator.ui.dope_sheet import put_key_clip  # the one key clipboard

        clip = copy_keys(self.ctx.doc, sel)
        put_key_clip(clip)
        return clip

    def paste_keys(self, mode: str = "merge") -> KeyEdit | None:
        """Ctrl+V: the copied keys at the current frame, on the channels they came from
        (or on the selected character's when none of those is here); they become the
        selection. ``mode`` "replace" (Ctrl+Shift+V) first clears the pasted range."""
        from qtanimator.ui.dope_sheet import key_clip

        clip = key_clip()
        if clip is None or not clip:
            return None
        doc = self.ctx.doc
        target = None
        asset = self.ctx.selection[0]
        if asset in doc.assets and not any(cid in doc.channels for cid in clip.channels):
            target = retarget(clip, asset, animatable_channel_ids(doc, asset))
        edit = paste_keys_command(doc, clip, self.ctx.time, mode, target)
        if edit.is_noop():
            return edit
        self.ctx.push(edit.command)
        self._apply_visibility()
        self.view.set_selection({c: i for c, i in edit.selection.items() if c in self.view.visible})
        return edit

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
        # Positions in metres beside rotations in degrees would flatten the positions to a
        # line (and thousands of pixels the rotations): open such a document normalised
        # (every curve to -1…1).
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


#: A document opens normalised when its position curves span this many times more (or less)
#: than its rotation curves, in the units shown (medians over the visible channels).
NORMALISE_RANGE_RATIO = 20.0
POSITION_DOFS = frozenset({"x", "y", "z", "tx", "ty", "tz"})


def _is_weighted(key: Key) -> bool:
    return key.in_weight is not None or key.out_weight is not None


def weighted_key(channel: Channel, i: int) -> Key:
    """Key ``i`` made weighted without changing the curve: each side's handle length is
    what it is now (one third of the span on that side; the first and last keys take the
    one span they have, a lone key a third of a second)."""
    keys = channel.keys
    key = keys[i]
    before = (key.time - keys[i - 1].time) / 3.0 if i > 0 else None
    after = (keys[i + 1].time - key.time) / 3.0 if i + 1 < len(keys) else None
    w_in = key.in_weight or before or after or 1.0 / 3.0
    w_out = key.out_weight or after or before or 1.0 / 3.0
    return replace(key, in_weight=w_in, out_weight=w_out)


def _ranges_differ(channels: Any, visible: Any) -> bool:
    """True when position and rotation curves are both visible and one kind's spans dwarf
    the other's in the units shown (pixels or SVG units beside degrees, metres beside
    degrees)."""
    spans: dict[bool, list[float]] = {True: [], False: []}
    for cid in visible:
        ch = channels.get(cid)
        if ch is None or len(ch.keys) < 2:
            continue
        values = ch.values
        span = float(values.max() - values.min()) * unit_scale(cid)
        if span > 0:
            spans[split_channel_id(cid)[2] in POSITION_DOFS].append(span)
    if not spans[True] or not spans[False]:
        return False
    positions, rotations = float(np.median(spans[True])), float(np.median(spans[False]))
    return positions > NORMALISE_RANGE_RATIO * rotations or rotations > NORMALISE_RANGE_RATIO * positions


def install(window: Any) -> CurveEditor:
    editor = CurveEditor(window.ctx, window)
    window.curve_editor = editor
    window.add_dock("curveEditorDock", "Curve Editor", editor, Qt.DockWidgetArea.BottomDockWidgetArea)
    from qtanimator.ui.timeline import add_timeline_keys

    add_timeline_keys(window, editor.plot)  # the timeline is installed before this editor
    return editor
