"""The 3D viewport: skinned characters, skeletons and cloth under two coloured lights.

``install(window)`` adds a central tab "3D" holding a toolbar, the GL view (``viewport3d``:
a widget holding a QOpenGLWindow in a window container, or a QOpenGLWidget, see
:data:`DEFAULT_SURFACE`) and a bar below it with the clip a glTF character plays and the
playback controls.

Mouse: left click picks a joint (``ctx.select``); left drag orbits (on a live cloth it grabs
the cloth, on a light's sphere it moves the light); middle drag or Shift+left pans; wheel or
Ctrl+left zooms; Alt+left drag on a character moves its placement in the view plane through
its root, Alt+Shift+left scales it about the root (issue 14; one undo step each); right drag
on a skin moves the point under the cursor by IK (that point in
the frame of the joint influencing it most; on a joint's sphere or bone, with the skin hidden
or missed, the joint's pivot), one undo step, keyed at the current frame; right drag elsewhere
zooms. Keys: F frames the selection (or everything),
X shows the axes (the MIT viewer's ``a``), B the skeleton (its ``s``), W/A/S/D/Q/E move a live
cloth's pins (CSE169: W/S in y, A/D in x, Q/E in z), Z/C rotate them, P pauses the live cloth,
Shift+R resets it, R resets the selected character's pose, Escape cancels an IK, light or
placement drag. View ▸ 3D Camera… shows the camera's distance, azimuth and inclination as fields
(:mod:`qtanimator.ui.camera_fields`); the toolbar's *Shadow* draws the floor shadow.

Cloth never runs on the UI thread: a :class:`~qtanimator.document.cloth_worker.ClothWorker`
fills the document's cloth caches in the background (the view draws the newest frame there
and never waits), and the interactive cloth is a
:class:`~qtanimator.document.live_cloth.LiveCloths` stepping in real time on its own thread.
A timer polls both and repaints when something new is there.

The parts, one module per idea (every public name is importable from here):

- :mod:`~qtanimator.ui.view3d_surfaces`: the GL surfaces (window or widget);
- :mod:`~qtanimator.ui.view3d`: :class:`Viewport3D`, the GL view (drawing, preparing its
  context early, pictures for screenshots: :func:`grab_with_3d`);
- :mod:`~qtanimator.ui.view3d_camera`: camera navigation (orbit, pan, zoom, framing, the
  camera by numbers, ``view3d.camera``);
- :mod:`~qtanimator.ui.view3d_picking`: joints, skin points and lights under the cursor;
- :mod:`~qtanimator.ui.view3d_drags`: the mouse and the 3D drags (IK, light move,
  placement, cloth grab) through the gesture protocol;
- :mod:`~qtanimator.ui.view3d_cloth`: driving the cloth simulations;
- :mod:`~qtanimator.ui.view3d_keys`: the keys, set key, copy / paste / reset pose;
- :mod:`~qtanimator.ui.view3d_base`: what the view's mixins share;
- :mod:`~qtanimator.ui.clip_controls`: the clip picker and playback bar under the view;
- this module: the "3D" tab (:class:`ViewportPanel`, its display toolbar) and
  ``install(window)`` with the View menu actions.
"""

from __future__ import annotations

from typing import Any

from PySide6.QtCore import QEvent, QObject, Qt, QTimer
from PySide6.QtGui import QAction
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QHBoxLayout,
    QLabel,
    QSizePolicy,
    QSpinBox,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from qtanimator.document.live_cloth import LiveCloths
from qtanimator.render.gl.renderer import WEIGHTS_ALL, WEIGHTS_OFF, ClothDraw
from qtanimator.render.scene3d import joint_index
from qtanimator.ui.camera_fields import show_camera_dialog
from qtanimator.ui.clip_controls import ClipControls
from qtanimator.ui.context import EditorContext
from qtanimator.ui.key_routing import install_view_key_router
from qtanimator.ui.view3d import Viewport3D, grab_with_3d
from qtanimator.ui.view3d_camera import CAMERA_PARAMETER
from qtanimator.ui.view3d_cloth import PIN_KEYS, PIN_STEP, PIN_TURN, PIN_TURNS, SIM_DT
from qtanimator.ui.view3d_drags import ik_dofs
from qtanimator.ui.view3d_surfaces import DEFAULT_SURFACE, surface_kind


