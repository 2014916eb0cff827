"""Weighted tangents (issue 13, item 4): spans with handle lengths are cubic Béziers in
time and value.

The reference here is independent of :mod:`qtanimator.core.bezier`: control points built
from the keys as the issue states them, the parameter found by plain bisection on a
de Casteljau evaluation of x(u), and the value and derivatives by de Casteljau on the
curve and on its hodographs (the derivative curves' control points).
"""

from __future__ import annotations

import hashlib
import itertools
import math

import numpy as np
import pytest

from qtanimator.core import bezier
from qtanimator.core.channel import Channel, Extrapolation, Interpolation, Key, Tangent

MODES = [m.value for m in Extrapolation]
TOL = 1e-9


# ------------------------------------------------------------------- the reference
def casteljau(points: list[float], u: float) -> float:
    pts = list(points)
    while len(pts) > 1:
        pts = [(1.0 - u) * a + u * b for a, b in zip(pts, pts[1:])]
    return pts[0]


def control_points(ch: Channel, i: int) -> tuple[list[float], list[float]]:
    """Absolute x and y control points of span i, with the issue's rule for a missing
    weight (a third of the span) and the clamp (scale both down so they fill the span)."""
    a, b = ch.keys[i], ch.keys[i + 1]
    span = b.time - a.time
    wa = span / 3 if a.out_weight is None else a.out_weight
    wb = span / 3 if b.in_weight is None else b.in_weight
    if wa + wb > span:
        wa, wb = wa * span / (wa + wb), wb * span / (wa + wb)
    s_in, s_out = ch.slopes()
    sa, sb = float(s_out[i]), float(s_in[i + 1])
    return ([a.time, a.time + wa, b.time - wb, b.time],
            [a.value, a.value + wa * sa, b.value - wb * sb, b.value])


def reference(ch: Channel, t: float) -> tuple[float, float, float]:
    """Value, dy/dt and d²y/dt² inside the keys (the span that starts at or before t)."""
    times = [k.time for k in ch.keys]
    if t in (times[0], times[-1]) and ch.pre is ch.post is Extrapolation.CONSTANT:
        # The end keys belong to the extrapolation: derivatives 0 (CMU handout, issue 18).
        return ch.keys[times.index(t)].value, 0.0, 0.0
    i = int(min(max(np.searchsorted(times, t, side="right") - 1, 0), len(times) - 2))
    xs, ys = control_points(ch, i)
    # Coordinates relative to the key nearer to t (the control points reversed when that
    # is the span's end), so that t's offset is exact and short handles keep their digits.
    if t - times[i] > times[i + 1] - t:
        xs, ys = xs[::-1], ys[::-1]
    ox, oy = xs[0], ys[0]
    hx = [q - ox for q in xs]
    hy = [q - oy for q in ys]
    x = t - ox
    rising = hx[3] > 0
    lo, hi = 0.0, 1.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        if (casteljau(hx, mid) < x) == rising:
            lo = mid
        else:
            hi = mid
    u = 0.5 * (lo + hi)
    # The hodographs: the control points of x'(u), y'(u) and of x''(u), y''(u).
    d1x = [3 * (q - p) for p, q in zip(hx, hx[1:])]
    d1y = [3 * (q - p) for p, q in zip(hy, hy[1:])]
    d2x = [2 * (q - p) for p, q in zip(d1x, d1x[1:])]
    d2y = [2 * (q - p) for p, q in zip(d1y, d1y[1:])]
    x1, y1, x2, y2 = (casteljau(c, u) for c in (d1x, d1y, d2x, d2y))
    return oy + casteljau(hy, u), y1 / x1, (y2 * x1 - y1 * x2) / x1 ** 3


def close(got: float, want: float, tol: float = TOL) -> bool:
    return abs(got - want) <= tol * max(1.0, abs(want))


