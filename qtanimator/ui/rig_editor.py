"""The 2D rig editor: a QGraphicsScene of the document's 2D characters.

Mouse (the reference animator's, plus a view you can move):

* hover highlights the joint under the cursor; a click selects it (``ctx.select``);
* left-drag on a joint rotates it about its pivot, on the root moves the character;
* right-drag pulls the picked point towards the cursor with IK (or, with *IK toggle mode*,
  the reference's toggle: right-press starts following the cursor, the next press stops);
* every drag is one gesture (``ctx.begin_gesture``): each mouse move previews its command
  at once, the release records one undo step, Escape takes the drag back exactly;
* middle-drag pans, the wheel zooms about the cursor, F fits the scene in the view.
* Alt+left-drag on a character moves its placement (issue 14; ``document.placement``),
  Alt+Shift+left-drag scales it about its pivot (×2 per 100 px to the right): one undo step
  each, Escape takes it back.

Auto-key (the timeline's record button, ``document.pose``): on, every drag keys; off, a
drag only poses — the unkeyed pose is shown until the frame changes or it is keyed (the
editor says so in its corner). S or I keys the selected joint (the character selected:
its root and position), Shift+S every joint of the character. Ctrl+C copies the selected
joint's pose (the whole character's when the character — its root — is selected), Ctrl+V
pastes it as keys at the current frame, Ctrl+Shift+V pastes it mirrored (left/right
joints swap; see ``document.pose.mirrored_value``). Each is one undo step.

Keys: Delete / Backspace delete the selected character's keys at the current frame
(Shift+Delete / Shift+Backspace: every character's; in key-all mode always every
character's, as keying is); ``d`` toggles the debug
overlays (the character's path with velocity (blue) and acceleration (red) arrows at its
keys, the IK source (red) / target (blue) dots and gradient arrows, and the HUD).
Onion skin: ghosts of earlier / later frames, with counts, step and tints. The selected
joint's limits (Properties) show as an orange wedge about its pivot that turns with its
parent; a left-drag stops at a limit and follows the cursor back.

Rig mode (the toolbar's *Rig Mode*, ``actionRigMode``; Spine's setup mode) shows each
character in its setup (rest) pose with its pivots and bones: left-drag a pivot marker to
move the pivot (one undo step; Escape takes it back), click a joint to select it, right-click
for *Make Joint From* (the drawing's layers and groups that are not joints yet; the new
joint hangs from the joint clicked), *Mark Dynamic* and *Remove Joint*. Every rig edit is a
command of :mod:`qtanimator.document.rigging`, saved in the project, never in the SVG.

The gesture logic lives in :mod:`qtanimator.ui.rig_interaction` (no Qt).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from PySide6.QtCore import QPointF, QRect, QRectF, Qt
from PySide6.QtGui import (
    QAction,
    QBrush,
    QColor,
    QFont,
    QFontMetricsF,
    QImage,
    QKeyEvent,
    QKeySequence,
    QMouseEvent,
    QPainter,
    QPainterPath,
    QPen,
    QPolygonF,
    QWheelEvent,
)
from PySide6.QtWidgets import (
    QCheckBox,
    QColorDialog,
    QGraphicsItem,
    QGraphicsScene,
    QGraphicsView,
    QLabel,
    QMenu,
    QSpinBox,
    QStyleOptionGraphicsItem,
    QToolBar,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from qtanimator.document import character2d
from qtanimator.document import pose as pose_doc
from qtanimator.document.commands import Command
from qtanimator.document.document import DocumentChange
from qtanimator.document.gesture import Gesture
from qtanimator.render import painter2d
from qtanimator.ui import rig_interaction as ri
from qtanimator.ui.context import EditorContext

if TYPE_CHECKING:
    from qtanimator.ui.main_window import MainWindow

#: The reference program's window colour (0.6, 0.6, 0.9).
BACKGROUND = QColor(153, 153, 230)
SCENE_LIMIT = 1.0e5
ZOOM_PER_DEGREE = 1.0015  # per wheel unit (1/8 degree)
#: The selected joint's limit wedge: radius on screen and colour (RGB).
LIMIT_WEDGE_RADIUS_PX = 48.0
LIMIT_WEDGE_COLOR = (255, 140, 0)


def _xy(point: np.ndarray) -> tuple[float, float]:
    """A scene point (``RigEditorView.to_scene``) as the pair the interaction functions take."""
    return float(point[0]), float(point[1])


class JointSprites:
    """Each joint's shapes rendered once into an image at the view's scale.

    While playing, the editor draws a joint as its image under the joint's world transform
    (a transformed blit) instead of filling and stroking every path again: several times
    faster on big rigs. The images are rebuilt when the zoom changes or when a joint's
    highlight changes; a still frame is always drawn as vectors.
    """

    PAD = 2.0
    MAX_PIXELS = 2048 * 2048

    def __init__(self) -> None:
        self._scale = 0.0
        self._images: dict[tuple[int, int, str], tuple[QImage, QRectF] | None] = {}

    def clear(self) -> None:
        self._images.clear()

    def _build(self, character: Any, index: int, state: str, scale: float) -> tuple[QImage, QRectF] | None:
        from dataclasses import replace

        from qtanimator.core.rig2d import Character

        joint = character.joints[index]
        boxes = [tuple(s.bounds()) for s in joint.shapes]
        if joint.svg:
            # What the SVG draws can reach past the geometry (blur, shadows, markers, wide
            # strokes) or exist without it (text, images): the recorded picture's box too.
            from qtanimator.render.svg_draw import joint_drawing

            drawing = joint_drawing(joint.svg)
            if drawing is not None:
                r = drawing[1].boundingRect()   # whole units: one unit of margin covers it
                if r.isValid():
                    boxes.append((r.left() - 1.0, r.top() - 1.0, r.right() + 2.0, r.bottom() + 2.0))
        if not boxes:
            return None
        x0 = min(b[0] for b in boxes) - self.PAD / scale
        y0 = min(b[1] for b in boxes) - self.PAD / scale
        x1 = max(b[2] for b in boxes) + self.PAD / scale
        y1 = max(b[3] for b in boxes) + self.PAD / scale
        w, h = int(math.ceil((x1 - x0) * scale)), int(math.ceil((y1 - y0) * scale))
        if w <= 0 or h <= 0 or w * h > self.MAX_PIXELS:
            return None
        image = QImage(w, h, QImage.Format.Format_ARGB32_Premultiplied)
        image.fill(0)
        single = Character(joint.name, [replace(joint, parent=None, children=[])])
        painter = QPainter(image)
        painter.scale(scale, scale)
        painter.translate(-x0, -y0)
        painter2d.draw_character(painter, single, single.rest_pose(),
                                 highlight=0 if state == "selected" else None,
                                 hover=0 if state == "hover" else None)
        painter.end()
        return image, QRectF(x0, y0, w / scale, h / scale)

    def draw(self, painter: QPainter, character: Any, pose: Any, highlight: int | None,
             hover: int | None) -> None:
        base = painter.worldTransform()
        scale = math.hypot(base.m11(), base.m12()) * painter.device().devicePixelRatioF()
        if abs(scale - self._scale) > 1e-3 * max(scale, 1e-9):
            self._images.clear()
            self._scale = scale
        painter.save()
        painter.setRenderHint(QPainter.RenderHint.SmoothPixmapTransform, True)
        cid = id(character)
        for i, joint in enumerate(character.joints):
            if not joint.shapes and not joint.svg:
                continue
            state = "selected" if i == highlight else ("hover" if i == hover else "")
            key = (cid, i, state)
            if key not in self._images:
                self._images[key] = self._build(character, i, state, scale)
            sprite = self._images[key]
            painter.setWorldTransform(painter2d.joint_transform(pose, i) * base)
            if sprite is None:
                painter.restore()
                painter2d.draw_character(painter, character, pose, highlight=highlight, hover=hover)
                return
            painter.drawImage(sprite[1], sprite[0])
        painter.restore()


class CharacterItem(QGraphicsItem):
    """One 2D character, drawn with the shared renderer in scene (SVG) units."""

    def __init__(self, editor: RigEditorView, asset: str) -> None:
        super().__init__()
        self.editor = editor
        self.asset = asset
        self.setFlag(QGraphicsItem.GraphicsItemFlag.ItemUsesExtendedStyleOption, False)

    def boundingRect(self) -> QRectF:
        # Poses change every frame; the view repaints fully, so a generous box is cheaper
        # than recomputing bounds of every posed shape.
        return QRectF(-SCENE_LIMIT, -SCENE_LIMIT, 2 * SCENE_LIMIT, 2 * SCENE_LIMIT)

    def paint(self, painter: QPainter, _option: QStyleOptionGraphicsItem, _widget: QWidget | None = None) -> None:
        doc = self.editor.ctx.doc
        character = doc.runtime.get(self.asset)
        pose = self.editor.poses().get(self.asset)
        if character is None or pose is None or doc.assets[self.asset].properties.get("hidden"):
            return  # hidden in the outliner
        highlight = self.editor.selected_joint_index(self.asset)
        hover = self.editor.hover[1] if self.editor.hover and self.editor.hover[0] == self.asset else None
        if self.editor.use_sprites():
            self.editor.sprites.draw(painter, character, pose, highlight, hover)
        else:
            painter2d.draw_character(painter, character, pose, highlight=highlight, hover=hover)


class RigEditorView(QGraphicsView):
    """The view; it owns the interaction state and the overlays."""

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
        self.ik_toggle_mode = False
        #: Rig mode (setup pose, pivots, rig edits) instead of animating.
        self.rig_mode = False
        self.rig_menu: QMenu | None = None
        self.frames_drawn = 0
        self.playing = False
        #: "playing" (sprites while playing), "always" or "never".
        self.sprite_mode = "playing"
        self.sprites = JointSprites()
        # Interaction state.
        self._drag: Any = None
        self._gesture: Gesture | None = None
        self._drag_button: Qt.MouseButton | None = None
        self._ik: tuple[str, int, np.ndarray] | None = None  # asset, joint, rest-pose source point
        self._ik_target: np.ndarray | None = None
        self._ik_following = False
        self._pan_from: QPointF | None = None
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

    def wheelEvent(self, event: QWheelEvent) -> None:
        delta = event.angleDelta().y() or event.angleDelta().x()
        if not delta:
            return
        factor = ZOOM_PER_DEGREE ** delta  # 120 per notch: × 1.2
        anchor = self.to_scene(event.position())
        self._auto_fit = False
        self.scale(factor, factor)
        # Keep the point under the cursor fixed.
        moved = self.from_scene(anchor) - event.position()
        self._pan_by(moved)
        event.accept()

    def resizeEvent(self, event: Any) -> None:
        super().resizeEvent(event)
        if self._auto_fit:
            self.fit_view()

    def _pan_by(self, delta: QPointF) -> None:
        h, v = self.horizontalScrollBar(), self.verticalScrollBar()
        h.setValue(h.value() + int(round(delta.x())))
        v.setValue(v.value() + int(round(delta.y())))

    # ------------------------------------------------------------------ mouse
    def _new_gesture(self, text: str) -> Gesture:
        return self.ctx.begin_gesture(text)

    def mousePressEvent(self, event: QMouseEvent) -> None:
        button = event.button()
        if button == Qt.MouseButton.MiddleButton:
            self._pan_from = event.position()
            self._auto_fit = False
            self.setCursor(Qt.CursorShape.ClosedHandCursor)
            event.accept()
            return
        if self._ik_following and button in (Qt.MouseButton.LeftButton, Qt.MouseButton.RightButton):
            self.finish_drag()  # the toggle's second press (or a left press) ends it
            if button == Qt.MouseButton.RightButton:
                event.accept()
                return
        if self._drag is not None:
            event.accept()
            return
        point = self.to_scene(event.position())
        time = self.ctx.time
        if self.rig_mode:
            self._rig_press(event, point)
            return
        try:
            hit = ri.pick(self.ctx.doc, time, _xy(point))
        except ModuleNotFoundError:
            hit = None
        if hit is not None and button in (Qt.MouseButton.LeftButton, Qt.MouseButton.RightButton):
            # Keys go to the frame under the cursor: stop playback first.
            playback = getattr(self.window(), "playback", None)
            if playback is not None:
                playback.pause()
            time = self.ctx.time
        alt = Qt.KeyboardModifier.AltModifier
        if button == Qt.MouseButton.LeftButton and hit is not None and event.modifiers() & alt:
            # Alt+drag places the character (issue 14), Alt+Shift+drag scales it: one undo step.
            asset = hit[0]
            self.ctx.select(asset, "")
            if event.modifiers() & Qt.KeyboardModifier.ShiftModifier:
                self._gesture = self._new_gesture(f"Scale {asset}")
                self._drag = ri.placement_scale_drag(self.ctx.doc, asset, _xy(point), self._pixel_size())
            else:
                self._gesture = self._new_gesture(f"Place {asset}")
                self._drag = ri.placement_move_drag(self.ctx.doc, asset, _xy(point))
            next(self._drag)
            self._drag_button = button
            event.accept()
            return
        if button == Qt.MouseButton.LeftButton:
            if hit is None:
                self.ctx.select("", "")
                event.accept()
                return
            asset, joint = hit
            character = self.ctx.doc.runtime[asset]
            autokey = pose_doc.autokey(self.ctx.doc)
            if joint == 0:
                self.ctx.select(asset, "")
                self._gesture = self._new_gesture(f"Move {asset}")
                self._drag = ri.move_drag(self.ctx.doc, asset, _xy(point), time, autokey)
            else:
                self.ctx.select(asset, character.joints[joint].name)
                self._gesture = self._new_gesture(f"Rotate {character.joints[joint].name}")
                self._drag = ri.rotate_drag(self.ctx.doc, asset, joint, _xy(point), time, autokey)
            next(self._drag)
            self._drag_button = button
            event.accept()
            return
        if button == Qt.MouseButton.RightButton:
            if hit is None:
                event.accept()
                return
            asset, joint = hit
            character = self.ctx.doc.runtime[asset]
            self.ctx.select(asset, character.joints[joint].name if joint else "")
            self._gesture = self._new_gesture("IK Drag")
            self._drag = ri.ik_drag(self.ctx.doc, asset, joint, _xy(point), time, pose_doc.autokey(self.ctx.doc))
            next(self._drag)
            self._ik = (asset, joint, ri.ik_source(self.ctx.doc, asset, joint, _xy(point), time))
            self._ik_target = point
            self._drag_button = button
            self._ik_following = self.ik_toggle_mode
            event.accept()
            return
        super().mousePressEvent(event)

    # -------------------------------------------------------------- rig mode
    def set_rig_mode(self, on: bool) -> None:
        """Enter or leave rig mode (the setup pose with pivots; see the module docstring)."""
        if self._drag is not None:
            self.abort_drag()
        self.rig_mode = bool(on)
        action = getattr(self, "rig_mode_action", None)
        if action is not None and action.isChecked() != self.rig_mode:
            action.setChecked(self.rig_mode)
        self.hover = None
        self.sprites.clear()
        self._invalidate()

    def _pixel_size(self) -> float:
        return 1.0 / max(abs(self.viewportTransform().m11()), 1e-12)

    def _rig_press(self, event: QMouseEvent, point: np.ndarray) -> None:
        doc, time = self.ctx.doc, self.ctx.time
        button = event.button()
        if button == Qt.MouseButton.LeftButton:
            grab = ri.pivot_at(doc, time, _xy(point), ri.PIVOT_GRAB_PX * self._pixel_size())
            if grab is not None:
                asset, joint = grab
                character = doc.runtime[asset]
                self.ctx.select(asset, character.joints[joint].name if joint else "")
                self._gesture = self._new_gesture(f"Move Pivot of {character.joints[joint].name}")
                self._drag = ri.pivot_drag(doc, asset, joint, _xy(point))
                next(self._drag)
                self._drag_button = button
            else:
                hit = ri.pick_rest(doc, time, _xy(point))
                if hit is None:
                    self.ctx.select("", "")
                else:
                    character = doc.runtime[hit[0]]
                    self.ctx.select(hit[0], character.joints[hit[1]].name if hit[1] else "")
            event.accept()
            return
        if button == Qt.MouseButton.RightButton:
            hit = ri.pick_rest(doc, time, _xy(point))
            if hit is None and self.character_ids():
                hit = (self.ctx.selection[0] or self.character_ids()[-1], 0)
            if hit is not None:
                self.show_rig_menu(hit[0], hit[1], event.position().toPoint())
            event.accept()
            return
        event.accept()

    def show_rig_menu(self, asset: str, joint: int, pos: Any) -> QMenu:
        """The rig-mode context menu of one joint, opened at viewport ``pos``."""
        from qtanimator.document import rigging

        doc = self.ctx.doc
        character = doc.runtime[asset]
        name = character.joints[joint].name
        self.ctx.select(asset, name if joint else "")
        menu = QMenu(self)
        menu.setObjectName("rigMenu")
        make = menu.addMenu("Make Joint From")
        make.setObjectName("rigMakeJointMenu")
        offered = rigging.candidates(doc, asset)
        for label in offered:
            action = make.addAction(label)
            action.triggered.connect(lambda _c=False, lb=label: self._rig_edit(
                lambda: rigging.make_joint_from_candidate(doc, asset, lb, parent=name), select=(asset, lb)))
        make.setEnabled(bool(offered))
        dynamic = menu.addAction("Mark Dynamic")
        dynamic.setObjectName("actionMarkDynamic")
        dynamic.setCheckable(True)
        dynamic.setChecked(bool(character.joints[joint].is_dynamic))
        dynamic.setEnabled(joint != 0)
        dynamic.triggered.connect(lambda on: self._rig_edit(
            lambda: rigging.set_dynamic_command(doc, asset, name, bool(on))))
        spring = menu.addAction("Spring Joint")
        spring.setObjectName("actionMarkSpring")
        spring.setToolTip("the joint follows its keys through a damped spring (secondary motion)")
        spring.setCheckable(True)
        spring.setChecked(bool(character.joints[joint].is_spring))
        spring.triggered.connect(lambda on: self._rig_edit(
            lambda: rigging.set_joint_mode_command(doc, asset, name, "spring" if on else "keyframed")))
        remove = menu.addAction("Remove Joint")
        remove.setObjectName("actionRemoveJoint")
        remove.setEnabled(joint != 0)
        remove.triggered.connect(lambda _c=False: self._rig_edit(
            lambda: rigging.remove_joint_command(doc, asset, name), select=(asset, "")))
        self.rig_menu = menu
        menu.popup(self.viewport().mapToGlobal(pos))
        return menu

    def _rig_edit(self, build: Any, select: tuple[str, str] | None = None) -> bool:
        from qtanimator.document.rigging import RigError
        from qtanimator.formats.errors import FormatError

        try:
            command = build()
        except (RigError, FormatError) as exc:
            self._say(str(exc))
            return False
        self.ctx.push(command)
        if select is not None:
            character = self.ctx.doc.runtime.get(select[0])
            if character is not None and select[1] and select[1] not in [j.name for j in character.joints]:
                select = (select[0], character.joints[-1].name)
            self.ctx.select(*select)
        return True

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

    def mouseMoveEvent(self, event: QMouseEvent) -> None:
        if self._pan_from is not None:
            delta = event.position() - self._pan_from
            self._pan_from = event.position()
            self._pan_by(QPointF(-delta.x(), -delta.y()))
            event.accept()
            return
        point = self.to_scene(event.position())
        if self._drag is not None and (self._ik_following or (self._drag_button is not None
                                                               and event.buttons() & self._drag_button)):
            self.drag_to(point)
            event.accept()
            return
        self._update_hover(point)
        event.accept()

    def drag_to(self, point: np.ndarray) -> None:
        """Feed one cursor position (scene units) to the current drag."""
        if self._drag is None or self._gesture is None:
            return
        if self._ik is not None:
            self._ik_target = np.asarray(point, dtype=np.float64)
        self._gesture.update(self._drag.send(point))
        self._invalidate()  # the preview is drawn now; other views follow once per frame

    def mouseReleaseEvent(self, event: QMouseEvent) -> None:
        if event.button() == Qt.MouseButton.MiddleButton and self._pan_from is not None:
            self._pan_from = None
            self.unsetCursor()
            event.accept()
            return
        if self._drag is not None and event.button() == self._drag_button and not self._ik_following:
            self.finish_drag()
            event.accept()
            return
        super().mouseReleaseEvent(event)

    def finish_drag(self) -> None:
        """End the drag: its folded command goes on the undo stack as one step."""
        gesture = self._gesture
        self._reset_drag()
        if gesture is not None:
            gesture.commit()
        self._invalidate()

    def abort_drag(self) -> None:
        """Escape: take back everything the current drag did."""
        gesture = self._gesture
        self._reset_drag()
        if gesture is not None:
            gesture.abort()
        self._invalidate()

    def _reset_drag(self) -> None:
        if self._drag is not None:
            self._drag.close()
        self._drag = None
        self._gesture = None
        self._drag_button = None
        self._ik = None
        self._ik_target = None
        self._ik_following = False

    @property
    def dragging(self) -> bool:
        return self._drag is not None

    def _update_hover(self, point: np.ndarray) -> None:
        try:
            hit = (ri.pick_rest if self.rig_mode else ri.pick)(self.ctx.doc, self.ctx.time, _xy(point))
        except ModuleNotFoundError:
            hit = None
        if hit != self.hover:
            self.hover = hit
            self.viewport().update()

    def leaveEvent(self, event: Any) -> None:
        if self.hover is not None:
            self.hover = None
            self.viewport().update()
        super().leaveEvent(event)

    # ------------------------------------------------------------------- keys
    def keyPressEvent(self, event: QKeyEvent) -> None:
        key = event.key()
        if key == Qt.Key.Key_Escape and self._drag is not None:
            self.abort_drag()
            event.accept()
            return
        if key in (Qt.Key.Key_Delete, Qt.Key.Key_Backspace):
            self.delete_keys(all_characters=bool(event.modifiers() & Qt.KeyboardModifier.ShiftModifier))
            event.accept()
            return
        if key == Qt.Key.Key_D and not event.modifiers() & ~Qt.KeyboardModifier.KeypadModifier:
            self.set_debug(not self.debug)
            event.accept()
            return
        super().keyPressEvent(event)

    # ------------------------------------------------------ set key, copy, paste
    def _say(self, text: str) -> None:
        window = self.window()
        bar = getattr(window, "statusBar", None)
        if callable(bar):
            bar().showMessage(text, 4000)

    def set_key(self, whole_character: bool = False) -> bool:
        """S / I (``whole_character`` False) or Shift+S: key the shown pose of the
        selected joint or of the whole selected character at the current frame."""
        if self._drag is not None:
            return False
        command = ri.set_key_command(self.ctx.doc, self.ctx.selection, self.ctx.time, whole_character)
        if command is None:
            self._say("Select a joint or a character to key.")
            return False
        self.ctx.push(command)
        return True

    def copy_pose(self) -> bool:
        """Ctrl+C: copy the selected joint's pose (the whole character's when it is selected)."""
        clip = ri.copy_selection(self.ctx.doc, self.ctx.selection, self.ctx.time)
        if clip is None:
            self._say("Select a joint or a character to copy its pose.")
            return False
        ri.pose_clipboard.clip = clip
        self._say(f"Copied the pose of {len(clip.values)} joint{'s' if len(clip.values) != 1 else ''}.")
        return True

    def paste_pose(self, mirrored: bool = False) -> bool:
        """Ctrl+V / Ctrl+Shift+V: key the copied pose (mirrored) at the current frame."""
        if self._drag is not None:
            return False
        command = ri.paste_command(self.ctx.doc, ri.pose_clipboard.clip, self.ctx.selection, self.ctx.time,
                                   mirrored)
        if command is None:
            self._say("Nothing to paste here: copy a pose of a character like this one first.")
            return False
        self.ctx.push(command)
        return True

    def delete_keys(self, all_characters: bool = False) -> bool:
        """Delete / Backspace: remove the selected character's keys at the current frame;
        Shift+Delete (``all_characters``): every 2D character's. In key-all mode every
        character's, as keying is. True when keys were deleted."""
        if self._drag is not None:
            return False
        asset = self.ctx.selection[0]
        if not all_characters and asset not in character2d.character_assets(self.ctx.doc):
            if not bool(self.ctx.doc.parameter(character2d.KEY_ALL_PARAMETER, False)):
                self._say("Select a character to delete its keys at this frame (Shift+Delete: every character's).")
                return False
        command: Command | None = character2d.delete_keys_at(self.ctx.doc, None if all_characters else asset,
                                                             self.ctx.time)
        if command is None:
            return False
        self.ctx.push(command)
        return True

    def set_debug(self, on: bool) -> None:
        self.debug = on
        action = getattr(self, "debug_action", None)
        if action is not None and action.isChecked() != on:
            action.setChecked(on)
        self.viewport().update()

    # ---------------------------------------------------------------- drawing
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


