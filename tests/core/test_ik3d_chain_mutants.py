"""The 3D IK chain helpers (core/ik3d_chain.py) against independent references: scipy's
rotations for Rodrigues and the Euler products, the nearest-Euler wrap checked by
re-multiplying the angles, hinge turns worked out by hand, and the PathChain's
kinematics against Skeleton.world_matrices and finite differences."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from qtanimator.core.ik3d_chain import (
    PathChain,
    _euler_matrix,
    _hinge_turn,
    _nearest_euler,
    _rotate_point,
    _turn_about_axis,
    perpendicular_part,
    rotation_about,
    shortest_arc,
    unit,
)
from qtanimator.core.rotation import ROTATION_ORDERS
from qtanimator.core.skeleton import Dof, Joint, Skeleton

TWO_PI = 2.0 * math.pi


def scipy_euler(angles, order):
    """R_a·R_b·R_c for ``order`` "abc", ``angles`` indexed x, y, z (intrinsic in scipy)."""
    idx = ["xyz".index(c) for c in order]
    return Rotation.from_euler(order.upper(), [angles[i] for i in idx]).as_matrix()


def test_rotation_about_is_rodrigues():
    """Every entry of the Rodrigues matrix (signs of the sine terms, the 1 - cos factor)."""
    rng = np.random.default_rng(5)
    for _ in range(10):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        angle = float(rng.uniform(-3.0, 3.0))
        np.testing.assert_allclose(rotation_about(axis, angle), Rotation.from_rotvec(axis * angle).as_matrix(),
                                   atol=1e-14)


@pytest.mark.parametrize("i", [0, 1, 2])
def test_turn_about_a_coordinate_axis(i):
    """Right-handed turns about x, y and z."""
    v = (0.3, -1.2, 2.5)
    angle = 0.7
    expected = Rotation.from_rotvec(np.eye(3)[i] * angle).apply(v)
    np.testing.assert_allclose(_turn_about_axis(i, angle, v), expected, atol=1e-14)


@pytest.mark.parametrize("order", ROTATION_ORDERS)
def test_euler_matrix_is_the_product_in_order(order):
    angles = [0.4, -1.1, 2.3]
    np.testing.assert_allclose(_euler_matrix(angles, order), scipy_euler(angles, order), atol=1e-14)


@pytest.mark.parametrize("order", ROTATION_ORDERS)
def test_nearest_euler_keeps_the_whole_turns_of_the_previous_values(order):
    """The triple returned reproduces the rotation and is the one nearest ``previous``,
    whole turns included (a joint at 2π + 0.4 stays there, not at 0.4)."""
    angles = np.array([0.4, -0.5, 0.3])
    r = scipy_euler(angles, order)
    for turns in ([1, 0, 0], [-1, 2, 0], [0, 0, -3], [2, -1, 1]):
        previous = angles + TWO_PI * np.array(turns) + [0.01, -0.02, 0.015]
        got = np.array(_nearest_euler(r, order, previous.tolist()))
        np.testing.assert_allclose(got, angles + TWO_PI * np.array(turns), atol=1e-12)


@pytest.mark.parametrize("order", ROTATION_ORDERS)
def test_nearest_euler_picks_the_flipped_triple_near_it(order):
    """(a + π, π - b, c + π) is the same rotation; near it, it is chosen."""
    angles = np.array([0.4, -0.5, 0.3])
    first, middle, last = ("xyz".index(ch) for ch in order)
    flipped = angles.copy()
    flipped[first] += math.pi
    flipped[middle] = math.pi - flipped[middle]
    flipped[last] += math.pi
    r = scipy_euler(angles, order)
    np.testing.assert_allclose(scipy_euler(flipped, order), r, atol=1e-14)
    got = np.array(_nearest_euler(r, order, (flipped + 0.05).tolist()))
    np.testing.assert_allclose(got, flipped, atol=1e-12)
    got = np.array(_nearest_euler(r, order, (angles - 0.05).tolist()))
    np.testing.assert_allclose(got, angles, atol=1e-12)


@pytest.mark.parametrize("order", ROTATION_ORDERS)
def test_nearest_euler_in_gimbal_lock_still_reproduces_the_rotation(order):
    """Middle angle ±π/2: only a sum or difference of the outer two is defined."""
    first, middle, last = ("xyz".index(ch) for ch in order)
    for mid in (math.pi / 2, -math.pi / 2):
        angles = np.zeros(3)
        angles[first], angles[middle], angles[last] = 0.3, mid, -0.2
        r = scipy_euler(angles, order)
        got = _nearest_euler(r, order, [0.0, 0.0, 0.0])
        np.testing.assert_allclose(scipy_euler(got, order), r, atol=1e-9)
        assert abs(got[middle] - mid) < 1e-6


def test_hinge_turn_by_hand():
    """About z through (1, 1, 0): the end 1 along +x from the pivot, the goal 2 along +y
    (heights along the axis do not matter): a quarter turn, positive (right-handed)."""
    pivot = (1.0, 1.0, 0.0)
    assert _hinge_turn((0.0, 0.0, 1.0), pivot, (2.0, 1.0, 5.0), (1.0, 3.0, -3.0)) == pytest.approx(math.pi / 2)
    assert _hinge_turn((0.0, 0.0, 1.0), pivot, (2.0, 1.0, 0.0), (1.0, -1.0, 0.0)) == pytest.approx(-math.pi / 2)
    # about x: end +y, goal +z: +π/2; about y: end +z, goal +x: +π/2
    assert _hinge_turn((1.0, 0.0, 0.0), (0, 0, 0), (0.0, 2.0, 0.0), (0.0, 0.0, 3.0)) == pytest.approx(math.pi / 2)
    assert _hinge_turn((0.0, 1.0, 0.0), (0, 0, 0), (0.0, 0.0, 2.0), (3.0, 0.0, 0.0)) == pytest.approx(math.pi / 2)
    # 135°: goal at (-1, 1) from the pivot
    assert _hinge_turn((0.0, 0.0, 1.0), (0, 0, 0), (1.0, 0.0, 0.0), (-1.0, 1.0, 7.0)) == pytest.approx(0.75 * math.pi)
    # the end or the goal on the axis: no turn
    assert _hinge_turn((0.0, 0.0, 1.0), pivot, (1.0, 1.0, 4.0), (1.0, 3.0, 0.0)) == 0.0
    assert _hinge_turn((0.0, 0.0, 1.0), pivot, (2.0, 1.0, 0.0), (1.0, 1.0, -2.0)) == 0.0


def test_rotate_point_about_a_pivot():
    rng = np.random.default_rng(9)
    for _ in range(5):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        angle = float(rng.uniform(-3, 3))
        pivot, point = rng.normal(size=3), rng.normal(size=3)
        expected = pivot + Rotation.from_rotvec(axis * angle).apply(point - pivot)
        got = _rotate_point(tuple(axis), angle, tuple(pivot), tuple(point))
        np.testing.assert_allclose(got, expected, atol=1e-13)


def test_unit_and_perpendicular_part():
    np.testing.assert_allclose(unit(np.array([3.0, 0.0, 4.0])), [0.6, 0.0, 0.8])
    assert unit(np.zeros(3)) is None
    assert unit(np.array([math.inf, 0.0, 0.0])) is None
    assert unit(np.array([math.nan, 1.0, 0.0])) is None
    np.testing.assert_array_equal(unit(np.array([0.0, -1e-100, 0.0])), [0.0, -1.0, 0.0])
    u = np.array([0.0, 0.6, 0.8])
    # v·u = 2·0.6 + 0.5·0.8 = 1.6
    expected = [1.0, 2.0 - 1.6 * 0.6, 0.5 - 1.6 * 0.8]
    np.testing.assert_allclose(perpendicular_part(np.array([1.0, 2.0, 0.5]), u), expected)


def test_shortest_arc():
    """Takes u's direction onto v's, about u × v, by the angle between them; identity for
    the same direction or a zero vector, a half turn for opposite ones."""
    rng = np.random.default_rng(2)
    for _ in range(5):
        u, v = rng.normal(size=3), rng.normal(size=3)
        r = shortest_arc(u * 3.0, v * 0.5)
        np.testing.assert_allclose(r @ (u / np.linalg.norm(u)), v / np.linalg.norm(v), atol=1e-12)
        axis = np.cross(u, v)
        np.testing.assert_allclose(r @ axis, axis, atol=1e-12)
        angle = math.acos(float(u @ v) / np.linalg.norm(u) / np.linalg.norm(v))
        assert np.trace(r) == pytest.approx(1.0 + 2.0 * math.cos(angle), abs=1e-12)
    np.testing.assert_array_equal(shortest_arc(np.array([1.0, 2.0, 3.0]), np.array([2.0, 4.0, 6.0])), np.eye(3))
    np.testing.assert_array_equal(shortest_arc(np.zeros(3), np.array([1.0, 0.0, 0.0])), np.eye(3))
    np.testing.assert_array_equal(shortest_arc(np.array([1.0, 0.0, 0.0]), np.zeros(3)), np.eye(3))
    for u in (np.array([1.0, 0.0, 0.0]), np.array([0.2, -0.3, 0.9])):
        r = shortest_arc(u, -2.0 * u)
        np.testing.assert_allclose(r @ u, -u, atol=1e-12)
        np.testing.assert_allclose(r @ r.T, np.eye(3), atol=1e-12)
        assert np.linalg.det(r) == pytest.approx(1.0)


def arm(order: str = "zyx", limit: float = 100000.0) -> Skeleton:
    def dofs():
        return (Dof(0, -limit, limit), Dof(0, -limit, limit), Dof(0, -limit, limit))
    return Skeleton([
        Joint("root", None, (0, 0, 0), dofs()),
        Joint("shoulder", 0, (0, 1, 0), dofs()),
        Joint("elbow", 1, (1, 0, 0), dofs()),
        Joint("wrist", 2, (0.8, 0.1, 0), dofs()),
        Joint("hand", 3, (0.3, 0, 0.1), dofs()),
        Joint("other", 0, (0, -1, 0), dofs()),
    ], rotation_order=order)


def posed_values(seed: int = 3) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return rng.uniform(-0.6, 0.6, (6, 3))


@pytest.mark.parametrize("order", ["zyx", "xyz", "yzx"])
def test_path_chain_frames_match_the_skeleton(order):
    """The path from the highest DOF owner to the end, hung from the fixed frame above it
    (placement, root translation, the root's own rotation), with scaled joints."""
    sk = arm(order)
    sk.placement = np.array([[0.0, -2.0, 0.0, 1.0], [2.0, 0.0, 0.0, 0.5], [0.0, 0.0, 2.0, -1.0], [0, 0, 0, 1.0]])
    sk.set_root_translation([0.2, 0.3, -0.4])
    sk.joints[2].scale = np.array([1.5, 0.5, 2.0])
    sk.joints[3].translation = np.array([0.1, 0.0, -0.2])
    v = posed_values()
    dofs = [(1, 0), (2, 2), (3, 1), (5, 0)]   # joint 5 is off the path to 4: ignored
    chain = PathChain(sk, 4, [0, 0, 0], dofs, 3, v)
    assert chain.path == [1, 2, 3, 4]
    assert chain.free == {1: [0], 2: [2], 3: [1]}
    world = sk.world_matrices(v)
    for j, f in zip(chain.path, chain.frames()):
        np.testing.assert_allclose(f, world[j], atol=1e-12)
    np.testing.assert_allclose(chain.end_position(), world[4, :3, 3], atol=1e-12)
    np.testing.assert_allclose(chain.base, world[0], atol=1e-12)
    res = chain.result(7)
    assert res.iterations == 7 and res.dofs == dofs
    assert res.values == {d: v[d] for d in dofs}
    assert res.error == pytest.approx(float(np.linalg.norm(world[4, :3, 3])), rel=1e-12)


def test_path_chain_with_an_offset_ends_at_the_effector():
    sk = arm()
    v = posed_values(4)
    offset = np.array([0.2, -0.1, 0.3])
    chain = PathChain(sk, 4, [1, 1, 1], [(4, 0), (3, 2)], 3, v, offset)
    assert chain.path == [3, 4, len(sk.joints)]
    world = sk.world_matrices(v)
    np.testing.assert_allclose(chain.end_position(), world[4, :3, :3] @ offset + world[4, :3, 3], atol=1e-12)
    np.testing.assert_allclose(chain.base, world[2], atol=1e-12)


def test_path_chain_starts_inside_the_limits():
    sk = arm(limit=0.3)
    v = np.zeros((6, 3))
    v[2] = [0.5, -0.7, 0.1]
    chain = PathChain(sk, 4, [0, 0, 0], [(2, 0), (2, 1)], 3, v)
    assert chain.v[2].tolist() == [0.3, -0.3, 0.1]   # the DOF not in the list is left as it is


@pytest.mark.parametrize("order", ["zyx", "xzy"])
def test_dof_axis_is_the_derivative_of_the_rotation(order):
    """Turning DOF a by h moves the end by h · axis × (end - pivot) to first order."""
    sk = arm(order)
    sk.joints[1].scale = np.array([2.0, 2.0, 2.0])
    v = posed_values(6)
    dofs = [(j, a) for j in (2, 3) for a in range(3)]
    chain = PathChain(sk, 4, [0, 0, 0], dofs, 3, v)
    frames = chain.frames()
    parents = [chain.base, *frames[:-1]]
    end = frames[-1][:3, 3]
    h = 1e-6
    for k, j in enumerate(chain.path[:-1]):
        pivot = frames[k][:3, 3]
        for a in range(3):
            axis = chain.axis(j, a, parents[k])
            assert np.linalg.norm(axis) == pytest.approx(1.0)
            moved = v.copy()
            moved[j, a] += h
            fd = (sk.world_matrices(moved)[4, :3, 3] - sk.world_matrices(v)[4, :3, 3]) / h
            np.testing.assert_allclose(np.cross(axis, end - pivot), fd, atol=1e-5)


def test_ccd_sweep_hinge_turns_and_limits():
    """One sweep over one hinge points the end at the target's projection; a limit clamps
    the turn and moves the end only as far as the limit."""
    sk = Skeleton([Joint("a", None, (0, 0, 0), (Dof(), Dof(), Dof(0, -0.5, 0.5))),
                   Joint("b", 0, (2, 0, 0))], rotation_order="xyz")
    chain = PathChain(sk, 1, [0.0, 3.0, 1.0], [(0, 2)], 3, None)
    chain.ccd_sweep()
    assert chain.v[0, 2] == 0.5
    np.testing.assert_allclose(chain.end_position(), [2 * math.cos(0.5), 2 * math.sin(0.5), 0.0], atol=1e-12)
    free = Skeleton([Joint("a", None, (0, 0, 0)), Joint("b", 0, (2, 0, 0))], rotation_order="xyz")
    chain = PathChain(free, 1, [-1.0, 1.0, 1.0], [(0, 2)], 3, None)
    chain.ccd_sweep()
    assert chain.v[0, 2] == pytest.approx(0.75 * math.pi)


def test_set_rotation_and_turn_world_under_a_scaled_parent():
    """turn_world(R) turns the joint's subtree by R in world space about its pivot, with a
    uniformly or non-uniformly scaled parent; set_rotation clamps each free DOF."""
    # A non-uniform scale (2, 2, 0.5) commutes with turns about its z axis only: the world
    # turn is then about the parent frame's z axis, which the joint's local frame can take.
    for scale, rotvec in (([2.0, 2.0, 2.0], [0.3, -0.2, 0.4]), ([1.0, 2.0, 0.5], None),
                          ([2.0, 2.0, 0.5], [0.0, 0.0, 0.6])):
        sk = arm("zyx")
        sk.joints[1].scale = np.array(scale)
        v = posed_values(8)
        v[1] = 0.0   # a scaled joint that also turns is not a rotation; keep it a pure scale
        dofs = [(2, 0), (2, 1), (2, 2)]
        chain = PathChain(sk, 4, [0, 0, 0], dofs, 3, v)
        frames = chain.frames()
        assert chain.path == [2, 3, 4]
        parent = chain.base   # the world frame of joint 1, scaled
        np.testing.assert_allclose(np.linalg.norm(parent[:3, :3], axis=0), scale, atol=1e-12)
        k = 0
        if rotvec is None:   # no turn at all: every DOF stays
            chain.turn_world(2, parent, np.eye(3))
            np.testing.assert_allclose(chain.v, v, atol=1e-12)
            continue
        # rotvec in the parent's (unscaled) axes
        p_rot = parent[:3, :3] / np.linalg.norm(parent[:3, :3], axis=0)
        turn = p_rot @ Rotation.from_rotvec(rotvec).as_matrix() @ p_rot.T
        before = frames[k]
        chain.turn_world(2, parent, turn)
        after = chain.frames()[k]
        np.testing.assert_allclose(after[:3, 3], before[:3, 3], atol=1e-12)
        np.testing.assert_allclose(after[:3, :3], turn @ before[:3, :3], atol=1e-10)
    sk = arm(limit=0.2)
    chain = PathChain(sk, 4, [0, 0, 0], [(2, 0), (2, 2)], 3, np.zeros((6, 3)))
    chain.set_rotation(2, scipy_euler([0.1, 0.1, -0.5], "zyx"))
    assert chain.v[2].tolist() == pytest.approx([0.1, 0.0, -0.2])   # y not free: left at 0


def test_extrapolate_follows_the_step_while_it_helps():
    """The pattern move tries 2, 4, 8 ... times the step: on a straight hinge towards a
    target 0.9 rad away, a step of 0.1 goes to 0.8 (16x would pass it)."""
    sk = Skeleton([Joint("a", None, (0, 0, 0)), Joint("b", 0, (1, 0, 0))], rotation_order="xyz")
    target = [math.cos(0.9), math.sin(0.9), 0.0]
    chain = PathChain(sk, 1, target, [(0, 2)], 3, None)
    before = chain.v.copy()
    chain.v[0, 2] = 0.1
    err = chain.error(chain.end_position())
    new_err = chain.extrapolate(before, err)
    assert chain.v[0, 2] == pytest.approx(0.8)
    assert new_err == pytest.approx(2 * math.sin(0.05), abs=1e-12)
    # no change: nothing to follow
    assert chain.extrapolate(chain.v.copy(), 0.5) == 0.5
