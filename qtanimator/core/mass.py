"""Mass, centre of mass and polar moment of inertia of 2D shapes about a pivot.

Two sets of formulas (``notes/cmu-animator.md`` section 5):

* **exact** (the default): area-weighted mass and centroid, and the true polar moment of
  every shape kind; open outlines (lines, polylines) are thin strokes whose mass per unit
  length is the stroke density;
* **reference**: the CMU starter program's formulas with their quirks (a polygon's moment
  is a per-unit-area value, rectangles subtract the pivot twice, lines carry a 4/3 factor,
  polyline centroids divide by the number of points). The handout's dynamics constants
  were tuned with these moments, so the ``handout`` pendulum preset uses them.

Strokes of open outlines are bands as wide as the stroke (mass per unit length ρ_s, the
starter's rule, with the band's w²/12 in the moment); filled shapes carry no stroke mass.
Densities follow the starter: stroke ρ_s = 1e-4 · α_stroke · (1 + 0.2 (w − 1)), fill
ρ_f = α_fill, or ρ_s when the fill is fully transparent.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class MassProperties:
    """Mass, centroid (world, rest pose) and polar moment of inertia about ``pivot``."""

    mass: float
    centroid: FloatArray
    inertia: float
    pivot: FloatArray

    @property
    def length(self) -> float:
        """Pendulum length |C − c|."""
        return float(np.hypot(*(self.centroid - self.pivot)))

    @property
    def offset(self) -> FloatArray:
        """The rest-pose vector from the pivot to the centre of mass (y0 in the notes)."""
        return np.asarray(self.centroid - self.pivot, dtype=np.float64)

    @property
    def inertia_about_centroid(self) -> float:
        return max(self.inertia - self.mass * self.length ** 2, 0.0)


class ShapeLike(Protocol):
    kind: str
    points: FloatArray
    closed: bool
    fill: tuple[float, float, float, float]
    stroke: tuple[float, float, float, float]
    stroke_width: float
    opacity: float
    ellipse: tuple[FloatArray, FloatArray] | None
    density_opacity: float | None


def stroke_density(alpha: float, width: float) -> float:
    return 0.0001 * alpha * (1.0 + 0.2 * (width - 1.0))


def shape_densities(shape: ShapeLike) -> tuple[float, float]:
    """(fill density, stroke density) by the starter's rules: the element's own opacity
    scales the fill density, its groups' opacity does not (``notes/cmu-animator.md`` 1.2)."""
    rho_s = stroke_density(shape.stroke[3], shape.stroke_width)
    own = shape.opacity if shape.density_opacity is None else shape.density_opacity
    a_fill = shape.fill[3] * own
    rho_f = a_fill if a_fill != 0 else rho_s
    return rho_f, rho_s


# ----------------------------------------------------------------- exact formulas
def _cross(a: FloatArray, b: FloatArray) -> FloatArray:
    return np.asarray(a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0], dtype=np.float64)


