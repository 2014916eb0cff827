"""Compiled kernels for the cloth (numba), used when numba is installed.

Each kernel computes exactly what the vectorised numpy code in :mod:`qtanimator.core.cloth`
computes (the tests compare the two), in one pass over the springs or triangles instead of
~40 whole-array numpy operations per substep. Compiled functions are cached on disk
(``cache=True``) and release the GIL (``nogil=True``), so only the very first run on a
machine pays the compile time and a worker thread never holds up the UI thread.

The per-spring and per-triangle arithmetic lives in small helpers (``_spring``,
``_add_drag``, ``_add_springs``) that every kernel calls: the force kernels, the fused
symplectic substep and the implicit substep share one definition of each force. Helpers are
compiled first and the kernels after them, all at the first call, so that importing the
cloth does not import numba.

The implicit substep (:func:`implicit_substep`) writes the values of the backward-Euler
matrix straight into a block-CSR pattern built once per cloth (``Cloth._implicit_setup``)
and solves it with a compiled block-Jacobi preconditioned conjugate gradient
(:func:`block_pcg`), warm-started from the previous step's velocity change.
"""

from __future__ import annotations

import importlib.util
import math
import os
import threading
from collections.abc import Callable
from typing import Any, TypeVar, cast

import numpy as np

#: numba is the optional ``qtanimator[fast]`` extra; ``QTANIMATOR_NO_NUMBA=1`` forces the numpy
#: paths even when it is installed (CI runs the cloth tests both ways).
HAVE_NUMBA = importlib.util.find_spec("numba") is not None and (
    os.environ.get("QTANIMATOR_NO_NUMBA", "") in ("", "0"))

#: What a window can show when the compiled kernels are missing (None when they are there).
SLOW_PATH_NOTE: str | None = None if HAVE_NUMBA else (
    "Cloth runs on the numpy fallback (numba is not installed, or QTANIMATOR_NO_NUMBA is set): "
    "about 5-7x slower. Install the 'fast' extra (pip install qtanimator[fast]) for the compiled solver.")

F = TypeVar("F", bound=Callable[..., Any])


# --------------------------------------------------------------------------- helpers
def _spring(x: Any, v: Any, i: int, j: int, rest: float, k: float, c: float) -> tuple[float, ...]:
    """One spring-damper from ``i`` to ``j``: ``(t, ux, uy, uz, inv_length, rel)`` with ``t``
    the tension ``k·(l − L) + c·(v_j − v_i)·u`` (the force on ``i`` is ``t·u``), ``u`` the
    unit direction, ``inv_length`` = 1 / max(l, 1e-12) and ``rel`` the closing speed."""
    dx = x[j, 0] - x[i, 0]
    dy = x[j, 1] - x[i, 1]
    dz = x[j, 2] - x[i, 2]
    length = math.sqrt(dx * dx + dy * dy + dz * dz)
    inv = 1.0 / max(length, 1e-12)
    ux = dx * inv
    uy = dy * inv
    uz = dz * inv
    rel = (v[j, 0] - v[i, 0]) * ux + (v[j, 1] - v[i, 1]) * uy + (v[j, 2] - v[i, 2]) * uz
    t = k * (length - rest) + c * rel
    return t, ux, uy, uz, inv, rel


def _add_springs(x: Any, v: Any, si: Any, sj: Any, rest: Any, k: Any, c: Any, force: Any) -> None:
    """Add the spring-damper forces of springs ``(si[s], sj[s])`` to ``force`` (N, 3)."""
    for s in range(si.shape[0]):
        i = si[s]
        j = sj[s]
        t, ux, uy, uz, _inv, _rel = _spring(x, v, i, j, rest[s], k[s], c[s])
        fx = t * ux
        fy = t * uy
        fz = t * uz
        force[i, 0] += fx
        force[i, 1] += fy
        force[i, 2] += fz
        force[j, 0] -= fx
        force[j, 1] -= fy
        force[j, 2] -= fz


