"""IK with an end-effector offset (a clicked point in the end joint's frame) and the ray
against triangles that finds that point (Qt-free)."""

from __future__ import annotations

import numpy as np
import pytest

from qtanimator.core import ik3d, ik3d_methods
from qtanimator.core.raycast import ray_triangles
from qtanimator.core.skeleton import Dof, Joint, Skeleton

OFFSET = np.array([0.5, 0.15, -0.1])


def arm(limits: tuple[float, float] = (-100000.0, 100000.0)) -> Skeleton:
    def dofs() -> tuple[Dof, Dof, Dof]:
        return (Dof(0, *limits), Dof(0, *limits), Dof(0, *limits))
    return Skeleton([
        Joint("root", None, (0, 0, 0), dofs()),
        Joint("shoulder", 0, (0, 1, 0), dofs()),
        Joint("elbow", 1, (1, 0, 0), dofs()),
        Joint("wrist", 2, (0.8, 0, 0), dofs()),
    ], rotation_order="zyx")


def effector(sk: Skeleton, values: np.ndarray, end: int, offset: np.ndarray) -> np.ndarray:
    w = sk.world_matrices(values)[end]
    return w[:3, :3] @ offset + w[:3, 3]


def own_and_parents(sk: Skeleton, end: int, n: int) -> list[tuple[int, int]]:
    return [(end, a) for a in range(3)] + ik3d.chain_dofs(sk, end, n)


def reachable_target(sk: Skeleton, dofs: list[tuple[int, int]], end: int, seed: int = 4) -> np.ndarray:
    values = sk.dof_values().copy()
    rng = np.random.default_rng(seed)
    for j, a in dofs:
        values[j, a] += rng.uniform(-0.5, 0.5)
    return effector(sk, values, end, OFFSET)


def apply(sk: Skeleton, result: ik3d.IKResult) -> np.ndarray:
    values = sk.dof_values().copy()
    for (j, a), v in result.values.items():
        values[j, a] = v
    return values


def test_jacobian_with_an_offset_matches_finite_differences():
    sk = arm()
    rng = np.random.default_rng(2)
    values = rng.uniform(-1, 1, (4, 3))
    dofs = own_and_parents(sk, 2, 2)   # the end's own DOFs move the offset point too
    p, jac = ik3d.jacobian(sk, values, dofs, 2, OFFSET)
    np.testing.assert_allclose(p, effector(sk, values, 2, OFFSET))
    h = 1e-6
    for col, (j, a) in enumerate(dofs):
        plus, minus = values.copy(), values.copy()
        plus[j, a] += h
        minus[j, a] -= h
        numeric = (effector(sk, plus, 2, OFFSET) - effector(sk, minus, 2, OFFSET)) / (2 * h)
        np.testing.assert_allclose(jac[:, col], numeric, atol=1e-6)


@pytest.mark.parametrize("solver", ["dls", "ccd", "fabrik"])
def test_the_offset_point_reaches_its_target(solver):
    sk = arm()
    dofs = own_and_parents(sk, 2, 1)   # elbow and shoulder move the point on the forearm
    target = reachable_target(sk, dofs, 2)
    if solver == "dls":
        result = ik3d.solve_ik(sk, 2, target, dofs=dofs, offset=OFFSET, iterations=200)
    else:
        fn = ik3d_methods.solve_ccd if solver == "ccd" else ik3d_methods.solve_fabrik
        result = fn(sk, 2, target, dofs=dofs, offset=OFFSET, iterations=500)
    reached = effector(sk, apply(sk, result), 2, OFFSET)
    assert np.linalg.norm(reached - target) < 1e-3
    np.testing.assert_allclose(result.position, reached, atol=1e-9)