class ViewportPanel(QWidget):
    """The "3D" tab: display toolbar, GL view, clip picker and playback controls."""

    def __init__(self, ctx: EditorContext, parent: QWidget | None = None, window: Any = None) -> None:
        super().__init__(parent)
        self.setObjectName("viewportPanel")
        self.view = Viewport3D(ctx, self)
        self.controls = ClipControls(ctx, self, window)
        bar = QHBoxLayout()
        bar.setContentsMargins(4, 2, 4, 2)
        self.show_mode = QComboBox(self)
        self.show_mode.setObjectName("viewportShow")
        self.show_mode.addItems(["Skin and skeleton", "Skin only", "Skeleton only"])
        self.show_mode.currentIndexChanged.connect(self._on_show)
        self.shading = QComboBox(self)
        self.shading.setObjectName("viewportShading")
        self.shading.addItems(["Auto normals", "Faceted", "Smooth"])
        self.shading.currentIndexChanged.connect(self._on_shading)
        self.weights = QComboBox(self)
        self.weights.setObjectName("viewportWeights")
        self.weights.addItems(["No weights", "All joint weights", "Selected joint weight"])
        # As wide as the shown choice needs, not as the longest one: the bar fits the
        # default layout with room for the frame time.
        self.weights.setSizeAdjustPolicy(QComboBox.SizeAdjustPolicy.AdjustToMinimumContentsLengthWithIcon)
        self.weights.setMinimumContentsLength(10)
        self.weights.currentIndexChanged.connect(lambda _i: self._on_weights())
        ctx.selectionChanged.connect(lambda _a, _j: self._on_weights())
        self.wireframe = QCheckBox("Wireframe", self)
        self.wireframe.setObjectName("viewportWireframe")
        self.wireframe.toggled.connect(self._on_wireframe)
        self.grid = QCheckBox("Grid", self)
        self.grid.setObjectName("viewportGrid")
        self.grid.setChecked(True)
        self.grid.toggled.connect(self._on_grid)
        self.shadow = QCheckBox("Shadow", self)
        self.shadow.setObjectName("viewportShadow")
        self.shadow.setToolTip("Shadow on the floor (y = 0) from the brighter light")
        self.shadow.toggled.connect(lambda on: self.view.set_display(show_shadow=on))
        self.view.displayChanged.connect(self._sync_display)
        self.chain = QSpinBox(self)
        self.chain.setObjectName("viewportIkChain")
        self.chain.setRange(1, 20)
        self.chain.setValue(self.view.ik_chain_length)
        self.chain.setPrefix("IK chain ")
        self.chain.valueChanged.connect(lambda v: setattr(self.view, "ik_chain_length", int(v)))
        frame = QToolButton(self)
        frame.setObjectName("viewportFrame")
        frame.setText("Frame")
        frame.setToolTip("Frame the selection (F)")
        frame.clicked.connect(self.view.frame_selection)
        self.status = QLabel(self)
        self.status.setObjectName("viewportStatus")
        # The frame time changes every frame: its width must not resize the view (or the
        # window) while playing. Long error texts are cut here and shown whole as a tooltip.
        # The label takes the bar's free space (right-aligned) and asks for none.
        self.status.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Preferred)
        self.status.setAlignment(Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
        self.view.frameRendered.connect(self._on_frame_rendered)
        for w in (self.show_mode, self.shading, self.weights, self.wireframe, self.grid, self.shadow, self.chain,
                  frame):
            bar.addWidget(w)
        bar.addWidget(self.status, 1)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.setSpacing(0)
        layout.addLayout(bar)
        layout.addWidget(self.view, 1)
        layout.addWidget(self.controls)

    def _on_show(self, index: int) -> None:
        self.view.set_display(show_skin=index in (0, 1), show_skeleton=index in (0, 2))

    def _sync_display(self) -> None:
        """Show what the view shows (after B, the View menu or a field here)."""
        o = self.view.options
        index = 0 if o.show_skin and o.show_skeleton else (1 if o.show_skin else 2)
        for widget, set_value in ((self.show_mode, lambda: self.show_mode.setCurrentIndex(index)),
                                  (self.shadow, lambda: self.shadow.setChecked(o.show_shadow))):
            blocked = widget.blockSignals(True)
            try:
                set_value()
            finally:
                widget.blockSignals(blocked)

    def _on_shading(self, index: int) -> None:
        self.view.options.faceted = (None, True, False)[index]
        self.view.update()

    def _on_weights(self) -> None:
        index = self.weights.currentIndex()
        mode = WEIGHTS_OFF
        if index == 1:
            mode = WEIGHTS_ALL
        elif index == 2:
            asset, joint = self.view.ctx.selection
            mode = WEIGHTS_OFF
            if asset and joint:
                skel = getattr(self.view.ctx.doc.runtime.get(asset), "skeleton", None)
                if skel is not None:
                    try:
                        mode = joint_index(skel, joint)
                    except (KeyError, ValueError):
                        mode = WEIGHTS_OFF
        self.view.options.weight_mode = mode
        self.view.options.weight_asset = self.view.ctx.selection[0] if index == 2 else None
        self.view.update()

    def _on_wireframe(self, on: bool) -> None:
        self.view.options.wireframe = on
        self.view.update()

    def _on_grid(self, on: bool) -> None:
        self.view.options.show_grid = on
        self.view.update()

    def _on_frame_rendered(self, ms: float) -> None:
        text = f"{ms:.1f} ms"
        if self.view.cloth_stale:
            text = f"cloth still simulating (an earlier frame is shown)  ·  {text}"
        if self.view.last_error:
            text = f"{self.view.last_error}  ·  {text}"
        self.status.setText(text)
        self.status.setToolTip(text)


#: Milliseconds after the main window first shows before the hidden 3D view prepares its GL
#: context (see :meth:`Viewport3D.prepare_gl`): after start-up work, before a user's click.
PREPARE_DELAY_MS = 250


class _PrepareOnShow(QObject):
    """Starts ``view.prepare_gl`` once, shortly after the main window is first shown."""

    def __init__(self, window: QWidget, view: Viewport3D) -> None:
        super().__init__(window)
        self.view = view
        window.installEventFilter(self)

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if event.type() == QEvent.Type.Show:
            watched.removeEventFilter(self)
            QTimer.singleShot(PREPARE_DELAY_MS, self.view, self.view.prepare_gl)
        return False


def install(window: Any) -> None:
    # A letter typed in a tree while the pointer is over the 3D view is the view's key.
    install_view_key_router()
    panel = ViewportPanel(window.ctx, window, window)
    _PrepareOnShow(window, panel.view)
    window.viewport_panel = panel
    window.viewport3d = panel.view
    window.save_hooks.append(panel.view.store_camera)
    window.add_central(panel, "3D")
    frame = window._action("actionFrameSelection3d", "Frame Selection (3D)", panel.view.frame_selection)
    window.view_menu.addAction(frame)
    _install_display_actions(window, panel.view)


def _install_display_actions(window: Any, view: Viewport3D) -> None:
    """View menu: the camera fields and the display toggles of the 3D view. The keys are the
    view's own (X, B: see its keyPressEvent), shown in the menu as hints only, so that X and B
    keep their meaning in the other editors."""
    camera = window._action("actionCamera3d", "3D Camera…", lambda: show_camera_dialog(window, view))
    camera.setStatusTip("Distance, azimuth and inclination of the 3D view's camera as fields")
    toggles = (
        ("actionShowAxes3d", "Show Axes (3D)\tX", "show_axes", lambda on: view.set_display(show_axes=on)),
        ("actionShowSkeleton3d", "Show Skeleton (3D)\tB", "show_skeleton",
         lambda on: view.set_display(show_skeleton=on) if on or view.options.show_skin
         else view.set_display(show_skeleton=False, show_skin=True)),
        ("actionFloorShadow3d", "Floor Shadow (3D)", "show_shadow", lambda on: view.set_display(show_shadow=on)),
    )
    actions: list[tuple[QAction, str]] = []
    window.view_menu.addAction(camera)
    for name, text, option, slot in toggles:
        action = QAction(text, window)
        action.setObjectName(name)
        action.setCheckable(True)
        action.setChecked(bool(getattr(view.options, option)))
        action.triggered.connect(slot)
        window.view_menu.addAction(action)
        actions.append((action, option))

    def sync() -> None:
        for action, option in actions:
            blocked = action.blockSignals(True)
            action.setChecked(bool(getattr(view.options, option)))
            action.blockSignals(blocked)

    view.displayChanged.connect(sync)
    window.action_camera3d = camera


__all__ = [
    "CAMERA_PARAMETER",
    "DEFAULT_SURFACE",
    "PIN_KEYS",
    "PIN_STEP",
    "PIN_TURN",
    "PIN_TURNS",
    "PREPARE_DELAY_MS",
    "SIM_DT",
    "ClipControls",
    "ClothDraw",
    "LiveCloths",
    "Viewport3D",
    "ViewportPanel",
    "grab_with_3d",
    "ik_dofs",
    "install",
    "surface_kind",
]