def _add_drag(x: Any, v: Any, air: Any, tris: Any, coef: float, force: Any) -> None:
    """Add −coef·|w|²·a·n̂ per triangle (coef = ½ρc_d, w = the mean over the corners of
    ``v − air``, a = area·(ŵ·n̂)), a third to each corner."""
    for t in range(tris.shape[0]):
        a = tris[t, 0]
        b = tris[t, 1]
        cc = tris[t, 2]
        e1x = x[b, 0] - x[a, 0]
        e1y = x[b, 1] - x[a, 1]
        e1z = x[b, 2] - x[a, 2]
        e2x = x[cc, 0] - x[a, 0]
        e2y = x[cc, 1] - x[a, 1]
        e2z = x[cc, 2] - x[a, 2]
        nx = e1y * e2z - e1z * e2y
        ny = e1z * e2x - e1x * e2z
        nz = e1x * e2y - e1y * e2x
        nlen = math.sqrt(nx * nx + ny * ny + nz * nz)
        if nlen <= 0.0:
            continue
        rx = ((v[a, 0] - air[a, 0]) + (v[b, 0] - air[b, 0]) + (v[cc, 0] - air[cc, 0])) / 3.0
        ry = ((v[a, 1] - air[a, 1]) + (v[b, 1] - air[b, 1]) + (v[cc, 1] - air[cc, 1])) / 3.0
        rz = ((v[a, 2] - air[a, 2]) + (v[b, 2] - air[b, 2]) + (v[cc, 2] - air[cc, 2])) / 3.0
        speed = math.sqrt(rx * rx + ry * ry + rz * rz)
        vn = rx * nx + ry * ny + rz * nz
        scale = -coef * speed * vn / (6.0 * nlen)
        fx = nx * scale
        fy = ny * scale
        fz = nz * scale
        for p in (a, b, cc):
            force[p, 0] += fx
            force[p, 1] += fy
            force[p, 2] += fz


def _gravity(force: Any, weight: float) -> None:
    """``force`` = the weight ``−weight·ŷ`` of every particle."""
    for i in range(force.shape[0]):
        force[i, 0] = 0.0
        force[i, 1] = -weight
        force[i, 2] = 0.0


def _set_kinematic(a: Any, kin_idx: Any, values: Any) -> None:
    for q in range(kin_idx.shape[0]):
        j = kin_idx[q]
        a[j, 0] = values[q, 0]
        a[j, 1] = values[q, 1]
        a[j, 2] = values[q, 2]


def _advance(x: Any, v: Any, h: float, kin_idx: Any, kin_pos: Any, kin_vel: Any) -> None:
    """``v[kin] = kin_vel``, ``x += v·h``, ``x[kin] = kin_pos``."""
    _set_kinematic(v, kin_idx, kin_vel)
    for i in range(x.shape[0]):
        x[i, 0] += v[i, 0] * h
        x[i, 1] += v[i, 1] * h
        x[i, 2] += v[i, 2] * h
    _set_kinematic(x, kin_idx, kin_pos)


def _block_matvec(data: Any, indptr: Any, indices: Any, p: Any, out: Any) -> float:
    """``out = A·p`` for a block-CSR matrix (blocks ``data[q]`` as 9 numbers, row-major);
    returns ``p·out``."""
    pap = 0.0
    for i in range(p.shape[0]):
        y0 = 0.0
        y1 = 0.0
        y2 = 0.0
        for q in range(indptr[i], indptr[i + 1]):
            j = indices[q]
            p0 = p[j, 0]
            p1 = p[j, 1]
            p2 = p[j, 2]
            y0 += data[q, 0] * p0 + data[q, 1] * p1 + data[q, 2] * p2
            y1 += data[q, 3] * p0 + data[q, 4] * p1 + data[q, 5] * p2
            y2 += data[q, 6] * p0 + data[q, 7] * p1 + data[q, 8] * p2
        out[i, 0] = y0
        out[i, 1] = y1
        out[i, 2] = y2
        pap += p[i, 0] * y0 + p[i, 1] * y1 + p[i, 2] * y2
    return pap


def _precondition(pre: Any, r: Any, z: Any) -> float:
    """``z = P·r`` with ``P`` the inverse diagonal blocks (symmetric, 6 numbers each:
    xx, xy, xz, yy, yz, zz); returns ``r·z``."""
    rz = 0.0
    for i in range(r.shape[0]):
        r0 = r[i, 0]
        r1 = r[i, 1]
        r2 = r[i, 2]
        z0 = pre[i, 0] * r0 + pre[i, 1] * r1 + pre[i, 2] * r2
        z1 = pre[i, 1] * r0 + pre[i, 3] * r1 + pre[i, 4] * r2
        z2 = pre[i, 2] * r0 + pre[i, 4] * r1 + pre[i, 5] * r2
        z[i, 0] = z0
        z[i, 1] = z1
        z[i, 2] = z2
        rz += r0 * z0 + r1 * z1 + r2 * z2
    return rz


