"""Compiled force kernels for the cloth (numba), used when numba is installed.

Each kernel computes exactly what the vectorised numpy code in :mod:`qtanimator.core.cloth`
computes (the tests compare the two), in one pass over the springs or triangles instead of
~40 whole-array numpy operations per substep. Compiled functions are cached on disk
(``cache=True``), so only the very first run on a machine pays the compile time.
"""

from __future__ import annotations

import importlib.util
import math
import os
from collections.abc import Callable
from typing import Any, TypeVar, cast

import numpy as np

#: numba is the optional ``qtanimator[fast]`` extra; ``QTANIMATOR_NO_NUMBA=1`` forces the numpy
#: paths even when it is installed (CI runs the cloth tests both ways).
HAVE_NUMBA = importlib.util.find_spec("numba") is not None and (
    os.environ.get("QTANIMATOR_NO_NUMBA", "") in ("", "0"))

F = TypeVar("F", bound=Callable[..., Any])


def _compile(fn: F) -> F:
    """``numba.njit(cache=True)`` when numba is installed, else the plain Python function."""
    if not HAVE_NUMBA:  # pragma: no cover - depends on the environment
        return fn
    import numba

    return cast(F, numba.njit(cache=True, nogil=True)(fn))


def _spring_forces(x: Any, v: Any, si: Any, sj: Any, rest: Any, k: Any, c: Any, force: Any) -> None:
    """Add the spring-damper forces of springs ``(si[s], sj[s])`` to ``force`` (N, 3)."""
    for s in range(si.shape[0]):
        i = si[s]
        j = sj[s]
        dx = x[j, 0] - x[i, 0]
        dy = x[j, 1] - x[i, 1]
        dz = x[j, 2] - x[i, 2]
        length = math.sqrt(dx * dx + dy * dy + dz * dz)
        inv = 1.0 / max(length, 1e-12)
        ux = dx * inv
        uy = dy * inv
        uz = dz * inv
        rel = (v[j, 0] - v[i, 0]) * ux + (v[j, 1] - v[i, 1]) * uy + (v[j, 2] - v[i, 2]) * uz
        t = k[s] * (length - rest[s]) + c[s] * rel
        fx = t * ux
        fy = t * uy
        fz = t * uz
        force[i, 0] += fx
        force[i, 1] += fy
        force[i, 2] += fz
        force[j, 0] -= fx
        force[j, 1] -= fy
        force[j, 2] -= fz


def _drag_forces(x: Any, rel: Any, tris: Any, coef: float, force: Any) -> None:
    """Add −coef·|v|²·a·n̂ per triangle (coef = ½ρc_d, v = mean corner ``rel``), ⅓ per corner."""
    for t in range(tris.shape[0]):
        a = tris[t, 0]
        b = tris[t, 1]
        c = tris[t, 2]
        e1x = x[b, 0] - x[a, 0]
        e1y = x[b, 1] - x[a, 1]
        e1z = x[b, 2] - x[a, 2]
        e2x = x[c, 0] - x[a, 0]
        e2y = x[c, 1] - x[a, 1]
        e2z = x[c, 2] - x[a, 2]
        nx = e1y * e2z - e1z * e2y
        ny = e1z * e2x - e1x * e2z
        nz = e1x * e2y - e1y * e2x
        nlen = math.sqrt(nx * nx + ny * ny + nz * nz)
        if nlen <= 0.0:
            continue
        rx = (rel[a, 0] + rel[b, 0] + rel[c, 0]) / 3.0
        ry = (rel[a, 1] + rel[b, 1] + rel[c, 1]) / 3.0
        rz = (rel[a, 2] + rel[b, 2] + rel[c, 2]) / 3.0
        speed = math.sqrt(rx * rx + ry * ry + rz * rz)
        vn = rx * nx + ry * ny + rz * nz
        scale = -coef * speed * vn / (6.0 * nlen)
        fx = nx * scale
        fy = ny * scale
        fz = nz * scale
        for p in (a, b, c):
            force[p, 0] += fx
            force[p, 1] += fy
            force[p, 2] += fz


