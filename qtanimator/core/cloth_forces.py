"""Cloth forces in numpy: springs, aerodynamic drag and the turbulent wind, and the bounds on
their rates that choose the step (the compiled twins are in :mod:`qtanimator.core.cloth_kernels`).

* Springs are spring-dampers along the line between two particles, each kind with its own
  stiffness ``k`` and damping ``c``:
  ``f_i = (k·(l − L) + c·(v_j − v_i)·u)·u`` with ``u`` the unit vector from i to j.
  Every spring family is a pair of slices of the flat particle array
  (:class:`~qtanimator.core.cloth_grid.SpringFamily`): gather and scatter are slice
  arithmetic, no index arrays, no per-particle Python loop.
* Gravity ``−g·ŷ`` and aerodynamic drag per triangle ``−½·ρ·c_d·|v|²·a·n̂`` with
  ``v`` = triangle velocity − wind (the mean over its corners), ``a = area·(v̂·n̂)``, split ⅓
  per corner. Optional turbulence adds a deterministic, seeded, smoothly varying gust field
  (a sum of travelling sine waves, amplitude ``turbulence`` m/s) to the wind, sampled at the
  particles once per frame.
"""

from __future__ import annotations

import math

import numpy as np

from qtanimator.core.cloth_grid import FloatArray, IntArray, SpringFamily
from qtanimator.core.cloth_params import ClothParams

__all__ = ["add_drag", "add_springs", "drag_rate", "stable_dt", "turbulence_modes", "wind_at"]


def turbulence_modes(seed: int) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The gust field's wave vectors (mode, component, xyz; 1/m), angular frequencies (rad/s)
    and phases, drawn from ``seed``."""
    rng = np.random.default_rng(seed)
    turb_k = rng.normal(0.0, 1.5, size=(4, 3, 3))  # (mode, component, xyz) wave vectors, 1/m
    turb_w = rng.uniform(0.5, 3.0, size=(4, 3)) * 2 * math.pi  # angular frequencies, rad/s
    turb_phase = rng.uniform(0.0, 2 * math.pi, size=(4, 3))
    return turb_k, turb_w, turb_phase


def wind_at(p: ClothParams, modes: tuple[FloatArray, FloatArray, FloatArray], time: float,
            points: FloatArray) -> FloatArray:
    """The wind (steady plus gusts) at ``points`` at ``time``."""
    turb_k, turb_w, turb_phase = modes
    wind = np.asarray(p.wind, dtype=np.float64)
    if p.turbulence <= 0:
        return np.broadcast_to(wind, points.shape)
    gust = np.zeros(points.shape)
    for m in range(turb_k.shape[0]):
        phase = np.einsum("ij,kj->ik", points, turb_k[m]) + turb_w[m] * time + turb_phase[m]
        gust += np.sin(phase)
    return wind + gust * (p.turbulence / math.sqrt(turb_k.shape[0] / 2.0))


def add_drag(x: FloatArray, rel: FloatArray, rows: int, cols: int, coef: float, force: FloatArray) -> None:
    """Add the drag of every triangle to ``force``; ``rel`` is each particle's velocity
    relative to the air, ``coef`` = ½·ρ·c_d."""
    R, C = rows, cols
    x2 = x.reshape(R, C, 3)
    r2 = rel.reshape(R, C, 3)
    f2 = force.reshape(R, C, 3)
    # Quad corners: a (r, c), b (r, c+1), c (r+1, c), d (r+1, c+1); triangles (a, c, d) and (a, d, b).
    sa, sb, sc, sd = (np.s_[:-1, :-1], np.s_[:-1, 1:], np.s_[1:, :-1], np.s_[1:, 1:])
    for corners in ((sa, sc, sd), (sa, sd, sb)):
        p0, p1, p2 = (x2[k] for k in corners)
        nrm = np.cross(p1 - p0, p2 - p0)
        vel = (r2[corners[0]] + r2[corners[1]] + r2[corners[2]]) / 3.0
        # |v|²·a·n̂ with a = area·(v̂·n̂), n̂ = nrm/|nrm|, area = |nrm|/2  →  |v|·(v·nrm)·nrm / (2·|nrm|)
        nlen = np.sqrt(np.einsum("...k,...k->...", nrm, nrm))
        speed = np.sqrt(np.einsum("...k,...k->...", vel, vel))
        vn = np.einsum("...k,...k->...", vel, nrm)
        scale = np.divide(-coef * speed * vn, 6.0 * nlen, out=np.zeros_like(nlen), where=nlen > 0)
        fc = nrm * scale[..., None]  # a third of the triangle's drag
        for corner in corners:
            f2[corner] += fc


def add_springs(families: list[SpringFamily], x: FloatArray, v: FloatArray, fam_k: FloatArray, fam_c: FloatArray,
                fam_rest: FloatArray, buffers: tuple[FloatArray, FloatArray, FloatArray, FloatArray],
                force: FloatArray) -> None:
    """Add every spring's force to ``force``; ``buffers`` are work arrays over the families'
    segments: (M, 3), (M, 3), (M,), (M,)."""
    d, dv, ln, s = buffers
    for f in families:
        o = f.offset
        np.subtract(x[o:], x[:-o], out=d[f.start:f.stop])
        np.subtract(v[o:], v[:-o], out=dv[f.start:f.stop])
    np.einsum("ij,ij->i", d, d, out=ln)
    np.sqrt(ln, out=ln)
    np.maximum(ln, 1e-12, out=s)
    np.divide(1.0, s, out=s)
    d *= s[:, None]  # d is now the unit direction u from i to j
    np.einsum("ij,ij->i", d, dv, out=s)
    s *= fam_c
    ln -= fam_rest
    ln *= fam_k
    ln += s  # scalar tension k·(l − L) + c·(dv·u)
    d *= ln[:, None]  # force on i; j gets the opposite
    for f in families:
        o = f.offset
        seg = d[f.start:f.stop]
        force[:-o] += seg
        force[o:] -= seg


def drag_rate(p: ClothParams, rows: int, cols: int, particle_mass: float) -> float:
    """A bound on the drag's ∂f/∂v ÷ m (1/s), Gershgorin over a particle's six triangles:
    each triangle's drag changes by at most 2·½ρc_d·|w|·area per m/s of its mean relative
    velocity ``w``, with |w| at most the wind, plus the gusts, plus 5 m/s of the cloth's own."""
    if p.drag_coefficient <= 0 or p.air_density <= 0:
        return 0.0
    speed = float(np.linalg.norm(p.wind)) + 5.0 * p.turbulence + 5.0
    area = p.width * p.height / (2.0 * (rows - 1) * (cols - 1))
    return 4.0 * 0.5 * p.air_density * p.drag_coefficient * speed * area / particle_mass