def weighted_channel(case: str, pre: str = "constant", post: str = "constant") -> Channel:
    pts = [(0.5, 1.0, 2.0), (0.8, 2.5, -1.0), (1.6, -0.5, 0.5), (2.0, 0.25, 4.0), (2.9, 1.75, 0.0)]
    weights = {
        # (in_weight, out_weight) per key
        "both": [(None, 0.05), (0.2, 0.5), (0.1, 0.12), (0.3, 0.6), (0.4, None)],
        "out only": [(None, 0.25), (None, 0.05), (None, 0.3), (None, 0.1), (None, None)],
        "in only": [(None, None), (0.02, None), (0.7, None), (0.05, None), (0.85, None)],
        "clamped": [(None, 0.29), (0.29, 0.79), (0.79, 0.39), (0.39, 0.89), (0.89, None)],
        "tiny": [(None, 1e-4), (1e-4, 1e-4), (1e-4, 1e-4), (1e-4, 1e-4), (1e-4, None)],
        "one span": [(None, None), (None, 0.6), (0.05, None), (None, None), (None, None)],
        # A short handle facing a long one: Newton from the linear guess leaves the bracket
        # (in the form solved from the short side), so the bisection steps are exercised.
        "lopsided": [(None, 3e-5), (0.29, 8e-5), (0.78, 4e-5), (0.39, 9e-5), (0.88, None)],
        "lopsided back": [(None, 0.29), (3e-5, 0.78), (8e-5, 0.39), (4e-5, 0.88), (9e-5, None)],
    }[case]
    return Channel([Key(t, v, Tangent.FIXED, Tangent.FIXED, s, s, in_weight=wi, out_weight=wo)
                    for (t, v, s), (wi, wo) in zip(pts, weights)], pre, post)


def without_weights(ch: Channel) -> Channel:
    return ch.with_keys(Key(k.time, k.value, k.in_tangent, k.out_tangent, k.in_slope, k.out_slope) for k in ch.keys)


CASES = ["both", "out only", "in only", "clamped", "tiny", "one span", "lopsided", "lopsided back"]


def inside_times(ch: Channel, count: int = 301) -> np.ndarray:
    t0, t1 = ch.keys[0].time, ch.keys[-1].time
    times = np.linspace(t0, t1, count)
    # The keys themselves, and points just past them.
    keys = np.array([k.time for k in ch.keys])
    return np.unique(np.concatenate([times, keys, keys[:-1] + 1e-7, keys[1:] - 1e-7]))


# -------------------------------------------------------------------- evaluation
@pytest.mark.parametrize("case", CASES)
def test_weighted_spans_match_de_casteljau_with_bisection(case):
    ch = weighted_channel(case)
    assert ch.is_weighted
    times = inside_times(ch)
    arrays = [ch.evaluate(times, d) for d in (0, 1, 2)]
    for j, t in enumerate(times):
        want = reference(ch, float(t))
        for d in (0, 1, 2):
            got = ch.evaluate(float(t), d)
            assert close(got, want[d]), (case, t, d, got, want[d])
            assert got == arrays[d][j]  # scalar and array paths agree to the bit


def test_the_solver_keeps_to_its_bracket_where_newton_cannot_go():
    # x control points 0, 1.5, -0.5, 1: x(u) runs backwards in the middle (no weights give
    # this; clamping prevents it), so Newton meets x'(u) <= 0 and only the bracket helps.
    ax, bx, cx = (float(v) for v in bezier.power_coefficients(np.array(1.5), np.array(-0.5), np.array(1.0)))
    xs = np.linspace(0.0, 1.0, 101)
    us = bezier.solve_array(xs, *(np.full_like(xs, v) for v in (ax, bx, cx, 1.0)))
    for x, ua in zip(xs, us):
        u = bezier.solve(float(x), ax, bx, cx, 1.0)
        assert 0.0 <= u <= 1.0 and u == ua
        assert abs(casteljau([0.0, 1.5, -0.5, 1.0], u) - x) <= 1e-12


def test_smooth_rules_give_the_direction_and_weights_the_length():
    ch = Channel([Key(0.0, 0.0, out_weight=0.6), Key(1.0, 2.0, "clamped", "smooth", in_weight=0.1, out_weight=0.9),
                  Key(3.0, 1.0, in_weight=0.2)])
    for t in np.linspace(0.0, 3.0, 97):
        want = reference(ch, float(t))
        for d in (0, 1, 2):
            assert close(ch.evaluate(float(t), d), want[d])


def test_weights_of_a_third_give_the_hermite_span():
    plain = without_weights(weighted_channel("both"))
    times = [k.time for k in plain.keys]
    thirds = plain.with_keys(
        Key(k.time, k.value, k.in_tangent, k.out_tangent, k.in_slope, k.out_slope,
            in_weight=(k.time - times[i - 1]) / 3 if i else None,
            out_weight=(times[i + 1] - k.time) / 3 if i + 1 < len(times) else None)
        for i, k in enumerate(plain.keys))
    assert thirds.is_weighted and not plain.is_weighted
    t = np.linspace(0.3, 3.1, 500)
    for d in (0, 1, 2):
        np.testing.assert_allclose(thirds.evaluate(t, d), plain.evaluate(t, d), rtol=1e-11, atol=1e-11)


