"""The orbit camera: azimuth, inclination and distance around a target point (y up).

Plain numpy, no GL: the viewport, the headless renderer and picking all use it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np


def perspective(fov_y_deg: float, aspect: float, near: float, far: float) -> np.ndarray:
    f = 1.0 / math.tan(math.radians(fov_y_deg) / 2.0)
    m = np.zeros((4, 4))
    m[0, 0] = f / max(aspect, 1e-9)
    m[1, 1] = f
    m[2, 2] = (far + near) / (near - far)
    m[2, 3] = 2.0 * far * near / (near - far)
    m[3, 2] = -1.0
    return m


def look_at(eye: np.ndarray, target: np.ndarray, up: np.ndarray) -> np.ndarray:
    f = target - eye
    f = f / np.linalg.norm(f)
    s = np.cross(f, up)
    if np.linalg.norm(s) < 1e-9:
        s = np.cross(f, np.array([0.0, 0.0, 1.0]))
    s = s / np.linalg.norm(s)
    u = np.cross(s, f)
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = s, u, -f
    m[:3, 3] = -m[:3, :3] @ eye
    return m


@dataclass
class OrbitCamera:
    """Angles in degrees. Inclination is the elevation above the ground plane (±89°)."""

    azimuth: float = 30.0
    inclination: float = 20.0
    distance: float = 6.0
    target: np.ndarray = field(default_factory=lambda: np.zeros(3))
    fov_y: float = 45.0

    # --------------------------------------------------------------- geometry
    def eye(self) -> np.ndarray:
        az, inc = math.radians(self.azimuth), math.radians(self.inclination)
        d = np.array([math.cos(inc) * math.sin(az), math.sin(inc), math.cos(inc) * math.cos(az)])
        return np.asarray(self.target, dtype=float) + self.distance * d

    def view(self) -> np.ndarray:
        return look_at(self.eye(), np.asarray(self.target, dtype=float), np.array([0.0, 1.0, 0.0]))

    def clip_range(self) -> tuple[float, float]:
        return max(self.distance * 0.01, 1e-3), self.distance * 100.0 + 100.0

    def projection(self, aspect: float) -> np.ndarray:
        near, far = self.clip_range()
        return perspective(self.fov_y, aspect, near, far)

    # ------------------------------------------------------------ interaction
    def orbit(self, d_azimuth: float, d_inclination: float) -> None:
        self.azimuth = (self.azimuth + d_azimuth) % 360.0
        self.inclination = float(np.clip(self.inclination + d_inclination, -89.0, 89.0))

    def zoom(self, factor: float) -> None:
        """Multiply the distance by ``factor`` (< 1 moves closer)."""
        self.distance = float(np.clip(self.distance * factor, 1e-3, 1e5))

    def pan(self, dx_pixels: float, dy_pixels: float, viewport_height: int) -> None:
        """Move the target so that the scene follows the mouse by (dx, dy) pixels."""
        world_per_pixel = 2.0 * self.distance * math.tan(math.radians(self.fov_y) / 2) / max(viewport_height, 1)
        v = self.view()
        right, up = v[0, :3], v[1, :3]
        self.target = np.asarray(self.target, dtype=float) + world_per_pixel * (-dx_pixels * right + dy_pixels * up)

    def frame(self, bmin: np.ndarray, bmax: np.ndarray, margin: float = 1.2) -> None:
        """Aim at the centre of a box and back off until its bounding sphere fits."""
        bmin, bmax = np.asarray(bmin, dtype=float), np.asarray(bmax, dtype=float)
        self.target = (bmin + bmax) / 2.0
        radius = max(float(np.linalg.norm(bmax - bmin)) / 2.0, 1e-3)
        self.distance = margin * radius / math.sin(math.radians(self.fov_y) / 2.0)

    # ------------------------------------------------------ screen <-> world
    def ray(self, x: float, y: float, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
        """World-space ray through pixel (x, y) (origin top left): (origin, unit direction)."""
        ndc = np.array([2.0 * x / width - 1.0, 1.0 - 2.0 * y / height])
        inv = np.linalg.inv(self.projection(width / max(height, 1)) @ self.view())
        p0 = inv @ np.array([ndc[0], ndc[1], -1.0, 1.0])
        p1 = inv @ np.array([ndc[0], ndc[1], 1.0, 1.0])
        a, b = p0[:3] / p0[3], p1[:3] / p1[3]
        d = b - a
        return a, d / np.linalg.norm(d)

    def project(self, points: np.ndarray, width: int, height: int) -> np.ndarray:
        """Pixel coordinates (x right, y down) and depth of world points, shape (N, 3)."""
        p = np.atleast_2d(np.asarray(points, dtype=float))
        h = np.c_[p, np.ones(len(p))] @ (self.projection(width / max(height, 1)) @ self.view()).T
        ndc = h[:, :3] / h[:, 3:4]
        return np.c_[(ndc[:, 0] + 1) * width / 2, (1 - ndc[:, 1]) * height / 2, ndc[:, 2]]

    def to_dict(self) -> dict[str, object]:
        return {"azimuth": self.azimuth, "inclination": self.inclination, "distance": self.distance,
                "target": [float(v) for v in self.target], "fov_y": self.fov_y}
