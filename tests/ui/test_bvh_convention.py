"""Properties: a BVH character's position convention is switchable, one undo step (issue 21)."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtWidgets import QComboBox
from samples import BLENDER_BVH

from qtanimator.document.character3d import BVH_POSITIONS, world_matrices
from qtanimator.ui.main_window import MainWindow


@pytest.fixture(autouse=True)
def private_settings(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("QTANIMATOR_SETTINGS_DIR", str(tmp_path_factory.mktemp("settings")))

# Blender-style: 6 channels per joint, the root's first position equal to its OFFSET.
ABSOLUTE = BLENDER_BVH


def test_switching_the_convention_is_one_undo_step_and_moves_the_character(qtbot, tmp_path, dialog_log):
    path = tmp_path / "blender_walk.bvh"
    path.write_text(ABSOLUTE)
    window = MainWindow()  # as tests/ui/test_import3d.py: real widgets, the 3D importer installed
    qtbot.addWidget(window)
    assert window.open_path(path), dialog_log
    doc, ctx = window.doc, window.ctx
    asset = next(a for a in doc.assets if doc.assets[a].source.endswith("blender_walk.bvh"))
    ctx.select(asset, "")
    combo = window.properties_panel.findChild(QComboBox, "bvhPositions")
    assert combo is not None and combo.currentText() == "absolute"  # detected
    root_before = world_matrices(doc, asset, 0.0)[:, :3, 3].copy()
    np.testing.assert_allclose(root_before[:, 1], [10.0, 5.0])  # the feet (Leg) stand at y = 0 - its End Site
    steps = ctx.undo_stack.count()

    combo.setCurrentText("relative")

    qtbot.waitUntil(lambda: ctx.undo_stack.count() == steps + 1)
    assert doc.assets[asset].properties[BVH_POSITIONS] == "relative"
    after = world_matrices(doc, asset, 0.0)[:, :3, 3]
    # Relative: the positions add to the OFFSETs, so every joint moves up by the root's
    # OFFSET and the leg by its own OFFSET again.
    np.testing.assert_allclose(after[0], root_before[0] + [0.0, 10.0, 0.0])
    np.testing.assert_allclose(after[1] - after[0], 2 * (root_before[1] - root_before[0]))
    combo = window.properties_panel.findChild(QComboBox, "bvhPositions")
    assert combo.currentText() == "relative"

    ctx.undo_stack.undo()
    np.testing.assert_allclose(world_matrices(doc, asset, 0.0)[:, :3, 3], root_before)
    assert doc.assets[asset].properties[BVH_POSITIONS] == "absolute"  # as detected at import
    assert window.properties_panel.findChild(QComboBox, "bvhPositions").currentText() == "absolute"
    ctx.undo_stack.redo()
    np.testing.assert_allclose(world_matrices(doc, asset, 0.0)[:, :3, 3], after)
