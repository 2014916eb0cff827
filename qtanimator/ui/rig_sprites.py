"""How the 2D rig editor draws a character: one scene item per character, drawn as vectors
by the shared renderer (:mod:`qtanimator.render.painter2d`) or, while playing, as cached
per-joint images (:class:`JointSprites`)."""

from __future__ import annotations

import math
from typing import Any, Protocol

from PySide6.QtCore import QRectF
from PySide6.QtGui import QImage, QPainter
from PySide6.QtWidgets import QGraphicsItem, QStyleOptionGraphicsItem, QWidget

from qtanimator.render import painter2d
from qtanimator.ui.context import EditorContext

SCENE_LIMIT = 1.0e5


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



class CharacterView(Protocol):
    """What a :class:`CharacterItem` asks of the view that shows it (the rig editor's)."""

    ctx: EditorContext
    hover: tuple[str, int] | None
    sprites: JointSprites

    def poses(self) -> dict[str, Any]: ...

    def selected_joint_index(self, asset: str) -> int | None: ...

    def use_sprites(self) -> bool: ...


class CharacterItem(QGraphicsItem):
    """One 2D character, drawn with the shared renderer in scene (SVG) units."""

    def __init__(self, editor: CharacterView, asset: str) -> None:
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

