"""The rotation module and quaternion-keyed channels, against closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.channel import Channel, Interpolation, Key, Tangent
from qtanimator.core.quaternion_channels import quaternions_at
from qtanimator.core.rotation import (
    ROTATION_ORDERS,
    euler_filter,
    euler_from_matrices,
    euler_to_quaternions,
    matrices_to_quaternions,
    quaternion_to_matrix,
    rotation_matrices,
    slerp,
)
from qtanimator.core.skeleton import Joint, Skeleton


def _about(axis, angle):
    """(x, y, z, w) of a turn by ``angle`` about a unit ``axis`` (closed form)."""
    a = np.asarray(axis, dtype=float)
    return np.array([*(a * math.sin(angle / 2)), math.cos(angle / 2)])


def test_slerp_turns_at_a_constant_rate_about_the_fixed_axis():
    axis = np.array([1.0, 2.0, 2.0]) / 3.0
    a, b = _about(axis, 0.3), _about(axis, 2.5)
    for u in (0.0, 0.25, 0.5, 0.9, 1.0):
        assert np.allclose(slerp(a, b, u), _about(axis, 0.3 + u * 2.2), atol=1e-12)


def test_slerp_takes_the_short_way_round():
    # 350° about z is −10°: half way is −5°, not 175°.
    a, b = _about([0, 0, 1], 0.0), _about([0, 0, 1], math.radians(350))
    mid = slerp(a, b, 0.5)
    expected = quaternion_to_matrix(_about([0, 0, 1], math.radians(-5)))
    assert np.allclose(quaternion_to_matrix(mid), expected, atol=1e-12)


@pytest.mark.parametrize("order", ROTATION_ORDERS)
def test_euler_round_trip_including_gimbal_lock(order):
    rng = np.random.default_rng(3)
    angles = rng.uniform(-3, 3, (200, 3))
    mid = "xyz".index(order[1])
    angles[:20, mid] = math.pi / 2  # locked
    angles[20:40, mid] = -math.pi / 2 + 1e-9  # next to the lock
    m = rotation_matrices(angles, order)
    back = rotation_matrices(euler_from_matrices(m, order), order)
    assert np.abs(back - m).max() < 1e-12


def test_quaternions_and_matrices_agree_with_the_axis_angle_form():
    rng = np.random.default_rng(5)
    axes = rng.normal(size=(100, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    angles = rng.uniform(-math.pi, math.pi, 100)
    q = np.array([_about(ax, an) for ax, an in zip(axes, angles)])
    m = quaternion_to_matrix(q)
    # Rodrigues' formula, independently
    k = np.zeros((100, 3, 3))
    k[:, 0, 1], k[:, 0, 2], k[:, 1, 2] = -axes[:, 2], axes[:, 1], -axes[:, 0]
    k -= np.swapaxes(k, 1, 2)
    rod = np.eye(3) + np.sin(angles)[:, None, None] * k + (1 - np.cos(angles))[:, None, None] * (k @ k)
    assert np.allclose(m, rod, atol=1e-12)
    back = matrices_to_quaternions(m)
    assert np.allclose(np.abs(np.sum(back * q, axis=1)), 1.0, atol=1e-12)  # q or −q
    assert np.all(back[:, 3] >= 0)


def test_euler_filter_makes_a_turn_past_180_degrees_continuous():
    t = np.linspace(0, 2 * math.pi, 50)
    truth = np.stack([0.2 * np.sin(t), 0.1 * np.ones_like(t), t], axis=1)  # z turns all the way round
    m = rotation_matrices(truth, "zyx")
    raw = euler_from_matrices(m, "zyx")
    assert np.abs(np.diff(raw[:, 2])).max() > 3  # the raw extraction wraps
    filtered = euler_filter(raw, "zyx")
    assert np.abs(np.diff(filtered, axis=0)).max() < 0.2
    assert np.allclose(rotation_matrices(filtered, "zyx"), m, atol=1e-12)


def _quat_channels(times, quats, interpolation=Interpolation.LINEAR, slopes=None):
    chans = []
    for slot in (3, 0, 1, 2):
        keys = []
        for k, (t, q) in enumerate(zip(times, quats)):
            if slopes is None:
                keys.append(Key(t, q[slot], Tangent.LINEAR, Tangent.LINEAR, interpolation=interpolation))
            else:
                a, b = slopes[k]
                keys.append(Key(t, q[slot], Tangent.FIXED, Tangent.FIXED, a[slot], b[slot], interpolation))
        chans.append(Channel(keys))
    return chans


def test_linear_quaternion_keys_are_slerped_not_blended_per_component():
    axis = np.array([0.0, 0.6, 0.8])
    q = [_about(axis, 0.0), _about(axis, 2.8), _about(axis, 2.8 + 3.0)]  # the second span crosses the sphere
    chans = _quat_channels([0.0, 1.0, 3.0], q)
    times = np.array([0.0, 0.3, 1.0, 1.5, 2.9, 3.0])
    got = quaternions_at(chans, [0, 0, 0, 1], times)
    angle = np.interp(times, [0, 1, 3], [0.0, 2.8, 5.8])
    for g, a in zip(got, angle):
        assert np.allclose(quaternion_to_matrix(g), quaternion_to_matrix(_about(axis, a)), atol=1e-12)


def test_stepped_quaternion_keys_hold():
    q = [_about([1, 0, 0], 0.5), _about([0, 1, 0], 1.0)]
    chans = _quat_channels([0.0, 1.0], q, Interpolation.CONSTANT)
    got = quaternions_at(chans, [0, 0, 0, 1], [0.0, 0.99, 1.0])
    assert np.allclose(got[1], q[0]) and np.allclose(got[2], q[1])


def test_cubic_quaternion_keys_follow_the_gltf_spline():
    q0, q1 = _about([0, 0, 1], 0.2), _about([1, 0, 0], 1.1)
    # tangents with a part along the quaternion itself: they change the normalised path
    b0 = np.array([0.3, -0.2, 0.5, 0.4])
    a1 = np.array([-0.1, 0.6, 0.2, -0.3])
    chans = _quat_channels([1.0, 3.0], [q0, q1], Interpolation.CUBIC, [(np.zeros(4), b0), (a1, np.zeros(4))])
    for t in (1.0, 1.5, 2.2, 3.0):
        u, dt = (t - 1.0) / 2.0, 2.0
        p = ((2 * u**3 - 3 * u**2 + 1) * q0 + (u**3 - 2 * u**2 + u) * dt * b0
             + (-2 * u**3 + 3 * u**2) * q1 + (u**3 - u**2) * dt * a1)
        assert np.allclose(quaternions_at(chans, [0, 0, 0, 1], [t])[0], p / np.linalg.norm(p), atol=1e-12)


def test_a_missing_component_holds_the_rest_value():
    rest = _about([0, 1, 0], 0.7)
    chans = _quat_channels([0.0, 1.0], [rest, rest])
    chans[2] = None  # no qy channel
    got = quaternions_at(chans, rest, [0.5])[0]
    assert np.allclose(got, rest, atol=1e-12)


def test_joints_translate_turn_scale_and_sit_below_the_placement():
    placement = np.eye(4)
    placement[:3, :3] = rotation_matrices([[-math.pi / 2, 0, 0]], "xyz")[0]
    placement[:3, 3] = [0, 0, 5]
    root = Joint("hips", None, [0, 1, 0], translation=[0, 0.5, 0], scale=[2, 1, 1])
    child = Joint("leg", 0, [1, 0, 0], translation=[0, -1, 0])
    skel = Skeleton([root, child, Joint("arm", None, [3, 0, 0])], rotation_order="zyx")
    skel.placement = placement
    skel.set_dof(0, "z", math.pi / 2)
    w = skel.world_matrices()
    r = rotation_matrices([[0, 0, math.pi / 2]], "zyx")[0]
    hips = np.eye(4)
    hips[:3, :3] = r @ np.diag([2, 1, 1])
    hips[:3, 3] = [0, 1.5, 0]
    leg = np.eye(4)
    leg[:3, 3] = [1, -1, 0]
    assert np.allclose(w[0], placement @ hips)
    assert np.allclose(w[1], placement @ hips @ leg)
    arm = np.eye(4)
    arm[:3, 3] = [3, 0, 0]
    assert np.allclose(w[2], placement @ arm)  # a second root


def test_euler_to_quaternion_matches_the_product_of_axis_turns():
    angles = np.array([[0.3, -1.2, 2.0]])
    q = euler_to_quaternions(angles, "zyx")[0]
    expected = quaternion_to_matrix(_about([0, 0, 1], 2.0)) @ quaternion_to_matrix(
        _about([0, 1, 0], -1.2)) @ quaternion_to_matrix(_about([1, 0, 0], 0.3))
    assert np.allclose(quaternion_to_matrix(q), expected, atol=1e-12)


def test_one_time_path_equals_the_array_path_and_notices_a_changed_channel():
    from qtanimator.core.quaternion_channels import quaternion_at

    rng = np.random.default_rng(11)
    q = rng.normal(size=(6, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    chans = _quat_channels([0.0, 0.4, 1.0, 1.3, 2.0, 2.2], list(q))
    times = np.linspace(-0.2, 2.4, 41)
    batch = quaternions_at(chans, [0, 0, 0, 1], times)
    for t, b in zip(times, batch):
        assert np.allclose(quaternion_at(chans, [0, 0, 0, 1], t), b, atol=1e-12)
    # the plan is cached on the first channel: replacing another channel must not reuse it
    changed = list(chans)
    changed[1] = Channel([Key(k.time, -k.value, Tangent.LINEAR, Tangent.LINEAR, interpolation=Interpolation.LINEAR)
                          for k in chans[1].keys])
    again = quaternions_at(changed, [0, 0, 0, 1], times)
    for t, b in zip(times, again):
        assert np.allclose(quaternion_at(changed, [0, 0, 0, 1], t), b, atol=1e-12)


def test_key_series_builds_the_same_keys_as_one_by_one_and_checks_them():
    times, values = [0.0, 0.5, 1.25], [1.0, -2.0, 3.5]
    linear = Key.series(times, values, Interpolation.CONSTANT)
    assert linear == [Key(t, v, Tangent.LINEAR, Tangent.LINEAR, interpolation=Interpolation.CONSTANT)
                      for t, v in zip(times, values)]
    cubic = Key.series(times, values, Interpolation.CUBIC, [0.1, 0.2, 0.3], [-1.0, -2.0, -3.0])
    assert cubic == [Key(t, v, Tangent.FIXED, Tangent.FIXED, a, b, Interpolation.CUBIC)
                     for t, v, a, b in zip(times, values, [0.1, 0.2, 0.3], [-1.0, -2.0, -3.0])]
    with pytest.raises(ValueError, match="finite"):
        Key.series([0.0, 1.0], [0.0, float("nan")], Interpolation.LINEAR)
    with pytest.raises(ValueError, match="slopes"):
        Key.series([0.0, 1.0], [0.0, 1.0], Interpolation.CUBIC, [0.0, float("inf")], [0.0, 0.0])


def test_the_one_time_path_at_and_outside_the_end_keys_equals_the_array_path():
    from qtanimator.core.channel import Extrapolation
    from qtanimator.core.quaternion_channels import quaternion_at

    rng = np.random.default_rng(4)
    q = rng.normal(size=(3, 4)) * 2.0  # not unit: both paths normalise
    chans = _quat_channels([0.5, 1.0, 2.0], list(q))
    for t in (-1.0, 0.5, 2.0, 3.0):
        assert np.allclose(quaternion_at(chans, [0, 0, 0, 1], t), quaternions_at(chans, [0, 0, 0, 1], [t])[0],
                           atol=1e-15)
    cycling = [c.with_extrapolation(Extrapolation.CYCLE, Extrapolation.CYCLE) for c in chans]
    for t in (-0.2, 2.3):  # not held: the array path decides
        assert np.allclose(quaternion_at(cycling, [0, 0, 0, 1], t), quaternions_at(cycling, [0, 0, 0, 1], [t])[0],
                           atol=1e-15)
