"""Property-based tests of channels over random keys, tangent rules and modes."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from hypothesis_profiles import thorough

from qtanimator.core.channel import Channel, Extrapolation, Interpolation, Key

# 60 examples locally, 200 with fixed seeds in CI (tests/hypothesis_profiles.py)
SETTINGS = thorough(deadline=None)

rules = st.one_of(st.sampled_from(["flat", "linear", "smooth", "clamped", "centripetal", "chordal", "tcb"]),
                  st.floats(-20, 20, allow_nan=False))
tcb = st.floats(-1, 1, allow_nan=False)
modes = st.sampled_from(list(Extrapolation))
interps = st.sampled_from(list(Interpolation))


@st.composite
def channels(draw: st.DrawFn, min_keys: int = 0) -> Channel:
    n = draw(st.integers(min_keys, 8))
    start = draw(st.floats(-50, 50, allow_nan=False))
    gaps = draw(st.lists(st.floats(0.01, 5.0), min_size=n, max_size=n))
    times = start + np.cumsum([0.0] + gaps[:-1]) if n else []
    keys = [Key.make(float(t), draw(st.floats(-100, 100, allow_nan=False)), draw(rules), draw(rules),
                     interpolation=draw(interps), tension=draw(tcb), continuity=draw(tcb), bias=draw(tcb))
            for t in times]
    return Channel(keys, draw(modes), draw(modes))


def sample_times(ch: Channel, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    if not ch.keys:
        return rng.uniform(-10, 10, 50)
    t0, t1 = ch.keys[0].time, ch.keys[-1].time
    d = max(t1 - t0, 1.0)
    return np.concatenate([rng.uniform(t0 - 5 * d, t1 + 5 * d, 200), [k.time for k in ch.keys]])


@SETTINGS
@given(channels(), st.integers(0, 2), st.integers(0, 2**32 - 1))
def test_values_are_finite_and_scalar_matches_array(ch: Channel, derivative: int, seed: int) -> None:
    t = sample_times(ch, seed)
    out = ch.evaluate(t, derivative)
    assert out.shape == t.shape and np.isfinite(out).all()
    # The scalar path does the same arithmetic: equal to the last bit.
    for i in range(0, t.size, 17):
        assert ch.evaluate(float(t[i]), derivative) == out[i]


@SETTINGS
@given(channels(min_keys=1))
def test_passes_through_every_key(ch: Channel) -> None:
    times = np.array([k.time for k in ch.keys])
    assert ch.evaluate(times).tolist() == [k.value for k in ch.keys]


@SETTINGS
@given(channels(min_keys=2), st.integers(0, 2**32 - 1), st.integers(1, 4))
def test_periodic_modes_repeat(ch: Channel, seed: int, m: int) -> None:
    t0, t1 = ch.keys[0].time, ch.keys[-1].time
    d = t1 - t0
    rise = ch.keys[-1].value - ch.keys[0].value
    rng = np.random.default_rng(seed)
    # Sample away from the period boundaries, where a cycle may jump.
    u = rng.uniform(0.01, 0.99, 40) * d
    inside = ch.evaluate(t0 + u)
    scale = 1e-9 * max(1.0, np.abs(inside).max(), abs(rise) * m) * max(1.0, abs(t0) + m * d)
    for mode, side in ((ch.post, 1), (ch.pre, -1)):
        t = t0 + u + side * m * d
        got = ch.evaluate(t)
        if mode is Extrapolation.CYCLE:
            np.testing.assert_allclose(got, inside, atol=scale)
        elif mode is Extrapolation.CYCLE_OFFSET:
            np.testing.assert_allclose(got, inside + side * m * rise, atol=scale)
        elif mode is Extrapolation.BOUNCE:
            mirrored = ch.evaluate(t1 - u) if m % 2 else inside
            np.testing.assert_allclose(got, mirrored, atol=scale)
        elif mode is Extrapolation.CONSTANT:
            assert (got == (ch.keys[-1].value if side > 0 else ch.keys[0].value)).all()


@SETTINGS
@given(channels(min_keys=2))
def test_clamped_rules_never_overshoot(ch: Channel) -> None:
    keys = [Key(k.time, k.value, "clamped", "clamped") for k in ch.keys]
    clamped = Channel(keys)
    for a, b in zip(keys, keys[1:]):
        y = clamped.evaluate(np.linspace(a.time, b.time, 50))
        lo, hi = min(a.value, b.value), max(a.value, b.value)
        tol = 1e-9 * max(1.0, abs(lo), abs(hi))
        assert y.min() >= lo - tol and y.max() <= hi + tol
