"""Graphics items of the curve editor: curves, keys and tangent handles, channel colours.

Everything is drawn in device pixels (keys and handles keep their size whatever the
zoom) from arrays mapped with numpy, one ``drawPolyline`` per curve part.
"""

from __future__ import annotations

import zlib
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt
import pyqtgraph as pg
from PySide6.QtCore import QPointF, QRectF, Qt
from PySide6.QtGui import QBrush, QColor, QPainter, QPen, QTransform
from PySide6.QtWidgets import QGraphicsItem

FloatArray = npt.NDArray[np.float64]

KEY_SIZE = 7.0          # key square side, pixels
HANDLE_LENGTH = 48.0    # tangent handle length, pixels
HANDLE_SIZE = 7.0       # handle dot diameter, pixels
HOVER_COLOUR = QColor(255, 255, 255)  # outline of the key or handle under the mouse

_AXIS_COLOURS = {
    "x": QColor(232, 86, 86),
    "y": QColor(112, 204, 92),
    "z": QColor(92, 148, 240),
}


def channel_colour(cid: str) -> QColor:
    """x / y / z DOFs are red / green / blue (as in Blender and Maya); others get a stable hue."""
    dof = cid.rsplit("/", 1)[-1].lower()
    last = dof[-1:] if dof else ""
    if last in _AXIS_COLOURS and (len(dof) == 1 or dof[:-1] in ("r", "t", "s", "rot", "pos", "trans", "scale")):
        return QColor(_AXIS_COLOURS[last])
    hue = (zlib.crc32(cid.encode()) * 0.618033988749895) % 1.0
    return QColor.fromHsvF(hue, 0.55, 0.95)


@dataclass
class KeyLayer:
    """What is drawn for one channel's keys, in view coordinates (frames, display value)."""

    x: FloatArray
    y: FloatArray
    selected: npt.NDArray[np.bool_]
    # Display slopes (display value per frame) of the selected keys, for their handles.
    slope_in: FloatArray = field(default_factory=lambda: np.zeros(0))
    slope_out: FloatArray = field(default_factory=lambda: np.zeros(0))
    #: The key under the mouse (index into x / y), drawn larger and lighter.
    hover_key: int | None = None
    #: The handle under the mouse: (position among the selected keys, "in" or "out").
    hover_handle: tuple[int, str] | None = None


@dataclass
class ChannelDrawing:
    """One channel as drawn: the keyed range (solid), extrapolation (dashed, NaN-separated
    pre and post parts) and keys, all in view coordinates."""

    cid: str
    colour: QColor
    x: FloatArray
    y: FloatArray
    ext_x: FloatArray
    ext_y: FloatArray
    keys: KeyLayer | None = None
    highlighted: bool = False


