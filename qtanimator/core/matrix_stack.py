"""The matrix stack of the lecture notes, as real API.

A :class:`MatrixStack` holds 4×4 float64 matrices (column vectors). It starts with one
identity matrix; ``push`` duplicates the top, ``pop`` discards it. Every transform
post-multiplies the top (``top = top · M``), like OpenGL's fixed pipeline, so a
hierarchy is drawn by ``push``, ``translate``/``rotate_*`` for the joint, recurse, ``pop``.

The capacity is fixed when the stack is made. Pushing onto a full stack raises
:class:`MatrixStackOverflow`; popping the last matrix raises :class:`MatrixStackUnderflow`.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

Matrix = npt.NDArray[np.float64]


class MatrixStackError(RuntimeError):
    """Base class of the matrix stack's errors."""


class MatrixStackOverflow(MatrixStackError):
    """``push`` on a full stack."""


class MatrixStackUnderflow(MatrixStackError):
    """``pop`` with only the base matrix left."""


def translation(x: float, y: float, z: float) -> Matrix:
    m = np.eye(4)
    m[0, 3], m[1, 3], m[2, 3] = x, y, z
    return m


def rotation_x(angle: float) -> Matrix:
    c, s = math.cos(angle), math.sin(angle)
    m = np.eye(4)
    m[1, 1], m[1, 2], m[2, 1], m[2, 2] = c, -s, s, c
    return m


def rotation_y(angle: float) -> Matrix:
    c, s = math.cos(angle), math.sin(angle)
    m = np.eye(4)
    m[0, 0], m[0, 2], m[2, 0], m[2, 2] = c, s, -s, c
    return m


def rotation_z(angle: float) -> Matrix:
    c, s = math.cos(angle), math.sin(angle)
    m = np.eye(4)
    m[0, 0], m[0, 1], m[1, 0], m[1, 1] = c, -s, s, c
    return m


def scaling(x: float, y: float, z: float) -> Matrix:
    return np.diag([float(x), float(y), float(z), 1.0])


class MatrixStack:
    """A fixed-capacity stack of 4×4 matrices; transforms post-multiply the top."""

    def __init__(self, capacity: int = 64) -> None:
        if capacity < 1:
            raise ValueError("a matrix stack needs room for at least one matrix")
        self.capacity = int(capacity)
        self._data = np.zeros((self.capacity, 4, 4))
        self._data[0] = np.eye(4)
        self._size = 1

    def __len__(self) -> int:
        return self._size

    @property
    def depth(self) -> int:
        """Number of matrices on the stack (1 when nothing was pushed)."""
        return self._size

    @property
    def top(self) -> Matrix:
        """A copy of the current (top) matrix."""
        return self._data[self._size - 1].copy()

    def push(self) -> None:
        """Duplicate the top matrix."""
        if self._size >= self.capacity:
            raise MatrixStackOverflow(
                f"matrix stack overflow: push onto a full stack (capacity {self.capacity}); "
                "a pop is missing or the hierarchy is deeper than the stack")
        self._data[self._size] = self._data[self._size - 1]
        self._size += 1

    def pop(self) -> Matrix:
        """Discard the top matrix and return it."""
        if self._size <= 1:
            raise MatrixStackUnderflow("matrix stack underflow: pop without a matching push")
        self._size -= 1
        return self._data[self._size].copy()

    def load_identity(self) -> None:
        self._data[self._size - 1] = np.eye(4)

    def load(self, matrix: npt.ArrayLike) -> None:
        """Replace the top matrix."""
        self._data[self._size - 1] = _as_matrix(matrix)

    def multiply(self, matrix: npt.ArrayLike) -> None:
        """``top = top · matrix``."""
        i = self._size - 1
        self._data[i] = self._data[i] @ _as_matrix(matrix)

    def translate(self, x: float, y: float, z: float) -> None:
        # Only the translation column changes: top[:, 3] += top[:, :3] · (x, y, z).
        top = self._data[self._size - 1]
        top[:, 3] += top[:, :3] @ np.array([x, y, z], dtype=np.float64)

    def rotate_x(self, angle: float) -> None:
        self.multiply(rotation_x(angle))

    def rotate_y(self, angle: float) -> None:
        self.multiply(rotation_y(angle))

    def rotate_z(self, angle: float) -> None:
        self.multiply(rotation_z(angle))

    def scale(self, x: float, y: float | None = None, z: float | None = None) -> None:
        """Scale by (x, y, z); ``scale(s)`` scales uniformly."""
        y = x if y is None else y
        z = x if z is None else z
        top = self._data[self._size - 1]
        top[:, :3] *= np.array([x, y, z], dtype=np.float64)

    def transform_points(self, points: npt.ArrayLike) -> Matrix:
        """Apply the top matrix to (N, 3) points."""
        p = np.asarray(points, dtype=np.float64)
        top = self._data[self._size - 1]
        result: Matrix = p @ top[:3, :3].T + top[:3, 3]
        return result


def _as_matrix(matrix: npt.ArrayLike) -> Matrix:
    m = np.asarray(matrix, dtype=np.float64)
    if m.shape != (4, 4):
        raise ValueError(f"expected a 4×4 matrix, got shape {m.shape}")
    return m
