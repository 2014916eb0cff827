"""Channel (core/channel.py): linear spans, and the column form's interp / broken entries."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.channel import Channel, Interpolation, Key, Tangent


def _keys(interps, broken=(False, False, False)):
    return [Key(float(i), float(i * i), "smooth", "smooth", interpolation=m, broken=b)
            for i, (m, b) in enumerate(zip(interps, broken))]


def test_linear_spans_flag_the_spans_that_start_at_a_linear_key():
    ch = Channel(_keys(["linear", "cubic", "constant"]) + [Key(3.0, 1.0, interpolation="linear")])
    np.testing.assert_array_equal(ch.linear_spans, [True, False, False])
    assert ch.linear_spans.dtype == bool
    # the last key's interpolation starts no span
    assert Channel(_keys(["cubic", "cubic", "linear"])).linear_spans.tolist() == [False, False]


def test_columns_leave_interp_out_when_every_span_is_cubic():
    d = Channel(_keys(["cubic"] * 3)).to_dict(columns=True)
    assert "interp" not in d


@pytest.mark.parametrize("interps, expected", [
    (["linear"] * 3, "linear"),
    (["constant"] * 3, "constant"),
    (["linear", "cubic", "constant"], ["linear", "cubic", "constant"]),
])
def test_columns_write_interp_otherwise(interps, expected):
    ch = Channel(_keys(interps))
    d = ch.to_dict(columns=True)
    assert d["interp"] == expected
    back = Channel.from_dict(d)
    assert [k.interpolation for k in back.keys] == [Interpolation(m) for m in interps]


def test_columns_leave_broken_out_when_no_key_is_broken():
    assert "broken" not in Channel(_keys(["cubic"] * 3)).to_dict(columns=True)


@pytest.mark.parametrize("broken, expected", [
    ((True, True, True), True),
    ((False, True, False), [False, True, False]),
])
def test_columns_write_broken_when_some_key_is(broken, expected):
    ch = Channel(_keys(["cubic"] * 3, broken))
    d = ch.to_dict(columns=True)
    assert d["broken"] == expected
    assert [k.broken for k in Channel.from_dict(d).keys] == list(broken)


def _casteljau(points, u):
    pts = list(points)
    while len(pts) > 1:
        pts = [(1.0 - u) * a + u * b for a, b in zip(pts, pts[1:])]
    return pts[0]


def test_span_handles_of_an_unweighted_channel_are_a_third_of_each_span():
    """Without weights each handle is Δt/3 (keys at 0, 1.5, 3.3 -> 0.5 and 0.6), and the Bézier
    they describe is the channel's Hermite span itself (catches a wrong handle length)."""
    ch = Channel([Key(0.0, 0.0), Key(1.5, 2.0), Key(3.3, -1.0)])
    weighted, h_out, h_in = ch.span_handles()
    np.testing.assert_array_equal(weighted, [False, False])
    np.testing.assert_allclose(h_out, [0.5, 0.6], rtol=1e-12)
    np.testing.assert_allclose(h_in, [0.5, 0.6], rtol=1e-12)
    s_in, s_out = ch.slopes()
    for i in range(2):
        a, b = ch.keys[i], ch.keys[i + 1]
        xs = [a.time, a.time + h_out[i], b.time - h_in[i], b.time]
        ys = [a.value, a.value + h_out[i] * s_out[i], b.value - h_in[i] * s_in[i + 1], b.value]
        for u in (0.25, 0.5, 0.8):
            # equally spaced x control points: x(u) is linear, t = ta + u·Δt
            assert _casteljau(xs, u) == pytest.approx(a.time + u * (b.time - a.time), abs=1e-12)
            assert _casteljau(ys, u) == pytest.approx(ch.evaluate(_casteljau(xs, u)), abs=1e-12)


def test_unweighted_adds_no_keys_where_the_hermite_is_exact_even_at_zero_tolerance():
    """A flat weighted span at value 0 is reproduced exactly (error 0) by the Hermite
    piece between its keys, so no cut is needed even with tolerance 0 (catches splitting
    on error == tolerance/2, which would cut until max_keys)."""
    ch = Channel([Key(0.0, 0.0, "flat", "flat", out_weight=0.2), Key(1.0, 0.0, "flat", "flat", in_weight=0.7)])
    assert ch.is_weighted
    out, added, worst = ch.unweighted(tolerance=0.0, max_keys=16)
    assert added == 0
    assert worst == 0.0
    assert not out.is_weighted
    assert len(out.keys) == 2


