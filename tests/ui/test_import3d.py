"""Opening 3D files in the window (File > Open, drag and drop) and File > Export glTF…."""

from __future__ import annotations

import numpy as np
import pytest
from docfix import set_parameters
from PySide6.QtCore import QMimeData, QPointF, Qt, QUrl
from PySide6.QtGui import QAction, QDropEvent

from qtanimator.document.character3d import ASSET_KIND, character, skinned_mesh
from qtanimator.formats.gltf import import_gltf
from qtanimator.ui.main_window import MainWindow


@pytest.fixture(autouse=True)
def private_settings(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("QTANIMATOR_SETTINGS_DIR", str(tmp_path_factory.mktemp("settings")))


@pytest.fixture
def window(qtbot):
    w = MainWindow()
    qtbot.addWidget(w)
    return w


def _opened(window, path, dialog_log):
    before = window.doc.state()
    count = window.ctx.undo_stack.count()
    assert window.open_path(path), dialog_log
    assert window.ctx.undo_stack.count() == count + 1  # one undo step
    added = [a for a in window.doc.assets.values() if a.kind == ASSET_KIND]
    return before, added[-1].id


@pytest.mark.parametrize("rel", [
    "cse169/wasp_walk/wasp.skel",
    "mit6837/Model1.skel",
    "mit6837/Model2.obj",
    "bvh/cmu_12_01_walk.bvh",
    "gltf/CesiumMan.glb",
    "gltf/SimpleSkin.gltf",
])
def test_open_3d_file_adds_a_character_and_undo_removes_it(window, shared_data, dialog_log, rel):
    before, aid = _opened(window, shared_data / rel, dialog_log)
    assert dialog_log == []
    assert aid in window.doc.runtime
    # shown: the 3D tab is current, the character selected
    assert window.central_tabs.currentWidget() is window.viewport_panel
    assert window.ctx.selection[0] == aid
    window.action_undo.trigger()
    assert window.doc.state() == before
    window.action_redo.trigger()
    assert aid in window.doc.assets


def test_wasp_opens_with_skin_and_walk(window, shared_data, dialog_log):
    _before, aid = _opened(window, shared_data / "cse169" / "wasp_walk" / "wasp.skel", dialog_log)
    props = window.doc.assets[aid].properties
    assert props["skin_file"].endswith("wasp.skin") and props["anim_file"].endswith("wasp_walk.anim")
    assert any("wasp_walk.anim" in n for n in window.last_import_notes)


def test_skin_then_anim_on_selected_character(window, shared_data, dialog_log):
    _before, aid = _opened(window, shared_data / "cse169" / "skeleton" / "wasp.skel", dialog_log)
    assert character(window.doc, aid).skin is None
    folder = shared_data / "cse169" / "wasp_walk"
    assert window.open_path(folder / "wasp.skin")
    assert character(window.doc, aid).skin is not None
    assert window.open_path(folder / "wasp_walk.anim")
    assert window.doc.assets[aid].properties["anim_file"].endswith("wasp_walk.anim")
    assert dialog_log == []
    window.action_undo.trigger()
    assert "anim_file" not in window.doc.assets[aid].properties


def test_anim_without_character_shows_an_error(window, shared_data, dialog_log):
    before = window.doc.state()
    assert not window.open_path(shared_data / "cse169" / "wasp_walk" / "wasp_walk.anim")
    assert dialog_log and "3D character" in dialog_log[-1][1]
    assert window.doc.state() == before
    assert window.ctx.undo_stack.count() == 0


@pytest.mark.parametrize("name,text", [
    ("broken.skel", "balljoint root { offset 0 0 }"),
    ("broken.bvh", "HIERARCHY\nROOT hips {\n OFFSET 0 0 0\n"),
    ("broken.glb", "glTF but not really"),
    ("broken.obj", "v 0 0 0\nf 1 2 3\n"),
    ("broken.skin", "positions 2 { 0 0 0 }"),
])
def test_bad_file_shows_error_and_leaves_document(window, tmp_path, dialog_log, name, text):
    path = tmp_path / name
    path.write_text(text)
    before = window.doc.state()
    assert not window.open_path(path)
    assert dialog_log and dialog_log[-1][0] == "Cannot open file"
    assert window.doc.state() == before
    assert window.ctx.undo_stack.count() == 0


def test_save_and_reopen_keeps_imported_assets(window, shared_data, tmp_path, dialog_log):
    for rel in ("cse169/wasp_walk/wasp.skel", "mit6837/Model1.skel", "bvh/fairmotion_sinusoidal.bvh",
                "gltf/RiggedSimple.glb"):
        window.ctx.select("", "")
        assert window.open_path(shared_data / rel), dialog_log
    project = tmp_path / "scene.qtanim"
    state = window.doc.state()
    assert window.save_to(project)
    assert window.doc.state() == state  # saving stores only view state (the 3D camera)
    assert "view3d.camera" in window.doc.view_state
    assert window.open_path(project)
    assert window.doc.state() == state
    for aid, asset in window.doc.assets.items():
        assert asset.kind == ASSET_KIND and aid in window.doc.runtime
    gl = [a for a in window.doc.assets if a.startswith("RiggedSimple")][0]
    assert skinned_mesh(window.doc, gl, 1.0)[0].shape[0] > 0


def test_drop_a_bvh_file(window, shared_data, dialog_log):
    mime = QMimeData()
    mime.setUrls([QUrl.fromLocalFile(str(shared_data / "bvh" / "fairmotion_sinusoidal.bvh"))])
    event = QDropEvent(QPointF(10, 10), Qt.DropAction.CopyAction, mime, Qt.MouseButton.LeftButton,
                       Qt.KeyboardModifier.NoModifier)
    window.dropEvent(event)
    assert [a.id for a in window.doc.assets.values()] == ["fairmotion_sinusoidal"]
    assert dialog_log == []


def test_export_gltf_action_and_round_trip(window, shared_data, tmp_path, dialog_log, monkeypatch):
    action = window.findChild(QAction, "actionExportGltf")
    assert action is not None and action in window.file_menu.actions()
    _before, aid = _opened(window, shared_data / "cse169" / "wasp_walk" / "wasp.skel", dialog_log)
    set_parameters(window.doc, {"frame_end": 30})
    out = tmp_path / "wasp.glb"
    from PySide6.QtWidgets import QFileDialog

    monkeypatch.setattr(QFileDialog, "getSaveFileName", staticmethod(lambda *a, **k: (str(out), "")))
    action.trigger()
    assert out.is_file(), dialog_log
    scene = import_gltf(out)
    for frame in (0, 10, 30):
        t = window.doc.frame_to_time(frame)
        ours = skinned_mesh(window.doc, aid, t)[0]
        theirs = scene.skinned_positions(0, t)
        assert np.abs(ours - theirs).max() <= 1e-4 * np.linalg.norm(np.ptp(ours, axis=0))
    assert all(title == "glTF export" for title, _ in dialog_log)


def test_export_gltf_shows_its_messages(window, shared_data, tmp_path, dialog_log):
    from qtanimator.ui.import3d import export_gltf_to

    _before, aid = _opened(window, shared_data / "mit6837" / "Model1.skel", dialog_log)
    # MIT weights do not sum to 1: the export divides them by their sum and says how far that
    # moves the mesh (every influence is kept)
    from qtanimator.document.character3d import set_dofs_command

    window.ctx.push(set_dofs_command(window.doc, aid, {(j, "x"): 0.8 for j in range(1, 10)}, 0.0))
    set_parameters(window.doc, {"frame_end": 2})
    assert export_gltf_to(window, tmp_path / "m.glb")
    assert (tmp_path / "m.glb").is_file()
    assert window.last_export_warnings == [t for title, t in dialog_log if title == "glTF export"]
    assert window.last_export_warnings and any("weight" in w for w in window.last_export_warnings)


def test_export_gltf_errors(window, shared_data, tmp_path, dialog_log):
    from qtanimator.ui.import3d import export_gltf_to

    assert not export_gltf_to(window, tmp_path / "none.glb")
    assert dialog_log[-1][0] == "Cannot export glTF"
    assert window.open_path(shared_data / "bvh" / "fairmotion_sinusoidal.bvh")
    assert not export_gltf_to(window, tmp_path / "bvh.glb")  # a skeleton without a skin
    assert "no skin" in dialog_log[-1][1]
    assert not (tmp_path / "bvh.glb").exists()


@pytest.mark.gl
@pytest.mark.parametrize("rel", ["bvh/cmu_12_01_walk.bvh", "gltf/CesiumMan.glb", "cse169/wasp_walk/wasp.skel"])
def test_opened_character_is_framed_in_the_3d_view(qtbot, shared_data, dialog_log, rel):
    w = MainWindow()
    qtbot.addWidget(w)
    w.resize(640, 480)
    w.show()
    qtbot.waitExposed(w)
    view = w.viewport3d
    w.viewport_panel.grid.setChecked(False)
    w.central_tabs.setCurrentWidget(w.viewport_panel)
    empty = view.render_image().astype(int)
    assert w.open_path(shared_data / rel), dialog_log
    img = view.render_image().astype(int)
    changed = np.any(np.abs(img - empty)[..., :3] > 8, axis=-1)
    # the character draws (a BVH skeleton as spheres and bones) and was framed: it spans a
    # good part of the view's height
    assert changed.mean() > 0.003, changed.mean()
    rows = np.flatnonzero(changed.any(axis=1))
    assert (rows[-1] - rows[0]) > 0.4 * changed.shape[0]
    assert view.last_error == ""


def test_a_clip_at_another_rate_is_offered_in_the_status_bar(window, tmp_path, dialog_log):
    from PySide6.QtWidgets import QPushButton
    from samples import write_bvh

    doc = window.doc
    doc.apply_channel("other/j/x", _two_keys())  # a document with keys: the rate is only offered
    assert window.open_path(write_bvh(tmp_path / "fast.bvh", 121))
    assert doc.fps == 60 and dialog_log == []
    button = window.statusBar().findChild(QPushButton, "adoptClipFps")
    assert button is not None and "120" in button.text()
    count = window.ctx.undo_stack.count()
    button.click()
    assert doc.fps == 120 and window.ctx.undo_stack.count() == count + 1
    assert window.fps_offer_button is None


def _two_keys():
    from qtanimator.core.channel import Channel, Key

    return Channel([Key(0.0, 0.0), Key(1.0, 1.0)])


def test_the_rate_offer_expiring_after_its_window_closed_raises_nothing(qtbot, monkeypatch, tmp_path):
    """The offer's expiry timer once fired into a deleted window (RuntimeError in the Qt event
    loop, seen in CI): it now belongs to the button and dies with the window."""
    from qtanimator.ui import import3d as ui_import3d
    from qtanimator.ui.main_window import MainWindow

    monkeypatch.setattr(ui_import3d, "OFFER_MS", 50)
    w = MainWindow(install_editors=False)
    w.show()
    ui_import3d.offer_fps(w, 120.0)
    assert w.fps_offer_button is not None
    w.close()
    w.deleteLater()
    qtbot.wait(200)  # past the expiry: pytest-qt fails the test on an exception in the event loop
