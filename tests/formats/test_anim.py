import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from qtanimator.core.channel import Channel, Extrapolation, Key, Tangent
from qtanimator.core.clip import AnimationClip
from qtanimator.formats import FormatError
from qtanimator.formats.anim import format_anim, load_anim, parse_anim, save_anim, summarize

SAMPLE = """animation {
  range 0.0 2.0
  numchannels 2
  channel {
    extrapolate constant linear
    keys 2 {
\t0.0\t0.1\tsmooth\tsmooth
\t1.1\t0.4\t13.7\t\t-0.22
    }
  }
  channel {
    extrapolate cycle cycle_offset
    keys 1 {
      0.5 2 flat flat
    }
  }
}
"""


def test_parses_a_small_file():
    clip = parse_anim(SAMPLE)
    assert (clip.start, clip.end) == (0.0, 2.0)
    a, b = clip.channels
    assert (a.pre, a.post) == (Extrapolation.CONSTANT, Extrapolation.LINEAR)
    assert a.keys[1].in_tangent is Tangent.FIXED and a.keys[1].in_slope == 13.7
    assert a.keys[1].out_slope == -0.22
    assert b.evaluate(-7.0) == 2.0  # a single key is constant whatever the mode


@pytest.mark.parametrize("transform", [
    lambda s: s.replace("\n", "\r\n"),
    lambda s: s.replace("\n", "\r"),
    lambda s: s.replace("\n", "\r\r\n"),
    lambda s: s.rstrip("\n"),
    lambda s: s.replace("\n", "   \n"),
    lambda s: s.replace("channel {", "channel 7 {", 1).replace("channel {", "channel 8{", 1),
    lambda s: s.replace("  numchannels 2\n", ""),
    lambda s: s.replace("  range 0.0 2.0\n", "").replace("numchannels 2", "numchannels 2 range 0 2"),
    lambda s: s.replace(" ", "\t\t"),
    lambda s: "# a comment\n" + s.replace("keys 2 {", "keys 2 { // two keys"),
    lambda s: s.replace("} ", "}").replace("{\n", "{"),
], ids=["crlf", "cr", "crcrlf", "no-final-newline", "trailing-spaces", "numbered", "no-numchannels",
        "range-later", "doubled-tabs", "comments", "glued-braces"])
def test_quirks_give_identical_channels(transform):
    assert parse_anim(transform(SAMPLE)) == parse_anim(SAMPLE)


@pytest.mark.parametrize("text,fragment,line", [
    ("", "empty", 1),
    ("animation {\n range 0 1\n numchannels 2\n channel {\n extrapolate constant constant\n keys 0 {\n }\n }\n}\n",
     "numchannels says 2", 3),
    ("animation {\n channel {\n extrapolate cyclic constant\n keys 0 { }\n }\n}", "unknown extrapolation", 3),
    ("animation {\n channel {\n keys 2 {\n 0 1 flat flat\n 0 2 flat flat\n }\n }\n}", "increasing time", 5),
    ("animation {\n channel {\n keys 2 {\n 0 1 flat flat\n }\n }\n}", "lists only 1", 5),
    ("animation {\n channel {\n keys 1 {\n 0 1 flat flat\n 1 2 flat flat }\n }\n}", "lists more", 5),
    ("animation {\n channel {\n keys 1 {\n 0 abc flat flat\n }\n }\n}", "expected a number", 4),
    ("animation {\n channel {\n keys 1 {\n 0 1 curvy flat\n }\n }\n}", "flat, linear, smooth", 4),
    ("animation {\n channel {\n keys 1 {\n 0 nan flat flat\n }\n }\n}", "finite", 4),
    ("animation {\n range 2 1\n}", "before it starts", 2),
    ("animation {\n range 0 1\n", "truncated", 2),
    ("animation {\n}\n}", "after the end", 3),
    ("skeleton {", "expected 'animation'", 1),
    ("animation {\n channel x {\n", "channel number", 2),
])
def test_errors_name_the_line(text, fragment, line):
    with pytest.raises(FormatError) as info:
        parse_anim(text, "bad.anim")
    err = info.value
    assert fragment in str(err)
    assert err.line == line
    assert err.path == "bad.anim"


