"""The 2D QPainter renderer shared by the rig editor and export.

Characters draw joint by joint in pre-order (children cover parents), each joint's shapes in
document order; a joint's world matrix becomes the painter's transform, so shapes keep
their rest-pose geometry.

A joint read from SVG carries its own SVG document (``Joint.svg``) and is drawn by QtSvg as
its author drew it (gradients, holes, caps, joins, dashes, group opacity, clip paths, masks,
markers, filters: :mod:`qtanimator.render.svg_draw`); the selection, hover and onion-skin
tints are then laid over the joint's silhouette, taken from its geometry. ``mode="geometry"``
draws the flattened shapes instead (the path of characters built without SVG, and the
drawing of earlier versions): fills, strokes (width, colour, alpha) and element opacity.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np
import numpy.typing as npt
from PySide6.QtCore import QPointF, QRectF, Qt
from PySide6.QtGui import (
    QBrush,
    QColor,
    QImage,
    QPainter,
    QPainterPath,
    QPainterPathStroker,
    QPen,
    QPolygonF,
    QTransform,
)

from qtanimator.core.rig2d import RGBA, Character, Pose, Shape
from qtanimator.document.character2d import character, character_assets, evaluate_pose
from qtanimator.document.document import Document
from qtanimator.document.outliner import is_hidden
from qtanimator.render.svg_draw import draw_joint

HIGHLIGHT_SELECTED = 0.5
HIGHLIGHT_HOVER = 0.35


def shape_path(shape: Shape) -> QPainterPath:
    """A QPainterPath of a shape's outline (rest-pose coordinates)."""
    path = QPainterPath()
    pts = shape.points
    if len(pts) == 0:
        return path
    poly = QPolygonF([QPointF(float(x), float(y)) for x, y in pts])
    path.addPolygon(poly)
    if shape.closed:
        path.closeSubpath()
    return path


def character_paths(ch: Character) -> list[list[QPainterPath]]:
    """QPainterPaths of every joint's shapes, built once per character."""
    paths: list[list[QPainterPath]] | None = ch.derived.get("painter2d.paths")
    if paths is None:
        paths = [[shape_path(s) for s in j.shapes] for j in ch.joints]
        ch.derived["painter2d.paths"] = paths
    return paths


def joint_silhouette(ch: Character, joint: int) -> QPainterPath:
    """The area a joint's geometry covers (fills and stroke bands united), built once."""
    cache: dict[int, QPainterPath] = ch.derived.setdefault("painter2d.silhouettes", {})
    path = cache.get(joint)
    if path is None:
        path = QPainterPath()
        path.setFillRule(Qt.FillRule.WindingFill)
        for shape, outline in zip(ch.joints[joint].shapes, character_paths(ch)[joint]):
            if shape.fill[3] > 0 and len(shape.points) >= 3:
                path = path.united(outline)
            if shape.stroke[3] > 0 and shape.stroke_width > 0:
                stroker = QPainterPathStroker()
                stroker.setWidth(float(shape.stroke_width))
                path = path.united(stroker.createStroke(outline))
        cache[joint] = path
    return path


def joint_transform(pose: Pose, joint: int) -> QTransform:
    """A joint's world matrix as a QTransform (Qt uses row vectors)."""
    m = pose.world[joint]
    return QTransform(float(m[0, 0]), float(m[1, 0]), float(m[0, 1]), float(m[1, 1]),
                      float(m[0, 2]), float(m[1, 2]))


def _qcolor(rgba: RGBA, lift: float = 0.0, wrap: bool = True, tint: QColor | None = None) -> QColor:
    r, g, b, a = rgba
    if lift:
        if wrap:
            r, g, b = ((r + lift) % 1.0 if r + lift != 1.0 else 1.0 for r in (r, g, b))
        else:
            r, g, b = (min(v + lift, 1.0) for v in (r, g, b))
    if tint is not None:
        t = tint.alphaF()
        r = r * (1 - t) + tint.redF() * t
        g = g * (1 - t) + tint.greenF() * t
        b = b * (1 - t) + tint.blueF() * t
    return QColor.fromRgbF(_clamp(r), _clamp(g), _clamp(b), _clamp(a))


