"""Authored placement of an asset: where a character stands in the scene (issue 14).

The placement is the asset property ``placement`` (saved with the project, changed by one
undoable :class:`~qtanimator.document.commands.SetAssetProperty`):

* 2D: ``{"translate": [x, y], "rotate": degrees, "scale": s}`` — the character's whole frame
  is moved, turned (counter-clockwise on the y-down screen, the joints' convention) and
  scaled uniformly about its rest root pivot: P = T(t) · T(c₀) · R(φ) · S(s) · T(−c₀).
  Everything the character computes (keys, pendulums, IK) stays in its own frame; the
  posed world matrices are P · W (:func:`qtanimator.document.character2d.evaluate_pose`).
* 3D: ``{"translate": [x, y, z], "rotate": [rx, ry, rz] degrees, "scale": s}`` —
  A = T(t) · Rz · Ry · Rx · S(s), put on top of the skeleton's own (file) placement:
  world = A · file placement · T(root translation) · L_root … in
  :func:`qtanimator.document.character3d.pose_skeleton`, so bones, skin, picking and IK
  all see it.

Missing fields are the identity; a missing property is no placement at all.
"""

from __future__ import annotations

import math
from collections.abc import Hashable, Mapping
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.document.commands import Command, SetAssetProperty
from qtanimator.document.document import Document

FloatArray = npt.NDArray[np.float64]

#: The asset property holding the authored placement.
PLACEMENT = "placement"
#: The height a new 3D character is scaled to (floor units: the floor grid's squares are 1).
CHARACTER_HEIGHT = 1.7
#: The gap left between an imported character and the ones already there (fraction of height).
GAP = 0.25
#: A character imported into a document without 3D characters is scaled only when its height
#: is more than this factor away from :data:`CHARACTER_HEIGHT` (centimetres, millimetres).
FAR_FROM_UNIT = 20.0


def _float(value: Any, default: float) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        return default
    return v if math.isfinite(v) else default


def _vector(value: Any, n: int) -> list[float]:
    if not isinstance(value, (list, tuple)):
        value = [value] * n if isinstance(value, (int, float)) else []
    out = [_float(v, 0.0) for v in list(value)[:n]]
    return out + [0.0] * (n - len(out))


def normalized(value: Any, dims: int) -> dict[str, Any]:
    """The placement property as ``{"translate", "rotate", "scale"}`` with every field (bad
    or missing fields are the identity's). ``dims`` is 2 or 3."""
    p = value if isinstance(value, Mapping) else {}
    scale = _float(p.get("scale"), 1.0)
    if scale == 0.0:
        scale = 1.0
    rotate: float | list[float] = _float(p.get("rotate"), 0.0) if dims == 2 else _vector(p.get("rotate"), 3)
    return {"translate": _vector(p.get("translate"), dims), "rotate": rotate, "scale": scale}


def placement_of(doc: Document, asset_id: str, dims: int) -> dict[str, Any]:
    asset = doc.assets.get(asset_id)
    return normalized(asset.properties.get(PLACEMENT) if asset is not None else None, dims)


def is_identity(p: Mapping[str, Any]) -> bool:
    rot = p["rotate"]
    return (not any(p["translate"]) and p["scale"] == 1.0
            and (rot == 0.0 if isinstance(rot, float) else not any(rot)))


def matrix3d(value: Any) -> FloatArray:
    """4×4 A = T(t) · Rz · Ry · Rx · S(s) of a 3D placement property."""
    p = normalized(value, 3)
    rx, ry, rz = (math.radians(a) for a in p["rotate"])
    cx, sx, cy, sy, cz, sz = math.cos(rx), math.sin(rx), math.cos(ry), math.sin(ry), math.cos(rz), math.sin(rz)
    r_x = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]], dtype=np.float64)
    r_y = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]], dtype=np.float64)
    r_z = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]], dtype=np.float64)
    m = np.eye(4)
    m[:3, :3] = r_z @ r_y @ r_x * p["scale"]
    m[:3, 3] = p["translate"]
    return m


def matrix2d(value: Any, pivot: npt.ArrayLike = (0.0, 0.0)) -> FloatArray:
    """3×3 P = T(t) · T(c) · R(φ) · S(s) · T(−c) of a 2D placement property, with R(φ) =
    [[cos φ, sin φ], [−sin φ, cos φ]] (counter-clockwise on a y-down screen)."""
    p = normalized(value, 2)
    phi = math.radians(p["rotate"])
    c, s = math.cos(phi), math.sin(phi)
    lin = np.array([[c, s], [-s, c]], dtype=np.float64) * p["scale"]
    piv = np.asarray(pivot, dtype=np.float64).reshape(2)
    m = np.eye(3)
    m[:2, :2] = lin
    m[:2, 2] = np.asarray(p["translate"], dtype=np.float64) + piv - lin @ piv
    return m


def set_placement_command(doc: Document, asset_id: str, value: Mapping[str, Any] | None,
                          gesture: Hashable | None = None, text: str = "Place character") -> Command:
    """One undo step setting the asset's placement (None removes it)."""
    return SetAssetProperty(doc, asset_id, PLACEMENT, None if value is None else dict(value), text=text,
                            gesture=gesture)


def set_field_command(doc: Document, asset_id: str, dims: int, field: str, index: int | None, value: float,
                      gesture: Hashable | None = None) -> Command:
    """Change one number of the placement (``field`` translate / rotate / scale, ``index`` the
    component of a vector field)."""
    p = placement_of(doc, asset_id, dims)
    if index is None or not isinstance(p[field], list):
        p[field] = float(value)
    else:
        p[field] = list(p[field])
        p[field][index] = float(value)
    return set_placement_command(doc, asset_id, p, gesture, text=f"Set {field}")


def boxes_overlap(a: tuple[FloatArray, FloatArray], b: tuple[FloatArray, FloatArray]) -> bool:
    """Whether two axis-aligned boxes (lo, hi) intersect (touching counts as disjoint)."""
    return bool(np.all(a[0] < b[1]) and np.all(b[0] < a[1]))
