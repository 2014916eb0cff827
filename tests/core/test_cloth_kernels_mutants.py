"""The cloth kernels against references written here, in 3D (mutation survivors, issue 17).

Every configuration has motion and geometry in all three axes (random particle positions,
velocities and wind), so a term that only touches the z component, or one of two symmetric
terms, changes the result. The expected values are independent of the code under test:

* forces are minus the finite-difference gradient of a spring energy
  ``Σ ½·k·(l − L)²`` and of a Rayleigh dissipation ``Σ ½·c·(u·(v_j − v_i))²`` written here,
  drag is ``−½ρc_d·|w|²·area·(ŵ·n̂)·n̂`` per triangle, a third per corner;
* the implicit step is a dense solve of ``(M + h²K + hC)·Δv = h·(f − h·K·v)`` with ``K`` the
  finite-difference Hessian of the spring energy (``k·uuᵀ`` for a compressed spring, which
  drops its transverse stiffness by design) and ``C = c·uuᵀ``;
* the preconditioner is ``numpy.linalg.inv`` of the dense diagonal blocks.

The kernels run compiled with numba and as plain Python without it (``QTANIMATOR_NO_NUMBA=1``,
or ``NUMBA_DISABLE_JIT=1``); the numpy implicit step (:func:`implicit_step_numpy`) is checked
against the same dense solve.
"""

from __future__ import annotations

import numpy as np
import pytest

from qtanimator.core import cloth_kernels
from qtanimator.core.cloth_implicit import implicit_pattern, implicit_step_numpy

# ------------------------------------------------------------------ the configuration
N = 6
SPRINGS = np.array([[0, 1], [1, 2], [2, 3], [3, 4], [4, 5], [0, 2], [1, 3], [2, 4], [0, 5], [1, 4]], dtype=np.int64)
TRIS = np.array([[0, 1, 2], [1, 3, 2], [2, 3, 4], [3, 5, 4]], dtype=np.int64)
MASS = 0.05
WEIGHT = MASS * 9.8
COEF = 0.5 * 1.225 * 1.1


def _scene(seed: int = 3) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(seed)
    x = rng.normal(0.0, 0.5, size=(N, 3))
    v = rng.normal(0.0, 1.5, size=(N, 3))
    air = rng.normal(0.0, 2.0, size=(N, 3)) + np.array([0.5, -0.3, 2.0])
    d = x[SPRINGS[:, 1]] - x[SPRINGS[:, 0]]
    ln = np.sqrt((d * d).sum(axis=1))
    # Most springs stretched (rest 60-90 % of the length), springs 3 and 7 compressed.
    rest = ln * rng.uniform(0.6, 0.9, size=len(SPRINGS))
    rest[[3, 7]] = ln[[3, 7]] * 1.3
    k = rng.uniform(50.0, 300.0, size=len(SPRINGS))
    c = rng.uniform(0.1, 0.8, size=len(SPRINGS))
    return {"x": x, "v": v, "air": air, "rest": rest, "k": k, "c": c}


# ------------------------------------------------------------------ references
def _energy(x: np.ndarray, rest: np.ndarray, k: np.ndarray) -> float:
    e = 0.0
    for s, (i, j) in enumerate(SPRINGS):
        length = float(np.sqrt(np.sum((x[j] - x[i]) ** 2)))
        e += 0.5 * k[s] * (length - rest[s]) ** 2
    return e


def _dissipation(x: np.ndarray, v: np.ndarray, c: np.ndarray) -> float:
    r = 0.0
    for s, (i, j) in enumerate(SPRINGS):
        d = x[j] - x[i]
        u = d / np.sqrt(np.sum(d * d))
        r += 0.5 * c[s] * float(np.dot(u, v[j] - v[i])) ** 2
    return r


def _minus_gradient(fun: object, y: np.ndarray, eps: float = 1e-6) -> np.ndarray:
    g = np.zeros_like(y)
    for p in range(y.shape[0]):
        for a in range(3):
            yp, ym = y.copy(), y.copy()
            yp[p, a] += eps
            ym[p, a] -= eps
            g[p, a] = -(fun(yp) - fun(ym)) / (2.0 * eps)  # type: ignore[operator]
    return g


def ref_spring_forces(s: dict[str, np.ndarray]) -> np.ndarray:
    x, v = s["x"], s["v"]
    elastic = _minus_gradient(lambda y: _energy(y, s["rest"], s["k"]), x)
    damping = _minus_gradient(lambda w: _dissipation(x, w, s["c"]), v)
    return elastic + damping