# --------------------------------------------------------------------------- kernels
def _spring_forces(x: Any, v: Any, si: Any, sj: Any, rest: Any, k: Any, c: Any, force: Any) -> None:
    """Add the spring-damper forces of springs ``(si[s], sj[s])`` to ``force`` (N, 3)."""
    _add_springs(x, v, si, sj, rest, k, c, force)


def _drag_forces(x: Any, v: Any, air: Any, tris: Any, coef: float, force: Any) -> None:
    """Add the aerodynamic drag of every triangle to ``force`` (N, 3): −coef·|w|²·a·n̂ with
    coef = ½ρc_d and ``w`` the mean of ``v − air`` over the corners, ⅓ per corner."""
    _add_drag(x, v, air, tris, coef, force)


def _symplectic_substep(x: Any, v: Any, air: Any, si: Any, sj: Any, rest: Any, k: Any, c: Any, tris: Any,
                        coef: float, weight: float, inv_mass_h: Any, h: float, kin_idx: Any, kin_pos: Any,
                        kin_vel: Any, force: Any) -> None:
    """One semi-implicit Euler substep without collisions, in one pass and without the GIL:
    gravity (``weight`` = m·g per particle), drag (relative to ``air``, the wind at each
    particle, when ``coef`` > 0), springs, then ``v += f·(h/m)``, ``x += v·h`` and the
    kinematic particles ``kin_idx`` set to ``kin_pos`` / ``kin_vel``. The same arithmetic
    as ``Cloth._symplectic_substep`` in numpy (tests compare them)."""
    _gravity(force, weight)
    if coef > 0.0:
        _add_drag(x, v, air, tris, coef, force)
    _add_springs(x, v, si, sj, rest, k, c, force)
    for i in range(x.shape[0]):
        s = inv_mass_h[i]
        v[i, 0] += force[i, 0] * s
        v[i, 1] += force[i, 1] * s
        v[i, 2] += force[i, 2] * s
    _advance(x, v, h, kin_idx, kin_pos, kin_vel)


def _block_pcg(data: Any, indptr: Any, indices: Any, pre: Any, b: Any, x: Any, r: Any, z: Any, p: Any, ap: Any,
               rtol: float, atol: float, maxiter: int, warm: bool) -> int:
    """Solve ``A·x = b`` (A symmetric positive definite, block CSR) by conjugate gradients
    preconditioned with the inverse diagonal blocks ``pre``. Starts from ``x`` when ``warm``,
    else from zero; stops when ``|r| ≤ max(rtol·|b|, atol)`` or after ``maxiter`` iterations.
    Returns the iterations done; −1 (and ``x`` = NaN) when ``b`` is not finite."""
    n = b.shape[0]
    bb = 0.0
    for i in range(n):
        bb += b[i, 0] * b[i, 0] + b[i, 1] * b[i, 1] + b[i, 2] * b[i, 2]
    target = max(rtol * math.sqrt(bb), atol)
    if not math.isfinite(target):
        x[:, :] = np.nan  # the step is already lost; the caller reports the blow-up
        return -1
    if warm:
        _block_matvec(data, indptr, indices, x, r)
        rr = 0.0
        for i in range(n):
            r[i, 0] = b[i, 0] - r[i, 0]
            r[i, 1] = b[i, 1] - r[i, 1]
            r[i, 2] = b[i, 2] - r[i, 2]
            rr += r[i, 0] * r[i, 0] + r[i, 1] * r[i, 1] + r[i, 2] * r[i, 2]
    else:
        rr = bb
        for i in range(n):
            x[i, 0] = 0.0
            x[i, 1] = 0.0
            x[i, 2] = 0.0
            r[i, 0] = b[i, 0]
            r[i, 1] = b[i, 1]
            r[i, 2] = b[i, 2]
    if target == 0.0 or math.sqrt(rr) <= target:
        return 0
    rz = _precondition(pre, r, z)
    for i in range(n):
        p[i, 0] = z[i, 0]
        p[i, 1] = z[i, 1]
        p[i, 2] = z[i, 2]
    it = 0
    while it < maxiter:
        it += 1
        pap = _block_matvec(data, indptr, indices, p, ap)
        if not pap > 0.0:
            break  # a zero search direction (converged exactly) or a matrix that is not SPD
        alpha = rz / pap
        rr = 0.0
        for i in range(n):
            x[i, 0] += alpha * p[i, 0]
            x[i, 1] += alpha * p[i, 1]
            x[i, 2] += alpha * p[i, 2]
            r[i, 0] -= alpha * ap[i, 0]
            r[i, 1] -= alpha * ap[i, 1]
            r[i, 2] -= alpha * ap[i, 2]
            rr += r[i, 0] * r[i, 0] + r[i, 1] * r[i, 1] + r[i, 2] * r[i, 2]
        if math.sqrt(rr) <= target:
            break
        rz_new = _precondition(pre, r, z)
        beta = rz_new / rz
        rz = rz_new
        for i in range(n):
            p[i, 0] = z[i, 0] + beta * p[i, 0]
            p[i, 1] = z[i, 1] + beta * p[i, 1]
            p[i, 2] = z[i, 2] + beta * p[i, 2]
    return it


