"""Compare a rendered curve editor view with a reference image (with a tolerance).

The reference is ``tests/ui/reference/curve_editor_view.png``. To regenerate it after an
intended change to the drawing, run::

    QTANIMATOR_UPDATE_REFERENCES=1 .venv/bin/python -m pytest tests/ui/test_curve_editor_image.py

and look at the new PNG before committing it. Only the data area (curves, keys, handles,
grid, frame line) is compared, so axis label fonts do not matter. On a mismatch the
rendered image and a difference image are written next to the test's tmp_path.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from docfix import set_channels
from PySide6.QtCore import QRect
from PySide6.QtGui import QImage
from PySide6.QtWidgets import QApplication

from qtanimator.core.channel import Channel, Key
from qtanimator.document import Document
from qtanimator.ui.context import EditorContext
from qtanimator.ui.curve_editor import CurveEditor

REFERENCE = Path(__file__).parent / "reference" / "curve_editor_view.png"
PIXEL_THRESHOLD = 48     # a pixel differs if a channel differs by more than this (0…255)
MAX_DIFFERENT = 0.006    # fraction of differing pixels tolerated (antialiasing, rasteriser)


def _image_array(image: QImage) -> np.ndarray:
    image = image.convertToFormat(QImage.Format.Format_RGB888)
    w, h = image.width(), image.height()
    data = np.frombuffer(image.constBits(), dtype=np.uint8, count=image.bytesPerLine() * h)
    return data.reshape(h, image.bytesPerLine())[:, : w * 3].reshape(h, w, 3).copy()


def render_view(qtbot) -> tuple[QImage, CurveEditor]:
    doc = Document()
    set_channels(doc, {"hero//x": Channel([Key(0.0, 0.0), Key(0.5, 2.0), Key(1.0, 1.0, "flat", "flat")], post="cycle")})
    set_channels(doc, {"hero/arm/angle": Channel(
        [Key.make(0.25, -1.0, "linear", "linear"), Key.make(1.25, 1.5, 0.0, 3.0)], pre="linear", post="bounce")})
    set_channels(doc, {"hero//y": Channel([Key(0.1, 0.5), Key(0.6, -0.5), Key(0.9, 0.2)],
                                      pre="cycle_offset", post="cycle_offset")})
    ctx = EditorContext(doc)
    ed = CurveEditor(ctx)
    qtbot.addWidget(ed)
    plot = ed.plot
    plot.setFixedSize(640, 360)
    plot.getPlotItem().getAxis("left").setWidth(48)
    plot.getPlotItem().getAxis("bottom").setHeight(36)
    ed.resize(1000, 520)
    ed.show()
    qtbot.waitExposed(ed)
    ctx.set_frame(20)
    ctx.select_channels(["hero//y"])
    ed.view.set_selection({"hero//x": [1], "hero//y": [2]})
    ed.view.vb.setRange(xRange=(-10, 100), yRange=(-1.6, 2.6), padding=0)
    QApplication.processEvents()
    return grab_data_area(ed), ed


def grab_data_area(ed: CurveEditor) -> QImage:
    rect = ed.view.vb.sceneBoundingRect().toRect().intersected(QRect(0, 0, 640, 360))
    return ed.plot.grab().toImage().copy(rect)


def test_rendered_view_matches_reference(qtbot, tmp_path):
    image, _ed = render_view(qtbot)
    if os.environ.get("QTANIMATOR_UPDATE_REFERENCES"):
        REFERENCE.parent.mkdir(parents=True, exist_ok=True)
        assert image.save(str(REFERENCE))
        pytest.skip(f"reference written to {REFERENCE}")
    assert REFERENCE.is_file(), "no reference image: run with QTANIMATOR_UPDATE_REFERENCES=1"
    actual = _image_array(image)
    expected = _image_array(QImage(str(REFERENCE)))
    assert actual.shape == expected.shape
    diff = np.abs(actual.astype(np.int16) - expected.astype(np.int16)).max(axis=2)
    different = float(np.mean(diff > PIXEL_THRESHOLD))
    if different > MAX_DIFFERENT:
        image.save(str(tmp_path / "actual.png"))
        QImage(np.ascontiguousarray(np.repeat((diff > PIXEL_THRESHOLD)[..., None] * 255, 3, axis=2)
                                    .astype(np.uint8)).data, diff.shape[1], diff.shape[0], diff.shape[1] * 3,
               QImage.Format.Format_RGB888).save(str(tmp_path / "diff.png"))
    assert different <= MAX_DIFFERENT, f"{different:.2%} of pixels differ; see {tmp_path}"
    # The comparison can fail: the image is not blank and a one-key change shows.
    assert actual.std() > 5


def test_image_comparison_detects_a_changed_key(qtbot):
    """Guards the tolerance: moving one key by a few frames must exceed it."""
    if not REFERENCE.is_file():
        pytest.skip("no reference image")
    image, ed = render_view(qtbot)
    set_channels(ed.ctx.doc, {"hero//y": ed.ctx.doc.channels["hero//y"].replace_keys({1: Key(0.7, 0.2)})})
    ed.view.refresh_all()
    QApplication.processEvents()
    moved = grab_data_area(ed)
    a, b = _image_array(image), _image_array(moved)
    assert float(np.mean(np.abs(a.astype(np.int16) - b.astype(np.int16)).max(axis=2) > PIXEL_THRESHOLD)) \
        > MAX_DIFFERENT
