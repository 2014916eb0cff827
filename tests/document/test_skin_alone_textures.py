"""Issue 14 item 4: a ``.skin`` alone, texture images from ``.skin`` materials and glTF, and
glTF export of textures (Qt-free: the render layer decodes; see tests/render/test_textures.py)."""

from __future__ import annotations

import io
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

from qtanimator.core.skinning import skin_positions
from qtanimator.document.character3d import ASSET_KIND, character, load_character3d_asset
from qtanimator.document.commands import UndoStack
from qtanimator.document.document import Document
from qtanimator.document.gltf_character import character_from_gltf
from qtanimator.document.import3d import export_gltf, import_file
from qtanimator.formats.gltf import import_gltf
from qtanimator.formats.skin import load_skin

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import gltf_validator  # noqa: E402


def _open(path: Path) -> tuple[Document, UndoStack, str, list[str]]:
    doc = Document()
    stack = UndoStack(doc)
    imp = import_file(doc, path)
    stack.push(imp.command)
    return doc, stack, imp.asset_id, imp.notes


@pytest.fixture
def head_alone(shared_data, tmp_path) -> Path:
    """head_tex.skin and its image in a folder without head_tex.skel."""
    for name in ("head_tex.skin", "head.bmp"):
        shutil.copy(shared_data / "cse169" / "head" / name, tmp_path / name)
    return tmp_path / "head_tex.skin"


@pytest.mark.parametrize("name", ["skin/tube.skin", "skin/wasp.skin", "skin/triangle.skin"])
def test_a_skin_without_a_skeleton_opens_in_its_bind_pose(shared_data, name):
    path = shared_data / "cse169" / name
    doc, stack, aid, notes = _open(path)
    ch = character(doc, aid)
    assert doc.assets[aid].kind == ASSET_KIND and doc.assets[aid].source == str(path.resolve())
    assert len(ch.skeleton.joints) == 1 and np.allclose(ch.skeleton.world_matrices()[0], np.eye(4))
    stored = load_skin(path)
    assert ch.skin is not None
    posed = skin_positions(ch.skin, ch.skinning_world(ch.skeleton.world_matrices()))
    assert np.allclose(posed, stored.positions)          # the mesh as stored
    assert "bind pose" in notes[0]
    # a project reopens it from the .skin
    again = load_character3d_asset(doc.assets[aid])
    assert again.skin is not None and np.allclose(again.skin.positions, stored.positions)
    stack.undo()
    assert aid not in doc.assets


def test_a_textured_skin_dresses_the_character_there_is(shared_data):
    doc, stack, aid, _notes = _open(shared_data / "cse169" / "head" / "head.skel")
    assert character(doc, aid).texture is None
    imp = import_file(doc, shared_data / "cse169" / "head" / "head_tex.skin")
    stack.push(imp.command)
    ch = character(doc, aid)
    assert imp.asset_id == aid and Path(doc.assets[aid].source).name == "head.skel"
    assert ch.texture is not None and Path(ch.texture.path).name == "head.bmp"
    assert ch.texture.read() == (shared_data / "cse169" / "head" / "head.bmp").read_bytes()


def test_a_skin_material_texture_is_the_image_beside_the_skin(head_alone):
    doc, _stack, aid, _notes = _open(head_alone)
    ch = character(doc, aid)
    assert ch.skin is not None and ch.skin.texcoords is not None
    assert ch.texture is not None and ch.texture.path == str(head_alone.parent / "head.bmp")
    (head_alone.parent / "head.bmp").unlink()
    assert ch.texture.read() is None          # missing: the render layer draws a checkerboard