def _implicit_assemble(x: Any, v: Any, air: Any, si: Any, sj: Any, rest: Any, k: Any, c: Any, tris: Any,
                       coef: float, weight: float, mass: float, h: float, free: Any, slot_diag: Any, slot_ij: Any,
                       slot_ji: Any, data: Any, pre: Any, rhs: Any, force: Any) -> None:
    """The linear system of one backward-Euler step, linearised once (Baraff & Witkin 1998):
    ``(M − h·∂f/∂v − h²·∂f/∂x)·Δv = h·(f + h·∂f/∂x·v)``, written into the block-CSR values
    ``data`` (pattern from ``Cloth._implicit_setup``: ``slot_diag[i]``, ``slot_ij[s]``,
    ``slot_ji[s]`` are the blocks (i, i), (i, j), (j, i) of spring s), the right-hand side
    ``rhs`` and the block-Jacobi preconditioner ``pre``.

    Per spring the force Jacobian is ``K = k·(β·I + (1 − β)·uuᵀ)`` with ``β = max(0, 1 − L/l)``
    (a compressed spring drops its transverse stiffness so that the matrix stays positive
    definite) and the damping Jacobian ``c·uuᵀ``; the block is ``S = h²·K + h·c·uuᵀ``. Rows
    and columns of particles that are not ``free`` (pins, the grabbed particle) are those of
    the identity with a zero right-hand side: their velocity change is fixed (zero), the
    constraint of Baraff and Witkin's filtered solve. Drag and gravity are explicit."""
    n = x.shape[0]
    _gravity(force, weight)
    if coef > 0.0:
        _add_drag(x, v, air, tris, coef, force)
    for i in range(n):
        q = slot_diag[i]
        for e in range(9):
            data[q, e] = 0.0
        data[q, 0] = mass
        data[q, 4] = mass
        data[q, 8] = mass
        rhs[i, 0] = 0.0  # accumulates ∂f/∂x·v first
        rhs[i, 1] = 0.0
        rhs[i, 2] = 0.0
    hh = h * h
    for s in range(si.shape[0]):
        i = si[s]
        j = sj[s]
        ks = k[s]
        t, ux, uy, uz, inv, rel = _spring(x, v, i, j, rest[s], ks, c[s])
        force[i, 0] += t * ux
        force[i, 1] += t * uy
        force[i, 2] += t * uz
        force[j, 0] -= t * ux
        force[j, 1] -= t * uy
        force[j, 2] -= t * uz
        beta = max(0.0, 1.0 - rest[s] * inv)
        a_iso = hh * ks * beta
        a_uu = hh * ks * (1.0 - beta) + h * c[s]
        sxx = a_uu * ux * ux + a_iso
        sxy = a_uu * ux * uy
        sxz = a_uu * ux * uz
        syy = a_uu * uy * uy + a_iso
        syz = a_uu * uy * uz
        szz = a_uu * uz * uz + a_iso
        for q in (slot_diag[i], slot_diag[j]):
            data[q, 0] += sxx
            data[q, 1] += sxy
            data[q, 2] += sxz
            data[q, 3] += sxy
            data[q, 4] += syy
            data[q, 5] += syz
            data[q, 6] += sxz
            data[q, 7] += syz
            data[q, 8] += szz
        if free[i] and free[j]:
            off = -1.0
        else:
            off = 0.0
        for q in (slot_ij[s], slot_ji[s]):
            data[q, 0] = off * sxx
            data[q, 1] = off * sxy
            data[q, 2] = off * sxz
            data[q, 3] = off * sxy
            data[q, 4] = off * syy
            data[q, 5] = off * syz
            data[q, 6] = off * sxz
            data[q, 7] = off * syz
            data[q, 8] = off * szz
        # ∂f/∂x·v: K·(v_j − v_i) at i, the opposite at j (u·(v_j − v_i) is rel).
        dvx = v[j, 0] - v[i, 0]
        dvy = v[j, 1] - v[i, 1]
        dvz = v[j, 2] - v[i, 2]
        kb = ks * beta
        ku = ks * (1.0 - beta) * rel
        kx = kb * dvx + ku * ux
        ky = kb * dvy + ku * uy
        kz = kb * dvz + ku * uz
        rhs[i, 0] += kx
        rhs[i, 1] += ky
        rhs[i, 2] += kz
        rhs[j, 0] -= kx
        rhs[j, 1] -= ky
        rhs[j, 2] -= kz
    for i in range(n):
        q = slot_diag[i]
        if free[i]:
            rhs[i, 0] = h * (force[i, 0] + h * rhs[i, 0])
            rhs[i, 1] = h * (force[i, 1] + h * rhs[i, 1])
            rhs[i, 2] = h * (force[i, 2] + h * rhs[i, 2])
            # The inverse of the symmetric diagonal block (cofactors / determinant).
            a0 = data[q, 0]
            a1 = data[q, 1]
            a2 = data[q, 2]
            a4 = data[q, 4]
            a5 = data[q, 5]
            a8 = data[q, 8]
            c0 = a4 * a8 - a5 * a5
            c1 = a2 * a5 - a1 * a8
            c2 = a1 * a5 - a2 * a4
            det = a0 * c0 + a1 * c1 + a2 * c2
            inv_det = 1.0 / det
            pre[i, 0] = c0 * inv_det
            pre[i, 1] = c1 * inv_det
            pre[i, 2] = c2 * inv_det
            pre[i, 3] = (a0 * a8 - a2 * a2) * inv_det
            pre[i, 4] = (a1 * a2 - a0 * a5) * inv_det
            pre[i, 5] = (a0 * a4 - a1 * a1) * inv_det
        else:
            rhs[i, 0] = 0.0
            rhs[i, 1] = 0.0
            rhs[i, 2] = 0.0
            for e in range(9):
                data[q, e] = 0.0
            data[q, 0] = 1.0
            data[q, 4] = 1.0
            data[q, 8] = 1.0
            pre[i, 0] = 1.0
            pre[i, 1] = 0.0
            pre[i, 2] = 0.0
            pre[i, 3] = 1.0
            pre[i, 4] = 0.0
            pre[i, 5] = 1.0


