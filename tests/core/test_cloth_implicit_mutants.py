"""The implicit cloth step (cloth_implicit.py) against a dense backward-Euler solve written here
(stiffness = finite-difference Jacobian of the spring force k·(l − L)·u), the block pattern
against a dense sparsity pattern, and the numpy step against the compiled kernel's path fed
with the same pattern (the kernels run as plain Python without numba)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.cloth import Cloth, ClothParams
from qtanimator.core.cloth_implicit import implicit_pattern, implicit_step_numpy

N = 4
#  0 - 1      springs: the square's sides, one diagonal, and 1-2 compressed
#  | \ |
#  2 - 3
SPRINGS = np.array([[0, 1], [0, 2], [1, 3], [2, 3], [0, 3], [1, 2]], dtype=np.int64)


def _scene() -> dict[str, np.ndarray]:
    rng = np.random.default_rng(12)
    x = np.array([[0.0, 0.0, 0.0], [0.3, 0.02, 0.05], [0.01, -0.3, -0.04], [0.32, -0.28, 0.03]])
    x += rng.normal(0.0, 0.01, size=x.shape)
    v = rng.normal(0.0, 0.5, size=(N, 3))
    ln = np.linalg.norm(x[SPRINGS[:, 1]] - x[SPRINGS[:, 0]], axis=1)
    rest = ln * np.array([0.8, 0.85, 0.9, 0.75, 0.95, 1.2])  # spring 5 (1-2) compressed
    k = np.array([120.0, 80.0, 150.0, 60.0, 40.0, 90.0])
    c = np.array([0.3, 0.1, 0.2, 0.5, 0.05, 0.4])
    return {"x": x, "v": v, "rest": rest, "k": k, "c": c}


def _spring_force(x: np.ndarray, v: np.ndarray, s: dict[str, np.ndarray]) -> np.ndarray:
    f = np.zeros((N, 3))
    for q, (i, j) in enumerate(SPRINGS):
        d = x[j] - x[i]
        length = np.linalg.norm(d)
        u = d / length
        t = s["k"][q] * (length - s["rest"][q]) + s["c"][q] * np.dot(v[j] - v[i], u)
        f[i] += t * u
        f[j] -= t * u
    return f


def _jacobians(s: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Dense ∂f/∂x (the finite-difference Jacobian of the elastic force k·(l − L)·u; a
    compressed spring keeps only its k·uuᵀ part, by design, so the matrix stays definite)
    and ∂f/∂v (−c·uuᵀ per spring), (3N, 3N)."""
    x = s["x"]
    dfdx = np.zeros((3 * N, 3 * N))
    dfdv = np.zeros((3 * N, 3 * N))
    eps = 1e-6
    for q, (i, j) in enumerate(SPRINGS):
        d = x[j] - x[i]
        length = np.linalg.norm(d)
        u = d / length
        if length > s["rest"][q]:
            jac = np.zeros((3, 3))
            for a in range(3):
                e = np.zeros(3)
                e[a] = eps
                fp = s["k"][q] * (np.linalg.norm(d + e) - s["rest"][q]) * (d + e) / np.linalg.norm(d + e)
                fm = s["k"][q] * (np.linalg.norm(d - e) - s["rest"][q]) * (d - e) / np.linalg.norm(d - e)
                jac[:, a] = (fp - fm) / (2 * eps)  # ∂(force on i)/∂d, d = x_j − x_i
        else:
            jac = s["k"][q] * np.outer(u, u)
        cuu = s["c"][q] * np.outer(u, u)
        for (r, cc), sign in (((i, i), -1.0), ((j, j), -1.0), ((i, j), 1.0), ((j, i), 1.0)):
            dfdx[3 * r:3 * r + 3, 3 * cc:3 * cc + 3] += sign * jac
            dfdv[3 * r:3 * r + 3, 3 * cc:3 * cc + 3] += sign * cuu
    return dfdx, dfdv


def _dense_step(s: dict[str, np.ndarray], force: np.ndarray, mass: float, h: float,
                free: slice = slice(0, N)) -> tuple[np.ndarray, np.ndarray]:
    """Backward Euler linearised once: (M − h·∂f/∂v − h²·∂f/∂x)·Δv = h·(f + h·∂f/∂x·v), solved
    densely for the ``free`` particles (the others: Δv = 0, their rows and columns dropped)."""
    x, v = s["x"], s["v"]
    dfdx, dfdv = _jacobians(s)
    a = mass * np.eye(3 * N) - h * dfdv - h * h * dfdx
    b = h * (force.ravel() + h * dfdx @ v.ravel())
    idx = np.arange(3 * N).reshape(N, 3)[free].ravel()
    dv = np.zeros(3 * N)
    dv[idx] = np.linalg.solve(a[np.ix_(idx, idx)], b[idx])
    v_new = v + dv.reshape(N, 3)
    return x + v_new * h, v_new


