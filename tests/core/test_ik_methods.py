"""CCD, FABRIK and the analytic two-bone IK solvers, 2D (qtanimator.core.ik_methods) and 3D
(qtanimator.core.ik3d_methods): reach, degenerate input, limits, the closed form."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from qtanimator.core.ik import IKStats, ik_error, planar_chain
from qtanimator.core.ik3d import chain_dofs, end_position
from qtanimator.core.ik3d_methods import solve_ccd as ccd3d
from qtanimator.core.ik3d_methods import solve_fabrik as fabrik3d
from qtanimator.core.ik3d_methods import solve_two_bone as two_bone3d
from qtanimator.core.ik3d_methods import two_bone_joints
from qtanimator.core.ik_methods import (
    solve_ccd,
    solve_fabrik,
    solve_two_bone,
    two_bone_applies,
    two_bone_closed_form,
)
from qtanimator.core.rig2d import Character, Joint, Shape
from qtanimator.core.skeleton import Dof, Skeleton
from qtanimator.core.skeleton import Joint as Joint3

ITERATIVE_2D: dict[str, Callable[..., np.ndarray]] = {"ccd": solve_ccd, "fabrik": solve_fabrik}
ITERATIVE_3D: dict[str, Callable[..., Any]] = {"ccd": ccd3d, "fabrik": fabrik3d}


# ------------------------------------------------------------------------------ 2D
def chain2d(lengths: list[float], seed: int = 0, dynamic: int | None = None) -> Character:
    """A chain of joints with the given bone lengths (0 allowed) in random directions;
    ``ch.tip`` is the end of the last bone."""
    rng = np.random.default_rng(seed)
    joints = []
    p = np.zeros(2)
    for i, length in enumerate(lengths):
        nxt = p + length * np.array([math.cos(rng.uniform(-1, 1)), math.sin(rng.uniform(-1, 1))])
        pts = np.array([p + (0, -1), nxt + (0, -1), nxt + (0, 1), p + (0, 1)])
        joints.append(Joint(f"j{i}", None if i == 0 else i - 1, p.copy(), is_dynamic=(i == dynamic),
                            shapes=[Shape(pts, True)]))
        p = nxt
    ch = Character("chain", joints)
    ch.tip = p  # type: ignore[attr-defined]
    return ch


def random_chain2d(n: int, seed: int) -> Character:
    rng = np.random.default_rng(seed)
    return chain2d([float(x) for x in rng.uniform(5, 30, n)], seed)


@pytest.mark.parametrize("method", sorted(ITERATIVE_2D))
@pytest.mark.parametrize("n", [3, 4, 6, 9])
def test_2d_reachable_random_targets_on_random_chains_are_reached(method: str, n: int) -> None:
    solve = ITERATIVE_2D[method]
    for seed in range(25):
        ch = random_chain2d(n, seed)
        rng = np.random.default_rng(seed + 1000)
        start = rng.uniform(-1, 1, n)
        goal = rng.uniform(-1, 1, n)
        goal[0] = start[0]  # the root is frozen: the target must be reachable without it
        lp = ch.tip  # type: ignore[attr-defined]
        q = ch.pose(goal, (3, -2)).to_world(n - 1, lp)
        stats = IKStats()
        b = solve(ch, start, (3, -2), n - 1, lp, q, max_iterations=5000, stats=stats)
        assert np.all(np.isfinite(b))
        assert b[0] == start[0]
        err = ik_error(ch, b, (3, -2), n - 1, lp, q)
        assert err < 1e-3, (seed, err)
        assert stats.method == method and stats.error == pytest.approx(err, abs=1e-9) and stats.iterations >= 1


@pytest.mark.parametrize("method", sorted(ITERATIVE_2D))
@pytest.mark.parametrize("n", [6, 12, 50])
def test_2d_long_chains_from_straight(method: str, n: int) -> None:
    ch = planar_chain(n, 10.0)
    rng = np.random.default_rng(n)
    lp = np.array([n * 10.0, 0.0])
    for _ in range(8):
        goal = rng.uniform(-0.4, 0.4, n)
        goal[0] = 0.0
        q = ch.pose(goal, (0, 0)).to_world(n - 1, lp)
        b = ITERATIVE_2D[method](ch, np.zeros(n), (0, 0), n - 1, lp, q, max_iterations=500)
        assert ik_error(ch, b, (0, 0), n - 1, lp, q) < 1e-3


@pytest.mark.parametrize("method", sorted(ITERATIVE_2D))
def test_2d_only_the_chain_moves_and_dynamic_joints_keep_their_world_angle(method: str) -> None:
    ch = chain2d([10.0] * 7, seed=4, dynamic=3)
    # a side branch off joint 2 must not move
    a = np.array([0.0, 0.3, -0.2, 0.5, 0.1, -0.3, 0.2])
    lp = ch.tip  # type: ignore[attr-defined]
    before = ch.pose(a, (0, 0))
    q = ch.pose(np.array([0.0, -0.2, 0.4, 0.0, -0.3, 0.2, 0.3]), (0, 0)).to_world(6, lp)
    b = ITERATIVE_2D[method](ch, a, (0, 0), 6, lp, q, max_iterations=500)
    after = ch.pose(b, (0, 0))
    assert after.world_angles[3] == pytest.approx(before.world_angles[3], abs=1e-12)
    assert b[0] == a[0]
    assert ik_error(ch, b, (0, 0), 6, lp, q) < ik_error(ch, a, (0, 0), 6, lp, q)
    # the joint above the dragged one only: joints below the dragged joint keep their angles
    c = ITERATIVE_2D[method](ch, a, (0, 0), 4, ch.joints[5].pivot, q, max_iterations=50)
    np.testing.assert_array_equal(c[5:], a[5:])


@pytest.mark.parametrize("method", [*sorted(ITERATIVE_2D), "two_bone"])
def test_2d_degenerate_and_unreachable_targets_never_give_nan(method: str) -> None:
    solve: Callable[..., np.ndarray] = ITERATIVE_2D.get(method, solve_two_bone)
    n = 3 if method == "two_bone" else 5
    straight = planar_chain(n, 10.0)      # collinear chain, along +x from (0, 0)
    lp = np.array([n * 10.0, 0.0])
    targets = [(0.0, 0.0),                # on the root's pivot
               (10.0, 0.0),               # on the first moving pivot
               (25.0, 0.0),               # in line with the straight chain, inside its reach
               (-30.0, 0.0),              # in line, behind
               (1e9, 1e9),                # far out of reach
               (n * 10.0, 0.0)]           # where the end already is
    for q in targets:
        b = solve(straight, np.zeros(n), (0, 0), n - 1, lp, q)
        assert np.all(np.isfinite(b)), q
        assert ik_error(straight, b, (0, 0), n - 1, lp, q) <= ik_error(straight, np.zeros(n), (0, 0), n - 1, lp,
                                                                        q) + 1e-9
    # out of reach: the chain points at the target (the best stretch)
    far = np.array([0.0, -500.0])
    b = solve(straight, np.full(n, 0.2), (0, 0), n - 1, lp, far, freeze_root=False, max_iterations=2000) \
        if method != "two_bone" else solve(straight, np.full(n, 0.2), (0, 0), n - 1, lp, far)
    first_pivot = straight.pose(np.full(n, 0.2), (0, 0)).pivots[1]   # the frozen root turned by 0.2
    expected = 500.0 - n * 10.0 if method != "two_bone" else float(np.hypot(*(far - first_pivot))) - 20.0
    assert ik_error(straight, b, (0, 0), n - 1, lp, far) == pytest.approx(expected, abs=0.05)
    # zero-length bones, and the grabbed point on the dragged joint's pivot
    lengths = [10.0, 0.0, 10.0] if method == "two_bone" else [10.0, 0.0, 10.0, 0.0, 10.0]
    ch = chain2d(lengths, seed=2)
    m = len(lengths)
    for lp2 in (ch.tip, ch.joints[m - 1].pivot):  # type: ignore[attr-defined]
        for q in ((0.0, 0.0), (5.0, 5.0), (1e6, 0.0)):
            b = solve(ch, np.full(m, 0.1), (0, 0), m - 1, lp2, q)
            assert np.all(np.isfinite(b))
    # not a point: nothing moves
    for q in ((math.nan, 0.0), (math.inf, 1.0)):
        np.testing.assert_array_equal(solve(straight, np.full(n, 0.1), (0, 0), n - 1, lp, q), np.full(n, 0.1))


@pytest.mark.parametrize("method", [*sorted(ITERATIVE_2D), "two_bone"])
@pytest.mark.parametrize("form", ["array", "list"])
def test_2d_limits_are_respected(method: str, form: str) -> None:
    solve: Callable[..., np.ndarray] = ITERATIVE_2D.get(method, solve_two_bone)
    n = 3 if method == "two_bone" else 6
    for seed in range(20):
        ch = random_chain2d(n, seed)
        rng = np.random.default_rng(seed)
        a = rng.uniform(-0.5, 0.5, n)
        lo, hi = a - rng.uniform(0.05, 0.6, n), a + rng.uniform(0.05, 0.6, n)
        lo[0], hi[0] = a[0] + 1.0, a[0] + 2.0   # the frozen root outside its limits: still not moved
        free = seed % 3 == 0   # some joints free, as character2d.joint_limits gives None
        limits: Any = np.column_stack([lo, hi])
        if free:
            limits[1] = (-math.inf, math.inf)
        if form == "list":
            limits = [None if free and k == 1 else (float(lo[k]), float(hi[k])) for k in range(n)]
        lp = ch.tip  # type: ignore[attr-defined]
        q = ch.pose(rng.uniform(-1.5, 1.5, n), (0, 0)).to_world(n - 1, lp)
        b = solve(ch, a, (0, 0), n - 1, lp, q, limits=limits)
        assert b[0] == a[0]
        check = np.ones(n, dtype=bool)
        check[0] = False
        if free:
            check[1] = False
        assert np.all(b[check] >= lo[check] - 1e-12) and np.all(b[check] <= hi[check] + 1e-12), seed
        assert np.all(np.isfinite(b))
        # never further than the start (inside its limits): CCD's clamped turns each lower the
        # distance, FABRIK keeps its best pass, two-bone keeps the start when projections are worse
        assert ik_error(ch, b, (0, 0), n - 1, lp, q) <= ik_error(ch, a, (0, 0), n - 1, lp, q) + 1e-9


def _bend_sign(ch: Character, angles: np.ndarray, lp: np.ndarray) -> float:
    """The sign of the middle joint's turn in joint angles (counter-clockwise on screen is
    positive: with y down that is a negative cross product)."""
    pose = ch.pose(angles, (0, 0))
    a, b, e = pose.pivots[1], pose.pivots[2], pose.to_world(2, lp)
    u, v = b - a, e - b
    return -float(np.sign(u[0] * v[1] - u[1] * v[0]))


def test_2d_two_bone_matches_the_law_of_cosines() -> None:
    for seed in range(40):
        ch = random_chain2d(3, seed)   # root frozen: two moving joints
        assert two_bone_applies(ch, 2) and not two_bone_applies(ch, 1) and not two_bone_applies(ch, 2, False)
        rng = np.random.default_rng(seed)
        lp = ch.tip  # type: ignore[attr-defined]
        a0 = rng.uniform(-1, 1, 3)
        pose0 = ch.pose(a0, (0, 0))
        pa = pose0.pivots[1]
        l1 = float(np.hypot(*(ch.rest_pivots[2] - ch.rest_pivots[1])))
        l2 = float(np.hypot(*(lp - ch.rest_pivots[2])))
        # a reachable target: distance between |l1 − l2| and l1 + l2, any direction
        d = rng.uniform(abs(l1 - l2) + 1e-3, l1 + l2 - 1e-3)
        phi = rng.uniform(-math.pi, math.pi)
        q = pa + d * np.array([math.cos(phi), math.sin(phi)])
        for bend in ("keep", "positive", "negative"):
            stats = IKStats()
            b = solve_two_bone(ch, a0, (0, 0), 2, lp, q, bend=bend, stats=stats)
            pose = ch.pose(b, (0, 0))
            pb, end = pose.pivots[2], pose.to_world(2, lp)
            assert np.hypot(*(end - q)) < 1e-9 and stats.iterations == 1
            # the law of cosines: the angle at the first pivot and at the middle one
            inner = math.acos((l1 * l1 + l2 * l2 - d * d) / (2 * l1 * l2))
            alpha = math.acos((l1 * l1 + d * d - l2 * l2) / (2 * l1 * d))
            u, v = pb - pa, q - pa
            assert math.acos(np.clip(u @ v / (np.hypot(*u) * np.hypot(*v)), -1, 1)) == pytest.approx(alpha, abs=1e-7)
            w = end - pb
            assert math.acos(np.clip(-u @ w / (np.hypot(*u) * np.hypot(*w)), -1, 1)) == pytest.approx(inner,
                                                                                                         abs=1e-7)
            first, turn = two_bone_closed_form(l1, l2, d, 1)
            assert abs(turn) == pytest.approx(math.pi - inner) and abs(first) == pytest.approx(alpha)
            want = {"positive": 1.0, "negative": -1.0, "keep": _bend_sign(ch, a0, lp)}[bend]
            assert _bend_sign(ch, b, lp) == want
            # only the two moving joints changed
            assert b[0] == a0[0]


def test_2d_two_bone_uses_the_other_side_when_limits_forbid_one() -> None:
    ch = planar_chain(3, 10.0)
    lp = np.array([30.0, 0.0])
    q = np.array([20.0, 5.0])
    limits = [None, (-math.pi, math.pi), (0.0, math.pi)]  # the middle joint bends positively only
    b = solve_two_bone(ch, np.zeros(3), (0, 0), 2, lp, q, limits=limits, bend="negative")
    assert b[2] >= 0 and ik_error(ch, b, (0, 0), 2, lp, q) < 1e-9
    # neither side fits: projected onto the limits, closer than the start
    tight = [None, (-0.1, 0.1), (0.0, 0.2)]
    c = solve_two_bone(ch, np.zeros(3), (0, 0), 2, lp, q, limits=tight)
    assert -0.1 <= c[1] <= 0.1 and 0.0 <= c[2] <= 0.2
    assert ik_error(ch, c, (0, 0), 2, lp, q) < ik_error(ch, np.zeros(3), (0, 0), 2, lp, q)
    with pytest.raises(ValueError):
        solve_two_bone(ch, np.zeros(3), (0, 0), 2, lp, q, bend="sideways")
    with pytest.raises(ValueError):
        solve_two_bone(planar_chain(4, 10.0), np.zeros(4), (0, 0), 3, [40.0, 0.0], q)


# ------------------------------------------------------------------------------ 3D
def random_skeleton(n: int, seed: int, order: str = "zyx", limits: tuple[float, float] = (-1e5, 1e5),
                    zero: int | None = None) -> Skeleton:
    rng = np.random.default_rng(seed)

    def dofs() -> tuple[Dof, Dof, Dof]:
        return Dof(0, *limits), Dof(0, *limits), Dof(0, *limits)

    joints = [Joint3("root", None, (0, 0, 0), dofs())]
    for i in range(1, n):
        offset = np.zeros(3) if i == zero else rng.uniform(-1, 1, 3)
        joints.append(Joint3(f"j{i}", i - 1, offset, dofs()))
    return Skeleton(joints, rotation_order=order)


def _pose(skel: Skeleton, start: np.ndarray, result: Any) -> np.ndarray:
    v = start.copy()
    for (j, a), x in result.values.items():
        v[j, a] = x
    return v


@pytest.mark.parametrize("method", sorted(ITERATIVE_3D))
@pytest.mark.parametrize("order", ["zyx", "xyz", "yzx"])
def test_3d_reachable_random_targets_on_random_skeletons_are_reached(method: str, order: str) -> None:
    for seed in range(15):
        sk = random_skeleton(6, seed, order)
        rng = np.random.default_rng(seed + 100)
        dofs = chain_dofs(sk, 5, 3)
        start = rng.uniform(-1, 1, (6, 3))
        goal = start.copy()
        for j, a in dofs:
            goal[j, a] = rng.uniform(-1.5, 1.5)
        q = end_position(sk, goal, 5)
        r = ITERATIVE_3D[method](sk, 5, q, dofs=dofs, values=start, iterations=1000)
        v = _pose(sk, start, r)
        assert np.all(np.isfinite(v))
        err = float(np.linalg.norm(end_position(sk, v, 5) - q))
        assert err < 1e-3 and r.error == pytest.approx(err, abs=1e-12), (seed, err)
        untouched = np.ones((6, 3), dtype=bool)
        for j, a in dofs:
            untouched[j, a] = False
        np.testing.assert_array_equal(v[untouched], start[untouched])
    np.testing.assert_array_equal(sk.dof_values(), np.zeros((6, 3)))  # the skeleton is left alone


def _closed_form_knee(a: np.ndarray, knee: np.ndarray, q: np.ndarray, l1: float, l2: float) -> np.ndarray:
    """Where the law of cosines puts the knee: at angle α from the line to the target, in
    the plane of that line and the current knee, on the knee's side."""
    d = float(np.linalg.norm(q - a))
    alpha = math.acos((l1 * l1 + d * d - l2 * l2) / (2 * l1 * d))
    u = (q - a) / d
    side = (knee - a) - ((knee - a) @ u) * u
    side /= np.linalg.norm(side)
    return a + l1 * (math.cos(alpha) * u + math.sin(alpha) * side)


