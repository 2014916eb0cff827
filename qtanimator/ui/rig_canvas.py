"""What the 2D rig editor shows: the base of its view (:class:`RigCanvas`).

The scene holds one :class:`~qtanimator.ui.rig_sprites.CharacterItem` per 2D character,
posed at the current frame (the poses are computed once per change; pendulums show the
latest state the background worker simulated). Behind them: onion-skin ghosts of earlier /
later frames; in front: the "unkeyed pose" note, rig mode's bones and pivots, the selected
joint's limit wedge and, with the debug overlays on (``d``), the characters' paths with
velocity / acceleration arrows, the IK source / target with gradient arrows, and the HUD.

The view onto the scene (fit, frame one character, pan) is here too; what the mouse and the
keys do is :class:`qtanimator.ui.rig_view.RigEditorView`, a subclass.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from PySide6.QtCore import QPointF, QRect, QRectF, Qt
from PySide6.QtGui import QBrush, QColor, QFont, QFontMetricsF, QPainter, QPainterPath, QPen, QPolygonF
from PySide6.QtWidgets import QGraphicsScene, QGraphicsView, QWidget

from qtanimator.document import character2d
from qtanimator.document import pose as pose_doc
from qtanimator.document.document import DocumentChange
from qtanimator.render import painter2d
from qtanimator.ui import rig_interaction as ri
from qtanimator.ui.context import EditorContext
from qtanimator.ui.rig_sprites import SCENE_LIMIT, CharacterItem, JointSprites

#: The reference program's window colour (0.6, 0.6, 0.9).
BACKGROUND = QColor(153, 153, 230)
#: The selected joint's limit wedge: radius on screen and colour (RGB).
LIMIT_WEDGE_RADIUS_PX = 48.0
LIMIT_WEDGE_COLOR = (255, 140, 0)


class RigCanvas(QGraphicsView):
    """The scene of 2D characters at the current frame, the view onto it and its overlays."""

    def __init__(self, ctx: EditorContext, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("rigEditorView")
        self.ctx = ctx
        self._scene = QGraphicsScene(self)
        self._scene.setObjectName("rigEditorScene")
        self._scene.setSceneRect(-SCENE_LIMIT, -SCENE_LIMIT, 2 * SCENE_LIMIT, 2 * SCENE_LIMIT)
        self._scene.setItemIndexMethod(QGraphicsScene.ItemIndexMethod.NoIndex)
        self.setScene(self._scene)
        self.setRenderHint(QPainter.RenderHint.Antialiasing, True)
        self.setViewportUpdateMode(QGraphicsView.ViewportUpdateMode.FullViewportUpdate)
        self.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self.setVerticalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self.setTransformationAnchor(QGraphicsView.ViewportAnchor.NoAnchor)
        self.setResizeAnchor(QGraphicsView.ViewportAnchor.AnchorViewCenter)
        self.setMouseTracking(True)
        self.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        self.setBackgroundBrush(QBrush(BACKGROUND))
        self.items_by_asset: dict[str, CharacterItem] = {}
        self.hover: tuple[str, int] | None = None
        self.debug = False
        self.onion = ri.OnionSettings()
        #: Rig mode (setup pose, pivots, rig edits) instead of animating.
        self.rig_mode = False
        self.frames_drawn = 0
        self.playing = False
        #: "playing" (sprites while playing), "always" or "never".
        self.sprite_mode = "playing"
        self.sprites = JointSprites()
        #: The IK drag's grabbed point (asset, joint, rest-pose source point) and its target,
        #: drawn by the debug overlays; set by the IK drag (RigEditorView).
        self._ik: tuple[str, int, np.ndarray] | None = None
        self._ik_target: np.ndarray | None = None
        self._poses: dict[str, Any] | None = None
        self._revision = 0
        self._path_cache: dict[tuple[str, int, int, int], np.ndarray] = {}
        self._fitted = False
        self._auto_fit = False
        ctx.frameChanged.connect(self._on_frame)
        ctx.documentChanged.connect(self._on_document)
        ctx.documentReset.connect(self._on_reset)
        ctx.selectionChanged.connect(lambda _a, _j: self.viewport().update())
        ctx.playingChanged.connect(self._on_playing)
        # Pendulum frames come from a background worker: poses() reads the latest state and
        # the view repaints when new frames arrive for a frame it shows (drawBackground).
        self._poses_exact = True
        self._simulation_pending = False
        ctx.simulationProgressed.connect(lambda: self.viewport().update() if self._simulation_pending else None)
        self._sync_items()

    def _on_playing(self, playing: bool) -> None:
        self.playing = playing
        if not playing:
            self.viewport().update()  # the still frame is drawn as vectors again

    def use_sprites(self) -> bool:
        return self.sprite_mode == "always" or (self.sprite_mode == "playing" and self.playing)

    # ------------------------------------------------------------------ state
    def character_ids(self) -> list[str]:
        try:
            return ri.character_ids(self.ctx.doc)
        except ModuleNotFoundError:
            return []

    def poses(self) -> dict[str, Any]:
        """The posed characters at the current frame (computed once per change). Pendulums
        show the latest simulated state and are never simulated here: until the background
        worker reaches the frame, the poses are read again at each repaint."""
        if self._poses is None:
            doc, t = self.ctx.doc, self.ctx.time
            self._poses_exact = character2d.simulation_ready(doc, t)  # checked first: the worker only adds
            if self.rig_mode:
                self._poses = ri.rig_poses(doc, t)
            else:
                self._poses = {aid: character2d.evaluate_pose(doc, aid, t, block=False) for aid in self.character_ids()}
        return self._poses

    def selected_joint_index(self, asset: str) -> int | None:
        sel_asset, joint = self.ctx.selection
        if sel_asset != asset:
            return None
        character = self.ctx.doc.runtime.get(asset)
        asset_obj = self.ctx.doc.assets.get(asset)
        if character is None or asset_obj is None or asset_obj.kind != character2d.ASSET_KIND:
            return None  # this editor draws 2D characters only (a 3D joint may be selected)
        if joint == "":
            return 0
        try:
            return int(character.joint_index(joint))
        except KeyError:
            return None

    def _invalidate(self) -> None:
        self._poses = None
        self._revision += 1
        self.viewport().update()

    def _on_frame(self, _frame: float) -> None:
        self._poses = None
        self.viewport().update()

    def _on_document(self, change: DocumentChange) -> None:
        if change.assets:
            self.sprites.clear()
            self._sync_items()
            if self.hover is not None and self.hover[0] not in self.ctx.doc.assets:
                self.hover = None
            if not self._fitted:
                self.fit_view()
        self._invalidate()

    def _on_reset(self) -> None:
        self.sprites.clear()
        self._reset_drag()  # the context discarded the gesture with the old document
        self.hover = None
        self._path_cache.clear()
        self._sync_items()
        self._fitted = False
        self.fit_view()
        self._invalidate()

    def _sync_items(self) -> None:
        ids = self.character_ids()
        for aid in list(self.items_by_asset):
            if aid not in ids:
                self._scene.removeItem(self.items_by_asset.pop(aid))
        for z, aid in enumerate(ids):
            item = self.items_by_asset.get(aid)
            if item is None:
                item = CharacterItem(self, aid)
                self.items_by_asset[aid] = item
                self._scene.addItem(item)
            item.setZValue(z)
        self._poses = None

    # ------------------------------------------------------------------- view
    def scene_bounds(self) -> QRectF:
        if not self.character_ids():
            return QRectF()
        return painter2d.scene_bounds(self.ctx.doc, self.ctx.time)

    def fit_view(self) -> None:
        rect = self.scene_bounds()
        if rect.isEmpty():
            return
        margin = 0.05 * max(rect.width(), rect.height())
        self.fitInView(rect.adjusted(-margin, -margin, margin, margin), Qt.AspectRatioMode.KeepAspectRatio)
        self._fitted = True
        self._auto_fit = True  # follow window resizes until the user zooms or pans
        self.viewport().update()

    def frame_asset(self, asset: str) -> bool:
        """Fit the view to one character as posed now (the outliner's Frame in View)."""
        pose = self.poses().get(asset)
        if pose is None:
            return False
        x0, y0, x1, y1 = self.ctx.doc.runtime[asset].bounds(pose)
        rect = QRectF(x0, y0, max(x1 - x0, 1e-6), max(y1 - y0, 1e-6))
        margin = 0.05 * max(rect.width(), rect.height())
        self.fitInView(rect.adjusted(-margin, -margin, margin, margin), Qt.AspectRatioMode.KeepAspectRatio)
        self._auto_fit = False  # the user chose this view: keep it on resize
        self.viewport().update()
        return True

    def to_scene(self, pos: QPointF) -> np.ndarray:
        inverse, _ok = self.viewportTransform().inverted()
        p = inverse.map(QPointF(pos))
        return np.array([p.x(), p.y()])

    def from_scene(self, xy: Any) -> QPointF:
        return self.viewportTransform().map(QPointF(float(xy[0]), float(xy[1])))

    def resizeEvent(self, event: Any) -> None:
        super().resizeEvent(event)
        if self._auto_fit:
            self.fit_view()

    def _pan_by(self, delta: QPointF) -> None:
        h, v = self.horizontalScrollBar(), self.verticalScrollBar()
        h.setValue(h.value() + int(round(delta.x())))
        v.setValue(v.value() + int(round(delta.y())))

    def _pixel_size(self) -> float:
        return 1.0 / max(abs(self.viewportTransform().m11()), 1e-12)

    def _reset_drag(self) -> None:
        """Forget the drag in progress (the document it worked on is gone): the IK overlay's
        state here; the interaction's too in :class:`~qtanimator.ui.rig_view.RigEditorView`."""
        self._ik = None
        self._ik_target = None

    # ---------------------------------------------------------------- drawing
    def set_debug(self, on: bool) -> None:
        self.debug = on
        action = getattr(self, "debug_action", None)
        if action is not None and action.isChecked() != on:
            action.setChecked(on)
        self.viewport().update()

    def drawBackground(self, painter: QPainter, rect: QRectF | QRect) -> None:
        painter.fillRect(rect, BACKGROUND)
        doc = self.ctx.doc
        ghosts = ri.onion_frames(self.ctx.frame, self.onion, *doc.frame_range)
        ids = self.character_ids()
        if not ids:
            self._simulation_pending = False
            return
        if not self._poses_exact:
            self._poses = None  # read before the worker caught up: read the latest again
        times = [self.ctx.time] + [doc.frame_to_time(frame) for frame, _side, _opacity in ghosts]
        self._simulation_pending = not character2d.simulation_ready(doc, times)
        if self._simulation_pending:
            self.ctx.watch_simulation()
        for frame, side, opacity in ghosts:
            r, g, b = self.onion.before_tint if side == "before" else self.onion.after_tint
            tint = QColor(r, g, b, 170)
            t = doc.frame_to_time(frame)
            for aid in ids:
                painter2d.draw_character(painter, doc.runtime[aid], character2d.evaluate_pose(doc, aid, t, block=False),
                                         tint=tint, opacity=opacity)

    def drawForeground(self, painter: QPainter, rect: QRectF | QRect) -> None:
        self.frames_drawn += 1
        if pose_doc.has_pending(self.ctx.doc, self.ctx.time):
            self._draw_unkeyed_note(painter)
        if self.rig_mode:
            self._draw_rig(painter)
        self._draw_limits(painter)
        if not self.debug:
            return
        ids = self.character_ids()
        if not ids:
            return
        self._draw_paths(painter, ids)
        self._draw_ik(painter)
        self._draw_hud(painter)

    def _draw_limits(self, painter: QPainter) -> None:
        """The selected joint's allowed range as a wedge about its pivot (from its direction
        at the lower limit to the upper, turning with the parent); only when it has limits."""
        asset = self.ctx.selection[0]
        if not asset or asset not in self.ctx.doc.runtime:
            return
        joint = self.selected_joint_index(asset)
        pose = self.poses().get(asset)
        if joint is None or pose is None:
            return
        limit = character2d.joint_limits(self.ctx.doc, asset)[joint]
        if limit is None:
            return
        outline = ri.limit_wedge(self.ctx.doc.runtime[asset], pose, joint, limit,
                                 LIMIT_WEDGE_RADIUS_PX * self._pixel_size())
        path = QPainterPath()
        path.addPolygon(QPolygonF([QPointF(float(x), float(y)) for x, y in outline]))
        painter.save()
        painter.setBrush(QColor(*LIMIT_WEDGE_COLOR, 50))
        painter.setPen(self._cosmetic(QColor(*LIMIT_WEDGE_COLOR), 2.5))
        painter.drawPath(path)
        painter.restore()

    def _draw_unkeyed_note(self, painter: QPainter) -> None:
        """Auto-key off: say that the pose shown is not keyed yet."""
        painter.save()
        painter.resetTransform()
        text = "Unkeyed pose: S keys the joint, Shift+S the character; another frame discards it"
        fm = QFontMetricsF(painter.font())
        box = QRectF(8, self.viewport().height() - fm.height() - 14, fm.horizontalAdvance(text) + 16,
                     fm.height() + 8)
        painter.setOpacity(0.85)
        painter.fillRect(box, QColor(160, 20, 20))
        painter.setOpacity(1.0)
        painter.setPen(QColor(255, 255, 255))
        painter.drawText(box, Qt.AlignmentFlag.AlignCenter, text)
        painter.restore()

    def _cosmetic(self, color: QColor, width: float) -> QPen:
        pen = QPen(color, width)
        pen.setCosmetic(True)
        pen.setCapStyle(Qt.PenCapStyle.RoundCap)
        return pen

    def _arrow(self, painter: QPainter, start: Any, vec: Any, color: QColor) -> None:
        a = QPointF(float(start[0]), float(start[1]))
        b = QPointF(float(start[0] + vec[0]), float(start[1] + vec[1]))
        painter.setPen(self._cosmetic(color, 2.0))
        painter.drawLine(a, b)
        length = math.hypot(float(vec[0]), float(vec[1]))
        if length < 1e-9:
            return
        scale = 1.0 / max(self.transform().m11(), 1e-9)
        head = 8.0 * scale
        ux, uy = vec[0] / length, vec[1] / length
        left = QPointF(b.x() - head * (ux + 0.5 * uy), b.y() - head * (uy - 0.5 * ux))
        right = QPointF(b.x() - head * (ux - 0.5 * uy), b.y() - head * (uy + 0.5 * ux))
        painter.setBrush(color)
        painter.drawPolygon(QPolygonF([b, left, right]))

    def _dot(self, painter: QPainter, xy: Any, diameter_px: float, color: QColor) -> None:
        r = diameter_px / 2.0 / max(self.transform().m11(), 1e-9)
        painter.setPen(Qt.PenStyle.NoPen)
        painter.setBrush(color)
        painter.drawEllipse(QPointF(float(xy[0]), float(xy[1])), r, r)

    def _draw_paths(self, painter: QPainter, ids: list[str]) -> None:
        doc = self.ctx.doc
        first, last = doc.frame_range
        selected = self.ctx.selection[0]
        fps = doc.fps
        for aid in ids:
            key = (aid, self._revision, first, last)
            pts = self._path_cache.get(key)
            if pts is None:
                pts = ri.character_path(doc, aid, np.arange(first, last + 1, dtype=np.float64))
                self._path_cache = {k: v for k, v in self._path_cache.items() if k[1] == self._revision}
                self._path_cache[key] = pts
            path = QPainterPath()
            path.addPolygon(QPolygonF([QPointF(float(x), float(y)) for x, y in pts]))
            painter.setOpacity(1.0 if aid == selected else 0.2)
            painter.setPen(self._cosmetic(QColor(255, 255, 255), 3.0))
            painter.setBrush(Qt.BrushStyle.NoBrush)
            painter.drawPath(path)
            painter.setOpacity(1.0)
            if aid != selected:
                continue
            current = ri.character_path(doc, aid, [self.ctx.frame])[0]
            self._dot(painter, current, 15.0, QColor(0, 0, 0))
            for k in ri.path_keys(doc, aid):
                self._dot(painter, k.position, 10.0, QColor(255, 255, 255))
                # The reference draws 5 × the per-frame derivatives.
                self._arrow(painter, k.position, 5.0 * k.velocity / fps, QColor(0, 0, 255))
                self._arrow(painter, k.position, 5.0 * k.acceleration / (fps * fps), QColor(255, 0, 0))

    def _draw_ik(self, painter: QPainter) -> None:
        if self._ik is None or self._ik_target is None:
            return
        asset, joint, local = self._ik
        doc = self.ctx.doc
        character = doc.runtime.get(asset)
        pose = self.poses().get(asset)
        if character is None or pose is None:
            return
        from qtanimator.core.ik import handout_gradient

        gradient = handout_gradient(character, pose, joint, local, self._ik_target)
        scale = float(character2d.ik_setting(doc, "ik.gradient_arrow_scale"))
        for start, end in ri.gradient_arrows(character, pose, gradient, scale):
            self._arrow(painter, start, end - start, QColor(255, 220, 0))
        self._dot(painter, pose.to_world(joint, local), 12.0, QColor(255, 0, 0))
        self._dot(painter, self._ik_target, 25.0, QColor(0, 0, 255, 200))

    def hud_text(self) -> list[str]:
        asset, _joint = self.ctx.selection
        if not asset or asset not in self.ctx.doc.runtime:
            return []
        return ri.hud_lines(self.ctx.doc, asset, self.selected_joint_index(asset), self.ctx.time)

    def _draw_hud(self, painter: QPainter) -> None:
        lines = self.hud_text()
        if not lines:
            return
        painter.save()
        painter.resetTransform()
        font = QFont("monospace")
        font.setStyleHint(QFont.StyleHint.TypeWriter)
        font.setPointSizeF(9.0)
        painter.setFont(font)
        fm = QFontMetricsF(font)
        width = max(fm.horizontalAdvance(s) for s in lines) + 16
        height = fm.lineSpacing() * len(lines) + 12
        box = QRectF(self.viewport().width() - width - 10, 10, width, height)
        painter.setOpacity(0.8)
        painter.fillRect(box, QColor(0, 0, 0))
        painter.setOpacity(1.0)
        painter.setPen(QColor(255, 255, 255))
        y = box.top() + 6 + fm.ascent()
        for s in lines:
            painter.drawText(QPointF(box.left() + 8, y), s)
            y += fm.lineSpacing()
        painter.restore()

    def _draw_rig(self, painter: QPainter) -> None:
        """Rig mode: bones from each pivot to its children's, and the pivot markers
        (white: dynamic; blue: spring; the selected joint's ringed)."""
        poses = self.poses()
        radius = 5.0 * self._pixel_size()
        for aid in self.character_ids():
            character = self.ctx.doc.runtime[aid]
            pose = poses.get(aid)
            if pose is None:
                continue
            selected = self.selected_joint_index(aid)
            painter.setPen(self._cosmetic(QColor(40, 40, 40, 200), 1.5))
            for k, j in enumerate(character.joints):
                if j.parent is not None:
                    a, b = pose.pivots[j.parent], pose.pivots[k]
                    painter.drawLine(QPointF(a[0], a[1]), QPointF(b[0], b[1]))
            for k, j in enumerate(character.joints):
                c = pose.pivots[k]
                ring = QColor(255, 200, 0) if k == selected else QColor(20, 20, 20)
                painter.setPen(self._cosmetic(ring, 3.0 if k == selected else 1.5))
                painter.setBrush(QBrush(QColor(255, 255, 255) if j.is_dynamic else
                                        QColor(60, 170, 255) if j.is_spring else QColor(220, 40, 40)))
                painter.drawEllipse(QPointF(c[0], c[1]), radius, radius)
            painter.setBrush(Qt.BrushStyle.NoBrush)
