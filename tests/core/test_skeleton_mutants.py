"""Skeleton defaults and structure (core/skeleton.py): the default box, the rotation-order
check, joint depths, axis names, DOF order and limits, per-joint rotation orders and the bind pose."""

from __future__ import annotations

import numpy as np
import pytest

from qtanimator.core.matrix_stack import rotation_x, rotation_y, rotation_z, translation
from qtanimator.core.skeleton import DEFAULT_BOXMAX, DEFAULT_BOXMIN, DEFAULT_LIMIT, Dof, Joint, Skeleton, axis_index


def test_default_box_is_a_cube_of_side_0_2_about_the_joint():
    # the .skel format's default box (boxmin -0.1, boxmax 0.1 on every axis)
    assert tuple(DEFAULT_BOXMIN) == (-0.1, -0.1, -0.1)
    assert tuple(DEFAULT_BOXMAX) == (0.1, 0.1, 0.1)
    j = Joint("a")
    np.testing.assert_array_equal(j.boxmin, [-0.1, -0.1, -0.1])
    np.testing.assert_array_equal(j.boxmax, [0.1, 0.1, 0.1])


def test_depths_count_edges_from_the_root():
    sk = Skeleton([Joint("root"), Joint("a", 0, [0, 1, 0]), Joint("b", 1, [0, 1, 0]),
                   Joint("c", 0, [1, 0, 0]), Joint("other_root")])
    assert sk.depths == [0, 1, 2, 1, 0]


@pytest.mark.parametrize("order", ["xyz", "xzy", "yxz", "yzx", "zxy", "zyx"])
def test_every_rotation_order_is_accepted(order):
    assert Skeleton([Joint("root")], rotation_order=order).rotation_order == order
    assert Joint("j", rotation_order=order).rotation_order == order


@pytest.mark.parametrize("order", ["xyx", "abc", "XYZ", "", "xy"])
def test_unknown_rotation_orders_are_refused(order):
    with pytest.raises(ValueError):
        Skeleton([Joint("root")], rotation_order=order)
    with pytest.raises(ValueError):
        Joint("j", rotation_order=order)


def test_axis_index_accepts_names_and_0_to_2_only():
    """x/y/z in either case and the ints 0..2; 3, -1, a bool, a float or another letter are
    refused with ValueError."""
    assert [axis_index(a) for a in ("x", "Y", "z", 0, 1, 2)] == [0, 1, 2, 0, 1, 2]
    for bad in (3, -1, True, 1.0, "w", None):
        with pytest.raises(ValueError):
            axis_index(bad)


def test_joint_keeps_its_three_dofs_in_order_and_copies_them():
    """The x, y, z DOFs stay in their places (pose reads them in order); a copy is deep."""
    j = Joint("j", None, [1, 2, 3], (Dof(0.1), Dof(0.2), Dof(0.3)))
    np.testing.assert_array_equal(j.pose, [0.1, 0.2, 0.3])
    c = j.copy()
    c.dofs[1].value = 5.0
    c.offset[0] = 9.0
    np.testing.assert_array_equal(j.pose, [0.1, 0.2, 0.3])
    np.testing.assert_array_equal(c.pose, [0.1, 5.0, 0.3])
    assert j.offset[0] == 1.0
    assert c.name == "j" and c.parent is None


def test_default_dof_is_unlimited_both_ways():
    """A DOF made without limits takes large negative and positive values unclamped."""
    d = Dof()
    assert (d.min, d.max) == (-DEFAULT_LIMIT, DEFAULT_LIMIT)
    d.value = -1234.5
    assert d.value == -1234.5
    d.value = 1234.5
    assert d.value == 1234.5


def test_a_joints_own_rotation_order_overrides_the_skeletons():
    """Joint 1 has order xyz (Rx·Ry·Rz), joint 2 none and so the skeleton's zyx (Rz·Ry·Rx);
    the products are built from the elementary matrices of the matrix stack."""
    sk = Skeleton([Joint("r"), Joint("a", 0, [0, 1, 0], rotation_order="xyz"), Joint("b", 1, [0, 0, 2])],
                  rotation_order="zyx")
    x, y, z = 0.3, -0.5, 0.7
    sk.set_dof_values([[0, 0, 0], [x, y, z], [x, y, z]])
    local = sk.local_matrices()
    np.testing.assert_allclose(local[1], translation(0, 1, 0) @ rotation_x(x) @ rotation_y(y) @ rotation_z(z),
                               atol=1e-14)
    np.testing.assert_allclose(local[2], translation(0, 0, 2) @ rotation_z(z) @ rotation_y(y) @ rotation_x(x),
                               atol=1e-14)
    assert sk.names == ["r", "a", "b"]


def test_bind_pose_ignores_the_dofs_and_the_root_translation():
    """Joint positions in the bind pose are the summed offsets; the posed ones move."""
    sk = Skeleton([Joint("r"), Joint("a", 0, [0, 1, 0]), Joint("b", 1, [0, 0, 2])])
    sk.set_dof_values([[0.4, 0.1, 0.2], [0.3, 0.0, 0.0], [0, 0, 0]])
    sk.set_root_translation([5.0, 6.0, 7.0])
    bind = sk.bind_world_matrices()
    np.testing.assert_allclose(bind[:, :3, 3], [[0, 0, 0], [0, 1, 0], [0, 1, 2]], atol=1e-15)
    np.testing.assert_allclose(bind[:, :3, :3], np.broadcast_to(np.eye(3), (3, 3, 3)), atol=1e-15)
    pos = sk.joint_positions()
    assert pos.shape == (3, 3)
    np.testing.assert_allclose(pos[0], [5.0, 6.0, 7.0])
    assert np.linalg.norm(pos[2] - pos[1]) == pytest.approx(2.0)
    assert np.linalg.norm(pos[1] - pos[0]) == pytest.approx(1.0)