def test_gltf_base_color_textures_embedded_and_external(shared_data, tmp_path):
    ch = character_from_gltf(import_gltf(shared_data / "gltf" / "CesiumMan.glb")).character
    (part,) = ch.parts
    assert part.texture is not None and part.texture.mime_type == "image/jpeg"
    assert part.texture.data is not None and part.texture.data[:3] == b"\xff\xd8\xff"
    assert part.color == (1.0, 1.0, 1.0, 1.0)   # no factor: the texture as it is
    # an external image inside the file's folder is a path; one outside it is not read
    scene = import_gltf(shared_data / "gltf" / "CesiumMan.glb")
    scene.images[0].data, scene.images[0].uri = None, "tex%20ture.jpg"
    ext = character_from_gltf(scene, tmp_path / "man.gltf").character.parts[0].texture
    assert ext is not None and ext.path == str((tmp_path / "tex ture.jpg").resolve()) and ext.read() is None
    (tmp_path / "tex ture.jpg").write_bytes(part.texture.data)
    assert ext.read() == part.texture.data
    scene.images[0].uri = "../outside.jpg"
    assert character_from_gltf(scene, tmp_path / "man.gltf").character.parts[0].texture.path is None


def _validated(path: Path) -> None:
    report = gltf_validator.validate(path)
    assert not report.errors, "; ".join(str(e) for e in report.errors[:10])


def test_gltf_export_keeps_cesium_mans_image_and_uvs(shared_data, tmp_path):
    src = shared_data / "gltf" / "CesiumMan.glb"
    doc, _stack, aid, _notes = _open(src)
    out = tmp_path / "man.glb"
    export_gltf(doc, aid, out)
    _validated(out)
    scene = import_gltf(out)
    original = import_gltf(src)
    assert scene.images[0].data == original.images[0].data and scene.images[0].mime_type == "image/jpeg"
    assert scene.materials[0]["pbrMetallicRoughness"]["baseColorTexture"] == {"index": 0}
    back = character_from_gltf(scene, out).character
    assert back.parts[0].texture is not None and back.parts[0].texture.data == original.images[0].data
    before = character(doc, aid).skin
    assert back.skin is not None and before is not None
    assert np.allclose(back.skin.texcoords, before.texcoords, atol=1e-6)


def test_gltf_export_of_a_textured_skin_embeds_its_bmp_as_png(head_alone, tmp_path):
    PIL = pytest.importorskip("PIL.Image")
    doc, _stack, aid, _notes = _open(head_alone)
    out = tmp_path / "head.glb"
    export_gltf(doc, aid, out)
    _validated(out)
    scene = import_gltf(out)
    (image,) = scene.images
    assert image.mime_type == "image/png" and image.data is not None
    with PIL.open(io.BytesIO(image.data)) as png, PIL.open(head_alone.parent / "head.bmp") as bmp:
        assert png.size == bmp.size == (512, 512)
        assert np.array_equal(np.asarray(png.convert("RGB")), np.asarray(bmp.convert("RGB")))
    back = character_from_gltf(scene, out).character
    assert back.parts[0].texture is not None and back.parts[0].texture.data == image.data
    # v flipped to glTF's top-left origin
    skin = character(doc, aid).skin
    assert skin is not None and back.skin is not None
    assert np.allclose(back.skin.texcoords[:, 1], 1.0 - skin.texcoords[:, 1], atol=1e-6)


def test_gltf_export_leaves_out_a_missing_image(head_alone, tmp_path):
    (head_alone.parent / "head.bmp").unlink()
    doc, _stack, aid, _notes = _open(head_alone)
    out = tmp_path / "head.glb"
    export_gltf(doc, aid, out)
    _validated(out)
    scene = import_gltf(out)
    assert not scene.images and "baseColorTexture" not in scene.materials[0]["pbrMetallicRoughness"]


def test_a_skin_opens_alone_beside_a_character_that_cannot_wear_it(shared_data):
    """A glTF character cannot wear a .skin: with it the only 3D character, the skin still
    opens on its own instead of failing."""
    doc = Document()
    stack = UndoStack(doc)
    stack.push(import_file(doc, shared_data / "gltf" / "CesiumMan.glb").command)
    before = set(doc.assets)
    result = import_file(doc, shared_data / "cse169" / "skin" / "tube.skin")
    stack.push(result.command)
    assert result.asset_id not in before and len(doc.assets) == len(before) + 1
    skin = load_skin(shared_data / "cse169" / "skin" / "tube.skin")
    ch = character(doc, result.asset_id)
    assert ch.skin is not None and len(ch.skin.positions) == len(skin.positions)
