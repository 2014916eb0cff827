"""Drawing the dope sheet: rows, diamonds, names, the ruler (:func:`paint_layer`, kept in a
pixmap by the view) and what is drawn over it every paint (:func:`paint_overlay`: the
playhead, the box of a box select, the hint of a retime or scale).

Only the visible rows are drawn; the key frames come from the view's
:class:`~qtanimator.ui.dope_rows.KeyFrames` cache. The functions take the view as a
:class:`DopeCanvas` (its geometry and rows).
"""

from __future__ import annotations

import math
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt
from PySide6.QtCore import QPointF, QRect, QRectF, Qt
from PySide6.QtGui import QColor, QFont, QFontMetrics, QPainter, QPen, QPixmap, QPolygonF

from qtanimator.ui.curves.items import SELECTED_FILL, channel_colour, draw_symbols
from qtanimator.ui.dope_rows import (
    HEADER_HEIGHT,
    INDENT,
    KEY_PICK,
    NAME_WIDTH,
    ROW_HEIGHT,
    KeyFrames,
    Row,
    tick_step,
)

FloatArray = npt.NDArray[np.float64]

BACKGROUND = QColor(38, 40, 44)
NAME_BACKGROUND = QColor(32, 34, 38)
ROW_COLOURS = (QColor(44, 46, 51), QColor(40, 42, 47))
ASSET_ROW = QColor(62, 66, 78)
JOINT_ROW = QColor(50, 53, 61)
CURRENT_ROW = QColor(70, 90, 120)
OUTSIDE_RANGE = QColor(0, 0, 0, 70)
GRID = QColor(56, 59, 66)        # opaque: a 1-pixel alpha fill is a slow path in the raster engine
TEXT = QColor(222, 222, 222)
DIM_TEXT = QColor(160, 160, 165)
RULER = QColor(30, 32, 36)
PLAYHEAD = QColor(80, 170, 255)
BOX_LINE = QColor(255, 255, 255, 200)
BOX_FILL = QColor(255, 255, 255, 30)
KEY_FILL = QColor(205, 205, 210)
SUMMARY_FILL = QColor(150, 160, 180)
DIAMOND_OUTLINE = QColor(10, 10, 10)

EMPTY_TEXT = ("No keys yet. Key a pose in the 2D rig editor (S) or import an animation; "
              "every channel then shows its keys here.")


class DopeCanvas(Protocol):
    """What drawing needs of the view."""

    ctx: Any
    rows: list[Row]
    px_per_frame: float
    key_frames: KeyFrames

    @property
    def doc(self) -> Any: ...

    def width(self) -> int: ...

    def height(self) -> int: ...

    def font(self) -> QFont: ...

    def fontMetrics(self) -> QFontMetrics: ...

    def key_area(self) -> QRectF: ...

    def x_of(self, frame: float | FloatArray) -> Any: ...

    def frame_at(self, x: float) -> float: ...

    def row_y(self, index: int) -> int: ...

    def visible_range(self) -> tuple[int, int]: ...

    def is_open(self, path: tuple[str, str]) -> bool: ...

    def tree_size(self) -> int: ...


# ---------------------------------------------------------------------- symbols
_diamonds: dict[str, QPixmap] = {}


def diamond(kind: str) -> QPixmap:
    """A pre-rendered diamond: "key", "selected", "summary" or "summary_selected"."""
    hit = _diamonds.get(kind)
    if hit is not None:
        return hit
    summary = kind.startswith("summary")
    size = 13 if summary else 11
    pm = QPixmap(size, size)
    pm.fill(Qt.GlobalColor.transparent)
    q = QPainter(pm)
    q.setRenderHint(QPainter.RenderHint.Antialiasing, True)
    c = size / 2.0
    r = c - 0.8
    q.setPen(QPen(DIAMOND_OUTLINE, 1.2))
    q.setBrush(SELECTED_FILL if kind.endswith("selected") else (SUMMARY_FILL if summary else KEY_FILL))
    q.drawPolygon(QPolygonF([QPointF(c, c - r), QPointF(c + r, c), QPointF(c, c + r), QPointF(c - r, c)]))
    q.end()
    _diamonds[kind] = pm
    return pm