def _clamp(v: float) -> float:
    return min(max(float(v), 0.0), 1.0)


def draw_character(painter: QPainter, ch: Character, pose: Pose, *, highlight: int | None = None,
                   tint: QColor | None = None, opacity: float = 1.0, hover: int | None = None,
                   mode: str = "svg") -> None:
    """Draw a posed character with the painter's current transform as the view.

    ``highlight`` lifts the selected joint's colours by 0.5 (geometry: wrapped at 1, as the
    reference program; SVG: the difference with mid grey, the same for colours above 0.5);
    ``hover`` by 0.35 (clamped); ``tint`` mixes every colour towards a colour by its alpha
    (onion skins); ``opacity`` multiplies everything. ``mode`` is ``"svg"`` (joints that
    carry an SVG document are drawn by QtSvg) or ``"geometry"`` (the flattened shapes).
    """
    if mode not in ("svg", "geometry"):
        raise ValueError(f"unknown drawing mode '{mode}' (svg or geometry)")
    paths = character_paths(ch)
    base_opacity = painter.opacity()
    painter.save()
    painter.setRenderHint(QPainter.RenderHint.Antialiasing, True)
    base = painter.worldTransform()
    for i, joint in enumerate(ch.joints):
        if not joint.shapes and not (mode == "svg" and joint.svg):
            continue
        painter.setWorldTransform(joint_transform(pose, i) * base)
        if mode == "svg" and joint.svg:
            painter.setOpacity(base_opacity * opacity)
            if draw_joint(painter, joint.svg):
                _overlay(painter, ch, i, highlight, hover, tint)
                continue
        lift, wrap = 0.0, True
        if highlight == i:
            lift = HIGHLIGHT_SELECTED
        elif hover == i:
            lift, wrap = HIGHLIGHT_HOVER, False
        for shape, path in zip(joint.shapes, paths[i]):
            painter.setOpacity(base_opacity * opacity * shape.opacity)
            if shape.fill[3] > 0 and len(shape.points) >= 3:
                painter.setBrush(QBrush(_qcolor(shape.fill, lift, wrap, tint)))
            else:
                painter.setBrush(Qt.BrushStyle.NoBrush)
            if shape.stroke[3] > 0 and shape.stroke_width > 0:
                pen = QPen(_qcolor(shape.stroke, 0.0, True, tint))
                pen.setWidthF(float(shape.stroke_width))
                pen.setCapStyle(Qt.PenCapStyle.FlatCap)
                pen.setJoinStyle(Qt.PenJoinStyle.MiterJoin)
                pen.setMiterLimit(10.0)
                painter.setPen(pen)
            else:
                painter.setPen(Qt.PenStyle.NoPen)
            painter.drawPath(path)
    painter.restore()


def _overlay(painter: QPainter, ch: Character, i: int, highlight: int | None, hover: int | None,
             tint: QColor | None) -> None:
    """Selection, hover and tint laid over a joint drawn by QtSvg, on its silhouette."""
    if highlight != i and hover != i and tint is None:
        return
    silhouette = joint_silhouette(ch, i)
    if silhouette.isEmpty():
        return
    painter.save()
    if highlight == i:
        painter.setCompositionMode(QPainter.CompositionMode.CompositionMode_Difference)
        painter.fillPath(silhouette, QColor.fromRgbF(HIGHLIGHT_SELECTED, HIGHLIGHT_SELECTED, HIGHLIGHT_SELECTED))
    elif hover == i:
        painter.setCompositionMode(QPainter.CompositionMode.CompositionMode_Plus)
        painter.fillPath(silhouette, QColor.fromRgbF(HIGHLIGHT_HOVER, HIGHLIGHT_HOVER, HIGHLIGHT_HOVER))
    if tint is not None:
        painter.setCompositionMode(QPainter.CompositionMode.CompositionMode_SourceOver)
        painter.fillPath(silhouette, tint)
    painter.restore()


