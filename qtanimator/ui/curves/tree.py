"""The channel tree: asset → joint → DOF, with visibility check boxes and a search filter.

Asset-level channels (joint ``""``, e.g. ``"hero//x"``) sit directly under their asset.
Checking a parent checks its children; a parent shows partially checked when its
children differ. The filter matches the full channel id, case-insensitively.
"""

from __future__ import annotations

from collections.abc import Iterable

from PySide6.QtCore import QItemSelection, QItemSelectionModel, QModelIndex, QSortFilterProxyModel, Qt, Signal
from PySide6.QtGui import QStandardItem, QStandardItemModel
from PySide6.QtWidgets import QAbstractItemView, QLineEdit, QTreeView, QVBoxLayout, QWidget

from qtanimator.document.document import split_channel_id
from qtanimator.ui.curves.items import channel_colour

CID_ROLE = Qt.ItemDataRole.UserRole + 1    # channel id on DOF rows
PATH_ROLE = Qt.ItemDataRole.UserRole + 2   # (asset, joint) on every row
SEARCH_ROLE = Qt.ItemDataRole.UserRole + 3  # text the filter matches


class ChannelTree(QWidget):
    """Search field plus tree. Emits which channels are shown and which are selected."""

    #: Channel ids that are checked and pass the filter, in document order.
    visibleChanged = Signal(list)
    #: The user selected rows: (channel ids under them, asset, joint of the current row).
    selectionEdited = Signal(list, str, str)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.search = QLineEdit(self)
        self.search.setObjectName("curveChannelFilter")
        self.search.setPlaceholderText("Filter channels…")
        self.search.setClearButtonEnabled(True)
        self.model = QStandardItemModel(self)
        self.proxy = QSortFilterProxyModel(self)
        self.proxy.setSourceModel(self.model)
        self.proxy.setRecursiveFilteringEnabled(True)
        self.proxy.setFilterCaseSensitivity(Qt.CaseSensitivity.CaseInsensitive)
        self.proxy.setFilterRole(SEARCH_ROLE)
        self.view = QTreeView(self)
        self.view.setObjectName("curveChannelTree")
        self.view.setModel(self.proxy)
        self.view.setHeaderHidden(True)
        self.view.setSelectionMode(QAbstractItemView.SelectionMode.ExtendedSelection)
        self.view.setUniformRowHeights(True)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.search)
        layout.addWidget(self.view)

        self._cids: list[str] = []
        self._leaves: dict[str, QStandardItem] = {}
        self._groups: dict[tuple[str, str], QStandardItem] = {}
        self._updating = False
        self._syncing_selection = False
        self.model.itemChanged.connect(self._item_changed)
        self.search.textChanged.connect(self._filter_changed)
        self.view.selectionModel().selectionChanged.connect(self._selection_changed)

    # ---------------------------------------------------------------- content
    def channel_ids(self) -> list[str]:
        return list(self._cids)

    def set_channels(self, cids: Iterable[str]) -> None:
        """Rebuild the tree for these channel ids, keeping each id's check state."""
        cids = list(cids)
        if cids == self._cids:
            return
        hidden = {cid for cid, item in self._leaves.items() if item.checkState() == Qt.CheckState.Unchecked}
        first_build = not self._groups
        expanded = self.expanded_groups()
        known = set(self._groups)
        scroll = self.view.verticalScrollBar().value()
        self._updating = True
        try:
            self.model.clear()
            self._leaves.clear()
            self._groups.clear()
            for cid in cids:
                asset, joint, dof = split_channel_id(cid)
                parent = self._group(asset, "")
                if joint:
                    parent = self._group(asset, joint)
                leaf = QStandardItem(dof)
                leaf.setEditable(False)
                leaf.setCheckable(True)
                leaf.setCheckState(Qt.CheckState.Unchecked if cid in hidden else Qt.CheckState.Checked)
                leaf.setData(cid, CID_ROLE)
                leaf.setData((asset, joint), PATH_ROLE)
                leaf.setData(cid, SEARCH_ROLE)
                leaf.setData(channel_colour(cid), Qt.ItemDataRole.DecorationRole)
                leaf.setToolTip(cid)
                parent.appendRow(leaf)
                self._leaves[cid] = leaf
            for group in self._groups.values():
                self._update_parent(group)
        finally:
            self._updating = False
        self._cids = cids
        if first_build:
            self.view.expandToDepth(0)
        else:
            # Keep what the user opened; a new asset opens like the first time, new joints closed.
            for path, item in self._groups.items():
                if path in expanded or (path not in known and not path[1]):
                    self.view.expand(self.proxy.mapFromSource(item.index()))
            self.view.doItemsLayout()  # the scroll range follows the rows now, not at the next paint
            self.view.verticalScrollBar().setValue(scroll)
        self.visibleChanged.emit(self.visible_channels())

    def expanded_groups(self) -> set[tuple[str, str]]:
        """``(asset, joint)`` of the open group rows (``joint`` is ``""`` for an asset row)."""
        out = set()
        for path, item in self._groups.items():
            index = self.proxy.mapFromSource(item.index())
            if index.isValid() and self.view.isExpanded(index):
                out.add(path)
        return out

    def _group(self, asset: str, joint: str) -> QStandardItem:
        item = self._groups.get((asset, joint))
        if item is not None:
            return item
        item = QStandardItem(joint or asset)
        item.setEditable(False)
        item.setCheckable(True)
        item.setCheckState(Qt.CheckState.Checked)
        item.setData((asset, joint), PATH_ROLE)
        item.setData(f"{asset}/{joint}" if joint else asset, SEARCH_ROLE)
        if joint:
            self._group(asset, "").appendRow(item)
        else:
            self.model.appendRow(item)
        self._groups[(asset, joint)] = item
        return item

    # ------------------------------------------------------------- visibility
    def visible_channels(self) -> list[str]:
        """Checked channels that pass the filter."""
        out = []
        for cid in self._cids:
            leaf = self._leaves[cid]
            if leaf.checkState() != Qt.CheckState.Checked:
                continue
            if self.proxy.mapFromSource(leaf.index()).isValid():
                out.append(cid)
        return out

    def set_checked(self, cids: Iterable[str], checked: bool) -> None:
        state = Qt.CheckState.Checked if checked else Qt.CheckState.Unchecked
        for cid in cids:
            leaf = self._leaves.get(cid)
            if leaf is not None:
                leaf.setCheckState(state)

    def _item_changed(self, item: QStandardItem) -> None:
        if self._updating:
            return
        self._updating = True
        try:
            state = item.checkState()
            if item.hasChildren() and state != Qt.CheckState.PartiallyChecked:
                self._set_descendants(item, state)
            parent = item.parent()
            while parent is not None:
                self._update_parent(parent)
                parent = parent.parent()
        finally:
            self._updating = False
        self.visibleChanged.emit(self.visible_channels())

    def _set_descendants(self, item: QStandardItem, state: Qt.CheckState) -> None:
        for r in range(item.rowCount()):
            child = item.child(r)
            child.setCheckState(state)
            if child.hasChildren():
                self._set_descendants(child, state)

    def _update_parent(self, item: QStandardItem) -> None:
        for r in range(item.rowCount()):
            child = item.child(r)
            if child.hasChildren():
                self._update_parent(child)
        states = {item.child(r).checkState() for r in range(item.rowCount())}
        if len(states) == 1:
            item.setCheckState(states.pop())
        elif states:
            item.setCheckState(Qt.CheckState.PartiallyChecked)

    def _filter_changed(self, text: str) -> None:
        self.proxy.setFilterFixedString(text)
        self.view.expandAll() if text else self.view.expandToDepth(0)
        self.visibleChanged.emit(self.visible_channels())

    # -------------------------------------------------------------- selection
    def _leaves_under(self, item: QStandardItem) -> list[str]:
        cid = item.data(CID_ROLE)
        if cid:
            return [cid]
        out: list[str] = []
        for r in range(item.rowCount()):
            out += self._leaves_under(item.child(r))
        return out

    def selected_channels(self) -> list[str]:
        chosen: set[str] = set()
        for index in self.view.selectionModel().selectedIndexes():
            item = self.model.itemFromIndex(self.proxy.mapToSource(index))
            if item is not None:
                chosen.update(self._leaves_under(item))
        return [cid for cid in self._cids if cid in chosen]

    def _selection_changed(self, *_args: object) -> None:
        if self._syncing_selection:
            return
        current = self.view.currentIndex()
        asset, joint = "", ""
        if current.isValid():
            path = current.data(PATH_ROLE)
            if path:
                asset, joint = path
        self.selectionEdited.emit(self.selected_channels(), asset, joint)

    def show_selection(self, asset: str, joint: str, cids: Iterable[str] = ()) -> None:
        """Select rows from outside (the joint tree, another editor) without echoing back."""
        rows: list[QModelIndex] = []
        wanted = list(cids)
        if wanted:
            rows = [self._leaves[c].index() for c in wanted if c in self._leaves]
        elif asset:
            group = self._groups.get((asset, joint)) or self._groups.get((asset, ""))
            if group is not None:
                rows = [group.index()]
        self._syncing_selection = True
        try:
            selection = QItemSelection()
            for src in rows:
                index = self.proxy.mapFromSource(src)
                if index.isValid():
                    selection.select(index, index)
            flags = QItemSelectionModel.SelectionFlag.ClearAndSelect | QItemSelectionModel.SelectionFlag.Rows
            self.view.selectionModel().select(selection, flags)
            if rows:
                first = self.proxy.mapFromSource(rows[0])
                if first.isValid():
                    self.view.scrollTo(first)
        finally:
            self._syncing_selection = False