def _implicit_substep(x: Any, v: Any, air: Any, si: Any, sj: Any, rest: Any, k: Any, c: Any, tris: Any,
                      coef: float, weight: float, mass: float, h: float, kin_idx: Any, kin_pos: Any, kin_vel: Any,
                      free: Any, indptr: Any, indices: Any, slot_diag: Any, slot_ij: Any, slot_ji: Any, data: Any,
                      pre: Any, rhs: Any, force: Any, dv: Any, r: Any, z: Any, p: Any, ap: Any, rtol: float,
                      atol: float, maxiter: int, warm: bool) -> int:
    """One linearised backward-Euler substep without collisions, without the GIL: the
    kinematic velocities, the system (:func:`implicit_assemble`), the solve for ``dv``
    (:func:`block_pcg`, from the ``dv`` passed in when ``warm``), then ``v += dv``,
    ``x += v·h`` and the kinematic particles set. Returns the CG iterations (−1: not finite)."""
    _set_kinematic(v, kin_idx, kin_vel)
    _implicit_assemble(x, v, air, si, sj, rest, k, c, tris, coef, weight, mass, h, free, slot_diag, slot_ij,
                       slot_ji, data, pre, rhs, force)
    it = _block_pcg(data, indptr, indices, pre, rhs, dv, r, z, p, ap, rtol, atol, maxiter, warm)
    for i in range(x.shape[0]):
        v[i, 0] += dv[i, 0]
        v[i, 1] += dv[i, 1]
        v[i, 2] += dv[i, 2]
    _advance(x, v, h, kin_idx, kin_pos, kin_vel)
    return it


