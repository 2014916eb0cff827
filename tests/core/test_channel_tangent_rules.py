"""Issue 18: the handout's end-knot derivatives, and the centripetal, chordal and TCB
tangent rules, each checked against its own definition written out here.

* The CMU 15-462 animator handout (Task 1B, notes/cmu-animator.md §7.4): Catmull-Rom with
  mirrored virtual knots at the ends, "t ≤ first knot → the first value" (and derivatives 0),
  "t ≥ last knot → the last value" (derivatives 0). :func:`handout_spline` is that spline.
* Centripetal / chordal Catmull-Rom (the handout's extra credit): the Barry–Goldman pyramid
  over the keys as points ``p = (t, v)``, knots spaced by ``|Δp|^α``, differentiated through
  every lerp of the pyramid (product rule on value–derivative pairs), then ``dv/dt`` at the
  key. :func:`pyramid` knows nothing of the closed form the channel uses.
* TCB: Kochanek & Bartels (1984), tangents per unit parameter ``DS`` (incoming) and ``DD``
  (outgoing) and their step-size adjustment ``DS·2N₀/(N₀+N₁)``, ``DD·2N₁/(N₀+N₁)``;
  :func:`kb_curve` evaluates their Hermite segments over u ∈ [0, 1] (not the channel's
  per-second polynomials).
"""

from __future__ import annotations

import itertools
import math
import warnings

import numpy as np
import pytest

from qtanimator.core.channel import Channel, Extrapolation, Key, Tangent, catmull_rom

MODES = [m.value for m in Extrapolation]
PTS = [(0.5, 1.0), (0.8, 2.5), (1.6, -0.5), (2.0, 0.25), (2.9, 1.75), (3.0, 1.9), (4.5, -3.0)]


def close(got: float, want: float, tol: float = 1e-9) -> bool:
    return abs(got - want) <= tol * max(1.0, abs(want))


# ----------------------------------------------------------- the handout's spline
def _hermite_unit(p0: float, p1: float, m0: float, m1: float, u: float, d: int) -> float:
    """Task 1A: the Hermite form on [0, 1] and its derivatives (the handout's bases)."""
    if d == 0:
        h = (2 * u**3 - 3 * u**2 + 1, u**3 - 2 * u**2 + u, -2 * u**3 + 3 * u**2, u**3 - u**2)
    elif d == 1:
        h = (6 * u**2 - 6 * u, 3 * u**2 - 4 * u + 1, -6 * u**2 + 6 * u, 3 * u**2 - 2 * u)
    else:
        h = (12 * u - 6, 6 * u - 4, -12 * u + 6, 6 * u - 2)
    return h[0] * p0 + h[1] * m0 + h[2] * p1 + h[3] * m1


def handout_spline(knots: list[tuple[float, float]], t: float, d: int) -> float:
    """Task 1B, as the handout words it."""
    if not knots:
        return 0.0
    if len(knots) == 1:
        return knots[0][1] if d == 0 else 0.0
    if t <= knots[0][0]:
        return knots[0][1] if d == 0 else 0.0
    if t >= knots[-1][0]:
        return knots[-1][1] if d == 0 else 0.0
    j = next(i for i, (tk, _v) in enumerate(knots) if tk > t)  # k2: first knot after t
    (t1, p1), (t2, p2) = knots[j - 1], knots[j]
    t0, p0 = knots[j - 2] if j >= 2 else (t1 - (t2 - t1), p1 - (p2 - p1))
    t3, p3 = knots[j + 1] if j + 1 < len(knots) else (t2 + (t2 - t1), p2 + (p2 - p1))
    m1 = (p2 - p0) / (t2 - t0)
    m2 = (p3 - p1) / (t3 - t1)
    h = t2 - t1
    return _hermite_unit(p1, p2, h * m1, h * m2, (t - t1) / h, d) / h**d