def test_two_bone_with_an_offset_uses_the_end_and_its_parent():
    sk = arm()
    dofs = own_and_parents(sk, 2, 1)
    assert ik3d_methods.two_bone_joints(sk, 2, dofs, tip=True) == (1, 2)
    assert ik3d_methods.two_bone_joints(sk, 2, dofs) is None
    target = reachable_target(sk, dofs, 2, seed=7)
    result = ik3d_methods.solve_two_bone(sk, 2, target, dofs=dofs, offset=OFFSET)
    assert np.linalg.norm(effector(sk, apply(sk, result), 2, OFFSET) - target) < 1e-3


def test_offset_solve_keeps_limits_and_no_offset_is_unchanged():
    sk = arm(limits=(-0.3, 0.3))
    dofs = own_and_parents(sk, 2, 1)
    far = np.array([-1.0, 2.5, 1.0])
    for fn in (ik3d.solve_ik, ik3d_methods.solve_ccd, ik3d_methods.solve_fabrik):
        result = fn(sk, 2, far, dofs=dofs, offset=OFFSET)
        assert all(-0.3 - 1e-12 <= v <= 0.3 + 1e-12 for v in result.values.values())
    # offset None (or the origin) is the joint's origin, as before
    target = np.array([1.2, 1.6, 0.3])
    plain = ik3d.solve_ik(arm(), 3, target)
    zero = ik3d.solve_ik(arm(), 3, target, offset=np.zeros(3), dofs=ik3d.chain_dofs(arm(), 3))
    assert plain.values == pytest.approx(zero.values, abs=1e-9)
    ccd = ik3d_methods.solve_ccd(arm(), 3, target)
    ccd0 = ik3d_methods.solve_ccd(arm(), 3, target, offset=np.zeros(3))
    assert ccd.values == pytest.approx(ccd0.values, abs=1e-9)


def test_ray_hits_a_triangle_where_the_closed_form_says():
    # the triangle z = 1 − x − y / 2 over x, y ≥ 0 (corners (1,0,0), (0,2,0), (0,0,1))
    positions = np.array([[1.0, 0, 0], [0, 2.0, 0], [0, 0, 1.0], [5, 5, 5], [6, 5, 5], [5, 6, 5]])
    triangles = np.array([[3, 4, 5], [0, 1, 2]])
    origin, direction = np.array([0.2, 0.4, 5.0]), np.array([0.0, 0.0, -2.0])
    hit = ray_triangles(origin, direction, positions, triangles)
    assert hit is not None and hit.triangle == 1
    z = 1 - 0.2 - 0.4 / 2
    np.testing.assert_allclose(hit.point, [0.2, 0.4, z], atol=1e-12)
    assert hit.t == pytest.approx((5.0 - z) / 2.0)
    np.testing.assert_allclose(hit.barycentric @ positions[triangles[1]], hit.point, atol=1e-12)
    # the nearer of two stacked triangles, either side facing; misses and rays pointing away
    stacked = np.vstack([positions[:3], positions[:3] + [0, 0, 1.0]])
    hit = ray_triangles(origin, direction, stacked, np.array([[0, 1, 2], [5, 4, 3]]))
    assert hit is not None and hit.triangle == 1 and hit.point[2] == pytest.approx(z + 1)
    assert ray_triangles(np.array([0.9, 0.9, 5.0]), direction, positions, triangles) is None
    assert ray_triangles(origin, -direction, positions, triangles) is None


def test_ray_prefilter_finds_what_testing_every_triangle_finds():
    rng = np.random.default_rng(5)
    positions = rng.normal(size=(300, 3))
    triangles = rng.integers(0, 300, (500, 3))
    for _ in range(50):
        origin, direction = rng.normal(size=3) * 4, rng.normal(size=3)
        hit = ray_triangles(origin, direction, positions, triangles)
        # brute force: every triangle alone
        best = None
        for k, tri in enumerate(triangles):
            h = ray_triangles(origin, direction, positions, tri[None, :])
            if h is not None and (best is None or h.t < best[1]):
                best = (k, h.t)
        assert (hit is None) == (best is None)
        if hit is not None and best is not None:
            assert hit.t == pytest.approx(best[1], abs=1e-12)
