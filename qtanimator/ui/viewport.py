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
:class:`~qtanimator.document.cloth_worker.LiveCloths` stepping in real time on its own thread.
A timer polls both and repaints when something new is there.
"""

from __future__ import annotations

import dataclasses
import math
import time as _time
from typing import Any

import numpy as np
from PySide6.QtCore import QElapsedTimer, QEvent, QObject, QPointF, Qt, QTimer, Signal
from PySide6.QtGui import QImage, QKeyEvent, QMouseEvent, QPixmap, QSurfaceFormat, QWheelEvent
from PySide6.QtOpenGL import QOpenGLWindow
from PySide6.QtOpenGLWidgets import QOpenGLWidget
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDoubleSpinBox,
    QHBoxLayout,
    QLabel,
    QProgressBar,
    QSizePolicy,
    QSpinBox,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from qtanimator.document.cloth_worker import LiveCloths, cloth_worker
from qtanimator.document.document import DocumentChange
from qtanimator.document.outliner import is_locked, pickable
from qtanimator.render.gl import surface_format, view_samples
from qtanimator.render.gl.camera import OrbitCamera
from qtanimator.render.gl.lights import LIGHT_NAMES, ambient_of, lights_of
from qtanimator.render.gl.picking import pick_joint, ray_sphere
from qtanimator.render.gl.renderer import (
    WEIGHTS_ALL,
    WEIGHTS_OFF,
    CharacterDraw,
    ClothDraw,
    SceneItem,
    SceneRenderer,
    ViewOptions,
    grid_scale_for,
)
from qtanimator.render.scene3d import scene_bounds, scene_items
from qtanimator.ui.clip_picker import ClipPicker
from qtanimator.ui.context import EditorContext

#: Cloth pin moves per key press: metres and radians.
PIN_STEP = 0.05
PIN_TURN = math.radians(5.0)
PIN_KEYS = {
    # As the CSE169 cloth project: W/S up/down (y), A/D left/right (x), Q/E in/out (z).
    Qt.Key.Key_W: (0.0, PIN_STEP, 0.0), Qt.Key.Key_S: (0.0, -PIN_STEP, 0.0),
    Qt.Key.Key_A: (-PIN_STEP, 0.0, 0.0), Qt.Key.Key_D: (PIN_STEP, 0.0, 0.0),
    Qt.Key.Key_Q: (0.0, 0.0, -PIN_STEP), Qt.Key.Key_E: (0.0, 0.0, PIN_STEP),
}
PIN_TURNS = {Qt.Key.Key_Z: PIN_TURN, Qt.Key.Key_C: -PIN_TURN}
#: The live cloth's fixed simulation step (seconds).
SIM_DT = 1.0 / 60.0

#: How the GL picture reaches the screen: "window" (a QOpenGLWindow in a window container:
#: the window system shows it, the main window is not composed through OpenGL) or "widget"
#: (a QOpenGLWidget: Qt composes the whole main window with OpenGL every frame). See
#: docs/decisions.md; the environment variable ``QTANIMATOR_VIEW3D_SURFACE`` overrides it.
DEFAULT_SURFACE = "window"


def surface_kind() -> str:
    """The GL surface kind to use ("window" or "widget")."""
    import os

    kind = os.environ.get("QTANIMATOR_VIEW3D_SURFACE", DEFAULT_SURFACE).strip().lower()
    return kind if kind in ("window", "widget") else DEFAULT_SURFACE


class _GLWidgetSurface(QOpenGLWidget):
    """The GL surface as a QOpenGLWidget child of the view (input goes to the view)."""

    def __init__(self, view: Viewport3D) -> None:
        super().__init__(view)
        self.view = view
        self.setFormat(surface_format(view_samples()))
        self.setAttribute(Qt.WidgetAttribute.WA_TransparentForMouseEvents, True)
        self.setFocusPolicy(Qt.FocusPolicy.NoFocus)

    def initializeGL(self) -> None:
        self.view.initialize_gl()

    def paintGL(self) -> None:
        self.view.paint_gl()


class _GLWindowSurface(QOpenGLWindow):
    """The GL surface as a QOpenGLWindow shown in a window container: the window system
    shows its pixels, so the main window is not composed through OpenGL. Input that the
    native window receives is handed to the view."""

    def __init__(self, view: Viewport3D) -> None:
        super().__init__(QOpenGLWindow.UpdateBehavior.NoPartialUpdate)
        self.view = view
        self.setFormat(surface_format(view_samples()))

    def initializeGL(self) -> None:
        self.view.initialize_gl()

    def paintGL(self) -> None:
        self.view.paint_gl()

    def mousePressEvent(self, event: QMouseEvent) -> None:
        self.view.setFocus(Qt.FocusReason.MouseFocusReason)
        self.view.mousePressEvent(event)

    def mouseMoveEvent(self, event: QMouseEvent) -> None:
        self.view.mouseMoveEvent(event)

    def mouseReleaseEvent(self, event: QMouseEvent) -> None:
        self.view.mouseReleaseEvent(event)

    def wheelEvent(self, event: QWheelEvent) -> None:
        self.view.wheelEvent(event)

    def keyPressEvent(self, event: QKeyEvent) -> None:
        self.view.keyPressEvent(event)


#: The document parameter holding the 3D camera (view state, written when saving).
CAMERA_PARAMETER = "view3d.camera"


def ik_dofs(skeleton: Any, joint: int, chain_length: int, surface: bool = False) -> list[tuple[int, int]]:
    """The DOFs a right-drag on ``joint`` solves over: its ``chain_length`` nearest
    ancestors without the root; when those have no free DOF (a joint whose only ancestor
    is the root, like the demo arm's elbow) the root's rotation is used, so the drag moves
    something instead of nothing. A drag on a point of the skin (``surface``: the effector
    is off the joint's pivot) moves ``chain_length`` joints counting the joint itself,
    whose own rotation now moves the point (the root's only when the root is clicked)."""
    from qtanimator.core.ik3d import chain_dofs

    if surface:
        own = [(joint, a) for a, d in enumerate(skeleton.joints[joint].dofs) if d.max - d.min > 1e-12]
        if skeleton.joints[joint].parent is None:
            return own
        return own + chain_dofs(skeleton, joint, max(chain_length - 1, 0))
    dofs = chain_dofs(skeleton, joint, chain_length)
    return dofs or chain_dofs(skeleton, joint, chain_length, include_root=True)


class Viewport3D(QWidget):
    """The GL view of the 3D scene (object name ``viewport3d``): camera, picking, gestures
    and live cloth; the pixels come from a GL surface filling it (``surface``: a
    QOpenGLWindow in a window container by default, or a QOpenGLWidget, see
    :data:`DEFAULT_SURFACE`). Mouse and key events reach this widget either way."""

    #: CPU milliseconds the last paintGL took (scene build + GL calls).
    frameRendered = Signal(float)
    #: The interactive cloth simulation was switched on or off.
    liveClothChanged = Signal(bool)
    #: The cloth cache worker moved on: a list of ClothProgress (at most ~10 per second).
    clothProgressChanged = Signal(object)
    #: The camera's distance, azimuth, inclination or target changed (mouse, fields, framing).
    cameraChanged = Signal()
    #: What the view shows changed (:meth:`set_display`: skin, skeleton, axes, shadow).
    displayChanged = Signal()

    #: How often the simulations are polled while they run (ms).
    POLL_MS = 16
    #: How often the progress is announced while the worker runs (ms).
    PROGRESS_MS = 100

    def __init__(self, ctx: EditorContext, parent: QWidget | None = None, surface: str | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("viewport3d")
        self.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        self.setMinimumSize(160, 120)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        #: "window" or "widget": how the picture reaches the screen.
        self.surface_kind = surface or surface_kind()
        self.gl: _GLWindowSurface | _GLWidgetSurface
        if self.surface_kind == "window":
            self.gl = _GLWindowSurface(self)
            # The container deletes its window, but PySide counts a window made in Python
            # as Python's: at exit PySide would delete it before the container, which then
            # touches a dangling pointer (a crash in QApplication's destructor). A QObject
            # parent first hands it to C++; the container then reparents it as it needs.
            QObject.setParent(self.gl, self)
            container = QWidget.createWindowContainer(self.gl, self)
            container.setObjectName("viewport3dSurface")
            container.setFocusPolicy(Qt.FocusPolicy.NoFocus)
            container.setMinimumSize(1, 1)
            layout.addWidget(container)
            self.surface_widget: QWidget = container
        else:
            self.gl = _GLWidgetSurface(self)
            self.gl.setObjectName("viewport3dSurface")
            layout.addWidget(self.gl)
            self.surface_widget = self.gl
        self.ctx = ctx
        self.camera = OrbitCamera()
        self.options = ViewOptions()
        self.renderer = SceneRenderer()
        #: The interactive cloths (stepped on their own thread while enabled).
        self.live = LiveCloths(SIM_DT)
        #: Fills the document's cloth caches on a background thread (``doc.caches["cloths"]``).
        self.cloth_worker = cloth_worker(ctx.doc)
        self.ik_chain_length = 3
        self.last_error = ""
        self.last_frame_ms = 0.0
        self.gl_info = ""
        self.cloth_stale = False    # the last paint showed an earlier cloth frame (still simulating)
        self._items: list[SceneItem] = []
        self._offscreen: tuple[Any, SceneRenderer] | None = None   # render_image before the first show
        self._framed_once = False   # the camera frames the scene at the first paint with items
        self._grid_pending = False  # a restored camera: size the grid at the first paint
        self._drag: dict[str, Any] | None = None
        self._press_pos = QPointF()
        self._camera_seen: tuple[float, ...] = ()   # what cameraChanged last announced
        self._prepare_state = ""    # prepare_gl: "", "context", "resources", "picture", "done"
        self._defer_renderer = False
        ctx.frameChanged.connect(lambda _f: self.update())
        ctx.selectionChanged.connect(lambda _a, _j: self.update())
        ctx.documentChanged.connect(self._on_document_changed)
        ctx.documentReset.connect(self._on_document_reset)
        self._seen_live = -1
        self._seen_worker = -1
        self._progress_clock = QElapsedTimer()
        self._progress_clock.start()
        self._was_busy = False
        self._sim_timer = QTimer(self)
        self._sim_timer.setInterval(self.POLL_MS)
        self._sim_timer.timeout.connect(self._poll_simulations)
        self._sim_timer.start()
        worker, live = self.cloth_worker, self.live
        # The threads stop with the view (the cache worker starts again when asked).
        self.destroyed.connect(lambda *_a: (worker.shutdown(1.0), live.close(1.0)))
        self.restore_camera()

    # ------------------------------------------------------------ document
    def _on_document_changed(self, change: DocumentChange) -> None:
        if self.live.enabled and (change.assets or change.parameters):
            self.live.sync(self.ctx.doc)
        self.watch_simulations()
        self.update()

    def _on_document_reset(self) -> None:
        self.live.clear()
        if self.live.enabled:
            self.live.sync(self.ctx.doc)
        self.watch_simulations()
        self.restore_camera()
        self.update()

    def set_live_cloth(self, enabled: bool) -> None:
        changed = enabled != self.live.enabled
        self.live.enabled = enabled
        if enabled:
            self.live.sync(self.ctx.doc)
        self.watch_simulations()
        if changed:
            self.liveClothChanged.emit(enabled)
        self.update()

    def watch_simulations(self) -> None:
        """Poll the cloth threads (until they have nothing new to show)."""
        if not self._sim_timer.isActive():
            self._sim_timer.start()

    def _poll_simulations(self) -> None:
        """Repaint when a simulation thread has something new; announce the progress."""
        live, worker = self.live, self.cloth_worker
        if live.enabled and live.version != self._seen_live:
            self._seen_live = live.version
            self.update()
        busy = worker.busy
        live_errors = tuple(sorted(live.errors.items()))
        if live_errors != getattr(self, "_seen_live_errors", ()):
            self._seen_live_errors = live_errors   # a live cloth blew up: the Cloth dock says why
            self.clothProgressChanged.emit(worker.progress())
        if worker.version != self._seen_worker:
            self._seen_worker = worker.version
            if self.cloth_stale:
                self.update()
            if busy != self._was_busy or self._progress_clock.elapsed() >= self.PROGRESS_MS:
                self._progress_clock.restart()
                self.clothProgressChanged.emit(worker.progress())
        elif busy != self._was_busy:
            self.clothProgressChanged.emit(worker.progress())
        self._was_busy = busy
        if not busy and not live.enabled:
            self._sim_timer.stop()

    # ----------------------------------------------------------------- GL
    def update(self) -> None:  # type: ignore[override]
        """Ask for a new picture (drawn at the next frame). A hidden GL window is not asked:
        it paints when it is exposed, and a request left pending would make a second
        picture right after that one."""
        if self.surface_kind == "window" and not self.gl.isExposed():
            return
        self.gl.update()

    def format(self) -> QSurfaceFormat:
        """The GL surface's format (OpenGL 3.3 core, depth, multisampling)."""
        return self.gl.format()

    # ------------------------------------------------------- preparing early
    #: Platforms whose GL windows can be prepared before they are shown.
    PREPARE_PLATFORMS = ("xcb", "wayland", "eglfs", "windows", "cocoa")

    def prepare_gl(self) -> bool:
        """Create the GL context and resources and draw one picture while the view is still
        hidden (another tab is current), in three steps of one event-loop turn each, so that
        opening the "3D" tab later only shows a picture. On llvmpipe the context costs about
        45 ms, the programs and meshes 10 ms and the first picture (shader variants compiled
        at the first draw) 10–40 ms: together they stalled the tab's first opening.

        Starts nothing when the view is already shown or prepared, for a QOpenGLWidget
        surface (Qt makes its context only when shown), or on a platform without real
        windows. True when the steps were started."""
        from PySide6.QtGui import QGuiApplication

        if (self.surface_kind != "window" or self._prepare_state != "" or self.gl.isExposed()
                or QGuiApplication.platformName() not in self.PREPARE_PLATFORMS):
            return False
        self._prepare_state = "context"
        QTimer.singleShot(0, self, self._prepare_step)  # dropped if the view goes
        return True

    def _prepare_step(self) -> None:
        from PySide6.QtCore import QSize
        from PySide6.QtGui import QResizeEvent

        state = self._prepare_state
        gl = self.gl
        if gl.isExposed() or not isinstance(gl, _GLWindowSurface) or state in ("", "done"):
            self._prepare_state = "done"  # shown meanwhile: Qt does the rest as usual
            return
        size = self.surface_widget.size()
        w, h = max(size.width(), 1), max(size.height(), 1)
        if state == "context":
            gl.create()
            gl.resize(w, h)
            # QOpenGLWindow makes its context (and calls initializeGL) in its resize event.
            self._defer_renderer = True
            try:
                QOpenGLWindow.resizeEvent(gl, QResizeEvent(QSize(w, h), QSize()))
            finally:
                self._defer_renderer = False
            self._prepare_state = "resources" if gl.context() is not None else "done"
        elif state == "resources":
            gl.makeCurrent()
            if not self.renderer.initialized:
                self.renderer.initialize()
            gl.doneCurrent()
            self._prepare_state = "picture"
        elif state == "picture":
            gl.makeCurrent()
            ratio = gl.devicePixelRatio()
            # Into the hidden window's back buffer (never swapped): compiles what the first
            # visible picture would, and sizes the camera to the scene.
            self._draw(self.renderer, max(1, int(w * ratio)), max(1, int(h * ratio)))
            gl.doneCurrent()
            self._prepare_state = "done"
        if self._prepare_state != "done":
            QTimer.singleShot(0, self, self._prepare_step)  # dropped if the view goes

    def initialize_gl(self) -> None:
        """The surface's initializeGL: its context is current."""
        from OpenGL import GL

        version = GL.glGetString(GL.GL_VERSION)
        renderer = GL.glGetString(GL.GL_RENDERER)
        self.gl_info = f"{version.decode() if version else '?'} / {renderer.decode() if renderer else '?'}"
        if not self._defer_renderer:  # prepare_gl makes the programs and meshes in a later step
            self.renderer.initialize()
        context = self.gl.context()
        if context is not None:
            context.aboutToBeDestroyed.connect(self._release_gl)

    def _release_gl(self) -> None:
        try:
            self.gl.makeCurrent()
        except RuntimeError:
            return  # the surface is being deleted: its context (not shared) takes the resources along
        self.renderer.release()
        self.gl.doneCurrent()

    def build_items(self) -> list[SceneItem]:
        """What to draw now (and pick against). Never simulates: a cloth shows the newest
        frame its cache has (the worker is asked for the one missing) or its live snapshot."""
        override = self.live.frames() if self.live.enabled else None
        errors: list[str] = []   # an asset that fails is left out; the others still draw
        items = scene_items(self.ctx.doc, self.ctx.time, self.ctx.selection, override, errors, wait=False)
        self.last_error = "; ".join(errors)
        stale = [i for i in items if isinstance(i, ClothDraw) and i.stale]
        for item in stale:
            self.cloth_worker.request(item.asset_id, self.ctx.frame)
        self.cloth_stale = bool(stale)
        if stale:
            self.watch_simulations()
        return items

    def paint_gl(self) -> None:
        """The surface's paintGL: build the scene and draw it."""
        ratio = self.gl.devicePixelRatio()
        self._draw(self.renderer, max(1, int(self.gl.width() * ratio)), max(1, int(self.gl.height() * ratio)))

    def _draw(self, renderer: SceneRenderer, w: int, h: int) -> None:
        start = _time.perf_counter()
        self._items = self.build_items()
        if not self._framed_once and self._items:
            self.frame_all()
            self._framed_once = True
        elif self._grid_pending and self._items:
            bounds = scene_bounds(self._items)
            if bounds is not None:
                self.options.grid_scale = grid_scale_for(*bounds)
            self._grid_pending = False
        self._camera_moved()
        doc = self.ctx.doc
        self.options.light_gizmo_size = self.gizmo_size()
        renderer.render(self._items, self.camera, w, h, lights_of(doc), ambient_of(doc), self.options)
        self.last_frame_ms = (_time.perf_counter() - start) * 1000.0
        self.frameRendered.emit(self.last_frame_ms)

    def render_image(self) -> np.ndarray:
        """The current picture as an H×W×4 RGBA uint8 array (renders a frame).

        A GL window that has not been shown yet (another tab is current) has no context:
        the picture is then drawn by the same renderer into an offscreen framebuffer."""
        from qtanimator.render.painter2d import image_to_array

        if isinstance(self.gl, _GLWindowSurface):
            if not self.gl.isValid():
                return self._render_offscreen()
            # QOpenGLWindow.grabFramebuffer reads what is in the back buffer: draw it first.
            from OpenGL import GL

            self.gl.makeCurrent()
            self.paint_gl()
            GL.glFinish()
        return image_to_array(self.gl.grabFramebuffer().convertToFormat(QImage.Format.Format_RGBA8888))

    def _render_offscreen(self) -> np.ndarray:
        from qtanimator.render.render3d import OffscreenGL

        ratio = self.devicePixelRatioF()
        size = (max(1, int(self.width() * ratio)), max(1, int(self.height() * ratio)))
        if self._offscreen is None:
            gl = OffscreenGL(size)
            renderer = SceneRenderer()
            renderer.initialize()
            self._offscreen = (gl, renderer)
        gl, renderer = self._offscreen
        gl.make_current()
        if gl.size != size:
            gl.resize(size)
        gl.bind()
        self._draw(renderer, *size)
        from OpenGL import GL

        GL.glFinish()
        return gl.read()

    # ------------------------------------------------------------- camera
    def restore_camera(self) -> bool:
        """Take the camera stored in the document (``view3d.camera``); without one (or with
        an unreadable one) the view frames the scene at its next paint. True if restored."""
        stored = self.ctx.doc.view_state.get(CAMERA_PARAMETER)
        camera = OrbitCamera()
        try:
            if not isinstance(stored, dict):
                raise ValueError("no stored camera")
            camera.azimuth = float(stored.get("azimuth", camera.azimuth))
            camera.inclination = float(stored.get("inclination", camera.inclination))
            camera.distance = float(stored.get("distance", camera.distance))
            camera.fov_y = float(stored.get("fov_y", camera.fov_y))
            target = np.asarray(stored.get("target", [0.0, 0.0, 0.0]), dtype=float)
            if target.shape != (3,) or not np.all(np.isfinite(target)) or not all(
                    math.isfinite(v) for v in (camera.azimuth, camera.inclination, camera.distance, camera.fov_y)):
                raise ValueError("bad stored camera")
            camera.target = target
        except (TypeError, ValueError):
            self._framed_once = False
            self._grid_pending = False
            return False
        self.camera = camera
        self._framed_once = True
        self._grid_pending = True
        self._camera_moved()
        return True

    def _camera_moved(self) -> None:
        """Announce ``cameraChanged`` when the camera differs from what was last announced."""
        c = self.camera
        now = (float(c.distance), float(c.azimuth), float(c.inclination),
               *(float(v) for v in np.asarray(c.target, dtype=float)))
        if now != self._camera_seen:
            self._camera_seen = now
            self.cameraChanged.emit()

    def set_camera(self, distance: float | None = None, azimuth: float | None = None,
                   inclination: float | None = None) -> None:
        """Place the orbit camera by numbers (the camera fields; CSE169's distance, azimuth and
        inclination in degrees) about its target. View state, like a mouse orbit: no undo step."""
        c = self.camera
        if distance is not None and math.isfinite(distance):
            c.distance = float(np.clip(distance, 1e-3, 1e5))
        if azimuth is not None and math.isfinite(azimuth):
            c.azimuth = float(azimuth) % 360.0
        if inclination is not None and math.isfinite(inclination):
            c.inclination = float(np.clip(inclination, -89.0, 89.0))
        self._framed_once = True   # a camera placed by hand is kept (and saved), not framed over
        self._camera_moved()
        self.update()

    # ------------------------------------------------------------ display
    def set_display(self, **changes: Any) -> None:
        """Change what the view shows (fields of :class:`ViewOptions`), tell the toolbar and
        the View menu (``displayChanged``) and repaint."""
        for name, value in changes.items():
            if not hasattr(self.options, name):
                raise AttributeError(f"ViewOptions has no {name!r}")
            setattr(self.options, name, value)
        self.displayChanged.emit()
        self.update()

    def toggle_skeleton(self) -> None:
        """B (the MIT viewer's ``s``): show or hide the skeleton; hiding it shows the skin."""
        if self.options.show_skeleton:
            self.set_display(show_skeleton=False, show_skin=True)
        else:
            self.set_display(show_skeleton=True)

    def camera_state(self) -> dict[str, Any]:
        """The camera as plain JSON data (what ``view3d.camera`` holds)."""
        c = self.camera
        return {"azimuth": float(c.azimuth), "inclination": float(c.inclination), "distance": float(c.distance),
                "target": [float(v) for v in np.asarray(c.target, dtype=float)], "fov_y": float(c.fov_y)}

    def store_camera(self) -> None:
        """Save hook: remember the camera in the document's view state (``view3d.camera``).

        Camera moves are view state, not edits: no command, no undo step, the document is
        not marked modified. Only a camera that has framed or shown a scene is stored; an
        untouched document keeps what it had.
        """
        if self._framed_once:
            self.ctx.doc.set_view_state(CAMERA_PARAMETER, self.camera_state())

    def frame_bounds(self, bounds: tuple[np.ndarray, np.ndarray]) -> None:
        """Point the camera at a box (a new 3D asset frames itself this way)."""
        self.camera.frame(*bounds)
        self.options.grid_scale = grid_scale_for(*bounds)
        self._framed_once = True
        self._grid_pending = False
        self._camera_moved()
        self.update()

    def frame_all(self) -> None:
        items = self._items or self.build_items()
        bounds = scene_bounds(items)
        if bounds is not None:
            self.camera.frame(*bounds)
            self.options.grid_scale = grid_scale_for(*bounds)
        self._camera_moved()
        self.update()

    def frame_selection(self) -> None:
        """Frame the selected joint's character (or everything)."""
        asset, joint = self.ctx.selection
        items = self._items or self.build_items()
        chosen = [i for i in items if getattr(i, "asset_id", None) == asset] if asset else []
        bounds = scene_bounds(chosen or items)
        if bounds is not None:
            self.camera.frame(*bounds)
            if joint:
                for item in chosen:
                    if isinstance(item, CharacterDraw) and item.selected is not None:
                        self.camera.target = item.world[item.selected, :3, 3].copy()
        self._camera_moved()
        self.update()

    def ray_at(self, pos: QPointF) -> tuple[np.ndarray, np.ndarray]:
        return self.camera.ray(pos.x(), pos.y(), max(self.width(), 1), max(self.height(), 1))

    def pick(self, pos: QPointF) -> tuple[str, int, float] | None:
        """The joint under a widget position: (asset id, joint index, distance)."""
        items = self.build_items()
        if self.options.show_skin:
            # over a skin the skeleton is drawn as spheres and bones: pick those
            items = [dataclasses.replace(i, boxmin=None, boxmax=None)
                     if isinstance(i, CharacterDraw) and i.skin is not None else i for i in items]
        # Locked assets (outliner) are drawn but not picked; hidden ones are not drawn.
        items = [i for i in items if not is_locked(self.ctx.doc, getattr(i, "asset_id", ""))]
        origin, direction = self.ray_at(pos)
        return pick_joint(items, origin, direction)

    def pick_surface(self, pos: QPointF) -> Any:
        """The point of a shown skin under a widget position
        (:class:`~qtanimator.document.surface_pick.SurfaceHit`), or None (skins hidden, a miss)."""
        from qtanimator.document.surface_pick import pick_surfaces

        if not self.options.show_skin:
            return None
        ids = [i.asset_id for i in self.build_items() if isinstance(i, CharacterDraw) and i.skin is not None]
        origin, direction = self.ray_at(pos)
        return pick_surfaces(self.ctx.doc, ids, self.ctx.time, origin, direction)

    def gizmo_size(self) -> float:
        return 0.015 * self.camera.distance

    def pick_light(self, pos: QPointF) -> str | None:
        """The light whose gizmo is under a widget position ("light1" / "light2")."""
        if not self.options.show_lights:
            return None
        origin, direction = self.ray_at(pos)
        best = None
        for name, light in zip(LIGHT_NAMES, lights_of(self.ctx.doc)):
            if not pickable(self.ctx.doc, name):
                continue  # locked or switched off in the outliner
            t = ray_sphere(origin, direction, light.position, 1.5 * self.gizmo_size())
            if t is not None and (best is None or t < best[1]):
                best = (name, t)
        return None if best is None else best[0]

    def _joint_key(self, asset_id: str, index: int) -> str:
        skel = getattr(self.ctx.doc.runtime.get(asset_id), "skeleton", None)
        if skel is None:
            return str(index)
        return str(skel.joint_keys()[index])

    # -------------------------------------------------------------- mouse
    def mousePressEvent(self, event: QMouseEvent) -> None:
        pos = event.position()
        self._press_pos = QPointF(pos)
        self._end_gesture()   # a second button during a drag: the first drag ends here
        button, mods = event.button(), event.modifiers()
        mode = "orbit"
        extra: dict[str, Any] = {}
        place = (self._start_place(pos, scale=bool(mods & Qt.KeyboardModifier.ShiftModifier))
                 if button == Qt.MouseButton.LeftButton and mods & Qt.KeyboardModifier.AltModifier else None)
        if place is not None:
            mode, extra = "place", place
        elif button == Qt.MouseButton.MiddleButton or (
                button == Qt.MouseButton.LeftButton and mods & Qt.KeyboardModifier.ShiftModifier):
            mode = "pan"
        elif button == Qt.MouseButton.LeftButton and mods & Qt.KeyboardModifier.ControlModifier:
            mode = "zoom"
        elif button == Qt.MouseButton.LeftButton and not (mods & Qt.KeyboardModifier.AltModifier):
            light = self.pick_light(pos)
            if light is not None:
                mode = "light"
                extra = {"light": light, "gesture": self.ctx.begin_gesture(f"Move {light}")}
            elif self._start_grab(pos):
                mode = "grab"
            else:
                mode = "click-orbit"
        elif button == Qt.MouseButton.RightButton:
            ik = self._start_ik(pos)
            mode = "ik" if ik is not None else "zoom"
            extra = ik or {}
        self._drag = {"mode": mode, "last": QPointF(pos), "moved": False, **extra}
        event.accept()

    def _end_gesture(self) -> None:
        """Commit the gesture of a drag in progress (one undo step) and forget the drag."""
        drag, self._drag = self._drag, None
        gesture = drag.get("gesture") if drag else None
        if gesture is not None:
            gesture.commit()

    def mouseMoveEvent(self, event: QMouseEvent) -> None:
        if self._drag is None:
            return
        pos = event.position()
        last: QPointF = self._drag["last"]
        dx, dy = pos.x() - last.x(), pos.y() - last.y()
        if (pos - self._press_pos).manhattanLength() > 3:
            self._drag["moved"] = True
        self._drag["last"] = QPointF(pos)
        mode = self._drag["mode"]
        if mode in ("orbit", "click-orbit"):
            if self._drag["moved"]:
                self.camera.orbit(-dx * 0.4, dy * 0.4)
        elif mode == "pan":
            self.camera.pan(dx, dy, self.height())
        elif mode == "zoom":
            self.camera.zoom(math.exp(dy * 0.01))
        elif mode == "grab":
            self._drag_grab(pos)
        elif mode == "light":
            self._drag_light(pos)
        elif mode == "place":
            self._drag_place(pos)
        elif mode == "ik":
            self._drag_ik(pos)
        self._camera_moved()
        self.update()

    def mouseReleaseEvent(self, event: QMouseEvent) -> None:
        drag = self._drag
        self._end_gesture()
        if drag is None:
            return
        if drag["mode"] == "click-orbit" and not drag["moved"]:
            hit = self.pick(event.position())
            if hit is None:
                self.ctx.select("", "")
            else:
                self.ctx.select(hit[0], self._joint_key(hit[0], hit[1]))
        elif drag["mode"] == "grab":
            self.live.release()
        self.update()

    def wheelEvent(self, event: QWheelEvent) -> None:
        steps = event.angleDelta().y() / 120.0
        self.camera.zoom(0.88 ** steps)
        self._camera_moved()
        self.update()

    # ---------------------------------------------------------- light drag
    def _drag_light(self, pos: QPointF) -> None:
        """Move the dragged light in the plane through it facing the camera (one undo step)."""
        from qtanimator.document.commands import SetParameter

        assert self._drag is not None
        name, gesture = self._drag["light"], self._drag["gesture"]
        anchor = next(l.position for n, l in zip(LIGHT_NAMES, lights_of(self.ctx.doc)) if n == name)
        target = self._on_view_plane(pos, anchor)
        if target is None or not gesture.active:
            return
        value = [round(float(v), 4) for v in target]
        gesture.update(SetParameter(self.ctx.doc, f"{name}.position", value, text=f"Move {name}"))

    # ------------------------------------------------------ placement drag
    def _start_place(self, pos: QPointF, scale: bool) -> dict[str, Any] | None:
        """Begin an Alt+left (move) or Alt+Shift+left (``scale``) drag of the placement of the
        3D character under the cursor (its skin, else a joint); None: nothing picked."""
        from qtanimator.document import character3d
        from qtanimator.document.placement import placement_of

        surface = self.pick_surface(pos)
        if surface is not None:
            asset_id = surface.asset_id
        else:
            hit = self.pick(pos)
            if hit is None:
                return None
            asset_id = hit[0]
        asset = self.ctx.doc.assets.get(asset_id)
        if asset is None or asset.kind != character3d.ASSET_KIND:
            return None
        self.ctx.select(asset_id, "")
        root = self._pose(asset_id).world_matrices()[0, :3, 3].copy()
        press = self._on_view_plane(pos, root)
        if press is None:
            return None
        verb = "Scale" if scale else "Place"
        return {"asset": asset_id, "scale": scale, "anchor": np.asarray(root, dtype=float), "press": press,
                "start": placement_of(self.ctx.doc, asset_id, 3), "press_x": float(pos.x()),
                "gesture": self.ctx.begin_gesture(f"{verb} {asset_id}")}

    def _drag_place(self, pos: QPointF) -> None:
        """Move the placement with the cursor in the view plane through the character's root
        (at the press), or scale it uniformly by the horizontal motion (×2 per 100 px to the
        right) keeping the root where it is; one undo step."""
        from qtanimator.document.placement import set_placement_command
        from qtanimator.ui.rig_interaction import placement_scale

        assert self._drag is not None
        drag = self._drag
        start, gesture = drag["start"], drag["gesture"]
        if not gesture.active:
            return
        t0 = np.asarray(start["translate"], dtype=float)
        if drag["scale"]:
            s = placement_scale(start["scale"], float(pos.x()) - drag["press_x"])
            # A = T(t)·R·S(s) scales about its origin: move t so the root stays put.
            root = drag["anchor"]
            t = root - (s / start["scale"]) * (root - t0)
            value = {**start, "translate": [float(v) for v in t], "scale": s}
            text = f"Scale {drag['asset']}"
        else:
            target = self._on_view_plane(pos, drag["anchor"])
            if target is None:
                return
            value = {**start, "translate": [float(v) for v in t0 + (target - drag["press"])]}
            text = f"Place {drag['asset']}"
        gesture.update(set_placement_command(self.ctx.doc, drag["asset"], value, text=text))

    # ---------------------------------------------------------- cloth grab
    def _start_grab(self, pos: QPointF) -> bool:
        if not self.live.enabled:
            return False
        origin, direction = self.ray_at(pos)
        hit = self.live.grab(origin, direction,
                             max_distance=lambda p: 2.5 * max(p.width, p.height) / max(p.cols, p.rows))
        if hit is None:
            return False
        asset_id, point = hit
        self._grab = (asset_id, point, self.camera.eye())
        return True

    def _drag_grab(self, pos: QPointF) -> None:
        asset_id, anchor, _eye = self._grab
        target = self._on_view_plane(pos, anchor)
        if target is not None:
            self.live.drag_grabbed(asset_id, target)

    def _on_view_plane(self, pos: QPointF, anchor: np.ndarray) -> np.ndarray | None:
        """Where the mouse ray meets the plane through ``anchor`` facing the camera."""
        origin, direction = self.ray_at(pos)
        normal = self.camera.eye() - np.asarray(self.camera.target, dtype=float)
        normal /= np.linalg.norm(normal)
        den = float(direction @ normal)
        if abs(den) < 1e-9:
            return None
        t = float((anchor - origin) @ normal) / den
        return origin + t * direction

    # ------------------------------------------------------------------ IK
    def _start_ik(self, pos: QPointF) -> dict[str, Any] | None:
        """Begin a right-drag IK gesture (None: nothing to drag). On a shown skin the point
        under the cursor is dragged: the effector is that point in the frame of the joint
        influencing it most. Elsewhere (skin hidden or missed) a joint's sphere, bone or box
        is picked and its pivot dragged."""
        surface = self.pick_surface(pos)
        offset = None
        if surface is not None:
            asset_id, joint, offset, anchor = surface.asset_id, surface.joint, surface.offset, surface.point
        else:
            hit = self.pick(pos)
            if hit is None:
                return None
            asset_id, joint, _t = hit
        runtime = self.ctx.doc.runtime.get(asset_id)
        skel = getattr(runtime, "skeleton", None)
        if skel is None or not ik_dofs(skel, joint, self.ik_chain_length, surface=offset is not None):
            return None   # nothing can move this joint (the root): right-drag zooms
        key = self._joint_key(asset_id, joint)
        self.ctx.select(asset_id, key)
        if offset is None:
            anchor = self._pose(asset_id).world_matrices()[joint, :3, 3].copy()
        from qtanimator.document.pose import autokey
        return {"asset": asset_id, "joint": joint, "anchor": np.asarray(anchor, dtype=float).copy(),
                "offset": offset, "autokey": autokey(self.ctx.doc),
                "gesture": self.ctx.begin_gesture(f"IK drag {key}")}

    def _pose(self, asset_id: str) -> Any:
        from qtanimator.document import character3d

        return character3d.pose_skeleton(self.ctx.doc, asset_id, self.ctx.time)

    def _drag_ik(self, pos: QPointF) -> None:
        """One IK step towards the cursor: keyed at the current frame (auto-key on) or only
        shown as the unkeyed pose (auto-key off; ``document.pose``)."""
        from qtanimator.document import character3d
        from qtanimator.document.pose import PosePreview

        assert self._drag is not None
        target = self._on_view_plane(pos, self._drag["anchor"])
        if target is None:
            return
        asset_id, joint = self._drag["asset"], self._drag["joint"]
        doc, time = self.ctx.doc, self.ctx.time
        skel = character3d.character(doc, asset_id).skeleton  # the chain: structure only
        offset = self._drag.get("offset")
        values = character3d.ik_values(doc, asset_id, joint, target, time,
                                       ik_dofs(skel, joint, self.ik_chain_length, surface=offset is not None), offset)
        if not values:
            return
        gesture = self._drag["gesture"]
        if not gesture.active:
            return
        if self._drag.get("autokey", True):
            gesture.update(character3d.set_dofs_command(doc, asset_id, values, time))
        else:
            gesture.update(PosePreview(doc, character3d.dof_values(doc, asset_id, values, time), time, "IK drag"))

    # ------------------------------------------------------ set key, copy, paste
    def _say(self, text: str) -> None:
        bar = getattr(self.window(), "statusBar", None)
        if callable(bar):
            bar().showMessage(text, 4000)

    def _selects_character(self) -> bool:
        from qtanimator.document.character3d import ASSET_KIND

        asset = self.ctx.doc.assets.get(self.ctx.selection[0])
        return asset is not None and asset.kind == ASSET_KIND

    def set_key(self, whole_character: bool = False) -> bool:
        """S / I: key the selected joint's DOFs; Shift+S every DOF of its character."""
        from qtanimator.ui.rig_interaction import set_key_command

        if self._drag is not None and self._drag.get("gesture") is not None:
            return False
        command = set_key_command(self.ctx.doc, self.ctx.selection, self.ctx.time, whole_character)
        if command is None:
            self._say("Select a joint to key.")
            return False
        self.ctx.push(command)
        return True

    def copy_pose(self) -> bool:
        """Ctrl+C: copy the selected joint's rotation (the whole character's when the
        character is selected)."""
        from qtanimator.ui.rig_interaction import copy_selection, pose_clipboard

        clip = copy_selection(self.ctx.doc, self.ctx.selection, self.ctx.time)
        if clip is None:
            self._say("Select a joint or a character to copy its pose.")
            return False
        pose_clipboard.clip = clip
        self._say(f"Copied the pose of {len(clip.values)} joint{'s' if len(clip.values) != 1 else ''}.")
        return True

    def paste_pose(self, mirrored: bool = False) -> bool:
        """Ctrl+V / Ctrl+Shift+V: key the copied pose (mirrored) at the current frame.
        (Keys of :meth:`keyPressEvent`, which sees them from the GL surface too.)"""
        from qtanimator.ui.rig_interaction import paste_command, pose_clipboard

        if self._drag is not None and self._drag.get("gesture") is not None:
            return False
        command = paste_command(self.ctx.doc, pose_clipboard.clip, self.ctx.selection, self.ctx.time, mirrored)
        if command is None:
            self._say("Nothing to paste here: copy a pose of a character like this one first.")
            return False
        self.ctx.push(command)
        return True

    def reset_pose(self) -> bool:
        """R: the selected character back to its rest pose, keyed now (as the joint tree's
        Reset Pose; one undo step)."""
        from qtanimator.ui.joint_tree import reset_pose_command

        asset = self.ctx.selection[0]
        command = reset_pose_command(self.ctx.doc, asset, self.ctx.time) if asset else None
        if command is None:
            self._say("Select a character to reset its pose.")
            return False
        self.ctx.push(command)
        return True

    def reset_cloth(self) -> None:
        """Shift+R (and the Cloth dock's Reset): every live cloth back to its rest shape."""
        self.live.reset()
        self.update()

    # ----------------------------------------------------------------- keys
    def keyPressEvent(self, event: QKeyEvent) -> None:
        key = event.key()
        mods = event.modifiers() & ~Qt.KeyboardModifier.KeypadModifier
        ctrl, shift = Qt.KeyboardModifier.ControlModifier, Qt.KeyboardModifier.ShiftModifier
        plain = mods in (Qt.KeyboardModifier.NoModifier, shift)
        if key in (Qt.Key.Key_S, Qt.Key.Key_I) and plain and self._selects_character():
            # Set key (S / I; Shift+S the whole character) when a 3D character is selected;
            # otherwise S keeps moving the live cloth's pins.
            self.set_key(whole_character=bool(mods & shift))
        elif key == Qt.Key.Key_C and mods == ctrl:
            self.copy_pose()
        elif key == Qt.Key.Key_V and mods in (ctrl, ctrl | shift):
            self.paste_pose(mirrored=bool(mods & shift))
        elif key == Qt.Key.Key_F:
            self.frame_selection()
        elif key == Qt.Key.Key_X and mods == Qt.KeyboardModifier.NoModifier:
            # the MIT viewer's ``a`` (A moves the cloth pins here)
            self.set_display(show_axes=not self.options.show_axes)
        elif key == Qt.Key.Key_B and mods == Qt.KeyboardModifier.NoModifier:
            # the MIT viewer's ``s`` (S sets a key here)
            self.toggle_skeleton()
        elif key in PIN_KEYS or key in PIN_TURNS:
            if not self.live.enabled:
                self.set_live_cloth(True)
            if key in PIN_KEYS:
                self.live.move_pins(PIN_KEYS[key])
            else:
                self.live.move_pins((0.0, 0.0, 0.0), (0.0, PIN_TURNS[key], 0.0))
            self.update()
        elif key == Qt.Key.Key_P:
            self.live.paused = not self.live.paused
        elif key == Qt.Key.Key_R and mods == shift:
            self.reset_cloth()
        elif key == Qt.Key.Key_R and mods == Qt.KeyboardModifier.NoModifier:
            self.reset_pose()
        elif key == Qt.Key.Key_Escape and self._drag is not None and self._drag.get("mode") in ("ik", "light", "place"):
            self._drag["gesture"].abort()   # the document goes back exactly; nothing to undo
            self._drag = None
            self.update()
        else:
            super().keyPressEvent(event)


class ClipControls(QWidget):
    """The clip picker (:class:`~qtanimator.ui.clip_picker.ClipPicker`), play / pause, speed,
    play mode and a progress bar over the document's frame range, synced with ``ctx.frame``
    (the timeline sees every frame it shows)."""

    MODES = ("loop", "once", "ping-pong", "continue")

    def __init__(self, ctx: EditorContext, parent: QWidget | None = None, window: Any = None) -> None:
        super().__init__(parent)
        from qtanimator.core.clip import ClipPlayer

        self.ctx = ctx
        self.window_ = window
        self._announcing = False
        self.player = ClipPlayer(0.0, 1.0)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(4, 2, 4, 2)
        self.play_button = QToolButton(self)
        self.play_button.setObjectName("viewportPlay")
        self.play_button.setCheckable(True)
        self.play_button.setText("Play")
        self.play_button.toggled.connect(self.set_playing)
        self.speed = QDoubleSpinBox(self)
        self.speed.setObjectName("viewportSpeed")
        self.speed.setRange(-4.0, 4.0)
        self.speed.setSingleStep(0.25)
        self.speed.setValue(1.0)
        self.speed.setSuffix("×")
        self.speed.valueChanged.connect(self._on_speed)
        self.mode = QComboBox(self)
        self.mode.setObjectName("viewportPlayMode")
        self.mode.addItems(list(self.MODES))
        self.mode.currentTextChanged.connect(self._on_mode)
        self.progress = QProgressBar(self)
        self.progress.setObjectName("viewportProgress")
        self.progress.setRange(0, 1000)
        self.progress.setTextVisible(True)
        self.progress.setFormat("%p%")
        self.progress.mousePressEvent = self._seek_click  # type: ignore[method-assign]
        # The clip the selected (or only) glTF character plays, before Play (the progress bar
        # runs over its duration); hidden while no character has clips. Here rather than in the
        # display bar above, which already fills the default window's width.
        self.clip = ClipPicker(ctx, self)
        self.clip.combo.setObjectName("viewportClip")
        layout.addWidget(self.clip)
        layout.addWidget(self.play_button)
        layout.addWidget(QLabel("Speed", self))
        layout.addWidget(self.speed)
        layout.addWidget(self.mode)
        layout.addWidget(self.progress, 1)
        self._clock = QElapsedTimer()
        self._timer = QTimer(self)
        self._timer.setTimerType(Qt.TimerType.PreciseTimer)
        self._timer.setInterval(8)
        self._timer.timeout.connect(self._tick)
        self._setting_frame = False
        ctx.frameChanged.connect(self._on_frame)
        ctx.playingChanged.connect(self._on_other_playing)
        self._on_frame(ctx.frame)

    def clip_range(self) -> tuple[float, float]:
        first, last = self.ctx.doc.frame_range
        return self.ctx.doc.frame_to_time(first), self.ctx.doc.frame_to_time(max(last, first))

    @property
    def playing(self) -> bool:
        return self._timer.isActive()

    def set_playing(self, playing: bool, announce: bool = True) -> None:
        """Start or stop playback; ``announce`` tells the other editors (ctx.playingChanged)."""
        if playing == self.playing:
            self.play_button.setChecked(playing)
            return
        if playing:
            other = getattr(self.window_, "playback", None)   # the timeline's playback
            if other is not None and getattr(other, "playing", False):
                other.pause()
            from qtanimator.core.clip import ClipPlayer

            start, end = self.clip_range()
            self.player = ClipPlayer(start, end, self.mode.currentText(), self.speed.value())
            t = self.ctx.time
            if self.mode.currentText() == "once" and t >= end:
                t = start
            self.player.elapsed = t - start if start <= t <= end or self.mode.currentText() == "continue" else 0.0
            self._clock.start()
            self._timer.start()
        else:
            self._timer.stop()
        self.play_button.setChecked(playing)
        self.play_button.setText("Pause" if playing else "Play")
        if announce:
            self._announcing = True
            try:
                self.ctx.playingChanged.emit(playing)
            finally:
                self._announcing = False

    def step(self, dt: float) -> None:
        """Advance playback by ``dt`` wall seconds (the timer calls this; tests may too)."""
        t = self.player.advance(dt)
        self._setting_frame = True
        try:
            self.ctx.set_frame(self.ctx.doc.time_to_frame(t))
        finally:
            self._setting_frame = False
        if self.player.finished:
            self.set_playing(False)

    def _tick(self) -> None:
        self.step(self._clock.restart() / 1000.0)

    def _on_speed(self, value: float) -> None:
        self.player.speed = float(value)

    def _on_mode(self, mode: str) -> None:
        from qtanimator.core.clip import PlayMode

        t = self.player.time
        self.player.mode = PlayMode(mode)
        self._seek_time(t)

    def _seek_time(self, t: float) -> None:
        start = self.player.start
        self.player.elapsed = max(t - start, 0.0) if self.player.mode.value != "continue" else t - start

    def _on_frame(self, frame: float) -> None:
        start, end = self.clip_range()
        t = self.ctx.doc.frame_to_time(frame)
        u = 0.0 if end <= start else (t - start) / (end - start)
        self.progress.setValue(int(round(1000 * min(max(u, 0.0), 1.0))))
        if not self._setting_frame and self.playing:
            self._seek_time(t)

    def _on_other_playing(self, playing: bool) -> None:
        if playing and self.playing and not self._announcing:
            self.set_playing(False, announce=False)

    def _seek_click(self, event: QMouseEvent) -> None:
        start, end = self.clip_range()
        u = min(max(event.position().x() / max(self.progress.width(), 1), 0.0), 1.0)
        self.ctx.set_frame(round(self.ctx.doc.time_to_frame(start + u * (end - start))))


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
                from qtanimator.render.scene3d import joint_index

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


def grab_with_3d(widget: QWidget) -> QPixmap:
    """``widget.grab()`` with the 3D views inside it drawn in: a GL window in a window
    container is shown by the window system and is not part of a widget grab
    (screenshots use this)."""
    from PySide6.QtCore import QPoint, QRect
    from PySide6.QtGui import QPainter

    pixmap = widget.grab()
    views = [widget] if isinstance(widget, Viewport3D) else []
    views += widget.findChildren(Viewport3D)
    painter = QPainter(pixmap)
    for view in views:
        if view.surface_kind != "window" or not view.isVisible():
            continue
        rgba = np.ascontiguousarray(view.render_image())
        h, w = rgba.shape[:2]
        image = QImage(rgba.data, w, h, 4 * w, QImage.Format.Format_RGBA8888).copy()
        origin = view.mapTo(widget, QPoint(0, 0)) if view is not widget else QPoint(0, 0)
        painter.drawImage(QRect(origin, view.size()), image)
    painter.end()
    return pixmap


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
    from PySide6.QtGui import QAction

    from qtanimator.ui.camera_fields import show_camera_dialog

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


__all__ = ["ClipControls", "ClothDraw", "LiveCloths", "Viewport3D", "ViewportPanel", "grab_with_3d", "install"]
