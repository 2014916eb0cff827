"""Ray picking of joints (numpy only): which joint is under the mouse."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from qtanimator.render.gl.renderer import CharacterDraw, SceneItem


def ray_box(origin: np.ndarray, direction: np.ndarray, bmin: np.ndarray, bmax: np.ndarray) -> float | None:
    """Distance along the ray to an axis-aligned box (None when missed or behind)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / direction
        t1, t2 = (bmin - origin) * inv, (bmax - origin) * inv
    t1 = np.where(np.isnan(t1), -np.inf, t1)
    t2 = np.where(np.isnan(t2), np.inf, t2)
    near, far = float(np.max(np.minimum(t1, t2))), float(np.min(np.maximum(t1, t2)))
    if near > far or far < 0:
        return None
    return max(near, 0.0)


def ray_sphere(origin: np.ndarray, direction: np.ndarray, centre: np.ndarray, radius: float) -> float | None:
    oc = origin - centre
    b = float(oc @ direction)
    c = float(oc @ oc) - radius * radius
    disc = b * b - c
    if disc < 0:
        return None
    t = -b - np.sqrt(disc)
    if t < 0:
        t = -b + np.sqrt(disc)
    return float(t) if t >= 0 else None


def ray_segment_distance(origin: np.ndarray, direction: np.ndarray, a: np.ndarray,
                         b: np.ndarray) -> tuple[float, float]:
    """(distance between the ray and segment ab, ray parameter of the closest point)."""
    u = b - a
    w = origin - a
    uu, ud, dd = float(u @ u), float(u @ direction), float(direction @ direction)
    uw, dw = float(u @ w), float(direction @ w)
    den = uu * dd - ud * ud
    s = float(np.clip((dd * uw - ud * dw) / den, 0.0, 1.0)) if den > 1e-12 else 0.0
    t = max((ud * s - dw) / dd, 0.0)
    return float(np.linalg.norm(origin + t * direction - (a + s * u))), float(t)


def pick_joint_in(item: CharacterDraw, origin: np.ndarray, direction: np.ndarray) -> tuple[int, float] | None:
    """The nearest joint of one character hit by the ray: (joint index, distance)."""
    best: tuple[int, float] | None = None
    if item.boxmin is not None and item.boxmax is not None:
        for j, w in enumerate(item.world):
            inv = np.linalg.inv(w)
            o = inv[:3, :3] @ origin + inv[:3, 3]
            d = inv[:3, :3] @ direction
            t = ray_box(o, d, item.boxmin[j], item.boxmax[j])
            if t is not None and (best is None or t < best[1]):
                best = (j, t)
        return best
    pos = item.world[:, :3, 3]
    r = item.joint_radius * 2.0
    for j, p in enumerate(pos):
        t = ray_sphere(origin, direction, p, r)
        if t is not None and (best is None or t < best[1]):
            best = (j, t)
    if best is not None:
        return best
    for j, p in enumerate(item.parents):
        if p < 0:
            continue
        dist, t = ray_segment_distance(origin, direction, pos[p], pos[j])
        if dist < item.joint_radius * 1.5 and (best is None or t < best[1]):
            best = (j, t)
    return best


def pick_joint(items: Sequence[SceneItem], origin: np.ndarray,
               direction: np.ndarray) -> tuple[str, int, float] | None:
    """The nearest joint of any character hit by the ray: (asset id, joint index, distance)."""
    best: tuple[str, int, float] | None = None
    o, d = np.asarray(origin, dtype=float), np.asarray(direction, dtype=float)
    for item in items:
        if not isinstance(item, CharacterDraw):
            continue
        hit = pick_joint_in(item, o, d)
        if hit is not None and (best is None or hit[1] < best[2]):
            best = (item.asset_id, hit[0], hit[1])
    return best
