"""The outliner's tree (the Joints dock's, :class:`JointTree`): every 2D character and 3D
skeleton with its joints, the other assets and the two lights.

The tree follows ``ctx.selection`` and sets it; keyframed joints carry a key icon (filled
once the joint has keys), dynamic (pendulum) joints a white bob. Each row has an eye and a
lock; F2 renames an asset, Delete removes it, F frames the current row's asset in its view
(there is no type-ahead: letters never move the current row), the right-click menu frames,
resets, hides, locks, renames or removes it. Drag a 2D joint onto another joint of the same character to
re-parent it (one undo step, :func:`qtanimator.document.rigging.reparent_command`); a drop
that would make a joint hang from itself is refused with a message in the status bar.
"""

from __future__ import annotations

from collections.abc import Callable, Collection
from typing import Any

from PySide6.QtCore import QEvent, QPoint, Qt, QTimer
from PySide6.QtGui import QAction, QContextMenuEvent, QKeyEvent, QMouseEvent, QPalette
from PySide6.QtWidgets import (
    QAbstractItemView,
    QApplication,
    QDockWidget,
    QHeaderView,
    QMenu,
    QTreeWidget,
    QTreeWidgetItem,
    QWidget,
)

from qtanimator.document import character2d, character3d, outliner
from qtanimator.document.commands import RemoveAsset
from qtanimator.document.document import split_channel_id
from qtanimator.document.outliner import HIDDEN, LOCKED
from qtanimator.ui.context import EditorContext
from qtanimator.ui.dof_specs import asset_kind, joint_names, reset_pose_command
from qtanimator.ui.outliner_icons import icon

ROLE = Qt.ItemDataRole.UserRole
#: What a row is: "asset", "joint" or "light".
KIND_ROLE = Qt.ItemDataRole.UserRole + 1
NAME_COLUMN, EYE_COLUMN, LOCK_COLUMN = 0, 1, 2
TOGGLE_WIDTH = 24
#: Light rows carry ``light:NAME`` as their id (a light is no asset; no asset id holds ':').
LIGHT_PREFIX = "light:"
LIGHT_TITLES = {"light1": "Light 1 (key)", "light2": "Light 2 (fill)"}