@pytest.mark.parametrize("order", ["zyx", "xyz"])
def test_3d_two_bone_matches_the_law_of_cosines(order: str) -> None:
    for seed in range(30):
        sk = random_skeleton(4, seed, order)
        rng = np.random.default_rng(seed)
        start = rng.uniform(-1, 1, (4, 3))
        dofs = chain_dofs(sk, 3, 2)
        assert two_bone_joints(sk, 3, dofs) == (1, 2) and two_bone_joints(sk, 3, chain_dofs(sk, 3, 1)) is None
        w = sk.world_matrices(start)
        a, knee, c = w[1, :3, 3], w[2, :3, 3], w[3, :3, 3]
        l1, l2 = float(np.linalg.norm(knee - a)), float(np.linalg.norm(c - knee))
        d = rng.uniform(abs(l1 - l2) + 1e-3, l1 + l2 - 1e-3)
        direction = rng.normal(size=3)
        q = a + d * direction / np.linalg.norm(direction)
        r = two_bone3d(sk, 3, q, dofs=dofs, values=start)
        v = _pose(sk, start, r)
        w2 = sk.world_matrices(v)
        assert r.iterations == 1 and r.error < 1e-9
        np.testing.assert_allclose(w2[3, :3, 3], q, atol=1e-9)
        np.testing.assert_allclose(w2[2, :3, 3], _closed_form_knee(a, knee, q, l1, l2), atol=1e-9)
        # with a pole: the knee goes to the pole's side of the line to the target
        pole = a + rng.normal(size=3)
        r = two_bone3d(sk, 3, q, dofs=dofs, values=start, pole=pole)
        w3 = sk.world_matrices(_pose(sk, start, r))
        np.testing.assert_allclose(w3[3, :3, 3], q, atol=1e-9)
        np.testing.assert_allclose(w3[2, :3, 3], _closed_form_knee(a, pole, q, l1, l2), atol=1e-9)


