"""Keys (core/keys.py): the Catmull-Rom slopes on three keys worked by hand, the dictionary
form's defaults, the Kochanek–Bartels parameters' validation and the series constructor."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.channel import Channel, Interpolation, Key, Tangent


@pytest.mark.parametrize("rule, expected", [
    # keys (0, 0), (1, 1), (3, 1): chords d0 = |(1, 1)| = √2, d1 = |(2, 0)| = 2. The slope at the
    # middle key is (w0·Δv0 + w1·Δv1) / (w0·Δt0 + w1·Δt1) with w0 = d1^(2α), w1 = d0^(2α):
    # chordal (α = 1): (4·1 + 2·0) / (4·1 + 2·2) = 0.5; centripetal (α = ½): 2 / (2 + 2√2) = √2 − 1;
    # smooth: (1 − 0) / (3 − 0) = 1/3.
    ("chordal", 0.5), ("centripetal", math.sqrt(2.0) - 1.0), ("smooth", 1.0 / 3.0),
])
def test_three_key_catmull_rom_slope_by_hand(rule, expected):
    ch = Channel([Key(0.0, 0.0, rule, rule), Key(1.0, 1.0, rule, rule), Key(3.0, 1.0, rule, rule)])
    s_in, s_out = ch.slopes()
    assert s_in[1] == pytest.approx(expected, rel=1e-14)
    assert s_out[1] == pytest.approx(expected, rel=1e-14)
    # the end keys: the one-sided secants 1 and 0
    assert (s_out[0], s_in[2]) == (pytest.approx(1.0), pytest.approx(0.0))


def test_four_key_smooth_slopes_use_each_keys_neighbours():
    """Keys (0, 0), (1, 2), (2, 3), (4, 0): interior slopes (3 − 0)/2 and (0 − 2)/3, ends the
    first and last secants 2 and −1.5."""
    ch = Channel([Key(0.0, 0.0), Key(1.0, 2.0), Key(2.0, 3.0), Key(4.0, 0.0)])
    s_in, s_out = ch.slopes()
    np.testing.assert_allclose(s_out, [2.0, 1.5, -2.0 / 3.0, -1.5], rtol=1e-14)
    np.testing.assert_allclose(s_in, s_out, rtol=1e-14)


def test_tcb_with_zero_parameters_is_smooth_and_tension_one_is_flat():
    """T = C = B = 0 gives the smooth slopes; T = 1 gives zero slopes everywhere."""
    pts = [(0.0, 0.0), (1.0, 2.0), (2.0, 3.0), (4.0, 0.0)]
    tcb = Channel([Key(t, v, "tcb", "tcb") for t, v in pts])
    smooth = Channel([Key(t, v) for t, v in pts])
    np.testing.assert_allclose(tcb.slopes()[0], smooth.slopes()[0], rtol=1e-14)
    np.testing.assert_allclose(tcb.slopes()[1], smooth.slopes()[1], rtol=1e-14)
    flat = Channel([Key(t, v, "tcb", "tcb", tension=1.0) for t, v in pts])
    np.testing.assert_array_equal(flat.slopes()[1], 0.0)


def test_key_from_a_minimal_dict_takes_the_defaults():
    """Only t and v given: smooth sides, cubic, not broken, no weights, T = C = B = 0."""
    k = Key.from_dict({"t": 1, "v": 2})
    assert k == Key(1.0, 2.0)
    assert (k.tension, k.continuity, k.bias) == (0.0, 0.0, 0.0)
    assert k.broken is False and k.in_weight is None and k.out_weight is None
    assert k.in_tangent is Tangent.SMOOTH and k.interpolation is Interpolation.CUBIC


def test_tcb_parameters_are_checked_and_stored_as_floats():
    k = Key(0.0, 1.0, "tcb", "tcb", tension=1, continuity=0, bias=-1)
    assert type(k.tension) is float and type(k.bias) is float and type(k.continuity) is float
    for bad in (True, "0.5", None):
        with pytest.raises(TypeError):
            Key(0.0, 1.0, tension=bad)
    for bad in (math.inf, math.nan):
        with pytest.raises(ValueError):
            Key(0.0, 1.0, bias=bad)


def test_make_reads_anim_style_tangents():
    """A number is a fixed slope, a name a rule."""
    k = Key.make(0, 1, 2.5, "flat")
    assert (k.in_tangent, k.in_slope, k.out_tangent, k.out_slope) == (Tangent.FIXED, 2.5, Tangent.FLAT, 0.0)
    assert type(k.time) is float and k.value == 1.0


def test_series_with_only_out_slopes_is_fixed_and_without_slopes_linear():
    keys = Key.series([0.0, 1.0], [0.0, 1.0], Interpolation.CUBIC, out_slopes=[3.0, 4.0])
    assert all(k.in_tangent is Tangent.FIXED and k.out_tangent is Tangent.FIXED for k in keys)
    assert [(k.in_slope, k.out_slope) for k in keys] == [(0.0, 3.0), (0.0, 4.0)]
    keys = Key.series(np.array([[0.0, 1.0, 2.0]]), [1.0, 2.0, 3.0], Interpolation.LINEAR)
    assert [k.time for k in keys] == [0.0, 1.0, 2.0]
    assert all(k.in_tangent is Tangent.LINEAR for k in keys)
    assert keys[1] == Key(1.0, 2.0, "linear", "linear", interpolation="linear")


# ---- surv4: a clamped extremum whose secants' product underflows


def test_clamped_slope_is_zero_at_a_tiny_extremum():
    # docs/decisions.md: clamped tangents are "zero at a local extremum". Here the middle key
    # is a peak (secants +1e-200 and -2e-200) whose secant product (-2e-400) underflows to
    # -0.0; the peak must still be flat, not the smooth slope (-1e-200 - 0) / 2 = -5e-201.
    ch = Channel([Key(0.0, 0.0, "clamped", "clamped"), Key(1.0, 1e-200, "clamped", "clamped"),
                  Key(2.0, -1e-200, "clamped", "clamped")])
    s_in, s_out = ch.slopes()
    assert s_in[1] == 0.0 and s_out[1] == 0.0
