"""Channel semantics (ARCHITECTURE §4, notes/cse169-formats.md §8)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.channel import Channel, Extrapolation, Interpolation, Key, Tangent, catmull_rom

MODES = [m.value for m in Extrapolation]
RULES = ["flat", "linear", "smooth", "clamped", 0.7]


def wavy(pre: str = "constant", post: str = "constant", rule: str | float = "smooth") -> Channel:
    """Five unevenly spaced keys, first and last values different, t0 != 0."""
    pts = [(0.5, 1.0), (0.8, 2.5), (1.6, -0.5), (2.0, 0.25), (2.9, 1.75)]
    return Channel([Key.make(t, v, rule, rule) for t, v in pts], pre, post)


def fd(ch: Channel, t: np.ndarray, derivative: int, h: float = 1e-5) -> np.ndarray:
    """Central finite difference of the (derivative - 1)-th derivative."""
    lower = derivative - 1
    return (ch.evaluate(t + h, lower) - ch.evaluate(t - h, lower)) / (2 * h)


# ------------------------------------------------------------------ pass-through
@pytest.mark.parametrize("rule", RULES)
def test_curve_passes_through_its_keys(rule):
    ch = wavy("cycle", "bounce", rule)
    times = np.array([k.time for k in ch.keys])
    values = np.array([k.value for k in ch.keys])
    assert np.array_equal(ch.evaluate(times), values)
    for t, v in zip(times, values):
        assert ch.evaluate(float(t)) == v


def test_stepped_and_linear_spans():
    ch = Channel([Key(0.0, 1.0, interpolation="constant"), Key(1.0, 3.0, interpolation="linear"),
                  Key(2.0, 5.0, interpolation="constant"), Key(3.0, -1.0)])
    assert ch.evaluate(0.0) == 1.0
    assert ch.evaluate(0.999) == 1.0
    assert ch.evaluate(1.0) == 3.0  # a stepped span ends on the next key's value
    assert ch.evaluate(1.5) == pytest.approx(4.0)
    assert ch.evaluate(1.5, 1) == pytest.approx(2.0)
    assert ch.evaluate(1.5, 2) == 0.0
    assert ch.evaluate(2.5) == 5.0
    assert ch.evaluate(2.5, 1) == 0.0
    assert ch.evaluate(3.0) == -1.0
    # A stepped last span still ends exactly on the last key.
    last = Channel([Key(0.0, 1.0, interpolation="constant"), Key(1.0, 2.0)])
    assert last.evaluate(np.array([0.5, 1.0])).tolist() == [1.0, 2.0]


def test_no_key_and_one_key():
    empty = Channel()
    assert empty.evaluate(3.0) == 0.0
    assert empty.evaluate(np.array([1.0, 2.0])).tolist() == [0.0, 0.0]
    for mode in MODES:
        one = Channel([Key.make(2.0, 7.0, "linear", 3.0)], mode, mode)
        t = np.array([-5.0, 2.0, 2.0 + 1e-12, 40.0])
        assert one.evaluate(t).tolist() == [7.0] * 4
        assert one.evaluate(t, 1).tolist() == [0.0] * 4
        assert one.evaluate(-1.0, 2) == 0.0
        assert one.evaluate(100.0) == 7.0
        s_in, s_out = one.slopes()
        assert s_in.tolist() == [0.0] and s_out.tolist() == [0.0]


def test_scalar_in_float_out_array_in_same_shape():
    ch = wavy("cycle_offset", "linear")
    assert type(ch.evaluate(1.0)) is float
    assert type(ch.evaluate(np.float32(1.0))) is float
    assert type(ch(1.0, 1)) is float
    grid = np.linspace(-3, 6, 24).reshape(2, 3, 4)
    out = ch.evaluate(grid)
    assert isinstance(out, np.ndarray) and out.shape == (2, 3, 4) and out.dtype == np.float64
    assert ch.evaluate([0.5, 0.8]).tolist() == [1.0, 2.5]
    assert ch.evaluate(np.array([])).shape == (0,)
    with pytest.raises(ValueError):
        ch.evaluate(1.0, 3)


# ------------------------------------------------------------------ tangents
def test_tangent_rules_resolve_as_specified():
    ch = Channel([Key.make(0.0, 0.0, "linear", "linear"), Key.make(1.0, 2.0, "smooth", "flat"),
                  Key.make(3.0, 3.0, "linear", "linear"), Key.make(4.0, 0.0, "smooth", "smooth")])
    s_in, s_out = ch.slopes()
    assert s_in[0] == s_out[0] == 2.0  # the first key's linear side uses the span to the next key
    assert s_in[1] == pytest.approx((3.0 - 0.0) / (3.0 - 0.0))  # central, not the mean of secants
    assert s_out[1] == 0.0
    assert s_in[2] == pytest.approx(0.5) and s_out[2] == pytest.approx(-3.0)  # one-sided
    assert s_in[3] == s_out[3] == pytest.approx(-3.0)  # smooth at the end: one-sided
    fixed = Channel([Key.make(0.0, 0.0, 13.7, -0.22), Key(1.0, 1.0)])
    assert fixed.slopes()[0][0] == 13.7 and fixed.slopes()[1][0] == -0.22
    assert fixed.evaluate(1e-9, 1) == pytest.approx(-0.22, abs=1e-6)  # the span leaves on the out slope
    assert fixed.evaluate(0.0, 1) == 0.0  # the first key itself: constant extrapolation's (issue 18)


def test_clamped_has_no_overshoot():
    # Monotone data with very uneven spacing makes smooth tangents overshoot.
    pts = [(0.0, 0.0), (0.1, 1.0), (2.0, 1.2), (2.1, 5.0), (2.2, 5.0), (3.0, 4.0)]
    clamped = Channel([Key.make(t, v, "clamped", "clamped") for t, v in pts])
    smooth = Channel([Key.make(t, v, "smooth", "smooth") for t, v in pts])
    worst_smooth = 0.0
    for (ta, va), (tb, vb) in zip(pts, pts[1:]):
        t = np.linspace(ta, tb, 401)
        lo, hi = min(va, vb), max(va, vb)
        y = clamped.evaluate(t)
        assert y.min() >= lo - 1e-12 and y.max() <= hi + 1e-12
        ys = smooth.evaluate(t)
        worst_smooth = max(worst_smooth, lo - ys.min(), ys.max() - hi)
    assert worst_smooth > 0.05  # the data really does make smooth overshoot
    s_in, _ = clamped.slopes()
    assert s_in[3] == 0.0 or s_in[4] == 0.0  # between equal values
    assert s_in[4] == 0.0  # local maximum


# ------------------------------------------------------------------ derivatives
@pytest.mark.parametrize("rule", ["smooth", "clamped", "flat", 0.7])
def test_derivatives_match_finite_differences_inside(rule):
    ch = wavy(rule=rule)
    times = [k.time for k in ch.keys]
    # Stay away from the keys, where the second derivative jumps.
    t = np.concatenate([np.linspace(a + 0.01, b - 0.01, 13) for a, b in zip(times, times[1:])])
    np.testing.assert_allclose(ch.evaluate(t, 1), fd(ch, t, 1), rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(ch.evaluate(t, 2), fd(ch, t, 2), rtol=1e-5, atol=1e-4)


@pytest.mark.parametrize("mode", MODES)
def test_derivatives_match_finite_differences_in_every_extrapolation_mode(mode):
    ch = wavy(mode, mode)
    d = ch.keys[-1].time - ch.keys[0].time
    keys = np.array([k.time for k in ch.keys])
    t = np.concatenate([np.linspace(-6.0, 0.49, 151), np.linspace(2.91, 11.0, 151)])
    # Keep clear of the images of keys, where derivatives may jump (cycle, bounce).
    images = (keys[None, :] + d * np.arange(-6, 7)[:, None]).ravel()
    t = t[np.min(np.abs(t[:, None] - images[None, :]), axis=1) > 1e-3]
    assert t.size > 200
    np.testing.assert_allclose(ch.evaluate(t, 1), fd(ch, t, 1), rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(ch.evaluate(t, 2), fd(ch, t, 2), rtol=1e-5, atol=2e-4)


def test_c1_continuity_at_smooth_keys():
    ch = wavy("linear", "linear")
    eps = 1e-9
    for k in ch.keys:
        left_v, right_v = ch.evaluate(k.time - eps), ch.evaluate(k.time + eps)
        assert left_v == pytest.approx(right_v, abs=1e-7)
        left_d, right_d = ch.evaluate(k.time - eps, 1), ch.evaluate(k.time + eps, 1)
        assert left_d == pytest.approx(right_d, abs=1e-6)
    # Linear extrapolation continues the end slopes: C1 at the first and last keys too.
    s_in, s_out = ch.slopes()
    assert ch.evaluate(ch.keys[0].time - 1e-3, 1) == pytest.approx(s_in[0])
    assert ch.evaluate(ch.keys[-1].time + 1e-3, 1) == pytest.approx(s_out[-1])


def test_broken_fixed_tangents_give_a_corner():
    ch = Channel([Key(0, 0), Key.make(1.0, 1.0, 2.0, -1.0), Key(2, 0)])
    assert ch.evaluate(1.0 - 1e-7, 1) == pytest.approx(2.0, abs=1e-5)
    assert ch.evaluate(1.0 + 1e-7, 1) == pytest.approx(-1.0, abs=1e-5)


# ------------------------------------------------------------------ extrapolation
def test_constant_extrapolation():
    ch = wavy()
    assert ch.evaluate(-100.0) == 1.0 and ch.evaluate(0.4999) == 1.0
    assert ch.evaluate(1e9) == 1.75
    assert ch.evaluate(np.array([-1.0, 50.0]), 1).tolist() == [0.0, 0.0]


def test_linear_extrapolation():
    ch = wavy("linear", "linear")
    s_in, s_out = ch.slopes()
    for s in (1e-6, 0.3, 10.0):
        assert ch.evaluate(0.5 - s) == pytest.approx(1.0 - s_in[0] * s)
        assert ch.evaluate(2.9 + s) == pytest.approx(1.75 + s_out[-1] * s)
        assert ch.evaluate(2.9 + s, 2) == 0.0
    # The first key's *in* slope and the last key's *out* slope are used.
    ch2 = Channel([Key.make(0.0, 0.0, 5.0, 1.0), Key.make(1.0, 1.0, -2.0, 3.0)], "linear", "linear")
    assert ch2.evaluate(-1.0) == -5.0
    assert ch2.evaluate(2.0) == 4.0


def test_cycle_is_periodic_and_lands_on_the_first_key_at_multiples():
    ch = wavy("cycle", "cycle")
    t0, t1 = 0.5, 2.9
    d = t1 - t0
    inside = np.linspace(t0 + 1e-6, t1 - 1e-6, 97)
    for m in (-3, -1, 1, 2, 7):
        np.testing.assert_allclose(ch.evaluate(inside + m * d), ch.evaluate(inside), atol=1e-9)
    assert ch.evaluate(t1) == 1.75  # strict boundary: the last key itself is inside
    # Floor convention: an exact multiple outside the keys is the first key's value
    # (times that are exact in binary, so the multiples are exact too).
    dyadic = Channel([Key(0.5, 1.0), Key(1.25, 3.0), Key(2.75, 1.75)], "cycle", "cycle")
    assert dyadic.evaluate(0.5 + 2.25) == 1.75  # m = 1 is the last key itself
    for m in (-3, -1, 2, 7):
        assert dyadic.evaluate(0.5 + m * 2.25) == 1.0
        assert dyadic.evaluate(np.array([0.5 + m * 2.25])).tolist() == [1.0]
        assert dyadic.evaluate(0.5 + m * 2.25 - 1e-9) == pytest.approx(1.75, abs=1e-7)


def test_cycle_offset_accumulates_and_is_continuous_at_multiples():
    ch = wavy("cycle_offset", "cycle_offset")
    t0, t1 = 0.5, 2.9
    d, rise = t1 - t0, 1.75 - 1.0
    inside = np.linspace(t0, t1 - 1e-9, 97)
    for m in (-4, -1, 1, 3):
        np.testing.assert_allclose(ch.evaluate(inside + m * d), ch.evaluate(inside) + m * rise, atol=1e-9)
        edge = t0 + m * d
        assert ch.evaluate(edge) == pytest.approx(1.0 + m * rise, abs=1e-12)
        assert ch.evaluate(edge - 1e-9) == pytest.approx(ch.evaluate(edge + 1e-9), abs=1e-7)


def test_bounce_is_symmetric():
    ch = wavy("bounce", "bounce")
    t0, t1 = 0.5, 2.9
    d = t1 - t0
    s = np.linspace(1e-6, d - 1e-6, 61)
    np.testing.assert_allclose(ch.evaluate(t1 + s), ch.evaluate(t1 - s), atol=1e-12)
    np.testing.assert_allclose(ch.evaluate(t0 - s), ch.evaluate(t0 + s), atol=1e-12)
    np.testing.assert_allclose(ch.evaluate(t1 + s, 1), -ch.evaluate(t1 - s, 1), atol=1e-9)
    # Two reflections make a period; the reflection uses t0 + t_last − t (t0 != 0 here).
    np.testing.assert_allclose(ch.evaluate(t0 + s + 2 * d), ch.evaluate(t0 + s), atol=1e-9)
    assert ch.evaluate(t1 + d) == pytest.approx(1.0, abs=1e-12)  # k = 1 odd: lands on t0
    assert ch.evaluate(t1 + 2 * d) == pytest.approx(1.75, abs=1e-12)


def test_pre_and_post_modes_are_independent():
    ch = wavy("bounce", "cycle_offset")
    assert ch.evaluate(0.5 - 0.3) == pytest.approx(ch.evaluate(0.5 + 0.3))
    assert ch.evaluate(2.9 + 0.3) == pytest.approx(ch.evaluate(0.5 + 0.3) + 0.75)
    ch2 = wavy("linear", "cycle")
    assert ch2.evaluate(-1.0) == pytest.approx(1.0 - 1.5 * ch2.slopes()[0][0])
    assert ch2.evaluate(2.9 + 0.3) == pytest.approx(ch2.evaluate(0.8))


def test_nan_and_infinite_times():
    ch = wavy("constant", "cycle")
    out = ch.evaluate(np.array([math.nan, -math.inf, math.inf]))
    assert math.isnan(out[0]) and out[1] == 1.0 and math.isnan(out[2])
    assert math.isnan(ch.evaluate(math.nan)) and ch.evaluate(-math.inf) == 1.0


# ------------------------------------------------------------------ the reference sample
def sample_anim_channels() -> list[Channel]:
    """data/cse169/anim/sample.anim, typed in from the file."""
    K = Key.make
    return [
        Channel([K(0.0, 0.1, "smooth", "smooth"), K(0.5, -0.3, "flat", "flat"),
                 K(0.75, 0.25, "linear", "linear"), K(1.1, 0.4, 13.7, -0.22)], "constant", "linear"),
        Channel([K(0.0, 0.1, "smooth", "smooth"), K(0.2, 0.5, "smooth", "smooth"),
                 K(0.4, -0.2, "smooth", "smooth"), K(0.6, 0.3, "smooth", "smooth")], "cycle", "cycle_offset"),
        Channel([K(0.0, 0.0, "flat", "flat"), K(0.5, 1.0, "flat", "flat"),
                 K(1.0, 0.0, "flat", "flat"), K(2.0, 0.0, "flat", "flat")], "bounce", "constant"),
    ]


WORKED = [  # notes §8.4
    (-1.0, 0.1, 0.5, 0.0), (-0.5, 0.1, 0.36875, 1.0), (-0.25, 0.1, -0.083594, 0.5),
    (0.3, -0.1976, 0.14375, 0.648), (1.5, 0.312, 0.54375, 0.0), (2.5, 0.092, 1.16875, 0.0),
    (3.0, -0.018, 1.1, 0.0), (4.0, -0.238, 1.0, 0.0),
]


def test_worked_values_of_sample_anim():
    chans = sample_anim_channels()
    times = np.array([row[0] for row in WORKED])
    for c, ch in enumerate(chans):
        expected = np.array([row[c + 1] for row in WORKED])
        np.testing.assert_allclose(ch.evaluate(times), expected, atol=1e-6)
        for t, e in zip(times, expected):
            assert ch.evaluate(float(t)) == pytest.approx(e, abs=1e-6)


def test_sample_anim_numbers_match_the_file(shared_data):
    """The hand-typed channels above are the file's numbers."""
    text = (shared_data / "cse169" / "anim" / "sample.anim").read_text()
    rows = [line.split() for line in text.splitlines()]
    keys = [r for r in rows if len(r) == 4 and r[0][0].isdigit()]
    typed = [k for ch in sample_anim_channels() for k in ch.keys]
    assert [(float(r[0]), float(r[1])) for r in keys] == [(k.time, k.value) for k in typed]
    modes = [r[1:] for r in rows if r and r[0] == "extrapolate"]
    assert modes == [[ch.pre.value, ch.post.value] for ch in sample_anim_channels()]