# ------------------------------------------------------------------------ layer
def paint_layer(view: DopeCanvas, p: QPainter) -> None:
    """Everything but the playhead and the box."""
    paint_rows(view, p)
    paint_ruler(view, p)


def paint_rows(view: DopeCanvas, p: QPainter) -> None:
    area = view.key_area()
    w = int(area.right())
    x0 = int(area.left())
    first, last = view.visible_range()
    doc = view.doc
    sel = view.ctx.key_selection.valid(doc.channels)
    view.key_frames.trim_selected(4 * view.tree_size() + 16)
    f_lo, f_hi = view.frame_at(area.left() - KEY_PICK), view.frame_at(area.right() + KEY_PICK)
    current = view.ctx.selection
    font = QFont(view.font())
    bold = QFont(font)
    bold.setBold(True)
    step = tick_step(view.px_per_frame)
    rows = view.rows
    # Frame range shading and grid.
    start, end = doc.frame_range
    top = HEADER_HEIGHT
    bottom = view.height()
    for i in range(first, last):
        r = rows[i]
        y = view.row_y(i)
        colour = ASSET_ROW if r.kind == "asset" else JOINT_ROW if r.kind == "joint" else ROW_COLOURS[i % 2]
        p.fillRect(QRect(0, y, w, ROW_HEIGHT), colour)
    xs, xe = view.x_of(float(start)), view.x_of(float(end))
    if xs > x0:
        p.fillRect(QRectF(x0, top, xs - x0, bottom - top), OUTSIDE_RANGE)
    if xe < w:
        p.fillRect(QRectF(max(xe, x0), top, w - max(xe, x0), bottom - top), OUTSIDE_RANGE)
    f = math.floor(f_lo / step) * step
    while f <= f_hi:
        x = int(view.x_of(float(f)))
        if x >= x0:
            p.fillRect(QRect(x, top, 1, bottom - top), GRID)  # a fill is much faster than a line
        f += step
    # Keys.
    for i in range(first, last):
        r = rows[i]
        centre_y = view.row_y(i) + ROW_HEIGHT / 2.0
        frames = view.key_frames.row_frames(r)
        a, b = np.searchsorted(frames, [f_lo, f_hi])
        if a >= b:
            continue
        shown = frames[a:b]
        chosen = view.key_frames.selected_frames(r, sel)
        mask = np.isin(shown, chosen) if len(chosen) else np.zeros(len(shown), dtype=bool)
        px = np.round(view.x_of(shown))
        kind = "summary" if r.summary else "key"
        for pick, symbol in ((~mask, kind), (mask, kind + "_selected")):
            if pick.any():
                xs_ = np.unique(px[pick])
                draw_symbols(p, diamond(symbol), xs_, np.full(len(xs_), centre_y))
    # Names.
    p.fillRect(QRect(0, top, NAME_WIDTH, bottom - top), NAME_BACKGROUND)
    for i in range(first, last):
        r = rows[i]
        y = view.row_y(i)
        rect = QRect(0, y, NAME_WIDTH, ROW_HEIGHT)
        if r.summary:
            highlighted = current == (r.asset, r.joint) or (r.kind == "asset" and current == (r.asset, ""))
            p.fillRect(rect, CURRENT_ROW if highlighted else (ASSET_ROW if r.kind == "asset" else JOINT_ROW))
            paint_arrow(p, r, y, view.is_open(r.path))
        elif i % 2:
            p.fillRect(rect, ROW_COLOURS[1])
        x = 6 + r.depth * INDENT + INDENT
        if not r.summary:
            p.fillRect(QRect(x - 10, y + 6, 6, ROW_HEIGHT - 12), channel_colour(r.cids[0]))
        p.setFont(bold if r.kind == "asset" else font)
        p.setPen(TEXT if r.summary else DIM_TEXT)
        p.drawText(QRect(x, y, NAME_WIDTH - x - 4, ROW_HEIGHT),
                   int(Qt.AlignmentFlag.AlignVCenter | Qt.AlignmentFlag.AlignLeft), r.label)
    p.setPen(QPen(QColor(0, 0, 0), 1))
    p.drawLine(NAME_WIDTH, 0, NAME_WIDTH, bottom)
    if not rows:
        p.setPen(DIM_TEXT)
        p.drawText(QRectF(area.left() + 12, top + 8, area.width() - 24, 3 * ROW_HEIGHT),
                   int(Qt.AlignmentFlag.AlignLeft | Qt.AlignmentFlag.AlignTop | Qt.TextFlag.TextWordWrap),
                   EMPTY_TEXT)


