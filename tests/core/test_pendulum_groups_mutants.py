"""Pendulum groups and pivot accelerations against hand computations (targets mutation-test
survivors): how dynamic joints group (coupled or not), which mass properties they take, how
the length scale scales offsets and moments, and the pivot accelerations against finite
differences of the forward kinematics."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.mass import MassProperties
from qtanimator.core.pendulum_groups import (
    build_groups,
    perp,
    pivot_accelerations,
    rotate,
    rotation_pivot_terms,
)
from qtanimator.core.pendulum_params import PendulumParams
from qtanimator.core.rig2d import Character, Joint, rotation

PIVOTS = [(0.0, 0.0), (10.0, 0.0), (10.0, 30.0), (16.0, 8.0), (10.0, 50.0), (12.0, 70.0)]
PARENTS = [None, 0, 1, 1, 2, 4]
DYNAMIC = [False, True, True, True, False, True]


def mp(k: int, reference: bool = False) -> MassProperties:
    """Distinct numbers per joint; the reference set differs from the exact one."""
    pivot = np.array(PIVOTS[k])
    y0 = np.array([1.0 + k, 5.0 + 2 * k]) * (2.0 if reference else 1.0)
    moment = 100.0 * (k + 1) * (3.0 if reference else 1.0)
    return MassProperties(2.0 + k + (10.0 if reference else 0.0), pivot + y0, moment, pivot)


def tree() -> Character:
    """0 keyed root; 1 dynamic; 2, 3 dynamic children of 1; 4 keyed child of 2; 5 dynamic
    child of 4 (a pendulum hanging from a keyed joint below a dynamic chain)."""
    return Character("t", [Joint(f"j{k}", PARENTS[k], np.array(PIVOTS[k]), is_dynamic=DYNAMIC[k],
                                 mass_properties=mp(k), reference_mass_properties=mp(k, True))
                           for k in range(len(PIVOTS))])


def test_rotate_and_perp_by_hand() -> None:
    """R(θ) = [[c, s], [−s, c]] (rig2d's convention); J(x, y) = (y, −x) = R(π/2)."""
    v = np.array([[3.0, 4.0], [-1.0, 2.0]])
    th = np.array([0.3, -2.0])
    out = rotate(v, th)
    for i in range(2):
        np.testing.assert_allclose(out[i], rotation(th[i]) @ v[i], rtol=1e-14)
    np.testing.assert_array_equal(perp(v), [[4.0, -3.0], [2.0, 1.0]])
    np.testing.assert_allclose(perp(v), rotate(v, np.full(2, math.pi / 2)), atol=1e-14)


def test_coupled_groups_follow_dynamic_parents_in_pre_order() -> None:
    groups = build_groups(tree(), PendulumParams(coupled=True))
    assert [g.joints for g in groups] == [[1, 2, 3], [5]]
    assert [g.top for g in groups] == [1, 5]
    np.testing.assert_array_equal(groups[0].parent, [-1, 0, 0])
    np.testing.assert_array_equal(groups[1].parent, [-1])
    # ancestor[i, k]: i is k or an ancestor of k
    np.testing.assert_array_equal(groups[0].ancestor, [[1, 1, 1], [0, 1, 0], [0, 0, 1]])
    # arm[i, k]: i's pivot to the point of i that carries k (k's own: its centre-of-mass offset)
    arm = groups[0].arm
    np.testing.assert_array_equal(arm[0, 0], [2.0, 7.0])
    np.testing.assert_array_equal(arm[0, 1], [0.0, 30.0])  # pivot 2 − pivot 1
    np.testing.assert_array_equal(arm[0, 2], [6.0, 8.0])  # pivot 3 − pivot 1
    np.testing.assert_array_equal(arm[1, 1], [3.0, 9.0])
    np.testing.assert_array_equal(arm[1, 2], [0.0, 0.0])
    np.testing.assert_array_equal(arm[2, 1], [0.0, 0.0])


def test_uncoupled_groups_are_one_joint_each() -> None:
    groups = build_groups(tree(), PendulumParams(coupled=False))
    assert [g.joints for g in groups] == [[1], [2], [3], [5]]
    for g in groups:
        np.testing.assert_array_equal(g.parent, [-1])
        np.testing.assert_array_equal(g.ancestor, [[True]])
        k = g.top
        np.testing.assert_array_equal(g.offset[0], [1.0 + k, 5.0 + 2 * k])
        np.testing.assert_array_equal(g.arm[0, 0], g.offset[0])
        assert g.mass[0] == 2.0 + k and g.inertia[0] == 100.0 * (k + 1)


def test_no_dynamic_joint_no_group() -> None:
    ch = Character("k", [Joint("a", None, np.zeros(2)), Joint("b", 0, np.ones(2))])
    assert build_groups(ch, PendulumParams()) == []


def test_a_dynamic_root_is_a_group() -> None:
    ch = Character("d", [Joint("a", None, np.zeros(2), is_dynamic=True,
                               mass_properties=MassProperties(1.0, np.array([0.0, 2.0]), 4.0, np.zeros(2)))])
    [g] = build_groups(ch, PendulumParams())
    assert g.joints == [0]
    np.testing.assert_array_equal(g.parent, [-1])


@pytest.mark.parametrize("inertia", ["exact", "reference"])
def test_the_mass_properties_follow_the_inertia_setting(inertia: str) -> None:
    """``reference`` takes the starter's mass, centre and moment; ``exact`` the shapes' own."""
    ref = inertia == "reference"
    [g, _] = build_groups(tree(), PendulumParams(inertia=inertia))
    for i, k in enumerate(g.joints):
        want = mp(k, ref)
        assert g.mass[i] == want.mass and g.inertia[i] == want.inertia
        np.testing.assert_allclose(g.offset[i], want.centroid - want.pivot, rtol=1e-15)


@pytest.mark.parametrize("s", [0.5, 2.0, 3.0, 1.0e-3])
def test_the_length_scale_scales_offsets_and_exact_moments(s: float) -> None:
    """Scaling every length by s keeps the mass, scales lever arms by s and an exact moment
    ∫r² dm by s². The reference moments are the handout's numbers and stay as they are
    (notes 9.4: g = 5000, L / 1000 with the unscaled reference I gives m g L / I = 51.5)."""
    for inertia, moment_factor in (("exact", s * s), ("reference", 1.0)):
        ref = inertia == "reference"
        [g, g5] = build_groups(tree(), PendulumParams(length_scale=s, inertia=inertia))
        for i, k in enumerate(g.joints):
            want = mp(k, ref)
            assert g.mass[i] == want.mass
            assert g.inertia[i] == pytest.approx(want.inertia * moment_factor, rel=1e-14)
            np.testing.assert_allclose(g.offset[i], (want.centroid - want.pivot) * s, rtol=1e-14)
        np.testing.assert_allclose(g.arm[0, 1], np.array([0.0, 30.0]) * s, rtol=1e-14)
        np.testing.assert_allclose(g.arm[0, 2], np.array([6.0, 8.0]) * s, rtol=1e-14)
        assert g5.inertia[0] == pytest.approx(mp(5, ref).inertia * moment_factor, rel=1e-14)


def test_the_scaled_rig_is_the_rig_drawn_smaller() -> None:
    """A pendulum with length_scale s and exact moments is the same pendulum drawn s times as
    large with the same mass: offsets × s, moment × s²."""
    s = 0.25
    pivot = np.array([4.0, 6.0])
    y0, mass, moment = np.array([3.0, 40.0]), 2.0, 5000.0

    def bob(y: np.ndarray, inertia: float) -> Character:
        p = MassProperties(mass, pivot + y, inertia, pivot)
        return Character("c", [Joint("base", None, np.zeros(2)),
                               Joint("bob", 0, pivot, is_dynamic=True, mass_properties=p)])

    [a] = build_groups(bob(y0, moment), PendulumParams(length_scale=s))
    [b] = build_groups(bob(y0 * s, moment * s * s), PendulumParams())
    np.testing.assert_allclose(a.offset, b.offset, rtol=1e-15)
    np.testing.assert_allclose(a.inertia, b.inertia, rtol=1e-15)
    np.testing.assert_array_equal(a.mass, b.mass)


# ------------------------------------------------------------------ pivot accelerations
CHAIN_PIVOTS = np.array([[5.0, 2.0], [15.0, 2.0], [15.0, 30.0], [-4.0, 12.0]])
CHAIN_PARENTS = [None, 0, 1, 0]


def chain() -> Character:
    return Character("ch", [Joint(f"c{k}", CHAIN_PARENTS[k], CHAIN_PIVOTS[k]) for k in range(4)])


# local angle α_k(t) = A_k + B_k t + C_k t², root translation T(t) = D t² / 2
A = np.array([0.3, -0.8, 1.2, 0.5])
B = np.array([1.5, -2.0, 0.7, 3.0])
C = np.array([-4.0, 2.5, 1.0, -1.5])
D = np.array([30.0, -12.0])


def world_state(ch: Character, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """World angles, rates and accelerations: each joint's local ones summed down the tree."""
    local = (A + B * t + C * t * t, B + 2 * C * t, 2 * C)
    anc = np.zeros((4, 4))
    for k in range(4):
        for j in ch.ancestors(k):
            anc[k, j] = 1.0
    return anc @ local[0], anc @ local[1], anc @ local[2]


def fk_pivots(ch: Character, t: float) -> np.ndarray:
    return ch.pose(A + B * t + C * t * t, 0.5 * D * t * t).pivots


def test_pivot_accelerations_match_finite_differences_of_the_pivots() -> None:
    """p'' of every pivot by a central second difference of the forward kinematics (O(h²))."""
    ch, t, h = chain(), 0.37, 1e-3
    fd = (fk_pivots(ch, t + h) - 2 * fk_pivots(ch, t) + fk_pivots(ch, t - h)) / (h * h)
    w, r, a = world_state(ch, t)
    got = pivot_accelerations(ch, w, r, a, D)
    np.testing.assert_allclose(got, fd, rtol=1e-5, atol=1e-4)
    assert np.abs(got[2] - got[1]).max() > 10.0  # the rotation terms matter here


def test_pivot_acceleration_scales_apply_to_their_own_part() -> None:
    """The translation part scales by accel_scale, the rotation part by rotation_accel_scale."""
    ch, t = chain(), 0.37
    w, r, a = world_state(ch, t)
    trans = pivot_accelerations(ch, w, r, a, D, 1.0, 0.0)
    rot = pivot_accelerations(ch, w, r, a, np.zeros(2), 1.0, 1.0)
    np.testing.assert_allclose(trans, np.tile(D, (4, 1)), rtol=1e-15)
    assert np.all(rot[0] == 0.0)
    got = pivot_accelerations(ch, w, r, a, D, 0.25, 7.0)
    np.testing.assert_allclose(got, 0.25 * trans + 7.0 * rot, rtol=1e-12, atol=1e-9)


def test_rotation_pivot_terms_by_hand() -> None:
    """Θ = π/2, Θ' = 3, Θ'' = 2, v = (1, 0): R(π/2)·v = (0, −1), J·(0, −1) = (−1, 0);
    2·(−1, 0) − 9·(0, −1) = (−2, 9); scaled by 0.5: (−1, 4.5)."""
    out = rotation_pivot_terms(np.array([math.pi / 2, 0.0]), np.array([3.0, 0.0]), np.array([2.0, 1.0]),
                               np.array([[1.0, 0.0], [0.0, 4.0]]), 0.5)
    np.testing.assert_allclose(out[0], [-1.0, 4.5], atol=1e-14)
    # Θ = 0, Θ' = 0, Θ'' = 1, v = (0, 4): J·v = (4, 0), × 0.5
    np.testing.assert_allclose(out[1], [2.0, 0.0], atol=1e-14)


def test_rotate_and_perp_of_stacked_arms() -> None:
    """The chains' arms are (n, n, 2): R(θ_i) applies along the last axis, row by row."""
    rng = np.random.default_rng(8)
    v = rng.uniform(-5.0, 5.0, (3, 3, 2))
    th = rng.uniform(-3.0, 3.0, 3)
    out = rotate(v, th[:, None])
    assert out.shape == (3, 3, 2) and perp(v).shape == (3, 3, 2)
    for i in range(3):
        for k in range(3):
            np.testing.assert_allclose(out[i, k], rotation(th[i]) @ v[i, k], rtol=1e-13, atol=1e-13)
            np.testing.assert_array_equal(perp(v)[i, k], [v[i, k, 1], -v[i, k, 0]])


def test_rotation_pivot_terms_are_unscaled_by_default() -> None:
    """Θ = 0, Θ' = 2, Θ'' = 0, v = (3, 0): −Θ'²·v = (−12, 0)."""
    out = rotation_pivot_terms(np.zeros(1), np.array([2.0]), np.zeros(1), np.array([[3.0, 0.0]]))
    np.testing.assert_allclose(out, [[-12.0, 0.0]], atol=1e-14)
