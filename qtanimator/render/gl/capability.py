"""Can this machine draw in 3D? The one check of an OpenGL context, used by the 3D view and
the headless 3D renderer.

Everything 3D here needs an OpenGL 3.3 core context (GLSL 330). :func:`context_problem`
says why a made context is not one (its version), :func:`shader_problem` compiles a trivial
GLSL 330 program in the current context (a driver may claim 3.3 and still refuse it), and
:func:`probe_gl` makes a throw-away offscreen context once per process and runs both, so
that the 3D view can decide *before* it creates a GL surface whether it can draw at all: on
Qt's ``offscreen`` platform, or with ``MESA_GL_VERSION_OVERRIDE=2.1``, a GL window would
otherwise fail its shaders and crash in its first paint. :func:`unavailable_text` is what
the view then says, and :func:`log_unavailable` writes it to the log once.
"""

from __future__ import annotations

import logging
import os
from dataclasses import dataclass

from PySide6.QtGui import QGuiApplication, QOffscreenSurface, QOpenGLContext, QSurfaceFormat

#: The OpenGL version every 3D context needs (the shaders are ``#version 330 core``).
MIN_VERSION = (3, 3)
#: What the 3D view needs, in words.
NEEDED = "OpenGL 3.3 (core profile)"

log = logging.getLogger("qtanimator.gl")

_VERTEX_330 = """#version 330 core
layout(location = 0) in vec3 position;
void main() { gl_Position = vec4(position, 1.0); }
"""
_FRAGMENT_330 = """#version 330 core
out vec4 color;
void main() { color = vec4(1.0); }
"""


class GLUnavailableError(OSError):
    """No OpenGL 3.3 context can be made here; the message says why."""


@dataclass(frozen=True)
class GLSupport:
    """What :func:`probe_gl` found: ``problem`` is "" when a usable 3.3 context was made."""

    problem: str
    #: GL_VERSION (or the context's version when no string could be read), "" without a context.
    version: str = ""
    #: GL_RENDERER, "" without a context.
    renderer: str = ""

    @property
    def ok(self) -> bool:
        return not self.problem

    @property
    def found(self) -> str:
        """What this machine gave, in words."""
        if not self.version:
            return "no OpenGL context"
        return f"OpenGL {self.version}" + (f" on {self.renderer}" if self.renderer else "")


def context_problem(context: QOpenGLContext | None) -> str:
    """"" when ``context`` is a valid OpenGL context of at least version 3.3, else why not
    ("OpenGL 2.1 < 3.3")."""
    if context is None or not context.isValid():
        return "no valid OpenGL context"
    fmt = context.format()
    version = (fmt.majorVersion(), fmt.minorVersion())
    if fmt.renderableType() == QSurfaceFormat.RenderableType.OpenGLES or context.isOpenGLES():
        return f"OpenGL ES {version[0]}.{version[1]} is not desktop OpenGL 3.3"
    if version < MIN_VERSION:
        return f"OpenGL {version[0]}.{version[1]} < {MIN_VERSION[0]}.{MIN_VERSION[1]}"
    return ""


def shader_problem() -> str:
    """Compile and link a trivial GLSL 330 core program in the current context: "" when it
    works, else the driver's log (or what went wrong calling it)."""
    from OpenGL import GL

    shaders: list[int] = []
    program = 0
    try:
        for kind, source in ((GL.GL_VERTEX_SHADER, _VERTEX_330), (GL.GL_FRAGMENT_SHADER, _FRAGMENT_330)):
            shader = int(GL.glCreateShader(kind))
            if not shader:
                return "glCreateShader failed (no current OpenGL context?)"
            shaders.append(shader)
            GL.glShaderSource(shader, source)
            GL.glCompileShader(shader)
            if not GL.glGetShaderiv(shader, GL.GL_COMPILE_STATUS):
                return "a GLSL 330 shader does not compile: " + _text(GL.glGetShaderInfoLog(shader))
        program = int(GL.glCreateProgram())
        for shader in shaders:
            GL.glAttachShader(program, shader)
        GL.glLinkProgram(program)
        if not GL.glGetProgramiv(program, GL.GL_LINK_STATUS):
            return "a GLSL 330 program does not link: " + _text(GL.glGetProgramInfoLog(program))
        return ""
    except Exception as exc:  # noqa: BLE001 - PyOpenGL raises many kinds; each means "no"
        return f"OpenGL calls fail: {exc}"
    finally:
        try:
            for shader in shaders:
                GL.glDeleteShader(shader)
            if program:
                GL.glDeleteProgram(program)
        except Exception:  # noqa: BLE001,S110 - nothing to clean up without a context
            pass


