"""rig2d paths the main tests leave open (targets mutation-test survivors): shape bounds
without a stroke, filled open outlines, to_local through a scaled placement, posed
character bounds and the angle_sums plan, all against hand computations."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.mass import MassProperties
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


# ----------------------------------------------------------------------------------------
# Defaults, the root, the tree's bookkeeping, validation and stroke hit tests.
def test_the_default_stroke_is_one_unit_wide() -> None:
    """SVG's initial stroke-width is 1: a stroked shape's bounds grow by half of it, and an
    open line is hit within 0.5 of it (plus the tolerance)."""
    stroked = Shape(SQUARE.copy(), True, stroke=(0.0, 0.0, 0.0, 1.0))
    assert stroked.stroke_width == 1.0
    assert stroked.bounds() == (0.5, 1.5, 5.5, 8.5)
    line = Shape(np.array([[0.0, 0.0], [10.0, 0.0]]), False, fill=(0.0, 0.0, 0.0, 0.0),
                 stroke=(0.0, 0.0, 0.0, 1.0), kind="line")
    assert line.contains((5.0, 0.49)) and line.contains((-0.3, 0.3))
    assert not line.contains((5.0, 0.51))
    assert not line.contains((10.6, 0.0))
    assert line.contains((5.0, 0.9), tolerance=0.45) and not line.contains((5.0, 1.0), tolerance=0.45)


def test_an_unstroked_open_line_is_hit_only_within_the_tolerance() -> None:
    line = Shape(np.array([[0.0, 0.0], [10.0, 0.0]]), False, fill=(0.0, 0.0, 0.0, 0.0),
                 stroke=(0.0, 0.0, 0.0, 0.0), stroke_width=6.0, kind="line")
    assert not line.contains((5.0, 0.0))
    assert line.contains((5.0, 0.2), tolerance=0.25) and not line.contains((5.0, 0.3), tolerance=0.25)


def test_a_closed_outline_is_hit_on_its_closing_edge() -> None:
    """A stroked, unfilled square: its edge from the last point back to the first counts."""
    sq = Shape(SQUARE.copy(), True, fill=(0.0, 0.0, 0.0, 0.0), stroke=(0.0, 0.0, 0.0, 1.0), stroke_width=2.0)
    assert sq.contains((1.5, 5.0))  # 0.5 from the closing edge x = 1
    assert not sq.contains((3.0, 5.0))  # inside but not filled, 2 from every edge
    assert not Shape(np.zeros((0, 2)), True).contains((0.0, 0.0))


def test_a_point_shape_is_hit_within_its_radius() -> None:
    dot = Shape(np.array([[3.0, 4.0]]), False, stroke=(0.0, 0.0, 0.0, 1.0), stroke_width=2.0, kind="point")
    assert dot.contains((3.6, 4.8))  # distance 1.0
    assert not dot.contains((3.7, 4.8))


def test_the_root_is_the_first_joint() -> None:
    ch = Character("c", [Joint("r", None, np.zeros(2)), Joint("a", 0, np.ones(2))])
    assert ch.root is ch.joints[0] and ch.root.name == "r"


def test_the_tree_bookkeeping() -> None:
    """Children in order, parents, ancestors from the joint up, names to indices."""
    z = np.zeros(2)
    ch = Character("c", [Joint("r", None, z), Joint("a", 0, z, is_dynamic=True), Joint("b", 1, z),
                         Joint("c", 0, z, is_spring=True), Joint("d", 3, z, is_dynamic=True, is_spring=True)])
    assert [j.children for j in ch.joints] == [[1, 3], [2], [], [4], []]
    np.testing.assert_array_equal(ch.parents, [-1, 0, 1, 0, 3])
    assert ch.ancestors(2) == [2, 1, 0] and ch.ancestors(0) == [0] and ch.ancestors(4) == [4, 3, 0]
    assert ch.joint_index("c") == 3
    assert list(ch.dynamic) == [False, True, False, False, True]
    assert list(ch.spring) == [False, False, False, True, False]  # a dynamic joint is never a spring
    assert list(ch.simulated) == [False, True, False, True, True]
    assert repr(ch) == "Character('c', 5 joints, 2 dynamic)"


@pytest.mark.parametrize("joints", [
    [],
    [Joint("a", 0, np.zeros(2))],
    [Joint("a", None, np.zeros(2)), Joint("b", None, np.zeros(2))],
    [Joint("a", None, np.zeros(2)), Joint("b", 1, np.zeros(2))],
    [Joint("a", None, np.zeros(2)), Joint("b", 2, np.zeros(2)), Joint("c", 0, np.zeros(2))],
    [Joint("a", None, np.zeros(2)), Joint("b", -1, np.zeros(2))],
    [Joint("a", None, np.zeros(2)), Joint("a", 0, np.zeros(2))],
])
def test_malformed_trees_are_refused(joints: list[Joint]) -> None:
    with pytest.raises(ValueError):
        Character("bad", joints)


def test_the_world_pivots_of_a_three_joint_chain() -> None:
    """Root (2, 3) turned by π/2, child (6, 3) by −π/2, grandchild (6, 7): world angles π/2,
    0, 0; the child's pivot is (2, 3) + R(π/2)·(4, 0) = (2, −1); the grandchild's is
    (2, −1) + R(0)·(0, 4) = (2, 3); then the translation (1, 1)."""
    z = [Shape(SQUARE.copy(), True)]
    ch = Character("c", [Joint("r", None, np.array([2.0, 3.0]), shapes=z), Joint("a", 0, np.array([6.0, 3.0])),
                         Joint("b", 1, np.array([6.0, 7.0]))])
    pose = ch.pose([math.pi / 2, -math.pi / 2, 0.0], (1.0, 1.0))
    np.testing.assert_allclose(pose.world_angles, [math.pi / 2, 0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(pose.pivots, [[3.0, 4.0], [3.0, 0.0], [3.0, 4.0]], atol=1e-12)
    np.testing.assert_allclose(pose.to_world(2, (6.0, 7.0)), (3.0, 4.0), atol=1e-12)
    np.testing.assert_allclose(pose.to_world(2, (7.0, 7.0)), (4.0, 4.0), atol=1e-12)
    np.testing.assert_allclose(pose.to_local(1, (4.0, 0.0)), (7.0, 3.0), atol=1e-12)
    rest = ch.rest_pose()
    np.testing.assert_allclose(rest.pivots, [[2.0, 3.0], [6.0, 3.0], [6.0, 7.0]])
    np.testing.assert_allclose(rest.world[:, :2, :2], np.tile(np.eye(2), (3, 1, 1)))


def test_placements_compose() -> None:
    """Placing twice is placing once by the product; None changes nothing."""
    ch = one_joint()
    pose = ch.pose([0.4], (1.0, -2.0))
    p1 = np.array([[2.0, 0.0, 10.0], [0.0, 2.0, -3.0], [0.0, 0.0, 1.0]])
    p2 = np.array([[0.0, -1.0, 4.0], [1.0, 0.0, 5.0], [0.0, 0.0, 1.0]])
    assert pose.placed(None) is pose
    twice = pose.placed(p1).placed(p2)
    once = pose.placed(p2 @ p1)
    np.testing.assert_allclose(twice.world, once.world, atol=1e-12)
    np.testing.assert_allclose(twice.pivots, once.pivots, atol=1e-12)
    np.testing.assert_allclose(twice.placement, p2 @ p1, atol=1e-15)
    np.testing.assert_allclose(once.pivots[0], (p2 @ p1 @ np.append(pose.pivots[0], 1.0))[:2], atol=1e-12)


def test_hit_test_finds_the_joint_under_a_posed_point() -> None:
    """The square 1…5 × 2…8 of joint 0 (pivot (2, 3)) turned by π/2: (x, y) → (2 + (y − 3),
    3 − (x − 2)), so the rest point (4, 7) lies at (6, 1); the rest point (3, 3) at (2, 2)."""
    ch = one_joint()
    pose = ch.pose([math.pi / 2])
    assert ch.hit_test(pose, (6.0, 1.0)) == 0
    assert ch.hit_test(pose, (2.0, 2.0)) == 0
    assert ch.hit_test(pose, (4.0, 7.0)) is None  # the rest position is empty now
    assert ch.hit_test(pose, (6.0, 5.5)) is None


def test_bounds_of_a_character_without_shapes_are_its_root_pivot() -> None:
    ch = Character("c", [Joint("r", None, np.array([4.0, -1.0]))])
    assert ch.bounds() == (4.0, -1.0, 4.0, -1.0)
    assert ch.bounds(ch.pose([1.0], (2.0, 3.0))) == (6.0, 2.0, 6.0, 2.0)


def test_a_ray_through_a_vertex_counts_once() -> None:
    """Even-odd rule on a diamond (0, 5), (5, 0), (10, 5), (5, 10): the horizontal ray from a
    point at y = 5 passes through the vertex (10, 5), which must count as one crossing."""
    diamond = Shape(np.array([[0.0, 5.0], [5.0, 0.0], [10.0, 5.0], [5.0, 10.0]]), True,
                    stroke=(0.0, 0.0, 0.0, 0.0))
    assert diamond.contains((2.0, 5.0)) and diamond.contains((8.0, 5.0))
    assert diamond.contains((5.0, 0.5)) and diamond.contains((5.0, 9.5))
    assert not diamond.contains((-1.0, 5.0)) and not diamond.contains((11.0, 5.0))
    assert not diamond.contains((1.0, 1.0)) and not diamond.contains((9.0, 9.0))


def test_each_pivot_is_carried_by_its_parent() -> None:
    """A child's pivot is a fixed point of its parent: pivots[k] = T_parent · c_k, and the
    joint's own matrix keeps its pivot in place (T_k · c_k = pivots[k])."""
    rng = np.random.default_rng(3)
    pivots = [(1.0, 2.0), (7.0, -3.0), (12.0, 5.0), (-4.0, 9.0), (3.0, 14.0)]
    parents = [None, 0, 1, 0, 3]
    ch = Character("c", [Joint(f"j{k}", parents[k], np.array(pivots[k])) for k in range(5)])
    for _ in range(3):
        pose = ch.pose(rng.uniform(-3.0, 3.0, 5), rng.uniform(-10.0, 10.0, 2))
        for k in range(1, 5):
            parent = parents[k]
            assert parent is not None
            np.testing.assert_allclose(pose.pivots[k], pose.to_world(parent, pivots[k]), atol=1e-12)
            np.testing.assert_allclose(pose.to_world(k, pivots[k]), pose.pivots[k], atol=1e-12)
            assert pose.world_angles[k] == pytest.approx(pose.world_angles[parent] + pose.angles[k], abs=1e-14)


