"""Slerp takes the short way when the second key is stored as −q (glTF 2.0: q and −q are the
same rotation, interpolation must not go the long way round).

Expected values: rotations about one axis, where the short way is the angle interpolated
linearly (closed form), and a slerp written here from Shoemake's formula for general keys.
Quaternions are (x, y, z, w), as the program stores them; results are compared as rotations
(q and −q are equal).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.channel import Channel, Interpolation, Key
from qtanimator.core.quaternion_channels import quaternion_at, quaternion_channels, quaternions_at
from qtanimator.core.rotation import slerp
from qtanimator.formats.gltf.model import GltfSampler


def axis_angle(axis: tuple[float, float, float], angle: float) -> np.ndarray:
    a = np.asarray(axis, dtype=np.float64)
    a = a / np.linalg.norm(a)
    return np.array([*(a * math.sin(angle / 2)), math.cos(angle / 2)])


def hand_slerp(p: np.ndarray, q: np.ndarray, u: float) -> np.ndarray:
    """Shoemake's slerp on the short arc, written out for the test."""
    d = float(np.dot(p, q))
    if d < 0:
        q, d = -q, -d
    theta = math.acos(min(1.0, d))
    if theta < 1e-9:
        return p
    return (math.sin((1 - u) * theta) * p + math.sin(u * theta) * q) / math.sin(theta)


def assert_same_rotation(got: np.ndarray, expected: np.ndarray, atol: float = 1e-9) -> None:
    got = np.asarray(got, dtype=np.float64)
    expected = np.asarray(expected, dtype=np.float64)
    assert np.linalg.norm(got) == pytest.approx(1.0, abs=1e-9)
    sign = 1.0 if float(np.dot(got, expected)) >= 0 else -1.0
    np.testing.assert_allclose(sign * got, expected, atol=atol)


def channels_from_keys(times: list[float], quats: list[np.ndarray]) -> list[Channel]:
    """``qw, qx, qy, qz`` channels with linear keys (slerp spans)."""
    arr = np.array(quats)
    return [Channel(Key.series(np.array(times), arr[:, slot], Interpolation.LINEAR)) for slot in (3, 0, 1, 2)]


# Keys 100° apart about z, the second stored negated: their dot product is −cos 50° < 0.
Q0 = axis_angle((0, 0, 1), 0.0)
Q1_NEG = -axis_angle((0, 0, 1), math.radians(100.0))
# General keys: a turn about a tilted axis, then a different one stored as −q (dot < 0)
G0 = axis_angle((1, 2, 0.5), 0.7)
G1_NEG = -axis_angle((-0.3, 1, 2), 1.9)


def test_the_keys_really_are_in_opposite_hemispheres() -> None:
    assert float(np.dot(Q0, Q1_NEG)) == pytest.approx(-math.cos(math.radians(50.0)))
    assert float(np.dot(G0, G1_NEG)) < -0.1


@pytest.mark.parametrize("u", [0.1, 0.25, 0.5, 0.8])
def test_slerp_of_a_negated_key_is_the_short_way_about_one_axis(u: float) -> None:
    # short way: u · 100° about +z (the long way would be u · (−260°))
    expected = axis_angle((0, 0, 1), math.radians(100.0 * u))
    assert_same_rotation(slerp(Q0, Q1_NEG, u), expected)
    ch = channels_from_keys([0.0, 2.0], [Q0, Q1_NEG])
    assert_same_rotation(quaternion_at(ch, (0, 0, 0, 1), 2.0 * u), expected)
    assert_same_rotation(quaternions_at(ch, (0, 0, 0, 1), [2.0 * u])[0], expected)
    sampler = GltfSampler(np.array([0.0, 2.0]), np.array([Q0, Q1_NEG]), "LINEAR")
    assert_same_rotation(sampler.evaluate(2.0 * u, rotation=True), expected)


