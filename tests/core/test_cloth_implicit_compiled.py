"""The compiled implicit cloth step (issue 22) against the implicit step it replaced.

``implicit_step_reference`` is the implicit substep as it was before issue 22, kept here
verbatim in spirit and independent of the new code: its own forces (gravity, drag, springs
with ``np.add.at``), a fresh ``scipy.sparse`` BSR matrix every step and a scalar-Jacobi
conjugate gradient from zero to a relative 1e-6. The new step (compiled, and its numpy
fallback) run with the same tolerance must follow it to 1e-5 m over 60 frames.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.sparse as sp

from qtanimator.core import cloth_kernels
from qtanimator.core.cloth import SOLVER_RTOL, Cloth, ClothParams, ClothStepCancelled
from qtanimator.core.cloth_kernels import HAVE_NUMBA

DT = 1.0 / 60.0
ACCELERATE = [False, pytest.param(True, marks=pytest.mark.skipif(not HAVE_NUMBA, reason="numba not installed"))]

#: The fixed scene: a flag-like cloth, two corners pinned, starting horizontal (it falls and
#: swings), wind and drag, springs of every kind with damping, no colliders.
SCENE = ClothParams(rows=11, cols=13, width=1.2, height=1.0, total_mass=0.6, structural_stiffness=400.0,
                    structural_damping=0.3, shear_stiffness=150.0, shear_damping=0.1, bend_stiffness=15.0,
                    bend_damping=0.05, wind=(1.5, 0.0, -2.5), drag_coefficient=1.1, ground_enabled=False,
                    pin_mode="top_corners", integrator="implicit", substeps=2,
                    orientation=(-math.pi / 2.0, 0.0, 0.0), origin=(0.0, 1.0, -0.5))


# ------------------------------------------------------------------ the reference
def _reference_forces(x: np.ndarray, v: np.ndarray, p: ClothParams, springs: np.ndarray, kinds: np.ndarray,
                      rest: np.ndarray, tris: np.ndarray, mass: float) -> np.ndarray:
    n = len(x)
    f = np.zeros((n, 3))
    f[:, 1] = -p.gravity * mass
    coef = 0.5 * p.air_density * p.drag_coefficient
    rel = v - np.asarray(p.wind)
    a, b, c = tris[:, 0], tris[:, 1], tris[:, 2]
    nrm = np.cross(x[b] - x[a], x[c] - x[a])
    w = (rel[a] + rel[b] + rel[c]) / 3.0
    nlen = np.linalg.norm(nrm, axis=1)
    speed = np.linalg.norm(w, axis=1)
    scale = -coef * speed * np.einsum("ij,ij->i", w, nrm) / (6.0 * nlen)
    for corner in (a, b, c):
        np.add.at(f, corner, nrm * scale[:, None])
    k = np.array([p.structural_stiffness, p.shear_stiffness, p.bend_stiffness])[kinds]
    cd = np.array([p.structural_damping, p.shear_damping, p.bend_damping])[kinds]
    i, j = springs[:, 0], springs[:, 1]
    d = x[j] - x[i]
    ln = np.linalg.norm(d, axis=1)
    u = d / ln[:, None]
    t = k * (ln - rest) + cd * np.einsum("ij,ij->i", v[j] - v[i], u)
    np.add.at(f, i, t[:, None] * u)
    np.add.at(f, j, -t[:, None] * u)
    return f


def _reference_pcg(a: sp.bsr_matrix, b: np.ndarray, inv_diag: np.ndarray, rtol: float, maxiter: int) -> np.ndarray:
    x = np.zeros_like(b)
    r = b.copy()
    target = rtol * np.linalg.norm(b)
    if target == 0.0:
        return x
    z = r * inv_diag
    p = z.copy()
    rz = r @ z
    for _ in range(maxiter):
        ap = a @ p
        alpha = rz / (p @ ap)
        x += alpha * p
        r -= alpha * ap
        if np.linalg.norm(r) <= target:
            break
        z = r * inv_diag
        rz_new = r @ z
        p = z + (rz_new / rz) * p
        rz = rz_new
    return x


def implicit_step_reference(x: np.ndarray, v: np.ndarray, h: float, p: ClothParams, springs: np.ndarray,
                            kinds: np.ndarray, rest: np.ndarray, tris: np.ndarray, pins: np.ndarray) -> None:
    """The pre-issue-22 implicit substep with static pins, in place on ``x`` and ``v``."""
    n = len(x)
    mass = p.total_mass / n
    v[pins] = 0.0
    free = np.ones(n, dtype=bool)
    free[pins] = False
    force = _reference_forces(x, v, p, springs, kinds, rest, tris, mass)
    k = np.array([p.structural_stiffness, p.shear_stiffness, p.bend_stiffness])[kinds]
    c = np.array([p.structural_damping, p.shear_damping, p.bend_damping])[kinds]
    i, j = springs[:, 0], springs[:, 1]
    d = x[j] - x[i]
    ln = np.linalg.norm(d, axis=1)
    u = d / ln[:, None]
    beta = np.maximum(0.0, 1.0 - rest / ln)
    uu = u[:, :, None] * u[:, None, :]
    blocks = uu * (h * h * k * (1.0 - beta) + h * c)[:, None, None] + np.eye(3) * (h * h * k * beta)[:, None, None]
    diag = np.zeros((n, 3, 3))
    np.add.at(diag, i, blocks)
    np.add.at(diag, j, blocks)
    diag += mass * np.eye(3)
    diag[~free] = np.eye(3)
    off = -blocks * (free[i] & free[j])[:, None, None]
    rows = np.concatenate([np.arange(n), i, j])
    cols = np.concatenate([np.arange(n), j, i])
    order = np.lexsort((cols, rows))
    data = np.concatenate([diag, off, off])[order]
    indptr = np.concatenate([[0], np.cumsum(np.bincount(rows, minlength=n))])
    a = sp.bsr_matrix((data, cols[order], indptr), shape=(3 * n, 3 * n))
    dv = v[j] - v[i]
    kdv = (k * beta)[:, None] * dv + (k * (1.0 - beta) * np.einsum("ij,ij->i", u, dv))[:, None] * u
    kv = np.zeros((n, 3))
    np.add.at(kv, i, kdv)
    np.add.at(kv, j, -kdv)
    rhs = h * (force + h * kv)
    rhs[~free] = 0.0
    sol = _reference_pcg(a, rhs.ravel(), 1.0 / a.diagonal(), 1e-6, max(200, 8 * int(math.sqrt(n))))
    v += sol.reshape(n, 3)
    v[pins] = 0.0
    x += v * h


def reference_frames(p: ClothParams, frames: int) -> list[np.ndarray]:
    grid = Cloth(p, accelerate=False)  # only for the grid: rest positions, springs, triangles, pins
    x, v = grid.rest_positions.copy(), np.zeros((grid.n, 3))
    out = []
    for _ in range(frames):
        for _ in range(p.substeps):
            implicit_step_reference(x, v, DT / p.substeps, p, grid.springs, grid.spring_kinds, grid.rest_lengths,
                                    grid.triangles, grid.pinned_indices)
        out.append(x.copy())
    return out


def new_frames(p: ClothParams, frames: int, accelerate: bool, reference_solver: bool = True) -> list[np.ndarray]:
    cloth = Cloth(p, accelerate=accelerate)
    assert cloth.accelerated == accelerate
    if reference_solver:  # the old stopping rule: relative 1e-6, from zero, no absolute floor
        cloth.solver_rtol, cloth.solver_atol_acceleration, cloth.warm_start = 1e-6, 0.0, False
    out = []
    for _ in range(frames):
        cloth.step(DT)
        out.append(cloth.positions.copy())
    return out


@pytest.fixture(scope="module")
def reference() -> list[np.ndarray]:
    return reference_frames(SCENE, 60)


# ------------------------------------------------------------------------ tests
def test_the_reference_scene_moves(reference: list[np.ndarray]) -> None:
    rest = Cloth(SCENE, accelerate=False).rest_positions
    assert np.abs(reference[-1] - rest).max() > 0.3     # it fell and swung: a real test of the step
    assert np.isfinite(reference[-1]).all()


@pytest.mark.parametrize("accelerate", ACCELERATE)
def test_new_implicit_step_matches_the_old_one_at_the_same_tolerance(reference: list[np.ndarray],
                                                                     accelerate: bool) -> None:
    frames = new_frames(SCENE, 60, accelerate)
    worst = max(float(np.abs(a - b).max()) for a, b in zip(frames, reference))
    assert worst <= 1e-5, f"largest difference {worst:.3g} m"


@pytest.mark.parametrize("accelerate", ACCELERATE)
def test_the_animation_tolerance_stays_within_a_millimetre(reference: list[np.ndarray], accelerate: bool) -> None:
    """The default stopping rule (relative 1e-3, warm start, absolute floor) is for animation:
    about a millimetre from the tight solve on a 1.2 m cloth over a second."""
    frames = new_frames(SCENE, 60, accelerate, reference_solver=False)
    worst = max(float(np.abs(a - b).max()) for a, b in zip(frames, reference))
    assert worst <= 2e-3, f"largest difference {worst:.3g} m"
    assert SOLVER_RTOL == 1e-3


@pytest.mark.skipif(not HAVE_NUMBA, reason="numba not installed")
def test_compiled_and_numpy_paths_agree_at_the_default_tolerance() -> None:
    """Without numba a project simulates the same cloth (the same solver, in numpy)."""
    p = SCENE.replace(substeps=0, turbulence=0.8, ground_enabled=True, ground_height=0.2)
    fast, slow = new_frames(p, 40, True, False), new_frames(p, 40, False, False)
    assert max(float(np.abs(a - b).max()) for a, b in zip(fast, slow)) <= 1e-7


def test_assembled_matrix_equals_an_independent_dense_build() -> None:
    """The compiled kernel's block-CSR values against a dense matrix built spring by spring."""
    if not HAVE_NUMBA:
        pytest.skip("numba not installed")
    rng = np.random.default_rng(5)
    cloth = Cloth(SCENE.replace(rows=5, cols=6), accelerate=True)
    x = cloth.rest_positions + rng.normal(0.0, 0.03, cloth.rest_positions.shape)
    v = rng.normal(0.0, 0.5, x.shape)
    cache = cloth._implicit_setup()
    h, n, p = 0.01, cloth.n, cloth.params
    free = np.ones(n, dtype=bool)
    free[cloth.pinned_indices] = False
    cloth_kernels.implicit_assemble(x, v, cloth._wind_field(), cloth._si, cloth._sj, cloth.rest_lengths,
                                    cloth._spring_k, cloth._spring_c, cloth.triangles, 0.5 * p.air_density *
                                    p.drag_coefficient, p.gravity * cloth.particle_mass, cloth.particle_mass, h,
                                    free, cache["slot_diag"], cache["slot_ij"], cache["slot_ji"], cache["data"],
                                    cache["pre"], cache["rhs"], cloth._force)
    got = sp.bsr_matrix((cache["data"].reshape(-1, 3, 3), cache["indices"], cache["indptr"]),
                        shape=(3 * n, 3 * n)).toarray()
    want = np.zeros((3 * n, 3 * n))
    for i in range(n):
        want[3 * i:3 * i + 3, 3 * i:3 * i + 3] = cloth.particle_mass * np.eye(3)
    k = np.array([p.structural_stiffness, p.shear_stiffness, p.bend_stiffness])[cloth.spring_kinds]
    c = np.array([p.structural_damping, p.shear_damping, p.bend_damping])[cloth.spring_kinds]
    for s, (i, j) in enumerate(cloth.springs):
        d = x[j] - x[i]
        ln = np.linalg.norm(d)
        u = d / ln
        beta = max(0.0, 1.0 - cloth.rest_lengths[s] / ln)
        block = h * h * k[s] * (beta * np.eye(3) + (1.0 - beta) * np.outer(u, u)) + h * c[s] * np.outer(u, u)
        for a, b in ((i, j), (j, i)):
            want[3 * a:3 * a + 3, 3 * a:3 * a + 3] += block
            want[3 * a:3 * a + 3, 3 * b:3 * b + 3] -= block
    for i in np.flatnonzero(~free):
        want[3 * i:3 * i + 3, :] = 0.0
        want[:, 3 * i:3 * i + 3] = 0.0
        want[3 * i:3 * i + 3, 3 * i:3 * i + 3] = np.eye(3)
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-15)
    assert np.allclose(cache["rhs"][~free], 0.0)
    # The block-Jacobi preconditioner is the inverse of the diagonal blocks (6 numbers each).
    pre = cache["pre"][:, [0, 1, 2, 1, 3, 4, 2, 4, 5]].reshape(n, 3, 3)
    diag = np.stack([want[3 * i:3 * i + 3, 3 * i:3 * i + 3] for i in range(n)])
    np.testing.assert_allclose(pre @ diag, np.broadcast_to(np.eye(3), (n, 3, 3)), atol=1e-9)