def paint_arrow(p: QPainter, r: Row, y: int, is_open: bool) -> None:
    """A summary row's expand / collapse arrow."""
    cx = 6 + r.depth * INDENT + 4
    cy = y + ROW_HEIGHT / 2.0
    if is_open:
        tri = [QPointF(cx - 4, cy - 2), QPointF(cx + 4, cy - 2), QPointF(cx, cy + 3)]
    else:
        tri = [QPointF(cx - 2, cy - 4), QPointF(cx + 3, cy), QPointF(cx - 2, cy + 4)]
    p.setPen(Qt.PenStyle.NoPen)
    p.setBrush(TEXT)
    p.drawPolygon(QPolygonF(tri))


def paint_ruler(view: DopeCanvas, p: QPainter) -> None:
    area = view.key_area()
    p.fillRect(QRect(0, 0, view.width(), HEADER_HEIGHT), RULER)
    step = tick_step(view.px_per_frame)
    f_lo, f_hi = view.frame_at(area.left()), view.frame_at(area.right())
    p.setPen(DIM_TEXT)
    f = math.floor(f_lo / step) * step
    while f <= f_hi:
        x = view.x_of(float(f))
        if x >= area.left():
            p.drawLine(QPointF(x, HEADER_HEIGHT - 6), QPointF(x, HEADER_HEIGHT))
            p.drawText(QPointF(x + 3, HEADER_HEIGHT - 8), str(int(f)))
        f += step
    p.setPen(TEXT)
    p.drawText(QRect(6, 0, NAME_WIDTH - 8, HEADER_HEIGHT),
               int(Qt.AlignmentFlag.AlignVCenter | Qt.AlignmentFlag.AlignLeft), "Channels")


# ---------------------------------------------------------------------- overlay
def playhead_rect(view: DopeCanvas, frame: float) -> QRect:
    """The strip the playhead and its label cover at ``frame``."""
    x = int(view.x_of(frame))
    half = max(24, view.fontMetrics().horizontalAdvance(f"{frame:g}") // 2 + 8)
    return QRect(x - half, 0, 2 * half, view.height())


def paint_overlay(view: DopeCanvas, p: QPainter, box: QRectF | None, hint: str) -> None:
    """The playhead, the box select's ``box`` (when given) and a ``hint`` line."""
    area = view.key_area()
    frame = view.ctx.frame
    x = view.x_of(frame)
    if area.left() <= x <= area.right():
        p.setPen(QPen(PLAYHEAD, 1.5))
        p.drawLine(QPointF(x, HEADER_HEIGHT), QPointF(x, view.height()))
        label = f"{frame:g}"
        tw = p.fontMetrics().horizontalAdvance(label) + 8
        label_box = QRectF(x - tw / 2, 2, tw, HEADER_HEIGHT - 4)
        p.fillRect(label_box, PLAYHEAD)
        p.setPen(QColor(10, 10, 10))
        p.drawText(label_box, int(Qt.AlignmentFlag.AlignCenter), label)
    if box is not None:
        p.setPen(QPen(BOX_LINE, 1, Qt.PenStyle.DashLine))
        p.setBrush(BOX_FILL)
        p.drawRect(box)
    if hint:
        p.setPen(TEXT)
        p.fillRect(QRect(NAME_WIDTH + 4, view.height() - ROW_HEIGHT - 4,
                         p.fontMetrics().horizontalAdvance(hint) + 12, ROW_HEIGHT), QColor(0, 0, 0, 170))
        p.drawText(QPointF(NAME_WIDTH + 10, view.height() - 10), hint)


__all__ = ["BACKGROUND", "DopeCanvas", "diamond", "paint_arrow", "paint_layer", "paint_overlay", "paint_rows",
           "paint_ruler", "playhead_rect"]