def test_unweighted_of_a_channel_without_weights_is_itself():
    ch = Channel([Key(0.0, 0.0), Key(1.0, 2.0)])
    assert ch.unweighted() == (ch, 0, 0.0)
    assert ch.unweighted()[0] is ch


def test_equality_ignores_what_was_computed_and_cached():
    """Two channels with the same keys are equal whether or not one was evaluated."""
    a = Channel([Key(0.0, 0.0, interpolation="linear"), Key(1.0, 2.0)])
    b = Channel([Key(0.0, 0.0, interpolation="linear"), Key(1.0, 2.0)])
    assert a.linear_spans.tolist() == [True]
    a.evaluate(0.5)
    assert a == b


def test_key_index_finds_a_key_within_the_tolerance_only():
    ch = Channel([Key(0.5, 0.0), Key(1.0, 2.0), Key(2.0, 1.0)])
    assert ch.key_index(1.0) == 1
    assert ch.key_index(1.0 + 1e-12) == 1
    assert ch.key_index(1.01) is None
    assert ch.key_index(1.01, tolerance=0.02) == 1
    assert ch.key_index(-1.0) is None
    assert Channel([]).key_index(0.0) is None
    moved = ch.set_key(Key(2.0, 5.0))
    assert [k.value for k in moved.keys] == [0.0, 2.0, 5.0]
    added = ch.set_key(Key(1.5, 5.0))
    assert [k.time for k in added.keys] == [0.5, 1.0, 1.5, 2.0]


def test_columns_share_equal_numbers_but_keep_minus_zero_apart():
    """Every key with the same weight (equal floats made separately) writes one number; fixed
    slopes 0.0 and -0.0 differ in sign, so both are written and read back exactly."""
    half = [float(text) for text in ("0.5", "0.50")]  # two float objects of one value
    assert half[0] is not half[1]
    ch = Channel([Key(0.0, 0.0, out_weight=half[0]), Key(1.0, 1.0, out_weight=half[1])])
    assert ch.to_dict(columns=True)["out_weight"] == 0.5
    f = Tangent.FIXED
    signed = Channel([Key(0.0, 0.0, f, f, 0.0, 0.0), Key(1.0, 1.0, f, f, -0.0, -0.0)])
    col = signed.to_dict(columns=True)["in"]
    assert isinstance(col, list) and [math.copysign(1.0, s) for s in col] == [1.0, -1.0]
    back = Channel.from_dict(signed.to_dict(columns=True))
    assert math.copysign(1.0, back.keys[1].in_slope) == -1.0


# ---- surv4: key_index's tolerance is inclusive; unweighted() keeps to max_keys


def test_key_index_tolerance_is_inclusive():
    # "within tolerance" includes the bound: 0.75 − 0.5 = 0.25 exactly in binary, and a
    # zero tolerance still finds a key at exactly that time.
    ch = Channel([Key(0.5, 1.0), Key(2.0, 3.0)])
    assert ch.key_index(0.75, tolerance=0.25) == 0
    assert ch.key_index(2.0, tolerance=0.0) == 1
    assert ch.key_index(0.75, tolerance=0.125) is None
    # set_key with a zero tolerance replaces the key at that exact time (no second key).
    assert len(ch.set_key(Key(2.0, 7.0), tolerance=0.0).keys) == 2


def test_unweighted_adds_no_more_than_max_keys(monkeypatch):
    import qtanimator.core.channel as channel_module

    calls = [0]
    real = channel_module.hermite

    def counted(*args, **kw):   # a cut-off for a subdivision that never stops
        calls[0] += 1   # one call per round of cutting, one row per piece
        if calls[0] > 50 or len(args[0]) > 64:
            raise RuntimeError("unweighted() kept subdividing past max_keys")
        return real(*args, **kw)

    monkeypatch.setattr(channel_module, "hermite", counted)
    # A weighted span far from its Hermite (long out handle, short in handle) against an
    # unreachable tolerance: only max_keys stops the cutting.
    ch = Channel([Key(0.0, 0.0, "fixed", "fixed", 0.0, 10.0, out_weight=0.9),
                  Key(1.0, 1.0, "fixed", "fixed", 10.0, 0.0, in_weight=0.05)])
    assert ch.is_weighted
    for cap in (0, 1, 3):
        out, added, _worst = ch.unweighted(tolerance=1e-300, max_keys=cap)
        assert added <= cap
        assert len(out.keys) == 2 + added
