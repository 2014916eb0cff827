"""Matrix stack (core/matrix_stack.py): the elementary matrices against Rodrigues' formula,
and every operation on the top of a stack deeper than one."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.matrix_stack import (
    MatrixStack,
    rotation_x,
    rotation_y,
    rotation_z,
    scaling,
    translation,
)


def _rodrigues(axis, angle):
    """4×4 rotation by ``angle`` about the unit ``axis``: I + sin·K + (1 − cos)·K²."""
    x, y, z = axis
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    m = np.eye(4)
    m[:3, :3] = np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * (k @ k)
    return m


@pytest.mark.parametrize("angle", [0.3, -1.1, 2.5])
def test_elementary_rotations_match_rodrigues(angle):
    """Each entry of rotation_x/y/z (sign and place of every sine) against an independent formula."""
    np.testing.assert_allclose(rotation_x(angle), _rodrigues((1, 0, 0), angle), atol=1e-15)
    np.testing.assert_allclose(rotation_y(angle), _rodrigues((0, 1, 0), angle), atol=1e-15)
    np.testing.assert_allclose(rotation_z(angle), _rodrigues((0, 0, 1), angle), atol=1e-15)


def test_translation_and_scaling_matrices():
    """translation puts (x, y, z) in the last column; scaling on the diagonal, w stays 1."""
    expected = np.eye(4)
    expected[:3, 3] = [1.5, -2.0, 3.25]
    np.testing.assert_array_equal(translation(1.5, -2.0, 3.25), expected)
    np.testing.assert_array_equal(scaling(2, 3, 4), np.diag([2.0, 3.0, 4.0, 1.0]))


def test_operations_act_on_the_top_of_a_deeper_stack():
    """With three matrices on the stack every operation reads and writes the top one only:
    the base and the middle matrix come back untouched by pops (catches an off-by-one index)."""
    s = MatrixStack(5)
    s.translate(1.0, 2.0, 3.0)
    base = translation(1.0, 2.0, 3.0)
    s.push()
    s.rotate_z(math.pi / 2)
    middle = base @ rotation_z(math.pi / 2)
    s.push()
    assert len(s) == s.depth == 3
    np.testing.assert_allclose(s.top, middle, atol=1e-15)
    s.scale(2.0)
    s.translate(1.0, 0.0, 0.0)
    top = middle @ scaling(2, 2, 2) @ translation(1, 0, 0)
    np.testing.assert_allclose(s.top, top, atol=1e-15)
    # (1, 0, 0) -> translate 1 in x: (2, 0, 0) -> scale 2: (4, 0, 0) -> rotate z 90°: (0, 4, 0) -> + (1, 2, 3)
    np.testing.assert_allclose(s.transform_points([[1.0, 0.0, 0.0]]), [[1.0, 6.0, 3.0]], atol=1e-14)
    s.load(np.diag([1.0, 2.0, 3.0, 1.0]))
    np.testing.assert_array_equal(s.top, np.diag([1.0, 2.0, 3.0, 1.0]))
    s.load_identity()
    np.testing.assert_array_equal(s.top, np.eye(4))
    np.testing.assert_array_equal(s.pop(), np.eye(4))
    np.testing.assert_allclose(s.top, middle, atol=1e-15)
    np.testing.assert_allclose(s.pop(), middle, atol=1e-15)
    np.testing.assert_array_equal(s.top, base)
    assert s.depth == 1


def test_capacity_is_exact():
    """A stack of capacity 3 holds exactly three matrices."""
    s = MatrixStack(3)
    s.push()
    s.push()
    assert s.depth == 3
    with pytest.raises(RuntimeError):
        s.push()
    np.testing.assert_array_equal(s.top, np.eye(4))
    assert MatrixStack(1).depth == 1


def test_load_and_multiply_accept_nested_lists():
    """A 4×4 list of lists is a matrix; multiply post-multiplies it."""
    s = MatrixStack()
    s.load(translation(0.0, 1.0, 0.0).tolist())
    s.multiply(scaling(2, 2, 2).tolist())
    np.testing.assert_allclose(s.transform_points([[1.0, 1.0, 1.0]]), [[2.0, 3.0, 2.0]])