def test_clamping_uses_scaled_weights_but_the_key_keeps_its_own():
    ch = Channel([Key(0.0, 0.0, "fixed", "fixed", 0.0, 3.0, out_weight=0.9),
                  Key(1.0, 1.0, "fixed", "fixed", -2.0, 0.0, in_weight=0.6)])
    assert ch.keys[0].out_weight == 0.9 and ch.keys[1].in_weight == 0.6
    weighted, h_out, h_in = ch.span_handles()
    assert weighted.tolist() == [True]
    assert h_out[0] == pytest.approx(0.6) and h_in[0] == pytest.approx(0.4)
    same = Channel([Key(0.0, 0.0, "fixed", "fixed", 0.0, 3.0, out_weight=0.6),
                    Key(1.0, 1.0, "fixed", "fixed", -2.0, 0.0, in_weight=0.4)])
    t = np.linspace(-0.5, 1.5, 201)
    for d in (0, 1, 2):
        np.testing.assert_allclose(ch.evaluate(t, d), same.evaluate(t, d), rtol=1e-12, atol=1e-12)
    # Time stays monotonic, so the curve is a function: finite everywhere.
    assert np.isfinite(ch.evaluate(np.linspace(0, 1, 1001), 2)).all()


def test_the_end_derivatives_of_a_weighted_last_span_reach_the_keys_that_repeat_it():
    # The end keys' derivatives are the extrapolation's (issue 18): a cycle before the first
    # key ends with the last span's end, a bounce after the last key leaves on it mirrored.
    ch = weighted_channel("both", "cycle", "bounce")
    t0, t1 = ch.keys[0].time, ch.keys[-1].time
    want = reference(ch, t1 - 1e-12)
    assert ch.evaluate(t1) == ch.keys[-1].value and ch.evaluate(t0) == ch.keys[0].value
    assert close(ch.evaluate(t0, 1), want[1], 1e-7)
    assert close(ch.evaluate(t0, 2), want[2], 1e-6)
    assert close(ch.evaluate(t1, 1), -want[1], 1e-7)
    assert close(ch.evaluate(t1, 2), want[2], 1e-6)
    for d in (1, 2):
        assert ch.evaluate(np.array([t0, t1]), d).tolist() == [ch.evaluate(t0, d), ch.evaluate(t1, d)]
    # Linear extrapolation leaves along the last key's out slope, as without weights, from
    # the last key itself on.
    lin = weighted_channel("both", "constant", "linear")
    assert lin.evaluate(t1 + 1.0) == pytest.approx(lin.keys[-1].value + lin.slopes()[1][-1])
    assert lin.evaluate(t1, 1) == lin.slopes()[1][-1] and lin.evaluate(t1, 2) == 0.0


@pytest.mark.parametrize("pre,post", list(itertools.product(MODES, MODES)))
def test_extrapolation_reuses_the_weighted_spans(pre, post):
    ch = weighted_channel("both", pre, post)
    t0, t1 = ch.keys[0].time, ch.keys[-1].time
    d = t1 - t0
    rise = ch.keys[-1].value - ch.keys[0].value
    times = np.concatenate([np.linspace(t0 - 2.3 * d, t0 - 1e-3, 41), np.linspace(t1 + 1e-3, t1 + 2.3 * d, 41)])
    arrays = [ch.evaluate(times, k) for k in (0, 1, 2)]
    for j, t in enumerate(times):
        mode = pre if t < t0 else post
        k = math.floor((t - t0) / d)
        u = (t - t0) - k * d
        if mode in ("cycle", "cycle_offset"):
            v, d1, d2 = reference(ch, t0 + u)
            if mode == "cycle_offset":
                v += k * rise
        elif mode == "bounce":
            odd = k % 2 == 1
            v, d1, d2 = reference(ch, t1 - u if odd else t0 + u)
            d1 = -d1 if odd else d1
        else:
            continue  # constant and linear: the key values and slopes, checked elsewhere
        for n, want in enumerate((v, d1, d2)):
            got = ch.evaluate(float(t), n)
            assert close(got, want, 1e-8), (pre, post, t, n, got, want)
            assert got == arrays[n][j]


def test_large_arrays_in_blocks_match_small_ones():
    ch = weighted_channel("clamped", "bounce", "cycle_offset")
    t = np.linspace(-5.0, 9.0, 70_001)
    for d in (0, 1, 2):
        whole = ch.evaluate(t, d)
        parts = np.concatenate([ch.evaluate(t[s:s + 1000], d) for s in range(0, t.size, 1000)])
        assert np.array_equal(whole, parts)


