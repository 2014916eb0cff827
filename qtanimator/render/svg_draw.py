"""Joints drawn as their author drew them: each joint's SVG document (``Joint.svg``, cut by
the SVG reader) rendered by QtSvg into a QPicture once, then replayed under the joint's
world transform every frame. A QPicture holds the drawing as vector commands, so it replays
sharp at any zoom; it is cached per document text.

Replaying a QPicture sets the opacity it recorded rather than multiplying the painter's,
so a joint drawn with an overall opacity below 1 (onion skins) is rendered by its
QSvgRenderer directly, which does multiply.
"""

from __future__ import annotations

from collections import OrderedDict

from PySide6.QtCore import QByteArray, QRectF
from PySide6.QtGui import QPainter, QPicture
from PySide6.QtSvg import QSvgRenderer

#: The joint documents' viewBox and size (the reader writes ``0 0 1 1``): rendering into
#: this rectangle maps the document's units one to one onto the painter's.
UNIT = QRectF(0.0, 0.0, 1.0, 1.0)
_CACHE_SIZE = 4096
_JOINTS: OrderedDict[str, tuple[QSvgRenderer, QPicture] | None] = OrderedDict()


def joint_drawing(svg: str) -> tuple[QSvgRenderer, QPicture] | None:
    """The renderer and the recorded picture of one joint document (None if QtSvg cannot
    read it)."""
    hit = _JOINTS.get(svg, False)
    if hit is not False:
        _JOINTS.move_to_end(svg)
        return hit  # type: ignore[return-value]
    renderer = QSvgRenderer(QByteArray(svg.encode("utf-8")))
    out: tuple[QSvgRenderer, QPicture] | None = None
    if renderer.isValid():
        picture = QPicture()
        p = QPainter(picture)
        p.setRenderHint(QPainter.RenderHint.Antialiasing, True)
        renderer.render(p, UNIT)
        p.end()
        out = (renderer, picture)
    _JOINTS[svg] = out
    if len(_JOINTS) > _CACHE_SIZE:
        _JOINTS.popitem(last=False)
    return out


def draw_joint(painter: QPainter, svg: str) -> bool:
    """Draw one joint document with the painter's transform as the joint's rest frame;
    False when QtSvg could not read it (the caller draws the geometry instead)."""
    drawing = joint_drawing(svg)
    if drawing is None:
        return False
    renderer, picture = drawing
    if painter.opacity() < 1.0:
        renderer.render(painter, UNIT)
    else:
        painter.drawPicture(0, 0, picture)
    return True
