"""Headless 3D rendering through an offscreen OpenGL context.

``render_frames_3d(doc, times, size)`` yields one RGBA image (H×W×4 uint8) per time, drawn by
the same :class:`~qtanimator.render.gl.renderer.SceneRenderer` as the viewport into a
multisampled framebuffer object of a ``QOffscreenSurface`` + ``QOpenGLContext``.

Without a display, the first call starts a private ``Xvfb`` (Mesa gives a GL 4.5 core context
there); Qt's ``offscreen`` platform has no OpenGL.
"""

from __future__ import annotations

import copy
import os
from collections.abc import Iterable, Iterator
from typing import Any

import numpy as np
from PySide6.QtGui import QGuiApplication, QOffscreenSurface, QOpenGLContext
from PySide6.QtOpenGL import QOpenGLFramebufferObject, QOpenGLFramebufferObjectFormat

from qtanimator.render.gl import surface_format
from qtanimator.render.gl.camera import OrbitCamera
from qtanimator.render.gl.capability import GLUnavailableError, context_problem
from qtanimator.render.gl.lights import ambient_of, lights_of
from qtanimator.render.gl.renderer import SceneItem, SceneRenderer, ViewOptions, grid_scale_for
from qtanimator.render.painter2d import image_to_array
from qtanimator.render.scene3d import scene_bounds, scene_items
from qtanimator.render.xvfb import start_private_xvfb


def ensure_gui_application() -> QGuiApplication:
    """The running QGuiApplication, or a new one (on a private Xvfb when there is no display)."""
    app = QGuiApplication.instance()
    if app is not None:
        return app  # type: ignore[return-value]
    platform = os.environ.get("QT_QPA_PLATFORM", "")
    has_display = bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    if platform in ("", "offscreen", "minimal") and not has_display:
        try:
            os.environ["DISPLAY"] = start_private_xvfb("640x480x24")
        except OSError as exc:
            raise GLUnavailableError(f"3D rendering needs a display: {exc}") from exc
        os.environ["QT_QPA_PLATFORM"] = "xcb"
    return QGuiApplication([])


class OffscreenGL:
    """An OpenGL 3.3 core context with a multisampled framebuffer of ``size`` pixels."""

    def __init__(self, size: tuple[int, int], samples: int = 4) -> None:
        ensure_gui_application()
        self.context = QOpenGLContext()
        self.context.setFormat(surface_format(samples))
        if not self.context.create():
            raise GLUnavailableError(
                f"cannot create an OpenGL context on the '{QGuiApplication.platformName()}' platform "
                "(3D rendering needs a display or Xvfb; qtanimator.render.render3d.ensure_gui_application() "
                "starts a private Xvfb when it creates the application)")
        problem = context_problem(self.context)
        if problem:
            raise GLUnavailableError(problem)
        fmt = self.context.format()
        self.surface = QOffscreenSurface()
        self.surface.setFormat(fmt)
        self.surface.create()
        self.samples = samples
        self.fbo: QOpenGLFramebufferObject | None = None
        self.make_current()
        self.resize(size)

    def make_current(self) -> None:
        if not self.context.makeCurrent(self.surface):
            raise GLUnavailableError("cannot make the offscreen OpenGL context current")

    def resize(self, size: tuple[int, int]) -> None:
        self.size = (int(size[0]), int(size[1]))
        fmt = QOpenGLFramebufferObjectFormat()
        fmt.setAttachment(QOpenGLFramebufferObject.Attachment.CombinedDepthStencil)
        fmt.setSamples(self.samples)
        self.fbo = QOpenGLFramebufferObject(self.size[0], self.size[1], fmt)
        self.fbo.bind()

    def bind(self) -> None:
        assert self.fbo is not None
        self.fbo.bind()

    def read(self) -> np.ndarray:
        """The framebuffer as an H×W×4 RGBA uint8 array (top row first)."""
        assert self.fbo is not None
        return image_to_array(self.fbo.toImage())

    def close(self) -> None:
        if self.fbo is not None:
            self.make_current()
            self.fbo.release()
            self.fbo = None
        self.context.doneCurrent()



def default_camera(items: list[SceneItem], doc: Any = None) -> OrbitCamera:
    """A camera framing the scene (or the one stored in the document's ``view3d.camera``)."""
    cam = OrbitCamera()
    stored = None if doc is None else doc.view_state.get("view3d.camera")
    if isinstance(stored, dict):
        cam.azimuth = float(stored.get("azimuth", cam.azimuth))
        cam.inclination = float(stored.get("inclination", cam.inclination))
        cam.distance = float(stored.get("distance", cam.distance))
        cam.target = np.asarray(stored.get("target", [0, 0, 0]), dtype=float)
        cam.fov_y = float(stored.get("fov_y", cam.fov_y))
        return cam
    bounds = scene_bounds(items)
    if bounds is not None:
        cam.frame(*bounds)
    return cam


def render_frames_3d(doc: Any, times: Iterable[float], size: tuple[int, int] = (640, 480),
                     camera: OrbitCamera | None = None, options: ViewOptions | None = None,
                     extra_items: Iterable[SceneItem] = ()) -> Iterator[np.ndarray]:
    """Render the document's 3D scene at each time (seconds) into H×W×4 uint8 RGBA arrays.

    The camera frames the scene at the first time unless one is given (or stored in the
    document as ``view3d.camera``). By default skins are drawn without their skeleton and
    without the light markers (``options`` changes that).
    """
    options = ViewOptions(show_skeleton=False, show_lights=False) if options is None else copy.copy(options)
    gl = OffscreenGL(size)
    renderer = SceneRenderer()
    extra = list(extra_items)
    try:
        for t in times:
            items = scene_items(doc, float(t)) + extra
            if camera is None:
                camera = default_camera(items, doc)
                bounds = scene_bounds(items)
                if bounds is not None:
                    options.grid_scale = grid_scale_for(*bounds)
            gl.make_current()
            gl.bind()
            renderer.render(items, camera, size[0], size[1], lights_of(doc), ambient_of(doc), options)
            yield gl.read()
    finally:
        gl.make_current()
        renderer.release()
        gl.close()