def map_points(tr: QTransform, x: FloatArray, y: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Apply an axis-aligned (or general affine) QTransform to arrays of points."""
    px = tr.m11() * x + tr.m21() * y + tr.m31()
    py = tr.m12() * x + tr.m22() * y + tr.m32()
    return px, py


def handle_offsets(tr: QTransform, slope: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Pixel offsets of an out handle of length HANDLE_LENGTH for display slopes ``slope``.

    The in handle is the negated offset of its own slope.
    """
    dx = tr.m11() + tr.m21() * slope
    dy = tr.m12() + tr.m22() * slope
    norm = np.hypot(dx, dy)
    norm[norm == 0] = 1.0
    return HANDLE_LENGTH * dx / norm, HANDLE_LENGTH * dy / norm


_LIMIT = 1e6  # pixel coordinates are clamped here so extreme zooms stay drawable


def _polylines(tr: QTransform, x: FloatArray, y: FloatArray) -> list[Any]:
    if len(x) < 2:
        return []
    px, py = map_points(tr, x, y)
    np.clip(px, -_LIMIT, _LIMIT, out=px)
    np.clip(py, -_LIMIT, _LIMIT, out=py)
    gaps = np.nonzero(np.isnan(x))[0]
    out = []
    start = 0
    for g in [*gaps.tolist(), len(x)]:
        if g - start >= 2:
            out.append(pg.functions.arrayToQPolygonF(px[start:g], py[start:g]))
        start = g + 1
    return out


class CurveLayer(pg.GraphicsObject):
    """Draws a set of channels (curves, keys, handles) in device pixels.

    The curve view uses two layers: a cached one for every channel that is not being
    edited (Qt keeps its pixels until the view or one of its channels changes) and a
    live one, redrawn each frame, for the channels under a drag or with selected keys.
    """

    def __init__(self, drawings: Callable[[], list[ChannelDrawing]], cached: bool) -> None:
        super().__init__()
        self._drawings = drawings
        if cached:
            self.setCacheMode(QGraphicsItem.CacheMode.DeviceCoordinateCache)

    def viewRangeChanged(self) -> None:  # called by the ViewBox when its range changes
        self.prepareGeometryChange()
        super().viewRangeChanged()

    def boundingRect(self) -> QRectF:
        vr = self.viewRect()
        return vr if vr is not None else QRectF()

    def paint(self, p: QPainter, *args: object) -> None:
        tr = p.transform()
        p.save()
        p.resetTransform()
        p.setRenderHint(QPainter.RenderHint.Antialiasing, True)
        drawings = self._drawings()
        p.setBrush(Qt.BrushStyle.NoBrush)
        for d in drawings:
            p.setPen(pen(d.colour, 1.5 if d.highlighted else 1.0, dashed=True, alpha=170))
            for poly in _polylines(tr, d.ext_x, d.ext_y):
                p.drawPolyline(poly)
            p.setPen(pen(d.colour, 2.5 if d.highlighted else 1.5))
            for poly in _polylines(tr, d.x, d.y):
                p.drawPolyline(poly)
        for d in drawings:
            if d.keys is not None and len(d.keys.x):
                _paint_keys(p, tr, d.keys, d.colour)
        p.restore()


def _paint_keys(p: QPainter, tr: QTransform, layer: KeyLayer, colour: QColor) -> None:
    outline = QPen(QColor(20, 20, 20), 1.0)
    half = KEY_SIZE / 2
    px, py = map_points(tr, layer.x, layer.y)
    sel = layer.selected
    if sel.any():
        sx, sy = px[sel], py[sel]
        ox, oy = handle_offsets(tr, layer.slope_out)
        ix, iy = handle_offsets(tr, layer.slope_in)
        p.setPen(QPen(QColor(200, 200, 200), 1.0))
        for k in range(len(sx)):
            c = QPointF(sx[k], sy[k])
            p.drawLine(c, QPointF(sx[k] + ox[k], sy[k] + oy[k]))
            p.drawLine(c, QPointF(sx[k] - ix[k], sy[k] - iy[k]))
        p.setBrush(QBrush(QColor(240, 240, 240)))
        p.setPen(outline)
        hr = HANDLE_SIZE / 2
        for k in range(len(sx)):
            p.drawEllipse(QPointF(sx[k] + ox[k], sy[k] + oy[k]), hr, hr)
            p.drawEllipse(QPointF(sx[k] - ix[k], sy[k] - iy[k]), hr, hr)
    unsel = ~sel
    p.setPen(QPen(colour, 1.5))
    p.setBrush(QBrush(QColor(15, 15, 15)))
    p.drawRects([QRectF(x - half, y - half, KEY_SIZE, KEY_SIZE) for x, y in zip(px[unsel], py[unsel])])
    if sel.any():
        p.setPen(outline)
        p.setBrush(QBrush(QColor(255, 190, 40)))
        p.drawRects([QRectF(x - half - 1, y - half - 1, KEY_SIZE + 2, KEY_SIZE + 2)
                     for x, y in zip(px[sel], py[sel])])
    # Hover feedback (as Blender does): a lighter, larger key or handle under the mouse.
    p.setPen(QPen(HOVER_COLOUR, 2.0))
    if layer.hover_key is not None and layer.hover_key < len(px):
        i = layer.hover_key
        p.setBrush(QBrush(QColor(255, 225, 140) if sel[i] else colour.lighter(150)))
        big = KEY_SIZE + 4
        p.drawRect(QRectF(px[i] - big / 2, py[i] - big / 2, big, big))
    if layer.hover_handle is not None and sel.any():
        k, side = layer.hover_handle
        sx, sy = px[sel], py[sel]
        if k < len(sx):
            ox, oy = handle_offsets(tr, (layer.slope_out if side == "out" else layer.slope_in)[k:k + 1])
            sign = 1.0 if side == "out" else -1.0
            c = QPointF(sx[k] + sign * ox[0], sy[k] + sign * oy[0])
            p.setBrush(QBrush(QColor(255, 225, 140)))
            p.drawEllipse(c, HANDLE_SIZE / 2 + 2, HANDLE_SIZE / 2 + 2)


def pen(colour: QColor, width: float, dashed: bool = False, alpha: int = 255) -> QPen:
    c = QColor(colour)
    c.setAlpha(alpha)
    result = QPen(c, width)
    result.setCosmetic(True)
    if dashed:
        result.setStyle(Qt.PenStyle.DashLine)
    return result
