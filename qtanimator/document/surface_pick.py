"""Picking a point of a 3D character's skinned surface, for IK where you click.

A ray (the mouse's, from the viewport's camera) is tested against the triangles of the
skin posed at the shown time (skinned on the CPU in float64, then
:func:`qtanimator.core.raycast.ray_triangles`). The hit point belongs to the joint that
influences the hit triangle most: each corner's skin weights times its barycentric
coordinate, summed per joint (skin slots mapped to joints through
:attr:`Character3D.palette <qtanimator.document.character3d.Character3D.palette>`). The IK
effector is that point in the joint's frame (``offset``), so it rides with the joint as
the skin does near it, and a right-drag moves the point under the cursor rather than the
joint's pivot.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from qtanimator.core.raycast import ray_triangles
from qtanimator.core.skinning import skin_positions
from qtanimator.document import character3d
from qtanimator.document.document import Document

FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class SurfaceHit:
    """A picked point of a character's skin: ``point`` (world) on ``triangle`` at ray
    parameter ``t``; ``joint`` the dominant influence there and ``offset`` the point in
    that joint's frame at the time picked (``W_joint · offset = point``)."""

    asset_id: str
    joint: int
    point: FloatArray
    offset: FloatArray
    triangle: int
    t: float


def dominant_joint(ch: character3d.Character3D, corners: npt.ArrayLike, barycentric: npt.ArrayLike) -> int | None:
    """The skeleton joint with the largest barycentric-weighted skin weight over a
    triangle's ``corners`` (3 vertex indices) at ``barycentric`` (3,); None without weights."""
    if ch.skin is None:
        return None
    binding = ch.skin.binding
    corners = np.asarray(corners, dtype=np.intp).reshape(3)
    bary = np.clip(np.asarray(barycentric, dtype=np.float64).reshape(3), 0.0, 1.0)
    totals: dict[int, float] = {}
    plain: dict[int, float] = {}   # unweighted by position: breaks a tie of zeros
    for corner, b in zip(corners.tolist(), bary.tolist()):
        mask = binding.vertex == corner
        for slot, w in zip(binding.joint[mask].tolist(), binding.weight[mask].tolist()):
            joint = int(slot) if ch.palette is None else int(ch.palette[slot])
            totals[joint] = totals.get(joint, 0.0) + b * float(w)
            plain[joint] = plain.get(joint, 0.0) + float(w)
    if not plain or max(plain.values()) <= 0.0:
        return None
    return max(totals, key=lambda j: (totals[j], plain[j]))


def pick_surface(doc: Document, asset_id: str, time: float, origin: npt.ArrayLike,
                 direction: npt.ArrayLike) -> SurfaceHit | None:
    """The nearest point of ``asset_id``'s skin posed at ``time`` on the ray, or None
    (no skin, a miss, or a triangle without weights)."""
    ch = character3d.character(doc, asset_id)
    if ch.skin is None:
        return None
    world = character3d.world_matrices(doc, asset_id, time)
    positions = skin_positions(ch.skin, ch.skinning_world(world))
    hit = ray_triangles(origin, direction, positions, ch.skin.triangles)
    if hit is None:
        return None
    corners = ch.skin.triangles[hit.triangle]
    joint = dominant_joint(ch, corners, hit.barycentric)
    if joint is None or not 0 <= joint < len(world):
        return None
    offset = np.linalg.solve(world[joint], np.append(hit.point, 1.0))[:3]
    return SurfaceHit(asset_id, joint, hit.point.copy(), np.asarray(offset, dtype=np.float64), hit.triangle, hit.t)


def pick_surfaces(doc: Document, asset_ids: Iterable[str], time: float, origin: npt.ArrayLike,
                  direction: npt.ArrayLike) -> SurfaceHit | None:
    """The nearest :func:`pick_surface` hit over several characters."""
    best: SurfaceHit | None = None
    for asset_id in asset_ids:
        hit = pick_surface(doc, asset_id, time, origin, direction)
        if hit is not None and (best is None or hit.t < best.t):
            best = hit
    return best


def effector_point(doc: Document, asset_id: str, joint: int, offset: npt.ArrayLike, time: float) -> FloatArray:
    """Where the point ``offset`` of ``joint``'s frame is in the pose shown at ``time``."""
    w = character3d.world_matrices(doc, asset_id, time)[joint]
    return np.asarray(w[:3, :3] @ np.asarray(offset, dtype=np.float64).reshape(3) + w[:3, 3], dtype=np.float64)


__all__ = ["SurfaceHit", "dominant_joint", "effector_point", "pick_surface", "pick_surfaces"]