class RigEditor(QWidget):
    """The view with its tool bar (fit, debug, onion skin, IK mode)."""

    def __init__(self, ctx: EditorContext, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("rigEditor")
        self.view = RigEditorView(ctx, self)
        self.toolbar = QToolBar("2D Editor", self)
        self.toolbar.setObjectName("rigEditorToolBar")
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.setSpacing(0)
        layout.addWidget(self.toolbar)
        layout.addWidget(self.view, 1)
        view = self.view

        self.fit_action = QAction("Fit View", self)
        self.fit_action.setObjectName("actionFitView")
        self.fit_action.setShortcut(QKeySequence("F"))
        self.fit_action.setShortcutContext(Qt.ShortcutContext.WidgetWithChildrenShortcut)
        self.fit_action.triggered.connect(lambda _c=False: view.fit_view())
        self.debug_action = QAction("Debug Overlays", self)
        self.debug_action.setObjectName("actionDebugOverlays")
        self.debug_action.setCheckable(True)
        self.debug_action.setToolTip("Paths, velocity / acceleration arrows, IK arrows and the HUD (d)")
        self.debug_action.toggled.connect(view.set_debug)
        view.debug_action = self.debug_action  # type: ignore[attr-defined]
        self.rig_mode_action = QAction("Rig Mode", self)
        self.rig_mode_action.setObjectName("actionRigMode")
        self.rig_mode_action.setCheckable(True)
        self.rig_mode_action.setToolTip("Setup pose: drag pivots; right-click a joint to make joints from "
                                        "layers, mark it dynamic or remove it")
        self.rig_mode_action.toggled.connect(view.set_rig_mode)
        view.rig_mode_action = self.rig_mode_action  # type: ignore[attr-defined]
        self.toolbar.addAction(self.fit_action)
        self.toolbar.addAction(self.debug_action)
        self.toolbar.addAction(self.rig_mode_action)
        self.addAction(self.fit_action)
        self.pose_actions = self._pose_actions()

        self.toolbar.addSeparator()
        self.onion_box = QCheckBox("Onion skin", self)
        self.onion_box.setObjectName("onionSkinCheck")
        self.toolbar.addWidget(self.onion_box)
        self.before_box = self._spin("onionBefore", "earlier", 0, 20, view.onion.before)
        self.after_box = self._spin("onionAfter", "later", 0, 20, view.onion.after)
        self.step_box = self._spin("onionStep", "step", 1, 100, view.onion.step)
        self.before_tint = self._tint_button("onionBeforeTint", "before_tint")
        self.after_tint = self._tint_button("onionAfterTint", "after_tint")
        for w in (self.onion_box,):
            w.toggled.connect(lambda _v: self._onion_changed())
        for box in (self.before_box, self.after_box, self.step_box):
            box.valueChanged.connect(lambda _v: self._onion_changed())

        self.toolbar.addSeparator()
        self.ik_toggle_box = QCheckBox("IK toggle mode", self)
        self.ik_toggle_box.setObjectName("ikToggleModeCheck")
        self.ik_toggle_box.setToolTip("Right-click starts following the cursor, the next click stops "
                                      "(the reference animator's IK)")
        self.ik_toggle_box.toggled.connect(lambda on: setattr(view, "ik_toggle_mode", on))
        self.toolbar.addWidget(self.ik_toggle_box)

    def _pose_actions(self) -> dict[str, QAction]:
        """Set key, key the character, copy / paste / paste mirrored pose: shortcuts of the
        view only (other editors bind Ctrl+C / Ctrl+V to their keys)."""
        view = self.view
        specs = (
            ("actionSetKey", "Set Key", ["S", "I"], lambda: view.set_key(False),
             "Key the selected joint (the character selected: its root and position) at this frame"),
            ("actionSetKeyCharacter", "Set Key on Whole Character", ["Shift+S"], lambda: view.set_key(True),
             "Key every joint of the selected character at this frame"),
            ("actionCopyPose", "Copy Pose", ["Ctrl+C"], view.copy_pose,
             "Copy the selected joint's pose (the whole character's when the character is selected)"),
            ("actionPastePose", "Paste Pose", ["Ctrl+V"], lambda: view.paste_pose(False),
             "Key the copied pose at this frame"),
            ("actionPasteMirrored", "Paste Pose Mirrored", ["Ctrl+Shift+V"], lambda: view.paste_pose(True),
             "Key the copied pose at this frame with left and right swapped"),
        )
        actions: dict[str, QAction] = {}
        for name, text, keys, slot, tip in specs:
            action = QAction(text, self)
            action.setObjectName(name)
            action.setShortcuts([QKeySequence(k) for k in keys])
            action.setShortcutContext(Qt.ShortcutContext.WidgetWithChildrenShortcut)
            action.setToolTip(f"{tip} ({', '.join(keys)})")
            action.triggered.connect(lambda _c=False, fn=slot: fn())
            view.addAction(action)
            actions[name] = action
        return actions

    def _spin(self, name: str, label: str, lo: int, hi: int, value: int) -> QSpinBox:
        self.toolbar.addWidget(QLabel(f" {label} ", self))
        box = QSpinBox(self)
        box.setObjectName(name)
        box.setRange(lo, hi)
        box.setValue(value)
        self.toolbar.addWidget(box)
        return box

    def _tint_button(self, name: str, field: str) -> QToolButton:
        button = QToolButton(self)
        button.setObjectName(name)
        button.setToolTip("Tint of the " + ("earlier" if field == "before_tint" else "later") + " ghosts")

        def paint() -> None:
            r, g, b = getattr(self.view.onion, field)
            button.setStyleSheet(f"background-color: rgb({r},{g},{b}); min-width: 16px;")

        def choose() -> None:
            r, g, b = getattr(self.view.onion, field)
            color = QColorDialog.getColor(QColor(r, g, b), self, "Onion skin tint")
            if color.isValid():
                self._set_onion(**{field: (color.red(), color.green(), color.blue())})
                paint()

        button.clicked.connect(choose)
        paint()
        self.toolbar.addWidget(button)
        return button

    def _set_onion(self, **changes: Any) -> None:
        from dataclasses import replace

        self.view.onion = replace(self.view.onion, **changes)
        self.view.viewport().update()

    def _onion_changed(self) -> None:
        self._set_onion(enabled=self.onion_box.isChecked(), before=self.before_box.value(),
                        after=self.after_box.value(), step=self.step_box.value())


# ---------------------------------------------------------------------- openers
def open_characters(window: MainWindow, path: Path) -> None:
    """Add the characters of an SVG file or folder (FormatError leaves the document as is)."""
    command = character2d.add_characters_command(window.doc, path, new_project_range=True)
    window.ctx.push(command)
    editor = getattr(window, "rig_editor", None)
    if editor is not None:
        editor.view.fit_view()
        window.central_tabs.setCurrentWidget(editor)


def install(window: MainWindow) -> None:
    editor = RigEditor(window.ctx)
    window.rig_editor = editor  # type: ignore[attr-defined]
    window.add_central(editor, "2D Rig")
    window.openers[".svg"] = open_characters
    window.openers["/"] = open_characters
    window.view_menu.addAction(editor.fit_action)
    window.view_menu.addAction(editor.debug_action)
    delete = QAction("Delete Keys at Current Frame", window)
    delete.setObjectName("actionDeleteFrameKeys")
    delete.setToolTip("The selected character's keys at the current frame (Delete / Backspace in the 2D editor)")
    delete.triggered.connect(lambda _c=False: editor.view.delete_keys())
    window.edit_menu.addAction(delete)
    delete_all = QAction("Delete Keys at Current Frame (All Characters)", window)
    delete_all.setObjectName("actionDeleteFrameKeysAll")
    delete_all.setToolTip("Every 2D character's keys at the current frame (Shift+Delete in the 2D editor)")
    delete_all.triggered.connect(lambda _c=False: editor.view.delete_keys(all_characters=True))
    window.edit_menu.addAction(delete_all)
    window.edit_menu.addSeparator()
    for action in editor.pose_actions.values():
        window.edit_menu.addAction(action)
    _restore_editor_settings(editor)


def _restore_editor_settings(editor: RigEditor) -> None:
    """The onion skin's counts and step are user preferences, kept in the program's settings
    (the IK mode is not: a toggle that silently persisted would surprise)."""
    from qtanimator.ui.main_window import settings

    s = settings()

    def stored(key: str, default: int) -> int:
        value = s.value(key, default)
        if not isinstance(value, (int, float, str)):
            raise TypeError(f"{key}: {value!r} is no number")
        return int(value)

    try:
        editor.before_box.setValue(stored("rigEditor/onionBefore", editor.before_box.value()))
        editor.after_box.setValue(stored("rigEditor/onionAfter", editor.after_box.value()))
        editor.step_box.setValue(stored("rigEditor/onionStep", editor.step_box.value()))
    except (TypeError, ValueError):
        pass

    def save() -> None:
        st = settings()
        st.setValue("rigEditor/onionBefore", editor.before_box.value())
        st.setValue("rigEditor/onionAfter", editor.after_box.value())
        st.setValue("rigEditor/onionStep", editor.step_box.value())

    for box in (editor.before_box, editor.after_box, editor.step_box):
        box.valueChanged.connect(lambda _v: save())


__all__ = ["CharacterItem", "RigEditor", "RigEditorView", "install", "open_characters"]
