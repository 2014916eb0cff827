"""2D IK: the handout gradient, gradient descent, and the damped least squares solver."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from qtanimator.core.ik import (
    _Chain,
    gradient_descent_step,
    handout_gradient,
    ik_error,
    planar_chain,
    solve_ik,
)
from qtanimator.core.rig2d import Character, Joint, Shape


def _fd_gradient(ch: Character, a: np.ndarray, t: np.ndarray, joint: int, lp: np.ndarray,
                 q: np.ndarray, h: float = 1e-6) -> np.ndarray:
    def f(x: np.ndarray) -> float:
        return 0.5 * ik_error(ch, x, t, joint, lp, q) ** 2
    g = np.zeros_like(a)
    for k in range(len(a)):
        e = np.zeros_like(a)
        e[k] = h
        g[k] = (f(a + e) - f(a - e)) / (2 * h)
    return g


def test_handout_gradient_matches_finite_differences(shared_data: Path) -> None:
    from qtanimator.formats.svg_rig import load_characters

    [arm] = load_characters(shared_data / "cmu-animator" / "scenes" / "arm.svg")
    rng = np.random.default_rng(3)
    for _ in range(5):
        a = rng.uniform(-1, 1, 6)
        t = rng.uniform(-20, 20, 2)
        lp, q = np.array([40.0, 0.0]), rng.uniform(-200, 200, 2)
        d = handout_gradient(arm, a, 4, lp, q, t)
        g = _fd_gradient(arm, a, t, 4, lp, q)
        chain = [1, 2, 4]
        np.testing.assert_allclose(d[chain], -g[chain], rtol=1e-5, atol=1e-3)
        assert d[0] == 0 and d[3] == 0 and d[5] == 0  # root frozen, off-chain joints 0


def test_gradient_descent_lowers_the_error() -> None:
    ch = planar_chain(4, 50.0)
    a = np.array([0.0, 0.3, 0.2, 0.1])
    lp, q = np.array([200.0, 0.0]), np.array([120.0, -90.0])
    e0 = ik_error(ch, a, (0, 0), 3, lp, q)
    b = gradient_descent_step(ch, a, (0, 0), 3, lp, q)
    assert ik_error(ch, b, (0, 0), 3, lp, q) < e0
    assert b[0] == a[0]


def _random_chain(n: int, seed: int) -> Character:
    rng = np.random.default_rng(seed)
    joints = []
    p = np.zeros(2)
    for i in range(n):
        nxt = p + rng.uniform(5, 30) * np.array([math.cos(rng.uniform(-1, 1)), math.sin(rng.uniform(-1, 1))])
        pts = np.array([p + (0, -1), nxt + (0, -1), nxt + (0, 1), p + (0, 1)])
        joints.append(Joint(f"j{i}", None if i == 0 else i - 1, p.copy(), shapes=[Shape(pts, True)]))
        p = nxt
    ch = Character("random", joints)
    ch.tip = p  # type: ignore[attr-defined]
    return ch


@settings(max_examples=40, deadline=None)
@given(st.integers(2, 9), st.integers(0, 10_000), st.floats(-200, 200), st.floats(-200, 200))
def test_every_solve_lowers_the_error_and_stays_finite(n: int, seed: int, qx: float, qy: float) -> None:
    ch = _random_chain(n, seed)
    rng = np.random.default_rng(seed)
    a = rng.uniform(-1, 1, n)
    lp = ch.tip  # type: ignore[attr-defined]
    q = np.array([qx, qy])
    e0 = ik_error(ch, a, (0, 0), n - 1, lp, q)
    b = solve_ik(ch, a, (0, 0), n - 1, lp, q)
    assert np.all(np.isfinite(b))
    assert ik_error(ch, b, (0, 0), n - 1, lp, q) <= e0 + 1e-12
    assert b[0] == a[0]  # root frozen


@pytest.mark.parametrize("n", [3, 6, 12, 50])
def test_reachable_targets_are_reached(n: int) -> None:
    ch = planar_chain(n, 10.0)
    rng = np.random.default_rng(n)
    lp = np.array([n * 10.0, 0.0])
    for _ in range(10):
        goal = rng.uniform(-0.4, 0.4, n)
        goal[0] = 0.0
        q = ch.pose(goal, (0, 0)).to_world(n - 1, lp)
        b = solve_ik(ch, np.zeros(n), (0, 0), n - 1, lp, q, tolerance=1e-4, max_iterations=200)
        assert ik_error(ch, b, (0, 0), n - 1, lp, q) < 1e-3


def test_unreachable_target_gives_the_best_stretch() -> None:
    ch = planar_chain(5, 10.0)
    lp = np.array([50.0, 0.0])
    q = np.array([0.0, -500.0])
    b = solve_ik(ch, np.full(5, 0.2), (0, 0), 4, lp, q, freeze_root=False)
    assert np.all(np.isfinite(b))
    assert ik_error(ch, b, (0, 0), 4, lp, q) == pytest.approx(450.0, abs=0.5)
    for far in ([1e9, 1e9], [0.0, 0.0]):
        c = solve_ik(ch, np.zeros(5), (0, 0), 4, lp, far)
        assert np.all(np.isfinite(c))
    assert np.array_equal(solve_ik(ch, np.zeros(5), (0, 0), 4, lp, [math.nan, 0.0]), np.zeros(5))


def test_limits_and_only_the_chain_moves(shared_data: Path) -> None:
    from qtanimator.formats.svg_rig import load_characters

    [ch] = load_characters(shared_data / "cmu-animator" / "scenes" / "character.svg")
    n = len(ch.joints)
    hand = 6
    chain = ch.ancestors(hand)
    a = np.zeros(n)
    pose = ch.pose(a, (0, 0))
    lp = ch.joints[hand].pivot + np.array([-20.0, 0.0])
    q = pose.to_world(hand, lp) + np.array([30.0, 60.0])
    limits = np.tile([-0.2, 0.2], (n, 1))
    b = solve_ik(ch, a, (0, 0), hand, lp, q, limits=limits)
    moved = set(np.flatnonzero((np.abs(b - a) > 1e-12) & ~ch.dynamic))
    assert moved and moved <= set(chain) - {0}
    # dynamic flaps on the moved limbs keep their world angle (their local angle compensates)
    np.testing.assert_allclose(ch.pose(b, (0, 0)).world_angles[ch.dynamic], pose.world_angles[ch.dynamic],
                               atol=1e-12)
    keyed = ~ch.dynamic
    assert np.all(b[keyed] >= -0.2 - 1e-12) and np.all(b[keyed] <= 0.2 + 1e-12)
    assert ik_error(ch, b, (0, 0), hand, lp, q) < ik_error(ch, a, (0, 0), hand, lp, q)
    free = solve_ik(ch, a, (0, 0), hand, lp, q)
    assert ik_error(ch, free, (0, 0), hand, lp, q) < 1e-3


def _with_dynamic(ch: Character, dyn: int) -> Character:
    joints = [Joint(j.name, j.parent, j.pivot, is_dynamic=(i == dyn), shapes=j.shapes)
              for i, j in enumerate(ch.joints)]
    return Character(ch.name, joints)


def test_jacobian_with_a_dynamic_ancestor_matches_finite_differences() -> None:
    ch = _with_dynamic(planar_chain(6, 10.0), 3)
    a = np.array([0.1, 0.2, -0.3, 0.4, 0.1, -0.2])
    pose = ch.pose(a, (0, 0))
    lp = np.array([60.0, 0.0])
    c = _Chain(ch, a, (0, 0), 5, lp, freeze_root=True)
    _, piv, tip = c.evaluate(np.zeros(6))
    np.testing.assert_allclose(tip, pose.to_world(5, lp), atol=1e-9)
    jac = c.jacobian(piv, tip)
    h = 1e-6
    for k in range(6):
        d = np.zeros(6)
        d[k] = h
        fd = (c.evaluate(d)[2] - c.evaluate(-d)[2]) / (2 * h)
        if c.var[k]:
            np.testing.assert_allclose(jac[:, k], fd, atol=1e-5)
        else:
            assert np.all(jac[:, k] == 0)
    # The held FK agrees with the full FK where the dynamic joint keeps its world angle.
    d = np.array([0.0, 0.3, 0.2, 0.0, 0.0, 0.0])
    b = a + d
    b[3] -= 0.5
    np.testing.assert_allclose(c.evaluate(d)[2], ch.pose(b, (0, 0)).to_world(5, lp), atol=1e-9)


def test_dynamic_ancestor_keeps_its_world_angle() -> None:
    ch = _with_dynamic(planar_chain(6, 10.0), 3)
    a = np.zeros(6)
    lp = np.array([60.0, 0.0])
    q = np.array([45.0, -20.0])
    b = solve_ik(ch, a, (0, 0), 5, lp, q)
    pa, pb = ch.pose(a, (0, 0)), ch.pose(b, (0, 0))
    assert pb.world_angles[3] == pytest.approx(pa.world_angles[3])
    assert ik_error(ch, b, (0, 0), 5, lp, q) < 1e-3


def test_mirrored_character() -> None:
    # the same chain mirrored in x (as an SVG scale(-1, 1) bakes it) solves as well
    base = planar_chain(4, 10.0)
    joints = [Joint(j.name, j.parent, j.pivot * [-1, 1], shapes=[Shape(s.points * [-1, 1], True) for s in j.shapes])
              for j in base.joints]
    ch = Character("mirrored", joints)
    lp = np.array([-40.0, 0.0])
    q = np.array([-25.0, -10.0])  # 25 from the first free pivot (−5, 5); the free links reach 30
    b = solve_ik(ch, np.zeros(4), (5, 5), 3, lp, q)
    assert ik_error(ch, b, (5, 5), 3, lp, q) < 1e-3
