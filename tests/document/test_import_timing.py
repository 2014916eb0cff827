"""Imported clips keep their timing (issue 15, item 5): a BVH / glTF clip's frame rate and
duration become the project's in a document without keys; with keys the range only grows
and the clip's rate is offered (set_fps_command)."""

from __future__ import annotations

import numpy as np
import pytest
from samples import write_bvh

from qtanimator.core.channel import Channel, Key
from qtanimator.document import Document, UndoStack
from qtanimator.document.character3d import set_fps_command, world_matrices
from qtanimator.document.import3d import import_file
from qtanimator.formats.bvh import load_bvh


def _import(doc, path):
    stack = UndoStack(doc)
    before = doc.state()
    result = import_file(doc, path)
    stack.push(result.command)
    return stack, result, before


def _keyed_document():
    doc = Document()
    doc.apply_channel("other/j/x", Channel([Key(0.0, 0.0), Key(1.0, 1.0)]))
    return doc


def test_120_fps_bvh_into_an_empty_document_sets_its_rate_and_range(tmp_path):
    path = write_bvh(tmp_path / "fast.bvh", 121)
    doc = Document()
    assert doc.fps == 60
    stack, result, before = _import(doc, path)
    clip = load_bvh(path)
    assert doc.fps == 120 and result.clip_fps is None
    assert any("120 fps" in n for n in result.notes)
    first, last = doc.frame_range
    assert first == 0 and doc.frame_to_time(last) >= clip.duration - 1e-9
    assert last == clip.frame_count - 1  # the range is the clip's: 1 s at 120 fps
    # every BVH frame is a document frame: frame k shows the file's row k
    for k in range(first, last + 1):
        assert np.allclose(world_matrices(doc, result.asset_id, doc.frame_to_time(k)),
                           clip.world_matrices(frame=k), atol=1e-3), k
    stack.undo()  # one undo step takes the rate back too
    assert doc.state() == before and doc.fps == 60


def test_short_clip_sets_a_short_range(tmp_path):
    path = write_bvh(tmp_path / "short.bvh", 5, "0.04")  # 0.16 s at 25 fps
    doc = Document()
    _stack, result, _before = _import(doc, path)
    assert doc.fps == 25
    first, last = doc.frame_range
    assert (first, last) == (0, 4)
    assert doc.frame_to_time(last) - doc.frame_to_time(first) == pytest.approx(0.16)


def test_short_clip_at_the_project_rate_only_sets_the_range(tmp_path):
    path = write_bvh(tmp_path / "short60.bvh", 11, "0.0166667")  # 0.1667 s at 60 fps
    doc = Document()
    _stack, result, _before = _import(doc, path)
    assert doc.fps == 60 and doc.frame_range == (0, 10)
    assert not any("frame rate" in n for n in result.notes)


def test_into_a_document_with_keys_the_rate_is_offered_not_imposed(tmp_path):
    path = write_bvh(tmp_path / "fast.bvh", 601)  # 5 s at 120 fps
    doc = _keyed_document()
    _stack, result, _before = _import(doc, path)
    assert doc.fps == 60 and result.clip_fps == 120
    assert any("120 fps" in n and "60 fps" in n for n in result.notes)
    assert doc.frame_range == (0, 300)  # grew to the clip's 5 s at 60 fps (it was 0–240)
    short = write_bvh(tmp_path / "short.bvh", 5, "0.04")
    _stack, result, _before = _import(doc, short)
    assert doc.frame_range == (0, 300) and result.clip_fps == 25  # never shrinks a chosen range


def test_set_fps_command_keeps_the_range_in_seconds_and_is_one_undo_step():
    doc = _keyed_document()
    doc.apply_parameter("frame_start", 30)
    doc.apply_parameter("frame_end", 270)  # 0.5 … 4.5 s
    stack = UndoStack(doc)
    before = doc.state()
    count = stack.count() if hasattr(stack, "count") else None
    stack.push(set_fps_command(doc, 120))
    assert doc.fps == 120 and doc.frame_range == (60, 540)
    assert doc.frame_to_time(60) == pytest.approx(0.5) and doc.frame_to_time(540) == pytest.approx(4.5)
    stack.push(set_fps_command(doc, 24))
    assert doc.frame_range == (12, 108)
    stack.undo()
    assert doc.fps == 120 and doc.frame_range == (60, 540)
    stack.undo()
    assert doc.state() == before
    if count is not None:
        assert stack.count() == count + 2
    with pytest.raises(ValueError):
        set_fps_command(doc, 0)