def test_wasp_walk_at_an_exact_period_multiple(shared_data):
    anim = pytest.importorskip("qtanimator.formats.anim")
    path = shared_data / "cse169" / "wasp_walk" / "wasp_walk.anim"
    clip = anim.load_anim(path)
    got = [clip.channels[i].evaluate(-2.0) for i in (2, 24, 25, 26)]
    np.testing.assert_allclose(got, [1.35, -0.541324, 0.718820, 1.467731], atol=1e-6)


# ------------------------------------------------------------------ values and editing
def test_key_make_and_dict_round_trip():
    k = Key.make(1, 2, "clamped", -0.5, interpolation="linear", broken=True)
    assert k.in_tangent is Tangent.CLAMPED and k.out_tangent is Tangent.FIXED and k.out_slope == -0.5
    assert k.interpolation is Interpolation.LINEAR
    assert Key.from_dict(k.to_dict()) == k
    ch = Channel([k, Key(0.0, 1.0)], "bounce", "cycle_offset")
    assert Channel.from_dict(ch.to_dict()) == ch
    assert hash(Channel.from_dict(ch.to_dict())) == hash(ch)
    with pytest.raises(ValueError):
        Key(math.nan, 1.0)
    with pytest.raises(ValueError):
        Key.make(0.0, 1.0, math.inf)
    with pytest.raises(ValueError):
        Key(0.0, 1.0, "bumpy")


