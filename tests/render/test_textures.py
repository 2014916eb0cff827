"""Texture images on skins, compared in pixels (Mesa under the private Xvfb): a ``.skin``
material's image, glTF's baseColorTexture, the checkerboard for a missing image, and a
``.skin`` opened without a skeleton."""

from __future__ import annotations

import dataclasses
import shutil
from pathlib import Path

import numpy as np
import pytest

from qtanimator.document.character3d import character
from qtanimator.document.commands import UndoStack
from qtanimator.document.document import Document
from qtanimator.document.import3d import import_file
from qtanimator.render.gl.camera import OrbitCamera
from qtanimator.render.gl.renderer import ViewOptions

pytestmark = pytest.mark.gl

SIZE = (200, 200)
#: a background no sample's pixels have (pure cyan)
BG = np.array([0, 255, 255])
PLAIN = ViewOptions(show_grid=False, show_lights=False, show_skeleton=False, background=(0, 1, 1, 1))


def _open(path: Path) -> tuple[Document, str]:
    doc = Document()
    imp = import_file(doc, path)
    UndoStack(doc).push(imp.command)
    return doc, imp.asset_id


def _render(doc: Document, azimuth: float = 0.0) -> np.ndarray:
    from qtanimator.render import scene3d
    from qtanimator.render.render3d import render_frames_3d

    bounds = scene3d.scene_bounds(scene3d.scene_items(doc, 0.0))
    assert bounds is not None
    centre, extent = (bounds[0] + bounds[1]) / 2, float(np.linalg.norm(bounds[1] - bounds[0]))
    camera = OrbitCamera(azimuth=azimuth, inclination=10.0, distance=1.5 * extent, target=centre)
    return next(iter(render_frames_3d(doc, [0.0], SIZE, camera=camera, options=PLAIN)))[..., :3].astype(int)


def _covered(img: np.ndarray) -> np.ndarray:
    return np.abs(img - BG).max(axis=-1) > 3


def _inner(img: np.ndarray) -> np.ndarray:
    """Covered pixels whose 8 neighbours are covered too (no edge blended with the background)."""
    c = _covered(img)
    out = c.copy()
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            out &= np.roll(np.roll(c, dy, axis=0), dx, axis=1)
    return out


def _colours(img: np.ndarray) -> int:
    px = img[_inner(img)] // 8          # ignore shading noise below 8 levels
    return len(np.unique(px, axis=0))


@pytest.fixture
def head_alone(shared_data, tmp_path) -> Path:
    for name in ("head_tex.skin", "head.bmp"):
        shutil.copy(shared_data / "cse169" / "head" / name, tmp_path / name)
    return tmp_path / "head_tex.skin"


def test_a_textured_head_shows_its_texture(qapp, head_alone):
    doc, aid = _open(head_alone)
    textured = _render(doc)
    ch = character(doc, aid)
    doc.runtime[aid] = dataclasses.replace(ch, texture=None)
    plain = _render(doc)
    assert _covered(textured).mean() > 0.08
    assert np.array_equal(_covered(textured), _covered(plain))    # the same mesh, drawn the same
    # the face texture: skin tones and dark hair, many colours; the plain skin is one hue
    assert _colours(textured) > 1.5 * _colours(plain)
    inner = _inner(textured)
    assert np.abs(textured - plain)[inner].mean() > 20
    px = textured[inner]
    assert (px.sum(axis=1) < 60).mean() > 0.05          # the hair is dark
    assert (plain[inner].sum(axis=1) < 60).mean() < 0.01
    assert (px[:, 0] > px[:, 2] + 20).mean() > 0.2       # skin is red over blue


def test_cesium_man_shows_his_texture(qapp, shared_data):
    doc, aid = _open(shared_data / "gltf" / "CesiumMan.glb")
    textured = _render(doc, azimuth=90.0)
    ch = character(doc, aid)
    doc.runtime[aid] = dataclasses.replace(ch, parts=[dataclasses.replace(p, texture=None) for p in ch.parts])
    flat = _render(doc, azimuth=90.0)
    assert np.array_equal(_covered(textured), _covered(flat))
    assert _colours(textured) > 2 * _colours(flat)
    px = textured[_inner(textured)]
    blue = (px[:, 2] > px[:, 0] + 40).mean()      # the blue stripes of the Cesium texture
    green = ((px[:, 1] > px[:, 2] + 10) & (px[:, 1] > px[:, 0] + 30)).mean()   # and its green ones
    assert blue > 0.03 and green > 0.002
    fp = flat[_inner(flat)]
    assert (fp[:, 2] > fp[:, 0] + 40).mean() < blue / 10


def _quad_skin(folder: Path, texture: str) -> Path:
    """A unit square facing +z with texture coordinates 0…1 and a material naming ``texture``."""
    text = f"""positions 4 {{ 0 0 0  1 0 0  1 1 0  0 1 0 }}
normals 4 {{ 0 0 1  0 0 1  0 0 1  0 0 1 }}
texcoords 4 {{ 0 0  1 0  1 1  0 1 }}
material square {{ texture {texture} }}
triangles 2 {{ 0 1 2  0 2 3 }}
"""
    path = folder / "square.skin"
    path.write_text(text)
    return path


def test_a_missing_image_draws_the_checkerboard(qapp, tmp_path):
    doc, _aid = _open(_quad_skin(tmp_path, "missing.png"))
    img = _render(doc)
    cover = _covered(img)
    assert cover.mean() > 0.2
    px = img[cover]
    magenta = (px[:, 0] > px[:, 1] + 40) & (px[:, 2] > px[:, 1] + 40)
    grey = np.abs(px[:, 0] - px[:, 1]) < 12
    assert magenta.mean() > 0.3 and grey.mean() > 0.3
    # alternating along a row through the middle: 8 cells, so several switches
    row = img[SIZE[1] // 2]
    on = row[_covered(row[None])[0]]
    kind = on[:, 0] > on[:, 1] + 40
    assert int(np.count_nonzero(np.diff(kind.astype(int)))) >= 5


def test_an_undecodable_image_draws_the_checkerboard_too(qapp, tmp_path):
    (tmp_path / "broken.png").write_bytes(b"\x89PNG\r\n\x1a\nnot really")
    doc, _aid = _open(_quad_skin(tmp_path, "broken.png"))
    px = _render(doc)
    px = px[_covered(px)]
    assert ((px[:, 0] > px[:, 1] + 40) & (px[:, 2] > px[:, 1] + 40)).mean() > 0.3


def test_an_image_beside_the_skin_is_drawn(qapp, tmp_path):
    from PySide6.QtGui import QColor, QImage

    image = QImage(16, 16, QImage.Format.Format_RGB32)
    image.fill(QColor(20, 200, 40))
    assert image.save(str(tmp_path / "green.png"))
    doc, _aid = _open(_quad_skin(tmp_path, "green.png"))
    px = _render(doc)
    px = px[_covered(px)]
    assert ((px[:, 1] > px[:, 0] + 60) & (px[:, 1] > px[:, 2] + 60)).mean() > 0.95


def test_a_skin_only_file_draws(qapp, shared_data):
    doc, aid = _open(shared_data / "cse169" / "skin" / "tube.skin")
    assert len(character(doc, aid).skeleton.joints) == 1
    img = _render(doc)
    assert 0.05 < _covered(img).mean() < 0.95