def _poses_bounds(doc: Document, poses: dict[str, Pose]) -> QRectF:
    rect = QRectF()
    for aid, pose in poses.items():
        x0, y0, x1, y1 = character(doc, aid).bounds(pose)
        rect = rect.united(QRectF(x0, y0, max(x1 - x0, 1e-6), max(y1 - y0, 1e-6)))
    return rect


def scene_bounds(doc: Document, time: float) -> QRectF:
    """The bounding box of every 2D character posed at ``time`` (empty rect if none)."""
    return _poses_bounds(doc, {aid: evaluate_pose(doc, aid, time) for aid in visible_characters(doc)})


def visible_characters(doc: Document) -> list[str]:
    """The 2D characters that are drawn (the outliner hides the others)."""
    return [aid for aid in character_assets(doc) if not is_hidden(doc, aid)]


def animation_bounds(doc: Document, times: Iterable[float]) -> QRectF:
    """The union of :func:`scene_bounds` over ``times`` (a steady camera for export)."""
    rect = QRectF()
    for t in times:
        rect = rect.united(scene_bounds(doc, t))
    return rect


def fit_transform(view: QRectF, size: tuple[int, int], margin: float = 0.04) -> QTransform:
    """Scale and centre ``view`` into an image of ``size`` keeping the aspect ratio."""
    w, h = size
    if view.isEmpty() or view.width() <= 0 or view.height() <= 0:
        return QTransform()
    avail_w, avail_h = w * (1 - 2 * margin), h * (1 - 2 * margin)
    s = min(avail_w / view.width(), avail_h / view.height())
    t = QTransform()
    t.translate(w / 2.0, h / 2.0)
    t.scale(s, s)
    t.translate(-view.center().x(), -view.center().y())
    return t


def background_color(background: str | QColor | None) -> QColor:
    if background is None or (isinstance(background, str) and background.lower() in ("none", "transparent")):
        return QColor(0, 0, 0, 0)
    color = QColor(background)
    if not color.isValid():
        raise ValueError(f"'{background}' is not a colour (use a name such as white or #rrggbb)")
    return color


def render_frame(doc: Document, time: float, size: tuple[int, int] = (960, 640),
                 background: str | QColor | None = "white", view: QRectF | None = None,
                 assets: Sequence[str] | None = None) -> QImage:
    """Draw every 2D character at ``time`` into a new ARGB32 image, fitted to the content
    (or to ``view``, in scene units)."""
    w, h = int(size[0]), int(size[1])
    if w <= 0 or h <= 0:
        raise ValueError("the image size must be positive")
    image = QImage(w, h, QImage.Format.Format_ARGB32_Premultiplied)
    image.fill(background_color(background))
    ids = list(assets) if assets is not None else visible_characters(doc)
    poses = {aid: evaluate_pose(doc, aid, time) for aid in ids}
    if view is None:
        view = _poses_bounds(doc, poses)
    painter = QPainter(image)
    try:
        painter.setRenderHint(QPainter.RenderHint.Antialiasing, True)
        painter.setWorldTransform(fit_transform(view, (w, h)))
        for aid, pose in poses.items():
            draw_character(painter, character(doc, aid), pose)
    finally:
        painter.end()
    return image


def image_to_array(image: QImage) -> npt.NDArray[np.uint8]:
    """An H×W×4 RGBA uint8 copy of a QImage."""
    img = image.convertToFormat(QImage.Format.Format_RGBA8888)
    w, h = img.width(), img.height()
    stride = img.bytesPerLine()
    buf = np.frombuffer(img.constBits(), dtype=np.uint8, count=stride * h).reshape(h, stride)
    return buf[:, : w * 4].reshape(h, w, 4).copy()
