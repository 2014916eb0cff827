"""Rotation helpers (core/rotation.py): the Euler filter's gimbal alternative with a
hand-computed angle set, the Hamilton product on the unit quaternions, and the quaternion
helpers against Rodrigues' formula, a finite difference and closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.rotation import (
    IDENTITY,
    axis_quaternions,
    euler_filter,
    euler_quaternions_with_rates,
    euler_to_quaternions,
    matrices_to_quaternions,
    normalize,
    polar,
    quaternion_conjugate,
    quaternion_multiply,
    quaternion_to_matrix,
    quaternions_to_euler,
    rotation_matrices,
    same_hemisphere,
    slerp,
    trs_matrix,
)


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


def _rodrigues(axis, angle):
    """3×3 rotation by ``angle`` about the unit ``axis``: I + sin·K + (1 − cos)·K²."""
    x, y, z = axis
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * (k @ k)


def _euler_matrix(angles, order):
    """R_a·R_b·R_c for order "abc", each factor by Rodrigues about its coordinate axis."""
    m = np.eye(3)
    for ch in order:
        i = "xyz".index(ch)
        m = m @ _rodrigues(np.eye(3)[i], angles[i])
    return m


def test_quaternion_to_matrix_is_the_axis_angle_rotation():
    """(sin(θ/2)·n, cos(θ/2)) is the rotation by θ about the unit n."""
    n = np.array([1.0, -2.0, 2.0]) / 3.0
    for theta in (0.4, 2.0, -1.3):
        q = np.concatenate([math.sin(theta / 2) * n, [math.cos(theta / 2)]])
        np.testing.assert_allclose(quaternion_to_matrix(q), _rodrigues(n, theta), atol=1e-14)


@pytest.mark.parametrize("order", ["xyz", "zyx", "yzx"])
def test_euler_quaternions_and_their_rates(order):
    """q represents R_a·R_b·R_c; dq is the time derivative of q along angles + t·rates (central
    difference, step 1e-6); without rates there is no derivative."""
    angles = np.array([[0.3, -0.7, 1.1], [2.0, 0.4, -2.5]])
    rates = np.array([[1.5, -0.5, 2.0], [-3.0, 0.7, 0.2]])
    q, dq = euler_quaternions_with_rates(angles, rates, order)
    for k in range(2):
        np.testing.assert_allclose(quaternion_to_matrix(q[k]), _euler_matrix(angles[k], order), atol=1e-14)
    h = 1e-6
    qp, _ = euler_quaternions_with_rates(angles + h * rates, None, order)
    qm, _ = euler_quaternions_with_rates(angles - h * rates, None, order)
    np.testing.assert_allclose(dq, (qp - qm) / (2 * h), atol=1e-8)
    q2, none = euler_quaternions_with_rates(angles, None, order)
    assert none is None
    np.testing.assert_array_equal(q2, q)


@pytest.mark.parametrize("order", ["xyz", "xzy", "yxz", "yzx", "zxy", "zyx"])
def test_euler_to_quaternions_and_back(order):
    """Angles with the middle one in (-π/2, π/2) come back exactly from the quaternion, which has
    w >= 0 and represents R_a·R_b·R_c."""
    angles = np.array([[0.3, -0.7, 1.1], [-2.9, 1.2, 0.05], [0.0, 0.0, 0.0]])
    mid = "xyz".index(order[1])
    angles[:, mid] = np.clip(angles[:, mid], -1.2, 1.2)
    q = euler_to_quaternions(angles, order)
    assert np.all(q[:, 3] >= 0.0)
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-15)
    for k in range(len(angles)):
        np.testing.assert_allclose(quaternion_to_matrix(q[k]), _euler_matrix(angles[k], order), atol=1e-14)
    np.testing.assert_allclose(quaternions_to_euler(q, order), angles, atol=1e-12)


def test_slerp_turns_at_constant_speed():
    """From 0 to 2 rad about z, u of the way is 2u rad about z (sin(u), cos(u) in z, w)."""
    a = np.array([0.0, 0.0, 0.0, 1.0])
    b = np.array([0.0, 0.0, math.sin(1.0), math.cos(1.0)])
    u = np.array([0.0, 0.25, 0.5, 0.9, 1.0])
    expected = np.stack([np.zeros(5), np.zeros(5), np.sin(u), np.cos(u)], axis=1)
    np.testing.assert_allclose(slerp(a, b, u), expected, atol=1e-14)
    # -b is the same rotation: the short way gives the same curve up to the sign at the end
    np.testing.assert_allclose(slerp(a, -b, u), expected, atol=1e-14)


def test_conjugate_normalize_and_hemisphere():
    """q·q* = 1; a zero quaternion stays zero under normalize; same_hemisphere flips only when
    the dot product with the reference is negative."""
    q = normalize([1.0, 2.0, -2.0, 4.0])
    np.testing.assert_allclose(np.linalg.norm(q), 1.0)
    np.testing.assert_allclose(quaternion_multiply(q, quaternion_conjugate(q)), [0, 0, 0, 1], atol=1e-15)
    np.testing.assert_array_equal(quaternion_conjugate([1.0, 2.0, 3.0, 4.0]), [-1.0, -2.0, -3.0, 4.0])
    np.testing.assert_array_equal(normalize(np.zeros((2, 4))), np.zeros((2, 4)))
    ref = np.array([0.0, 0.0, 0.0, 1.0])
    np.testing.assert_array_equal(same_hemisphere([0.6, 0.0, 0.0, -0.8], ref), [-0.6, 0.0, 0.0, 0.8])
    np.testing.assert_array_equal(same_hemisphere([0.6, 0.0, 0.0, 0.8], ref), [0.6, 0.0, 0.0, 0.8])


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_axis_quaternions(axis):
    """The rotation by θ about one coordinate axis: sin(θ/2) in that slot, cos(θ/2) in w."""
    theta = np.array([[0.5, -1.0], [2.0, 3.0]])
    q = axis_quaternions(theta, axis)
    assert q.shape == (2, 2, 4)
    expected = np.zeros((2, 2, 4))
    expected[..., axis] = np.sin(theta / 2)
    expected[..., 3] = np.cos(theta / 2)
    np.testing.assert_array_equal(q, expected)


@pytest.mark.parametrize("axis, theta", [
    ((3.0, 1.0, -1.0), 2.8), ((1.0, 3.0, 1.0), 2.8), ((-1.0, 1.0, 3.0), 2.8), ((0.0, 0.0, 1.0), -2.9),
    ((1.0, 1.0, 1.0), 2.5), ((1.0, -2.0, 2.0), 0.3),
])
def test_matrices_to_quaternions_for_every_pivot(axis, theta):
    """Rotations by nearly π about axes mostly along x, y or z make that diagonal term the
    largest (each pivot of Shepperd's method), a small angle the trace: all give
    (sin(θ/2)·n, cos(θ/2)) with w >= 0."""
    n = np.asarray(axis) / np.linalg.norm(axis)
    q = matrices_to_quaternions(_rodrigues(n, theta)[None])[0]
    expected = np.concatenate([math.sin(theta / 2) * n, [math.cos(theta / 2)]])
    expected *= 1.0 if expected[3] >= 0 else -1.0
    np.testing.assert_allclose(q, expected, atol=1e-14)


def test_trs_and_polar():
    """trs_matrix is T·R·S; polar splits R·P back into the rotation and the stretch."""
    n = np.array([0.0, 0.6, 0.8])
    q = np.concatenate([math.sin(0.35) * n, [math.cos(0.35)]])
    m = trs_matrix([1.0, 2.0, 3.0], q, [2.0, 0.5, 3.0])
    expected = np.eye(4)
    expected[:3, :3] = _rodrigues(n, 0.7) @ np.diag([2.0, 0.5, 3.0])
    expected[:3, 3] = [1.0, 2.0, 3.0]
    np.testing.assert_allclose(m, expected, atol=1e-14)
    r, p = polar(m[:3, :3])
    np.testing.assert_allclose(r, _rodrigues(n, 0.7), atol=1e-12)
    np.testing.assert_allclose(p, np.diag([2.0, 0.5, 3.0]), atol=1e-12)


def test_euler_filter_of_one_sample_is_that_sample():
    np.testing.assert_array_equal(euler_filter([[0.1, 4.0, -5.0]], "xyz"), [[0.1, 4.0, -5.0]])


def test_identity_is_the_unit_quaternion_of_no_rotation():
    """(x, y, z, w) = (0, 0, 0, 1) (the module's convention, glTF's order): no rotation,
    and the neutral element of the Hamilton product."""
    np.testing.assert_array_equal(IDENTITY, [0.0, 0.0, 0.0, 1.0])
    np.testing.assert_allclose(quaternion_to_matrix(IDENTITY), np.eye(3), atol=0.0)
    q = axis_quaternions(np.array([0.7]), 1)[0]
    np.testing.assert_allclose(quaternion_multiply(IDENTITY, q), q, atol=1e-15)
