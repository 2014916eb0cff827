"""The GL view of the 3D scene: :class:`Viewport3D` (object name ``viewport3d``), drawing the
document's skinned characters, skeletons and cloth under two coloured lights.

The pixels come from a GL surface filling the view (:mod:`~qtanimator.ui.view3d_surfaces`);
the view builds the scene items each paint (never simulating, never waiting) and draws them
with a :class:`~qtanimator.render.gl.renderer.SceneRenderer`, prepares its GL context while
still hidden, and renders pictures for screenshots. Camera, picking, drags, live cloth and
keys are its mixins, one module each.

Before it makes a GL surface the view asks once whether a usable OpenGL 3.3 context can be
made here (:func:`~qtanimator.render.gl.capability.probe_gl`); where not (Qt's offscreen
platform, an OpenGL 2.1 driver), and when the surface's own context fails its check, its
shaders fail, a paint raises or the context is lost later, the view shows a
:class:`~qtanimator.ui.view3d_surfaces.GLMessage` instead of a picture, logs why once, and
never lets the error reach the user as a crash or a traceback dialog. The document, the
keys and the other editors are unaffected.
"""

from __future__ import annotations

import logging
import time as _time
from typing import Any

import numpy as np
from OpenGL import GL
from PySide6.QtCore import QObject, QPoint, QPointF, QRect, QSize, Qt, QTimer, Signal
from PySide6.QtGui import QGuiApplication, QImage, QOpenGLContext, QPainter, QPixmap, QResizeEvent, QSurfaceFormat
from PySide6.QtOpenGL import QOpenGLWindow
from PySide6.QtWidgets import QVBoxLayout, QWidget

from qtanimator.document.document import DocumentChange
from qtanimator.render.gl.camera import OrbitCamera
from qtanimator.render.gl.capability import (
    GLUnavailableError,
    context_problem,
    current_gl_strings,
    log_unavailable,
    probe_gl,
    unavailable_text,
)
from qtanimator.render.gl.lights import ambient_of, lights_of
from qtanimator.render.gl.renderer import ClothDraw, SceneItem, SceneRenderer, ViewOptions, grid_scale_for
from qtanimator.render.painter2d import image_to_array
from qtanimator.render.render3d import OffscreenGL
from qtanimator.render.scene3d import scene_bounds, scene_items
from qtanimator.ui.context import EditorContext
from qtanimator.ui.view3d_keys import ViewKeys
from qtanimator.ui.view3d_surfaces import GLMessage, GLView, _GLWidgetSurface, _GLWindowSurface, surface_kind

log = logging.getLogger(__name__)