def test_nan_and_infinite_times_with_weights():
    ch = weighted_channel("both", "cycle", "bounce")
    assert math.isnan(ch.evaluate(math.nan))
    assert np.isnan(ch.evaluate(np.array([math.nan, math.inf, -math.inf]))).all()


# ------------------------------------------------------- what stays as it was
def test_unweighted_spans_of_a_weighted_channel_are_the_hermite_ones_bit_for_bit():
    ch = weighted_channel("one span", "cycle", "cycle")
    plain = without_weights(ch)
    weighted, _, _ = ch.span_handles()
    assert weighted.tolist() == [False, True, False, False]
    t = np.linspace(-3.0, 6.0, 2001)
    local = (t - 0.5) % 2.4 + 0.5
    outside = (local < 0.8) | (local >= 1.6)
    for d in (0, 1, 2):
        assert np.array_equal(ch.evaluate(t, d)[outside], plain.evaluate(t, d)[outside])
        assert not np.allclose(ch.evaluate(t, d)[~outside], plain.evaluate(t, d)[~outside])


def test_weights_off_cubic_spans_change_nothing():
    base = [Key(0.0, 1.0, interpolation="linear"), Key(1.0, 3.0, interpolation="constant"),
            Key(2.0, 0.0), Key(3.0, 2.0)]
    ch = Channel(base)
    heavy = Channel([Key(0.0, 1.0, interpolation="linear", in_weight=0.3, out_weight=0.4),
                     Key(1.0, 3.0, interpolation="constant", in_weight=0.2, out_weight=0.9),
                     Key(2.0, 0.0), Key(3.0, 2.0, out_weight=0.5)])
    assert not heavy.is_weighted
    t = np.linspace(-1, 4, 301)
    for d in (0, 1, 2):
        assert np.array_equal(heavy.evaluate(t, d), ch.evaluate(t, d))


def _reference_channels():
    rules = ["flat", "linear", "smooth", "clamped", 0.7]
    pts = [(0.5, 1.0), (0.8, 2.5), (1.6, -0.5), (2.0, 0.25), (2.9, 1.75)]
    for rule in rules:
        for pre, post in itertools.product(MODES, MODES):
            yield Channel([Key.make(t, v, rule, rule) for t, v in pts], pre, post)
    yield Channel([Key(0.0, 1.0, interpolation="constant"), Key(1.0, 3.0, interpolation="linear"),
                   Key.make(2.0, 5.0, "flat", 1.5), Key.make(3.0, -1.0, -2.0, "clamped"), Key(3.25, 0.5)],
                  "cycle_offset", "bounce")
    yield Channel([Key(1.0, 2.0)], "linear", "cycle")
    yield Channel([Key(0.0, 0.0), Key(1.0, 1.0)], "linear", "linear")


#: The digest of these channels' values and derivatives, scalar and array, computed by the
#: channel code before weighted tangents existed (commit cde32d5; the full digest was
#: e88620847840378022234258dc4a852ffca4576fb1eb404c8133ecd116ae97a7). Issue 18 gave the
#: first and last key the extrapolation's derivatives, so those samples are left out: this
#: digest is what that older code gives for every other sample.
UNWEIGHTED_DIGEST = "b6659ddd07c7365d1f3ed456782e7c2247a31702a4f2d1de0e344608486766f6"


def test_unweighted_channels_evaluate_bit_for_bit_as_before_weights():
    times = np.concatenate([np.linspace(-4.0, 7.0, 97), [0.5, 0.8, 1.6, 2.0, 2.9], [3.0, 3.25, 0.0, 1.0]])
    h = hashlib.sha256()
    for ch in _reference_channels():
        assert not ch.is_weighted
        ends = [ch.keys[0].time, ch.keys[-1].time] if len(ch.keys) > 1 else []
        for d in (0, 1, 2):
            keep = ~np.isin(times, ends) if d else np.ones(times.size, dtype=bool)
            h.update(np.asarray(ch.evaluate(times, d), dtype="<f8")[keep].tobytes())
            h.update(np.array([ch.evaluate(float(t), d) for t in times], dtype="<f8")[keep].tobytes())
    assert h.hexdigest() == UNWEIGHTED_DIGEST