def test_round_trip_keeps_every_field(tmp_path):
    clip = parse_anim(SAMPLE.replace("flat flat", "clamped linear"))
    path = tmp_path / "out.anim"
    save_anim(clip, path)
    again = load_anim(path)
    assert again == clip
    save_anim(again, path)
    assert load_anim(path) == clip
    assert not list(tmp_path.glob(".*.tmp"))


def test_failed_save_leaves_the_old_file(tmp_path):
    path = tmp_path / "keep.anim"
    path.write_text("old")
    from qtanimator.core.channel import Interpolation
    bad = AnimationClip([Channel([Key(0, 0, interpolation=Interpolation.LINEAR), Key(1, 1)])], 0, 1)
    with pytest.raises(ValueError):
        save_anim(bad, path)
    assert path.read_text() == "old"


# ---------------------------------------------------------------- property tests
tangent = st.one_of(st.sampled_from(["flat", "linear", "smooth", "clamped"]),
                    st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False))
value = st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False)


@st.composite
def clips(draw):
    channels = []
    for _ in range(draw(st.integers(0, 4))):
        times = []  # keys at least 1e-6 s apart, as a file must hold them (docs/formats.md)
        for t in sorted(set(draw(st.lists(st.floats(-100, 100, allow_nan=False), max_size=6)))):
            if not times or t - times[-1] >= 1e-6:
                times.append(t)
        keys = [Key.make(t, draw(value), draw(tangent), draw(tangent)) for t in times]
        ext = st.sampled_from([e.value for e in Extrapolation])
        channels.append(Channel(keys, draw(ext), draw(ext)))
    start = draw(st.floats(-10, 10, allow_nan=False))
    return AnimationClip(channels, start, start + draw(st.floats(0, 10, allow_nan=False)))


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(clips())
def test_round_trip_property(clip):
    assert parse_anim(format_anim(clip)) == clip


@settings(max_examples=150, deadline=None)
@given(st.data())
def test_fuzz_truncated_and_mutated_input_only_raises_format_error(data):
    text = format_anim(parse_anim(SAMPLE))
    mode = data.draw(st.sampled_from(["truncate", "mutate", "delete", "insert"]))
    if mode == "truncate":
        text = text[: data.draw(st.integers(0, len(text)))]
    else:
        i = data.draw(st.integers(0, len(text) - 1))
        junk = data.draw(st.text(alphabet="{}0123456789.-e \n\r\tabcxyz", max_size=8))
        if mode == "mutate":
            text = text[:i] + junk + text[i + len(junk):]
        elif mode == "delete":
            text = text[:i] + text[i + data.draw(st.integers(1, 20)):]
        else:
            text = text[:i] + junk + text[i:]
    try:
        clip = parse_anim(text, "fuzz.anim")
    except FormatError as err:
        assert err.line is not None and err.line >= 1
    else:
        assert isinstance(clip, AnimationClip)


@settings(max_examples=100, deadline=None)
@given(st.text(max_size=200))
def test_fuzz_random_text(text):
    try:
        parse_anim(text)
    except FormatError:
        pass


@settings(max_examples=30, deadline=None)
@given(st.binary(max_size=300))
def test_fuzz_random_bytes(tmp_path_factory, raw):
    path = tmp_path_factory.mktemp("fuzz") / "x.anim"
    path.write_bytes(raw)
    try:
        load_anim(path)
    except FormatError:
        pass


def test_huge_counts_fail_fast():
    with pytest.raises(FormatError, match="too short"):
        parse_anim("animation { channel { keys 999999999999 { 0 1 flat flat } } }")