@pytest.mark.skipif(not HAVE_NUMBA, reason="numba not installed")
def test_block_pcg_solves_a_random_spd_system() -> None:
    rng = np.random.default_rng(2)
    n = 7
    dense = rng.normal(size=(3 * n, 3 * n))
    dense = dense @ dense.T + 3 * n * np.eye(3 * n)
    indptr = np.arange(0, n * n + 1, n, dtype=np.int64)
    indices = np.tile(np.arange(n, dtype=np.int64), n)
    data = np.stack([dense[3 * i:3 * i + 3, 3 * j:3 * j + 3].ravel() for i in range(n) for j in range(n)])
    inv = np.linalg.inv(np.stack([dense[3 * i:3 * i + 3, 3 * i:3 * i + 3] for i in range(n)]))
    pre = inv[:, [0, 0, 0, 1, 1, 2], [0, 1, 2, 1, 2, 2]]
    b = rng.normal(size=(n, 3))
    x = np.zeros((n, 3))
    work = [np.zeros((n, 3)) for _ in range(4)]
    its = cloth_kernels.block_pcg(data, indptr, indices, pre, b, x, *work, 1e-12, 0.0, 100, False)
    assert 0 < its <= 3 * n
    np.testing.assert_allclose(x.ravel(), np.linalg.solve(dense, b.ravel()), rtol=1e-9, atol=1e-12)
    # Warm-started from the answer it is done at once; not finite gives −1 and NaN.
    assert cloth_kernels.block_pcg(data, indptr, indices, pre, b, x, *work, 1e-6, 0.0, 100, True) == 0
    assert cloth_kernels.block_pcg(data, indptr, indices, pre, b * np.nan, x, *work, 1e-6, 0.0, 100, True) == -1
    assert np.isnan(x).all()


