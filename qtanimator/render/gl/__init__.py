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

_probed: list[str] = []


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
    """GL_RENDERER of a default context here ("" when none can be made): asked once per
    process with a throw-away offscreen context (about 40 ms on llvmpipe)."""
    if not _probed:
        name = ""
        try:
            from PySide6.QtGui import QGuiApplication, QOffscreenSurface, QOpenGLContext

            if QGuiApplication.instance() is not None:
                context = QOpenGLContext()
                context.setFormat(surface_format(0))
                surface = QOffscreenSurface()
                surface.setFormat(context.format())
                surface.create()
                if context.create() and context.makeCurrent(surface):
                    from OpenGL import GL

                    raw = GL.glGetString(GL.GL_RENDERER)
                    name = raw.decode(errors="replace") if isinstance(raw, bytes) else str(raw or "")
                    context.doneCurrent()
                surface.destroy()
        except Exception:  # noqa: BLE001 - no GL here: the view reports it when it shows
            name = ""
        _probed.append(name)
    return _probed[0]


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
