"""GPU meshes: vertex arrays for static, dynamic, instanced and GPU-skinned triangle meshes,
plus the primitive shapes the viewport draws (box, sphere, cylinder, plane, grid lines).

Attribute locations match ``resources/shaders/mesh.vert``.
"""

from __future__ import annotations

import ctypes
import math

import numpy as np
from OpenGL import GL

A_POSITION, A_NORMAL, A_COLOR, A_INFLUENCE, A_MODEL, A_ICOLOR, A_TEXCOORD = 0, 1, 2, 3, 4, 8, 9


def _buffer(target: int, data: np.ndarray, usage: int = GL.GL_STATIC_DRAW) -> int:
    buf = int(GL.glGenBuffers(1))
    GL.glBindBuffer(target, buf)
    GL.glBufferData(target, data.nbytes, data, usage)
    return buf


def _attribute(loc: int, buf: int, size: int, stride: int = 0, offset: int = 0, divisor: int = 0) -> None:
    GL.glBindBuffer(GL.GL_ARRAY_BUFFER, buf)
    GL.glEnableVertexAttribArray(loc)
    GL.glVertexAttribPointer(loc, size, GL.GL_FLOAT, GL.GL_FALSE, stride, ctypes.c_void_p(offset))
    if divisor:
        GL.glVertexAttribDivisor(loc, divisor)


class Mesh:
    """Indexed geometry in a vertex array object. ``mode`` is GL_TRIANGLES or GL_LINES."""

    def __init__(self, positions: np.ndarray, normals: np.ndarray | None, indices: np.ndarray,
                 colors: np.ndarray | None = None, dynamic: bool = False, mode: int = GL.GL_TRIANGLES) -> None:
        self.mode = mode
        usage = GL.GL_DYNAMIC_DRAW if dynamic else GL.GL_STATIC_DRAW
        positions = np.ascontiguousarray(positions, dtype=np.float32).reshape(-1, 3)
        if normals is None:
            normals = np.zeros_like(positions)
            normals[:, 1] = 1.0
        normals = np.ascontiguousarray(normals, dtype=np.float32).reshape(-1, 3)
        self.vertex_count = len(positions)
        self.vao = int(GL.glGenVertexArrays(1))
        GL.glBindVertexArray(self.vao)
        self.vbo_pos = _buffer(GL.GL_ARRAY_BUFFER, positions, usage)
        _attribute(A_POSITION, self.vbo_pos, 3)
        self.vbo_nrm = _buffer(GL.GL_ARRAY_BUFFER, normals, usage)
        _attribute(A_NORMAL, self.vbo_nrm, 3)
        self.vbo_col = 0
        if colors is not None:
            self.vbo_col = _buffer(GL.GL_ARRAY_BUFFER, np.ascontiguousarray(colors, dtype=np.float32))
            _attribute(A_COLOR, self.vbo_col, 4)
        idx = np.ascontiguousarray(indices, dtype=np.uint32).ravel()
        self.index_count = len(idx)
        self.ibo = _buffer(GL.GL_ELEMENT_ARRAY_BUFFER, idx)
        self.vbo_inst = 0
        self.instance_count = 0
        GL.glBindVertexArray(0)

    def update(self, positions: np.ndarray, normals: np.ndarray | None = None) -> None:
        """Replace vertex positions (and normals) of a dynamic mesh; same vertex count."""
        p = np.ascontiguousarray(positions, dtype=np.float32)
        GL.glBindBuffer(GL.GL_ARRAY_BUFFER, self.vbo_pos)
        GL.glBufferSubData(GL.GL_ARRAY_BUFFER, 0, p.nbytes, p)
        if normals is not None:
            n = np.ascontiguousarray(normals, dtype=np.float32)
            GL.glBindBuffer(GL.GL_ARRAY_BUFFER, self.vbo_nrm)
            GL.glBufferSubData(GL.GL_ARRAY_BUFFER, 0, n.nbytes, n)

    def set_instances(self, models: np.ndarray, colors: np.ndarray) -> None:
        """Per-instance model matrices (K, 4, 4) and colours (K, 4) for instanced drawing."""
        k = len(models)
        data = np.empty((k, 20), dtype=np.float32)
        # columns of each column-vector matrix, as mesh.vert reads them
        data[:, :16] = np.asarray(models, dtype=np.float32).transpose(0, 2, 1).reshape(k, 16)
        data[:, 16:] = colors
        GL.glBindVertexArray(self.vao)
        if not self.vbo_inst:
            self.vbo_inst = int(GL.glGenBuffers(1))
            GL.glBindBuffer(GL.GL_ARRAY_BUFFER, self.vbo_inst)
            for c in range(4):
                _attribute(A_MODEL + c, self.vbo_inst, 4, 80, 16 * c, divisor=1)
            _attribute(A_ICOLOR, self.vbo_inst, 4, 80, 64, divisor=1)
        GL.glBindBuffer(GL.GL_ARRAY_BUFFER, self.vbo_inst)
        GL.glBufferData(GL.GL_ARRAY_BUFFER, data.nbytes, data, GL.GL_DYNAMIC_DRAW)
        GL.glBindVertexArray(0)
        self.instance_count = k

    def draw(self, instanced: bool = False) -> None:
        GL.glBindVertexArray(self.vao)
        if instanced:
            if self.instance_count:
                GL.glDrawElementsInstanced(self.mode, self.index_count, GL.GL_UNSIGNED_INT, None,
                                           self.instance_count)
        else:
            GL.glDrawElements(self.mode, self.index_count, GL.GL_UNSIGNED_INT, None)
        GL.glBindVertexArray(0)

    def draw_range(self, first: int, count: int) -> None:
        """Draw ``count`` indices from index ``first`` (one part of the mesh)."""
        if count <= 0:
            return
        GL.glBindVertexArray(self.vao)
        GL.glDrawElements(self.mode, count, GL.GL_UNSIGNED_INT, ctypes.c_void_p(4 * first))
        GL.glBindVertexArray(0)

    def delete(self) -> None:
        bufs = [b for b in (self.vbo_pos, self.vbo_nrm, self.vbo_col, self.ibo, self.vbo_inst) if b]
        GL.glDeleteBuffers(len(bufs), bufs)
        GL.glDeleteVertexArrays(1, [self.vao])


