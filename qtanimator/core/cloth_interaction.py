"""Interaction with a running cloth: moving the pins, grabbing a particle, moving capsules.

Kinematic particles: the pinned set (moved rigidly by :meth:`ClothInteraction.move_pins`)
and the grabbed particle. They move linearly to their targets over the substeps of the next
:meth:`Cloth.step <qtanimator.core.cloth.Cloth.step>` and land on them exactly
(:meth:`ClothInteraction._kinematics` gives the step their start and end places).
:class:`qtanimator.core.cloth.Cloth` inherits these methods.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from qtanimator.core.cloth_collide import Capsules, capsule_depths, capsules
from qtanimator.core.cloth_grid import BoolArray, FloatArray, IntArray, nearest_particle, rotation_matrix

__all__ = ["ClothInteraction"]


class ClothInteraction:
    """The pin, grab and capsule methods of :class:`~qtanimator.core.cloth.Cloth` (a mixin:
    the cloth sets these attributes up)."""

    n: int
    positions: FloatArray
    velocities: FloatArray
    pinned: BoolArray
    pin_targets: FloatArray
    grabbed: int | None
    _pin_index: IntArray
    _grab_target: FloatArray | None
    _capsules: Capsules | None
    _capsules_now: tuple[FloatArray, FloatArray, FloatArray] | None

    def pin_centroid(self) -> FloatArray:
        """Centroid of the pin targets (the pivot of :meth:`move_pins` rotations)."""
        if len(self._pin_index) == 0:
            return np.asarray(self.positions.mean(axis=0), dtype=np.float64)
        return np.asarray(self.pin_targets.mean(axis=0), dtype=np.float64)

    # ---------------------------------------------------------- interaction
    def move_pins(self, translation: Any = (0.0, 0.0, 0.0), rotation: Any = None, *, immediate: bool = False) -> None:
        """Move the pinned set rigidly: rotate about the pins' centroid, then translate.

        ``rotation`` is a rotation vector (axis·angle, radians) or a 3×3 matrix. The pins travel
        to their new places during the next :meth:`step` (with the matching velocity, so the
        springs see a smooth motion) and are exactly there after it. With ``immediate=True`` the
        pinned particles jump there now (for editing while paused).
        """
        t = np.asarray(translation, dtype=np.float64).reshape(3)
        if len(self._pin_index) == 0:
            return
        centre = self.pin_centroid()
        targets = self.pin_targets
        if rotation is not None:
            rot = rotation_matrix(rotation)
            targets = (targets - centre) @ rot.T + centre
        self.pin_targets = targets + t
        if immediate:
            self.positions[self._pin_index] = self.pin_targets
            self.velocities[self._pin_index] = 0.0

    def set_pin_targets(self, targets: Any) -> None:
        """Where the pinned particles are at the end of the next :meth:`step` (they land
        there exactly), in the order of :attr:`pinned_indices`. A character's joint drives
        an attached cloth this way."""
        t = np.asarray(targets, dtype=np.float64)
        if t.shape != (len(self._pin_index), 3):
            raise ValueError(f"pin targets must be ({len(self._pin_index)}, 3), not {t.shape}")
        self.pin_targets = t.copy()

    def set_capsules(self, a: Any, b: Any, radius: Any, a_start: Any = None, b_start: Any = None) -> None:
        """Capsule colliders for the next :meth:`step`: segments ``a[k] → b[k]`` (K, 3) with
        ``radius[k]``, where they are at the end of the step; ``a_start`` / ``b_start`` where
        they are at its start (default: already there). An empty K removes them."""
        caps = capsules(a, b, radius, a_start, b_start)
        self._capsules = caps
        self._capsules_now = None if caps is None else (caps[2].copy(), caps[3].copy(), caps[4].copy())

    def capsule_penetration(self) -> float:
        """The deepest a free particle lies inside a capsule (at its end place), in metres
        (≤ 0: none is inside)."""
        if self._capsules is None:
            return -math.inf
        _, _, a, b, r = self._capsules
        _, _, _, depth = capsule_depths(self.positions, a, b, r)
        free = np.ones(self.n, dtype=bool)
        free[self._pin_index] = False
        return float(depth[free].max()) if free.any() else -math.inf

    @property
    def pinned_indices(self) -> IntArray:
        """Indices of the pinned particles, in the order of :attr:`pin_targets`."""
        return self._pin_index.copy()

    def grab(self, ray_origin: Any, ray_dir: Any, max_distance: float | None = None) -> int | None:
        """Grab the particle nearest to a ray (in front of its origin); None when there is none.

        With ``max_distance`` only particles that close to the ray count.
        """
        i = nearest_particle(self.positions, ray_origin, ray_dir, max_distance)
        if i is not None:
            self.grab_particle(i)
        return i

    def grab_particle(self, index: int) -> None:
        """Grab particle ``index`` where it is now (:meth:`drag_grabbed` then moves it)."""
        if not 0 <= index < self.n:
            raise ValueError(f"particle {index} is outside the cloth's {self.n} particles")
        self.grabbed = int(index)
        self._grab_target = self.positions[index].copy()

    def drag_grabbed(self, target: Any) -> None:
        """Move the grabbed particle to ``target`` during the next step (no-op without a grab)."""
        if self.grabbed is None:
            return
        self._grab_target = np.asarray(target, dtype=np.float64).reshape(3).copy()
        if self.pinned[self.grabbed]:
            slot = int(np.searchsorted(self._pin_index, self.grabbed))
            self.pin_targets[slot] = self._grab_target

    def release(self) -> None:
        """Let go of the grabbed particle; it keeps its velocity."""
        self.grabbed = None
        self._grab_target = None

    def _kinematics(self) -> tuple[IntArray, FloatArray, FloatArray]:
        idx = self._pin_index
        start = self.positions[idx]
        end = self.pin_targets
        g = self.grabbed
        if g is not None and self._grab_target is not None and not self.pinned[g]:
            idx = np.append(idx, g)
            start = np.vstack([start, self.positions[g][None]])
            end = np.vstack([end, self._grab_target[None]])
        return idx, start.copy(), end.copy()
