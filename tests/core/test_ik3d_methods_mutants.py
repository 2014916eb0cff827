"""3D CCD / FABRIK / two-bone (core/ik3d_methods.py) on small skeletons worked out by hand:
FABRIK's backward pass when a pivot lands on the target, the two-bone solver's default
DOFs with an effector offset, its fall-back to the start pose when limits spoil the
analytic pose, and the knee turned to the pole side."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.ik3d_methods import solve_ccd, solve_fabrik, solve_two_bone
from qtanimator.core.skeleton import Dof, Joint, Skeleton


def free() -> tuple[Dof, Dof, Dof]:
    return (Dof(), Dof(), Dof())


def test_fabrik_backward_pass_when_the_target_is_on_a_pivot():
    """The backward pass pulls the end's parent towards the target; when the parent already
    sits on the target (no direction), it must keep the bone's current direction (from
    the end towards the parent), not borrow the bone above."""
    # a (0,0,0) -> b (1,0,0) -> c = b + (0,1,0): two bones of length 1, three free DOFs
    # each. Target = b. Backward: back[2] = b, back[1] = b + 1·unit(b - c) = (1,-1,0).
    # Forward: a turns so that b points at (1,-1,0): b' = (cos45°, -sin45°, 0); b then
    # aims c at the target, c' = b' + unit(target - b'). |target - b'|² = 2 - √2, so the
    # error after one pass is 1 - sqrt(2 - √2).
    sk = Skeleton([Joint("a", None, (0, 0, 0), free()), Joint("b", 0, (1, 0, 0), free()),
                   Joint("c", 1, (0, 1, 0), free())], rotation_order="xyz")
    dofs = [(j, a) for j in (0, 1) for a in range(3)]
    target = np.array([1.0, 0.0, 0.0])
    res = solve_fabrik(sk, 2, target, dofs=dofs, iterations=1, accelerate=False)
    assert res.iterations == 1
    s = math.sqrt(0.5)
    b1 = np.array([s, -s, 0.0])
    w = target - b1
    np.testing.assert_allclose(res.position, b1 + w / np.linalg.norm(w), atol=1e-12)
    assert res.error == pytest.approx(1.0 - math.sqrt(2.0 - math.sqrt(2.0)), abs=1e-12)


def test_two_bone_with_an_offset_defaults_to_the_free_dofs_of_the_end_and_its_parent():
    """With an effector offset the end and its parent are the two joints; their DOFs whose
    limits are not pinned are used (symmetric limits included, a pinned DOF left out)."""
    sk = Skeleton([Joint("a", None, (0, 0, 0), free()), Joint("b", 0, (1, 0, 0), free()),
                   Joint("c", 1, (1, 0, 0), (Dof(0.3, 0.3, 0.3), Dof(0, -3.0, 3.0), Dof()))],
                  rotation_order="xyz")
    # the effector is 0.8 beyond c: bones of 1 (b to c) and 0.8; the target is
    # sqrt(0.2² + 0.9² + 0.3²) = 0.97 from b, inside [0.2, 1.8]: the knee bends by
    # pi - acos((1 + 0.64 - 0.94) / 1.6) = 2.0 rad (< 3), so the analytic solve reaches it
    target = np.array([1.2, 0.9, 0.3])
    res = solve_two_bone(sk, 2, target, offset=[0.8, 0.0, 0.0])
    assert sorted(res.dofs) == [(1, 0), (1, 1), (1, 2), (2, 1), (2, 2)]
    assert res.error < 1e-5
    np.testing.assert_allclose(res.position, target, atol=1e-5)


def test_two_bone_falls_back_to_the_start_when_limits_spoil_the_analytic_pose():
    """The first joint is pinned: bending the middle to the target's distance alone ends
    further from the target than the start, so with no CCD sweeps the start is kept."""
    # a (0,0,0), b (1,0,0), end c = (1,1,0); the first joint's z is pinned at 0, the middle
    # turns about z. Target (1.1, 0.6): start error sqrt(0.1² + 0.4²) = sqrt(0.17). The
    # middle bend making |c - a| = |target| = sqrt(1.57) puts c at about (0.785, 0.977),
    # 0.49 from the target: worse. (The middle joint b is sqrt(0.37) from the target,
    # farther than the end, so comparing against b's distance would keep the bad pose.)
    sk = Skeleton([Joint("a", None, (0, 0, 0), (Dof(), Dof(), Dof(0, 0, 0))), Joint("b", 0, (1, 0, 0), free()),
                   Joint("c", 1, (0, 1, 0), free())], rotation_order="xyz")
    dofs = [(0, 2), (1, 2)]
    target = [1.1, 0.6, 0.0]
    res = solve_two_bone(sk, 2, target, dofs=dofs, iterations=0)
    assert res.values == {(0, 2): 0.0, (1, 2): 0.0}
    assert res.error == pytest.approx(math.sqrt(0.17), rel=1e-12)
    # with CCD sweeps the middle alone points the end at the target: the end on the
    # circle of radius 1 about b nearest the target, 1 - |target - b| = 1 - sqrt(0.37) away
    res = solve_two_bone(sk, 2, target, dofs=dofs)
    assert res.values[(0, 2)] == 0.0
    assert res.error == pytest.approx(1.0 - math.sqrt(0.37), abs=1e-7)


def test_two_bone_turns_the_knee_to_the_pole_even_when_the_end_cannot_get_closer():
    """The end is already on the line to an unreachable target and the middle joint is
    pinned: the error cannot change, but the knee must still swing to the pole's side."""
    # a (0,0,0), knee b (1,1,0), end c (2,0,0) on the x axis; target (5,0,0), pole below
    # (1,-1,0). The first joint turns half a turn about x (the line a -> target): c stays
    # at (2,0,0), the error stays 3, the knee goes to (1,-1,0).
    sk = Skeleton([Joint("a", None, (0, 0, 0), free()),
                   Joint("b", 0, (1, 1, 0), (Dof(), Dof(), Dof(0, 0, 0))),
                   Joint("c", 1, (1, -1, 0), free())], rotation_order="xyz")
    for iterations in (0, 100):
        res = solve_two_bone(sk, 2, [5.0, 0.0, 0.0], dofs=[(0, 0), (0, 1), (0, 2), (1, 2)],
                             pole=[1.0, -1.0, 0.0], iterations=iterations)
        np.testing.assert_allclose(res.position, [2.0, 0.0, 0.0], atol=1e-12)
        assert res.error == pytest.approx(3.0, abs=1e-12)
        v = np.zeros((3, 3))
        for (j, a), x in res.values.items():
            v[j, a] = x
        knee = sk.world_matrices(v)[1, :3, 3]
        np.testing.assert_allclose(knee, [1.0, -1.0, 0.0], atol=1e-12)


