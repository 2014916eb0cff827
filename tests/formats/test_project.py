"""JSON projects: deterministic round trip, relative paths, atomic saves, bad input."""

from __future__ import annotations

import json
import os
import shutil
import stat
from pathlib import Path

import pytest
from docfix import set_channels, set_parameters
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from needs import missing

from qtanimator.core.channel import Channel, Interpolation, Key, Tangent
from qtanimator.document import (
    AddAsset,
    Asset,
    Document,
    InsertKey,
    SetExtrapolation,
    SetParameter,
    UndoStack,
    open_document,
    save_document,
)
from qtanimator.formats import FormatError, atomic
from qtanimator.formats.info import summarize
from qtanimator.formats.project import (
    FORMAT_VERSION,
    NUMBERS_PER_LINE,
    ProjectData,
    load_project,
    parse_project,
    project_to_json,
)


def make_doc(folder: Path) -> Document:
    """A document with every kind of authored data; assets are kinds without loaders."""
    (folder / "assets").mkdir(parents=True, exist_ok=True)
    (folder / "assets" / "sky.png").write_bytes(b"not really a png")
    (folder / "assets" / "bulb.txt").write_text("bulb")
    doc = Document()
    stack = UndoStack(doc)
    stack.push(AddAsset(Asset("lamp", "light", str(folder / "assets" / "bulb.txt"),
                              {"texture_file": str(folder / "assets" / "sky.png"), "intensity": 0.75,
                               "name": "Lamp ü", "tags": ["a", "b"], "empty_file": ""})))
    stack.push(InsertKey(doc, "lamp//intensity", Key.make(0.0, 1.0, "flat", 2.5)))
    stack.push(InsertKey(doc, "lamp//intensity", Key.make(0.5, 0.25, "clamped", "linear",
                                                          interpolation="constant", broken=True)))
    stack.push(InsertKey(doc, "lamp/bulb/rz", Key(1.0 / 3.0, -0.1)))
    stack.push(SetExtrapolation(doc, ["lamp//intensity"], "bounce", "cycle_offset"))
    stack.push(SetParameter(doc, "fps", 24))
    stack.push(SetParameter(doc, "cloth.wind", {"speed": 1.5, "dir": [0.0, 1e-300, -2.0]}))
    return doc


def test_save_load_save_gives_identical_bytes(tmp_path):
    doc = make_doc(tmp_path)
    first = tmp_path / "scene.qtanim"
    save_document(doc, first)
    loaded = open_document(first)
    assert loaded.state() == doc.state()
    assert loaded.path == str(first.resolve())
    second = tmp_path / "again.qtanim"
    save_document(loaded, second)
    assert first.read_bytes() == second.read_bytes()
    data = json.loads(first.read_text())
    assert data["format"] == "qtanimator-project" and data["version"] == FORMAT_VERSION


def test_asset_paths_are_stored_relative_and_follow_the_folder(tmp_path):
    doc = make_doc(tmp_path / "a")
    save_document(doc, tmp_path / "a" / "scene.qtanim")
    data = json.loads((tmp_path / "a" / "scene.qtanim").read_text())
    asset = data["assets"][0]
    assert asset["source"] == "assets/bulb.txt"
    assert asset["properties"]["texture_file"] == "assets/sky.png"
    assert asset["properties"]["empty_file"] == ""  # not a path: left alone
    shutil.move(tmp_path / "a", tmp_path / "b")
    moved = open_document(tmp_path / "b" / "scene.qtanim")
    lamp = moved.assets["lamp"]
    assert lamp.source == str((tmp_path / "b" / "assets" / "bulb.txt").resolve())
    assert Path(lamp.properties["texture_file"]).read_bytes() == b"not really a png"
    # A project saved in another folder points back at the same files.
    (tmp_path / "c" / "deeper").mkdir(parents=True)
    save_document(moved, tmp_path / "c" / "deeper" / "copy.qtanim")
    copy = json.loads((tmp_path / "c" / "deeper" / "copy.qtanim").read_text())
    assert copy["assets"][0]["source"] == "../../b/assets/bulb.txt"
    assert open_document(tmp_path / "c" / "deeper" / "copy.qtanim").assets["lamp"].source == lamp.source


def test_a_failed_save_leaves_the_old_file(tmp_path):
    doc = make_doc(tmp_path)
    path = tmp_path / "scene.qtanim"
    save_document(doc, path)
    old = path.read_bytes()
    set_parameters(doc, {"bad": float("nan")})
    with pytest.raises(ValueError, match="JSON cannot store"):
        save_document(doc, path)
    set_parameters(doc, {"bad": object()})
    with pytest.raises(ValueError, match="JSON cannot store"):
        save_document(doc, path)
    assert path.read_bytes() == old
    assert sorted(p.name for p in tmp_path.iterdir()) == ["assets", "scene.qtanim"]