# --------------------------------------------------------------------------- compilation
#: Helpers first: a kernel finds its callees among the module's globals when it compiles.
_HELPERS = ("_spring", "_add_springs", "_add_drag", "_gravity", "_set_kinematic", "_advance", "_block_matvec",
            "_precondition", "_block_pcg", "_implicit_assemble")
_compiled: dict[str, Callable[..., Any]] = {}
_compile_lock = threading.Lock()


def _compile_all() -> None:
    """Replace the helpers by their compiled versions, then the kernels (lazily: ``numba.njit``
    compiles, or loads from the disk cache, at the first call). Threads may race to the first
    call (the cache worker and the live cloth): the lock makes one of them do it."""
    with _compile_lock:
        if _compiled:
            return
        g = globals()
        kernels: dict[str, Callable[..., Any]] = {}
        if HAVE_NUMBA:
            import numba

            jit = numba.njit(cache=True, nogil=True)
            for name in _HELPERS:
                g[name] = jit(g[name])
            for name in _KERNELS:
                kernels[name] = g[name] if name in _HELPERS else jit(g[name])
        else:  # pragma: no cover - the numpy paths in cloth.py are used instead
            for name in _KERNELS:
                kernels[name] = g[name]
        _compiled.update(kernels)


def _kernel(fn: F) -> F:
    """The public entry of a kernel: compiles everything at the first call of any kernel."""
    name = fn.__name__

    def call(*args: Any) -> Any:
        if not _compiled:
            _compile_all()
        return _compiled[name](*args)

    call.__name__ = name.lstrip("_")
    call.__doc__ = fn.__doc__
    return cast(F, call)


_KERNELS = ("_spring_forces", "_drag_forces", "_symplectic_substep", "_block_pcg", "_implicit_assemble",
            "_implicit_substep")
spring_forces = _kernel(_spring_forces)
drag_forces = _kernel(_drag_forces)
symplectic_substep = _kernel(_symplectic_substep)
block_pcg = _kernel(_block_pcg)
implicit_assemble = _kernel(_implicit_assemble)
implicit_substep = _kernel(_implicit_substep)


_WARM = False


def warm_up() -> float:
    """Compile (or load from the cache) every kernel; returns the seconds it took (nothing
    after the first call). Loading numba and the cached kernels takes a few hundred
    milliseconds of interpreter time: the application does it while it builds its window,
    so that the first cloth frame a worker computes does not take it from the UI thread
    while the user plays or drags."""
    import time

    global _WARM
    t0 = time.perf_counter()
    if HAVE_NUMBA and not _WARM:
        _WARM = True
        # A three-particle cloth, particle 0 pinned, through every kernel with real types.
        x = np.zeros((3, 3))
        x[1, 0] = 1.0
        x[2, 1] = 1.0
        v = np.zeros((3, 3))
        f = np.zeros((3, 3))
        si = np.array([0, 1], dtype=np.int64)
        sj = np.array([1, 2], dtype=np.int64)
        ones = np.ones(2)
        tris = np.array([[0, 1, 2]], dtype=np.int64)
        none = np.zeros(0, dtype=np.int64)
        # The fused substeps are what a cloth runs; spring_forces, drag_forces, block_pcg and
        # implicit_assemble (for tests) compile at their first call.
        symplectic_substep(x, v, v.copy(), si, sj, ones, ones, ones, tris, 1.0, 0.1, np.ones(3), 0.01,
                           none, np.zeros((0, 3)), np.zeros((0, 3)), f)
        indptr = np.array([0, 2, 5, 7], dtype=np.int64)
        indices = np.array([0, 1, 0, 1, 2, 1, 2], dtype=np.int64)
        slot_diag = np.array([0, 3, 6], dtype=np.int64)
        slot_ij = np.array([1, 4], dtype=np.int64)
        slot_ji = np.array([2, 5], dtype=np.int64)
        free = np.array([False, True, True])
        rhs, force, dv, r, z, p, ap = (np.zeros((3, 3)) for _ in range(7))
        implicit_substep(x, v, v.copy(), si, sj, ones, ones, ones, tris, 1.0, 0.1, 0.1, 0.01, none,
                         np.zeros((0, 3)), np.zeros((0, 3)), free, indptr, indices, slot_diag, slot_ij, slot_ji,
                         np.zeros((7, 9)), np.zeros((3, 6)), rhs, force, dv, r, z, p, ap, 1e-3, 0.0, 10, True)
    return time.perf_counter() - t0
