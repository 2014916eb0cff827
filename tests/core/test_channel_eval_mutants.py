"""Channel compilation and evaluation (core/channel_eval.py): the compiled fields checked
against hand-worked Hermite coefficients, and the empty channel."""

from __future__ import annotations

import numpy as np
import pytest

from qtanimator.core.channel import Channel, Key, Tangent
from qtanimator.core.channel_eval import compile_keys

F = Tangent.FIXED


def test_empty_keys_compile_to_zero_scalars():
    """No keys: every scalar of the compiled form is 0 (no period, no rise, no end slopes)."""
    c = compile_keys([])
    assert (c.t0, c.t1, c.period) == (0.0, 0.0, 0.0)
    assert (c.p0, c.p1, c.rise) == (0.0, 0.0, 0.0)
    assert (c.in0, c.out1) == (0.0, 0.0)
    assert c.times.size == 0 and c.a.size == 0


def test_compiled_coefficients_of_a_hand_worked_span():
    """Keys (0, 0) slope 1 and (2, 4) slope 3: p(x) = a x³ + b x² + c x + d with d = 0, c = 1,
    p(2) = 8a + 4b + 2 = 4 and p'(2) = 12a + 4b + 1 = 3 give a = 0, b = 0.5. The sentinel at
    the last key continues the span: value 4, slope 3, curvature 2b = 1."""
    c = compile_keys([Key(0.0, 0.0, F, F, 1.0, 1.0), Key(2.0, 4.0, F, F, 3.0, 3.0)])
    np.testing.assert_allclose(c.a, [0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(c.b, [0.5, 0.5], atol=1e-12)
    np.testing.assert_allclose(c.c, [1.0, 3.0], atol=1e-12)
    np.testing.assert_allclose(c.d, [0.0, 4.0], atol=1e-12)
    assert (c.t0, c.t1, c.period) == (0.0, 2.0, 2.0)
    assert (c.p0, c.p1, c.rise) == (0.0, 4.0, 4.0)
    assert (c.in0, c.out1) == (1.0, 3.0)


def test_evaluation_of_the_hand_worked_span_with_cycle_offset_and_linear_sides():
    """p(x) = x + x²/2 on [0, 2]; cycle_offset after adds the rise 4 per period, linear
    before continues with the first slope 1."""
    ch = Channel([Key(0.0, 0.0, F, F, 1.0, 1.0), Key(2.0, 4.0, F, F, 3.0, 3.0)], "linear", "cycle_offset")
    for t in (0.5, 1.0, 1.7):
        assert ch.evaluate(t) == pytest.approx(t + t * t / 2)
        assert ch.evaluate(t, 1) == pytest.approx(1 + t)
        assert ch.evaluate(t, 2) == pytest.approx(1.0)
        assert ch.evaluate(t + 2.0) == pytest.approx(t + t * t / 2 + 4.0)
        assert ch.evaluate(t + 4.0) == pytest.approx(t + t * t / 2 + 8.0)
    assert ch.evaluate(-1.5) == pytest.approx(-1.5)
    ts = np.array([-1.5, 0.5, 2.5, 4.25])
    np.testing.assert_allclose(ch.evaluate(ts), [-1.5, 0.625, 0.625 + 4.0, 0.25 + 0.03125 + 8.0])
