"""Rotation helpers (core/rotation.py): the Euler filter's gimbal alternative with a
hand-computed angle set, and the Hamilton product on the unit quaternions."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.rotation import euler_filter, quaternion_multiply, rotation_matrices


@pytest.mark.parametrize("order", ["xyz", "zyx", "yxz"])
def test_euler_filter_takes_the_gimbal_alternative(order):
    # (a, b, c) in the order's axes and (a + π, π - b, c + π) are the same rotation. The
    # second sample is given as the alternative of (0.12, 0.22, 0.31) wrapped into (-π, π]:
    # (0.12 - π, π - 0.22, 0.31 - π); the filter must bring back (0.12, 0.22, 0.31).
    ia, ib, ic = ("xyz".index(ch) for ch in order)
    first = np.zeros(3)
    first[[ia, ib, ic]] = [0.1, 0.2, 0.3]
    near = np.zeros(3)
    near[[ia, ib, ic]] = [0.12, 0.22, 0.31]
    alt = np.zeros(3)
    alt[[ia, ib, ic]] = [0.12 - math.pi, math.pi - 0.22, 0.31 - math.pi]
    # precondition: the same rotation (so the input is a valid Euler sequence)
    np.testing.assert_allclose(rotation_matrices(alt[None], order), rotation_matrices(near[None], order), atol=1e-14)
    out = euler_filter([first, alt], order)
    np.testing.assert_allclose(out[0], first, atol=0)
    np.testing.assert_allclose(out[1], near, atol=1e-14)


@pytest.mark.parametrize("order", ["xyz", "zxy"])
def test_euler_filter_unwraps_whole_turns(order):
    e = np.array([[3.0, 0.1, -3.0], [3.1 - 2 * math.pi, 0.1, -3.1 + 2 * math.pi]])
    np.testing.assert_allclose(euler_filter(e, order)[1], [3.1, 0.1, -3.1], atol=1e-14)


I, J, K, ONE = (1.0, 0.0, 0.0, 0.0), (0.0, 1.0, 0.0, 0.0), (0.0, 0.0, 1.0, 0.0), (0.0, 0.0, 0.0, 1.0)


@pytest.mark.parametrize("a, b, expected", [
    (I, J, K), (J, K, I), (K, I, J),
    (J, I, (0.0, 0.0, -1.0, 0.0)), (K, J, (-1.0, 0.0, 0.0, 0.0)), (I, K, (0.0, -1.0, 0.0, 0.0)),
    (I, I, (0.0, 0.0, 0.0, -1.0)), (J, J, (0.0, 0.0, 0.0, -1.0)), (K, K, (0.0, 0.0, 0.0, -1.0)),
    (ONE, J, J), (J, ONE, J),
])
def test_hamilton_product_of_the_units(a, b, expected):
    # i·j = k, j·k = i, k·i = j, the reverse products negated, i² = j² = k² = -1 (x, y, z, w)
    np.testing.assert_array_equal(quaternion_multiply(a, b), expected)


def test_hamilton_product_general():
    # (1 + 2i + 3j + 4k)(5 + 6i + 7j + 8k) = -60 + 12i + 30j + 24k (expanded by hand)
    p = (2.0, 3.0, 4.0, 1.0)
    q = (6.0, 7.0, 8.0, 5.0)
    np.testing.assert_array_equal(quaternion_multiply(p, q), [12.0, 30.0, 24.0, -60.0])