@pytest.mark.parametrize("warm", [False, True])
def test_numpy_implicit_step_matches_a_dense_solve(warm: bool) -> None:
    s = _scene()
    mass, h = 0.02, 0.01
    force = _spring_force(s["x"], s["v"], s)
    force[:, 1] -= 9.8 * mass
    x_ref, v_ref = _dense_step(s, force, mass, h)
    x, v = s["x"].copy(), s["v"].copy()
    start = np.full((N, 3), 0.3)
    none = np.zeros(0, dtype=np.int64)
    it = implicit_step_numpy(x, v, force, (SPRINGS[:, 0], SPRINGS[:, 1], s["k"], s["c"], s["rest"]), mass, h,
                             none, np.zeros((0, 3)), np.zeros((0, 3)), np.ones(N, dtype=bool), start, (1e-14, 0.0),
                             warm, implicit_pattern(N, SPRINGS, accelerated=False))
    assert it > 0
    np.testing.assert_allclose(v, v_ref, rtol=1e-7, atol=1e-9)
    np.testing.assert_allclose(x, x_ref, rtol=1e-9, atol=1e-11)
    np.testing.assert_allclose(start, v_ref - s["v"], rtol=1e-7, atol=1e-9)  # the velocity change, for next time


def test_a_kinematic_particle_lands_on_its_target_and_is_no_unknown() -> None:
    """Particle 0 kinematic: it ends at kin_pos with kin_vel; the others solve the dense
    system restricted to the free particles (its rows and columns dropped)."""
    s = _scene()
    mass, h = 0.02, 0.01
    kin_pos, kin_vel = np.array([[0.05, 0.01, -0.02]]), np.array([[0.2, -0.1, 0.4]])
    s["v"][0] = kin_vel[0]
    force = _spring_force(s["x"], s["v"], s)
    x, v = s["x"].copy(), s["v"].copy()
    free = np.array([False, True, True, True])
    implicit_step_numpy(x, v, force, (SPRINGS[:, 0], SPRINGS[:, 1], s["k"], s["c"], s["rest"]), mass, h,
                        np.array([0]), kin_pos, kin_vel, free, np.zeros((N, 3)), (1e-14, 0.0), False,
                        implicit_pattern(N, SPRINGS, accelerated=False))
    np.testing.assert_array_equal(x[0], kin_pos[0])
    np.testing.assert_array_equal(v[0], kin_vel[0])
    x_ref, v_ref = _dense_step(s, force, mass, h, free=slice(1, N))
    np.testing.assert_allclose(v[1:], v_ref[1:], rtol=1e-7, atol=1e-9)
    np.testing.assert_allclose(x[1:], x_ref[1:], rtol=1e-9, atol=1e-11)


def test_the_block_pattern_holds_the_diagonal_and_every_spring_both_ways() -> None:
    """Block row i lists i and every spring partner, sorted; the slots point at them."""
    for accelerated in (False, True):
        cache = implicit_pattern(N, SPRINGS, accelerated)
        indptr, indices = cache["indptr"], cache["indices"]
        want = {i: {i} for i in range(N)}
        for i, j in SPRINGS:
            want[int(i)].add(int(j))
            want[int(j)].add(int(i))
        for i in range(N):
            assert indices[indptr[i]:indptr[i + 1]].tolist() == sorted(want[i])
        assert cache["nblocks"] == N + 2 * len(SPRINGS) == indptr[-1]

        def row_of(slot: int, indptr: np.ndarray = indptr) -> int:
            return int(np.searchsorted(indptr, slot, side="right") - 1)

        for i in range(N):
            assert row_of(cache["slot_diag"][i]) == i and indices[cache["slot_diag"][i]] == i
        for q, (i, j) in enumerate(SPRINGS):
            assert row_of(cache["slot_ij"][q]) == i and indices[cache["slot_ij"][q]] == j
            assert row_of(cache["slot_ji"][q]) == j and indices[cache["slot_ji"][q]] == i
        assert cache["maxiter"] == max(200, 8 * int(math.sqrt(N)))


def test_the_compiled_path_with_the_pattern_steps_like_the_numpy_path() -> None:
    """The same small cloth stepped through the kernel path (``accelerated`` set by hand: the
    kernels run compiled with numba, as plain Python without it; it takes the pattern's CG
    work vectors) and through numpy, with the solver tightened: the same frames."""
    p = ClothParams(rows=3, cols=3, width=0.4, height=0.4, total_mass=0.05, wind=(0.5, 0.0, 1.5),
                    ground_enabled=False, orientation=(0.2, 0.3, 0.1), pin_mode="top_corners", substeps=2)
    cloths = []
    for accel in (False, True):
        cloth = Cloth(p, accelerate=False)
        cloth.accelerated = accel
        cloth.solver_rtol = 1e-12
        cloth.solver_atol_acceleration = 0.0
        cloth.move_pins((0.05, 0.02, -0.03))
        cloth.step(1.0 / 60.0)
        cloth.step(1.0 / 60.0)
        cloths.append(cloth)
    assert cloths[1].last_iterations > 0
    np.testing.assert_allclose(cloths[1].positions, cloths[0].positions, rtol=1e-9, atol=1e-11)
    np.testing.assert_allclose(cloths[1].velocities, cloths[0].velocities, rtol=1e-7, atol=1e-9)
