"""OpenGL 3.3 core drawing for the 3D viewport and the headless 3D renderer.

Everything here runs with a current OpenGL context (a QOpenGLWidget's or the offscreen one of
:mod:`qtanimator.render.render3d`) and calls OpenGL through PyOpenGL.
"""

from __future__ import annotations

from PySide6.QtGui import QSurfaceFormat


def surface_format(samples: int = 4) -> QSurfaceFormat:
    """The format every 3D context uses: OpenGL 3.3 core, 24-bit depth, multisampling."""
    fmt = QSurfaceFormat()
    fmt.setRenderableType(QSurfaceFormat.RenderableType.OpenGL)
    fmt.setVersion(3, 3)
    fmt.setProfile(QSurfaceFormat.OpenGLContextProfile.CoreProfile)
    fmt.setDepthBufferSize(24)
    fmt.setStencilBufferSize(8)
    fmt.setSamples(samples)
    return fmt
