"""Placing characters in the window (issue 14 item 2): imports land beside each other, the
view frames them, the Properties fields edit the placement as undoable commands."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QDoubleSpinBox

from qtanimator.document import character2d as c2d
from qtanimator.document import character3d as c3d
from qtanimator.document.placement import PLACEMENT, boxes_overlap
from qtanimator.ui.main_window import MainWindow


@pytest.fixture(autouse=True)
def private_settings(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("QTANIMATOR_SETTINGS_DIR", str(tmp_path_factory.mktemp("settings")))


@pytest.fixture
def window(qtbot):
    w = MainWindow()
    qtbot.addWidget(w)
    w.resize(1200, 800)
    w.show()
    qtbot.waitExposed(w)
    return w


def _type(qtbot, box: QDoubleSpinBox, text: str) -> None:
    box.setFocus()
    qtbot.keyClick(box, Qt.Key.Key_A, Qt.KeyboardModifier.ControlModifier)
    qtbot.keyClicks(box, text)
    qtbot.keyClick(box, Qt.Key.Key_Return)
    qtbot.wait(20)  # the command is pushed after the field's signal returns


def test_3d_imports_land_beside_each_other_and_are_framed(window, qtbot, shared_data, dialog_log):
    ids = []
    for rel in ("cse169/wasp_walk/wasp.skel", "gltf/CesiumMan.glb", "bvh/cmu_12_01_walk.bvh"):
        assert window.open_path(shared_data / rel), dialog_log
        ids.append(window.ctx.selection[0])
        # the view frames the new character: the camera looks at its box
        lo, hi = c3d.bounds(window.doc, ids[-1], window.ctx.time)
        target = np.asarray(window.viewport3d.camera.target, dtype=float)
        assert np.all(target >= lo - 1e-6) and np.all(target <= hi + 1e-6)
    boxes = [c3d.bounds(window.doc, aid, window.ctx.time) for aid in ids]
    for i in range(3):
        for j in range(i + 1, 3):
            assert not boxes_overlap(boxes[i], boxes[j])
    heights = [float(b[1][1] - b[0][1]) for b in boxes]
    assert max(heights) / min(heights) < 1.1


def test_properties_fields_place_a_3d_character(window, qtbot, shared_data, dialog_log):
    assert window.open_path(shared_data / "cse169" / "wasp_walk" / "wasp.skel"), dialog_log
    assert window.ctx.selection[0] == "wasp"
    box = window.findChild(QDoubleSpinBox, "placementTranslateX")
    assert box is not None and box.isVisible()
    before = c3d.world_matrices(window.doc, "wasp", 0.0)
    count = window.ctx.undo_stack.count()
    _type(qtbot, box, "3")
    assert window.doc.assets["wasp"].properties[PLACEMENT]["translate"] == [3.0, 0.0, 0.0]
    assert window.ctx.undo_stack.count() == count + 1
    after = c3d.world_matrices(window.doc, "wasp", 0.0)
    assert np.allclose(after[:, :3, 3], before[:, :3, 3] + [3.0, 0.0, 0.0])
    scale = window.findChild(QDoubleSpinBox, "placementScale")
    _type(qtbot, scale, "2")
    assert window.doc.assets["wasp"].properties[PLACEMENT]["scale"] == 2.0
    window.action_undo.trigger()
    assert window.doc.assets["wasp"].properties[PLACEMENT]["scale"] == 1.0
    # the field shows the document after undo
    assert window.findChild(QDoubleSpinBox, "placementScale").value() == 1.0
    window.action_undo.trigger()
    assert PLACEMENT not in window.doc.assets["wasp"].properties


def test_svg_characters_land_side_by_side_and_fit(window, qtbot, shared_data, dialog_log):
    scenes = shared_data / "cmu-animator" / "scenes"
    assert window.open_path(scenes / "arm.svg"), dialog_log
    assert window.open_path(scenes / "pencil.svg"), dialog_log
    a, b = c2d.character_assets(window.doc)
    ba, bb = c2d.shown_bounds(window.doc, a), c2d.shown_bounds(window.doc, b)
    assert bb[0] > ba[2]  # disjoint: the new one to the right
    view = window.rig_editor.view
    shown = view.mapToScene(view.viewport().rect()).boundingRect()
    for x0, y0, x1, y1 in (ba, bb):
        assert shown.left() <= x0 and x1 <= shown.right() and shown.top() <= y0 and y1 <= shown.bottom()
    # the 2D fields move the character
    window.ctx.select(b, "")
    qtbot.wait(10)
    box = window.findChild(QDoubleSpinBox, "placementRotate")
    assert box is not None
    _type(qtbot, box, "90")
    assert window.doc.assets[b].properties[PLACEMENT]["rotate"] == 90.0
