"""The GL surfaces of the 3D view: how its picture reaches the screen.

A :class:`GLView` (the 3D view) is filled by one surface: a QOpenGLWindow in a window
container (``"window"``: the window system shows it, the main window is not composed through
OpenGL) or a QOpenGLWidget (``"widget"``: Qt composes the whole main window with OpenGL every
frame). See docs/decisions.md; the environment variable ``QTANIMATOR_VIEW3D_SURFACE``
overrides :data:`DEFAULT_SURFACE`. Either way the surface calls the view's
``initialize_gl`` / ``paint_gl`` and the view receives the mouse and the keys.
"""

from __future__ import annotations

import os

from PySide6.QtCore import Qt
from PySide6.QtGui import QKeyEvent, QMouseEvent, QWheelEvent
from PySide6.QtOpenGL import QOpenGLWindow
from PySide6.QtOpenGLWidgets import QOpenGLWidget
from PySide6.QtWidgets import QWidget

from qtanimator.render.gl import surface_format, view_samples

#: How the GL picture reaches the screen: "window" (a QOpenGLWindow in a window container:
#: the window system shows it, the main window is not composed through OpenGL) or "widget"
#: (a QOpenGLWidget: Qt composes the whole main window with OpenGL every frame). See
#: docs/decisions.md; the environment variable ``QTANIMATOR_VIEW3D_SURFACE`` overrides it.
DEFAULT_SURFACE = "window"


def surface_kind() -> str:
    """The GL surface kind to use ("window" or "widget")."""
    kind = os.environ.get("QTANIMATOR_VIEW3D_SURFACE", DEFAULT_SURFACE).strip().lower()
    return kind if kind in ("window", "widget") else DEFAULT_SURFACE


class GLView(QWidget):
    """A widget whose pixels come from a GL surface filling it; the surface calls these with
    its context current."""

    def initialize_gl(self) -> None:
        """The surface's initializeGL."""
        raise NotImplementedError

    def paint_gl(self) -> None:
        """The surface's paintGL."""
        raise NotImplementedError


class _GLWidgetSurface(QOpenGLWidget):
    """The GL surface as a QOpenGLWidget child of the view (input goes to the view)."""

    def __init__(self, view: GLView) -> None:
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

    def __init__(self, view: GLView) -> None:
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


__all__ = ["DEFAULT_SURFACE", "GLView", "surface_kind"]