def test_a_save_that_fails_while_writing_leaves_the_old_file(tmp_path, monkeypatch):
    doc = make_doc(tmp_path)
    path = tmp_path / "scene.qtanim"
    save_document(doc, path)
    old = path.read_bytes()
    set_parameters(doc, {"fps": 30})

    def broken_replace(src: str, dst: str) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", broken_replace)
    with pytest.raises(OSError):
        save_document(doc, path)
    monkeypatch.undo()
    assert path.read_bytes() == old
    assert sorted(p.name for p in tmp_path.iterdir()) == ["assets", "scene.qtanim"]


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="needs a non-root POSIX user")
def test_a_save_into_a_read_only_folder_fails_cleanly(tmp_path):
    doc = make_doc(tmp_path)
    path = tmp_path / "scene.qtanim"
    save_document(doc, path)
    old = path.read_bytes()
    tmp_path.chmod(0o555)
    try:
        with pytest.raises(OSError):
            save_document(doc, path)
    finally:
        tmp_path.chmod(0o755)
    assert path.read_bytes() == old


@pytest.mark.skipif(os.name != "posix", reason="POSIX file modes")
def test_saving_keeps_the_file_mode(tmp_path):
    doc = make_doc(tmp_path)
    path = tmp_path / "scene.qtanim"
    save_document(doc, path)
    assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~atomic._UMASK  # as open() would make it
    path.chmod(0o640)
    save_document(doc, path)
    assert stat.S_IMODE(path.stat().st_mode) == 0o640


GOOD = {"format": "qtanimator-project", "version": 1, "parameters": {"fps": 30},
        "assets": [{"id": "hero", "kind": "light", "source": None, "properties": {}}],
        "channels": {"hero//x": {"pre": "cycle", "post": "linear",
                                 "keys": [{"t": 0.0, "v": 1.0, "in": "smooth", "out": 2.0}]}}}


def variant(**changes: object) -> str:
    data = json.loads(json.dumps(GOOD))
    for dotted, value in changes.items():
        target = data
        *path, last = dotted.split("__")
        for part in path:
            target = target[int(part)] if part.isdigit() else target[part]
        target[last] = value
    return json.dumps(data)


@pytest.mark.parametrize("text, words", [
    ("", "not valid JSON"),
    ("{", "not valid JSON"),
    ("[1, 2]", "not a qtanimator project"),
    ('{"format": "something-else", "version": 1}', "not a qtanimator project"),
    (variant(version=FORMAT_VERSION + 1), "newer qtanimator"),
    (variant(version="1"), "no version"),
    (variant(version=0), "unknown project format version"),
    (variant(parameters=[]), "must be an object"),
    (variant(parameters={"fps": 0}), "fps"),
    (variant(parameters={"fps": "fast"}), "fps"),
    (variant(parameters={"frame_end": 2.5}), "frame_end"),
    (variant(assets={}), "must be a list"),
    (variant(assets=[{"id": "a/b", "kind": "light"}]), "contains '/'"),
    (variant(assets=[{"id": "a", "kind": "light"}, {"id": "a", "kind": "light"}]), "repeated"),
    (variant(assets=[{"id": "a", "kind": "light", "source": 3}]), "must be a path"),
    (variant(assets=[{"id": "a", "kind": "light", "source": "x\u0000y"}]), "not a usable path"),
    (variant(channels={"hero-x": {}}), "asset/joint/dof"),
    (variant(**{"channels__hero//x": {"keys": [{"t": 0}]}}), "malformed"),
    (variant(**{"channels__hero//x__pre": "sideways"}), "malformed"),
    (variant(**{"channels__hero//x__keys": [{"t": 1e308, "v": 1}, {"t": 1e308, "v": 2}]}), "malformed"),
    (variant(**{"channels__hero//x__keys": [{"t": 10**400, "v": 1}]}), "malformed"),
    (variant(**{"channels__hero//x__keys": [{"t": True, "v": 1}]}), "malformed"),
    (variant(**{"channels__hero//x__keys": [{"t": 0, "v": 1, "in": [1]}]}), "malformed"),
    (variant(**{"channels__hero//x": {"times": [0.0, 1.0], "values": [1.0]}}), "malformed"),
    (variant(**{"channels__hero//x": {"times": [0.0]}}), "malformed"),
    (variant(**{"channels__hero//x": {"times": {}, "values": []}}), "malformed"),
    (variant(**{"channels__hero//x": {"times": [True], "values": [1.0]}}), "malformed"),
    (variant(**{"channels__hero//x": {"times": [0.0], "values": ["1"]}}), "malformed"),
    (variant(**{"channels__hero//x": {"times": [0.0, 0.0], "values": [1.0, 2.0]}}), "malformed"),
    (variant(**{"channels__hero//x": {"times": [10**400], "values": [1.0]}}), "malformed"),
    (variant(**{"channels__hero//x": {"times": [0.0], "values": [1.0], "in": "sideways"}}), "malformed"),
    (variant(**{"channels__hero//x": {"times": [0.0], "values": [1.0], "in": ["smooth", "flat"]}}), "malformed"),
    (variant(**{"channels__hero//x": {"times": [0.0], "values": [1.0], "out": None}}), "malformed"),
    (variant(**{"channels__hero//x": {"times": [0.0], "values": [1.0], "out": [[1.0]]}}), "malformed"),
    (variant(**{"channels__hero//x": {"times": [0.0], "values": [1.0], "interp": ["bezier"]}}), "malformed"),
    (variant(**{"channels__hero//x": {"times": [0.0], "values": [1.0], "broken": 1}}), "malformed"),
    (variant(**{"channels__hero//x": {"times": [0.0], "values": [1.0], "broken": [None]}}), "malformed"),
    (variant(**{"channels__hero//x": {"times": [0.0], "values": [1.0], "keys": []}}), "malformed"),
    ('{"format": "qtanimator-project", "version": 1, "parameters": {"x": 1e999}}', "too large"),
    ('{"format": "qtanimator-project", "version": 1, "parameters": {"x": NaN}}', "NaN"),
    ("[" * 100000, "nested too deeply|not valid JSON"),
])
def test_bad_projects_raise_format_error(tmp_path, text, words):
    path = tmp_path / "bad.qtanim"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(FormatError, match=words) as info:
        load_project(path)
    assert info.value.path == str(path)
    assert str(info.value).startswith("bad.qtanim")