def test_two_bone_and_ccd_agree_with_the_law_of_cosines():
    """A reachable target in the bend plane: the two-bone solve is exact in one step and
    the middle joint's bend is the law-of-cosines angle."""
    # bones 1 and 1 along x, middle bent 90° about z (end offset (0,1,0)). Target at
    # distance d = 1.5 from a: the interior angle at the knee is acos((1 + 1 - d²)/2), so
    # the bend from straight is pi - that; the geometry already bends by pi/2.
    sk = Skeleton([Joint("a", None, (0, 0, 0), free()), Joint("b", 0, (1, 0, 0), free()),
                   Joint("c", 1, (0, 1, 0), free())], rotation_order="xyz")
    d = 1.5
    target = np.array([d * math.cos(0.4), d * math.sin(0.4), 0.0])
    res = solve_two_bone(sk, 2, target, dofs=[(0, 2), (1, 2)])
    assert res.iterations == 1
    assert res.error < 1e-9
    bend = math.pi - math.acos((2.0 - d * d) / 2.0)
    assert res.values[(1, 2)] == pytest.approx(bend - math.pi / 2, abs=1e-9)
    ccd = solve_ccd(sk, 2, target, dofs=[(0, 2), (1, 2)], tolerance=1e-10, iterations=200)
    assert ccd.error < 1e-9
    assert ccd.values[(1, 2)] == pytest.approx(bend - math.pi / 2, abs=1e-6)


def _arm(s: float) -> Skeleton:
    return Skeleton([Joint("root", None, (0, 0, 0), free()), Joint("shoulder", 0, np.array((0, 1, 0)) * s, free()),
                     Joint("elbow", 1, np.array((1, 0, 0)) * s, free()),
                     Joint("wrist", 2, np.array((0.75, 0.125, 0)) * s, free()),
                     Joint("hand", 3, np.array((0.25, 0, 0.125)) * s, free())], rotation_order="zyx")


