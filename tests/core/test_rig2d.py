"""Forward kinematics, the rotation convention, and hit testing."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from qtanimator.core.rig2d import Character, Joint, Shape, rotation


def square(cx: float, cy: float, h: float = 5.0, fill: tuple[float, float, float, float] = (1, 0, 0, 1)) -> Shape:
    pts = np.array([[cx - h, cy - h], [cx + h, cy - h], [cx + h, cy + h], [cx - h, cy + h]])
    return Shape(pts, True, fill=fill)


def chain() -> Character:
    """Three joints along +x: pivots at 0, 10, 20; shapes centred between pivots."""
    return Character("chain", [
        Joint("a", None, np.array([0.0, 0.0]), shapes=[square(5, 0)]),
        Joint("b", 0, np.array([10.0, 0.0]), shapes=[square(15, 0)]),
        Joint("c", 1, np.array([20.0, 0.0]), shapes=[square(25, 0)]),
    ])


def test_rotation_is_counter_clockwise_on_a_y_down_screen() -> None:
    # a point to the right of the pivot moves up the screen (y decreases)
    p = rotation(0.1) @ np.array([1.0, 0.0])
    assert p[1] < 0
    np.testing.assert_allclose(rotation(math.pi / 2) @ np.array([1.0, 0.0]), (0, -1), atol=1e-12)


def test_forward_kinematics_chain() -> None:
    ch = chain()
    pose = ch.pose([0.0, math.pi / 2, 0.0], (3.0, 4.0))
    np.testing.assert_allclose(pose.pivots, [[3, 4], [13, 4], [13, -6]], atol=1e-12)
    np.testing.assert_allclose(pose.to_world(2, (30, 0)), (13, -16), atol=1e-12)
    np.testing.assert_allclose(pose.world_angles, [0, math.pi / 2, math.pi / 2])
    # to_local inverts to_world
    np.testing.assert_allclose(pose.to_local(2, pose.to_world(2, (7, -2))), (7, -2), atol=1e-12)


def test_fk_matches_the_handout_form() -> None:
    # p_i = p_parent + R(Θ_parent)(c_i − c_parent) with Θ the accumulated angle
    ch = chain()
    rng = np.random.default_rng(1)
    for _ in range(5):
        a = rng.uniform(-3, 3, 3)
        pose = ch.pose(a, (0, 0))
        theta = np.cumsum(a)
        p1 = pose.pivots[0] + rotation(theta[0]) @ (ch.rest_pivots[1] - ch.rest_pivots[0])
        p2 = p1 + rotation(theta[1]) @ (ch.rest_pivots[2] - ch.rest_pivots[1])
        np.testing.assert_allclose(pose.pivots[1:], [p1, p2], atol=1e-9)


def test_hit_test_reverse_draw_order() -> None:
    ch = Character("overlap", [
        Joint("a", None, np.array([0.0, 0.0]), shapes=[square(0, 0, 10)]),
        Joint("b", 0, np.array([0.0, 0.0]), shapes=[square(5, 0, 5)]),
    ])
    pose = ch.rest_pose()
    assert ch.hit_test(pose, (6, 0)) == 1  # b is drawn later, on top
    assert ch.hit_test(pose, (-6, 0)) == 0
    assert ch.hit_test(pose, (50, 50)) is None
    turned = ch.pose([0.0, math.pi], (0, 0))  # b now lies on the left
    assert ch.hit_test(turned, (-6, 0)) == 1
    assert ch.hit_test(turned, (8, 0)) == 0


def test_hit_test_strokes_and_lines() -> None:
    line = Shape(np.array([[0.0, 0.0], [10.0, 0.0]]), False, fill=(0, 0, 0, 0), stroke=(0, 0, 0, 1),
                 stroke_width=4.0, kind="line")
    ch = Character("line", [Joint("a", None, np.array([0.0, 0.0]), shapes=[line])])
    assert ch.hit_test(ch.rest_pose(), (5, 1.9)) == 0
    assert ch.hit_test(ch.rest_pose(), (5, 2.5)) is None


def test_character_validation() -> None:
    with pytest.raises(ValueError):
        Character("x", [])
    with pytest.raises(ValueError):
        Character("x", [Joint("a", None, np.zeros(2)), Joint("a", 0, np.zeros(2))])
    with pytest.raises(ValueError):
        Character("x", [Joint("a", None, np.zeros(2)), Joint("b", 5, np.zeros(2))])


def test_sample_arm_pose(shared_data: Path) -> None:
    from qtanimator.formats.svg_rig import load_characters

    [arm] = load_characters(shared_data / "cmu-animator" / "scenes" / "arm.svg")
    angles = np.zeros(6)
    angles[1] = math.pi / 2
    pose = arm.pose(angles, (0, 0))
    # the arm turns about (40, 340): the hand's pivot (40, 140) goes to (−160, 340)
    np.testing.assert_allclose(pose.pivots[2], (-160, 340), atol=1e-9)
    assert arm.hit_test(pose, (-100, 340)) == 1
    x0, y0, x1, y1 = arm.bounds()
    assert (x0, y0, x1, y1) == pytest.approx((-5, -20, 85, 390))  # notes: x −5…85, y −20…390


def test_world_matrices_are_the_product_of_local_transforms(shared_data: Path) -> None:
    # T_joint = T_parent · T(c) · R(θ) · T(−c), the root's parent being T(translation)
    from qtanimator.formats.svg_rig import load_characters

    [ch] = load_characters(shared_data / "cmu-animator" / "scenes" / "character.svg")
    rng = np.random.default_rng(7)
    a = rng.uniform(-2, 2, len(ch.joints))
    t = np.array([12.0, -30.0])
    pose = ch.pose(a, t)

    def translate(v: np.ndarray) -> np.ndarray:
        m = np.eye(3)
        m[:2, 2] = v
        return m

    def rot(theta: float) -> np.ndarray:
        m = np.eye(3)
        m[:2, :2] = rotation(theta)
        return m

    expected: list[np.ndarray] = []
    for k, j in enumerate(ch.joints):
        parent = translate(t) if j.parent is None else expected[j.parent]
        expected.append(parent @ translate(j.pivot) @ rot(a[k]) @ translate(-j.pivot))
        np.testing.assert_allclose(pose.world[k], expected[k], atol=1e-9)
        np.testing.assert_allclose(pose.pivots[k], (parent @ np.append(j.pivot, 1.0))[:2], atol=1e-9)
