"""The implicit cloth integrator's linear algebra in numpy (the fallback without numba).

``"implicit"`` is backward Euler linearised once per step (Baraff & Witkin 1998): solve
``(M − h·∂f/∂v − h²·∂f/∂x)·Δv = h·(f + h·∂f/∂x·v)``. Springs and their damping are implicit,
drag and gravity explicit; compressed springs drop their transverse stiffness so the matrix
stays positive definite. Pins and the grabbed particle are constraints of the solve (identity
rows and columns, zero right-hand side). The block-CSR sparsity pattern is built once per grid
(:func:`implicit_pattern`); with numba every step writes the matrix values straight into it
and solves with a compiled block-Jacobi conjugate gradient (:mod:`qtanimator.core.cloth_kernels`),
without numba :func:`implicit_step_numpy` assembles the same system with numpy /
scipy.sparse and solves it by the same CG in numpy (:func:`_pcg`; 5-7× slower,
``cloth_kernels.SLOW_PATH_NOTE`` says so).

The CG starts from the previous step's velocity change and stops at
``|r| ≤ max(rtol·|b|, atol)`` with ``rtol`` = ``cloth.SOLVER_RTOL`` (1e-3: over 250 frames of
the 2 m benchmark cloth the positions stay within about 1 mm of a solve to 1e-9) and
``atol`` = ``cloth.SOLVER_ATOL_ACCELERATION`` × h × particle mass × √N (every eigenvalue of
the matrix is at least the particle mass, so the RMS error of the velocity change stays
below 1e-3 m/s² × h: a settled cloth does not chase ever smaller residuals), or after
``max(200, 8·√N)`` iterations.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from qtanimator.core.cloth_grid import BoolArray, FloatArray, IntArray

__all__ = ["SpringArrays", "implicit_pattern", "implicit_step_numpy"]

#: The springs as the solver reads them: (i, j, stiffness, damping, rest length), one entry per spring.
SpringArrays = tuple[IntArray, IntArray, FloatArray, FloatArray, FloatArray]


def implicit_pattern(n: int, springs: IntArray, accelerated: bool) -> dict[str, Any]:
    """The block-CSR pattern of the implicit matrix of ``n`` particles (built once per grid)
    and work arrays; without ``accelerated`` also what the numpy path needs.

    Row i holds blocks (i, i) and (i, j) for every spring touching i, columns sorted;
    ``slot_diag[i]``, ``slot_ij[s]``, ``slot_ji[s]`` say where each spring writes."""
    si, sj = springs[:, 0], springs[:, 1]
    ns = len(si)
    rows = np.concatenate([np.arange(n), si, sj])
    cols = np.concatenate([np.arange(n), sj, si])
    key = rows * n + cols
    order = np.argsort(key, kind="stable")
    slot = np.empty_like(order)
    slot[order] = np.arange(len(order))
    indptr = np.concatenate([[0], np.cumsum(np.bincount(rows, minlength=n))]).astype(np.int64)
    indices = np.ascontiguousarray(cols[order].astype(np.int64))
    nblocks = len(order)
    cache: dict[str, Any] = {
        "slot_diag": np.ascontiguousarray(slot[:n]), "slot_ij": np.ascontiguousarray(slot[n:n + ns]),
        "slot_ji": np.ascontiguousarray(slot[n + ns:]), "indptr": indptr, "indices": indices,
        "nblocks": nblocks, "data": np.zeros((nblocks, 9)), "pre": np.zeros((n, 6)), "rhs": np.zeros((n, 3)),
        "work": [np.zeros((n, 3)) for _ in range(4)],
        "maxiter": max(200, 8 * int(math.sqrt(n))),
    }
    if not accelerated:
        import scipy.sparse as sp  # only the numpy implicit path needs it

        cache["incidence"] = sp.csr_matrix(
            (np.ones(2 * ns), (np.concatenate([si, sj]), np.concatenate([np.arange(ns)] * 2))), shape=(n, ns))
        cache["bsr_matrix"] = sp.bsr_matrix
    return cache


def implicit_step_numpy(x: FloatArray, v: FloatArray, force: FloatArray, springs: SpringArrays,
                        particle_mass: float, h: float, kin_idx: IntArray, kin_pos: FloatArray, kin_vel: FloatArray,
                        free: BoolArray, start: FloatArray, tolerance: tuple[float, float], warm: bool,
                        cache: dict[str, Any]) -> int:
    """One backward-Euler step in numpy, in place on ``x`` and ``v`` (``v`` already holds the
    kinematic velocities, ``force`` the forces at ``x``, ``v``): assemble, solve from ``start``
    (the velocity change, updated in place) to ``tolerance`` = (rtol, atol), move. Returns the
    CG iterations (the twin of ``cloth_kernels.implicit_substep`` without its collisions)."""
    n = len(x)
    si, sj, k, c, rest = springs
    d = x[sj] - x[si]
    ln = np.sqrt(np.einsum("ij,ij->i", d, d))
    u = d / np.maximum(ln, 1e-12)[:, None]
    beta = np.maximum(0.0, 1.0 - rest / np.maximum(ln, 1e-12))
    # Block per spring: S = h²·K_s + h·c·uuᵀ with K_s = k·(β·I + (1 − β)·uuᵀ).
    a_iso = h * h * k * beta
    a_uu = h * h * k * (1.0 - beta) + h * c
    uu = u[:, :, None] * u[:, None, :]
    blocks = uu * a_uu[:, None, None]
    blocks[:, 0, 0] += a_iso
    blocks[:, 1, 1] += a_iso
    blocks[:, 2, 2] += a_iso
    diag = (cache["incidence"] @ blocks.reshape(-1, 9)).reshape(n, 3, 3)
    diag[:, 0, 0] += particle_mass
    diag[:, 1, 1] += particle_mass
    diag[:, 2, 2] += particle_mass
    diag[~free] = np.eye(3)
    both_free = (free[si] & free[sj]).astype(np.float64)
    off = -blocks * both_free[:, None, None]
    data = np.empty((cache["nblocks"], 3, 3))
    data[cache["slot_diag"]] = diag
    data[cache["slot_ij"]] = off
    data[cache["slot_ji"]] = off
    a = cache["bsr_matrix"]((data, cache["indices"], cache["indptr"]), shape=(3 * n, 3 * n))

    # rhs = h·(f + h·(∂f/∂x)·v); (∂f/∂x·v)_i = Σ K_s·(v_j − v_i), the opposite at j.
    dv = v[sj] - v[si]
    kdv = (k * beta)[:, None] * dv + (k * (1.0 - beta) * np.einsum("ij,ij->i", u, dv))[:, None] * u
    kv = np.zeros((n, 3))
    for comp in range(3):
        kv[:, comp] = np.bincount(si, kdv[:, comp], n) - np.bincount(sj, kdv[:, comp], n)
    rhs = h * (force + h * kv)
    rhs[~free] = 0.0
    with np.errstate(all="ignore"):
        pre = np.linalg.inv(diag) if np.isfinite(diag).all() else np.full_like(diag, np.nan)
    rtol, atol = tolerance
    iterations = _pcg(a, rhs.ravel(), pre, start.reshape(-1), rtol, atol, cache["maxiter"], warm)
    v += start
    v[kin_idx] = kin_vel
    x += v * h
    x[kin_idx] = kin_pos
    return iterations


def _dot(a: FloatArray, b: FloatArray) -> float:
    # einsum, not BLAS: a threaded BLAS dot stalls on a busy machine and is no faster at these sizes.
    return float(np.einsum("i,i->", a, b))


def _pcg(a: Any, b: FloatArray, pre: FloatArray, x: FloatArray, rtol: float, atol: float, maxiter: int,
         warm: bool) -> int:
    """Conjugate gradients on ``a·x = b``, preconditioned with ``pre`` (the inverse 3×3
    diagonal blocks, (N, 3, 3)), in place on ``x``: from ``x`` when ``warm`` else from zero,
    until ``|r| ≤ max(rtol·|b|, atol)`` or ``maxiter`` iterations. The numpy twin of
    ``cloth_kernels.block_pcg``; returns the iterations done (−1 when ``b`` is not finite)."""
    n = len(pre)

    def precondition(r: FloatArray) -> FloatArray:
        return np.einsum("nij,nj->ni", pre, r.reshape(n, 3)).reshape(-1)

    target = max(rtol * math.sqrt(_dot(b, b)), atol)
    if not math.isfinite(target):
        x[:] = np.nan  # the step is already lost; the caller reports the blow-up
        return -1
    if warm:
        r = b - a @ x
    else:
        x[:] = 0.0
        r = b.copy()
    if target == 0.0 or math.sqrt(_dot(r, r)) <= target:
        return 0
    z = precondition(r)
    p = z.copy()
    rz = _dot(r, z)
    it = 0
    while it < maxiter:
        it += 1
        ap = a @ p
        pap = _dot(p, ap)
        if not pap > 0.0:
            break
        alpha = rz / pap
        x += alpha * p
        r -= alpha * ap
        if math.sqrt(_dot(r, r)) <= target:
            break
        z = precondition(r)
        rz_new = _dot(r, z)
        p *= rz_new / rz
        p += z
        rz = rz_new
    return it
