"""Graphics items of the curve editor: per-channel drawings, the cached and live layers,
the hover mark, channel colours.

Curves are QPainterPaths in view coordinates (:mod:`qtanimator.ui.curves.paths`), built
once per channel object and zoom level and mapped to pixels by the painter (cosmetic
pens, so a line keeps its width whatever the zoom). Keys and handles are drawn in device
pixels as batches of pre-rendered symbols (``drawPixmapFragments``), never one call per key.

A channel's drawing is a :class:`ChannelDrawing`, not a QGraphicsItem of its own: in a
QGraphicsView every item under an updated region is painted again unless it caches its
pixels, and a pixmap per curve would cost a viewport's worth of memory per channel. The
view keeps two layers instead (see :class:`CurveLayer`): a cached one with the channels
not being edited (its pixels are kept until the view or one of those channels changes) and
a live one, painted every frame, with the channels under a drag or with selected keys.
"""

from __future__ import annotations

import math
import zlib
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
import pyqtgraph as pg
import shiboken6
from PySide6.QtCore import QPointF, QRectF, Qt
from PySide6.QtGui import QColor, QPainter, QPainterPath, QPen, QPixmap, QTransform
from PySide6.QtWidgets import QGraphicsItem

from qtanimator.core.channel import Channel
from qtanimator.ui.curves.drags import handle_extents
from qtanimator.ui.curves.paths import (
    LINE_TO,
    MOVE_TO,
    Spans,
    bezier_path,
    extrapolation_path,
    path_from_elements,
    reduced_path,
)

FloatArray = npt.NDArray[np.float64]

KEY_SIZE = 7.0          # key square side, pixels
HANDLE_LENGTH = 48.0    # tangent handle length, pixels
HANDLE_SIZE = 7.0       # handle dot diameter, pixels
DOT_SIZE = 3            # side of the dot drawn for a key among dense keys, pixels
HOVER_COLOUR = QColor(255, 255, 255)  # outline of the key or handle under the mouse
#: Keys closer than this (pixels, on average over the view) are drawn as dots instead of
#: squares...
DENSE_KEY_SPACING = 6.0
#: ...and closer than this not at all (a key every pixel or two: the curve is the keys);
#: selected keys are always drawn.
HIDDEN_KEY_SPACING = 2.0
#: Spans narrower than this (pixels, on average) are drawn reduced per column...
DENSE_SPAN_SPACING = 2.0
#: ...of about this many pixels (a power-of-two number of frames), to within this many
#: pixels in value (a power of two of the view's values per pixel).
COLUMN_PIXELS = 4.0
TOLERANCE_PIXELS = 0.5
#: Handles are drawn (and can be grabbed) for at most this many selected keys per channel.
MAX_HANDLES = 256
KEY_OUTLINE = QColor(20, 20, 20)
KEY_FILL = QColor(15, 15, 15)
SELECTED_FILL = QColor(255, 190, 40)
HANDLE_FILL = QColor(240, 240, 240)
HANDLE_LINE = QColor(200, 200, 200)

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