def polygon_properties(points: npt.ArrayLike, density: float, pivot: npt.ArrayLike) -> MassProperties:
    """Exact properties of a uniform simple polygon (either winding)."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    c = np.asarray(pivot, dtype=np.float64)
    if len(p) < 3:
        return polyline_properties(p, 0.0, c)
    q = np.roll(p, -1, axis=0)
    x = _cross(p, q)
    area2 = float(x.sum())
    if area2 == 0.0:
        return MassProperties(0.0, p.mean(axis=0), 0.0, c)
    centroid = ((p + q) * x[:, None]).sum(axis=0) / (3.0 * area2)
    a, b = p - c, q - c
    xa = _cross(a, b)
    j = abs(float((xa * ((a * a).sum(1) + (a * b).sum(1) + (b * b).sum(1))).sum()) / 12.0)
    return MassProperties(density * abs(area2) / 2.0, centroid, density * j, c)


def polyline_properties(points: npt.ArrayLike, density: float, pivot: npt.ArrayLike,
                        width: float = 0.0) -> MassProperties:
    """A stroke along an open polyline; ``density`` is mass per unit length.

    Each segment is a thin band ℓ × ``width`` (joins ignored): I_g = m (ℓ² + w²) / 12; with
    ``width`` 0 this is the thin-rod limit m ℓ² / 12.
    """
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    c = np.asarray(pivot, dtype=np.float64)
    if len(p) == 0:
        return MassProperties(0.0, c.copy(), 0.0, c)
    if len(p) == 1:
        return MassProperties(0.0, p[0].copy(), 0.0, c)
    seg = p[1:] - p[:-1]
    ell = np.hypot(seg[:, 0], seg[:, 1])
    mid = (p[1:] + p[:-1]) / 2.0
    total = float(ell.sum())
    if total == 0.0:
        return MassProperties(0.0, p.mean(axis=0), 0.0, c)
    m = density * ell
    centroid = (mid * ell[:, None]).sum(axis=0) / total
    d2 = ((mid - c) ** 2).sum(axis=1)
    inertia = float((m * ((ell ** 2 + width * width) / 12.0 + d2)).sum())
    return MassProperties(float(m.sum()), centroid, inertia, c)


def ellipse_properties(center: npt.ArrayLike, axes: npt.ArrayLike, density: float,
                       pivot: npt.ArrayLike) -> MassProperties:
    """A filled ellipse ``center + A·u`` over the unit disc (A: 2×2, any affine image)."""
    g = np.asarray(center, dtype=np.float64)
    A = np.asarray(axes, dtype=np.float64).reshape(2, 2)
    c = np.asarray(pivot, dtype=np.float64)
    det = abs(float(np.linalg.det(A)))
    m = density * math.pi * det
    ig = m * float((A * A).sum()) / 4.0
    d = g - c
    return MassProperties(m, g.copy(), ig + m * float(d @ d), c)


def point_properties(p: npt.ArrayLike, mass: float, pivot: npt.ArrayLike) -> MassProperties:
    q = np.asarray(p, dtype=np.float64)
    c = np.asarray(pivot, dtype=np.float64)
    d = q - c
    return MassProperties(mass, q.copy(), mass * float(d @ d), c)


def shape_mass_properties(shape: ShapeLike, pivot: npt.ArrayLike) -> MassProperties:
    """Exact properties of one shape about ``pivot`` (starter densities)."""
    rho_f, rho_s = shape_densities(shape)
    if shape.kind == "point":
        return point_properties(shape.points[0], shape.stroke[3], pivot)
    if shape.ellipse is not None:
        return ellipse_properties(shape.ellipse[0], shape.ellipse[1], rho_f, pivot)
    if shape.closed:
        return polygon_properties(shape.points, rho_f, pivot)
    return polyline_properties(shape.points, rho_s, pivot, shape.stroke_width)


def combine(parts: list[MassProperties], pivot: npt.ArrayLike) -> MassProperties:
    """Sum of parts about a common pivot; zero total mass puts the centroid at the pivot."""
    c = np.asarray(pivot, dtype=np.float64)
    m = sum(p.mass for p in parts)
    inertia = sum(p.inertia for p in parts)
    if m <= 0.0:
        return MassProperties(0.0, c.copy(), float(inertia), c)
    centroid = sum((p.mass * p.centroid for p in parts), np.zeros(2)) / m
    return MassProperties(float(m), np.asarray(centroid, dtype=np.float64), float(inertia), c)


def joint_mass_properties(shapes: list[ShapeLike], pivot: npt.ArrayLike,
                          reference: bool = False) -> MassProperties:
    fn = reference_shape_mass_properties if reference else shape_mass_properties
    return combine([fn(s, pivot) for s in shapes], pivot)


# ------------------------------------------------------------ reference (quirks)
def _reference_polygon_moment(points: FloatArray, density: float, centre: FloatArray) -> float:
    a = points - centre
    b = np.roll(a, -1, axis=0)
    x = _cross(a, b)
    s = float(x.sum())
    if s == 0.0:
        return 0.0
    ab = a + b
    return density * abs(float(((ab * ab).sum(1) * x).sum()) / 6.0) / abs(s)


def reference_shape_mass_properties(shape: ShapeLike, pivot: npt.ArrayLike) -> MassProperties:
    """The CMU starter's per-shape values (section 5.4 of the notes)."""
    c = np.asarray(pivot, dtype=np.float64)
    rho_f, rho_s = shape_densities(shape)
    if shape.kind == "point":
        return point_properties(shape.points[0], shape.stroke[3], c)
    if shape.ellipse is not None:
        return ellipse_properties(shape.ellipse[0], shape.ellipse[1], rho_f, c)
    p = np.asarray(shape.points, dtype=np.float64)
    if shape.kind == "line" or (not shape.closed and len(p) == 2):
        length = float(np.hypot(*(p[1] - p[0])))
        middle = (p[0] + p[1]) / 2.0
        d = middle - c
        return MassProperties(rho_s * length, middle, rho_s * (4.0 / 3.0) * length * float(d @ d), c)
    if not shape.closed:
        seg = p[1:] - p[:-1]
        ell = np.hypot(seg[:, 0], seg[:, 1])
        mid = (p[1:] + p[:-1]) / 2.0
        d2 = ((mid - c) ** 2).sum(axis=1)
        centroid = mid.sum(axis=0) / len(p)
        return MassProperties(float(rho_s * ell.sum()), centroid,
                              float((rho_s * (4.0 / 3.0) * ell * d2).sum()), c)
    exact = polygon_properties(p, rho_f, c)
    centre = 2.0 * c if shape.kind == "rect" else c
    return MassProperties(exact.mass, exact.centroid, _reference_polygon_moment(p, rho_f, centre), c)