def stable_dt(springs: IntArray, rest_positions: FloatArray, spring_k: FloatArray, spring_c: FloatArray,
              particle_mass: float, drag: float) -> float:
    """Longest stable symplectic substep, estimated from the rest configuration.

    Gershgorin bounds per particle and axis on the largest eigenvalues λ_K of M⁻¹K and λ_C of
    M⁻¹C (springs act along their direction u: row a gets Σ k·|u_a|·Σ_b|u_b| from both ends),
    then the damped-oscillator condition of semi-implicit Euler, h²·λ_K/4 + h·λ_C/2 ≤ 1.
    Drag acts like damping and adds ``drag`` (:func:`drag_rate`) to λ_C.
    """
    n = len(rest_positions)
    i, j = springs[:, 0], springs[:, 1]
    d = rest_positions[j] - rest_positions[i]
    u = np.abs(d / np.linalg.norm(d, axis=1)[:, None])
    w = u * u.sum(axis=1)[:, None]  # (S, 3)
    lam = []
    for coef in (spring_k, spring_c):
        rows = np.zeros((n, 3))
        for a in range(3):
            rows[:, a] = np.bincount(i, coef * w[:, a], n) + np.bincount(j, coef * w[:, a], n)
        lam.append(2.0 * float(rows.max()) / particle_mass)
    lam[1] += drag
    qa, qb = lam[0] / 4.0, lam[1] / 2.0
    if qa <= 0 and qb <= 0:
        return math.inf
    h = 1.0 / qb if qa <= 0 else (-qb + math.sqrt(qb * qb + 4.0 * qa)) / (2.0 * qa)
    return 0.9 * h