class TextureBuffer:
    """A buffer texture (samplerBuffer) of RGBA32F or RG32F texels."""

    def __init__(self, data: np.ndarray, internal: int) -> None:
        self.internal = internal
        self.buf = _buffer(GL.GL_TEXTURE_BUFFER, np.ascontiguousarray(data, dtype=np.float32), GL.GL_DYNAMIC_DRAW)
        self.tex = int(GL.glGenTextures(1))
        GL.glBindTexture(GL.GL_TEXTURE_BUFFER, self.tex)
        GL.glTexBuffer(GL.GL_TEXTURE_BUFFER, internal, self.buf)
        GL.glBindTexture(GL.GL_TEXTURE_BUFFER, 0)
        self.nbytes = data.nbytes

    def update(self, data: np.ndarray) -> None:
        d = np.ascontiguousarray(data, dtype=np.float32)
        GL.glBindBuffer(GL.GL_TEXTURE_BUFFER, self.buf)
        if d.nbytes != self.nbytes:
            GL.glBufferData(GL.GL_TEXTURE_BUFFER, d.nbytes, d, GL.GL_DYNAMIC_DRAW)
            self.nbytes = d.nbytes
        else:
            GL.glBufferSubData(GL.GL_TEXTURE_BUFFER, 0, d.nbytes, d)

    def bind(self, unit: int) -> None:
        GL.glActiveTexture(GL.GL_TEXTURE0 + unit)
        GL.glBindTexture(GL.GL_TEXTURE_BUFFER, self.tex)

    def delete(self) -> None:
        GL.glDeleteTextures(1, [self.tex])
        GL.glDeleteBuffers(1, [self.buf])


