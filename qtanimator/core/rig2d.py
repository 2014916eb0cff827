"""2D jointed characters: joints, shapes, forward kinematics and hit testing.

Coordinates are SVG user units with y pointing down. A joint's rotation is
R(θ) = [[cos θ, sin θ], [−sin θ, cos θ]] (positive = counter-clockwise on screen), and

    T_joint = T_parent · T(c) · R(θ) · T(−c)

with c the joint's rest-pose pivot; the root's parent transform is the character's
translation. Shapes are stored in rest-pose coordinates with every SVG transform baked in,
so a pose only needs one 3×3 matrix per joint.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.core.mass import MassProperties, joint_mass_properties

FloatArray = npt.NDArray[np.float64]
RGBA = tuple[float, float, float, float]


@dataclass(eq=False)
class Shape:
    """One drawable piece of a joint, free of any Qt type.

    ``points`` is the outline after flattening curves (rest-pose coordinates, transforms
    baked in); ``closed`` says whether it is a filled area (polygon) or an open polyline.
    ``kind`` records the SVG element it came from (``polygon``, ``polyline``, ``line``,
    ``rect``, ``ellipse``, ``path``, ``point``); ellipses and circles also keep their exact
    geometry in ``ellipse`` = (centre, A) with the ellipse = centre + A·(unit disc).
    Colours are RGBA in 0…1; ``fill`` alpha includes ``fill-opacity``, and ``opacity`` is
    the element's group opacity (applied to fill and stroke when drawing).
    ``density_opacity`` is the element's own ``opacity`` only, the factor the starter's
    fill density uses (groups' opacity is a look, not a mass); None: ``opacity``.
    """

    points: FloatArray
    closed: bool
    fill: RGBA = (0.0, 0.0, 0.0, 1.0)
    stroke: RGBA = (0.0, 0.0, 0.0, 0.0)
    stroke_width: float = 1.0
    opacity: float = 1.0
    kind: str = "polygon"
    ellipse: tuple[FloatArray, FloatArray] | None = None
    density_opacity: float | None = None

    def bounds(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) of the outline, stroke included."""
        p = self.points
        h = self.stroke_width / 2.0 if self.stroke[3] > 0 else 0.0
        return (float(p[:, 0].min()) - h, float(p[:, 1].min()) - h,
                float(p[:, 0].max()) + h, float(p[:, 1].max()) + h)

    def contains(self, point: npt.ArrayLike, tolerance: float = 0.0) -> bool:
        """Point-in-shape test in rest-pose coordinates.

        Filled areas use the even-odd rule; open outlines and stroked edges are hit
        within half the stroke width plus ``tolerance``.
        """
        q = np.asarray(point, dtype=np.float64)
        p = self.points
        if len(p) == 0:
            return False
        if self.closed and self.fill[3] > 0 and len(p) >= 3 and _inside_polygon(p, q):
            return True
        half = (self.stroke_width / 2.0 if self.stroke[3] > 0 else 0.0) + tolerance
        if not self.closed and self.fill[3] > 0 and len(p) >= 3 and _inside_polygon(p, q):
            return True
        if half <= 0:
            return False
        return _distance_to_outline(p, q, self.closed) <= half


def _inside_polygon(p: FloatArray, q: FloatArray) -> bool:
    x, y = p[:, 0], p[:, 1]
    x2, y2 = np.roll(x, -1), np.roll(y, -1)
    cond = (y > q[1]) != (y2 > q[1])
    with np.errstate(divide="ignore", invalid="ignore"):
        xi = x + (q[1] - y) * (x2 - x) / (y2 - y)
    return bool(np.count_nonzero(cond & (q[0] < xi)) % 2 == 1)


def _distance_to_outline(p: FloatArray, q: FloatArray, closed: bool) -> float:
    if len(p) == 1:
        return float(np.hypot(*(p[0] - q)))
    a = p if closed else p[:-1]
    b = np.roll(p, -1, axis=0) if closed else p[1:]
    ab = b - a
    denom = (ab * ab).sum(1)
    t = np.clip(((q - a) * ab).sum(1) / np.where(denom > 0, denom, 1.0), 0.0, 1.0)
    d = a + ab * t[:, None] - q
    return float(np.sqrt((d * d).sum(1)).min())


@dataclass(eq=False)
class Joint:
    """A rigid part rotating about ``pivot`` (rest pose) relative to its ``parent``."""

    name: str
    parent: int | None
    pivot: FloatArray
    is_dynamic: bool = False
    shapes: list[Shape] = field(default_factory=list)
    children: list[int] = field(default_factory=list)
    mass_properties: MassProperties | None = None
    reference_mass_properties: MassProperties | None = None
    #: The joint's own drawing as a standalone SVG document (its elements with the
    #: definitions they use, minus the pivot marker and the child joints) in the joint's
    #: rest frame, the frame of ``shapes``; drawn by a real SVG renderer. None: draw
    #: ``shapes`` (characters built from geometry alone).
    svg: str | None = None
    #: A spring joint: its keyed local angle is followed through a damped spring
    #: (:mod:`qtanimator.core.spring_joint`). A dynamic joint is never a spring.
    is_spring: bool = False

    @property
    def mass(self) -> float:
        return self.mass_properties.mass if self.mass_properties else 0.0

    @property
    def centroid(self) -> FloatArray:
        return self.mass_properties.centroid if self.mass_properties else self.pivot

    @property
    def inertia(self) -> float:
        return self.mass_properties.inertia if self.mass_properties else 0.0


@dataclass(eq=False)
class Pose:
    """A character posed: local ``angles`` (J,), ``translation`` (2,), world matrices
    (J, 3, 3), current pivots (J, 2) and world (accumulated) angles (J,)."""

    angles: FloatArray
    translation: FloatArray
    world: FloatArray
    pivots: FloatArray
    world_angles: FloatArray
    #: The authored placement P (3×3) already folded into ``world`` and ``pivots`` (None:
    #: none). ``angles``, ``translation`` and ``world_angles`` stay in the character's frame.
    placement: FloatArray | None = None

    def placed(self, placement: npt.ArrayLike | None) -> Pose:
        """This pose seen through a placement P: world matrices P · W, pivots P · p."""
        if placement is None:
            return self
        m = np.asarray(placement, dtype=np.float64).reshape(3, 3)
        world = m @ self.world
        pivots = self.pivots @ m[:2, :2].T + m[:2, 2]
        total = m if self.placement is None else m @ self.placement
        return Pose(self.angles, self.translation, world, pivots, self.world_angles, total)

    def to_world(self, joint: int, local_point: npt.ArrayLike) -> FloatArray:
        """A rest-pose point of ``joint`` mapped to its current position."""
        p = np.asarray(local_point, dtype=np.float64)
        m = self.world[joint]
        return np.asarray(m[:2, :2] @ p + m[:2, 2], dtype=np.float64)

    def to_local(self, joint: int, world_point: npt.ArrayLike) -> FloatArray:
        """Inverse of :meth:`to_world` (the IK source point of a right-press)."""
        p = np.asarray(world_point, dtype=np.float64)
        m = self.world[joint]
        if self.placement is not None:  # a scaled placement: not a rotation any more
            return np.asarray(np.linalg.solve(m[:2, :2], p - m[:2, 2]), dtype=np.float64)
        return np.asarray(m[:2, :2].T @ (p - m[:2, 2]), dtype=np.float64)


def rotation(theta: float) -> FloatArray:
    """R(θ) in the starter's convention (counter-clockwise on a y-down screen)."""
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, s], [-s, c]])


