"""Quaternion-keyed rotations (core/quaternion_channels.py) against closed forms: the slerp
of rotations about one axis turns the angle linearly, stepped spans hold, the scalar and the
vectorised paths agree, and the Euler <-> quaternion channel conversions sample at fps."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.channel import Channel, Interpolation, Key
from qtanimator.core.quaternion_channels import euler_channels, quaternion_at, quaternion_channels, quaternions_at
from qtanimator.core.rotation import normalize

LIN = Interpolation.LINEAR


def _about_z(angle):
    """(x, y, z, w) of the rotation by ``angle`` about z."""
    return np.array([0.0, 0.0, math.sin(angle / 2), math.cos(angle / 2)])


def _channels(times, quats, interp=LIN, pre="constant", post="constant"):
    """qw, qx, qy, qz channels of (x, y, z, w) key quaternions."""
    q = np.asarray(quats, dtype=np.float64)
    return [Channel(Key.series(times, q[:, slot], interp), pre, post) for slot in (3, 0, 1, 2)]


def test_slerp_span_turns_the_angle_linearly_in_time():
    """Keys 0 rad at t = 1 and 2 rad about z at t = 3 (less than pi apart): at t the angle is
    t - 1 (slerp turns at constant speed about the fixed axis)."""
    chans = _channels([1.0, 3.0], [_about_z(0.0), _about_z(2.0)])
    ts = np.array([1.0, 1.25, 2.0, 2.5, 3.0])
    expected = np.array([_about_z(t - 1.0) for t in ts])
    np.testing.assert_allclose(quaternions_at(chans, [0, 0, 0, 1], ts), expected, atol=1e-12)
    for t, q in zip(ts, expected):
        np.testing.assert_allclose(quaternion_at(chans, [0, 0, 0, 1], t), q, atol=1e-12)


def test_three_keys_pick_the_span_of_each_time():
    """Keys 0, 1, 3 rad about z at t = 0, 1, 2: each span turns linearly between its keys."""
    chans = _channels([0.0, 1.0, 2.0], [_about_z(0.0), _about_z(1.0), _about_z(3.0)])
    ts = np.array([0.5, 0.9, 1.1, 1.5, 1.99])
    angles = np.where(ts < 1.0, ts, 1.0 + 2.0 * (ts - 1.0))
    expected = np.array([_about_z(a) for a in angles])
    np.testing.assert_allclose(quaternions_at(chans, [0, 0, 0, 1], ts), expected, atol=1e-12)
    for t, q in zip(ts, expected):
        np.testing.assert_allclose(quaternion_at(chans, [0, 0, 0, 1], t), q, atol=1e-12)


def test_nearly_equal_keys_are_blended_linearly_and_normalised():
    """Keys 0.01 rad apart (dot > 0.9995): the normalised linear blend, within 1e-9 of the
    slerp (the angle at the middle is 0.005 rad)."""
    chans = _channels([0.0, 1.0], [_about_z(0.0), _about_z(0.01)])
    np.testing.assert_allclose(quaternion_at(chans, [0, 0, 0, 1], 0.5), _about_z(0.005), atol=1e-9)
    np.testing.assert_allclose(quaternions_at(chans, [0, 0, 0, 1], [0.5])[0], _about_z(0.005), atol=1e-9)


def test_outside_the_keys_constant_extrapolation_holds_the_end_keys():
    """Before the first key the first rotation holds, after the last the last."""
    chans = _channels([0.0, 1.0], [_about_z(0.4), _about_z(1.0)])
    for t, a in ((-2.0, 0.4), (0.0, 0.4), (1.0, 1.0), (5.0, 1.0)):
        np.testing.assert_allclose(quaternion_at(chans, [0, 0, 0, 1], t), _about_z(a), atol=1e-12)
        np.testing.assert_allclose(quaternions_at(chans, [0, 0, 0, 1], [t])[0], _about_z(a), atol=1e-12)


def test_stepped_span_holds_its_first_key():
    chans = _channels([0.0, 1.0, 2.0], [_about_z(0.2), _about_z(1.0), _about_z(2.0)], Interpolation.CONSTANT)
    for t, a in ((0.5, 0.2), (0.99, 0.2), (1.5, 1.0)):
        np.testing.assert_allclose(quaternion_at(chans, [0, 0, 0, 1], t), _about_z(a), atol=1e-12)


def test_a_missing_component_holds_the_rest_value():
    """qx and qy missing (None): the rest's x, y (0) hold; qw and qz are the keyed ones."""
    q = np.array([_about_z(0.0), _about_z(1.0)])
    w = Channel(Key.series([0.0, 1.0], q[:, 3], LIN))
    z = Channel(Key.series([0.0, 1.0], q[:, 2], LIN))
    got = quaternions_at([w, None, None, z], [0.0, 0.0, 0.0, 1.0], [0.0, 1.0])
    np.testing.assert_allclose(got, q, atol=1e-12)
    np.testing.assert_allclose(quaternion_at([w, None, None, z], [0.0, 0.0, 0.0, 1.0], 1.0), q[1], atol=1e-12)