@pytest.mark.parametrize("accelerate", ACCELERATE)
def test_warm_start_saves_iterations_and_is_part_of_the_state(accelerate: bool) -> None:
    p = SCENE.replace(substeps=1)
    warm, cold = Cloth(p, accelerate=accelerate), Cloth(p, accelerate=accelerate)
    cold.warm_start = False
    iters = {"warm": 0, "cold": 0}
    for _ in range(30):
        warm.step(DT)
        cold.step(DT)
        iters["warm"] += warm.last_iterations
        iters["cold"] += cold.last_iterations
    assert iters["warm"] < iters["cold"]
    # The solver's start travels with the state: resuming gives identical frames.
    saved = warm.state()
    assert saved.solver_start is not None and np.abs(saved.solver_start).max() > 0

    def five_frames() -> list[np.ndarray]:
        out = []
        for _ in range(5):
            warm.step(DT)
            out.append(warm.positions.copy())
        return out

    ahead = five_frames()
    warm.set_state(saved)
    again = five_frames()
    assert all(np.array_equal(a, b) for a, b in zip(ahead, again))
    # A cancelled step puts the start back too.
    before = warm.state()
    with pytest.raises(ClothStepCancelled):
        warm.step(DT, should_stop=lambda: True)
    assert np.array_equal(warm.state().solver_start, before.solver_start)


def test_the_matrix_pattern_is_built_once_per_grid() -> None:
    cloth = Cloth(SCENE)
    cloth.step(DT)
    pattern = cloth._implicit_setup()
    cloth.set_params(cloth.params.replace(wind=(0.0, 0.0, 4.0), structural_stiffness=900.0, pin_mode="top_edge"))
    cloth.step(DT)
    assert cloth._implicit_setup() is pattern
    cloth.set_params(cloth.params.replace(rows=9))
    assert cloth._implicit_setup() is not pattern


def test_without_numba_the_cloth_says_it_is_slower() -> None:
    assert (cloth_kernels.SLOW_PATH_NOTE is None) == HAVE_NUMBA
    if not HAVE_NUMBA:
        assert "numba" in str(cloth_kernels.SLOW_PATH_NOTE) and not Cloth(SCENE).accelerated