def ref_drag(x: np.ndarray, v: np.ndarray, air: np.ndarray, coef: float) -> np.ndarray:
    f = np.zeros((len(x), 3))
    for tri in TRIS:
        p0, p1, p2 = x[tri]
        cross = np.cross(p1 - p0, p2 - p0)
        area = 0.5 * np.linalg.norm(cross)
        n_hat = cross / np.linalg.norm(cross)
        w = (v[tri] - air[tri]).mean(axis=0)
        speed = np.linalg.norm(w)
        total = -coef * speed ** 2 * area * (np.dot(w / speed, n_hat)) * n_hat
        for p in tri:
            f[p] += total / 3.0
    return f


def ref_total_force(s: dict[str, np.ndarray]) -> np.ndarray:
    f = ref_spring_forces(s) + ref_drag(s["x"], s["v"], s["air"], COEF)
    f[:, 1] -= WEIGHT
    return f


def ref_stiffness(s: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Dense (3N, 3N) K (minus the Jacobian of the elastic force, compressed springs ``k·uuᵀ``)
    and C (minus the Jacobian of the damping force in v)."""
    x = s["x"]
    big_k = np.zeros((3 * N, 3 * N))
    big_c = np.zeros((3 * N, 3 * N))
    for q, (i, j) in enumerate(SPRINGS):
        d0 = x[j] - x[i]
        u = d0 / np.linalg.norm(d0)

        def e(d: np.ndarray, q: int = q) -> float:
            return 0.5 * s["k"][q] * (np.linalg.norm(d) - s["rest"][q]) ** 2

        if np.linalg.norm(d0) < s["rest"][q]:
            block = s["k"][q] * np.outer(u, u)
        else:
            block = np.zeros((3, 3))
            eps = 1e-4
            for a in range(3):
                for b in range(3):
                    da, db = np.eye(3)[a] * eps, np.eye(3)[b] * eps
                    block[a, b] = (e(d0 + da + db) - e(d0 + da - db) - e(d0 - da + db) + e(d0 - da - db)) / (
                        4 * eps * eps)
        cblock = s["c"][q] * np.outer(u, u)
        for big, blk in ((big_k, block), (big_c, cblock)):
            for r_, c_, sign in ((i, i, 1), (j, j, 1), (i, j, -1), (j, i, -1)):
                big[3 * r_:3 * r_ + 3, 3 * c_:3 * c_ + 3] += sign * blk
    return big_k, big_c


def ref_system(s: dict[str, np.ndarray], h: float, free: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The filtered backward-Euler system (A, rhs) as dense arrays."""
    big_k, big_c = ref_stiffness(s)
    a = MASS * np.eye(3 * N) + h * h * big_k + h * big_c
    rhs = h * (ref_total_force(s).ravel() - h * big_k @ s["v"].ravel())
    fixed = np.repeat(~free, 3)
    a[fixed, :] = 0.0
    a[:, fixed] = 0.0
    a[fixed, fixed] = 1.0
    rhs[fixed] = 0.0
    return a, rhs


def _dense(data: np.ndarray, indptr: np.ndarray, indices: np.ndarray) -> np.ndarray:
    n = len(indptr) - 1
    out = np.zeros((3 * n, 3 * n))
    for i in range(n):
        for q in range(indptr[i], indptr[i + 1]):
            j = indices[q]
            out[3 * i:3 * i + 3, 3 * j:3 * j + 3] += data[q].reshape(3, 3)
    return out


# ------------------------------------------------------------------ forces
def test_the_test_references_agree_with_closed_forms() -> None:
    s = _scene()
    i, j = SPRINGS[0]
    d = s["x"][j] - s["x"][i]
    ln = np.linalg.norm(d)
    u = d / ln
    one = {**s, "k": np.where(np.arange(len(SPRINGS)) == 0, s["k"], 0.0),
           "c": np.where(np.arange(len(SPRINGS)) == 0, s["c"], 0.0)}
    f = ref_spring_forces(one)
    tension = s["k"][0] * (ln - s["rest"][0]) + s["c"][0] * np.dot(s["v"][j] - s["v"][i], u)
    np.testing.assert_allclose(f[i], tension * u, rtol=1e-6)
    np.testing.assert_allclose(f[j], -tension * u, rtol=1e-6)


def test_spring_forces_kernel_matches_the_energy_gradient_in_3d() -> None:
    s = _scene()
    force = np.zeros((N, 3))
    cloth_kernels.spring_forces(s["x"], s["v"], SPRINGS[:, 0].copy(), SPRINGS[:, 1].copy(), s["rest"], s["k"],
                                s["c"], force)
    np.testing.assert_allclose(force, ref_spring_forces(s), rtol=1e-6, atol=1e-6)


def test_drag_forces_kernel_matches_the_drag_law_with_wind_in_z() -> None:
    s = _scene()
    force = np.full((N, 3), 0.25)  # the kernel adds to what is there
    cloth_kernels.drag_forces(s["x"], s["v"], s["air"], TRIS, COEF, force)
    expected = ref_drag(s["x"], s["v"], s["air"], COEF) + 0.25
    np.testing.assert_allclose(force, expected, rtol=1e-10, atol=1e-12)
    assert np.abs(expected[:, 2] - 0.25).min() > 1e-3  # the z components are not trivial


def test_symplectic_substep_kernel_matches_a_hand_step() -> None:
    s = _scene()
    x, v = s["x"].copy(), s["v"].copy()
    h = 1e-3
    kin_idx = np.array([4], dtype=np.int64)
    kin_pos = np.array([[0.1, 0.2, 0.3]])
    kin_vel = np.array([[-0.4, 0.5, -0.6]])
    force = np.zeros((N, 3))
    cloth_kernels.symplectic_substep(x, v, s["air"], SPRINGS[:, 0].copy(), SPRINGS[:, 1].copy(), s["rest"], s["k"],
                                     s["c"], TRIS, COEF, WEIGHT, np.full(N, h / MASS), h, kin_idx, kin_pos, kin_vel,
                                     force)
    v_new = s["v"] + ref_total_force(s) * (h / MASS)
    v_new[4] = kin_vel[0]
    x_new = s["x"] + v_new * h
    x_new[4] = kin_pos[0]
    np.testing.assert_allclose(v, v_new, rtol=1e-7, atol=1e-8)
    np.testing.assert_allclose(x, x_new, rtol=1e-9, atol=1e-11)
    np.testing.assert_array_equal(x[4], kin_pos[0])
    np.testing.assert_array_equal(v[4], kin_vel[0])


# ------------------------------------------------------------------ the implicit step
def _pattern() -> dict[str, np.ndarray]:
    return implicit_pattern(N, SPRINGS, accelerated=False)


def test_implicit_assemble_matches_a_dense_build() -> None:
    s = _scene()
    h = 0.01
    cache = _pattern()
    free = np.ones(N, dtype=bool)
    free[5] = False
    data = np.full((cache["nblocks"], 9), 7.0)  # stale values must be overwritten
    pre = np.full((N, 6), 7.0)
    rhs = np.full((N, 3), 7.0)
    force = np.full((N, 3), 7.0)
    cloth_kernels.implicit_assemble(s["x"], s["v"], s["air"], SPRINGS[:, 0].copy(), SPRINGS[:, 1].copy(), s["rest"],
                                    s["k"], s["c"], TRIS, COEF, WEIGHT, MASS, h, free, cache["slot_diag"],
                                    cache["slot_ij"], cache["slot_ji"], data, pre, rhs, force)
    a_ref, rhs_ref = ref_system(s, h, free)
    np.testing.assert_allclose(force, ref_total_force(s), rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(_dense(data, cache["indptr"], cache["indices"]), a_ref, rtol=1e-5, atol=1e-9)
    np.testing.assert_allclose(rhs.ravel(), rhs_ref, rtol=1e-6, atol=1e-10)
    for i in range(N):
        inv = np.linalg.inv(a_ref[3 * i:3 * i + 3, 3 * i:3 * i + 3])
        np.testing.assert_allclose(pre[i], inv[[0, 0, 0, 1, 1, 2], [0, 1, 2, 1, 2, 2]], rtol=1e-5, atol=1e-9)


def _dense_step(s: dict[str, np.ndarray], h: float, kin: int, kin_pos: np.ndarray,
                kin_vel: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    free = np.ones(N, dtype=bool)
    free[kin] = False
    s = {**s, "v": s["v"].copy()}
    s["v"][kin] = kin_vel
    a, rhs = ref_system(s, h, free)
    dv = np.linalg.solve(a, rhs).reshape(N, 3)
    v = s["v"] + dv
    v[kin] = kin_vel
    x = s["x"] + v * h
    x[kin] = kin_pos
    return x, v


@pytest.mark.parametrize("warm", [False, True])
def test_implicit_substep_kernel_matches_a_dense_solve(warm: bool) -> None:
    s = _scene()
    h = 0.01
    kin_pos = np.array([[0.3, -0.2, 0.7]])
    kin_vel = np.array([[0.2, 0.1, -0.3]])
    x_ref, v_ref = _dense_step(s, h, 5, kin_pos[0], kin_vel[0])
    cache = _pattern()
    free = np.ones(N, dtype=bool)
    free[5] = False
    x, v = s["x"].copy(), s["v"].copy()
    work = [np.full((N, 3), 3.0) for _ in range(6)]  # rhs, force, r, z, p, ap: stale garbage
    dv = np.full((N, 3), 0.5)
    it = cloth_kernels.implicit_substep(x, v, s["air"], SPRINGS[:, 0].copy(), SPRINGS[:, 1].copy(), s["rest"],
                                        s["k"], s["c"], TRIS, COEF, WEIGHT, MASS, h, np.array([5], dtype=np.int64),
                                        kin_pos, kin_vel, free, cache["indptr"], cache["indices"], cache["slot_diag"],
                                        cache["slot_ij"], cache["slot_ji"], np.zeros((cache["nblocks"], 9)),
                                        np.zeros((N, 6)), work[0], work[1], dv, work[2], work[3], work[4], work[5],
                                        1e-13, 0.0, 500, warm)
    assert it > 0
    np.testing.assert_allclose(v, v_ref, rtol=1e-6, atol=1e-8)
    np.testing.assert_allclose(x, x_ref, rtol=1e-8, atol=1e-10)


@pytest.mark.parametrize("warm", [False, True])
def test_numpy_implicit_step_matches_a_dense_solve(warm: bool) -> None:
    s = _scene()
    h = 0.01
    kin_pos = np.array([[0.3, -0.2, 0.7]])
    kin_vel = np.array([[0.2, 0.1, -0.3]])
    x_ref, v_ref = _dense_step(s, h, 5, kin_pos[0], kin_vel[0])
    free = np.ones(N, dtype=bool)
    free[5] = False
    x, v = s["x"].copy(), s["v"].copy()
    v[5] = kin_vel[0]
    sv = {**s, "v": v.copy()}
    start = np.full((N, 3), 0.5)
    it = implicit_step_numpy(x, v, ref_total_force(sv), (SPRINGS[:, 0], SPRINGS[:, 1], s["k"], s["c"], s["rest"]),
                             MASS, h, np.array([5]), kin_pos, kin_vel, free, start, (1e-13, 0.0), warm, _pattern())
    assert it > 0
    np.testing.assert_allclose(v, v_ref, rtol=1e-6, atol=1e-8)
    np.testing.assert_allclose(x, x_ref, rtol=1e-8, atol=1e-10)


# ------------------------------------------------------------------ the conjugate gradient
def _block_system(seed: int, coupled: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A random SPD block-CSR matrix on 5 particles in a chain (block diagonal unless ``coupled``)."""
    rng = np.random.default_rng(seed)
    n = 5
    dense = np.zeros((3 * n, 3 * n))
    for i in range(n):
        g = rng.normal(size=(3, 3))
        dense[3 * i:3 * i + 3, 3 * i:3 * i + 3] = g @ g.T + 0.5 * np.eye(3)
    if coupled:
        for i in range(n - 1):
            u = rng.normal(size=3)
            blk = 0.8 * np.outer(u, u)
            for r_, c_, sign in ((i, i, 1), (i + 1, i + 1, 1), (i, i + 1, -1), (i + 1, i, -1)):
                dense[3 * r_:3 * r_ + 3, 3 * c_:3 * c_ + 3] += sign * blk
    indptr, indices, blocks = [0], [], []
    for i in range(n):
        for j in range(n):
            if np.any(dense[3 * i:3 * i + 3, 3 * j:3 * j + 3]):
                indices.append(j)
                blocks.append(dense[3 * i:3 * i + 3, 3 * j:3 * j + 3].ravel())
        indptr.append(len(indices))
    return dense, np.array(blocks), np.array(indptr, dtype=np.int64), np.array(indices, dtype=np.int64)


def _pre(dense: np.ndarray) -> np.ndarray:
    n = len(dense) // 3
    out = np.zeros((n, 6))
    for i in range(n):
        inv = np.linalg.inv(dense[3 * i:3 * i + 3, 3 * i:3 * i + 3])
        out[i] = inv[[0, 0, 0, 1, 1, 2], [0, 1, 2, 1, 2, 2]]
    return out


def test_block_pcg_with_the_exact_block_inverse_converges_in_one_iteration() -> None:
    # A block-diagonal matrix preconditioned by its own inverse: the first step is exact.
    dense, data, indptr, indices = _block_system(5, coupled=False)
    b = np.random.default_rng(6).normal(size=(5, 3))
    x = np.zeros((5, 3))
    work = [np.full((5, 3), 9.0) for _ in range(4)]
    it = cloth_kernels.block_pcg(data, indptr, indices, _pre(dense), b, x, *work, 1e-10, 0.0, 50, False)
    assert it == 1
    np.testing.assert_allclose(x.ravel(), np.linalg.solve(dense, b.ravel()), rtol=1e-9, atol=1e-12)


def test_block_pcg_cold_start_ignores_stale_work_arrays_and_meets_its_tolerance() -> None:
    dense, data, indptr, indices = _block_system(7, coupled=True)
    rng = np.random.default_rng(8)
    b = rng.normal(size=(5, 3))
    x = rng.normal(size=(5, 3))  # not warm: must start from zero
    work = [rng.normal(size=(5, 3)) for _ in range(4)]
    it = cloth_kernels.block_pcg(data, indptr, indices, _pre(dense), b, x, *work, 1e-12, 0.0, 200, False)
    assert it > 0
    np.testing.assert_allclose(x.ravel(), np.linalg.solve(dense, b.ravel()), rtol=1e-9, atol=1e-11)


def test_block_pcg_stops_only_when_the_true_residual_is_small() -> None:
    # Identity preconditioner, a right-hand side along z: the stopping test must count |r_z|².
    dense, data, indptr, indices = _block_system(11, coupled=True)
    pre = np.tile([1.0, 0.0, 0.0, 1.0, 0.0, 1.0], (5, 1))
    b = np.zeros((5, 3))
    b[:, 2] = [1.0, -2.0, 1.5, 0.7, -1.1]
    b[:, 0] = 1e-3
    rtol = 1e-8
    x = np.zeros((5, 3))
    work = [np.zeros((5, 3)) for _ in range(4)]
    cloth_kernels.block_pcg(data, indptr, indices, pre, b, x, *work, rtol, 0.0, 500, False)
    residual = np.linalg.norm(b.ravel() - dense @ x.ravel())
    assert residual <= rtol * np.linalg.norm(b) * 1.0001


def test_both_conjugate_gradients_stop_at_maxiter() -> None:
    s = _scene()
    h = 0.01
    free = np.ones(N, dtype=bool)
    cache = {**_pattern(), "maxiter": 2}
    it = implicit_step_numpy(s["x"].copy(), s["v"].copy(), ref_total_force(s),
                             (SPRINGS[:, 0], SPRINGS[:, 1], s["k"], s["c"], s["rest"]), MASS, h,
                             np.zeros(0, dtype=np.int64), np.zeros((0, 3)), np.zeros((0, 3)), free, np.zeros((N, 3)),
                             (1e-14, 0.0), False, cache)
    assert it == 2
    dense, data, indptr, indices = _block_system(7, coupled=True)
    work = [np.zeros((5, 3)) for _ in range(4)]
    b = np.random.default_rng(1).normal(size=(5, 3))
    pre = np.tile([1.0, 0.0, 0.0, 1.0, 0.0, 1.0], (5, 1))
    assert cloth_kernels.block_pcg(data, indptr, indices, pre, b, np.zeros((5, 3)), *work, 1e-14, 0.0, 2, False) == 2


@pytest.mark.skipif(not cloth_kernels.HAVE_NUMBA, reason="warm_up does nothing without numba")
def test_warm_up_runs_every_kernel_on_its_toy_cloth(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(cloth_kernels, "_WARM", False)
    assert cloth_kernels.warm_up() >= 0.0
    assert cloth_kernels._WARM
    assert set(cloth_kernels._compiled) == set(cloth_kernels._KERNELS)