class JointTree(QTreeWidget):
    """The outliner: every asset (2D and 3D characters with their joints, cloths, others)
    and the two lights, each with an eye (shown / hidden) and a lock toggle.

    Click the eye or the lock to toggle it; F2 or a double-click renames an asset, Delete
    removes it, and the right-click menu frames it in the view, resets its pose, hides,
    locks, renames or removes it. Every change is one undo step."""

    def __init__(self, ctx: EditorContext, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("jointTree")
        self.ctx = ctx
        self.setHeaderHidden(True)
        self.setColumnCount(3)
        header = self.header()
        header.setStretchLastSection(False)
        header.setSectionResizeMode(NAME_COLUMN, QHeaderView.ResizeMode.Stretch)
        for column in (EYE_COLUMN, LOCK_COLUMN):
            header.setSectionResizeMode(column, QHeaderView.ResizeMode.Fixed)
            header.resizeSection(column, TOGGLE_WIDTH)
        self.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)  # F2 / double-click: below
        self.icons = {k: icon(k) for k in ("dynamic", "keyed", "key", "character", "skeleton", "cloth", "light",
                                            "shown", "hidden", "locked", "unlocked")}
        self._items: dict[tuple[str, str], QTreeWidgetItem] = {}
        self._syncing = False
        self.currentItemChanged.connect(self._current_changed)
        self.itemChanged.connect(self._item_changed)
        #: A re-parenting drag: the joint item pressed, where, and whether it is moving.
        self._press: tuple[QTreeWidgetItem, QPoint] | None = None
        self.reparenting = False
        self.last_message = ""
        #: The open context menu (tests find its actions here).
        self.menu: QMenu | None = None

    # ------------------------------------------------------------- rows
    @staticmethod
    def row_kind(item: QTreeWidgetItem | None) -> str:
        """``asset``, ``joint`` or ``light`` (``""`` for None)."""
        return "" if item is None else str(item.data(0, KIND_ROLE))

    def light_item(self, name: str) -> QTreeWidgetItem | None:
        return self._items.get((LIGHT_PREFIX + name, ""))

    def toggle_rect(self, item: QTreeWidgetItem, column: int) -> Any:
        """Where the eye (EYE_COLUMN) or lock (LOCK_COLUMN) of a row is drawn (viewport coordinates)."""
        return self.visualRect(self.indexFromItem(item, column))

    # ------------------------------------------------------- mouse and keys
    def _toggle_at(self, event: QMouseEvent) -> bool:
        """A left press on an eye or a lock: toggle it (without selecting the row)."""
        if event.button() != Qt.MouseButton.LeftButton:
            return False
        pos = event.position().toPoint()
        item = self.itemAt(pos)
        column = self.columnAt(pos.x())
        if item is None or column not in (EYE_COLUMN, LOCK_COLUMN) or self.row_kind(item) == "joint":
            return False
        self.toggle(item.data(0, ROLE)[0], HIDDEN if column == EYE_COLUMN else LOCKED)
        event.accept()
        return True

    def mousePressEvent(self, event: QMouseEvent) -> None:
        self._press = None
        self.reparenting = False
        if self._toggle_at(event):
            return
        super().mousePressEvent(event)
        item = self.itemAt(event.position().toPoint())
        if event.button() == Qt.MouseButton.RightButton:
            self._menu_requested(event.position().toPoint())
            event.accept()
            return
        if event.button() == Qt.MouseButton.LeftButton and self.row_kind(item) == "joint":
            assert item is not None
            self._press = (item, event.position().toPoint())

    def mouseMoveEvent(self, event: QMouseEvent) -> None:
        if self._press is not None and event.buttons() & Qt.MouseButton.LeftButton:
            moved = (event.position().toPoint() - self._press[1]).manhattanLength()
            if moved >= QApplication.startDragDistance():
                if not self.reparenting:
                    self.reparenting = True
                    self.viewport().setCursor(Qt.CursorShape.DragMoveCursor)
                event.accept()
                return
        if not self.reparenting:
            super().mouseMoveEvent(event)

    def mouseReleaseEvent(self, event: QMouseEvent) -> None:
        press, dragging = self._press, self.reparenting
        self._press = None
        self.reparenting = False
        if dragging:
            self.viewport().unsetCursor()
        if press is None or not dragging or event.button() != Qt.MouseButton.LeftButton:
            super().mouseReleaseEvent(event)
            return
        event.accept()
        target = self.itemAt(event.position().toPoint())
        if target is None or target is press[0]:
            return
        self.reparent(press[0].data(0, ROLE), target.data(0, ROLE))

    def mouseDoubleClickEvent(self, event: QMouseEvent) -> None:
        if self._toggle_at(event):  # a quick second click on a toggle toggles it back
            return
        item = self.itemAt(event.position().toPoint())
        if event.button() == Qt.MouseButton.LeftButton and self.row_kind(item) == "asset":
            assert item is not None
            self.start_rename(item)
            event.accept()
            return
        super().mouseDoubleClickEvent(event)

    def event(self, event: QEvent) -> bool:
        # F2 and Delete belong to the tree while it has the focus (not to a window shortcut).
        if event.type() == QEvent.Type.ShortcutOverride and isinstance(event, QKeyEvent) \
                and event.key() in (Qt.Key.Key_F2, Qt.Key.Key_Delete) and self.state() != self.State.EditingState:
            event.accept()
            return True
        return super().event(event)

    def keyboardSearch(self, search: str) -> None:
        """No type-ahead: a letter typed here is a view's key (F frames), never a jump to the
        next row whose name starts with it (see :mod:`qtanimator.ui.key_routing`)."""

    def keyPressEvent(self, event: QKeyEvent) -> None:
        item = self.currentItem()
        if self.state() != self.State.EditingState and event.modifiers() == Qt.KeyboardModifier.NoModifier:
            if event.key() == Qt.Key.Key_F:
                # Frame the current row's asset in its view (the pointer was not over a
                # view: then the view has the key, see key_routing).
                if item is not None and self.row_kind(item) != "light":
                    self.frame_in_view(item.data(0, ROLE)[0])
                event.accept()
                return
            if event.key() == Qt.Key.Key_F2 and item is not None:
                self.start_rename(item)
                event.accept()
                return
            if event.key() in (Qt.Key.Key_Delete, Qt.Key.Key_Backspace) and item is not None:
                self.remove(item.data(0, ROLE)[0] if self.row_kind(item) != "joint" else "")
                event.accept()
                return
        super().keyPressEvent(event)

    # ------------------------------------------------------------- edits
    def toggle(self, target: str, name: str) -> None:
        """Flip ``hidden`` or ``locked`` of an asset (or ``light:NAME`` row id): one undo step."""
        target = target.removeprefix(LIGHT_PREFIX)
        self.ctx.push(outliner.set_flag_command(self.ctx.doc, target, name, not outliner.flag(self.ctx.doc,
                                                                                                target, name)))

    def start_rename(self, item: QTreeWidgetItem) -> bool:
        if self.row_kind(item) != "asset":
            return self._say("Only assets can be renamed here.")
        self.setCurrentItem(item, NAME_COLUMN)
        self.editItem(item, NAME_COLUMN)
        return True

    def _item_changed(self, item: QTreeWidgetItem, column: int) -> None:
        if self._syncing or column != NAME_COLUMN or self.row_kind(item) != "asset":
            return
        old = item.data(0, ROLE)[0]
        new = item.text(NAME_COLUMN).strip()
        if new == old:
            return
        # The tree is rebuilt by the rename: leave the editor's signal first.
        QTimer.singleShot(0, lambda: self.rename(old, new))

    def rename(self, old: str, new: str) -> bool:
        """Rename an asset (its channels and the selection follow); a name in use, empty or
        with other characters than letters, digits and - _ . is refused with a message."""
        doc = self.ctx.doc
        problem = outliner.name_problem(doc, old, new)
        if problem is not None:
            item = self._items.get((old, ""))
            if item is not None:
                self._syncing = True
                item.setText(NAME_COLUMN, old)
                self._syncing = False
            return self._say(problem)
        asset, joint = self.ctx.selection
        channels = self.ctx.channel_selection
        self.ctx.push(outliner.rename_command(doc, old, new))
        if asset == old:
            self.ctx.select(new, joint)
        prefix = old + "/"
        if any(c.startswith(prefix) for c in channels):
            self.ctx.select_channels([new + "/" + c[len(prefix):] if c.startswith(prefix) else c for c in channels])
        self._say(f"Renamed {old} to {new}.")
        return True

    def remove(self, asset: str) -> bool:
        """Remove an asset and its channels: one undo step."""
        if asset.startswith(LIGHT_PREFIX):
            return self._say("The lights cannot be removed: hide them instead.")
        if asset not in self.ctx.doc.assets:
            return self._say("Select an asset's row to remove it.")
        self.ctx.push(RemoveAsset(self.ctx.doc, asset))
        return True

    # ------------------------------------------------------- context menu
    def contextMenuEvent(self, event: QContextMenuEvent) -> None:
        # A right press opens the menu (mousePressEvent); here only the Menu key does.
        event.accept()
        if event.reason() != QContextMenuEvent.Reason.Mouse and self.currentItem() is not None:
            self._menu_requested(self.visualItemRect(self.currentItem()).center())

    def _menu_requested(self, pos: QPoint) -> None:
        item = self.itemAt(pos)
        if item is None:
            return
        menu = self.context_menu(item)
        menu.popup(self.viewport().mapToGlobal(pos))

    def context_menu(self, item: QTreeWidgetItem) -> QMenu:
        """The right-click menu of a row (of its asset for a joint's row)."""
        target = item.data(0, ROLE)[0]
        light = self.row_kind(item) == "light"
        name = target.removeprefix(LIGHT_PREFIX)
        doc = self.ctx.doc
        menu = QMenu(self)
        menu.setObjectName("outlinerMenu")
        menu.setAttribute(Qt.WidgetAttribute.WA_DeleteOnClose)

        def add(object_name: str, text: str, slot: Callable[[], object], enabled: bool = True) -> QAction:
            action = menu.addAction(text)
            action.setObjectName(object_name)
            action.setEnabled(enabled)
            action.triggered.connect(lambda _c=False: slot())
            return action

        kind = asset_kind(doc, target)
        character = kind in (character2d.ASSET_KIND, character3d.ASSET_KIND)
        add("outlinerFrame", "Frame in View", lambda: self.frame_in_view(target), not light)
        add("outlinerResetPose", "Reset Pose", lambda: self._reset_pose(target), character)
        menu.addSeparator()
        hidden, locked = outliner.is_hidden(doc, name), outliner.is_locked(doc, name)
        add("outlinerHide", "Show" if hidden else "Hide", lambda: self.toggle(name, HIDDEN))
        add("outlinerLock", "Unlock" if locked else "Lock", lambda: self.toggle(name, LOCKED))
        menu.addSeparator()
        rename_item = self._items.get((target, ""))
        add("outlinerRename", "Rename… (F2)", lambda: rename_item is not None and self.start_rename(rename_item),
            not light)
        add("outlinerRemove", "Remove (Delete)", lambda: self.remove(target), not light)
        self.menu = menu
        return menu

    def _reset_pose(self, asset: str) -> None:
        cmd = reset_pose_command(self.ctx.doc, asset, self.ctx.time)
        if cmd is not None:
            self.ctx.push(cmd)

    def frame_in_view(self, asset: str) -> bool:
        """Show the editor that draws ``asset`` and fit its view to it: the 2D editor for a
        2D character, the 3D view for the rest."""
        window = self.window()
        doc = self.ctx.doc
        if asset not in doc.assets:
            return False
        if asset_kind(doc, asset) == character2d.ASSET_KIND:
            editor = getattr(window, "rig_editor", None)
            if editor is None:
                return False
            _show_central(window, editor)
            return bool(editor.view.frame_asset(asset))
        view = getattr(window, "viewport3d", None)
        if view is None:
            return False
        _show_central(window, getattr(window, "viewport_panel", view))
        if self.ctx.selection[0] != asset:
            self.ctx.select(asset, "")
        view.frame_selection()
        return True

    def reparent(self, source: tuple[str, str], target: tuple[str, str]) -> bool:
        """Make ``target`` (asset, joint) the parent of ``source``: one undo step."""
        asset, joint = source
        doc = self.ctx.doc
        if asset_kind(doc, asset) != character2d.ASSET_KIND:
            return self._say("Only the joints of 2D characters can be re-parented here.")
        if target[0] != asset:
            return self._say("A joint can only hang from a joint of its own character.")
        from qtanimator.document import rigging
        from qtanimator.formats.errors import FormatError

        parent = target[1] or doc.runtime[asset].joints[0].name
        try:
            command = rigging.reparent_command(doc, asset, joint, parent)
        except (rigging.RigError, FormatError) as exc:
            return self._say(str(exc))
        self.ctx.push(command)
        self.ctx.select(asset, joint)
        return True

    def _say(self, text: str) -> bool:
        self.last_message = text
        bar = getattr(self.window(), "statusBar", None)
        if callable(bar):
            bar().showMessage(text, 5000)
        return False

    def rebuild(self) -> None:
        self._syncing = True
        self.clear()
        self._items.clear()
        doc = self.ctx.doc
        for aid, asset in doc.assets.items():
            top = QTreeWidgetItem([aid])
            top.setData(0, ROLE, (aid, ""))
            top.setData(0, KIND_ROLE, "asset")
            top.setFlags(top.flags() | Qt.ItemFlag.ItemIsEditable)
            icon = ("character" if asset.kind == character2d.ASSET_KIND
                    else "skeleton" if asset.kind == character3d.ASSET_KIND
                    else "cloth" if asset.kind == "cloth" else "")
            if icon:
                top.setIcon(0, self.icons[icon])
            top.setToolTip(0, f"{aid} ({asset.kind}): F2 renames, Delete removes, right-click for more")
            self.addTopLevelItem(top)
            self._items[(aid, "")] = top
            self._show_flags(top, aid)
            items: list[QTreeWidgetItem] = []
            for name, parent, _dynamic in joint_names(doc, aid):
                item = QTreeWidgetItem([name])
                item.setData(0, ROLE, (aid, name))
                item.setData(0, KIND_ROLE, "joint")
                (items[parent] if parent is not None else top).addChild(item)
                items.append(item)
                self._items[(aid, name)] = item
            top.setExpanded(True)
            for item in items:
                item.setExpanded(True)
        for name in outliner.LIGHTS:
            row = QTreeWidgetItem([LIGHT_TITLES.get(name, name)])
            row.setData(0, ROLE, (LIGHT_PREFIX + name, ""))
            row.setData(0, KIND_ROLE, "light")
            row.setIcon(0, self.icons["light"])
            row.setToolTip(0, f"{name}: its position, colour and intensity are in the Lights dock")
            self.addTopLevelItem(row)
            self._items[(LIGHT_PREFIX + name, "")] = row
            self._show_flags(row, name)
        self.refresh_icons()
        self._syncing = False
        self.follow_selection()

    def _show_flags(self, item: QTreeWidgetItem, target: str) -> None:
        """The eye and lock of a row, and its name greyed when hidden."""
        doc = self.ctx.doc
        hidden, locked = outliner.is_hidden(doc, target), outliner.is_locked(doc, target)
        item.setIcon(EYE_COLUMN, self.icons["hidden" if hidden else "shown"])
        item.setToolTip(EYE_COLUMN, "hidden: click to show" if hidden else "shown: click to hide")
        item.setIcon(LOCK_COLUMN, self.icons["locked" if locked else "unlocked"])
        item.setToolTip(LOCK_COLUMN, "locked: click to unlock" if locked else "click to lock (no picking in views)")
        item.setForeground(NAME_COLUMN, self.palette().brush(
            QPalette.ColorGroup.Disabled if hidden else QPalette.ColorGroup.Active, QPalette.ColorRole.Text))

    def refresh_flags(self) -> None:
        """Update every row's eye and lock (flags are asset properties and light parameters)."""
        self._syncing = True
        try:
            for (target, joint), item in self._items.items():
                if not joint:
                    self._show_flags(item, target.removeprefix(LIGHT_PREFIX))
        finally:
            self._syncing = False

    def refresh_icons(self, assets: Collection[str] | None = None) -> None:
        """Update the keyed / not keyed icons of every joint (of ``assets`` only if given)."""
        doc = self.ctx.doc
        shown = {k[0] for k in self._items}
        targets = shown if assets is None else shown & set(assets)
        if not targets:
            return
        keyed: set[tuple[str, str]] = set()
        for aid in targets:
            for cid, ch in doc.channels_of(aid):
                if ch.keys:
                    a, j, _dof = split_channel_id(cid)
                    keyed.add((a, j))
        for aid in targets:
            for name, _parent, dynamic in joint_names(doc, aid):
                item = self._items.get((aid, name))
                if item is None:
                    continue
                kind = "dynamic" if dynamic else ("keyed" if (aid, name) in keyed else "key")
                item.setIcon(0, self.icons[kind])
                item.setToolTip(0, {"dynamic": "dynamic joint (pendulum)", "keyed": "keyframed joint (has keys)",
                                    "key": "keyframed joint"}[kind])

    def item_for(self, asset: str, joint: str) -> QTreeWidgetItem | None:
        return self._items.get((asset, joint))

    def follow_selection(self) -> None:
        item = self.item_for(*self.ctx.selection)
        self._syncing = True
        self.setCurrentItem(item)  # type: ignore[arg-type]
        if item is None:
            self.clearSelection()
        else:
            self.scrollToItem(item)
        self._syncing = False

    def _current_changed(self, current: QTreeWidgetItem | None, _previous: QTreeWidgetItem | None) -> None:
        if self._syncing or current is None:
            return
        asset, joint = current.data(0, ROLE)
        if self.row_kind(current) == "light":
            # A light is no asset: show its dock (position, colour, intensity) instead.
            dock = self.window().findChild(QDockWidget, "lightDock")
            if dock is not None:
                dock.show()
                dock.raise_()
            return
        self.ctx.select(asset, joint)

    def step_joint(self, delta: int) -> None:
        """Select the next / previous joint of the selected asset (pre-order, wrapping)."""
        asset, joint = self.ctx.selection
        if not asset:
            return
        names = [""] + [n for n, _p, _d in joint_names(self.ctx.doc, asset)]
        i = names.index(joint) if joint in names else 0
        self.ctx.select(asset, names[(i + delta) % len(names)])


def _show_central(window: QWidget, widget: QWidget) -> None:
    """Bring the central tab holding ``widget`` to the front."""
    tabs = getattr(window, "central_tabs", None)
    if tabs is None:
        return
    for i in range(tabs.count()):
        page = tabs.widget(i)
        if page is widget or page.isAncestorOf(widget):
            tabs.setCurrentIndex(i)
            return