def csr_influences(indptr: np.ndarray, joints: np.ndarray, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(first, count) per vertex and the (joint, weight) list from CSR arrays."""
    indptr = np.asarray(indptr)
    first, counts = indptr[:-1], np.diff(indptr)
    return np.c_[first, counts].astype(np.float32), np.c_[joints, weights].astype(np.float32)


class SkinnedMesh(Mesh):
    """A mesh skinned in the vertex shader from its bind pose.

    ``influence`` is (N, 2): each vertex's first entry and count in ``pairs``, the flat
    (joint, weight) list (see :func:`csr_influences`). Call
    :meth:`set_joint_matrices` with M_j = W_j·B_j⁻¹ (J, 4, 4) every frame: the only
    per-frame upload is J·64 bytes.
    """

    def __init__(self, positions: np.ndarray, normals: np.ndarray | None, triangles: np.ndarray,
                 influence: np.ndarray, pairs: np.ndarray, joint_count: int,
                 texcoords: np.ndarray | None = None) -> None:
        super().__init__(positions, normals, triangles)
        influence = np.ascontiguousarray(influence, dtype=np.float32)
        pairs = np.ascontiguousarray(pairs, dtype=np.float32).reshape(-1, 2)
        if len(pairs) == 0:
            pairs = np.zeros((1, 2), np.float32)
        self.joint_count = int(joint_count)
        self.max_influences = int(influence[:, 1].max()) if len(influence) else 0
        GL.glBindVertexArray(self.vao)
        self.vbo_inf = _buffer(GL.GL_ARRAY_BUFFER, influence)
        _attribute(A_INFLUENCE, self.vbo_inf, 2)
        self.vbo_uv = 0
        if texcoords is not None:  # (N, 2), t = 0 at the image's top row
            self.vbo_uv = _buffer(GL.GL_ARRAY_BUFFER, np.ascontiguousarray(texcoords, dtype=np.float32).reshape(-1, 2))
            _attribute(A_TEXCOORD, self.vbo_uv, 2)
        GL.glBindVertexArray(0)
        self.influences = TextureBuffer(pairs, GL.GL_RG32F)
        self.joints = TextureBuffer(np.tile(np.eye(4, dtype=np.float32), (max(self.joint_count, 1), 1, 1)),
                                    GL.GL_RGBA32F)

    def set_joint_matrices(self, matrices: np.ndarray) -> None:
        m = np.asarray(matrices, dtype=np.float32)
        # texel 4j+c holds column c of joint j's column-vector matrix
        self.joints.update(np.ascontiguousarray(m.transpose(0, 2, 1)))

    def bind_textures(self) -> None:
        self.joints.bind(0)
        self.influences.bind(1)
        GL.glActiveTexture(GL.GL_TEXTURE0)

    def delete(self) -> None:
        GL.glDeleteBuffers(1, [self.vbo_inf])
        if self.vbo_uv:
            GL.glDeleteBuffers(1, [self.vbo_uv])
        self.influences.delete()
        self.joints.delete()
        super().delete()


# ------------------------------------------------------------------ primitives
def box_geometry() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The unit cube [0, 1]³ with one normal per face (24 vertices, 12 triangles)."""
    pos: list[np.ndarray] = []
    nrm: list[np.ndarray] = []
    tri: list[tuple[int, int, int]] = []
    for axis in range(3):
        for side in (0.0, 1.0):
            n = np.zeros(3)
            n[axis] = 1.0 if side else -1.0
            u, v = (axis + 1) % 3, (axis + 2) % 3
            base = len(pos)
            for a, b in ((0, 0), (1, 0), (1, 1), (0, 1)):
                p = np.zeros(3)
                p[axis], p[u], p[v] = side, a, b
                pos.append(p)
                nrm.append(n)
            if side:
                tri += [(base, base + 1, base + 2), (base, base + 2, base + 3)]
            else:
                tri += [(base, base + 2, base + 1), (base, base + 3, base + 2)]
    return np.array(pos), np.array(nrm), np.array(tri)


def sphere_geometry(rings: int = 10, segments: int = 14) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The unit sphere (positions equal normals)."""
    pos = []
    for i in range(rings + 1):
        th = math.pi * i / rings
        for j in range(segments + 1):
            ph = 2 * math.pi * j / segments
            pos.append((math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph)))
    tri = []
    w = segments + 1
    for i in range(rings):
        for j in range(segments):
            a, b = i * w + j, (i + 1) * w + j
            tri += [(a, a + 1, b), (a + 1, b + 1, b)]
    p = np.array(pos)
    return p, p.copy(), np.array(tri)


def cylinder_geometry(sides: int = 8) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A radius-1 cylinder along +z from z = 0 to z = 1, with smooth side normals and caps."""
    pos, nrm, tri = [], [], []
    for j in range(sides + 1):
        a = 2 * math.pi * j / sides
        c, s = math.cos(a), math.sin(a)
        pos += [(c, s, 0.0), (c, s, 1.0)]
        nrm += [(c, s, 0.0), (c, s, 0.0)]
    for j in range(sides):
        a = 2 * j
        tri += [(a, a + 2, a + 1), (a + 1, a + 2, a + 3)]
    for z, nz in ((0.0, -1.0), (1.0, 1.0)):
        centre = len(pos)
        pos.append((0.0, 0.0, z))
        nrm.append((0.0, 0.0, nz))
        for j in range(sides + 1):
            a = 2 * math.pi * j / sides
            pos.append((math.cos(a), math.sin(a), z))
            nrm.append((0.0, 0.0, nz))
        for j in range(sides):
            t = (centre, centre + 1 + j, centre + 2 + j)
            tri.append(t if nz > 0 else (t[0], t[2], t[1]))
    return np.array(pos), np.array(nrm), np.array(tri)


def plane_geometry(size: float = 1.0, divisions: int = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A square in the y = 0 plane, centred at the origin, facing +y."""
    n = divisions + 1
    xs = np.linspace(-size / 2, size / 2, n)
    x, z = np.meshgrid(xs, xs)
    pos = np.c_[x.ravel(), np.zeros(n * n), z.ravel()]
    nrm = np.tile([0.0, 1.0, 0.0], (n * n, 1))
    tri = []
    for i in range(divisions):
        for j in range(divisions):
            a = i * n + j
            tri += [(a, a + n, a + 1), (a + 1, a + n, a + n + 1)]
    return pos, nrm, np.array(tri)


def grid_geometry(half_extent: float = 5.0, step: float = 0.5,
                  height: float = -2e-3) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Ground grid lines just below y = 0 (so a floor at 0 hides them): positions, colours
    (axes tinted), line indices."""
    n = int(round(half_extent / step))
    pos, col = [], []
    for i in range(-n, n + 1):
        v = i * step
        major = i % 2 == 0
        base = (0.42, 0.42, 0.45, 1.0) if major else (0.32, 0.32, 0.35, 1.0)
        cx = (0.75, 0.3, 0.3, 1.0) if i == 0 else base   # line along x at z = 0
        cz = (0.3, 0.35, 0.8, 1.0) if i == 0 else base   # line along z at x = 0
        e = half_extent
        pos += [(-e, height, v), (e, height, v), (v, height, -e), (v, height, e)]
        col += [cx, cx, cz, cz]
    return np.array(pos), np.array(col), np.arange(len(pos))