def test_the_default_paint_is_svg_s_initial_values() -> None:
    """SVG: fill black and opaque, no stroke; group opacity 1."""
    s = Shape(SQUARE.copy(), True)
    assert s.fill == (0.0, 0.0, 0.0, 1.0) and s.stroke == (0.0, 0.0, 0.0, 0.0) and s.opacity == 1.0
    assert s.contains((3.0, 5.0)) and not s.contains((0.5, 5.0))


def test_given_mass_properties_are_kept() -> None:
    """A joint's own mass properties (exact and reference) are kept; missing ones are computed
    from its shapes (none here: no mass)."""
    given = MassProperties(3.0, np.array([1.0, 2.0]), 7.0, np.zeros(2))
    ref = MassProperties(5.0, np.array([0.0, 4.0]), 9.0, np.zeros(2))
    ch = Character("c", [Joint("a", None, np.zeros(2), mass_properties=given, reference_mass_properties=ref),
                         Joint("b", 0, np.zeros(2))])
    assert ch.joints[0].mass_properties is given and ch.joints[0].reference_mass_properties is ref
    assert ch.joints[1].mass_properties is not None and ch.joints[1].mass_properties.mass == 0.0
    assert ch.joints[1].reference_mass_properties is not None and ch.joints[1].reference_mass_properties.mass == 0.0


def test_character_bounds_include_half_the_stroke_on_every_side() -> None:
    """The square 1…5 × 2…8 with a visible stroke 4 wide reaches 2 further on every side:
    (−1, 0, 7, 10), the same as Shape.bounds; posed at +(10, 20) it is (9, 20, 17, 30)."""
    shape = Shape(SQUARE.copy(), True, stroke=(0.0, 0.0, 0.0, 1.0), stroke_width=4.0)
    ch = Character("s", [Joint("a", None, np.array([2.0, 3.0]), shapes=[shape])])
    assert ch.bounds() == (-1.0, 0.0, 7.0, 10.0)
    assert ch.bounds() == shape.bounds()
    assert ch.bounds(ch.pose([0.0], (10.0, 20.0))) == pytest.approx((9.0, 20.0, 17.0, 30.0), abs=1e-12)