def test_the_handout_example_has_zero_derivatives_at_its_end_knots():
    ch = catmull_rom([(0, 0), (1, 1), (2, 0)])
    for t in (0.0, 2.0):
        for d in (1, 2):
            assert ch.evaluate(t, d) == 0.0
            assert ch.evaluate(np.array([t, 1.0, t]), d)[[0, 2]].tolist() == [0.0, 0.0]
            assert ch.evaluate(np.array([t]), d)[0] == 0.0  # also where every sample is a key
    # Just inside, the spans still move: the end knots are where it stops.
    assert ch.evaluate(1e-9, 1) == pytest.approx(1.0, abs=1e-6)
    assert ch.evaluate(2.0 - 1e-9, 1) == pytest.approx(-1.0, abs=1e-6)
    assert ch.evaluate(2.0 - 1e-9, 2) == pytest.approx(2.0, abs=1e-6)
    assert ch.evaluate(0.0) == 0.0 and ch.evaluate(2.0) == 0.0


@pytest.mark.parametrize("knots", [
    [(0, 0), (1, 1), (2, 0)],
    [(0.0, 0.0), (1.0, 1.0)],
    [(3.0, 2.0)],
    PTS,
    [(-1.0, 0.3), (0.25, -2.0), (0.5, 4.0), (3.0, 4.5)],
])
def test_smooth_keys_with_constant_extrapolation_are_the_handout_spline(knots):
    ch = catmull_rom(knots)
    times = [k[0] for k in knots]
    samples = np.unique(np.concatenate([np.linspace(times[0] - 1.5, times[-1] + 1.5, 301), times,
                                        np.array(times) + 1e-7, np.array(times) - 1e-7]))
    for d in (0, 1, 2):
        arr = ch.evaluate(samples, d)
        for j, t in enumerate(samples):
            want = handout_spline(knots, float(t), d)
            assert close(ch.evaluate(float(t), d), want, 1e-7 if d else 1e-12), (t, d)
            assert arr[j] == ch.evaluate(float(t), d)


# ------------------------------------------------- the other extrapolation modes
def test_end_key_derivatives_belong_to_the_extrapolation_in_every_mode():
    """Documented in docs/decisions.md: at the first key the derivatives are the
    pre-extrapolation's, at the last key the post-extrapolation's (their limit from
    outside); at interior keys still the span that starts there."""
    pts = [(0.5, 1.0, 2.0), (0.8, 2.5, -1.0), (1.6, -0.5, 0.5), (2.9, 1.75, 4.0)]
    for pre, post in itertools.product(MODES, MODES):
        ch = Channel([Key.make(t, v, s, s) for t, v, s in pts], pre, post)
        t0, t1 = pts[0][0], pts[-1][0]
        for t, side, mode in ((t0, -1.0, ch.pre), (t1, 1.0, ch.post)):
            for d in (1, 2):
                got = ch.evaluate(t, d)
                assert ch.evaluate(np.array([t, 1.0]), d)[0] == got
                if mode is Extrapolation.CONSTANT:
                    assert got == 0.0
                elif mode is Extrapolation.LINEAR:
                    assert got == ((pts[0][2] if side < 0 else pts[-1][2]) if d == 1 else 0.0)
                else:  # periodic: the repeated curve just outside
                    assert close(got, ch.evaluate(t + side * 1e-9, d), 1e-5), (pre, post, t, d)
    # The values at the keys are the keys' own, whatever the mode.
    for pre, post in itertools.product(MODES, MODES):
        ch = Channel([Key.make(t, v, s, s) for t, v, s in pts], pre, post)
        assert ch.evaluate(np.array([p[0] for p in pts])).tolist() == [p[1] for p in pts]


def test_cycle_end_keys_take_the_other_end_of_the_period():
    # A cycle whose spans leave the first key at slope 2 and reach the last key at slope 4.
    ch = Channel([Key.make(0.0, 0.0, 2.0, 2.0), Key.make(1.0, 1.0, 4.0, 4.0)], "cycle", "cycle")
    assert ch.evaluate(1.0, 1) == 2.0   # after the last key the cycle starts again
    assert ch.evaluate(0.0, 1) == 4.0   # before the first key the cycle was ending
    bounce = ch.with_extrapolation("bounce", "bounce")
    assert bounce.evaluate(1.0, 1) == -4.0  # after the last key it runs back
    assert bounce.evaluate(0.0, 1) == -2.0