@pytest.mark.parametrize("solver", [solve_fabrik, solve_ccd])
def test_solvers_are_scale_invariant(solver):
    """The same arm and target drawn 2^50 times smaller or 2^30 times larger (exact in
    floating point) give the same angles: every "too short to have a direction" threshold
    is relative to the chain's length."""
    target = np.array([0.5, 2.25, 0.75])
    ref = solver(_arm(1.0), 4, target, tolerance=1e-9, iterations=5)
    for s in (2.0 ** -50, 2.0 ** 30):
        res = solver(_arm(s), 4, target * s, tolerance=1e-9 * s, iterations=5)
        assert res.values == ref.values
        assert res.iterations == ref.iterations
        assert res.error == pytest.approx(ref.error * s, rel=1e-12)


def test_one_ccd_sweep_without_acceleration_by_hand():
    """Two unit bones along x, hinges about z; target (0.5, 1.2). A sweep turns the middle
    first (pointing the end from b = (1, 0) at the target), then the base (pointing the
    end from the origin at the target); without acceleration nothing else happens."""
    sk = Skeleton([Joint("a", None, (0, 0, 0)), Joint("b", 0, (1, 0, 0)), Joint("c", 1, (1, 0, 0))],
                  rotation_order="xyz")
    res = solve_ccd(sk, 2, [0.5, 1.2, 0.0], dofs=[(0, 2), (1, 2)], iterations=1, accelerate=False)
    t1 = math.atan2(1.2, 0.5 - 1.0)
    end = np.array([1.0 + math.cos(t1), math.sin(t1)])
    t0 = math.atan2(1.2, 0.5) - math.atan2(end[1], end[0])
    assert res.values[(1, 2)] == pytest.approx(t1, abs=1e-12)
    assert res.values[(0, 2)] == pytest.approx(t0, abs=1e-12)
    c, s = math.cos(t0), math.sin(t0)
    np.testing.assert_allclose(res.position, [c * end[0] - s * end[1], s * end[0] + c * end[1], 0.0], atol=1e-12)


def test_one_ccd_sweep_on_three_hinges_without_acceleration():
    """Three unit bones along x with z hinges, target (0, 3.2) out of reach. A 2D CCD sweep
    written out here (each pivot, from the last, turns the end towards the target; the
    pivots above do not move) gives the values; with ``accelerate=False`` no pattern move
    follows, even though one would help here."""
    sk = Skeleton([Joint("a", None, (0, 0, 0)), Joint("b", 0, (1, 0, 0)), Joint("c", 1, (1, 0, 0)),
                   Joint("d", 2, (1, 0, 0))], rotation_order="xyz")
    goal = np.array([0.0, 3.2])
    pivots = [np.array([0.0, 0.0]), np.array([1.0, 0.0]), np.array([2.0, 0.0])]
    end = np.array([3.0, 0.0])
    turns = [0.0, 0.0, 0.0]
    for k in (2, 1, 0):
        u, w = end - pivots[k], goal - pivots[k]
        turns[k] = math.atan2(u[0] * w[1] - u[1] * w[0], u @ w)
        c, s = math.cos(turns[k]), math.sin(turns[k])
        end = pivots[k] + np.array([c * u[0] - s * u[1], s * u[0] + c * u[1]])
    dofs = [(0, 2), (1, 2), (2, 2)]
    res = solve_ccd(sk, 3, [0.0, 3.2, 0.0], dofs=dofs, iterations=1, accelerate=False)
    assert [res.values[d] for d in dofs] == pytest.approx(turns, abs=1e-12)
    assert res.error == pytest.approx(float(np.linalg.norm(goal - end)), abs=1e-12)
    # the pattern move does help here: the accelerated sweep ends closer
    assert solve_ccd(sk, 3, [0.0, 3.2, 0.0], dofs=dofs, iterations=1).error < res.error - 0.1


