"""Camera navigation of the 3D view: orbit, pan and zoom by the mouse, framing (F), the camera
by numbers (the camera fields) and the camera kept in the document's view state
(``view3d.camera``, written when saving; no undo step, the document is not modified).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from PySide6.QtCore import QPointF

from qtanimator.render.gl.camera import OrbitCamera
from qtanimator.render.gl.renderer import CharacterDraw, grid_scale_for
from qtanimator.render.scene3d import scene_bounds
from qtanimator.ui.view3d_base import ViewPart

#: The document parameter holding the 3D camera (view state, written when saving).
CAMERA_PARAMETER = "view3d.camera"
#: The farthest a box the camera frames may reach (metres): beyond it the view matrices
#: lose every digit, and an infinite or NaN box would make the camera NaN (issue 31).
MAX_FRAMED_COORDINATE = 1e9


def framable(bounds: tuple[np.ndarray, np.ndarray] | None) -> tuple[np.ndarray, np.ndarray] | None:
    """``bounds`` when the camera can frame it: finite and within ±:data:`MAX_FRAMED_COORDINATE`;
    else None (the camera stays where it is)."""
    if bounds is None:
        return None
    lo, hi = (np.asarray(b, dtype=float) for b in bounds)
    if lo.shape != (3,) or hi.shape != (3,):
        return None
    corners = np.concatenate([lo, hi])
    if not (np.isfinite(corners).all() and float(np.max(np.abs(corners))) <= MAX_FRAMED_COORDINATE):
        return None
    return lo, hi


class CameraNavigation(ViewPart):
    """The orbit camera of the 3D view (``self.camera``): moving, framing, storing it."""

    _camera_seen: tuple[float, ...]   # what cameraChanged last announced

    def restore_camera(self) -> bool:
        """Take the camera stored in the document (``view3d.camera``); without one (or with
        an unreadable one) the view frames the scene at its next paint. True if restored."""
        stored = self.ctx.doc.view_state.get(CAMERA_PARAMETER)
        camera = OrbitCamera()
        try:
            if not isinstance(stored, dict):
                raise ValueError("no stored camera")
            camera.azimuth = float(stored.get("azimuth", camera.azimuth))
            camera.inclination = float(stored.get("inclination", camera.inclination))
            camera.distance = float(stored.get("distance", camera.distance))
            camera.fov_y = float(stored.get("fov_y", camera.fov_y))
            target = np.asarray(stored.get("target", [0.0, 0.0, 0.0]), dtype=float)
            if target.shape != (3,) or not np.all(np.isfinite(target)) or not all(
                    math.isfinite(v) for v in (camera.azimuth, camera.inclination, camera.distance, camera.fov_y)):
                raise ValueError("bad stored camera")
            if framable((target, target)) is None or not 0.0 < camera.distance <= MAX_FRAMED_COORDINATE \
                    or not 0.0 < camera.fov_y < 180.0 or max(abs(camera.azimuth), abs(camera.inclination)) > 1e6:
                raise ValueError("stored camera out of range")
            camera.target = target
        except (TypeError, ValueError):
            self._framed_once = False
            self._grid_pending = False
            return False
        self.camera = camera
        self._framed_once = True
        self._grid_pending = True
        self._camera_moved()
        return True

    def _camera_moved(self) -> None:
        """Announce ``cameraChanged`` when the camera differs from what was last announced."""
        c = self.camera
        now = (float(c.distance), float(c.azimuth), float(c.inclination),
               *(float(v) for v in np.asarray(c.target, dtype=float)))
        if now != self._camera_seen:
            self._camera_seen = now
            self.cameraChanged.emit()

    def set_camera(self, distance: float | None = None, azimuth: float | None = None,
                   inclination: float | None = None) -> None:
        """Place the orbit camera by numbers (the camera fields; CSE169's distance, azimuth and
        inclination in degrees) about its target. View state, like a mouse orbit: no undo step."""
        c = self.camera
        if distance is not None and math.isfinite(distance):
            c.distance = float(np.clip(distance, 1e-3, 1e5))
        if azimuth is not None and math.isfinite(azimuth):
            c.azimuth = float(azimuth) % 360.0
        if inclination is not None and math.isfinite(inclination):
            c.inclination = float(np.clip(inclination, -89.0, 89.0))
        self._framed_once = True   # a camera placed by hand is kept (and saved), not framed over
        self._camera_moved()
        self.update()

    def navigate(self, mode: str, dx: float, dy: float) -> None:
        """Move the camera by a mouse motion of (dx, dy) pixels: ``"orbit"``, ``"pan"`` or
        ``"zoom"`` (the caller announces and repaints)."""
        if mode == "orbit":
            self.camera.orbit(-dx * 0.4, dy * 0.4)
        elif mode == "pan":
            self.camera.pan(dx, dy, self.height())
        elif mode == "zoom":
            self.camera.zoom(math.exp(dy * 0.01))

    def zoom_steps(self, steps: float) -> None:
        """The wheel: zoom in by ``steps`` notches (out when negative)."""
        self.camera.zoom(0.88 ** steps)
        self._camera_moved()
        self.update()

    def camera_state(self) -> dict[str, Any]:
        """The camera as plain JSON data (what ``view3d.camera`` holds)."""
        c = self.camera
        return {"azimuth": float(c.azimuth), "inclination": float(c.inclination), "distance": float(c.distance),
                "target": [float(v) for v in np.asarray(c.target, dtype=float)], "fov_y": float(c.fov_y)}

    def store_camera(self) -> None:
        """Save hook: remember the camera in the document's view state (``view3d.camera``).

        Camera moves are view state, not edits: no command, no undo step, the document is
        not marked modified. Only a camera that has framed or shown a scene is stored; an
        untouched document keeps what it had.
        """
        if self._framed_once:
            self.ctx.doc.set_view_state(CAMERA_PARAMETER, self.camera_state())

    def frame_bounds(self, bounds: tuple[np.ndarray, np.ndarray]) -> None:
        """Point the camera at a box (a new 3D asset frames itself this way); a box that is
        not :func:`framable` leaves the camera as it is."""
        found = framable(bounds)
        if found is None:
            return
        self.camera.frame(*found)
        self.options.grid_scale = grid_scale_for(*found)
        self._framed_once = True
        self._grid_pending = False
        self._camera_moved()
        self.update()

    def frame_all(self) -> None:
        items = self._items or self.build_items()
        bounds = framable(scene_bounds(items))
        if bounds is not None:
            self.camera.frame(*bounds)
            self.options.grid_scale = grid_scale_for(*bounds)
        self._camera_moved()
        self.update()

    def frame_selection(self) -> None:
        """Frame the selected joint's character (or everything)."""
        asset, joint = self.ctx.selection
        items = self._items or self.build_items()
        chosen = [i for i in items if getattr(i, "asset_id", None) == asset] if asset else []
        bounds = framable(scene_bounds(chosen or items))
        if bounds is not None:
            self.camera.frame(*bounds)
            if joint:
                for item in chosen:
                    if isinstance(item, CharacterDraw) and item.selected is not None:
                        self.camera.target = item.world[item.selected, :3, 3].copy()
        self._camera_moved()
        self.update()

    def ray_at(self, pos: QPointF) -> tuple[np.ndarray, np.ndarray]:
        """The camera ray through a widget position: (origin, unit direction)."""
        return self.camera.ray(pos.x(), pos.y(), max(self.width(), 1), max(self.height(), 1))

    def _on_view_plane(self, pos: QPointF, anchor: np.ndarray) -> np.ndarray | None:
        """Where the mouse ray meets the plane through ``anchor`` facing the camera."""
        origin, direction = self.ray_at(pos)
        normal = self.camera.eye() - np.asarray(self.camera.target, dtype=float)
        normal /= np.linalg.norm(normal)
        den = float(direction @ normal)
        if abs(den) < 1e-9:
            return None
        t = float((anchor - origin) @ normal) / den
        return origin + t * direction


__all__ = ["CAMERA_PARAMETER", "CameraNavigation"]
