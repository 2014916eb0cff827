"""Collect Assets and relinking moved files, without Qt (qtanimator.document.asset_files, io)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from qtanimator.document import Document, UndoStack, open_document, save_document
from qtanimator.document.asset_files import (
    FileRef,
    collect_assets,
    file_refs,
    find_beside,
    gltf_external_files,
)
from qtanimator.document.commands import AddAsset
from qtanimator.document.document import Asset
from qtanimator.document.io import open_document_relinked
from qtanimator.formats.errors import FormatError
from qtanimator.formats.project import load_project

SCENES = Path(__file__).resolve().parents[2] / "scenes"


def _doc_with(tmp_path: Path) -> tuple[Document, UndoStack, Path]:
    """A 2D character from a folder of SVGs, a 3D arm (skel + skin + anim) and a cloth, all
    outside the project folder; two different files share the name "arm.skin"."""
    art = tmp_path / "art"
    (art / "chars").mkdir(parents=True)
    shutil.copy(SCENES / "flappy.svg", art / "chars" / "flappy.svg")
    shutil.copy(SCENES / "pencil.svg", art / "chars" / "pencil.svg")
    for name in ("arm.skel", "arm.skin", "arm_wave.anim"):
        shutil.copy(SCENES / "arm3d" / name, art / name)
    (art / "other").mkdir()
    (art / "other" / "arm.skin").write_text((SCENES / "arm3d" / "arm.skin").read_text() + "# another skin\n")
    doc = Document()
    stack = UndoStack(doc)
    stack.push(AddAsset(Asset("birds", "character2d", str(art / "chars"), {"index": 0})))
    stack.push(AddAsset(Asset("arm", "character3d", str(art / "arm.skel"),
                              {"skin_file": str(art / "arm.skin"), "anim_file": str(art / "arm_wave.anim")})))
    stack.push(AddAsset(Asset("arm2", "character3d", str(art / "arm.skel"),
                              {"skin_file": str(art / "other" / "arm.skin")})))
    stack.push(AddAsset(Asset("flag", "cloth", None, {"rows": 4})))
    return doc, stack, art


def test_file_refs_lists_sources_and_file_properties(tmp_path):
    doc, _stack, art = _doc_with(tmp_path)
    refs = file_refs(doc.assets.values())
    assert FileRef("birds", "source", str(art / "chars")) in refs
    assert FileRef("arm", "skin_file", str(art / "arm.skin")) in refs
    assert FileRef("arm", "anim_file", str(art / "arm_wave.anim")) in refs
    assert not [r for r in refs if r.asset_id == "flag"]


def test_collect_copies_once_renames_clashes_and_undoes_as_one_step(tmp_path):
    doc, stack, art = _doc_with(tmp_path)
    before = doc.state()
    project = tmp_path / "proj"
    result = collect_assets(doc, project)
    assets = project / "assets"
    assert sorted(p.name for p in assets.iterdir()) == ["arm-2.skin", "arm.skel", "arm.skin", "arm_wave.anim",
                                                         "chars"]
    assert sorted(p.name for p in (assets / "chars").iterdir()) == ["flappy.svg", "pencil.svg"]
    assert (assets / "arm-2.skin").read_bytes() == (art / "other" / "arm.skin").read_bytes()
    assert len(result.copied) == 5  # arm.skel once, though two assets use it
    assert result.command is not None
    stack.push(result.command)
    assert doc.assets["birds"].source == str(assets / "chars")
    assert doc.assets["arm2"].source == str(assets / "arm.skel")
    assert doc.assets["arm2"].properties["skin_file"] == str(assets / "arm-2.skin")
    assert doc.assets["flag"].properties == {"rows": 4}
    assert stack.undo() and doc.state() == before  # one step
    stack.redo()
    # Collecting again copies nothing and changes nothing.
    again = collect_assets(doc, project)
    assert again.command is None and again.copied == []
    # The saved project travels: move it, delete the originals, open it.
    save_document(doc, project / "p.qtanim")
    text = (project / "p.qtanim").read_text()
    assert '"outside"' not in text and '"source": "assets/chars"' in text
    moved = Path(shutil.move(str(project), str(tmp_path / "moved")))
    shutil.rmtree(art)
    opened = open_document(moved / "p.qtanim")
    assert opened.assets["arm"].properties["skin_file"] == str((moved / "assets" / "arm.skin").resolve())
    assert {"birds", "arm", "arm2"} <= set(opened.runtime)


def test_collect_into_the_same_file_reuses_identical_copies(tmp_path):
    doc, _stack, _art = _doc_with(tmp_path)
    project = tmp_path / "proj"
    (project / "assets").mkdir(parents=True)
    shutil.copy(SCENES / "arm3d" / "arm.skel", project / "assets" / "arm.skel")  # the same bytes
    (project / "assets" / "arm.skin").write_text("someone else's file\n")  # a different file
    result = collect_assets(doc, project)
    assert str(project.resolve() / "assets" / "arm.skel") not in [c for _o, c in result.copied]
    assert (project / "assets" / "arm.skin").read_text() == "someone else's file\n"  # never overwritten
    assert result.command is not None
    new = result.command.new
    assert new["arm"].properties["skin_file"].endswith("arm-2.skin")


def test_a_gltf_is_collected_with_its_buffers_and_images(tmp_path):
    src = tmp_path / "src" / "model"
    (src / "tex").mkdir(parents=True)
    (src / "mesh.bin").write_bytes(b"\0" * 8)
    (src / "tex" / "skin color.png").write_bytes(b"png")
    gltf = src / "model.gltf"
    buffers = [{"uri": "mesh.bin", "byteLength": 8}, {"uri": "data:application/octet-stream;base64,AA=="}]
    images = [{"uri": "tex/skin%20color.png"}, {"uri": "/etc/passwd"}]
    gltf.write_text(json.dumps({"asset": {"version": "2.0"}, "buffers": buffers, "images": images}))
    assert gltf_external_files(gltf) == ["mesh.bin", "tex/skin color.png"]
    doc = Document()
    doc.assets["m"] = Asset("m", "gltf_character", str(gltf), {})
    project = tmp_path / "proj"
    result = collect_assets(doc, project)
    assert result.command is not None
    assert (project / "assets" / "model.gltf").is_file()
    assert (project / "assets" / "mesh.bin").is_file() and (project / "assets" / "tex" / "skin color.png").is_file()


def test_find_beside_searches_breadth_first_and_stops(tmp_path, monkeypatch):
    import qtanimator.document.asset_files as asset_files

    (tmp_path / "a" / "b" / "c").mkdir(parents=True)
    (tmp_path / "a" / "b" / "c" / "deep.svg").write_text("")
    (tmp_path / "z").mkdir()
    (tmp_path / "z" / "deep.svg").write_text("")
    assert find_beside("deep.svg", [tmp_path]) == (tmp_path / "z" / "deep.svg").resolve()  # shallower first
    (tmp_path / "z" / "deep.svg").unlink()
    assert find_beside("deep.svg", [tmp_path]) == (tmp_path / "a" / "b" / "c" / "deep.svg").resolve()
    monkeypatch.setattr(asset_files, "SEARCH_DEPTH", 2)
    assert find_beside("deep.svg", [tmp_path]) is None
    monkeypatch.setattr(asset_files, "SEARCH_DEPTH", 4)
    monkeypatch.setattr(asset_files, "SEARCH_LIMIT", 3)
    assert find_beside("deep.svg", [tmp_path]) is None
    assert find_beside("x.svg", [tmp_path / "missing"]) is None


def test_open_finds_moved_files_asks_for_the_rest_and_fails_when_refused(tmp_path):
    doc, _stack, art = _doc_with(tmp_path)
    project = tmp_path / "proj" / "p.qtanim"
    project.parent.mkdir()
    save_document(doc, project)
    data = load_project(project)
    assert {r.id: r.outside for r in data.assets} == {"birds": ["source"], "arm": ["source", "skin_file",
                                                                                    "anim_file"],
                                                      "arm2": ["source", "skin_file"], "flag": []}
    # The user moves the characters into the project, and the 3D files somewhere else.
    shutil.move(str(art / "chars"), str(project.parent / "chars"))
    elsewhere = tmp_path / "backup"
    shutil.move(str(art), str(elsewhere))
    asked: list[FileRef] = []

    def locate(ref: FileRef) -> str | None:
        asked.append(ref)
        return str(elsewhere / Path(ref.path).relative_to(art)) if ref.path.endswith("arm.skel") else None

    opened, relinks = open_document_relinked(project, locate)
    assert [r.how for r in relinks if r.ref.asset_id == "birds"] == ["found"]
    assert opened.assets["birds"].source == str((project.parent / "chars").resolve())
    # arm.skel asked once though two assets use it; its folder then gave the skin and anim.
    assert [Path(r.path).name for r in asked] == ["arm.skel"]
    assert opened.assets["arm"].properties["skin_file"] == str((elsewhere / "arm.skin").resolve())
    # The folder moved as a whole: other/arm.skin is found at its place in it, not by name.
    assert opened.assets["arm2"].properties["skin_file"] == str((elsewhere / "other" / "arm.skin").resolve())
    assert {"birds", "arm"} <= set(opened.runtime)
    # Nothing found, nothing chosen: the reader's error, naming the file.
    shutil.rmtree(elsewhere)
    with pytest.raises(FormatError, match="arm"):
        open_document_relinked(project, lambda ref: None)


def test_outside_must_be_a_list_of_names(tmp_path):
    doc = Document()
    path = tmp_path / "p.qtanim"
    save_document(doc, path)
    obj = json.loads(path.read_text())
    obj["assets"] = [{"id": "a", "kind": "cloth", "source": None, "properties": {}, "outside": "source"}]
    path.write_text(json.dumps(obj))
    with pytest.raises(FormatError, match="outside"):
        load_project(path)
