"""Picking in the 3D view: the joint, the point of a skin or the light under the cursor.

Locked assets (outliner) are drawn but not picked; hidden ones are not drawn, so not picked.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from PySide6.QtCore import QPointF

from qtanimator.document.outliner import is_locked, pickable
from qtanimator.document.surface_pick import pick_surfaces
from qtanimator.render.gl.lights import LIGHT_NAMES, lights_of
from qtanimator.render.gl.picking import pick_joint, ray_sphere
from qtanimator.render.gl.renderer import CharacterDraw
from qtanimator.ui.view3d_camera import CameraNavigation


class Picking(CameraNavigation):
    """What is under a widget position, along the camera ray (:meth:`ray_at`)."""

    def pick(self, pos: QPointF) -> tuple[str, int, float] | None:
        """The joint under a widget position: (asset id, joint index, distance)."""
        items = self.build_items()
        if self.options.show_skin:
            # over a skin the skeleton is drawn as spheres and bones: pick those
            items = [dataclasses.replace(i, boxmin=None, boxmax=None)
                     if isinstance(i, CharacterDraw) and i.skin is not None else i for i in items]
        # Locked assets (outliner) are drawn but not picked; hidden ones are not drawn.
        items = [i for i in items if not is_locked(self.ctx.doc, getattr(i, "asset_id", ""))]
        origin, direction = self.ray_at(pos)
        return pick_joint(items, origin, direction)

    def pick_surface(self, pos: QPointF) -> Any:
        """The point of a shown skin under a widget position
        (:class:`~qtanimator.document.surface_pick.SurfaceHit`), or None (skins hidden, a miss)."""
        if not self.options.show_skin:
            return None
        ids = [i.asset_id for i in self.build_items() if isinstance(i, CharacterDraw) and i.skin is not None]
        origin, direction = self.ray_at(pos)
        return pick_surfaces(self.ctx.doc, ids, self.ctx.time, origin, direction)

    def gizmo_size(self) -> float:
        """The radius of a light's sphere in the view (it keeps its size on screen)."""
        return 0.015 * self.camera.distance

    def pick_light(self, pos: QPointF) -> str | None:
        """The light whose gizmo is under a widget position ("light1" / "light2")."""
        if not self.options.show_lights:
            return None
        origin, direction = self.ray_at(pos)
        best = None
        for name, light in zip(LIGHT_NAMES, lights_of(self.ctx.doc)):
            if not pickable(self.ctx.doc, name):
                continue  # locked or switched off in the outliner
            t = ray_sphere(origin, direction, light.position, 1.5 * self.gizmo_size())
            if t is not None and (best is None or t < best[1]):
                best = (name, t)
        return None if best is None else best[0]

    def _joint_key(self, asset_id: str, index: int) -> str:
        """The selection key (``ctx.select``) of a character's joint index."""
        skel = getattr(self.ctx.doc.runtime.get(asset_id), "skeleton", None)
        if skel is None:
            return str(index)
        return str(skel.joint_keys()[index])


__all__ = ["Picking"]
