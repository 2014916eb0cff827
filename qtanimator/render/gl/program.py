"""GLSL programs loaded from ``resources/shaders`` with a small typed uniform setter."""

from __future__ import annotations

import ctypes
from collections.abc import Sequence
from typing import Any

import numpy as np
from OpenGL import GL

from qtanimator.paths import shader_path


class ShaderError(RuntimeError):
    """A shader failed to compile or link; the message holds the driver's log."""


def _compile(kind: int, source: str, name: str) -> int:
    shader = GL.glCreateShader(kind)
    GL.glShaderSource(shader, source)
    GL.glCompileShader(shader)
    if not GL.glGetShaderiv(shader, GL.GL_COMPILE_STATUS):
        log = GL.glGetShaderInfoLog(shader)
        GL.glDeleteShader(shader)
        raise ShaderError(f"{name}: {log.decode(errors='replace') if isinstance(log, bytes) else log}")
    return int(shader)


class Program:
    """A linked program from ``<vert>.vert`` and ``<frag>.frag`` in resources/shaders.

    ``feedback`` names vertex outputs to capture with transform feedback (interleaved).
    """

    def __init__(self, vert: str, frag: str, feedback: Sequence[str] = ()) -> None:
        vs = _compile(GL.GL_VERTEX_SHADER, shader_path(vert).read_text(), vert)
        fs = _compile(GL.GL_FRAGMENT_SHADER, shader_path(frag).read_text(), frag)
        self.id = int(GL.glCreateProgram())
        GL.glAttachShader(self.id, vs)
        GL.glAttachShader(self.id, fs)
        if feedback:
            names = (ctypes.c_char_p * len(feedback))(*[n.encode() for n in feedback])
            GL.glTransformFeedbackVaryings(self.id, len(feedback),
                                           ctypes.cast(names, ctypes.POINTER(ctypes.POINTER(ctypes.c_char))),
                                           GL.GL_INTERLEAVED_ATTRIBS)
        GL.glLinkProgram(self.id)
        GL.glDeleteShader(vs)
        GL.glDeleteShader(fs)
        if not GL.glGetProgramiv(self.id, GL.GL_LINK_STATUS):
            log = GL.glGetProgramInfoLog(self.id)
            raise ShaderError(f"{vert}+{frag}: {log.decode(errors='replace') if isinstance(log, bytes) else log}")
        self._locations: dict[str, int] = {}

    def use(self) -> None:
        GL.glUseProgram(self.id)

    def location(self, name: str) -> int:
        loc = self._locations.get(name)
        if loc is None:
            loc = int(GL.glGetUniformLocation(self.id, name))
            self._locations[name] = loc
        return loc

    def set(self, name: str, value: Any) -> None:
        """Set a uniform of the bound program: int, float, vec2/3/4, mat4, or arrays of vec3."""
        loc = self.location(name)
        if loc < 0:
            return
        if isinstance(value, bool | int | np.integer):
            GL.glUniform1i(loc, int(value))
            return
        if isinstance(value, float | np.floating):
            GL.glUniform1f(loc, float(value))
            return
        a = np.asarray(value, dtype=np.float32)
        if a.shape == (4, 4):
            # numpy is row-major: transpose so that GL sees the column-vector matrix
            GL.glUniformMatrix4fv(loc, 1, GL.GL_TRUE, a)
        elif a.shape == (3,):
            GL.glUniform3fv(loc, 1, a)
        elif a.shape == (4,):
            GL.glUniform4fv(loc, 1, a)
        elif a.shape == (2,):
            GL.glUniform2fv(loc, 1, a)
        elif a.ndim == 2 and a.shape[1] == 3:
            GL.glUniform3fv(loc, a.shape[0], np.ascontiguousarray(a))
        else:
            raise ValueError(f"uniform {name}: unsupported shape {a.shape}")

    def delete(self) -> None:
        if self.id:
            GL.glDeleteProgram(self.id)
            self.id = 0