def test_quaternion_channels_sample_keys_and_fps_and_match_the_euler_angle():
    """rz keyed 0 at t = 0 and 1.2 rad at t = 1 (linear): at fps 4 the quaternion channels have
    keys at 0, 0.25, 0.5, 0.75, 1 whose values are the rotation about z by 1.2·t."""
    rz = Channel(Key.series([0.0, 1.0], [0.0, 1.2], LIN))
    qw, qx, qy, qz = quaternion_channels([None, None, rz], [0.0, 0.0, 0.0], "xyz", 4.0)
    times = np.array([0.0, 0.25, 0.5, 0.75, 1.0])
    for ch in (qw, qx, qy, qz):
        np.testing.assert_allclose(ch.times, times, atol=1e-15)
        assert all(k.interpolation is LIN for k in ch.keys)
    np.testing.assert_allclose(qw.values, np.cos(0.6 * times), atol=1e-12)
    np.testing.assert_allclose(qz.values, np.sin(0.6 * times), atol=1e-12)
    np.testing.assert_allclose(qx.values, 0.0, atol=1e-12)
    np.testing.assert_allclose(qy.values, 0.0, atol=1e-12)


def test_euler_channels_of_a_quaternion_span():
    """A slerp about z from 0 to 1.5 rad over 1 s, sampled at fps 2: rz = 1.5·t at t = 0, 0.5, 1."""
    chans = _channels([0.0, 1.0], [_about_z(0.0), _about_z(1.5)])
    rx, ry, rz = euler_channels(chans, [0, 0, 0, 1], "xyz", 2.0)
    np.testing.assert_allclose(rz.times, [0.0, 0.5, 1.0], atol=1e-15)
    np.testing.assert_allclose(rz.values, [0.0, 0.75, 1.5], atol=1e-12)
    np.testing.assert_allclose(rx.values, 0.0, atol=1e-12)
    np.testing.assert_allclose(ry.values, 0.0, atol=1e-12)
    assert euler_channels([None] * 4, [0, 0, 0, 1], "xyz", 2.0) == [None, None, None]
    assert quaternion_channels([None] * 3, [0, 0, 0], "xyz", 2.0) == [None] * 4


@pytest.mark.parametrize("fps", [3.0, 10.0])
def test_sample_grid_spacing_is_one_over_fps(fps):
    """Keys at 0.5 and 2.5: the samples are 0.5 + k/fps up to 2.5 (and the key times)."""
    rz = Channel(Key.series([0.5, 2.5], [0.0, 1.0], LIN))
    qw = quaternion_channels([None, None, rz], [0.0, 0.0, 0.0], "xyz", fps)[0]
    n = int(math.floor(2.0 * fps + 1e-9)) + 1
    expected = np.unique(np.concatenate([0.5 + np.arange(n) / fps, [2.5]]))
    np.testing.assert_allclose(qw.times, expected, atol=1e-12)


def test_equal_keys_hold_the_rotation_between_them():
    """Two keys with the same rotation (dot 1, angle 0): the span holds it exactly."""
    q = _about_z(0.8)
    chans = _channels([0.0, 1.0], [q, q])
    for t in (0.25, 0.5, 0.75):
        np.testing.assert_allclose(quaternion_at(chans, [0, 0, 0, 1], t), q, atol=1e-15)
        np.testing.assert_allclose(quaternions_at(chans, [0, 0, 0, 1], [t])[0], q, atol=1e-15)