@pytest.mark.parametrize("u", [0.2, 0.5, 0.9])
def test_slerp_of_general_keys_in_opposite_hemispheres_matches_a_hand_slerp(u: float) -> None:
    expected = hand_slerp(G0, G1_NEG, u)
    # and the short arc's angle to each key is u and 1 − u of the whole (a second check)
    whole = 2 * math.acos(abs(float(np.dot(G0, G1_NEG))))
    assert 2 * math.acos(min(1.0, abs(float(np.dot(expected, G0))))) == pytest.approx(u * whole)
    assert whole < math.pi
    assert_same_rotation(slerp(G0, G1_NEG, u), expected)
    ch = channels_from_keys([1.0, 3.0, 4.0], [G0, G1_NEG, G0])
    t = 1.0 + 2.0 * u
    assert_same_rotation(quaternion_at(ch, (0, 0, 0, 1), t), expected)
    assert_same_rotation(quaternions_at(ch, (0, 0, 0, 1), [t])[0], expected)
    # the third span goes back from −G1 to G0, again the short way
    back = hand_slerp(G1_NEG, G0, u)
    assert_same_rotation(quaternion_at(ch, (0, 0, 0, 1), 3.0 + u), back)
    assert_same_rotation(quaternions_at(ch, (0, 0, 0, 1), [3.0 + u])[0], back)
    sampler = GltfSampler(np.array([1.0, 3.0]), np.array([G0, G1_NEG]), "LINEAR")
    assert_same_rotation(sampler.evaluate(t, rotation=True), expected)


def test_many_samples_in_a_vectorised_call_all_take_the_short_way() -> None:
    ch = channels_from_keys([0.0, 1.0], [Q0, Q1_NEG])
    us = np.linspace(0.05, 0.95, 19)
    got = quaternions_at(ch, (0, 0, 0, 1), us)
    for u, q in zip(us, got):
        assert_same_rotation(q, axis_angle((0, 0, 1), math.radians(100.0 * u)))
    batch = slerp(np.tile(G0, (len(us), 1)), np.tile(G1_NEG, (len(us), 1)), us)
    for u, q in zip(us, batch):
        assert_same_rotation(q, hand_slerp(G0, G1_NEG, float(u)))


def test_euler_to_quaternion_keys_stay_in_one_hemisphere() -> None:
    """rz from 170° to 190°: w = cos(θ/2) changes sign at 180°, so quaternions with w ≥ 0
    would jump to the other hemisphere there; the keys are made to follow each other, so
    each component curve is continuous and every span is the short way."""
    rz = Channel(Key.series(np.array([0.0, 1.0]), np.radians([170.0, 190.0]), Interpolation.LINEAR))
    zero = Channel(Key.series(np.array([0.0, 1.0]), np.zeros(2), Interpolation.LINEAR))
    qw, qx, qy, qz = quaternion_channels([zero, zero, rz], (0.0, 0.0, 0.0), "xyz", 24.0)
    assert qw is not None and qx is not None and qy is not None and qz is not None
    # rx and ry without channels hold their rest angles (0 here): the same keys
    alone = quaternion_channels([None, None, rz], (0.0, 0.0, 0.0), "xyz", 24.0)
    for a, b in zip(alone, (qw, qx, qy, qz)):
        assert a is not None and np.array_equal(a.values, b.values) and np.array_equal(a.times, b.times)
    keys = np.stack([qx.values, qy.values, qz.values, qw.values], axis=1)
    assert len(keys) == 25
    dots = np.einsum("ij,ij->i", keys[1:], keys[:-1])
    assert np.all(dots > 0.99)
    # the z component and w vary smoothly: no jump between neighbouring keys
    assert np.max(np.abs(np.diff(keys, axis=0))) < 0.02
    # and the rotation at every sample is rz (closed form about z)
    for t, q in zip(qw.times, keys):
        assert_same_rotation(q, axis_angle((0, 0, 1), math.radians(170.0 + 20.0 * t)), atol=1e-9)


def test_an_axis_without_a_channel_holds_its_rest_angle() -> None:
    """rx without keys rests at 90°, rz turns 0 → 60°: every sample is Rx(90°) then Rz in
    the "xyz" order's composition, checked against the closed form."""
    rz = Channel(Key.series(np.array([0.0, 1.0]), np.radians([0.0, 60.0]), Interpolation.LINEAR))
    qw, qx, qy, qz = quaternion_channels([None, None, rz], (math.radians(90.0), 0.0, 0.0), "xyz", 4.0)
    assert qw is not None and qx is not None and qy is not None and qz is not None
    for i, t in enumerate(qw.times):
        got = np.array([qx.values[i], qy.values[i], qz.values[i], qw.values[i]])
        from qtanimator.core.rotation import euler_to_quaternions

        expected = euler_to_quaternions(np.array([[math.radians(90.0), 0.0, math.radians(60.0 * t)]]), "xyz")[0]
        assert_same_rotation(got, expected, atol=1e-12)
        assert abs(got[0]) > 0.1  # the rest angle is there: a pure z turn has no x part
