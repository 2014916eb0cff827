"""The outliner's row icons, drawn in code (no image files)."""

from __future__ import annotations

from PySide6.QtCore import QPointF, Qt
from PySide6.QtGui import QBrush, QColor, QIcon, QPainter, QPainterPath, QPen, QPixmap, QPolygonF


def icon(kind: str) -> QIcon:
    """The 16 px icon of ``kind``: ``dynamic``, ``keyed``, ``key``, ``shown``, ``hidden``,
    ``locked``, ``unlocked``, ``cloth``, ``light``, ``character`` (anything else: a box,
    the 3D skeleton's)."""
    pix = QPixmap(16, 16)
    pix.fill(Qt.GlobalColor.transparent)
    p = QPainter(pix)
    p.setRenderHint(QPainter.RenderHint.Antialiasing)
    if kind == "dynamic":
        p.setPen(QPen(QColor(40, 40, 40), 1.2))
        p.drawLine(QPointF(8, 1), QPointF(8, 8))
        p.setBrush(QBrush(QColor(255, 255, 255)))
        p.drawEllipse(QPointF(8, 11), 4, 4)
    elif kind in ("keyed", "key"):
        diamond = QPolygonF([QPointF(8, 2), QPointF(14, 8), QPointF(8, 14), QPointF(2, 8)])
        p.setPen(QPen(QColor(150, 80, 0), 1.2))
        p.setBrush(QBrush(QColor(255, 160, 0)) if kind == "keyed" else Qt.BrushStyle.NoBrush)
        p.drawPolygon(diamond)
    elif kind in ("shown", "hidden"):
        eye = QPainterPath()
        eye.moveTo(1, 8)
        eye.quadTo(8, 1, 15, 8)
        eye.quadTo(8, 15, 1, 8)
        p.setPen(QPen(QColor(40, 40, 40) if kind == "shown" else QColor(160, 160, 160), 1.3))
        p.setBrush(QBrush(QColor(255, 255, 255)) if kind == "shown" else Qt.BrushStyle.NoBrush)
        p.drawPath(eye)
        if kind == "shown":
            p.setBrush(QBrush(QColor(40, 40, 40)))
            p.drawEllipse(QPointF(8, 8), 2.5, 2.5)
        else:
            p.drawLine(QPointF(2, 14), QPointF(14, 2))
    elif kind in ("locked", "unlocked"):
        color = QColor(40, 40, 40) if kind == "locked" else QColor(175, 175, 175)
        p.setPen(QPen(color, 1.5))
        p.setBrush(Qt.BrushStyle.NoBrush)
        shackle = QPainterPath()
        shackle.moveTo(5, 8)
        shackle.lineTo(5, 5)
        shackle.arcTo(5, 2, 6, 6, 180, -180)
        shackle.lineTo(11, 8 if kind == "locked" else 5)
        p.drawPath(shackle)
        p.setBrush(QBrush(color))
        p.drawRoundedRect(3, 8, 10, 7, 1.5, 1.5)
    elif kind == "cloth":
        p.setPen(QPen(QColor(60, 60, 90), 1.0))
        p.setBrush(QBrush(QColor(200, 120, 200)))
        cloth = QPainterPath()
        cloth.moveTo(2, 3)
        cloth.lineTo(14, 3)
        cloth.quadTo(12, 9, 14, 14)
        cloth.quadTo(8, 11, 2, 14)
        cloth.quadTo(4, 9, 2, 3)
        p.drawPath(cloth)
    elif kind == "light":
        p.setPen(QPen(QColor(150, 110, 0), 1.0))
        p.setBrush(QBrush(QColor(255, 220, 90)))
        p.drawEllipse(QPointF(8, 7), 4.5, 4.5)
        p.setBrush(QBrush(QColor(120, 120, 120)))
        p.drawRect(6, 12, 4, 3)
    elif kind == "character":
        p.setPen(QPen(QColor(30, 30, 30), 1.2))
        p.setBrush(QBrush(QColor(120, 170, 255)))
        p.drawEllipse(QPointF(8, 5), 3, 3)
        p.drawRoundedRect(4, 9, 8, 6, 2, 2)
    else:
        p.setPen(QPen(QColor(30, 30, 30), 1.2))
        p.setBrush(QBrush(QColor(180, 220, 140)))
        p.drawRect(3, 3, 10, 10)
    p.end()
    return QIcon(pix)
