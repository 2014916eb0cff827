"""The joint tree dock: every 2D character and 3D skeleton with its joints, and the DOF panel.

The tree follows ``ctx.selection`` and sets it; keyframed joints carry a key icon (filled
once the joint has keys), dynamic (pendulum) joints a white bob. Below the tree, the DOF
panel shows one slider and spin box per degree of freedom of the selected joint within
its limits (a 3D joint: its rotation as Euler angles in its rotation order, also when it is
keyed as a quaternion, and its translation and scale where it moves or scales); an edit
keys the DOF at the current frame, and one slider drag is one gesture
(``ctx.begin_gesture``): one undo step, and Escape during the drag puts the value back.

Drag a 2D joint onto another joint of the same character to re-parent it (one undo step,
:func:`qtanimator.document.rigging.reparent_command`); a drop that would make a joint hang
from itself is refused with a message in the status bar.

The parts: :mod:`qtanimator.ui.outliner_tree` (the tree), :mod:`qtanimator.ui.dof_panel`
(the sliders), :mod:`qtanimator.ui.dof_specs` (the DOFs as plain data, no Qt) and
:mod:`qtanimator.ui.outliner_icons`; this module is the dock that holds them.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtCore import Qt
from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import QVBoxLayout, QWidget

from qtanimator.document.document import DocumentChange
from qtanimator.ui.context import EditorContext
from qtanimator.ui.dof_panel import DofPanel, DofRow
from qtanimator.ui.dof_specs import (
    SLIDER_STEPS_PER_UNIT,
    TRANSLATION_LIMIT,
    DofSpec,
    dof_specs,
    joint_names,
    reset_pose_command,
)
from qtanimator.ui.key_routing import install_view_key_router
from qtanimator.ui.outliner_tree import (
    EYE_COLUMN,
    KIND_ROLE,
    LIGHT_PREFIX,
    LIGHT_TITLES,
    LOCK_COLUMN,
    NAME_COLUMN,
    ROLE,
    TOGGLE_WIDTH,
    JointTree,
)

if TYPE_CHECKING:
    from qtanimator.ui.main_window import MainWindow


class JointTreePanel(QWidget):
    def __init__(self, ctx: EditorContext, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("jointTreePanel")
        self.ctx = ctx
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        self.tree = JointTree(ctx, self)
        self.dofs = DofPanel(ctx, self)
        layout.addWidget(self.tree, 3)
        layout.addWidget(self.dofs, 1)
        self.dofs.prev_button.clicked.connect(lambda: self.tree.step_joint(-1))
        self.dofs.next_button.clicked.connect(lambda: self.tree.step_joint(1))
        self.dofs.reset_button.clicked.connect(self.reset_pose)
        ctx.selectionChanged.connect(self._selection_changed)
        ctx.documentChanged.connect(self._document_changed)
        ctx.documentReset.connect(self._reset)
        ctx.frameChanged.connect(lambda _f: self.dofs.refresh_values())
        self._reset()

    def _reset(self) -> None:
        self.tree.rebuild()
        self.dofs.rebuild()

    def _selection_changed(self, _asset: str, _joint: str) -> None:
        self.tree.follow_selection()
        self.dofs.rebuild()

    def _document_changed(self, change: DocumentChange) -> None:
        if change.assets:
            self.tree.rebuild()
            self.dofs.rebuild()
            return
        if change.channels:
            self.tree.refresh_icons(change.channel_assets())
        if any(p.endswith((".hidden", ".locked")) for p in change.parameters):
            self.tree.refresh_flags()  # a light's eye or lock
        if change.channels or change.parameters:
            self.dofs.refresh_values()

    def reset_pose(self) -> None:
        asset = self.ctx.selection[0]
        if not asset:
            return
        cmd = reset_pose_command(self.ctx.doc, asset, self.ctx.time)
        if cmd is not None:
            self.ctx.push(cmd)


def install(window: MainWindow) -> None:
    # A letter typed in the tree while the pointer is over a view is that view's key.
    install_view_key_router()
    panel = JointTreePanel(window.ctx)
    window.joint_tree = panel  # type: ignore[attr-defined]
    window.add_dock("jointTreeDock", "Outliner", panel, Qt.DockWidgetArea.LeftDockWidgetArea)
    reset = QAction("Reset Pose", window)
    reset.setObjectName("actionResetPose")
    reset.setShortcut(QKeySequence("R"))
    reset.setShortcutContext(Qt.ShortcutContext.WidgetWithChildrenShortcut)
    reset.triggered.connect(lambda _c=False: panel.reset_pose())
    panel.addAction(reset)
    window.reset_pose_action = reset  # type: ignore[attr-defined]
    view = window.findChild(QWidget, "rigEditorView")
    if view is not None:
        view.addAction(reset)



__all__ = ["EYE_COLUMN", "KIND_ROLE", "LIGHT_PREFIX", "LIGHT_TITLES", "LOCK_COLUMN", "NAME_COLUMN", "ROLE",
           "SLIDER_STEPS_PER_UNIT", "TOGGLE_WIDTH", "TRANSLATION_LIMIT", "DofPanel", "DofRow", "DofSpec",
           "JointTree", "JointTreePanel", "dof_specs", "install", "joint_names", "reset_pose_command"]