class Viewport3D(ViewKeys, GLView):
    """The GL view of the 3D scene (object name ``viewport3d``): camera, picking, gestures
    and live cloth; the pixels come from a GL surface filling it (``surface``: a
    QOpenGLWindow in a window container by default, or a QOpenGLWidget, see
    :data:`~qtanimator.ui.view3d_surfaces.DEFAULT_SURFACE`). Mouse and key events reach
    this widget either way.

    Without a usable OpenGL 3.3 context it shows a :class:`GLMessage` (``message``) instead
    and ``gl_problem`` says why; the rest of the view (camera, keys, cloth threads) stays."""

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
    #: The view cannot draw (no usable OpenGL 3.3 context, or it was lost): the reason.
    glUnavailable = Signal(str)

    def __init__(self, ctx: EditorContext, parent: QWidget | None = None, surface: str | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("viewport3d")
        self.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        self.setMinimumSize(160, 120)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        #: "window" or "widget": how the picture reaches the screen.
        self.surface_kind = surface or surface_kind()
        #: Why the view cannot draw ("" while it can); then ``message`` is shown instead.
        self.gl_problem = ""
        self.message: GLMessage | None = None
        #: The GL surface; None where no usable OpenGL context could be made.
        self.gl: _GLWindowSurface | _GLWidgetSurface | None = None
        self.gl_info = ""
        support = probe_gl()
        if not support.ok:
            # No GL surface at all: a GL window without a usable context fails its shaders
            # and crashes in its first paint (Qt's offscreen platform, OpenGL 2.1).
            self.surface_widget: QWidget = self._show_unavailable(support.problem, support.found)
        elif self.surface_kind == "window":
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
            self.surface_widget = container
        else:
            self.gl = _GLWidgetSurface(self)
            self.gl.setObjectName("viewport3dSurface")
            layout.addWidget(self.gl)
            self.surface_widget = self.gl
        self.ctx = ctx
        self.camera = OrbitCamera()
        self.options = ViewOptions()
        self.renderer = SceneRenderer()
        # The live cloths, the cache worker (``doc.caches["cloths"]``) and the timer polling them.
        self._start_simulations(ctx.doc)
        self.ik_chain_length = 3
        self.last_error = ""
        self.last_frame_ms = 0.0
        self._items = []
        self._offscreen: tuple[Any, SceneRenderer] | None = None   # render_image before the first show
        self._framed_once = False   # the camera frames the scene at the first paint with items
        self._grid_pending = False  # a restored camera: size the grid at the first paint
        self._drag = None
        self._press_pos = QPointF()
        self._camera_seen = ()
        self._prepare_state = ""    # prepare_gl: "", "context", "resources", "picture", "done"
        self._defer_renderer = False
        ctx.frameChanged.connect(lambda _f: self.update())
        ctx.selectionChanged.connect(lambda _a, _j: self.update())
        ctx.documentChanged.connect(self._on_document_changed)
        ctx.documentReset.connect(self._on_document_reset)
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

    # ----------------------------------------------------------------- GL
    def update(self) -> None:  # type: ignore[override]
        """Ask for a new picture (drawn at the next frame). A hidden GL window is not asked:
        it paints when it is exposed, and a request left pending would make a second
        picture right after that one."""
        if self.gl is None or self.gl_problem:
            return
        if isinstance(self.gl, _GLWindowSurface) and not self.gl.isExposed():
            return
        self.gl.update()

    def format(self) -> QSurfaceFormat:
        """The GL surface's format (OpenGL 3.3 core, depth, multisampling); an empty format
        without a surface."""
        return self.gl.format() if self.gl is not None else QSurfaceFormat()

    # ------------------------------------------------------- no usable GL
    def _show_unavailable(self, problem: str, found: str = "", stopped: bool = False) -> GLMessage:
        """Show the message instead of the picture (now: call it outside a paint);
        ``stopped``: the view drew before."""
        self.gl_problem = problem
        message = self.message
        if message is None:
            message = self.message = GLMessage(self)
            layout = self.layout()
            assert layout is not None
            layout.addWidget(message)
        message.set_text(unavailable_text(problem, found, stopped))
        if self.gl is not None:
            # A hidden GL window gets no more expose events: nothing paints any more.
            self.surface_widget.hide()
        message.show()
        log_unavailable(problem, found)
        self.glUnavailable.emit(problem)
        return message

    def _gl_failed(self, problem: str) -> None:
        """The GL surface cannot draw: stop drawing now (every later paint returns at once)
        and show the message at the next turn of the event loop (this is called from inside
        the surface's initializeGL or paintGL, where hiding it is not safe)."""
        if self.gl_problem:
            return
        self.gl_problem = problem
        found = self.gl_info and f"OpenGL {self.gl_info}"
        stopped = self.last_frame_ms > 0   # it drew before: not a missing capability
        QTimer.singleShot(0, self, lambda: self._show_unavailable(problem, found, stopped))  # dropped if the view goes

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
        if (not isinstance(self.gl, _GLWindowSurface) or self.gl_problem or self._prepare_state != ""
                or self.gl.isExposed() or QGuiApplication.platformName() not in self.PREPARE_PLATFORMS):
            return False
        self._prepare_state = "context"
        QTimer.singleShot(0, self, self._prepare_step)  # dropped if the view goes
        return True

    def _prepare_step(self) -> None:
        try:
            self._prepare_next()
        except Exception as exc:  # noqa: BLE001 - never a traceback dialog: the view says why
            self._prepare_state = "done"
            log.exception("3D view: preparing the OpenGL context failed")
            self._gl_failed(f"preparing the picture failed ({type(exc).__name__}: {exc})")

    def _prepare_next(self) -> None:
        state = self._prepare_state
        gl = self.gl
        if (not isinstance(gl, _GLWindowSurface) or self.gl_problem or gl.isExposed()
                or state in ("", "done")):
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
            self._prepare_state = "resources" if gl.context() is not None and not self.gl_problem else "done"
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
        """The surface's initializeGL: its context should be current. Checks it (version 3.3,
        current) before making the programs; any failure shows the message instead."""
        if self.gl_problem or self.gl is None:
            return
        try:
            context = self.gl.context()
            problem = context_problem(context)
            if not problem and QOpenGLContext.currentContext() is None:
                problem = "the OpenGL context cannot be made current"
            version, renderer = current_gl_strings()
            self.gl_info = f"{version or '?'} / {renderer or '?'}"
            if problem:
                self._gl_failed(problem)
                return
            if not self._defer_renderer:  # prepare_gl makes the programs and meshes in a later step
                self.renderer.initialize()
            if context is not None:
                context.aboutToBeDestroyed.connect(self._on_context_destroyed)
        except Exception as exc:  # noqa: BLE001 - a shader that fails: the message, not a dialog
            log.exception("3D view: initializing OpenGL failed")
            self._gl_failed(f"initializing OpenGL failed ({type(exc).__name__}: {exc})")

    def _on_context_destroyed(self) -> None:
        """The surface's context goes (lost, or the surface is deleted): free what the
        renderer holds in it and stop drawing; the message says so (when the view stays)."""
        self._release_gl()
        if not self.gl_problem:
            self._gl_failed("the OpenGL context was lost")

    def _release_gl(self) -> None:
        gl = self.gl
        if gl is None:
            return
        try:
            gl.makeCurrent()
        except RuntimeError:
            return  # the surface is being deleted: its context (not shared) takes the resources along
        try:
            if QOpenGLContext.currentContext() is not None:
                self.renderer.release()
            else:  # nothing current to delete them in: forget them
                self.renderer = SceneRenderer()
        finally:
            gl.doneCurrent()

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
        """The surface's paintGL: build the scene and draw it. Nothing once the view cannot
        draw; an error here shows the message (and is logged) instead of reaching the user."""
        gl = self.gl
        if gl is None or self.gl_problem:
            return
        try:
            if QOpenGLContext.currentContext() is None:
                self._gl_failed("the OpenGL context was lost")
                return
            ratio = gl.devicePixelRatio()
            self._draw(self.renderer, max(1, int(gl.width() * ratio)), max(1, int(gl.height() * ratio)))
        except Exception as exc:  # noqa: BLE001 - never a crash or a dialog per frame
            log.exception("3D view: drawing failed")
            self._gl_failed(f"drawing failed ({type(exc).__name__}: {exc})")

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
        the picture is then drawn by the same renderer into an offscreen framebuffer.
        Raises :class:`GLUnavailableError` when the view cannot draw."""
        if self.gl is None or self.gl_problem:
            raise GLUnavailableError(self.gl_problem or "no OpenGL surface")
        if isinstance(self.gl, _GLWindowSurface):
            if not self.gl.isValid():
                return self._render_offscreen()
            # QOpenGLWindow.grabFramebuffer reads what is in the back buffer: draw it first.
            self.gl.makeCurrent()
            ratio = self.gl.devicePixelRatio()
            self._draw(self.renderer, max(1, int(self.gl.width() * ratio)), max(1, int(self.gl.height() * ratio)))
            GL.glFinish()
        return image_to_array(self.gl.grabFramebuffer().convertToFormat(QImage.Format.Format_RGBA8888))

    def _render_offscreen(self) -> np.ndarray:
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
        GL.glFinish()
        return gl.read()

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


def grab_with_3d(widget: QWidget) -> QPixmap:
    """``widget.grab()`` with the 3D views inside it drawn in: a GL window in a window
    container is shown by the window system and is not part of a widget grab
    (screenshots use this)."""
    pixmap = widget.grab()
    views = [widget] if isinstance(widget, Viewport3D) else []
    views += widget.findChildren(Viewport3D)
    painter = QPainter(pixmap)
    for view in views:
        if view.surface_kind != "window" or not view.isVisible() or view.gl_problem or view.gl is None:
            continue  # a widget surface, or the message: already in the grab
        rgba = np.ascontiguousarray(view.render_image())
        h, w = rgba.shape[:2]
        image = QImage(rgba.data, w, h, 4 * w, QImage.Format.Format_RGBA8888).copy()
        origin = view.mapTo(widget, QPoint(0, 0)) if view is not widget else QPoint(0, 0)
        painter.drawImage(QRect(origin, view.size()), image)
    painter.end()
    return pixmap


__all__ = ["Viewport3D", "grab_with_3d"]