def test_the_good_variant_loads(tmp_path):
    data = parse_project(variant(), tmp_path / "ok.qtanim")
    assert data.channels["hero//x"] == Channel([Key.make(0.0, 1.0, "smooth", 2.0)], "cycle", "linear")


def test_unreadable_and_binary_files(tmp_path):
    with pytest.raises(FormatError, match="cannot read"):
        load_project(tmp_path / "missing.qtanim")
    with pytest.raises(FormatError, match="cannot read"):
        load_project(tmp_path)
    (tmp_path / "bin.qtanim").write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(FormatError, match="not UTF-8"):
        load_project(tmp_path / "bin.qtanim")


def test_every_truncation_is_a_format_error(tmp_path):
    doc = make_doc(tmp_path)
    save_document(doc, tmp_path / "scene.qtanim")
    raw = (tmp_path / "scene.qtanim").read_bytes().rstrip()
    bad = tmp_path / "cut.qtanim"
    for n in range(0, len(raw) - 1, 7):
        bad.write_bytes(raw[:n])
        with pytest.raises(FormatError):
            open_document(bad)


@pytest.fixture(scope="module")
def saved_project(tmp_path_factory: pytest.TempPathFactory) -> bytes:
    folder = tmp_path_factory.mktemp("fuzz")
    save_document(make_doc(folder), folder / "scene.qtanim")
    return (folder / "scene.qtanim").read_bytes()


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_fuzzed_projects_only_raise_format_error(tmp_path, saved_project, data):
    kind = data.draw(st.sampled_from(["mutate", "splice", "random", "json"]))
    raw = bytearray(saved_project)
    if kind == "mutate":
        for _ in range(data.draw(st.integers(1, 8))):
            i = data.draw(st.integers(0, len(raw) - 1))
            raw[i] = data.draw(st.integers(0, 255))
    elif kind == "splice":
        i = data.draw(st.integers(0, len(raw)))
        j = data.draw(st.integers(i, min(len(raw), i + 40)))
        raw[i:j] = data.draw(st.binary(max_size=20))
    elif kind == "random":
        raw = bytearray(data.draw(st.binary(max_size=200)))
    else:
        json_values = st.recursive(st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=5),
                                   lambda c: st.lists(c, max_size=3) | st.dictionaries(st.text(max_size=5), c,
                                                                                        max_size=3), max_leaves=8)
        obj = json.loads(saved_project)
        section = data.draw(st.sampled_from(["parameters", "assets", "channels"]))
        obj[section] = data.draw(json_values)
        raw = bytearray(json.dumps(obj).encode())
    path = tmp_path / "fuzz.qtanim"
    path.write_bytes(bytes(raw))
    caller = make_doc(tmp_path / "caller")
    before = caller.state()
    try:
        loaded = open_document(path)
    except FormatError:
        pass
    else:
        # Whatever loads must save again.
        save_document(loaded, tmp_path / "resaved.qtanim")
        assert open_document(tmp_path / "resaved.qtanim").state() == loaded.state()
    assert caller.state() == before


