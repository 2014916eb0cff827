"""The properties dock: the selected joint (with its limits) and character, pendulum parameters, IK settings.

Everything editable is a document parameter changed through a command (SetParameter, or
``character2d.set_pendulum_preset`` for a preset), or an asset property changed through its
own command (a BVH character's position convention, the clip a glTF character plays, the
collision radius of a 3D character's bone that attached cloth collides with), so it
is undoable and saved with the project. Read-only facts (mass, inertia, pivot…) are shown as labels.

This module holds the dock, its selection handling and refresh; each group is built by its
own module through a :class:`~qtanimator.ui.properties_form.PanelForm`:
``properties_joint`` (a 2D joint and character), ``properties_joint3d`` (a 3D joint or
skeleton), ``properties_sim`` (IK, pendulums, springs), ``properties_placement``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QLabel, QScrollArea, QVBoxLayout, QWidget

from qtanimator.document import character2d, character3d
from qtanimator.document.character2d import ik_setting
from qtanimator.document.document import DocumentChange
from qtanimator.ui.context import EditorContext
from qtanimator.ui.properties_form import PanelForm
from qtanimator.ui.properties_joint import JOINT_MODE_LABELS, LIMIT_RANGE_DEGREES, character2d_group, joint2d_group
from qtanimator.ui.properties_joint3d import joint3d_group
from qtanimator.ui.properties_placement import placement_group
from qtanimator.ui.properties_sim import ik_group, pendulum_group, spring_group
from qtanimator.ui.widgets import wrap_long_rows

if TYPE_CHECKING:
    from qtanimator.ui.main_window import MainWindow


class PropertiesPanel(QWidget):
    """A form rebuilt when the selection changes; values refresh on document events."""

    def __init__(self, ctx: EditorContext, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("propertiesPanel")
        self.ctx = ctx
        outer = QVBoxLayout(self)
        outer.setContentsMargins(0, 0, 0, 0)
        self.scroll_area = QScrollArea(self)
        self.scroll_area.setWidgetResizable(True)
        outer.addWidget(self.scroll_area)
        self.body: QWidget | None = None
        self._simulation_refreshers: list[Callable[[], None]] = []
        self._refreshers: list[Callable[[], None]] = []
        self.editors: dict[str, QWidget] = {}
        ctx.selectionChanged.connect(lambda _a, _j: self.rebuild())
        ctx.documentReset.connect(self.rebuild)
        ctx.documentChanged.connect(self._on_document)
        ctx.frameChanged.connect(lambda _f: self.refresh())
        ctx.simulationProgressed.connect(self._simulation_progressed)
        self.rebuild()

    # ------------------------------------------------------------ structure
    def _on_document(self, change: DocumentChange) -> None:
        if change.assets:
            self.rebuild()
        elif self._shows_changed(change):
            self.refresh()

    def _shows_changed(self, change: DocumentChange) -> bool:
        """True when the change touches what the dock shows: the selected asset's channels
        or any parameter (IK, pendulum and project settings are shown for every selection)."""
        if change.parameters:
            return True
        asset = self.ctx.selection[0]
        return bool(asset) and asset in change.channel_assets()

    def _simulation_progressed(self) -> None:
        for fn in self._simulation_refreshers:
            fn()

    def refresh(self) -> None:
        for fn in self._refreshers:
            fn()

    def rebuild(self) -> None:
        panel = PanelForm(self.ctx, self, self.rebuild, self.refresh)
        self._refreshers = panel.refreshers
        self._simulation_refreshers = panel.simulation_refreshers
        self.editors = panel.editors
        body = QWidget()
        layout = QVBoxLayout(body)
        asset, joint = self.ctx.selection
        doc = self.ctx.doc
        kind = doc.assets[asset].kind if asset in doc.assets else ""
        if kind == character2d.ASSET_KIND and asset in doc.runtime:
            if joint:
                layout.addWidget(joint2d_group(panel, asset, joint))
            layout.addWidget(character2d_group(panel, asset))
            if bool(doc.runtime[asset].simulated.any()):
                layout.addWidget(pendulum_group(panel, asset))
            if bool(doc.runtime[asset].spring.any()):
                layout.addWidget(spring_group(panel, asset))
            layout.addWidget(placement_group(panel, asset, 2))
        elif kind == character3d.ASSET_KIND and asset in doc.runtime:
            layout.addWidget(joint3d_group(panel, asset, joint))
            layout.addWidget(placement_group(panel, asset, 3))
        elif not asset:
            label = QLabel("Select a joint or a character.")
            label.setObjectName("propertiesHint")
            layout.addWidget(label)
        layout.addWidget(ik_group(panel))
        layout.addStretch(1)
        wrap_long_rows(body)
        self.scroll_area.setWidget(body)  # deletes the previous body
        self.body = body
        self.refresh()


def install(window: MainWindow) -> None:
    panel = PropertiesPanel(window.ctx)
    window.properties_panel = panel  # type: ignore[attr-defined]
    window.add_dock("propertiesDock", "Properties", panel, Qt.DockWidgetArea.RightDockWidgetArea)


__all__ = ["JOINT_MODE_LABELS", "LIMIT_RANGE_DEGREES", "PropertiesPanel", "install", "ik_setting"]