def map_points(tr: QTransform, x: FloatArray, y: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Apply an axis-aligned (or general affine) QTransform to arrays of points."""
    px = tr.m11() * x + tr.m21() * y + tr.m31()
    py = tr.m12() * x + tr.m22() * y + tr.m32()
    return px, py


def handle_offsets(tr: QTransform, slope: FloatArray,
                   extent: FloatArray | None = None) -> tuple[FloatArray, FloatArray]:
    """Pixel offsets of an out handle for slopes ``slope`` (in the units ``tr`` maps: y per
    x): HANDLE_LENGTH pixels long, or, where ``extent`` (x units) is finite, the real handle
    of a weighted key, ``extent`` along x. The in handle is the negated offset of its own
    slope and extent."""
    dx = tr.m11() + tr.m21() * slope
    dy = tr.m12() + tr.m22() * slope
    norm = np.hypot(dx, dy)
    norm[norm == 0] = 1.0
    ox, oy = HANDLE_LENGTH * dx / norm, HANDLE_LENGTH * dy / norm
    if extent is not None:
        real = np.isfinite(extent)
        if real.any():
            e = np.where(real, extent, 0.0)
            ox = np.where(real, dx * e, ox)
            oy = np.where(real, dy * e, oy)
    return ox, oy


def display_transform(offset: float, scale: float) -> QTransform:
    """(frame, value) → (frame, display value) with display value = (value − offset) · scale."""
    return QTransform(1.0, 0.0, 0.0, scale, 0.0, -offset * scale)


class ChannelDrawing:
    """One channel as the curve editor draws it, cached per channel object.

    The keyed range is an exact Bézier path, or per pixel column when its spans are
    narrower than :data:`DENSE_SPAN_SPACING` pixels (one path per power-of-two zoom level,
    so zooming by less than a factor of about 1.4 rebuilds nothing); the extrapolation is
    built for a range wider than the view, so panning rebuilds it only past that range.
    :attr:`builds` counts every path built (tests check that an edit rebuilds only the
    edited channels).
    """

    def __init__(self, cid: str, channel: Channel, fps: float) -> None:
        self.cid = cid
        self.colour = channel_colour(cid)
        self.channel = channel
        self.fps = fps
        #: (offset, scale): display value = (value − offset) · scale (normalised view).
        self.display: tuple[float, float] = (0.0, 1.0)
        self.highlighted = False
        #: Indices of the selected keys (sorted); their handles are drawn.
        self.selected: Sequence[int] = ()
        #: Paths built since this drawing was made.
        self.builds = 0
        self._spans: Spans | None = None
        self._exact: QPainterPath | None = None
        self._reduced: dict[tuple[int, int], QPainterPath] = {}
        self._ext: tuple[Any, float, float, QPainterPath] | None = None
        self._drawable: bool | None = None

    def set_channel(self, channel: Channel, fps: float) -> bool:
        """Show another version of the channel; False when it is the same object."""
        if channel is self.channel and fps == self.fps:
            return False
        self.channel = channel
        self.fps = fps
        self._spans = None
        self._exact = None
        self._reduced.clear()
        self._ext = None
        self._drawable = None
        return True

    @property
    def spans(self) -> Spans:
        """The channel's keys and spans as arrays (see :class:`~.paths.Spans`)."""
        if self._spans is None:
            self._spans = Spans.of(self.channel, self.fps)
        return self._spans

    @property
    def frames(self) -> FloatArray:
        """Key times in frames."""
        return self.spans.frames

    def level(self, tr: QTransform) -> tuple[int, int] | None:
        """The per-column zoom level ``(x, y)`` (powers of two of frames and values per
        pixel) for the full transform ``tr`` (data → pixels), or None to draw exactly."""
        keys = self.channel.keys
        px_per_frame = abs(tr.m11())
        if len(keys) < 3 or px_per_frame <= 0.0:
            return None
        frames = self.frames
        spacing = (frames[-1] - frames[0]) * px_per_frame / (len(keys) - 1)
        if spacing >= DENSE_SPAN_SPACING:
            return None
        px_per_value = max(abs(tr.m22()), 1e-300)
        return round(math.log2(COLUMN_PIXELS / px_per_frame)), round(-math.log2(px_per_value))

    @property
    def drawable(self) -> bool:
        """Whether every number the paths are built from is finite. A channel a project's
        bounds allow always is; one that is not (keys 5e-324 s apart: slopes overflow) is
        not drawn at all, since Qt can crash painting NaN geometry (issue 31)."""
        found = self._drawable
        if found is None:
            sp = self.spans
            arrays = (sp.frames, sp.values, sp.v0, sp.v1, sp.bend, sp.c1x, sp.c1y, sp.c2x, sp.c2y)
            with np.errstate(all="ignore"):
                found = all(a is None or bool(np.isfinite(a).all()) for a in arrays)
                if found and len(self.channel.keys) > 1:
                    found = bool(np.isfinite(self.channel.slopes()).all())
            self._drawable = found
        return found

    def paths(self, tr: QTransform, x0: float, x1: float) -> tuple[QPainterPath, QPainterPath]:
        """The keyed path and the extrapolation over frames ``[x0, x1]`` (view coordinates
        before the display transform) for the full transform ``tr`` (data → pixels); empty
        paths for a channel that is not :attr:`drawable` or a range that is not finite."""
        if not (self.drawable and math.isfinite(x0) and math.isfinite(x1)):
            return QPainterPath(), QPainterPath()
        level = self.level(tr)
        keyed = self._keyed(level)
        column_level = round(math.log2(COLUMN_PIXELS / max(abs(tr.m11()), 1e-300)))
        key = (level, column_level)
        hit = self._ext
        if hit is not None and hit[0] == key and hit[1] <= x0 and x1 <= hit[2]:
            return keyed, hit[3]
        width = x1 - x0
        a, b = x0 - width, x1 + width
        tolerance = TOLERANCE_PIXELS / max(abs(tr.m22()), 1e-300)
        ext = extrapolation_path(self.channel, self.fps, keyed, a, b, 2.0 ** column_level, tolerance)
        self.builds += 1
        self._ext = (key, a, b, ext)
        return keyed, ext

    def _keyed(self, level: tuple[int, int] | None) -> QPainterPath:
        if level is None:
            if self._exact is None:
                self._exact = bezier_path(self.channel, self.fps, self.spans)
                self.builds += 1
            return self._exact
        path = self._reduced.get(level)
        if path is None:
            if len(self._reduced) >= 2:
                self._reduced.clear()
            path = reduced_path(self.channel, self.fps, 2.0 ** level[0], TOLERANCE_PIXELS * 2.0 ** level[1],
                                self.spans)
            self._reduced[level] = path
            self.builds += 1
        return path


def pen(colour: QColor, width: float, dashed: bool = False, alpha: int = 255) -> QPen:
    c = QColor(colour)
    c.setAlpha(alpha)
    result = QPen(c, width)
    result.setCosmetic(True)
    if dashed:
        result.setStyle(Qt.PenStyle.DashLine)
    return result


class CurveLayer(pg.GraphicsObject):
    """Draws a set of channels (curves, keys, handles).

    The curve view uses two layers: a cached one for every channel that is not being
    edited (Qt keeps its pixels until the view or one of its channels changes) and a
    live one, redrawn each frame, for the channels under a drag or with selected keys.
    :attr:`updates` and :attr:`paints` count update requests and paints.
    """

    def __init__(self, drawings: Callable[[], list[ChannelDrawing]], cached: bool) -> None:
        super().__init__()
        self._drawings = drawings
        self.updates = 0
        self.paints = 0
        if cached:
            self.setCacheMode(QGraphicsItem.CacheMode.DeviceCoordinateCache)

    def update(self, *args: Any) -> None:
        self.updates += 1
        super().update(*args)

    def viewRangeChanged(self) -> None:  # called by the ViewBox when its range changes
        self.prepareGeometryChange()
        super().viewRangeChanged()

    def boundingRect(self) -> QRectF:
        vr = self.viewRect()
        return vr if vr is not None else QRectF()

    def paint(self, p: QPainter, *args: object) -> None:
        self.paints += 1
        vr = self.viewRect()
        if vr is None:
            return
        tr = p.transform()
        x0, x1 = vr.left(), vr.right()
        drawings = self._drawings()
        p.save()
        p.setRenderHint(QPainter.RenderHint.Antialiasing, True)
        p.setBrush(Qt.BrushStyle.NoBrush)
        for d in drawings:
            full = display_transform(*d.display) * tr
            keyed, ext = d.paths(full, x0, x1)
            p.setTransform(full)
            if not ext.isEmpty():
                p.setPen(pen(d.colour, 1.0, dashed=True, alpha=170))
                p.drawPath(ext)
            # Width-1 cosmetic pens take Qt's fast stroker; a highlighted curve is drawn
            # twice a pixel apart rather than with a wider (much slower) pen.
            p.setPen(pen(d.colour, 1.0))
            p.drawPath(keyed)
            if d.highlighted:
                p.setTransform(full * QTransform.fromTranslate(0.0, 1.0))
                p.drawPath(keyed)
        p.resetTransform()
        for d in drawings:
            if d.channel.keys:
                _paint_keys(p, display_transform(*d.display) * tr, d, x0, x1)
        p.restore()


# ------------------------------------------------------------------ symbols
_symbols: dict[tuple[str, int], QPixmap] = {}


def _symbol(kind: str, colour: QColor | None = None) -> QPixmap:
    """A pre-rendered key, selected key, dot or handle (cached per kind and colour)."""
    rgba = colour.rgba() if colour is not None else 0
    hit = _symbols.get((kind, rgba))
    if hit is not None:
        return hit
    size = {"key": 10, "selected": 12, "dot": DOT_SIZE, "handle": 10}[kind]
    pm = QPixmap(size, size)
    pm.fill(Qt.GlobalColor.transparent)
    q = QPainter(pm)
    q.setRenderHint(QPainter.RenderHint.Antialiasing, kind == "handle")
    c = size / 2.0
    if kind == "key":
        assert colour is not None
        q.setPen(QPen(colour, 1.5))
        q.setBrush(KEY_FILL)
        q.drawRect(QRectF(c - KEY_SIZE / 2, c - KEY_SIZE / 2, KEY_SIZE, KEY_SIZE))
    elif kind == "selected":
        q.setPen(QPen(KEY_OUTLINE, 1.0))
        q.setBrush(SELECTED_FILL)
        q.drawRect(QRectF(c - KEY_SIZE / 2 - 1, c - KEY_SIZE / 2 - 1, KEY_SIZE + 2, KEY_SIZE + 2))
    elif kind == "dot":
        assert colour is not None
        q.fillRect(0, 0, size, size, colour)
    else:
        q.setPen(QPen(KEY_OUTLINE, 1.0))
        q.setBrush(HANDLE_FILL)
        q.drawEllipse(QPointF(c, c), HANDLE_SIZE / 2, HANDLE_SIZE / 2)
    q.end()
    _symbols[(kind, rgba)] = pm
    return pm


def draw_symbols(p: QPainter, pixmap: QPixmap, px: FloatArray, py: FloatArray) -> None:
    """Draw ``pixmap`` centred (to the pixel) at every point: one ``drawPixmapFragments``."""
    n = len(px)
    if n == 0:
        return
    w, h = pixmap.width(), pixmap.height()
    frags = np.empty((n, 10), dtype=np.float64)
    frags[:, 0] = np.floor(px - w / 2.0 + 0.5) + w / 2.0
    frags[:, 1] = np.floor(py - h / 2.0 + 0.5) + h / 2.0
    frags[:, 2:10] = (0.0, 0.0, w, h, 1.0, 1.0, 0.0, 1.0)  # source rect, scale, rotation, opacity
    np.clip(frags[:, :2], -1e6, 1e6, out=frags[:, :2])
    fragments = shiboken6.wrapInstance(frags.ctypes.data, QPainter.PixmapFragment)  # a view of ``frags``
    p.drawPixmapFragments(fragments, n, pixmap)  # type: ignore[arg-type]


def _paint_keys(p: QPainter, tr: QTransform, d: ChannelDrawing, x0: float, x1: float) -> None:
    """Keys of one channel in device pixels (``tr``: data → pixels, reset on ``p``)."""
    frames = d.frames
    values = d.channel.values
    margin = KEY_SIZE / max(abs(tr.m11()), 1e-300)
    i0, i1 = np.searchsorted(frames, [x0 - margin, x1 + margin])
    i0, i1 = int(i0), int(i1)
    sel = np.asarray(d.selected, dtype=np.int64)
    many = len(sel) > MAX_HANDLES  # as CurveView.handle_at: no handles to draw or take
    sel = sel[(sel >= i0) & (sel < i1)]
    count = i1 - i0
    spacing = abs(tr.m11()) * (frames[i1 - 1] - frames[i0]) / (count - 1) if count > 1 else math.inf
    if count > 0 and spacing >= HIDDEN_KEY_SPACING:
        unsel = np.ones(count, dtype=bool)
        unsel[sel - i0] = False
        ux, uy = map_points(tr, frames[i0:i1][unsel], values[i0:i1][unsel])
        symbol = "key" if spacing >= DENSE_KEY_SPACING else "dot"
        draw_symbols(p, _symbol(symbol, d.colour), ux, uy)
    if not len(sel):
        return
    sx, sy = map_points(tr, frames[sel], values[sel])
    if many:
        # Many selected keys (select all on a long clip): no handles, and one square per
        # couple of pixels.
        cell = np.floor(sx / 2.0)
        keep = np.concatenate(([True], cell[1:] != cell[:-1]))
        sx, sy = sx[keep], sy[keep]
    else:
        s_in, s_out = d.channel.slopes()
        ext = handle_extents(d.channel)
        e_in, e_out = (None, None) if ext is None else (ext[0][sel] * d.fps, ext[1][sel] * d.fps)
        ox, oy = handle_offsets(tr, s_out[sel] / d.fps, e_out)
        ix, iy = handle_offsets(tr, s_in[sel] / d.fps, e_in)
        n = len(sel)
        types = np.tile(np.array([MOVE_TO, LINE_TO, LINE_TO], np.int32), n)
        hx = np.column_stack([sx - ix, sx, sx + ox]).ravel()
        hy = np.column_stack([sy - iy, sy, sy + oy]).ravel()
        p.setPen(QPen(HANDLE_LINE, 1.0))
        p.drawPath(path_from_elements(types, hx, hy))
        draw_symbols(p, _symbol("handle"), np.concatenate([sx - ix, sx + ox]), np.concatenate([sy - iy, sy + oy]))
    draw_symbols(p, _symbol("selected"), sx, sy)


@dataclass(frozen=True)
class HoverMark:
    """The key or handle under the mouse, in view coordinates (frames, display value)."""

    kind: str            # "key" or "handle"
    x: float
    y: float
    colour: QColor
    selected: bool = False
    slope: float = 0.0   # display slope (display value per frame) of the hovered handle
    side: str = ""       # "in" or "out" for a handle
    extent: float = math.nan  # frames along time of a real-length (weighted) handle


class HoverLayer(pg.GraphicsObject):
    """The key or handle under the mouse, drawn larger and lighter (as Blender does).

    Its own item, so that hovering never repaints the cached layer.
    """

    def __init__(self, mark: Callable[[], HoverMark | None]) -> None:
        super().__init__()
        self._mark = mark

    def viewRangeChanged(self) -> None:
        self.prepareGeometryChange()
        super().viewRangeChanged()

    def boundingRect(self) -> QRectF:
        vr = self.viewRect()
        return vr if vr is not None else QRectF()

    def paint(self, p: QPainter, *args: object) -> None:
        m = self._mark()
        if m is None:
            return
        tr = p.transform()
        px, py = map_points(tr, np.array([m.x]), np.array([m.y]))
        p.save()
        p.resetTransform()
        p.setRenderHint(QPainter.RenderHint.Antialiasing, True)
        p.setPen(QPen(HOVER_COLOUR, 2.0))
        if m.kind == "key":
            p.setBrush(QColor(255, 225, 140) if m.selected else m.colour.lighter(150))
            big = KEY_SIZE + 4
            p.drawRect(QRectF(px[0] - big / 2, py[0] - big / 2, big, big))
        else:
            ox, oy = handle_offsets(tr, np.array([m.slope]), np.array([m.extent]))
            sign = 1.0 if m.side == "out" else -1.0
            p.setBrush(QColor(255, 225, 140))
            p.drawEllipse(QPointF(px[0] + sign * ox[0], py[0] + sign * oy[0]), HANDLE_SIZE / 2 + 2,
                          HANDLE_SIZE / 2 + 2)
        p.restore()
