"""Cloth collisions: the ground plane, static spheres and moving capsules.

* Collisions with a ground plane ``y = ground_height`` and spheres: particles are projected
  to the surface (plus ``collision_margin``), the normal velocity is reflected with the
  restitution and the tangential velocity loses Coulomb friction.
* Moving capsules (:meth:`Cloth.set_capsules <qtanimator.core.cloth.Cloth.set_capsules>`:
  segments with a radius, e.g. a character's bones): after every substep a particle inside
  one is pushed out to ``radius + margin`` along the normal from the segment (the deepest
  capsule first, three passes where capsules overlap) and the inward normal component of its
  velocity is removed. The capsules move linearly from their start to their end place over
  the substeps of the next step.

Kinematic particles (pins, the grabbed one) never collide. Everything works in place on the
cloth's position and velocity arrays.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from qtanimator.core.cloth_grid import FloatArray, IntArray
from qtanimator.core.cloth_params import ClothParams

__all__ = ["Capsules", "SphereArrays", "capsule_depths", "capsules", "collide", "sphere_arrays"]

#: Spheres as ``(centre array, radius, restitution, friction)``.
SphereArrays = list[tuple[FloatArray, float, float, float]]
#: Capsules for a step: start ends a, b, end ends a, b (K, 3) and radii (K,).
Capsules = tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]


def sphere_arrays(p: ClothParams) -> SphereArrays:
    """The spheres of ``p`` with their centres as arrays."""
    return [(np.asarray(s.centre, dtype=np.float64), float(s.radius), float(s.restitution),
             float(s.friction)) for s in p.spheres]


def capsules(a: Any, b: Any, radius: Any, a_start: Any = None, b_start: Any = None) -> Capsules | None:
    """Checked capsules for :meth:`Cloth.set_capsules <qtanimator.core.cloth.Cloth.set_capsules>`
    (None for an empty set); raises ValueError for mismatched shapes, non-finite ends or radii ≤ 0."""
    end_a = np.asarray(a, dtype=np.float64).reshape(-1, 3)
    end_b = np.asarray(b, dtype=np.float64).reshape(-1, 3)
    rad = np.asarray(radius, dtype=np.float64).reshape(-1)
    if not (len(end_a) == len(end_b) == len(rad)):
        raise ValueError("capsule ends and radii must have the same length")
    if len(rad) and not (np.isfinite(end_a).all() and np.isfinite(end_b).all() and (rad > 0).all()):
        raise ValueError("capsules need finite ends and positive radii")
    if len(rad) == 0:
        return None
    sa = end_a if a_start is None else np.asarray(a_start, dtype=np.float64).reshape(-1, 3)
    sb = end_b if b_start is None else np.asarray(b_start, dtype=np.float64).reshape(-1, 3)
    if sa.shape != end_a.shape or sb.shape != end_b.shape:
        raise ValueError("capsule start and end places must have the same shape")
    return (sa.copy(), sb.copy(), end_a.copy(), end_b.copy(), rad.copy())


def collide(p: ClothParams, x: FloatArray, v: FloatArray, spheres: SphereArrays,
            capsules_now: tuple[FloatArray, FloatArray, FloatArray] | None, kin_idx: IntArray) -> None:
    """Resolve every collision of the free particles, in place on ``x`` and ``v``."""
    margin = p.collision_margin
    if p.ground_enabled:
        floor = p.ground_height + margin
        hit = x[:, 1] < floor
        if len(kin_idx):
            hit[kin_idx] = False
        if hit.any():
            idx = np.flatnonzero(hit)
            x[idx, 1] = floor
            normal = np.broadcast_to(np.array([0.0, 1.0, 0.0]), (len(idx), 3))
            _respond(v, idx, normal, p.ground_restitution, p.ground_friction)
    for centre, radius, restitution, friction in spheres:
        rad = radius + margin
        rel = x - centre
        dist2 = np.einsum("ij,ij->i", rel, rel)
        hit = dist2 < rad * rad
        if len(kin_idx):
            hit[kin_idx] = False
        if not hit.any():
            continue
        idx = np.flatnonzero(hit)
        r = rel[idx]
        dist = np.sqrt(dist2[idx])
        normal = np.empty_like(r)
        ok = dist > 1e-12
        normal[ok] = r[ok] / dist[ok, None]
        normal[~ok] = (0.0, 1.0, 0.0)
        # A relative 1e-12 outside the surface, so rounding never leaves a point inside.
        x[idx] = centre + normal * (rad * (1.0 + 1e-12))
        _respond(v, idx, normal, restitution, friction)
    if capsules_now is not None:
        _collide_capsules(x, v, margin, kin_idx, *capsules_now)


def _collide_capsules(x: FloatArray, v: FloatArray, margin: float, kin_idx: IntArray, a: FloatArray, b: FloatArray,
                      radius: FloatArray) -> None:
    """Push free particles out of the capsules to radius + margin; drop inward velocity."""
    reach = radius + margin
    for _ in range(3):   # overlapping capsules: a push out of one may end in another
        closest, normal, which, depth = capsule_depths(x, a, b, reach)
        if len(kin_idx):
            depth[kin_idx] = -math.inf
        hit = depth > 0
        if not hit.any():
            return
        idx = np.flatnonzero(hit)
        x[idx] = closest[idx] + normal[idx] * (reach[which[idx]] * (1.0 + 1e-12))[:, None]
        vn = np.einsum("ij,ij->i", v[idx], normal[idx])
        v[idx] -= np.minimum(vn, 0.0)[:, None] * normal[idx]


def _respond(v: FloatArray, idx: IntArray, normal: FloatArray, restitution: float, friction: float) -> None:
    vel = v[idx]
    vn = np.einsum("ij,ij->i", vel, normal)
    approaching = vn < 0
    dvn = np.where(approaching, -(1.0 + restitution) * vn, 0.0)
    vt = vel - vn[:, None] * normal
    vt_len = np.sqrt(np.einsum("ij,ij->i", vt, vt))
    # Coulomb friction: the tangential speed drops by μ·|Δv_n| (never reversing).
    keep = np.where(vt_len > 0, np.maximum(0.0, 1.0 - friction * dvn / np.maximum(vt_len, 1e-300)), 1.0)
    vn_new = np.where(approaching, -restitution * vn, vn)
    v[idx] = vt * keep[:, None] + vn_new[:, None] * normal


def capsule_depths(x: FloatArray, a: FloatArray, b: FloatArray,
                    radius: FloatArray) -> tuple[FloatArray, FloatArray, IntArray, FloatArray]:
    """For every point: the closest point on its deepest capsule's segment, the outward unit
    normal, that capsule's index and the depth ``radius − distance`` (> 0: inside)."""
    ab = b - a
    ab2 = np.einsum("kj,kj->k", ab, ab)
    ap = x[:, None, :] - a[None, :, :]
    t = np.clip(np.einsum("nkj,kj->nk", ap, ab) / np.where(ab2 > 0, ab2, 1.0), 0.0, 1.0)
    closest = a[None, :, :] + t[:, :, None] * ab[None, :, :]
    d = x[:, None, :] - closest
    dist = np.sqrt(np.einsum("nkj,nkj->nk", d, d))
    pen = radius[None, :] - dist
    k = np.argmax(pen, axis=1)
    rows = np.arange(len(x))
    dk, lk = d[rows, k], dist[rows, k]
    normal = np.empty_like(dk)
    ok = lk > 1e-12
    normal[ok] = dk[ok] / lk[ok, None]
    # On the axis itself: any direction across the segment.
    across = np.cross(ab[k[~ok]], np.array([0.0, 0.0, 1.0]))
    across[np.einsum("ij,ij->i", across, across) < 1e-24] = (1.0, 0.0, 0.0)
    normal[~ok] = across / np.linalg.norm(across, axis=1)[:, None] if len(across) else across
    return closest[rows, k], normal, k.astype(np.int64), pen[rows, k]

