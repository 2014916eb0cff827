"""Projects (and the glTF and Spine readers) whose numbers or types cannot reach a view
(issue 31, part 4 and the "Crashes and errors that are not FormatError" rows).

Each hostile file is refused with a :class:`FormatError` that names the file and the
property; numbers at the documented bounds still open. The expectations are written out here
(the property names as they stand in the file, the bounds of docs/formats.md), not derived
from the reader.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import gltf_gen
import pytest

from qtanimator.document.io import open_document
from qtanimator.formats.errors import FormatError
from qtanimator.formats.gltf import import_gltf
from qtanimator.formats.project import load_project
from qtanimator.formats.spine import read_spine

REPO = Path(__file__).resolve().parents[2]
#: The bounds docs/formats.md promises (written out, not imported).
MAX_TIME = 1e6
MAX_VALUE = 1e9
TIME_TOLERANCE = 1e-6


def project(folder: Path, name: str, assets: list[dict[str, Any]] | None = None,
            channels: dict[str, Any] | None = None) -> Path:
    """A project file ``name`` in ``folder``, with the pencil SVG beside it."""
    (folder / "pencil.svg").write_bytes((REPO / "scenes" / "pencil.svg").read_bytes())
    path = folder / name
    path.write_text(json.dumps({"format": "qtanimator-project", "version": 2, "parameters": {},
                                "assets": assets or [], "channels": channels or {}}), encoding="utf-8")
    return path


PENCIL = {"id": "pencil", "kind": "character2d", "source": "pencil.svg"}


def channel(times: list[float], values: list[float], **more: Any) -> dict[str, Any]:
    return {"pencil//x": {"times": times, "values": values, **more}}


#: (name, channels, the words the error must hold). The first is issue 31's 349-byte
#: project that crashed the window.
HOSTILE_CHANNELS = [
    ("denormal_gap", channel([0, 5e-324], [0, 1], pre="cycle", post="cycle"), ['"times"', "5e-324"]),
    ("equal_after_rounding", channel([1.0, 1.0 + 1e-9], [0, 1]), ['"times"']),
    ("time_1e308", channel([0, 1e308], [0, 1]), ['"times"', "1e+308"]),
    ("time_negative", channel([-1e7, 0], [0, 1]), ['"times"']),
    ("value_1e308", channel([0, 1], [0, 1e308]), ['"values"', "1e+308"]),
    ("value_negative", channel([0, 1], [-2e9, 0]), ['"values"']),
    ("tangent_in", channel([0, 1], [0, 1], **{"in": 1e308}), ['"in"']),
    ("tangent_out", channel([0, 1], [0, 1], out=-1e308), ['"out"']),
    ("weight", channel([0, 1], [0, 1], in_weight=[None, 1e300]), ['"in_weight"']),
    ("tension", channel([0, 1], [0, 1], tension=[0, 1e300]), ['"tension"']),
    ("version1_keys", {"pencil//x": {"keys": [{"t": 0, "v": 0}, {"t": 1e-300, "v": 1}]}}, ['"times"']),
]


@pytest.mark.parametrize(("name", "channels", "words"), HOSTILE_CHANNELS, ids=[c[0] for c in HOSTILE_CHANNELS])
def test_a_channel_beyond_the_bounds_is_a_format_error_naming_the_property(
        tmp_path: Path, name: str, channels: dict[str, Any], words: list[str]) -> None:
    path = project(tmp_path, f"{name}.qtanim", [PENCIL], channels)
    with pytest.raises(FormatError) as info:
        load_project(path)
    text = str(info.value)
    assert text.startswith(f"{name}.qtanim: ")
    assert "pencil//x" in text
    for word in words:
        assert word in text, text


def test_the_349_byte_project_of_the_issue_is_refused(tmp_path: Path) -> None:
    text = ('{"format":"qtanimator-project","version":2,"assets":[{"id":"pencil","kind":"character2d",'
            '"source":"pencil.svg"}],"channels":{"pencil//x":{"pre":"cycle","post":"cycle",'
            '"times":[0,5e-324],"values":[0,1]}}}')
    project(tmp_path, "unused.qtanim")
    path = tmp_path / "tiny.qtanim"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(FormatError, match='"times"'):
        open_document(path)


def test_numbers_at_the_bounds_still_open(tmp_path: Path) -> None:
    times = [-MAX_TIME, -MAX_TIME + TIME_TOLERANCE, 0.0, MAX_TIME]
    values = [-MAX_VALUE, MAX_VALUE, 0.0, 1.0]
    path = project(tmp_path, "edge.qtanim", [PENCIL],
                   channel(times, values, pre="cycle_offset", post="bounce", **{"in": MAX_VALUE, "out": -MAX_VALUE}))
    doc = open_document(path)
    ch = doc.channels["pencil//x"]
    assert list(ch.times) == times
    for t in (-2e6, -MAX_TIME + 5e-7, 0.5, 3e6):
        assert math.isfinite(ch.evaluate(t))


HOSTILE_ASSETS = [
    ("index_list", [dict(PENCIL, properties={"index": [0]})], ['"index"', "pencil"]),
    ("index_text", [dict(PENCIL, properties={"index": "zero"})], ['"index"', "pencil"]),
    ("index_bool", [dict(PENCIL, properties={"index": True})], ['"index"']),
    ("index_negative", [dict(PENCIL, properties={"index": -1})], ['"index"']),
    ("skin_file_number", [{"id": "arm", "kind": "character3d", "source": "pencil.svg",
                           "properties": {"skin_file": 123}}], ['"skin_file"', "arm"]),
    ("anim_file_list", [{"id": "arm", "kind": "character3d", "source": "pencil.svg",
                         "properties": {"anim_file": ["a.anim"]}}], ['"anim_file"', "arm"]),
]


@pytest.mark.parametrize(("name", "assets", "words"), HOSTILE_ASSETS, ids=[c[0] for c in HOSTILE_ASSETS])
def test_a_property_of_the_wrong_type_is_a_format_error_naming_it(tmp_path: Path, name: str,
                                                                  assets: list[dict[str, Any]],
                                                                  words: list[str]) -> None:
    path = project(tmp_path, f"{name}.qtanim", assets)
    with pytest.raises(FormatError) as info:
        load_project(path)
    text = str(info.value)
    assert text.startswith(f"{name}.qtanim: ")
    for word in words:
        assert word in text, text


@pytest.mark.parametrize(("prop", "value"), [("width", 1e308), ("height", 1e300), ("origin", [0.0, 1e300, 0.0])])
def test_a_cloth_too_big_for_any_view_is_a_format_error_naming_the_file_and_property(
        tmp_path: Path, prop: str, value: Any) -> None:
    path = project(tmp_path, "cloth.qtanim", [{"id": "sheet", "kind": "cloth", "properties": {prop: value}}])
    with pytest.raises(FormatError) as info:
        open_document(path)
    text = str(info.value)
    assert text.startswith("cloth.qtanim: ")
    assert "sheet" in text and f"sheet.{prop}" in text


def gltf_sampler(folder: Path, times: list[float]) -> Path:
    b = gltf_gen.Builder("keys")
    root = b.node("root")
    b.animation("move", [(root, "translation", times, [[0.0, 0.0, 0.0]] * len(times), "LINEAR")])
    return b.save(folder / "keys.glb")


@pytest.mark.parametrize(("times", "words"), [
    ([0.0, 0.5, 0.5, 1.0], ["samplers[0].input", "increase"]),
    ([0.0, 1e-8], ["samplers[0].input", "increase"]),
    ([0.0, 3e38], ["samplers[0].input", "limit"]),
    ([-3e38, 0.0], ["samplers[0].input", "limit"]),
])
def test_gltf_sampler_times_a_channel_cannot_hold_are_a_format_error(tmp_path: Path, times: list[float],
                                                                     words: list[str]) -> None:
    path = gltf_sampler(tmp_path, times)
    with pytest.raises(FormatError) as info:
        import_gltf(path)
    text = str(info.value)
    assert text.startswith("keys.glb: ")
    for word in words:
        assert word in text, text


def test_gltf_sampler_times_at_the_bounds_are_read(tmp_path: Path) -> None:
    scene = import_gltf(gltf_sampler(tmp_path, [0.0, 0.25, 1000.0]))
    assert len(scene.animations) == 1


@pytest.mark.parametrize("version", ["²", "³.8", "٣.8", "9" * 5000])
def test_a_spine_version_of_other_digits_is_not_an_int_error(tmp_path: Path, version: str) -> None:
    path = tmp_path / "hero.json"
    path.write_text(json.dumps({"skeleton": {"spine": version}, "bones": [{"name": "root"}]}), encoding="utf-8")
    try:
        read_spine(path)
    except FormatError as exc:
        assert str(exc).startswith("hero.json: ")


def test_an_old_spine_version_is_still_named(tmp_path: Path) -> None:
    path = tmp_path / "hero.json"
    path.write_text(json.dumps({"skeleton": {"spine": "3.8.99"}, "bones": [{"name": "root"}]}), encoding="utf-8")
    with pytest.raises(FormatError, match="Spine 3.8.99"):
        read_spine(path)


# ------------------------------------------- importers make only channels a project can hold
ANIM = """animation {{
  range 0 1
  numchannels 1
  channel {{
    extrapolate constant constant
    keys 2 {{
      0 0 flat flat
      {t} {v} {tan} flat
    }}
  }}
}}
"""


@pytest.mark.parametrize(("t", "v", "tan"), [(1e-9, 0, "flat"), (2e6, 0, "flat"), (1, 1e300, "flat"), (1, 0, 1e300)])
def test_an_anim_channel_beyond_the_bounds_is_a_format_error(tmp_path: Path, t: float, v: float, tan: str) -> None:
    from qtanimator.formats.anim import load_anim

    path = tmp_path / "wave.anim"
    path.write_text(ANIM.format(t=t, v=v, tan=tan), encoding="utf-8")
    with pytest.raises(FormatError) as info:
        load_anim(path)
    assert str(info.value).startswith("wave.anim, line ")
    assert "channel 0" in str(info.value) or "channel 1" in str(info.value)


@pytest.mark.parametrize(("frame_time", "value", "words"), [
    ("1e-9", "0", "frame time"), ("5000", "0", "limit"), ("0.01", "1e300", "limit")])
def test_a_bvh_whose_keys_a_channel_cannot_hold_is_a_format_error(tmp_path: Path, frame_time: str, value: str,
                                                                  words: str) -> None:
    from qtanimator.formats.bvh import load_bvh

    text = ("HIERARCHY\nROOT hip\n{\n  OFFSET 0 0 0\n  CHANNELS 1 Xposition\n"
            "  End Site\n  {\n    OFFSET 0 1 0\n  }\n}\n"
            f"MOTION\nFrames: 300\nFrame Time: {frame_time}\n" + f"{value}\n" * 300)
    path = tmp_path / "walk.bvh"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(FormatError) as info:
        load_bvh(path)
    assert str(info.value).startswith("walk.bvh, line ") and words in str(info.value)