def test_keys_in_opposite_hemispheres_take_the_short_way():
    """Keys 0.5 rad and 1.5 rad about z, the second stored negated: the slerp still turns from
    0.5 to 1.5 rad (up to the sign of the whole quaternion)."""
    chans = _channels([0.0, 1.0], [_about_z(0.5), -_about_z(1.5)])
    for t in (0.25, 0.5, 0.75):
        got = quaternion_at(chans, [0, 0, 0, 1], t)
        expected = _about_z(0.5 + t)
        assert abs(float(np.dot(got, expected))) == pytest.approx(1.0, abs=1e-12)


def test_components_keyed_at_different_times_are_evaluated_one_by_one():
    """qz keyed at 0 and 2 s, the others at 0 and 1 s: no shared spans, so each component is
    evaluated on its own and the four normalised (nlerp), in both paths."""
    a, b = _about_z(0.2), _about_z(1.4)
    w = Channel(Key.series([0.0, 1.0], [a[3], b[3]], LIN))
    x = Channel(Key.series([0.0, 1.0], [0.0, 0.0], LIN))
    y = Channel(Key.series([0.0, 1.0], [0.0, 0.0], LIN))
    z = Channel(Key.series([0.0, 2.0], [a[2], b[2]], LIN))
    for t in (0.25, 0.5, 0.9):
        raw = np.array([0.0, 0.0, z.evaluate(t), w.evaluate(t)])
        expected = raw / np.linalg.norm(raw)
        np.testing.assert_allclose(quaternion_at([w, x, y, z], [0, 0, 0, 1], t), expected, atol=1e-14)
        np.testing.assert_allclose(quaternions_at([w, x, y, z], [0, 0, 0, 1], [t])[0], expected, atol=1e-14)
    # the same with the odd component out being qx (rotation about x this time)
    a, b = a[[2, 1, 0, 3]], b[[2, 1, 0, 3]]
    w = Channel(Key.series([0.0, 1.0], [a[3], b[3]], LIN))
    x = Channel(Key.series([0.0, 2.0], [a[0], b[0]], LIN))
    z = Channel(Key.series([0.0, 1.0], [0.0, 0.0], LIN))
    for t in (0.25, 0.5, 0.9):
        raw = np.array([x.evaluate(t), 0.0, 0.0, w.evaluate(t)])
        np.testing.assert_allclose(quaternion_at([w, x, y, z], [0, 0, 0, 1], t), raw / np.linalg.norm(raw),
                                   atol=1e-14)


def test_repeated_calls_give_the_same_bits():
    """quaternion_at prepares the keys once per set of channels and reuses them: a second call
    at the same time returns exactly what the first did (the cache changes no result)."""
    def about(angle, axis):
        n = np.asarray(axis, dtype=np.float64) / np.linalg.norm(axis)
        return np.concatenate([math.sin(angle / 2) * n, [math.cos(angle / 2)]])

    chans = _channels([0.0, 1.0], [about(0.3, [1, 2, 3]), about(2.0, [-1, 0.5, 2])])
    ts = np.linspace(0.01, 0.99, 99)
    first = np.array([quaternion_at(chans, [0, 0, 0, 1], t) for t in ts])
    again = np.array([quaternion_at(chans, [0, 0, 0, 1], t) for t in ts])
    np.testing.assert_array_equal(again, first)
    np.testing.assert_allclose(first, quaternions_at(chans, [0, 0, 0, 1], ts), atol=1e-15)


def test_at_the_first_key_both_paths_give_the_normalised_key_exactly():
    """At the first key's time the value is that key's components normalised once (what
    evaluating each component there and normalising gives, quaternion_at's docstring),
    bit for bit on both paths, not a slerp at u = 0 of the pre-normalised keys, which
    normalises twice. Key (x, y, z, w) = (1, 2, 3, 4) is not unit: normalising it again
    moves the last bit, so only the single normalisation matches exactly."""
    raw = np.array([1.0, 2.0, 3.0, 4.0])
    chans = _channels([0.5, 2.0], [raw, _about_z(1.0)])
    expected = normalize(raw[None, :])[0]
    np.testing.assert_array_equal(quaternions_at(chans, [0, 0, 0, 1], [0.5])[0], expected)
    np.testing.assert_array_equal(quaternion_at(chans, [0, 0, 0, 1], 0.5), expected)