@pytest.mark.parametrize("solver", [solve_ccd, solve_fabrik])
def test_no_free_dofs_returns_the_current_pose(solver):
    """With no DOF to turn nothing moves: the result is the end where it is, 0 iterations."""
    sk = _arm(1.0)
    res = solver(sk, 4, [0.5, 2.0, 0.5], dofs=[])
    assert res.iterations == 0 and res.values == {}
    np.testing.assert_allclose(res.position, [2.0, 1.125, 0.125], atol=1e-14)
    assert res.error == pytest.approx(math.sqrt(1.5 ** 2 + 0.875 ** 2 + 0.375 ** 2), rel=1e-12)


def test_a_straight_chain_bends_towards_the_pole():
    """Bones in line give no bend plane: the pole (a world point) chooses it. First pivot
    a = (0, 1, 0), bones of 1 along x, target 1.2 from a along x: the knee must come out
    on the pole's side, at height sqrt(1 - 0.6²) = 0.8 above the line towards the pole."""
    sk = Skeleton([Joint("root", None, (0, 0, 0)), Joint("a", 0, (0, 1, 0), free()), Joint("b", 1, (1, 0, 0), free()),
                   Joint("c", 2, (1, 0, 0), free())], rotation_order="xyz")
    a = np.array([0.0, 1.0, 0.0])
    for side in (np.array([0.0, 0.0, 1.0]), np.array([0.0, -0.6, 0.8])):
        res = solve_two_bone(sk, 3, a + [1.2, 0.0, 0.0], pole=a + [0.6, 0.0, 0.0] + 3.0 * side)
        assert res.error < 1e-9
        v = np.zeros((4, 3))
        for (j, ax), x in res.values.items():
            v[j, ax] = x
        knee = sk.world_matrices(v)[2, :3, 3]
        np.testing.assert_allclose(knee, a + [0.6, 0.0, 0.0] + 0.8 * side, atol=1e-9)


def _oblique_knee(scale: float) -> Skeleton:
    """a (3 free DOFs) -> b at (s, 0, 0), a hinge about z only -> c at b + (s, 0, s): the
    lower bone leans out of the hinge's plane (half of it along the hinge axis)."""
    return Skeleton([Joint("a", None, (0, 0, 0), free()),
                     Joint("b", 0, (scale, 0, 0), (Dof(0, 0, 0), Dof(0, 0, 0), Dof())),
                     Joint("c", 1, (scale, 0, scale), (Dof(0, 0, 0), Dof(0, 0, 0), Dof(0, 0, 0)))],
                    rotation_order="xyz")


OBLIQUE_DOFS = [(0, 0), (0, 1), (0, 2), (1, 2)]


def test_two_bone_hinge_oblique_to_the_lower_bone_is_solved_analytically():
    """Turning the hinge by theta about z moves c - b = (1, 0, 1) to (cos, sin, 1), so
    |c - a|^2 = (1 + cos)^2 + sin^2 + 1 = 3 + 2 cos(theta). A target 2 from a needs
    cos(theta) = 1/2: |theta| = pi/3, whatever the method. With no CCD sweep allowed
    (iterations=0) only the analytic step, which must split the lower bone into its part
    along the hinge and the part across it, can get there."""
    target = np.array([1.2, 1.6, 0.0])   # |target| = 2
    res = solve_two_bone(_oblique_knee(1.0), 2, target, dofs=OBLIQUE_DOFS, iterations=0)
    assert res.error < 1e-9
    np.testing.assert_allclose(res.position, target, atol=1e-9)
    assert abs(res.values[(1, 2)]) == pytest.approx(math.pi / 3, abs=1e-9)


def test_two_bone_is_scale_invariant_for_a_tiny_skeleton():
    """The same skeleton and target scaled by 1e-13 (tolerance too) is the same problem:
    the same joint angles, in one analytic step. Bones of 1e-13 are short in absolute
    terms but not relative to the chain, so they are not the "zero-length bone" case."""
    s = 1e-13
    target = np.array([1.2, 1.6, 0.0])
    big = solve_two_bone(_oblique_knee(1.0), 2, target, dofs=OBLIQUE_DOFS, iterations=0)
    tiny = solve_two_bone(_oblique_knee(s), 2, target * s, dofs=OBLIQUE_DOFS, iterations=0, tolerance=1e-5 * s)
    assert tiny.error <= 1e-9 * s
    assert tiny.iterations == big.iterations
    for key, value in big.values.items():
        assert tiny.values[key] == pytest.approx(value, abs=1e-9)
