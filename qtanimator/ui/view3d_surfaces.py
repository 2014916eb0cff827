"""The GL surfaces of the 3D view: how its picture reaches the screen.

A :class:`GLView` (the 3D view) is filled by one surface: a QOpenGLWindow in a window
container (``"window"``: the window system shows it, the main window is not composed through
OpenGL) or a QOpenGLWidget (``"widget"``: Qt composes the whole main window with OpenGL every
frame). See docs/decisions.md; the environment variable ``QTANIMATOR_VIEW3D_SURFACE``
overrides :data:`DEFAULT_SURFACE`. Either way the surface calls the view's
``initialize_gl`` / ``paint_gl`` and the view receives the mouse and the keys.

Where no usable OpenGL 3.3 context can be had (no OpenGL at all, an older version, shaders
that do not compile, a context lost later) the view shows a :class:`GLMessage` instead: what
was found, what is needed, and what still works.
"""

from __future__ import annotations

import os

from PySide6.QtCore import Qt
from PySide6.QtGui import QKeyEvent, QMouseEvent, QWheelEvent
from PySide6.QtOpenGL import QOpenGLWindow
from PySide6.QtOpenGLWidgets import QOpenGLWidget
from PySide6.QtWidgets import QFrame, QHBoxLayout, QLabel, QSizePolicy, QVBoxLayout, QWidget

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


class GLMessage(QFrame):
    """What the 3D view shows instead of its picture when it cannot draw (object name
    ``viewport3dMessage``): a title and the reason, what is needed and what still works.
    The text can be selected and copied (for a bug report)."""

    TITLE = "The 3D view is not available"

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("viewport3dMessage")
        self.setFrameShape(QFrame.Shape.NoFrame)
        self.setAutoFillBackground(True)
        self.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Ignored)
        self.setMinimumSize(1, 1)
        self.title = QLabel(self.TITLE, self)
        self.title.setObjectName("viewport3dMessageTitle")
        font = self.title.font()
        font.setBold(True)
        font.setPointSizeF(font.pointSizeF() * 1.3)
        self.title.setFont(font)
        self.title.setAlignment(Qt.AlignmentFlag.AlignCenter)
        self.body = QLabel(self)
        self.body.setObjectName("viewport3dMessageText")
        self.body.setWordWrap(True)
        self.body.setAlignment(Qt.AlignmentFlag.AlignCenter)
        self.body.setTextFormat(Qt.TextFormat.PlainText)
        self.body.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        # A column at most 560 px wide in the middle (a word-wrapped label gets its height for
        # its width only when the layout does not align it).
        column = QWidget(self)
        column.setMaximumWidth(560)
        inner = QVBoxLayout(column)
        inner.setContentsMargins(0, 0, 0, 0)
        inner.addWidget(self.title)
        inner.addSpacing(12)
        inner.addWidget(self.body)
        row = QHBoxLayout()
        row.addStretch(1)
        row.addWidget(column, 100)
        row.addStretch(1)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(24, 24, 24, 24)
        layout.addStretch(1)
        layout.addLayout(row)
        layout.addStretch(1)

    def set_text(self, text: str) -> None:
        self.body.setText(text)

    def text(self) -> str:
        """The title and the explanation."""
        return f"{self.title.text()}\n\n{self.body.text()}"


__all__ = ["DEFAULT_SURFACE", "GLMessage", "GLView", "surface_kind"]