def _symplectic_substep(x: Any, v: Any, air: Any, si: Any, sj: Any, rest: Any, k: Any, c: Any, tris: Any,
                        coef: float, weight: float, inv_mass_h: Any, h: float, kin_idx: Any, kin_pos: Any,
                        kin_vel: Any, force: Any) -> None:
    """One semi-implicit Euler substep without collisions, in one pass and without the GIL:
    gravity (``weight`` = m·g per particle), drag (relative to ``air``, the wind at each
    particle, when ``coef`` > 0), springs, then ``v += f·(h/m)``, ``x += v·h`` and the
    kinematic particles ``kin_idx`` set to ``kin_pos`` / ``kin_vel``. The same arithmetic
    as ``Cloth._symplectic_substep`` in numpy (tests compare them)."""
    n = x.shape[0]
    for i in range(n):
        force[i, 0] = 0.0
        force[i, 1] = -weight
        force[i, 2] = 0.0
    if coef > 0.0:
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
    _spring_forces_inline(x, v, si, sj, rest, k, c, force)
    for i in range(n):
        s = inv_mass_h[i]
        v[i, 0] += force[i, 0] * s
        v[i, 1] += force[i, 1] * s
        v[i, 2] += force[i, 2] * s
    for q in range(kin_idx.shape[0]):
        j = kin_idx[q]
        v[j, 0] = kin_vel[q, 0]
        v[j, 1] = kin_vel[q, 1]
        v[j, 2] = kin_vel[q, 2]
    for i in range(n):
        x[i, 0] += v[i, 0] * h
        x[i, 1] += v[i, 1] * h
        x[i, 2] += v[i, 2] * h
    for q in range(kin_idx.shape[0]):
        j = kin_idx[q]
        x[j, 0] = kin_pos[q, 0]
        x[j, 1] = kin_pos[q, 1]
        x[j, 2] = kin_pos[q, 2]


def _lazy(fn: F) -> F:
    """Compile on first call, so importing the cloth does not import numba."""
    compiled: list[Callable[..., Any]] = []

    def call(*args: Any) -> Any:
        if not compiled:
            compiled.append(_compile(fn))
        return compiled[0](*args)

    call.__name__ = fn.__name__.lstrip("_")
    call.__doc__ = fn.__doc__
    return cast(F, call)


# The fused substep calls the spring loop through this global: compiled, numba needs a
# compiled callee, made at the first call (importing this module does not import numba).
_spring_forces_inline: Callable[..., None] = _spring_forces


def _lazy_fused(fn: F) -> F:
    compiled: list[Callable[..., Any]] = []

    def call(*args: Any) -> Any:
        if not compiled:
            global _spring_forces_inline
            if HAVE_NUMBA:
                _spring_forces_inline = _compile(_spring_forces)
            compiled.append(_compile(fn))
        return compiled[0](*args)

    call.__name__ = fn.__name__.lstrip("_")
    call.__doc__ = fn.__doc__
    return cast(F, call)


spring_forces = _lazy(_spring_forces)
drag_forces = _lazy(_drag_forces)
symplectic_substep = _lazy_fused(_symplectic_substep)


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
        x = np.zeros((3, 3))
        x[1, 0] = 1.0
        x[2, 1] = 1.0
        v = np.zeros((3, 3))
        f = np.zeros((3, 3))
        idx = np.array([0, 1], dtype=np.int64)
        spring_forces(x, v, idx, idx[::-1].copy(), np.ones(2), np.ones(2), np.ones(2), f)
        drag_forces(x, v, np.array([[0, 1, 2]], dtype=np.int64), 1.0, f)
        symplectic_substep(x, v, v.copy(), idx, idx[::-1].copy(), np.ones(2), np.ones(2), np.ones(2),
                           np.array([[0, 1, 2]], dtype=np.int64), 1.0, 0.1, np.ones(3), 0.01,
                           np.zeros(0, dtype=np.int64), np.zeros((0, 3)), np.zeros((0, 3)), f)
    return time.perf_counter() - t0
