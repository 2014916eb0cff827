"""Cloth assets in the document: commands, undo, saving, and the per-frame simulation cache."""

from __future__ import annotations

import numpy as np
import pytest

from qtanimator.core.cloth import Cloth, ClothParams
from qtanimator.document import Document, SetParameter, UndoStack, open_document, save_document
from qtanimator.document.cloth import (
    ASSET_KIND,
    ClothCache,
    add_cloth_command,
    cloth_cache,
    cloth_params,
    cloth_problem,
    cloth_state,
    set_cloth_param_command,
)

SMALL = ClothParams(rows=8, cols=8, wind=(0.0, 0.0, 2.0), integrator="symplectic")


def make_doc(params: ClothParams = SMALL) -> tuple[Document, UndoStack, str]:
    doc = Document()
    stack = UndoStack(doc)
    stack.push(add_cloth_command(doc, params))
    (asset_id,) = doc.assets
    return doc, stack, asset_id


def direct(params: ClothParams, frames: int, dt: float = 1.0 / 60.0) -> np.ndarray:
    cloth = Cloth(params)
    for _ in range(frames):
        cloth.step(dt)
    return cloth.positions.copy()


def test_add_cloth_creates_an_asset_and_undoes() -> None:
    doc, stack, aid = make_doc()
    assert aid == "cloth"
    asset = doc.assets[aid]
    assert asset.kind == ASSET_KIND and asset.source is None
    assert asset.properties == SMALL.to_dict()
    assert cloth_params(doc, aid) == SMALL
    assert isinstance(doc.runtime[aid], ClothCache)
    stack.push(add_cloth_command(doc))
    assert set(doc.assets) == {"cloth", "cloth_2"}
    stack.undo()
    stack.undo()
    assert doc.assets == {}
    stack.redo()
    assert "cloth" in doc.assets


def test_cloth_state_matches_a_direct_simulation() -> None:
    doc, _, aid = make_doc()
    assert np.array_equal(cloth_state(doc, aid, 0), Cloth(SMALL).rest_positions)
    assert np.array_equal(cloth_state(doc, aid, 12), direct(SMALL, 12))
    assert np.array_equal(cloth_state(doc, aid, 12.7), direct(SMALL, 12))  # fractional frames round down
    assert np.array_equal(cloth_state(doc, aid, -5), Cloth(SMALL).rest_positions)


def test_cache_steps_forward_from_the_last_cached_frame() -> None:
    doc, _, aid = make_doc()
    cache = cloth_cache(doc, aid)
    first = cloth_state(doc, aid, 5)
    assert cache.cached_frames == 6
    later = cloth_state(doc, aid, 9)
    assert cache.cached_frames == 10
    assert cloth_state(doc, aid, 5) is first  # earlier frames come from the cache
    assert cloth_cache(doc, aid) is cache
    assert not later.flags.writeable
    assert np.array_equal(later, direct(SMALL, 9))


def test_changing_a_parameter_invalidates_and_undo_restores() -> None:
    doc, stack, aid = make_doc()
    before = cloth_state(doc, aid, 20).copy()
    stack.push(set_cloth_param_command(doc, aid, "wind", (0.0, 0.0, -3.0)))
    assert doc.assets[aid].properties["wind"] == [0.0, 0.0, -3.0]
    after = cloth_state(doc, aid, 20)
    assert np.array_equal(after, direct(SMALL.replace(wind=(0.0, 0.0, -3.0)), 20))
    assert after[~Cloth(SMALL).pinned, 2].mean() < 0 < before[~Cloth(SMALL).pinned, 2].mean()
    stack.undo()
    assert np.array_equal(cloth_state(doc, aid, 20), before)


def test_fps_change_invalidates_the_cache() -> None:
    doc, stack, aid = make_doc()
    cloth_state(doc, aid, 10)
    stack.push(SetParameter(doc, "fps", 30.0))
    assert np.array_equal(cloth_state(doc, aid, 10), direct(SMALL, 10, 1.0 / 30.0))


def test_slider_gesture_is_one_undo_step() -> None:
    doc, stack, aid = make_doc()
    for k in (300.0, 400.0, 500.0):
        stack.push(set_cloth_param_command(doc, aid, "structural_stiffness", k, gesture="drag-1"))
    assert doc.assets[aid].properties["structural_stiffness"] == 500.0
    stack.undo()
    assert doc.assets[aid].properties["structural_stiffness"] == SMALL.structural_stiffness


@pytest.mark.parametrize("name,value", [("rows", 1), ("pin_mode", "sideways"), ("no_such_thing", 1.0),
                                        ("wind", [1.0])])
def test_bad_parameter_values_are_refused(name: str, value: object) -> None:
    doc, _, aid = make_doc()
    with pytest.raises(ValueError):
        set_cloth_param_command(doc, aid, name, value)


def test_blow_up_keeps_the_last_good_frame_and_explains() -> None:
    doc, stack, aid = make_doc()
    stack.push(set_cloth_param_command(doc, aid, "structural_stiffness", 1.0e4))
    stack.push(set_cloth_param_command(doc, aid, "substeps", 1))
    positions = cloth_state(doc, aid, 60)
    assert np.isfinite(positions).all()
    problem = cloth_problem(doc, aid)
    assert problem is not None and "substeps" in problem.message
    stack.push(set_cloth_param_command(doc, aid, "integrator", "implicit"))
    assert np.isfinite(cloth_state(doc, aid, 60)).all()
    assert cloth_problem(doc, aid) is None


def test_project_round_trip_rebuilds_the_cache(tmp_path: object) -> None:
    from pathlib import Path

    doc, _, aid = make_doc()
    expected = cloth_state(doc, aid, 15).copy()
    path = Path(str(tmp_path)) / "cloth.qtanim"
    save_document(doc, path)
    loaded = open_document(path)
    assert loaded.assets[aid].properties == SMALL.to_dict()
    assert isinstance(loaded.runtime[aid], ClothCache)
    assert np.array_equal(cloth_state(loaded, aid, 15), expected)


def test_frame_start_is_the_rest_state() -> None:
    doc = Document()
    stack = UndoStack(doc)
    stack.push(SetParameter(doc, "frame_start", 10))
    stack.push(add_cloth_command(doc, SMALL, asset_id="flag"))
    assert np.array_equal(cloth_state(doc, "flag", 10), Cloth(SMALL).rest_positions)
    assert np.array_equal(cloth_state(doc, "flag", 14), direct(SMALL, 4))
    with pytest.raises(ValueError):
        add_cloth_command(doc, SMALL, asset_id="flag")