def test_missing_file(tmp_path):
    with pytest.raises(FormatError, match="cannot read"):
        load_anim(tmp_path / "nope.anim")


# ------------------------------------------------------------------ conformance
WORKED = {  # notes §8.4
    -1.0: (0.1, 0.5, 0.0), -0.5: (0.1, 0.36875, 1.0), -0.25: (0.1, -0.083594, 0.5),
    0.3: (-0.1976, 0.14375, 0.648), 1.5: (0.312, 0.54375, 0.0), 2.5: (0.092, 1.16875, 0.0),
    3.0: (-0.018, 1.1, 0.0), 4.0: (-0.238, 1.0, 0.0),
}


def test_sample_worked_values(shared_data):
    clip = load_anim(shared_data / "cse169/anim/sample.anim")
    assert (clip.start, clip.end) == (0.0, 2.0)
    assert [(c.pre.value, c.post.value) for c in clip.channels] == [
        ("constant", "linear"), ("cycle", "cycle_offset"), ("bounce", "constant")]
    for t, expected in WORKED.items():
        got = [ch.evaluate(t) for ch in clip.channels]
        assert got == pytest.approx(expected, abs=5e-7), t


WASP = ["wasp_walk.anim", "wasp_walk_crlf.anim", "wasp_walk_unnumbered.anim"]


@pytest.mark.parametrize("name", WASP)
def test_wasp_walk_facts(shared_data, name):
    clip = load_anim(shared_data / "cse169/wasp_walk" / name)
    assert (clip.start, clip.end) == (0.0, 4.0)
    assert len(clip.channels) == 72
    assert sum(len(c.keys) for c in clip.channels) == 239
    sizes = [len(c.keys) for c in clip.channels]
    assert (sizes.count(1), sizes.count(2), sizes.count(3), sizes.count(5)) == (29, 1, 1, 41)
    times = [k.time for c in clip.channels for k in c.keys]
    assert (min(times), max(times)) == (-1.0, 4.0)
    pairs = [(c.pre.value, c.post.value) for c in clip.channels]
    assert pairs.count(("constant", "constant")) == 31
    assert pairs.count(("cycle", "cycle")) == 40
    assert pairs[2] == ("cycle_offset", "cycle_offset")
    rules = [r for c in clip.channels for k in c.keys for r in (k.in_tangent.value, k.out_tangent.value)]
    assert (rules.count("smooth"), rules.count("linear"), rules.count("flat")) == (246, 216, 16)
    # at an exact period multiple before the keys (floor convention)
    assert clip.channels[2].evaluate(-2.0) == pytest.approx(1.35, abs=1e-9)
    for ch, v in ((24, -0.541324), (25, 0.718820), (26, 1.467731)):
        assert clip.channels[ch].evaluate(-2.0) == pytest.approx(v, abs=1e-6)
    assert clip.channels[1].evaluate(3.3) == pytest.approx(0.95)


def test_wasp_variants_agree(shared_data):
    clips = [load_anim(shared_data / "cse169/wasp_walk" / n) for n in WASP]
    t = np.arange(-2.0, 6.0001, 0.05)
    ref = clips[0].evaluate(t)
    for c in clips[1:]:
        assert c == clips[0]
        assert np.array_equal(c.evaluate(t), ref)


def test_every_shared_anim_round_trips(shared_data, tmp_path):
    files = sorted(shared_data.rglob("*.anim"))
    assert files
    for f in files:
        clip = load_anim(f)
        save_anim(clip, tmp_path / f.name)
        assert load_anim(tmp_path / f.name) == clip
        s = summarize(f)
        assert s["channels"] == len(clip.channels)


def test_summary_values(shared_data):
    s = summarize(shared_data / "cse169/wasp_walk/wasp_walk.anim")
    assert s["keys"] == 239 and s["range"] == [0.0, 4.0] and s["key_time_range"] == [-1.0, 4.0]
    assert s["extrapolation"]["cycle cycle"] == 40
    assert math.isfinite(s["range"][1])
