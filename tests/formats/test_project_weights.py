"""Weighted tangents in project files (issue 13, item 4): written only when a key has one,
read back exactly, and save → load → save gives identical bytes."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from qtanimator.core.channel import Channel, Key, Tangent
from qtanimator.formats import FormatError
from qtanimator.formats.project import ProjectData, load_project, parse_project, project_to_json, save_project

SCENES = Path(__file__).resolve().parents[2] / "scenes"


def weighted_project() -> ProjectData:
    many = Channel([Key(i / 24.0, np.sin(i / 3.0), "smooth", "clamped",
                        in_weight=None if i % 3 else 0.01 * (i + 1), out_weight=0.02 if i % 2 else None)
                    for i in range(27)], "cycle", "bounce")
    shared = Channel([Key(0.0, 0.0, out_weight=0.125, in_weight=0.125), Key(1.0, 1.0, out_weight=0.125,
                                                                            in_weight=0.125)])
    fixed = Channel([Key.make(0.0, 1.0, 0.5, -2.0, out_weight=1.0 / 3.0),
                     Key.make(0.75, -1.0, "flat", "linear", in_weight=0.7, broken=True)], "linear", "cycle_offset")
    plain = Channel([Key(0.0, 1.0), Key(0.5, 2.0, Tangent.FLAT, Tangent.FLAT)])
    return ProjectData(parameters={"fps": 24.0, "frame_start": 0, "frame_end": 48},
                       channels={"hero/arm/rz": many, "hero/arm/rx": shared, "hero//x": fixed, "hero//y": plain})


def test_weighted_keys_save_load_save_to_identical_bytes(tmp_path):
    data = weighted_project()
    first = tmp_path / "a.qtanim"
    save_project(data, first)
    loaded = load_project(first)
    assert loaded.channels == data.channels
    for cid, ch in data.channels.items():
        t = np.linspace(-1.0, 2.0, 301)
        for d in (0, 1, 2):
            assert np.array_equal(loaded.channels[cid].evaluate(t, d), ch.evaluate(t, d))
    second = tmp_path / "b.qtanim"
    save_project(loaded, second)
    assert first.read_bytes() == second.read_bytes()


def test_weights_are_columns_written_only_where_a_key_has_one(tmp_path):
    data = weighted_project()
    channels = json.loads(project_to_json(data, tmp_path))["channels"]
    assert "in_weight" not in channels["hero//y"] and "out_weight" not in channels["hero//y"]
    assert channels["hero/arm/rx"]["in_weight"] == 0.125 and channels["hero/arm/rx"]["out_weight"] == 0.125
    assert channels["hero//x"]["out_weight"] == [1.0 / 3.0, None]
    assert channels["hero//x"]["in_weight"] == [None, 0.7]
    many = channels["hero/arm/rz"]
    assert many["in_weight"][:4] == [0.01, None, None, 0.04] and many["out_weight"][:2] == [None, 0.02]
    # After the other columns and before the times, like the rules they qualify.
    assert list(channels["hero//x"]) == ["pre", "post", "in", "out", "broken", "in_weight", "out_weight",
                                         "times", "values"]


def test_projects_without_weights_save_as_before(tmp_path):
    shipped = sorted(SCENES.rglob("*.qtanim"))
    assert shipped
    for path in shipped:
        data = load_project(path)
        text = project_to_json(data, path.parent)
        assert text == path.read_text(encoding="utf-8"), path
        assert "weight" not in text


def test_format_1_keys_carry_weights(tmp_path):
    text = json.dumps({"format": "qtanimator-project", "version": 1, "channels": {"a/b/c": {
        "keys": [{"t": 0.0, "v": 0.0, "in": "smooth", "out": 1.5, "out_weight": 0.4},
                 {"t": 1.0, "v": 1.0, "in": "flat", "out": "smooth", "in_weight": 0.1}]}}})
    ch = parse_project(text, tmp_path / "old.qtanim").channels["a/b/c"]
    assert ch.keys[0].out_weight == 0.4 and ch.keys[1].in_weight == 0.1 and ch.is_weighted


@pytest.mark.parametrize("column,words", [
    ("[0.1]", "entries"),
    ("[0.1, -0.5]", "positive"),
    ("[0.1, 0]", "positive"),
    ("[0.1, \"0.5\"]", "number of seconds"),
    ("true", "number of seconds"),
    ("[0.1, [0.2]]", "number of seconds"),
])
def test_bad_weights_are_format_errors(tmp_path, column, words):
    text = ('{"format": "qtanimator-project", "version": 2, "channels": {"a/b/c": '
            '{"times": [0.0, 1.0], "values": [0.0, 1.0], "out_weight": ' + column + '}}}')
    with pytest.raises(FormatError, match=words):
        parse_project(text, tmp_path / "bad.qtanim")
