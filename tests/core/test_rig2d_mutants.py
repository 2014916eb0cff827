"""rig2d paths the main tests leave open (targets mutation-test survivors): shape bounds
without a stroke, filled open outlines, to_local through a scaled placement, posed
character bounds and the angle_sums plan, all against hand computations."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.rig2d import Character, Joint, Shape, angle_sums

SQUARE = np.array([[1.0, 2.0], [5.0, 2.0], [5.0, 8.0], [1.0, 8.0]])


def test_shape_bounds_add_half_the_stroke_only_when_stroked() -> None:
    bare = Shape(SQUARE.copy(), True, stroke=(0.0, 0.0, 0.0, 0.0), stroke_width=4.0)
    assert bare.bounds() == (1.0, 2.0, 5.0, 8.0)
    stroked = Shape(SQUARE.copy(), True, stroke=(0.0, 0.0, 0.0, 1.0), stroke_width=4.0)
    assert stroked.bounds() == (-1.0, 0.0, 7.0, 10.0)


def test_a_filled_open_triangle_is_hit_inside() -> None:
    """SVG fills an open polyline as if closed: a 3-point open outline with a fill is hit at
    an interior point, and missed outside it (no stroke)."""
    tri = Shape(np.array([[0.0, 0.0], [6.0, 0.0], [0.0, 6.0]]), False, fill=(0.0, 0.0, 0.0, 1.0),
                stroke=(0.0, 0.0, 0.0, 0.0), kind="polyline")
    assert tri.contains((1.0, 1.0))
    assert tri.contains((2.0, 3.5))
    assert not tri.contains((4.0, 4.0))


def one_joint() -> Character:
    return Character("one", [Joint("a", None, np.array([2.0, 3.0]),
                                   shapes=[Shape(SQUARE.copy(), True, stroke=(0.0, 0.0, 0.0, 0.0))])])


def test_to_local_through_a_scaled_placement() -> None:
    """Rest pose seen through P = scale 2, translate (10, −3): world = 2·p + (10, −3), so a
    world point q maps back to (q − (10, −3)) / 2."""
    ch = one_joint()
    placement = np.array([[2.0, 0.0, 10.0], [0.0, 2.0, -3.0], [0.0, 0.0, 1.0]])
    pose = ch.rest_pose().placed(placement)
    np.testing.assert_allclose(pose.to_local(0, (14.0, 5.0)), (2.0, 4.0), atol=1e-12)
    # rotated joint (90° about its pivot (2, 3)) then placed: local (3, 3) → R(π/2)·(1, 0) +
    # (2, 3) = (2, 2) → placed (14, 1).
    posed = ch.pose([math.pi / 2]).placed(placement)
    np.testing.assert_allclose(posed.to_world(0, (3.0, 3.0)), (14.0, 1.0), atol=1e-12)
    np.testing.assert_allclose(posed.to_local(0, (14.0, 1.0)), (3.0, 3.0), atol=1e-12)


def test_character_bounds_rest_and_posed() -> None:
    """Square 1…5 × 2…8 turned by 90° about the pivot (2, 3): (x, y) → (2 + (y − 3),
    3 − (x − 2)), so x spans 1…7 and y spans 0…4; then the translation (10, 20)."""
    ch = one_joint()
    assert ch.bounds() == (1.0, 2.0, 5.0, 8.0)
    b = ch.bounds(ch.pose([math.pi / 2], (10.0, 20.0)))
    assert b == pytest.approx((11.0, 20.0, 17.0, 24.0), abs=1e-12)


def test_angle_sums_plan_by_hand() -> None:
    """Keyed root 0; 1 dynamic under 0; 2 keyed under 1; 3 keyed under 0.
    world_0 = θ0; world_1 = its own (dynamic) world; world_2 = world_1 + θ2;
    world_3 = θ0 + θ3."""
    z = np.zeros(2)
    ch = Character("c", [Joint("r", None, z), Joint("d", 0, z, is_dynamic=True), Joint("k", 1, z),
                         Joint("s", 0, z)])
    key_sum, dyn_pick = angle_sums(ch)
    np.testing.assert_array_equal(key_sum, [[1, 0, 0, 0], [0, 0, 0, 0], [0, 0, 1, 0], [1, 0, 0, 1]])
    np.testing.assert_array_equal(dyn_pick, [[0, 0, 0, 0], [0, 1, 0, 0], [0, 1, 0, 0], [0, 0, 0, 0]])
    local = np.array([0.3, 0.0, -0.7, 1.1])
    dyn_world = np.array([0.0, 2.0, 0.0, 0.0])
    np.testing.assert_allclose(key_sum @ local + dyn_pick @ dyn_world, [0.3, 2.0, 1.3, 1.4])


def test_angle_sums_of_a_single_keyed_joint() -> None:
    key_sum, dyn_pick = angle_sums(Character("c", [Joint("r", None, np.zeros(2))]))
    np.testing.assert_array_equal(key_sum, [[1.0]])
    np.testing.assert_array_equal(dyn_pick, [[0.0]])