def test_channels_are_immutable_values():
    ch = catmull_rom([(0.0, 0.0), (1.0, 1.0)])
    ch2 = ch.set_key(Key(0.5, 3.0))
    assert len(ch) == 2 and len(ch2) == 3 and ch2.evaluate(0.5) == 3.0
    # Setting a key at an existing time keeps its rules and changes only its value.
    flat = Channel([Key(0.0, 0.0, "flat", "flat"), Key(1.0, 1.0)])
    assert flat.set_key(Key(0.0, 5.0)).keys[0] == Key(0.0, 5.0, "flat", "flat")
    assert ch2.remove_keys([1]).evaluate(0.5) == 0.5
    with pytest.raises(ValueError):
        ch2.replace_keys({0: Key(1.0, 9.0)})
    with pytest.raises(ValueError):
        Channel([Key(1.0, 0.0), Key(1.0, 1.0)])
    assert ch.with_extrapolation(post="cycle").post is Extrapolation.CYCLE
    assert ch.with_extrapolation(post="cycle").pre is Extrapolation.CONSTANT
    with pytest.raises(AttributeError):
        ch.pre = Extrapolation.CYCLE  # type: ignore[misc]
    assert ch.key_index(1.0 + 1e-12) == 1 and ch.key_index(0.5) is None


def test_large_arrays_are_evaluated_in_blocks_identically():
    ch = wavy("bounce", "cycle_offset")
    t = np.linspace(-20.0, 20.0, 200_003)
    whole = ch.evaluate(t)
    parts = np.concatenate([ch.evaluate(t[:1000]), ch.evaluate(t[1000:])])
    assert np.array_equal(whole, parts)
