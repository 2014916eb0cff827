"""Skeleton defaults and structure (core/skeleton.py): the default box, the rotation-order
check and joint depths."""

from __future__ import annotations

import numpy as np
import pytest

from qtanimator.core.skeleton import DEFAULT_BOXMAX, DEFAULT_BOXMIN, Joint, Skeleton


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