def test_info_summarises_a_project(tmp_path):
    doc = make_doc(tmp_path)
    save_document(doc, tmp_path / "scene.qtanim")
    summary = summarize(tmp_path / "scene.qtanim")
    assert summary["kind"] == "qtanimator project"
    assert summary["channels"] == 2 and summary["keys"] == 3
    assert summary["key_time_range"] == [0.0, 0.5]
    assert summary["assets"][0]["id"] == "lamp"
    json.dumps(summary)  # plain JSON data


def test_the_demo_project_round_trips(tmp_path):
    from qtanimator.paths import demo_project

    demo = demo_project()
    if not demo.exists():
        missing("no bundled demo project")
    doc = open_document(demo)
    save_document(doc, tmp_path / "x.qtanim")
    again = open_document(tmp_path / "x.qtanim")
    assert again.state() == doc.state()
    save_document(again, tmp_path / "y.qtanim")
    assert (tmp_path / "x.qtanim").read_bytes() == (tmp_path / "y.qtanim").read_bytes()
    assert set(again.runtime) == set(doc.runtime)  # every asset loaded again from its source


def test_format_error_carries_where_and_pickles():
    import pickle

    err = FormatError("expected a number.", "/data/wasp.skel", 12, 5)
    assert str(err) == "wasp.skel, line 12, column 5: expected a number."
    assert isinstance(err, ValueError)
    back = pickle.loads(pickle.dumps(err))
    assert (back.message, back.path, back.line, back.column) == ("expected a number.", "/data/wasp.skel", 12, 5)
    assert str(back) == str(err)
    assert str(FormatError("plain")) == "plain"


def test_view_state_round_trips_apart_from_authored_state(tmp_path):
    from qtanimator.document import Document, open_document, save_document

    doc = Document()
    doc.set_view_state("view3d.camera", {"azimuth": 30.0, "target": [0.0, 1.0, 0.0]})
    authored = doc.state()
    path = tmp_path / "v.qtanim"
    save_document(doc, path)
    again = open_document(path)
    assert again.view_state == {"view3d.camera": {"azimuth": 30.0, "target": [0.0, 1.0, 0.0]}}
    assert again.state() == authored
    text = path.read_text()
    path.write_text(text.replace('"view": {', '"view": [{').replace("}\n  }\n}", "}\n  }]\n}"))
    with pytest.raises(FormatError, match='"view" must be an object'):
        open_document(path)


# ------------------------------------------------------------------ format 2: key columns
def test_channels_are_written_as_columns(tmp_path):
    doc = make_doc(tmp_path)
    long = Channel([Key(i / 24.0, (-1.0) ** i * i / 7.0) for i in range(2 * NUMBERS_PER_LINE + 3)], "cycle")
    set_channels(doc, {"lamp/bulb/rx": long})
    save_document(doc, tmp_path / "scene.qtanim")
    text = (tmp_path / "scene.qtanim").read_text(encoding="utf-8")
    channels = json.loads(text)["channels"]
    assert all("keys" not in ch for ch in channels.values())
    # Rules every key shares are written once.
    assert channels["lamp/bulb/rx"] == {"pre": "cycle", "post": "constant", "in": "smooth", "out": "smooth",
                                        "times": [k.time for k in long.keys], "values": [k.value for k in long.keys]}
    assert channels["lamp/bulb/rz"] == {"pre": "constant", "post": "constant", "in": "smooth", "out": "smooth",
                                        "times": [1.0 / 3.0], "values": [-0.1]}
    # Rules that differ are written per key; a fixed slope is a number.
    assert channels["lamp//intensity"] == {
        "pre": "bounce", "post": "cycle_offset", "in": ["flat", "clamped"], "out": [2.5, "linear"],
        "interp": ["cubic", "constant"], "broken": [False, True], "times": [0.0, 0.5], "values": [1.0, 0.25]}
    # Long columns are wrapped, NUMBERS_PER_LINE numbers a line; short ones stay on one line.
    assert '"times": [0.3333333333333333],\n' in text
    start = text.index('"times": [', text.index('"lamp/bulb/rx"'))
    column = text[start:text.index("]", start) + 1]
    rows = column.splitlines()[1:-1]
    assert [len(r.split(",")) - (1 if r.endswith(",") else 0) for r in rows] == [NUMBERS_PER_LINE] * 2 + [3]
    assert rows[0].startswith(" " * 8 + "0.0, 0.041666666666666664, ")
    assert open_document(tmp_path / "scene.qtanim").channels == doc.channels