def test_3d_two_bone_with_a_hinge_knee() -> None:
    # the middle joint turns about z only (its x and y locked), as an elbow
    for seed in range(15):
        sk = random_skeleton(4, seed)
        for ax in (0, 1):
            sk.joints[2].dofs[ax].set_limits(0.0, 0.0)
        dofs = chain_dofs(sk, 3, 2)
        assert {a for j, a in dofs if j == 2} == {2}
        rng = np.random.default_rng(seed)
        start = np.zeros((4, 3))
        start[1] = rng.uniform(-1, 1, 3)
        goal = start.copy()
        goal[1] = rng.uniform(-1.5, 1.5, 3)
        goal[2, 2] = rng.uniform(-2, 2)
        q = end_position(sk, goal, 3)
        r = two_bone3d(sk, 3, q, dofs=dofs, values=start)
        v = _pose(sk, start, r)
        assert np.linalg.norm(end_position(sk, v, 3) - q) < 1e-3
        assert v[2, 0] == 0.0 and v[2, 1] == 0.0


@pytest.mark.parametrize("method", [*sorted(ITERATIVE_3D), "two_bone"])
def test_3d_degenerate_and_unreachable_targets_never_give_nan(method: str) -> None:
    solve: Callable[..., Any] = ITERATIVE_3D.get(method, two_bone3d)
    chain_length = 2 if method == "two_bone" else 3
    straight = Skeleton([Joint3("root", None, (0, 0, 0)), Joint3("a", 0, (0, 1, 0)), Joint3("b", 1, (1, 0, 0)),
                         Joint3("c", 2, (1, 0, 0)), Joint3("d", 3, (1, 0, 0))])
    end = 4 if method != "two_bone" else 3
    dofs = chain_dofs(straight, end, chain_length)
    top = straight.world_matrices()[dofs[-1][0], :3, 3]
    for q in ((0, 0, 0), tuple(top), (2.5, 1, 0), (-3, 1, 0), (1e9, -1e9, 0), (0.5, 1, 0)):
        r = solve(straight, end, np.array(q, dtype=float), dofs=dofs)
        assert all(math.isfinite(x) for x in r.values.values()) and math.isfinite(r.error), q
    # a zero-length bone (a joint on its parent's pivot)
    sk = random_skeleton(5, 3, zero=3)
    dofs = chain_dofs(sk, 4, chain_length)
    for q in ((0, 0, 0), (0.3, 0.2, 0.1), (50, 0, 0)):
        r = solve(sk, 4, np.array(q, dtype=float), dofs=dofs)
        assert all(math.isfinite(x) for x in r.values.values())
    r = solve(straight, end, np.array([math.nan, 0, 0]), dofs=chain_dofs(straight, end, chain_length))
    assert all(x == 0.0 for x in r.values.values()) and math.isnan(r.error)


@pytest.mark.parametrize("method", [*sorted(ITERATIVE_3D), "two_bone"])
def test_3d_limits_are_respected(method: str) -> None:
    solve: Callable[..., Any] = ITERATIVE_3D.get(method, two_bone3d)
    chain_length = 2 if method == "two_bone" else 3
    for seed in range(10):
        sk = random_skeleton(5, seed, limits=(-0.4, 0.5))
        sk.joints[2].dofs[1].set_limits(0.2, 0.2)   # a locked DOF: never in the chain, never moved
        dofs = chain_dofs(sk, 4, chain_length)
        assert (2, 1) not in dofs
        rng = np.random.default_rng(seed)
        q = rng.uniform(-2, 2, 3)
        r = solve(sk, 4, q, dofs=dofs)
        lo, hi = sk.dof_limits()
        for (j, a), x in r.values.items():
            assert lo[j, a] - 1e-12 <= x <= hi[j, a] + 1e-12
        start_err = float(np.linalg.norm(end_position(sk, sk.dof_values(), 4) - q))
        assert r.error <= start_err + 1e-9