# ------------------------------------------------------------------ keys and data
@pytest.mark.parametrize("bad", [0.0, -0.1, math.nan, math.inf])
def test_a_weight_must_be_finite_and_positive(bad):
    with pytest.raises(ValueError, match="weight"):
        Key(0.0, 1.0, in_weight=bad)
    with pytest.raises(ValueError, match="weight"):
        Key(0.0, 1.0, out_weight=bad)


@pytest.mark.parametrize("bad", [True, "0.5", [0.5]])
def test_a_weight_must_be_a_number(bad):
    with pytest.raises(TypeError, match="weight"):
        Key(0.0, 1.0, out_weight=bad)


def test_weights_are_floats_and_survive_edits():
    k = Key(0.0, 1.0, in_weight=1, out_weight=np.float32(0.25))
    assert type(k.in_weight) is float and type(k.out_weight) is float
    assert k.moved(2.0, 3.0).out_weight == 0.25
    ch = Channel([k, Key(1.0, 0.0)]).set_key(Key(0.0, 5.0))
    assert ch.keys[0].in_weight == 1.0 and ch.keys[0].out_weight == 0.25 and ch.keys[0].value == 5.0


def test_key_dicts_hold_weights_only_when_set():
    assert "in_weight" not in Key(0.0, 1.0).to_dict() and "out_weight" not in Key(0.0, 1.0).to_dict()
    k = Key.make(0.5, 1.0, "clamped", 2.5, in_weight=0.125, out_weight=0.75)
    d = k.to_dict()
    assert d["in_weight"] == 0.125 and d["out_weight"] == 0.75
    assert Key.from_dict(d) == k


def test_columns_write_weights_only_when_a_key_has_one():
    ch = weighted_channel("both", "cycle", "bounce")
    plain = without_weights(ch)
    assert "in_weight" not in plain.to_dict(columns=True) and "out_weight" not in plain.to_dict(columns=True)
    d = ch.to_dict(columns=True)
    assert d["in_weight"] == [None, 0.2, 0.1, 0.3, 0.4]
    assert d["out_weight"] == [0.05, 0.5, 0.12, 0.6, None]
    assert Channel.from_dict(d) == ch
    assert Channel.from_dict(ch.to_dict()) == ch
    shared = Channel([Key(0.0, 0.0, out_weight=0.2), Key(1.0, 1.0, out_weight=0.2)])
    assert shared.to_dict(columns=True)["out_weight"] == 0.2
    assert Channel.from_dict(shared.to_dict(columns=True)) == shared
    # Unsorted columns (a hand-edited file) keep each weight with its key.
    messy = {"times": [1.0, 0.0], "values": [1.0, 0.0], "out_weight": [None, 0.3]}
    assert Channel.from_dict(messy).keys[0].out_weight == 0.3


@pytest.mark.parametrize("column", [[0.1], [0.1, "x"], [0.1, -1.0], True])
def test_bad_weight_columns_are_refused(column):
    with pytest.raises((TypeError, ValueError)):
        Channel.from_dict({"times": [0.0, 1.0], "values": [0.0, 1.0], "in_weight": column})


# ------------------------------------------------------------- without weights
@pytest.mark.parametrize("case", CASES)
def test_unweighted_equivalent_follows_the_curve(case):
    ch = weighted_channel(case, "cycle_offset", "bounce")
    out, added, worst = ch.unweighted()
    assert not out.is_weighted
    assert all(k.in_weight is None and k.out_weight is None for k in out.keys)
    assert added == len(out.keys) - len(ch.keys) and added > 0
    assert {k.time for k in ch.keys} <= {k.time for k in out.keys}
    assert (out.pre, out.post) == (ch.pre, ch.post)
    t = np.linspace(-3.0, 7.0, 4001)
    deviation = float(np.max(np.abs(out.evaluate(t) - ch.evaluate(t))))
    assert deviation <= 1e-5 * max(1.0, float(np.max(np.abs(ch.values))))
    assert worst <= 1e-5 * max(1.0, float(np.max(np.abs(ch.values))))


def test_unweighted_equivalent_keeps_rules_away_from_weighted_spans():
    ch = weighted_channel("one span")
    ch = ch.with_keys([Key(0.0, 0.3, "smooth", "clamped")] + list(ch.keys))
    out, added, _ = ch.unweighted()
    assert out.keys[0].out_tangent is Tangent.CLAMPED and out.keys[0].in_tangent is Tangent.SMOOTH
    plain = Channel([Key(0.0, 0.0), Key(1.0, 1.0)])
    assert plain.unweighted() == (plain, 0, 0.0)
    assert out.keys[-1].interpolation is Interpolation.CUBIC