def test_format_1_projects_still_load_and_save_as_format_2(tmp_path):
    doc = make_doc(tmp_path)
    save_document(doc, tmp_path / "new.qtanim")
    old = json.loads((tmp_path / "new.qtanim").read_text(encoding="utf-8"))
    old["version"] = 1
    old["channels"] = {cid: Channel.from_dict(ch).to_dict() for cid, ch in old["channels"].items()}
    assert all("keys" in ch and "times" not in ch for ch in old["channels"].values())
    (tmp_path / "old.qtanim").write_text(json.dumps(old, indent=2), encoding="utf-8")
    loaded = open_document(tmp_path / "old.qtanim")
    assert loaded.state() == doc.state()
    save_document(loaded, tmp_path / "resaved.qtanim")
    assert (tmp_path / "resaved.qtanim").read_bytes() == (tmp_path / "new.qtanim").read_bytes()


def _bits(x: float) -> str:
    return float(x).hex()


#: Any float a project may hold (issue 31: values and slopes within ±1e9, times within
#: ±1e6 s and at least 1e-6 s apart; docs/formats.md), every bit pattern of that range.
finite = st.floats(min_value=-1e9, max_value=1e9)
rules = st.sampled_from(["flat", "linear", "smooth", "clamped"]) | finite


def _apart(times: list[float]) -> list[float]:
    """``times`` without each one closer than 1e-6 s to the one kept before it (in order of time)."""
    kept: list[float] = []
    for t in sorted(times):
        if not kept or t - kept[-1] >= 1e-6:
            kept.append(t)
    return kept


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(times=st.lists(st.floats(min_value=-1e6, max_value=1e6), min_size=0, max_size=40).map(_apart),
       data=st.data(), shared=st.booleans())
def test_columns_keep_every_key_exactly(tmp_path, times, data, shared):
    n = len(times)
    values = data.draw(st.lists(finite, min_size=n, max_size=n))
    if shared:
        one = (data.draw(rules), data.draw(rules), data.draw(st.sampled_from(list(Interpolation))), False)
        sides = [one] * n
    else:
        sides = [(data.draw(rules), data.draw(rules), data.draw(st.sampled_from(list(Interpolation))),
                  data.draw(st.booleans())) for _ in range(n)]
    keys = [Key.make(t, v, i, o, interpolation=m, broken=b) for t, v, (i, o, m, b) in zip(times, values, sides)]
    ch = Channel(keys, data.draw(st.sampled_from(["constant", "linear", "cycle"])), "bounce")
    project = ProjectData(channels={"a/b/c": ch})
    text = project_to_json(project, tmp_path)
    back = parse_project(text, tmp_path / "p.qtanim").channels["a/b/c"]
    assert back == ch
    for a, b in zip(ch.keys, back.keys):
        assert [_bits(a.time), _bits(a.value)] == [_bits(b.time), _bits(b.value)]
        for side in ("in", "out"):
            if getattr(a, f"{side}_tangent") is Tangent.FIXED:
                assert _bits(getattr(a, f"{side}_slope")) == _bits(getattr(b, f"{side}_slope"))
    assert project_to_json(ProjectData(channels={"a/b/c": back}), tmp_path) == text


def test_a_rule_is_shared_only_when_every_key_writes_it_the_same_way():
    def columns(*slopes: float) -> object:
        return Channel([Key.make(i, 0.0, s, "flat") for i, s in enumerate(slopes)]).to_dict(columns=True)["in"]

    assert columns(0.5, 0.5, 0.5) == 0.5
    assert columns(0.0, -0.0) == [0.0, -0.0] and str(columns(0.0, -0.0)) == "[0.0, -0.0]"
    assert columns(1.0, 2.0) == [1.0, 2.0]
    ch = Channel([Key(0, 1), Key(1, 2, "smooth", "smooth", 0, 0, "linear")])
    assert ch.to_dict(columns=True) == {"pre": "constant", "post": "constant", "in": "smooth", "out": "smooth",
                                        "interp": ["cubic", "linear"], "times": [0.0, 1.0], "values": [1.0, 2.0]}
    assert Channel().to_dict(columns=True) == {"pre": "constant", "post": "constant", "times": [], "values": []}
    assert Channel.from_dict(Channel().to_dict(columns=True)) == Channel()