def _text(value: object) -> str:
    text = value.decode(errors="replace") if isinstance(value, bytes) else str(value or "")
    return text.strip() or "(the driver gave no log)"


def current_gl_strings() -> tuple[str, str]:
    """GL_VERSION and GL_RENDERER of the current context ("" each when they cannot be read)."""
    try:
        from OpenGL import GL

        return _string(GL.glGetString(GL.GL_VERSION)), _string(GL.glGetString(GL.GL_RENDERER))
    except Exception:  # noqa: BLE001 - no current context
        return "", ""


def _string(value: object) -> str:
    return value.decode(errors="replace") if isinstance(value, bytes) else str(value or "")


_probed: list[GLSupport] = []


def probe_gl() -> GLSupport:
    """Can a usable OpenGL 3.3 core context be made here? Asked once per process with a
    throw-away offscreen context (about 40 ms on llvmpipe, nothing on a platform without
    OpenGL); needs a QGuiApplication."""
    if not _probed:
        if QGuiApplication.instance() is None:  # asked again once there is one
            return GLSupport("no QGuiApplication to make an OpenGL context with")
        _probed.append(_probe())
        support = _probed[0]
        if support.ok:
            log.info("3D view: %s", support.found)
    return _probed[0]


def _probe() -> GLSupport:
    from qtanimator.render.gl import surface_format

    platform = QGuiApplication.platformName()
    context = QOpenGLContext()
    context.setFormat(surface_format(0))
    if not context.create():
        return GLSupport(f"no OpenGL context can be made on the Qt platform '{platform}'")
    surface = QOffscreenSurface()
    surface.setFormat(context.format())
    surface.create()
    try:
        if not context.makeCurrent(surface):
            return GLSupport("the OpenGL context cannot be made current")
        version, renderer = current_gl_strings()
        if not version:
            fmt = context.format()
            version = f"{fmt.majorVersion()}.{fmt.minorVersion()}"
        problem = context_problem(context) or shader_problem()
        context.doneCurrent()
        return GLSupport(problem, version, renderer)
    finally:
        surface.destroy()


def forget_probe() -> None:
    """Probe again at the next :func:`probe_gl` (tests)."""
    _probed.clear()


def unavailable_text(problem: str, found: str = "", stopped: bool = False) -> str:
    """The 3D view's message when it cannot draw (plain text, a few short paragraphs);
    ``stopped``: it drew before (a lost context, an error while drawing)."""
    if stopped:
        parts = [f"The 3D view stopped drawing: {problem}." + (f" (Its context: {found}.)" if found else ""),
                 "The details are in the log (Help ▸ Report a Problem). Restart qtanimator to get the 3D "
                 "view back; save your work first."]
    elif found and found != "no OpenGL context":
        parts = [f"The 3D view needs {NEEDED}. This system gave {found} ({problem})."]
    else:
        parts = [f"The 3D view needs {NEEDED}, and none could be had here: {problem}."]
    hints = []
    for name in ("MESA_GL_VERSION_OVERRIDE", "MESA_GLSL_VERSION_OVERRIDE") if not stopped else ():
        if os.environ.get(name):
            hints.append(f"{name}={os.environ[name]}")
    if hints:
        parts.append(f"The environment sets {' and '.join(hints)}: "
                     f"unset {'them' if len(hints) > 1 else 'it'} to get the driver's own version.")
    elif stopped:
        pass
    elif "platform 'offscreen'" in problem or "platform 'minimal'" in problem:
        parts.append("Start qtanimator on a display (X11 or Wayland) to use the 3D view.")
    else:
        parts.append("Update the graphics driver, or run on a machine whose OpenGL supports 3.3.")
    parts.append("Everything else still works: the 2D editor, the curve editor, the dope sheet and the "
                 "outliner (3D characters you open are there), and headless 2D rendering "
                 "(qtanimator render --view 2d).")
    return "\n\n".join(parts)


_logged: set[str] = set()


def log_unavailable(problem: str, found: str = "") -> bool:
    """Log why the 3D view cannot draw, once per problem per process. True when logged now."""
    if problem in _logged:
        return False
    _logged.add(problem)
    log.warning("3D view disabled: needs %s; found %s: %s", NEEDED, found or "no OpenGL context", problem)
    return True


__all__ = [
    "MIN_VERSION",
    "NEEDED",
    "GLSupport",
    "GLUnavailableError",
    "context_problem",
    "current_gl_strings",
    "forget_probe",
    "log_unavailable",
    "probe_gl",
    "shader_problem",
    "unavailable_text",
]
