"""The document itself: parameters, ids, notification, snapshots."""

from __future__ import annotations

from docfix import set_parameters

from qtanimator.core.channel import Channel, Key
from qtanimator.document import Asset, Document, DocumentChange
from qtanimator.document.document import PROJECT_DEFAULTS


def test_defaults_and_time_conversion():
    doc = Document()
    assert doc.parameters == PROJECT_DEFAULTS and doc.parameters is not PROJECT_DEFAULTS
    assert doc.fps == 60.0 and doc.frame_range == (0, 240)
    assert doc.frame_to_time(90) == 1.5 and doc.time_to_frame(1.5) == 90
    set_parameters(doc, {"fps": 24})
    assert doc.frame_to_time(12) == 0.5
    assert doc.parameter("missing", 3) == 3


def test_unique_asset_ids():
    doc = Document()
    assert doc.unique_asset_id("my hero/1.svg") == "my_hero_1.svg"
    doc.assets["hero"] = Asset("hero", "light")
    assert doc.unique_asset_id("hero") == "hero_2"
    doc.assets["hero_2"] = Asset("hero_2", "light")
    assert doc.unique_asset_id("hero") == "hero_3"
    assert doc.unique_asset_id("///") == "___"
    assert doc.unique_asset_id("") == "asset"


def test_channels_of_an_asset():
    doc = Document()
    for cid in ("hero//x", "hero/arm/rz", "hero2//x", "prop//y"):
        doc.apply_channel(cid, Channel([Key(0, 1)]))
    assert [cid for cid, _ in doc.channels_of("hero")] == ["hero//x", "hero/arm/rz"]


def test_notification_and_reset():
    doc = Document()
    seen: list[DocumentChange] = []
    doc.subscribe(seen.append)
    doc.apply_parameter("cloth.wind", 2.0)
    doc.apply_parameter("cloth.wind", None)
    doc.apply_asset("a", Asset("a", "light"), runtime="R")
    doc.apply_channel("a//x", Channel([Key(0, 1)]), time_from=0.5)
    assert [(set(e.parameters), set(e.assets), dict(e.channels)) for e in seen] == [
        ({"cloth.wind"}, set(), {}), ({"cloth.wind"}, set(), {}), (set(), {"a"}, {}), (set(), set(), {"a//x": 0.5})]
    assert seen[-1].time_from == 0.5 and "cloth.wind" not in doc.parameters
    other = Document()
    set_parameters(other, {"fps": 30})
    doc.replace_all(other)
    assert seen[-1].reset and doc.fps == 30 and doc.assets == {} and doc.runtime == {}
    doc.unsubscribe(seen.append)
    doc.apply_parameter("fps", 25)
    assert len(seen) == 5


def test_state_is_a_deep_copy():
    doc = Document()
    doc.apply_asset("a", Asset("a", "light", None, {"color": [1, 0, 0]}))
    doc.apply_parameter("wind", {"dir": [0, 1]})
    state = doc.state()
    state["assets"][0]["properties"]["color"][0] = 9
    state["parameters"]["wind"]["dir"][0] = 9
    assert doc.state() != state
    assert doc.assets["a"].properties["color"] == [1, 0, 0]
    assert "runtime" not in doc.state()


def test_channels_and_parameters_are_read_only_views():
    import copy
    import pickle

    import pytest

    doc = Document(channels={"a//x": Channel([Key(0, 1)])}, parameters={"fps": 24})
    assert doc.fps == 24 and doc.frame_range == (0, 240)  # the defaults fill in the rest
    with pytest.raises(TypeError):
        doc.channels["a//y"] = Channel()  # type: ignore[index]
    with pytest.raises(TypeError):
        doc.parameters["fps"] = 30  # type: ignore[index]
    with pytest.raises(AttributeError):
        doc.channels = {}  # type: ignore[misc]
    view = doc.channels
    doc.apply_channel("a//y", Channel([Key(0, 2)]))
    assert "a//y" in view and dict(doc.channels).keys() == {"a//x", "a//y"}  # live, not a copy
    for back in (pickle.loads(pickle.dumps(doc)), copy.deepcopy(doc)):
        assert back.state() == doc.state()
        back.apply_parameter("fps", 30)
        assert back.fps == 30 and doc.fps == 24
    shallow = copy.copy(doc)
    assert shallow.channels == doc.channels and shallow.state() == doc.state()