class Character:
    """A jointed 2D character: joints in pre-order (root first)."""

    def __init__(self, name: str, joints: list[Joint], source: str | None = None,
                 warnings: list[str] | None = None) -> None:
        if not joints:
            raise ValueError("a character needs at least one joint")
        self.name = name
        self.joints = joints
        self.source = source
        self.warnings = list(warnings or [])
        #: Names of the drawing's layers and top-level groups that could become joints
        #: (filled by the SVG reader for a drawing that is not rigged).
        self.joint_candidates: list[str] = []
        #: Each candidate's element reference in the SVG (see ``formats.svg_rig``'s rig spec).
        self.candidate_elements: dict[str, str] = {}
        #: The rig spec that rebuilds this character from its SVG (plain data; the asset
        #: property ``rig`` once it is rigged in the program), or None.
        self.rig_spec: dict[str, Any] | None = None
        #: Data others derive from this character on first use and keep with it (the IK
        #: solver's chain plans, the 2D painter's outlines), by the user's key: owned, like
        #: the character, by the document's runtime and dropped with it; never saved.
        self.derived: dict[str, Any] = {}
        for i, j in enumerate(joints):
            if i == 0 and j.parent is not None:
                raise ValueError("the first joint must be the root")
            if i > 0 and (j.parent is None or not 0 <= j.parent < i):
                raise ValueError("joints must be in pre-order with parents before children")
            j.children = []
        for i, j in enumerate(joints):
            if j.parent is not None:
                joints[j.parent].children.append(i)
            if j.mass_properties is None:
                j.mass_properties = joint_mass_properties(list(j.shapes), j.pivot)
            if j.reference_mass_properties is None:
                j.reference_mass_properties = joint_mass_properties(list(j.shapes), j.pivot, reference=True)
        names = [j.name for j in joints]
        if len(set(names)) != len(names):
            raise ValueError("joint names must be unique within a character")
        self._index = {n: i for i, n in enumerate(names)}
        self.parents = np.array([-1 if j.parent is None else j.parent for j in joints], dtype=np.intp)
        self.rest_pivots = np.array([j.pivot for j in joints], dtype=np.float64).reshape(-1, 2)
        self.dynamic = np.array([j.is_dynamic for j in joints], dtype=bool)
        self.spring = np.array([j.is_spring and not j.is_dynamic for j in joints], dtype=bool)
        #: Joints the simulation moves: dynamic (pendulum) and spring joints.
        self.simulated = self.dynamic | self.spring
        n = len(joints)
        ancestry = np.zeros((n, n))
        for k, j in enumerate(joints):
            if j.parent is not None:
                ancestry[k] = ancestry[j.parent]
            ancestry[k, k] = 1.0
        self._ancestry = ancestry
        self._ancestry_no_root = ancestry[:, 1:]
        self._parent_index = self.parents[1:]
        self._offsets = self.rest_pivots[1:] - self.rest_pivots[self.parents[1:]]

    def __repr__(self) -> str:
        return f"Character({self.name!r}, {len(self.joints)} joints, {int(self.dynamic.sum())} dynamic)"

    @property
    def root(self) -> Joint:
        return self.joints[0]

    def joint_index(self, name: str) -> int:
        return self._index[name]

    def ancestors(self, joint: int) -> list[int]:
        """``joint`` and its ancestors, from the joint up to the root."""
        chain = []
        j: int | None = joint
        while j is not None:
            chain.append(j)
            j = self.joints[j].parent
        return chain

    def rest_pose(self) -> Pose:
        return self.pose(np.zeros(len(self.joints)), np.zeros(2))

    def pose(self, angles: npt.ArrayLike, translation: npt.ArrayLike = (0.0, 0.0)) -> Pose:
        """Forward kinematics for local joint ``angles`` (J,) and a root ``translation``.

        Vectorised over the tree: world angles Θ = A·θ (A[k, m] = 1 when m is k or one of
        its ancestors) and pivots p = p_root + B·s with s_n = R(Θ_parent)(c_n − c_parent)
        (B is A without the root column); then T_k = [R(Θ_k) | p_k − R(Θ_k)·c_k].
        """
        a = np.asarray(angles, dtype=np.float64).reshape(len(self.joints))
        t = np.asarray(translation, dtype=np.float64).reshape(2)
        n = len(self.joints)
        world_angles = self._ancestry @ a
        c = self.rest_pivots
        pivots = np.empty((n, 2))
        pivots[:] = c[0] + t
        if n > 1:
            th = world_angles[self._parent_index]
            cs, sn = np.cos(th), np.sin(th)
            d = self._offsets
            steps = np.stack([cs * d[:, 0] + sn * d[:, 1], -sn * d[:, 0] + cs * d[:, 1]], axis=1)
            pivots += self._ancestry_no_root @ steps
        cs, sn = np.cos(world_angles), np.sin(world_angles)
        world = np.zeros((n, 3, 3))
        world[:, 0, 0] = cs
        world[:, 0, 1] = sn
        world[:, 1, 0] = -sn
        world[:, 1, 1] = cs
        world[:, 2, 2] = 1.0
        world[:, 0, 2] = pivots[:, 0] - (cs * c[:, 0] + sn * c[:, 1])
        world[:, 1, 2] = pivots[:, 1] - (-sn * c[:, 0] + cs * c[:, 1])
        return Pose(a.copy(), t.copy(), world, pivots, world_angles)

    def hit_test(self, pose: Pose, point: npt.ArrayLike, tolerance: float = 0.0) -> int | None:
        """The topmost joint under a world ``point`` (reverse draw order), or None."""
        q = np.asarray(point, dtype=np.float64)
        for i in range(len(self.joints) - 1, -1, -1):
            local = pose.to_local(i, q)
            for shape in reversed(self.joints[i].shapes):
                if shape.contains(local, tolerance):
                    return i
        return None

    def bounds(self, pose: Pose | None = None) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) of the posed character (rest pose by default)."""
        xs: list[float] = []
        ys: list[float] = []
        for i, j in enumerate(self.joints):
            for s in j.shapes:
                pts = s.points
                if pose is not None:
                    m = pose.world[i]
                    pts = pts @ m[:2, :2].T + m[:2, 2]
                h = s.stroke_width / 2.0 if s.stroke[3] > 0 else 0.0
                xs += [float(pts[:, 0].min()) - h, float(pts[:, 0].max()) + h]
                ys += [float(pts[:, 1].min()) - h, float(pts[:, 1].max()) + h]
        if not xs:
            c = self.rest_pivots[0] if pose is None else pose.pivots[0]
            return float(c[0]), float(c[1]), float(c[0]), float(c[1])
        return min(xs), min(ys), max(xs), max(ys)


def angle_sums(ch: Character) -> tuple[FloatArray, FloatArray]:
    """How a joint's world angle is built from local angles: ``(key_sum, dyn_pick)``, both
    (J, J). ``key_sum[k]`` sums the keyed local angles of ``k`` and its keyed ancestors up to
    (not including) the nearest dynamic one, whose world angle ``dyn_pick[k]`` picks (a row
    of zeros when there is none): ``world = key_sum @ local + dyn_pick @ dynamic_world``."""
    n = len(ch.joints)
    key_sum = np.zeros((n, n))
    dyn_pick = np.zeros((n, n))
    nearest = [-1] * n
    for k, j in enumerate(ch.joints):
        p = j.parent
        if j.is_dynamic:
            nearest[k] = k
        else:
            if p is not None:
                key_sum[k] = key_sum[p]
                nearest[k] = nearest[p]
            key_sum[k, k] = 1.0
        if nearest[k] >= 0:
            dyn_pick[k, nearest[k]] = 1.0
    return key_sum, dyn_pick