# ---------------------------------------------------- centripetal and chordal
def _lerp(a: tuple[np.ndarray, np.ndarray], b: tuple[np.ndarray, np.ndarray], s0: float, s1: float,
          s: float) -> tuple[np.ndarray, np.ndarray]:
    """((s1 − s)·a + (s − s0)·b)/(s1 − s0) on value–derivative pairs (d/ds by the product rule)."""
    wa, wb = (s1 - s) / (s1 - s0), (s - s0) / (s1 - s0)
    dwa, dwb = -1.0 / (s1 - s0), 1.0 / (s1 - s0)
    return wa * a[0] + wb * b[0], dwa * a[0] + wa * a[1] + dwb * b[0] + wb * b[1]


def pyramid(p: list[np.ndarray], alpha: float, s: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Barry–Goldman: the point of the Catmull-Rom segment p1 → p2 at knot parameter s
    (default s1, the start) and its derivative d/ds. Knots s_{j+1} = s_j + |p_{j+1} − p_j|^α."""
    knots = [0.0]
    for a, b in zip(p, p[1:]):
        knots.append(knots[-1] + float(np.linalg.norm(b - a)) ** alpha)
    s0, s1, s2, s3 = knots
    s = s1 if s is None else s
    zero = np.zeros(2)
    P = [(q, zero) for q in p]
    a1 = _lerp(P[0], P[1], s0, s1, s)
    a2 = _lerp(P[1], P[2], s1, s2, s)
    a3 = _lerp(P[2], P[3], s2, s3, s)
    b1 = _lerp(a1, a2, s0, s2, s)
    b2 = _lerp(a2, a3, s1, s3, s)
    return _lerp(b1, b2, s1, s2, s)


def pyramid_slopes(pts: list[tuple[float, float]], alpha: float) -> list[float]:
    """dv/dt of the 2D Catmull-Rom curve at each key; at the ends the handout's mirrored
    virtual key (p₋₁ = 2p₀ − p₁)."""
    p = [np.array(q, dtype=float) for q in pts]
    ext = [2 * p[0] - p[1], *p, 2 * p[-1] - p[-2]]
    out = []
    for i in range(len(p)):
        if i + 4 <= len(ext):
            _point, tangent = pyramid(ext[i:i + 4], alpha)  # the segment that starts at key i
        else:  # the last key: the end of the segment that reaches it
            seg = ext[i - 1:i + 3]
            s2 = sum(float(np.linalg.norm(b - a)) ** alpha for a, b in zip(seg[:3], seg[1:3]))
            _point, tangent = pyramid(seg, alpha, s2)
        out.append(float(tangent[1] / tangent[0]))
    return out


def test_the_reference_pyramid_is_sound():
    p = [np.array(q, dtype=float) for q in PTS[:4]]
    for alpha in (0.0, 0.5, 1.0):
        # It interpolates p1 and p2 ...
        knots = np.cumsum([0.0] + [np.linalg.norm(b - a) ** alpha for a, b in zip(p, p[1:])])
        assert np.allclose(pyramid(p, alpha, knots[1])[0], p[1])
        assert np.allclose(pyramid(p, alpha, knots[2])[0], p[2])
        # ... and its derivative is the finite difference of its points.
        s, h = 0.3 * knots[1] + 0.7 * knots[2], 1e-6
        fd = (pyramid(p, alpha, s + h)[0] - pyramid(p, alpha, s - h)[0]) / (2 * h)
        assert np.allclose(pyramid(p, alpha, s)[1], fd, rtol=1e-6, atol=1e-8)
    # Uniform knots are the handout's Catmull-Rom: the slope between the two neighbours.
    uniform = pyramid_slopes(PTS, 0.0)
    for i in range(1, len(PTS) - 1):
        assert close(uniform[i], (PTS[i + 1][1] - PTS[i - 1][1]) / (PTS[i + 1][0] - PTS[i - 1][0]), 1e-12)


@pytest.mark.parametrize("rule,alpha", [("centripetal", 0.5), ("chordal", 1.0)])
def test_centripetal_and_chordal_slopes_match_the_barry_goldman_pyramid(rule, alpha):
    rng = np.random.default_rng(18)
    cases = [PTS, [(0.0, 0.0), (1.0, 1.0), (2.0, 0.0)], [(0.0, 0.0), (0.01, 40.0), (3.0, 41.0), (3.1, -5.0)]]
    for _ in range(40):
        n = int(rng.integers(3, 9))
        times = np.cumsum(rng.uniform(0.02, 2.0, n)) - 1.0
        values = rng.normal(0.0, rng.choice([0.1, 1.0, 30.0]), n)
        cases.append(list(zip(times.tolist(), values.tolist())))
    for pts in cases:
        ch = Channel([Key(t, v, rule, rule) for t, v in pts])
        s_in, s_out = ch.slopes()
        want = pyramid_slopes(pts, alpha)
        for i, w in enumerate(want):
            assert close(float(s_in[i]), w) and close(float(s_out[i]), w), (rule, pts, i, s_in[i], w)
        # The curve leaves each interior key along that slope (the span's own derivative).
        for i in range(1, len(pts) - 1):
            assert close(ch.evaluate(pts[i][0], 1), want[i])


def test_the_pyramid_is_c1_so_either_segment_gives_the_key_slope():
    # Key p2 ends the segment p1 → p2 of (p0 … p3) and starts the segment p2 → p3 of (p1 … p4).
    p = [np.array(q, dtype=float) for q in PTS[:5]]
    for alpha in (0.5, 1.0):
        knots = [0.0]
        for a, b in zip(p[0:4], p[1:4]):
            knots.append(knots[-1] + float(np.linalg.norm(b - a)) ** alpha)
        _pt, left = pyramid(p[0:4], alpha, knots[2])
        _pt, right = pyramid(p[1:5], alpha)
        assert close(left[1] / left[0], right[1] / right[0], 1e-12)


def test_alpha_matters():
    """Centripetal, chordal and smooth are different rules on uneven keys (a mutation that
    swapped α would fail the pyramid test above)."""
    pts = [(0.0, 0.0), (0.1, 5.0), (2.0, 5.5), (2.2, 0.0)]
    slopes = {rule: Channel([Key(t, v, rule, rule) for t, v in pts]).slopes()[1][1:3]
              for rule in ("smooth", "centripetal", "chordal")}
    assert not np.allclose(slopes["smooth"], slopes["centripetal"])
    assert not np.allclose(slopes["centripetal"], slopes["chordal"])
    assert np.allclose(pyramid_slopes(pts, 0.5)[1:3], slopes["centripetal"], rtol=1e-12)
    assert not np.allclose(pyramid_slopes(pts, 1.0)[1:3], slopes["centripetal"], rtol=1e-6)


def test_two_keys_and_huge_values_stay_finite():
    two = Channel([Key(0.0, 1.0, "centripetal", "chordal"), Key(1.0, 3.0, "chordal", "centripetal")])
    assert two.slopes()[0].tolist() == [2.0, 2.0] and two.slopes()[1].tolist() == [2.0, 2.0]
    big = Channel([Key(0.0, 0.0, "chordal", "chordal"), Key(1.0, 1e300, "chordal", "chordal"),
                   Key(2.0, -1e300, "centripetal", "centripetal")])
    assert np.isfinite(big.slopes()[0]).all() and np.isfinite(big.slopes()[1]).all()


# ------------------------------------------------------------------------ TCB
def kb_curve(pts: list[tuple[float, float]], tcb: list[tuple[float, float, float]], t: float,
             d: int) -> float:
    """Kochanek–Bartels with the paper's step-size adjustment, as Hermite segments in u.

    The paper has no rule for the first and last key (one neighbour); the channel gives
    them ``(1 − T)`` times the chord of their only span, per unit u of that span (what the
    handout's mirrored virtual key gives when C = B = 0)."""
    n = len(pts)
    times = [p[0] for p in pts]
    vals = [p[1] for p in pts]

    def ds_dd(i: int) -> tuple[float, float]:
        """The incoming (DS) and outgoing (DD) tangent of key i, per unit u of its segments."""
        T, C, B = tcb[i]
        if i in (0, n - 1):
            j = 1 if i == 0 else n - 1
            chord = vals[j] - vals[j - 1]
            return (1 - T) * chord, (1 - T) * chord
        a, b = vals[i] - vals[i - 1], vals[i + 1] - vals[i]
        DS = (1 - T) * (1 + B) * (1 - C) / 2 * a + (1 - T) * (1 - B) * (1 + C) / 2 * b
        DD = (1 - T) * (1 + B) * (1 + C) / 2 * a + (1 - T) * (1 - B) * (1 - C) / 2 * b
        n0, n1 = times[i] - times[i - 1], times[i + 1] - times[i]
        return DS * 2 * n0 / (n0 + n1), DD * 2 * n1 / (n0 + n1)

    j = max(i for i in range(n - 1) if times[i] <= t) if t < times[-1] else n - 2
    h = times[j + 1] - times[j]
    start = ds_dd(j)[1]     # DD of the key the segment leaves
    end = ds_dd(j + 1)[0]   # DS of the key it reaches
    return _hermite_unit(vals[j], vals[j + 1], start, end, (t - times[j]) / h, d) / h**d


@pytest.mark.parametrize("params", [
    [(0.0, 0.0, 0.0)] * 7,
    [(0.5, 0.0, 0.0), (-0.5, 0.3, 0.1), (0.2, -0.7, 0.9), (1.0, 0.0, 0.0), (0.0, 1.0, -1.0), (-1.0, 0.4, 0.4),
     (0.3, 0.3, 0.3)],
    [(0.0, -1.0, 0.0), (0.0, 0.5, 0.0), (0.0, 0.0, 1.0), (0.0, 0.0, -1.0), (0.9, 0.9, 0.9), (0.1, -0.2, 0.3),
     (0.0, 0.0, 0.0)],
])
def test_tcb_matches_kochanek_bartels(params):
    ch = Channel([Key(t, v, "tcb", "tcb", tension=T, continuity=C, bias=B) for (t, v), (T, C, B) in zip(PTS, params)])
    times = np.linspace(PTS[0][0], PTS[-1][0], 403)
    arrays = [ch.evaluate(times, d) for d in (0, 1, 2)]
    for j, t in enumerate(times):
        if float(t) in (PTS[0][0], PTS[-1][0]):
            continue  # derivatives at the end keys are the extrapolation's (tested above)
        for d in (0, 1, 2):
            if d == 2 and any(abs(float(t) - k[0]) < 1e-12 for k in PTS):
                continue
            want = kb_curve(PTS, params, float(t), d)
            assert close(float(arrays[d][j]), want, 1e-9), (t, d, arrays[d][j], want)


def test_tcb_defaults_are_smooth_and_continuity_breaks_the_slope():
    plain = Channel([Key(t, v) for t, v in PTS])
    tcb = Channel([Key(t, v, "tcb", "tcb") for t, v in PTS])
    np.testing.assert_allclose(tcb.slopes()[0], plain.slopes()[0], rtol=1e-14, atol=1e-14)
    np.testing.assert_allclose(tcb.slopes()[1], plain.slopes()[1], rtol=1e-14, atol=1e-14)
    corner = Channel([Key(t, v, "tcb", "tcb", continuity=-0.8 if i == 2 else 0.0) for i, (t, v) in enumerate(PTS)])
    s_in, s_out = corner.slopes()
    assert s_in[2] != pytest.approx(s_out[2])
    tense = Channel([Key(t, v, "tcb", "tcb", tension=1.0) for t, v in PTS])
    assert np.all(tense.slopes()[0] == 0.0) and np.all(tense.slopes()[1] == 0.0)


def test_mixed_rules_on_one_channel():
    rules = ["flat", "linear", "smooth", "clamped", "centripetal", "chordal", "tcb", 0.7]
    keys = [Key.make(t, v, rules[i % len(rules)], rules[(i + 3) % len(rules)], bias=0.25)
            for i, (t, v) in enumerate(PTS)]
    ch = Channel(keys, "cycle", "bounce")
    s_in, s_out = ch.slopes()

    def side(k: Key, which: str) -> Tangent | float:
        rule = getattr(k, f"{which}_tangent")
        return getattr(k, f"{which}_slope") if rule is Tangent.FIXED else rule

    # Each side resolves as it would if every key had that side's rule.
    for i, k in enumerate(keys):
        same_in = Channel([Key.make(t, v, side(k, "in"), side(k, "in"), bias=0.25) for t, v in PTS])
        same_out = Channel([Key.make(t, v, side(k, "out"), side(k, "out"), bias=0.25) for t, v in PTS])
        assert s_in[i] == same_in.slopes()[0][i] and s_out[i] == same_out.slopes()[1][i]
    t = np.linspace(-3.0, 9.0, 777)
    for d in (0, 1, 2):
        arr = ch.evaluate(t, d)
        assert np.isfinite(arr).all()
        assert [ch.evaluate(float(x), d) for x in t[::37]] == arr[::37].tolist()


# ------------------------------------------------------------------ keys and data
def test_tcb_parameters_are_saved_only_when_set():
    assert "tension" not in Key(0.0, 1.0).to_dict()
    k = Key(0.0, 1.0, "tcb", "tcb", tension=0.5, continuity=-0.25, bias=1)
    d = k.to_dict()
    assert (d["in"], d["out"], d["tension"], d["continuity"], d["bias"]) == ("tcb", "tcb", 0.5, -0.25, 1.0)
    assert Key.from_dict(d) == k and type(Key.from_dict(d).bias) is float
    ch = Channel([Key(0.0, 1.0), k.moved(1.0, 2.0), Key(2.0, 0.0, "centripetal", "chordal")])
    assert "tension" not in Channel([Key(0.0, 1.0)]).to_dict(columns=True)
    for columns in (False, True):
        data = ch.to_dict(columns=columns)
        assert Channel.from_dict(data) == ch
        assert np.array_equal(Channel.from_dict(data).slopes()[1], ch.slopes()[1])
    cols = ch.to_dict(columns=True)
    assert cols["tension"] == [0.0, 0.5, 0.0] and cols["out"] == ["smooth", "tcb", "chordal"]
    shared = Channel([Key(0.0, 1.0, "tcb", "tcb", bias=0.5), Key(1.0, 2.0, "tcb", "tcb", bias=0.5)])
    assert shared.to_dict(columns=True)["bias"] == 0.5
    assert Channel.from_dict(shared.to_dict(columns=True)) == shared


@pytest.mark.parametrize("bad,error", [(math.nan, ValueError), (math.inf, ValueError), (True, TypeError),
                                       ("0.5", TypeError), (None, TypeError)])
def test_tcb_parameters_must_be_finite_numbers(bad, error):
    for name in ("tension", "continuity", "bias"):
        with pytest.raises(error, match=name):
            Key(0.0, 1.0, **{name: bad})
    with pytest.raises(error):
        Channel.from_dict({"times": [0.0, 1.0], "values": [0.0, 1.0], "bias": [0.0, bad]})


def test_series_keys_have_default_tcb_parameters():
    keys = Key.series([0.0, 1.0], [1.0, 2.0], "linear")
    assert keys[0] == Key(0.0, 1.0, "linear", "linear", interpolation="linear")
    assert (keys[1].tension, keys[1].continuity, keys[1].bias) == (0.0, 0.0, 0.0)


def test_anim_files_keep_the_catmull_rom_rules_and_write_tcb_as_fixed_slopes():
    from qtanimator.core.clip import AnimationClip
    from qtanimator.formats.anim import AnimExportWarning, format_anim, parse_anim

    centripetal = Channel([Key(t, v, "centripetal", "chordal") for t, v in PTS], "cycle", "linear")
    tcb = Channel([Key(t, v, "tcb", "tcb", tension=0.3, continuity=-0.2, bias=0.4) for t, v in PTS],
                  "linear", "constant")
    clip = AnimationClip([centripetal, tcb], 0.0, 5.0)
    with pytest.warns(AnimExportWarning, match="channel 1 has TCB"):
        text = format_anim(clip)
    back = parse_anim(text)
    assert back.channels[0] == centripetal
    assert all(k.in_tangent is Tangent.FIXED and k.out_tangent is Tangent.FIXED for k in back.channels[1].keys)
    t = np.linspace(-1.0, 6.0, 301)
    for d in (0, 1, 2):
        np.testing.assert_allclose(back.channels[1].evaluate(t, d), tcb.evaluate(t, d), rtol=1e-12, atol=1e-12)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        format_anim(AnimationClip([centripetal], 0.0, 5.0))  # no warning: the rules are written as they are
