"""The curve editor's Qt-free commands (qtanimator.document.curve_commands) and normalisation."""

from __future__ import annotations

import numpy as np
import pytest
from docfix import set_channels
from hypothesis import given, settings
from hypothesis import strategies as st

from qtanimator.core.channel import Channel, Extrapolation, Key, Tangent
from qtanimator.document import Document, UndoStack
from qtanimator.document.commands import MoveKeys
from qtanimator.document.curve_commands import SetKeysBroken, SetKeySlopes
from qtanimator.ui.curves.normalisation import NormalisationCache, channel_normalisation

RULES = ["flat", "linear", "smooth", "clamped"]
tangent = st.one_of(st.sampled_from(RULES), st.floats(-10, 10, allow_nan=False))


@st.composite
def channels(draw):
    n = draw(st.integers(2, 6))
    times = sorted(draw(st.lists(st.integers(0, 200), min_size=n, max_size=n, unique=True)))
    keys = [Key.make(t / 60.0, draw(st.floats(-5, 5)), draw(tangent), draw(tangent), broken=draw(st.booleans()))
            for t in times]
    return Channel(keys, draw(st.sampled_from(list(Extrapolation))), draw(st.sampled_from(list(Extrapolation))))


@settings(max_examples=40, deadline=None)
@given(channels(), st.data())
def test_move_keeps_rules_and_slopes_and_undo_is_exact(ch, data):
    doc = Document()
    set_channels(doc, {"a/j/rx": ch})
    idx = data.draw(st.lists(st.integers(0, len(ch.keys) - 1), min_size=1, unique=True))
    dt = data.draw(st.integers(-30, 30)) / 60.0
    dv = data.draw(st.floats(-3, 3))
    stack = UndoStack(doc)
    try:
        cmd = MoveKeys({"a/j/rx": ch}, {"a/j/rx": idx}, dt, {"a/j/rx": dv}, gesture="g")
    except ValueError:
        return  # two keys would share a time
    stack.push(cmd)
    new = doc.channels["a/j/rx"]
    moved = sorted((ch.keys[i].time + dt, ch.keys[i]) for i in idx)
    for t, old in moved:
        k = new.keys[new.key_index(t)]
        assert (k.in_tangent, k.out_tangent, k.in_slope, k.out_slope, k.broken, k.interpolation) == \
            (old.in_tangent, old.out_tangent, old.in_slope, old.out_slope, old.broken, old.interpolation)
        assert k.value == pytest.approx(old.value + dv)
    assert (new.pre, new.post) == (ch.pre, ch.post)
    stack.undo()
    assert doc.channels["a/j/rx"] == ch


def test_time_scale_divides_fixed_slopes_and_merges_in_one_gesture():
    ch = Channel([Key.make(0.0, 0.0, "flat", 2.0), Key.make(1.0, 1.0, -4.0, "smooth")])
    doc = Document()
    set_channels(doc, {"c//x": ch})
    stack = UndoStack(doc)
    for f in (1.5, 2.0, 0.5):
        stack.push(MoveKeys({"c//x": ch}, {"c//x": [0, 1]}, 0.0, 0.0, gesture="s", time_scale=(0.0, f)))
    assert len(stack.done) == 1
    new = doc.channels["c//x"]
    assert [k.time for k in new.keys] == [0.0, 0.5]
    assert new.keys[0].out_slope == 4.0 and new.keys[1].in_slope == -8.0
    assert new.keys[0].in_tangent is Tangent.FLAT and new.keys[1].out_tangent is Tangent.SMOOTH
    # The curve's shape is the old one squeezed in time: same value at the scaled times.
    t = np.linspace(0, 1, 11)
    assert np.allclose(new.evaluate(t * 0.5), ch.evaluate(t))
    stack.undo()
    assert doc.channels["c//x"] == ch


def test_set_key_slopes_and_break_unify():
    doc = Document()
    ch = Channel([Key(0, 0), Key(1, 2), Key(2, 0, "linear", "linear")])
    set_channels(doc, {"c//x": ch})
    stack = UndoStack(doc)
    stack.push(SetKeySlopes(doc, "c//x", 1, in_slope=1.5, gesture="h"))
    stack.push(SetKeySlopes(doc, "c//x", 1, in_slope=2.5, out_slope=2.5, gesture="h"))
    assert len(stack.done) == 1
    k = doc.channels["c//x"].keys[1]
    assert (k.in_tangent, k.out_tangent, k.in_slope, k.out_slope) == (Tangent.FIXED, Tangent.FIXED, 2.5, 2.5)
    stack.push(SetKeysBroken(doc, {"c//x": [2]}, True))
    assert doc.channels["c//x"].keys[2].broken
    s_in, s_out = doc.channels["c//x"].slopes()
    assert s_in[2] == s_out[2]  # linear at the last key: both sides use the last span
    stack.push(SetKeySlopes(doc, "c//x", 2, out_slope=3.0))
    stack.push(SetKeysBroken(doc, {"c//x": [2]}, False))
    k = doc.channels["c//x"].keys[2]
    assert not k.broken and k.in_slope == k.out_slope == pytest.approx(0.5 * (s_in[2] + 3.0))
    while stack.undo():
        pass
    assert doc.channels["c//x"] == ch


def test_normalisation_maps_the_keyed_range_to_minus_one_one_and_caches_by_identity():
    from qtanimator.core.channel import Interpolation

    ch = Channel([Key(0.0, 0.0, interpolation=Interpolation.CONSTANT), Key(1.0, 4.0), Key(2.0, 2.0)])
    off, scale = channel_normalisation(ch)
    v = (ch.evaluate(np.linspace(0, 2, 1001)) - off) * scale
    assert v.min() == pytest.approx(-1, abs=1e-3) and v.max() == pytest.approx(1, abs=1e-3)
    assert channel_normalisation(Channel([Key(0, 5.0)])) == (5.0, 1.0)
    cache = NormalisationCache()
    assert cache.get("c//x", ch) == (off, scale)
    cache._entries["c//x"] = (ch, 7.0, 3.0)  # a hit returns the stored entry
    assert cache.get("c//x", ch) == (7.0, 3.0)
    assert cache.get("c//x", Channel(ch.keys)) == (off, scale)  # an equal but new object: computed again
