"""OpenGL 3.3 core drawing for the 3D viewport and the headless 3D renderer.

Everything here runs with a current OpenGL context (a QOpenGLWidget's or the offscreen one of
:mod:`qtanimator.render.render3d`) and calls OpenGL through PyOpenGL.
"""

from __future__ import annotations

import os

from PySide6.QtGui import QSurfaceFormat

#: Words in GL_RENDERER that name a software rasteriser (Mesa llvmpipe / softpipe / swrast,
#: Windows' GDI generic): there, 4× multisampling costs 15–20 ms of CPU per frame.
SOFTWARE_RENDERERS = ("llvmpipe", "softpipe", "swrast", "software rasterizer", "gdi generic")
#: Samples of the interactive 3D view on a GPU.
VIEW_SAMPLES = 4


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


def gl_renderer_name() -> str:
    """GL_RENDERER of a default context here ("" when none can be made): the one probe of
    :func:`qtanimator.render.gl.capability.probe_gl`, asked once per process."""
    from qtanimator.render.gl.capability import probe_gl

    return probe_gl().renderer


def is_software_renderer(name: str) -> bool:
    low = name.lower()
    return any(word in low for word in SOFTWARE_RENDERERS)


def view_samples() -> int:
    """Multisampling of the interactive 3D view: ``QTANIMATOR_VIEW_SAMPLES`` when set, else
    none on a software rasteriser (where it would take most of each frame: a 4× picture of
    the demo costs 15–20 ms on llvmpipe against 3–5 ms without) and 4 on a GPU. Exported and
    rendered pictures keep their own setting (``qtanimator render`` multisamples always)."""
    env = os.environ.get("QTANIMATOR_VIEW_SAMPLES", "").strip()
    if env.isdigit():
        return int(env)
    return 0 if is_software_renderer(gl_renderer_name()) else VIEW_SAMPLES
