"""The mouse in the 3D view: camera drags and the 3D drags that edit (IK, light move,
placement) or grab the live cloth.

Left click picks a joint (``ctx.select``); left drag orbits (on a live cloth it grabs the
cloth, on a light's sphere it moves the light); middle drag or Shift+left pans; wheel or
Ctrl+left zooms; Alt+left drag on a character moves its placement in the view plane through
its root, Alt+Shift+left scales it about the root; right drag on a skin moves the point under
the cursor by IK (on a joint's sphere or bone, with the skin hidden or missed, the joint's
pivot); right drag elsewhere zooms. Every edit goes through the one gesture protocol:
``ctx.begin_gesture`` at the press, ``update`` per move, ``commit`` at the release (one undo
step), ``abort`` on Escape (:meth:`ViewDrags.abort_drag`).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from PySide6.QtCore import QPointF, Qt
from PySide6.QtGui import QMouseEvent, QWheelEvent

from qtanimator.core.ik3d import chain_dofs
from qtanimator.document import character3d
from qtanimator.document.character3d import Character3D
from qtanimator.document.commands import SetParameter
from qtanimator.document.placement import placement_of, set_placement_command
from qtanimator.document.pose import PosePreview, autokey
from qtanimator.render.gl.lights import LIGHT_NAMES, lights_of
from qtanimator.ui.rig_interaction import placement_scale
from qtanimator.ui.view3d_cloth import LiveClothDriving
from qtanimator.ui.view3d_picking import Picking

#: Drag modes whose gesture Escape aborts.
EDIT_DRAGS = ("ik", "light", "place")


def ik_dofs(skeleton: Any, joint: int, chain_length: int, surface: bool = False) -> list[tuple[int, int]]:
    """The DOFs a right-drag on ``joint`` solves over: its ``chain_length`` nearest
    ancestors without the root; when those have no free DOF (a joint whose only ancestor
    is the root, like the demo arm's elbow) the root's rotation is used, so the drag moves
    something instead of nothing. A drag on a point of the skin (``surface``: the effector
    is off the joint's pivot) moves ``chain_length`` joints counting the joint itself,
    whose own rotation now moves the point (the root's only when the root is clicked)."""
    if surface:
        own = [(joint, a) for a, d in enumerate(skeleton.joints[joint].dofs) if d.max - d.min > 1e-12]
        if skeleton.joints[joint].parent is None:
            return own
        return own + chain_dofs(skeleton, joint, max(chain_length - 1, 0))
    dofs = chain_dofs(skeleton, joint, chain_length)
    return dofs or chain_dofs(skeleton, joint, chain_length, include_root=True)


class ViewDrags(Picking, LiveClothDriving):
    """Mouse events of the 3D view and the drags they start (``self._drag``)."""

    _press_pos: QPointF
    _grab: tuple[str, Any, np.ndarray]

    # -------------------------------------------------------------- mouse
    def mousePressEvent(self, event: QMouseEvent) -> None:
        pos = event.position()
        self._press_pos = QPointF(pos)
        self._end_gesture()   # a second button during a drag: the first drag ends here
        button, mods = event.button(), event.modifiers()
        mode = "orbit"
        extra: dict[str, Any] = {}
        place = (self._start_place(pos, scale=bool(mods & Qt.KeyboardModifier.ShiftModifier))
                 if button == Qt.MouseButton.LeftButton and mods & Qt.KeyboardModifier.AltModifier else None)
        if place is not None:
            mode, extra = "place", place
        elif button == Qt.MouseButton.MiddleButton or (
                button == Qt.MouseButton.LeftButton and mods & Qt.KeyboardModifier.ShiftModifier):
            mode = "pan"
        elif button == Qt.MouseButton.LeftButton and mods & Qt.KeyboardModifier.ControlModifier:
            mode = "zoom"
        elif button == Qt.MouseButton.LeftButton and not (mods & Qt.KeyboardModifier.AltModifier):
            light = self.pick_light(pos)
            if light is not None:
                mode = "light"
                extra = {"light": light, "gesture": self.ctx.begin_gesture(f"Move {light}")}
            elif self._start_grab(pos):
                mode = "grab"
            else:
                mode = "click-orbit"
        elif button == Qt.MouseButton.RightButton:
            ik = self._start_ik(pos)
            mode = "ik" if ik is not None else "zoom"
            extra = ik or {}
        self._drag = {"mode": mode, "last": QPointF(pos), "moved": False, **extra}
        event.accept()

    def _end_gesture(self) -> None:
        """Commit the gesture of a drag in progress (one undo step) and forget the drag."""
        drag, self._drag = self._drag, None
        gesture = drag.get("gesture") if drag else None
        if gesture is not None:
            gesture.commit()

    def abort_drag(self) -> bool:
        """Escape: cancel an IK, light or placement drag (the document goes back exactly;
        nothing to undo). False when no such drag is in progress."""
        if self._drag is None or self._drag.get("mode") not in EDIT_DRAGS:
            return False
        self._drag["gesture"].abort()
        self._drag = None
        self.update()
        return True

    def mouseMoveEvent(self, event: QMouseEvent) -> None:
        if self._drag is None:
            return
        pos = event.position()
        last: QPointF = self._drag["last"]
        dx, dy = pos.x() - last.x(), pos.y() - last.y()
        if (pos - self._press_pos).manhattanLength() > 3:
            self._drag["moved"] = True
        self._drag["last"] = QPointF(pos)
        mode = self._drag["mode"]
        if mode in ("orbit", "click-orbit"):
            if self._drag["moved"]:
                self.navigate("orbit", dx, dy)
        elif mode in ("pan", "zoom"):
            self.navigate(mode, dx, dy)
        elif mode == "grab":
            self._drag_grab(pos)
        elif mode == "light":
            self._drag_light(pos)
        elif mode == "place":
            self._drag_place(pos)
        elif mode == "ik":
            self._drag_ik(pos)
        self._camera_moved()
        self.update()

    def mouseReleaseEvent(self, event: QMouseEvent) -> None:
        drag = self._drag
        self._end_gesture()
        if drag is None:
            return
        if drag["mode"] == "click-orbit" and not drag["moved"]:
            hit = self.pick(event.position())
            if hit is None:
                self.ctx.select("", "")
            else:
                self.ctx.select(hit[0], self._joint_key(hit[0], hit[1]))
        elif drag["mode"] == "grab":
            self.live.release()
        self.update()

    def wheelEvent(self, event: QWheelEvent) -> None:
        self.zoom_steps(event.angleDelta().y() / 120.0)

    # ---------------------------------------------------------- light drag
    def _drag_light(self, pos: QPointF) -> None:
        """Move the dragged light in the plane through it facing the camera (one undo step)."""
        assert self._drag is not None
        name, gesture = self._drag["light"], self._drag["gesture"]
        anchor = next(l.position for n, l in zip(LIGHT_NAMES, lights_of(self.ctx.doc)) if n == name)
        target = self._on_view_plane(pos, anchor)
        if target is None or not gesture.active:
            return
        value = [round(float(v), 4) for v in target]
        gesture.update(SetParameter(self.ctx.doc, f"{name}.position", value, text=f"Move {name}"))

    # ------------------------------------------------------ placement drag
    def _start_place(self, pos: QPointF, scale: bool) -> dict[str, Any] | None:
        """Begin an Alt+left (move) or Alt+Shift+left (``scale``) drag of the placement of the
        3D character under the cursor (its skin, else a joint); None: nothing picked."""
        surface = self.pick_surface(pos)
        if surface is not None:
            asset_id = surface.asset_id
        else:
            hit = self.pick(pos)
            if hit is None:
                return None
            asset_id = hit[0]
        asset = self.ctx.doc.assets.get(asset_id)
        if asset is None or asset.kind != character3d.ASSET_KIND:
            return None
        self.ctx.select(asset_id, "")
        root = self._pose(asset_id).world_matrices()[0, :3, 3].copy()
        press = self._on_view_plane(pos, root)
        if press is None:
            return None
        verb = "Scale" if scale else "Place"
        return {"asset": asset_id, "scale": scale, "anchor": np.asarray(root, dtype=float), "press": press,
                "start": placement_of(self.ctx.doc, asset_id, 3), "press_x": float(pos.x()),
                "gesture": self.ctx.begin_gesture(f"{verb} {asset_id}")}

    def _drag_place(self, pos: QPointF) -> None:
        """Move the placement with the cursor in the view plane through the character's root
        (at the press), or scale it uniformly by the horizontal motion (×2 per 100 px to the
        right) keeping the root where it is; one undo step."""
        assert self._drag is not None
        drag = self._drag
        start, gesture = drag["start"], drag["gesture"]
        if not gesture.active:
            return
        t0 = np.asarray(start["translate"], dtype=float)
        if drag["scale"]:
            s = placement_scale(start["scale"], float(pos.x()) - drag["press_x"])
            # A = T(t)·R·S(s) scales about its origin: move t so the root stays put.
            root = drag["anchor"]
            t = root - (s / start["scale"]) * (root - t0)
            value = {**start, "translate": [float(v) for v in t], "scale": s}
            text = f"Scale {drag['asset']}"
        else:
            target = self._on_view_plane(pos, drag["anchor"])
            if target is None:
                return
            value = {**start, "translate": [float(v) for v in t0 + (target - drag["press"])]}
            text = f"Place {drag['asset']}"
        gesture.update(set_placement_command(self.ctx.doc, drag["asset"], value, text=text))

    # ---------------------------------------------------------- cloth grab
    def _start_grab(self, pos: QPointF) -> bool:
        if not self.live.enabled:
            return False
        origin, direction = self.ray_at(pos)
        hit = self.live.grab(origin, direction,
                             max_distance=lambda p: 2.5 * max(p.width, p.height) / max(p.cols, p.rows))
        if hit is None:
            return False
        asset_id, point = hit
        self._grab = (asset_id, point, self.camera.eye())
        return True

    def _drag_grab(self, pos: QPointF) -> None:
        asset_id, anchor, _eye = self._grab
        target = self._on_view_plane(pos, anchor)
        if target is not None:
            self.live.drag_grabbed(asset_id, target)

    # ------------------------------------------------------------------ IK
    def _start_ik(self, pos: QPointF) -> dict[str, Any] | None:
        """Begin a right-drag IK gesture (None: nothing to drag). On a shown skin the point
        under the cursor is dragged: the effector is that point in the frame of the joint
        influencing it most. Elsewhere (skin hidden or missed) a joint's sphere, bone or box
        is picked and its pivot dragged."""
        surface = self.pick_surface(pos)
        offset = None
        if surface is not None:
            asset_id, joint, offset, anchor = surface.asset_id, surface.joint, surface.offset, surface.point
        else:
            hit = self.pick(pos)
            if hit is None:
                return None
            asset_id, joint, _t = hit
        runtime = self.ctx.doc.runtime.get(asset_id)
        skel = runtime.skeleton if isinstance(runtime, Character3D) else None
        if skel is None or not ik_dofs(skel, joint, self.ik_chain_length, surface=offset is not None):
            return None   # nothing can move this joint (the root): right-drag zooms
        key = self._joint_key(asset_id, joint)
        self.ctx.select(asset_id, key)
        if offset is None:
            anchor = self._pose(asset_id).world_matrices()[joint, :3, 3].copy()
        return {"asset": asset_id, "joint": joint, "anchor": np.asarray(anchor, dtype=float).copy(),
                "offset": offset, "autokey": autokey(self.ctx.doc),
                "gesture": self.ctx.begin_gesture(f"IK drag {key}")}

    def _pose(self, asset_id: str) -> Any:
        return character3d.pose_skeleton(self.ctx.doc, asset_id, self.ctx.time)

    def _drag_ik(self, pos: QPointF) -> None:
        """One IK step towards the cursor: keyed at the current frame (auto-key on) or only
        shown as the unkeyed pose (auto-key off; ``document.pose``)."""
        assert self._drag is not None
        target = self._on_view_plane(pos, self._drag["anchor"])
        if target is None:
            return
        asset_id, joint = self._drag["asset"], self._drag["joint"]
        doc, time = self.ctx.doc, self.ctx.time
        skel = character3d.character(doc, asset_id).skeleton  # the chain: structure only
        offset = self._drag.get("offset")
        values = character3d.ik_values(doc, asset_id, joint, target, time,
                                       ik_dofs(skel, joint, self.ik_chain_length, surface=offset is not None), offset)
        if not values:
            return
        gesture = self._drag["gesture"]
        if not gesture.active:
            return
        if self._drag.get("autokey", True):
            gesture.update(character3d.set_dofs_command(doc, asset_id, values, time))
        else:
            gesture.update(PosePreview(doc, character3d.dof_values(doc, asset_id, values, time), time, "IK drag"))


__all__ = ["EDIT_DRAGS", "ViewDrags", "ik_dofs"]
