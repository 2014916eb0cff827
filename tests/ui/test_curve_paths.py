"""The curve editor's paths (qtanimator.ui.curves.paths) against Channel.evaluate.

An independent check of the Hermite → Bézier conversion: every drawn segment of a path
is evaluated in its own Bernstein form (from the path's elements, not from the code that
built them) at interior parameters and compared with ``Channel.evaluate`` at the time its
x gives, for every span shape, tangent rule and extrapolation mode.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from PySide6.QtGui import QPainterPath

from qtanimator.core.channel import Channel, Extrapolation, Interpolation, Key, Tangent
from qtanimator.ui.curves.paths import (
    MAX_COPIES,
    bezier_path,
    extrapolation_path,
    reduced_path,
)

FPS = 60.0
U = np.linspace(0.01, 0.99, 11)
MODES = list(Extrapolation)
RULES = ["flat", "linear", "smooth", "clamped"]


def segments(path: QPainterPath) -> list[list[tuple[float, float]]]:
    """Every drawn segment as its control points: 2 for a line, 4 for a cubic."""
    out = []
    cur = None
    i, n = 0, path.elementCount()
    while i < n:
        e = path.elementAt(i)
        if e.type == QPainterPath.ElementType.MoveToElement:
            cur = (e.x, e.y)
            i += 1
        elif e.type == QPainterPath.ElementType.LineToElement:
            out.append([cur, (e.x, e.y)])
            cur = (e.x, e.y)
            i += 1
        else:
            assert e.type == QPainterPath.ElementType.CurveToElement
            c2, end = path.elementAt(i + 1), path.elementAt(i + 2)
            assert c2.type == end.type == QPainterPath.ElementType.CurveToDataElement
            out.append([cur, (e.x, e.y), (c2.x, c2.y), (end.x, end.y)])
            cur = (end.x, end.y)
            i += 3
    return out


def bernstein(points: list[tuple[float, float]], u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    p = np.array(points)
    if len(p) == 2:
        return p[0, 0] + u * (p[1, 0] - p[0, 0]), p[0, 1] + u * (p[1, 1] - p[0, 1])
    w = np.stack([(1 - u) ** 3, 3 * u * (1 - u) ** 2, 3 * u ** 2 * (1 - u), u ** 3])
    return w.T @ p[:, 0], w.T @ p[:, 1]


def check_path(path: QPainterPath, ch: Channel, fps: float, a: float, b: float, cover: bool = True) -> None:
    """Each non-vertical segment equals the channel at interior points (x in frames), and
    (``cover``) together they cover ``[a, b]`` without gaps."""
    spans = []
    for seg in segments(path):
        x0, x1 = seg[0][0], seg[-1][0]
        if abs(x1 - x0) <= 1e-9 * max(1.0, abs(x0)):
            # A vertical line: a step or a cycle's jump, at a key time (modulo the period).
            continue
        if len(seg) == 4:  # x is linear in the parameter: evenly spaced x control points
            xs = [p[0] for p in seg]
            assert xs[1] - xs[0] == pytest.approx(xs[3] - xs[2], rel=1e-9, abs=1e-9)
            assert xs[2] - xs[1] == pytest.approx(xs[3] - xs[2], rel=1e-9, abs=1e-9)
        x, y = bernstein(seg, U)
        expected = ch.evaluate(x / fps)
        np.testing.assert_allclose(y, expected, rtol=1e-9, atol=1e-9)
        spans.append((min(x0, x1), max(x0, x1)))
    spans.sort()
    assert spans, "nothing drawn"
    if not cover:
        return
    assert spans[0][0] <= a + 1e-9 and spans[-1][1] >= b - 1e-9
    reach = spans[0][1]
    for lo, hi in spans[1:]:
        assert lo <= reach + 1e-9 * max(1.0, abs(lo)), f"gap in the path between {reach} and {lo}"
        reach = max(reach, hi)


def check_channel(ch: Channel, fps: float = FPS) -> None:
    keyed = bezier_path(ch, fps)
    f0, f1 = ch.times[0] * fps, ch.times[-1] * fps
    if len(ch.keys) > 1:
        check_path(keyed, ch, fps, f0, f1)
    period = max(f1 - f0, 1.0)
    a, b = f0 - 3.3 * period, f1 + 3.7 * period
    ext = extrapolation_path(ch, fps, keyed, a, b)
    check_path(ext, ch, fps, a, b, cover=False)
    # Pre and post together with the keyed range cover [a, b].
    whole = QPainterPath(ext)
    whole.addPath(keyed)
    check_path(whole, ch, fps, a, b)


def mixed_channel(pre: Extrapolation | str, post: Extrapolation | str) -> Channel:
    """Every span shape and every tangent rule (broken keys, fixed slopes) in one channel."""
    return Channel([
        Key.make(0.10, 0.5, "flat", "smooth"),
        Key.make(0.35, 2.0, "linear", 4.0, broken=True),
        Key.make(0.50, -1.0, "clamped", "clamped", interpolation=Interpolation.LINEAR),
        Key.make(0.80, 1.5, "smooth", "flat", interpolation=Interpolation.CONSTANT),
        Key.make(1.05, 0.25, -3.0, "linear"),
        Key.make(1.30, 1.0, "smooth", "smooth", interpolation=Interpolation.CONSTANT),
        Key.make(1.45, -0.5, "flat", 2.5),
        Key.make(1.90, 0.75, "clamped", "smooth"),
    ], pre, post)


@pytest.mark.parametrize("pre", MODES)
@pytest.mark.parametrize("post", MODES)
def test_every_span_rule_and_extrapolation_matches_evaluate(pre, post):
    check_channel(mixed_channel(pre, post))


@pytest.mark.parametrize("rule", [*RULES, 1.75])
@pytest.mark.parametrize("interp", list(Interpolation))
def test_each_tangent_rule_and_span_shape_alone(rule, interp):
    keys = [Key.make(t, v, rule, rule, interpolation=interp)
            for t, v in ((0.0, 0.0), (0.4, 1.0), (0.5, 3.0), (1.2, -2.0), (1.3, -2.0))]
    for mode in MODES:
        check_channel(Channel(keys, mode, mode), fps=24.0)


def test_a_single_key_and_two_keys():
    one = Channel([Key(0.5, 2.0)], "cycle", "linear")  # a single key is constant everywhere
    ext = extrapolation_path(one, FPS, bezier_path(one, FPS), -10, 100)
    check_path(ext, one, FPS, -10, 100)
    check_channel(Channel([Key(0.5, 2.0), Key(0.75, -1.0)], "bounce", "cycle_offset"))


channel_st = st.builds(
    lambda times, data, pre, post: Channel(
        [Key.make(t / 60.0, v, ti, to, interpolation=ip, broken=bk)
         for t, (v, ti, to, ip, bk) in zip(times, data)], pre, post),
    st.lists(st.integers(0, 400), min_size=2, max_size=7, unique=True).map(sorted),
    st.lists(st.tuples(st.floats(-50, 50), st.one_of(st.sampled_from(RULES), st.floats(-20, 20)),
                       st.one_of(st.sampled_from(RULES), st.floats(-20, 20)), st.sampled_from(list(Interpolation)),
                       st.booleans()), min_size=7, max_size=7),
    st.sampled_from(MODES), st.sampled_from(MODES))


@settings(max_examples=60, deadline=None)
@given(channel_st)
def test_random_channels_match_evaluate(ch):
    check_channel(ch)


# ------------------------------------------------------------- level of detail
def dense_channel(n: int = 2000, pre: str = "constant", post: str = "constant") -> Channel:
    rng = np.random.default_rng(3)
    t = np.arange(n) / 60.0
    v = np.sin(2.1 * t) + 0.3 * np.sin(7.3 * t) + 0.05 * rng.normal(size=n)
    kinds = [Interpolation.CUBIC, Interpolation.LINEAR, Interpolation.CONSTANT]
    return Channel([Key(float(a), float(b), interpolation=kinds[i % 7 % 3]) for i, (a, b) in enumerate(zip(t, v))],
                   pre, post)


def envelope_check(path: QPainterPath, ch: Channel, column: float, tolerance: float, a: float, b: float) -> None:
    """Every value of the channel lies within what the path draws in its pixel column (or
    a neighbouring one: a line joins neighbouring columns), give or take ``tolerance``."""
    pts = np.array([(path.elementAt(i).x, path.elementAt(i).y) for i in range(path.elementCount())])
    assert (np.diff(pts[:, 0]) >= 0).all()  # a polyline in time order
    x = np.linspace(a, b, 20011)
    y = ch.evaluate(x / FPS)
    drawn_x = np.concatenate([pts[:, 0], x])
    drawn_y = np.concatenate([pts[:, 1], np.interp(x, pts[:, 0], pts[:, 1])])
    col = np.floor(drawn_x / column).astype(np.int64)
    lo_c = col.min()
    size = col.max() - lo_c + 3
    lo = np.full(size, np.inf)
    hi = np.full(size, -np.inf)
    np.minimum.at(lo, col - lo_c + 1, drawn_y)
    np.maximum.at(hi, col - lo_c + 1, drawn_y)
    lo3 = np.minimum(np.minimum(lo[:-2], lo[1:-1]), lo[2:])
    hi3 = np.maximum(np.maximum(hi[:-2], hi[1:-1]), hi[2:])
    c = np.floor(x / column).astype(np.int64) - lo_c
    assert (y >= lo3[c] - tolerance).all() and (y <= hi3[c] + tolerance).all()


@pytest.mark.parametrize("column", [1.0, 2.0, 8.0])
def test_reduced_path_is_bounded_by_the_columns_and_keeps_the_envelope(column):
    ch = dense_channel()
    f0, f1 = ch.times[0] * FPS, ch.times[-1] * FPS
    tolerance = 0.01
    path = reduced_path(ch, FPS, column, tolerance)
    columns = math.ceil((f1 - f0) / column) + 1
    assert path.elementCount() <= 3 * columns + 1
    assert (path.elementAt(0).x, path.elementAt(0).y) == (f0, ch.values[0])
    last = path.elementAt(path.elementCount() - 1)
    assert (last.x, last.y) == (f1, ch.values[-1])
    envelope_check(path, ch, column, tolerance, f0, f1)


def test_reduced_path_keeps_wide_spans_and_sub_pixel_bulges():
    # Dense keys, then one wide cubic span with a large bulge, then a sub-column span with
    # steep fixed slopes (its bulge is narrower than a column but taller than a pixel).
    keys = [Key(i / 60.0, math.sin(i / 10.0)) for i in range(300)]
    keys += [Key.make(10.0, 0.0, "smooth", 40.0), Key.make(20.0, 0.0, -40.0, 60.0),
             Key.make(20.4, 0.0, 60.0, "flat")]
    ch = Channel(keys)
    path = reduced_path(ch, FPS, 4.0, 0.01)
    envelope_check(path, ch, 4.0, 0.05, ch.times[0] * FPS, ch.times[-1] * FPS)


@pytest.mark.parametrize("mode", ["cycle", "cycle_offset", "bounce"])
def test_periodic_extrapolation_of_a_reduced_path_and_the_sampled_fallback(mode):
    ch = dense_channel(400, mode, mode)
    f0, f1 = ch.times[0] * FPS, ch.times[-1] * FPS
    period = f1 - f0
    keyed = reduced_path(ch, FPS, 2.0, 0.01)
    a, b = f0 - 2.5 * period, f1 + 3.5 * period
    ext = extrapolation_path(ch, FPS, keyed, a, b, 2.0, 0.01)
    envelope_check(ext, ch, 2.0, 0.05, a, f0 - 1e-6)
    envelope_check(ext, ch, 2.0, 0.05, f1 + 1e-6, b)
    # Hundreds of periods across the range: sampled per column instead of copied, with
    # periods wider (2) and narrower (8) than a column; and far from the keys.
    short = Channel([Key(0.0, 0.0), Key(0.05, 1.0), Key(0.1, 0.5)], mode, mode)
    for column, (a, b) in ((2.0, (-3000.0, 3000.0)), (8.0, (-3000.0, 3000.0)), (8.0, (1e6, 1e6 + 9000.0))):
        ext = extrapolation_path(short, FPS, bezier_path(short, FPS), a, b, column, 0.01)
        assert (b - a) / (short.times[-1] * FPS) > MAX_COPIES
        assert ext.elementCount() <= 3 * (b - a) / column + 3 * MAX_COPIES
        if a < 0:
            envelope_check(ext, short, column, 0.05, a, -1e-6)
        envelope_check(ext, short, column, 0.05, max(a, 6.0 + 1e-6), b)


def test_stepped_span_is_upright():
    ch = Channel([Key(0.0, 0.0, interpolation=Interpolation.CONSTANT), Key(1.0, 4.0), Key(2.0, 2.0)])
    segs = segments(bezier_path(ch, 10.0))
    assert segs[0] == [(0.0, 0.0), (10.0, 0.0)]   # flat to the next key's time
    assert segs[1] == [(10.0, 0.0), (10.0, 4.0)]  # then up to its value
    assert len(segs[2]) == 4 and segs[2][-1] == (20.0, 2.0)
    assert Tangent.SMOOTH in (ch.keys[1].in_tangent, ch.keys[1].out_tangent)
