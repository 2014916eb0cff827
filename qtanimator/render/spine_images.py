"""Spine export with its PNG attachments (issue 15, item 7): ``NAME.json`` from
:mod:`qtanimator.document.spine_export` and ``images/<joint>.png``, each joint's rest drawing
rasterised as the 2D views draw it (its SVG document through QtSvg, else its shapes;
:func:`qtanimator.render.painter2d.draw_character`) on a transparent background.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from PySide6.QtCore import QBuffer, QByteArray, QIODevice, Qt
from PySide6.QtGui import QImage, QPainter

from qtanimator.core.rig2d import Character, Joint
from qtanimator.document.character2d import character
from qtanimator.document.document import Document
from qtanimator.document.spine_export import MARGIN, PIXELS_PER_UNIT, Region, regions, write_spine_json
from qtanimator.formats.atomic import write_atomic
from qtanimator.render.painter2d import draw_character


def joint_image(ch: Character, region: Region, pixels_per_unit: float = PIXELS_PER_UNIT) -> QImage:
    """One joint's rest drawing over ``region`` (ARGB, premultiplied, transparent elsewhere)."""
    j = ch.joints[region.joint]
    alone = Character(j.name, [Joint(j.name, None, j.pivot.copy(), shapes=list(j.shapes), svg=j.svg)])
    image = QImage(region.width, region.height, QImage.Format.Format_ARGB32_Premultiplied)
    image.fill(Qt.GlobalColor.transparent)
    painter = QPainter(image)
    try:
        painter.scale(pixels_per_unit, pixels_per_unit)
        painter.translate(-region.x0, -region.y0)
        draw_character(painter, alone, alone.rest_pose())
    finally:
        painter.end()
    return image


def export_spine(doc: Document, asset_id: str, path: str | os.PathLike[str],
                 pixels_per_unit: float = PIXELS_PER_UNIT, margin: float = MARGIN) -> dict[str, Any]:
    """Write ``path`` (``NAME.json``) and ``images/*.png`` beside it; returns the JSON data.

    Needs a QGuiApplication (QImage text and SVG rendering); raises OSError when writing fails.
    """
    out = Path(path)
    folder = out.parent / "images"
    folder.mkdir(parents=True, exist_ok=True)
    ch = character(doc, asset_id)
    for r in regions(ch, pixels_per_unit, margin):
        target = folder / f"{r.file}.png"
        png = QByteArray()
        buffer = QBuffer(png)
        buffer.open(QIODevice.OpenModeFlag.WriteOnly)
        # the stubs want the format as bytes, PySide6 takes a str
        if not joint_image(ch, r, pixels_per_unit).save(buffer, "PNG"):  # type: ignore[call-overload]
            raise OSError(f"could not encode the image of {target}")
        buffer.close()
        write_atomic(target, bytes(png.data()))  # atomic; a pipe or a device is refused
    return write_spine_json(doc, asset_id, out, pixels_per_unit, margin)
