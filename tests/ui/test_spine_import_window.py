"""A Spine animation opened in the window: File ▸ Open of a Spine ``.json`` (and the Import
Spine Animation action) puts it onto the 2D character as one undo step; a project ``.json``
still opens as a project; a file that cannot go anywhere shows a message and changes nothing."""

from __future__ import annotations

import json
import math

import pytest

from qtanimator.document.character2d import character, evaluate_pose, key_joint
from qtanimator.document.spine_export import write_spine_json
from qtanimator.ui.main_window import MainWindow


@pytest.fixture(autouse=True)
def private_settings(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("QTANIMATOR_SETTINGS_DIR", str(tmp_path_factory.mktemp("settings")))


@pytest.fixture
def window(qtbot):
    w = MainWindow()
    qtbot.addWidget(w)
    return w


def _arm(window, shared_data, dialog_log) -> str:
    assert window.open_path(shared_data / "cmu-animator" / "scenes" / "arm.svg"), dialog_log
    return next(a.id for a in window.doc.assets.values() if a.kind == "character2d")


def test_open_spine_json_keys_the_character_as_one_undo_step(window, shared_data, dialog_log, tmp_path):
    aid = _arm(window, shared_data, dialog_log)
    doc = window.doc
    joints = [j.name for j in character(doc, aid).joints]
    # an animation made by the export of a posed copy: joint 1 at 0.7 rad at frame 20
    window.ctx.push(key_joint(doc, aid, 1, 0.7, 20 / doc.fps))
    posed = evaluate_pose(doc, aid, 20 / doc.fps)
    path = tmp_path / "arm_anim.json"
    write_spine_json(doc, aid, path)
    window.action_undo.trigger()  # the character unposed again
    before = doc.state()
    assert evaluate_pose(doc, aid, 20 / doc.fps).world_angles[1] != pytest.approx(posed.world_angles[1])
    index = window.ctx.undo_stack.index()
    assert window.open_path(path), dialog_log
    assert dialog_log == []
    assert window.ctx.undo_stack.index() == index + 1  # one undo step
    got = evaluate_pose(doc, aid, 20 / doc.fps)
    assert got.world_angles[1] == pytest.approx(posed.world_angles[1], abs=1e-9)
    assert math.isclose(posed.world_angles[1] - posed.world_angles[0], 0.7, abs_tol=1e-9)
    assert "Spine animation" in " ".join(window.last_import_notes)
    assert any(f"/{joints[1]}/" in cid for cid in doc.channels)
    window.action_undo.trigger()
    assert doc.state() == before


def test_spine_json_without_a_character_says_so_and_changes_nothing(window, shared_data, dialog_log, tmp_path):
    aid = _arm(window, shared_data, dialog_log)
    path = tmp_path / "arm_anim.json"
    write_spine_json(window.doc, aid, path)
    window.ctx.replace_document(type(window.doc)())  # a new, empty document
    before = window.doc.state()
    assert not window.open_path(path)
    assert dialog_log and "2D character" in dialog_log[-1][-1]
    assert window.doc.state() == before


def test_a_project_json_still_opens_as_a_project(window, shared_data, dialog_log, tmp_path):
    aid = _arm(window, shared_data, dialog_log)
    path = tmp_path / "project.json"
    assert window.save_to(str(path))
    data = json.loads(path.read_text())
    assert "skeleton" not in data
    window.ctx.replace_document(type(window.doc)())
    assert window.open_path(path), dialog_log
    assert aid in window.doc.assets


def test_import_spine_action_is_in_the_file_menu(window):
    assert window.action_import_spine.objectName() == "actionImportSpine"
    assert window.action_import_spine in window.file_menu.actions()


def test_export_spine_writes_json_and_images(window, shared_data, dialog_log, tmp_path):
    from qtanimator.ui.spine import export_spine_to

    aid = _arm(window, shared_data, dialog_log)
    out = tmp_path / "arm.json"
    assert export_spine_to(window, out), dialog_log
    data = json.loads(out.read_text())
    assert [b["name"] for b in data["bones"]][1:] == [j.name for j in character(window.doc, aid).joints]
    pngs = sorted(p.name for p in (tmp_path / "images").iterdir())
    assert pngs and all(p.endswith(".png") for p in pngs)
    assert window.action_export_spine in window.file_menu.actions()
