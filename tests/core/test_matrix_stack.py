import math

import numpy as np
import pytest

from qtanimator.core.matrix_stack import (
    MatrixStack,
    MatrixStackOverflow,
    MatrixStackUnderflow,
    rotation_x,
    rotation_y,
    rotation_z,
    scaling,
    translation,
)


def test_starts_with_identity_and_push_pop_restores():
    s = MatrixStack(4)
    assert np.array_equal(s.top, np.eye(4))
    s.translate(1, 2, 3)
    s.push()
    s.rotate_z(0.5)
    assert s.depth == 2
    popped = s.pop()
    assert np.allclose(popped, translation(1, 2, 3) @ rotation_z(0.5))
    assert np.allclose(s.top, translation(1, 2, 3))


def test_overflow_and_underflow_raise_clear_errors():
    s = MatrixStack(2)
    s.push()
    with pytest.raises(MatrixStackOverflow, match="overflow"):
        s.push()
    s.pop()
    with pytest.raises(MatrixStackUnderflow, match="underflow"):
        s.pop()
    assert s.depth == 1  # a failed pop leaves the stack usable


def test_transforms_post_multiply_in_order():
    s = MatrixStack()
    s.translate(1, 0, 0)
    s.rotate_x(0.3)
    s.rotate_y(-0.7)
    s.scale(2, 3, 4)
    expected = translation(1, 0, 0) @ rotation_x(0.3) @ rotation_y(-0.7) @ scaling(2, 3, 4)
    assert np.allclose(s.top, expected)
    s.multiply(rotation_z(1.0))
    assert np.allclose(s.top, expected @ rotation_z(1.0))
    s.load_identity()
    assert np.array_equal(s.top, np.eye(4))


def test_rotations_are_right_handed():
    # +90° about z takes x to y; about x takes y to z; about y takes z to x.
    assert np.allclose(rotation_z(math.pi / 2) @ [1, 0, 0, 1], [0, 1, 0, 1])
    assert np.allclose(rotation_x(math.pi / 2) @ [0, 1, 0, 1], [0, 0, 1, 1])
    assert np.allclose(rotation_y(math.pi / 2) @ [0, 0, 1, 1], [1, 0, 0, 1])


def test_top_is_a_copy_and_bad_shapes_are_refused():
    s = MatrixStack()
    t = s.top
    t[0, 3] = 5
    assert s.top[0, 3] == 0
    with pytest.raises(ValueError):
        s.multiply(np.eye(3))
    with pytest.raises(ValueError):
        MatrixStack(0)


def test_transform_points():
    s = MatrixStack()
    s.translate(0, 1, 0)
    s.scale(2)
    assert np.allclose(s.transform_points([[1, 1, 1]]), [[2, 3, 2]])
