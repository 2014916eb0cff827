"""The 2D QPainter renderer: pixels, draw order, highlight, bounds, moving pendulums."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PySide6.QtCore import QRectF
from PySide6.QtGui import QColor, QImage, QPainter

from qtanimator.core.rig2d import Character, Joint, Shape
from qtanimator.document import Document
from qtanimator.document.character2d import add_characters_command, character, evaluate_pose
from qtanimator.render.painter2d import (
    draw_character,
    fit_transform,
    image_to_array,
    render_frame,
    scene_bounds,
)

SCENES = Path(__file__).resolve().parents[2] / "scenes"


def box(x0: float, y0: float, x1: float, y1: float, rgba: tuple[float, float, float, float]) -> Shape:
    return Shape(np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=float), True, fill=rgba)


def two_boxes() -> Character:
    return Character("boxes", [
        Joint("red", None, np.array([0.0, 0.0]), shapes=[box(0, 0, 40, 40, (1, 0, 0, 1))]),
        Joint("blue", 0, np.array([20.0, 20.0]), shapes=[box(20, 20, 60, 60, (0, 0, 1, 1))]),
    ])


def paint(ch: Character, angles: list[float], **kw: object) -> np.ndarray:
    img = QImage(80, 80, QImage.Format.Format_ARGB32_Premultiplied)
    img.fill(QColor("white"))
    p = QPainter(img)
    draw_character(p, ch, ch.pose(angles, (0, 0)), **kw)  # type: ignore[arg-type]
    p.end()
    return image_to_array(img)


def test_children_cover_parents_and_rotation_sense(qapp) -> None:  # type: ignore[no-untyped-def]
    ch = two_boxes()
    a = paint(ch, [0.0, 0.0])
    assert tuple(a[30, 30, :3]) == (0, 0, 255)  # overlap: the child is drawn on top
    assert tuple(a[10, 10, :3]) == (255, 0, 0)
    assert tuple(a[70, 70, :3]) == (255, 255, 255)
    # +90° turns the child counter-clockwise on screen about (20, 20): it now lies up-right
    b = paint(ch, [0.0, np.pi / 2])
    assert tuple(b[10, 30, :3]) == (0, 0, 255)
    assert tuple(b[30, 30, :3]) == (255, 0, 0)


def test_highlight_and_opacity(qapp) -> None:  # type: ignore[no-untyped-def]
    ch = two_boxes()
    lit = paint(ch, [0.0, 0.0], highlight=0)
    assert tuple(lit[10, 10, :3]) == (128, 128, 128)  # (1, 0, 0) + 0.5 wrapped at 1: (0.5, 0.5, 0.5)
    faint = paint(ch, [0.0, 0.0], opacity=0.5)
    assert 120 <= faint[10, 10, 1] <= 135
    tinted = paint(ch, [0.0, 0.0], tint=QColor(0, 255, 0, 255))
    assert tuple(tinted[10, 10, :3]) == (0, 255, 0)


def test_fit_transform_keeps_aspect_and_centres() -> None:
    t = fit_transform(QRectF(0, 0, 100, 50), (200, 200), margin=0.0)
    r = t.mapRect(QRectF(0, 0, 100, 50))
    assert r.width() == pytest.approx(200) and r.height() == pytest.approx(100)
    assert r.center().x() == pytest.approx(100) and r.center().y() == pytest.approx(100)


def _clock_doc() -> Document:
    doc = Document()
    add_characters_command(doc, SCENES / "pendulum_clock.svg").do(doc)
    return doc


def test_render_frame_fits_content_and_the_pendulum_moves(qapp, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    doc = _clock_doc()
    view = scene_bounds(doc, 0.0)
    assert view.width() > 100 and view.height() > 300
    frames = [image_to_array(render_frame(doc, f / 60, (200, 300), view=view)) for f in (0, 20, 40)]
    for a in frames:
        assert a.shape == (300, 200, 4)
        ink = np.argwhere(np.any(a[..., :3] < 200, axis=2))
        # content fills the frame (fit to content) but stays inside it
        assert ink[:, 0].min() < 30 and ink[:, 0].max() > 270
    assert np.abs(frames[0].astype(int) - frames[1].astype(int)).sum() > 1000
    assert np.abs(frames[1].astype(int) - frames[2].astype(int)).sum() > 1000
    # the case, hands and face do not move: the top half stays the same
    assert np.array_equal(frames[0][:120], frames[1][:120])
    render_frame(doc, 0.5, (200, 300)).save(str(tmp_path / "clock.png"))
    assert (tmp_path / "clock.png").stat().st_size > 1000


def test_transparent_background(qapp) -> None:  # type: ignore[no-untyped-def]
    doc = _clock_doc()
    a = image_to_array(render_frame(doc, 0.0, (100, 100), background="transparent"))
    assert a[0, 0, 3] == 0 and a[..., 3].max() == 255
    with pytest.raises(ValueError):
        render_frame(doc, 0.0, (100, 100), background="not-a-colour")


def test_sample_character_renders(qapp, shared_data: Path) -> None:  # type: ignore[no-untyped-def]
    doc = Document()
    add_characters_command(doc, shared_data / "cmu-animator" / "scenes" / "character.svg").do(doc)
    ch = character(doc, "character")
    pose = evaluate_pose(doc, "character", 0.0)
    a = image_to_array(render_frame(doc, 0.0, (240, 240)))
    # yellow head at the top centre
    r, g, b = a[35, 120, :3]
    assert r > 200 and g > 150 and b < 120
    assert ch.hit_test(pose, ch.rest_pivots[0]) is not None
