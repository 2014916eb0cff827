"""Compiled evaluation of a channel: per-span polynomial coefficients computed once per
channel, then vectorised evaluation (one ``searchsorted`` and a gather of coefficients, no
Python loop per sample) and the pre / post extrapolation.

Semantics (ARCHITECTURE section 4, notes/cse169-formats.md section 8): the span after key
``i`` is cubic Hermite with ``v0 = Δt·out[i]``, ``v1 = Δt·in[i+1]``, or linear, or constant
(stepped); a cubic span with a weight on either side is a cubic Bézier in time and value
(:mod:`qtanimator.core.bezier`). Before the first key and after the last one the pre / post
extrapolation applies, with strict boundaries for values and the floor convention at exact
period multiples; the derivatives *at* the first and last key are the extrapolation's.

The scalar and the array paths do the same floating-point operations in the same order, so
they agree to the last bit (a test checks this). :class:`qtanimator.core.channel.Channel`
compiles itself once (:func:`compile_keys`) and calls these.
"""

from __future__ import annotations

import math
from bisect import bisect_right
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.core import bezier
from qtanimator.core.keys import PERIODIC, Extrapolation, Interpolation, Key, resolve_slopes

FloatArray = npt.NDArray[np.float64]

__all__ = ["BLOCK", "Compiled", "compile_keys", "evaluate_array", "evaluate_scalar", "hermite", "weighted_spans"]

#: Large arrays are evaluated in blocks of this many samples, so that the dozen or so
#: numpy passes per block stay in the CPU cache.
BLOCK = 65536


@dataclass(frozen=True, eq=False)
class Compiled:
    """Everything evaluation needs, computed once per channel.

    The polynomial of span ``i`` is ``((a x + b) x + c) x + d`` with ``x = t − times[i]``
    in seconds (the Hermite form of notes §8.2 with ``u = x/Δ`` folded into the
    coefficients). Index ``n − 1`` is a sentinel "span" that starts at the last key: its
    value is exactly the last key's value and its first and second derivatives are those
    at the end of the last real span, so ``t == t_last`` needs no special case and a
    stepped last span ends on its key.

    Weighted spans (see :class:`Key`) are Béziers instead: ``weighted`` marks them (None
    when a channel has none, so an unweighted channel runs exactly the Hermite code), and
    ``bez`` holds the forms ``(ax, bx, cx, ay, by, cy, y0, span)`` of
    :mod:`qtanimator.core.bezier`, forward of span ``i`` at ``2·i`` and backward at
    ``2·i + 1``, with x measured as ``rel`` measures it; ``bez_l`` the same per span as
    plain floats, ``(forward, backward)``, or None for a Hermite span.
    """

    times: FloatArray
    values: FloatArray
    slope_in: FloatArray
    slope_out: FloatArray
    rel: FloatArray  # times − t0, computed exactly like ``t − t0`` for a sample
    a: FloatArray
    b: FloatArray
    c: FloatArray
    d: FloatArray
    # Plain-float copies for the scalar path (bisect and Python arithmetic, same rounding).
    rel_l: list[float]
    coef_l: list[tuple[float, float, float, float]]
    t0: float
    t1: float
    period: float
    p0: float
    p1: float
    rise: float  # p_last − p0, the cycle_offset step
    in0: float   # the first key's in slope (linear pre-extrapolation)
    out1: float  # the last key's out slope (linear post-extrapolation)
    weighted: npt.NDArray[np.bool_] | None = None
    bez: tuple[FloatArray, ...] = ()
    bez_l: list[tuple[tuple[float, ...], tuple[float, ...]] | None] | None = None
    # Handle extents (seconds) evaluation uses per span: out of its first key, into its last.
    handle_out: FloatArray | None = None
    handle_in: FloatArray | None = None



def evaluate_scalar(c: Compiled, n: int, pre: Extrapolation, post: Extrapolation, t: float, deriv: int) -> float:
    """The value or a derivative at one time of a channel of ``n`` ≥ 1 keys compiled to ``c``."""
    if n == 1:
        return math.nan if math.isnan(t) else (c.p0 if deriv == 0 else 0.0)
    w = t - c.t0
    period = c.period
    if 0.0 <= w <= period and (deriv == 0 or 0.0 < w < period):
        i = bisect_right(c.rel_l, w) - 1
        if c.bez_l is not None and (bz := c.bez_l[i]) is not None:
            return _bezier(bz, w - c.rel_l[i], deriv)
        return _poly(c.coef_l[i], w - c.rel_l[i], deriv)
    if math.isnan(w):
        return math.nan
    # Outside, or a derivative at the first / last key: those belong to the extrapolation.
    before = w <= 0.0
    mode = pre if before else post
    if mode is Extrapolation.CONSTANT:
        return (c.p0 if before else c.p1) if deriv == 0 else 0.0
    if mode is Extrapolation.LINEAR:
        slope = c.in0 if before else c.out1
        if deriv == 0:
            return c.p0 + c.in0 * w if before else c.p1 + c.out1 * (t - c.t1)
        return slope if deriv == 1 else 0.0
    if not math.isfinite(w):
        return math.nan  # an infinite time has no place in a period
    # At the first key itself, the pre side is the end of the previous period (k = −1).
    k = -1.0 if w == 0.0 else float(math.floor(w / period))
    u = min(max(w - k * period, 0.0), period)
    odd = mode is Extrapolation.BOUNCE and math.fmod(k, 2.0) != 0.0
    if odd:
        u = period - u
    i = max(bisect_right(c.rel_l, u) - 1, 0)
    if c.bez_l is not None and (bz := c.bez_l[i]) is not None:
        res = _bezier(bz, u - c.rel_l[i], deriv)
    else:
        res = _poly(c.coef_l[i], u - c.rel_l[i], deriv)
    if odd and deriv == 1:
        res = -res
    if mode is Extrapolation.CYCLE_OFFSET and deriv == 0:
        res += k * c.rise
    return res

def evaluate_array(c: Compiled, n: int, pre: Extrapolation, post: Extrapolation, t: FloatArray,
                   deriv: int) -> FloatArray:
    """The same at an array of times (flat; blocks of at most :data:`BLOCK` stay in the cache)."""
    if n == 1:
        res = np.full_like(t, c.p0 if deriv == 0 else 0.0)
        res[np.isnan(t)] = np.nan
        return res
    period = c.period
    w = t - c.t0
    if w.size and ((0.0 <= w.min() and w.max() <= period) if deriv == 0 else
                   (0.0 < w.min() and w.max() < period)):
        # Fast path: every sample lies between the first and the last key (strictly for a
        # derivative: the derivatives at the end keys are the extrapolation's).
        i = np.searchsorted(c.rel, w, side="right")
        i -= 1
        return _span_array(c, i, w - c.rel.take(i), deriv)
    with np.errstate(invalid="ignore"):
        return _extrapolate_array(c, pre, post, t, w, deriv)

def _extrapolate_array(c: Compiled, pre: Extrapolation, post: Extrapolation, t: FloatArray, w: FloatArray,
                       deriv: int) -> FloatArray:
    period = c.period
    pre_p = pre in PERIODIC
    post_p = post in PERIODIC
    # Values: the keys are inside (strict boundaries). Derivatives: the first and the last
    # key belong to the pre / post extrapolation (the handout's "at and outside the end knots").
    before = w <= 0.0 if deriv else w < 0.0
    after = w >= period if deriv else w > period
    k: FloatArray | None = None
    odd: npt.NDArray[np.bool_] | None = None
    if pre_p or post_p:
        # k = floor((t - t0) / d) outside the keys, 0 inside and on non-periodic sides;
        # for a derivative at the first key itself k = −1 (the end of the period before).
        q = np.floor(w / period)
        if pre_p and post_p:
            # floor gives 0 inside, except 1 at w == d exactly (the last key itself).
            k = q
            if deriv:
                np.copyto(k, -1.0, where=w == 0.0)
            else:
                np.copyto(k, 0.0, where=w == period)
        elif pre_p:
            k = np.minimum(q, 0.0)
            if deriv:
                np.copyto(k, -1.0, where=w == 0.0)
        else:
            k = np.where(after, q, 0.0)
        u = k * period
        np.subtract(w, u, out=u)
        if pre is Extrapolation.BOUNCE or post is Extrapolation.BOUNCE:
            odd = np.fmod(k, 2.0) != 0.0
            if pre is not Extrapolation.BOUNCE:
                odd &= k > 0.0
            elif post is not Extrapolation.BOUNCE:
                odd &= k < 0.0
    else:
        u = w.copy()
    np.clip(u, 0.0, period, out=u)
    if odd is not None:
        u = np.where(odd, period - u, u)
    # u >= 0 = rel[0], so i >= 0. NaN samples (and infinite ones in a periodic mode)
    # sort after every key, land in the sentinel and stay NaN all the way through.
    i = np.searchsorted(c.rel, u, side="right")
    i -= 1
    res = _span_array(c, i, u - c.rel.take(i), deriv)
    if odd is not None and deriv == 1:
        np.negative(res, out=res, where=odd)
    if k is not None and deriv == 0:
        if pre is Extrapolation.CYCLE_OFFSET and post is Extrapolation.CYCLE_OFFSET:
            res += k * c.rise
        elif pre is Extrapolation.CYCLE_OFFSET:
            res += np.minimum(k, 0.0) * c.rise
        elif post is Extrapolation.CYCLE_OFFSET:
            res += np.maximum(k, 0.0) * c.rise
    if not pre_p:
        fill: Any
        if pre is Extrapolation.LINEAR:
            fill = c.p0 + c.in0 * w if deriv == 0 else (c.in0 if deriv == 1 else 0.0)
        else:
            fill = c.p0 if deriv == 0 else 0.0
        res = np.where(before, fill, res)
    if not post_p:
        if post is Extrapolation.LINEAR:
            fill = c.p1 + c.out1 * (t - c.t1) if deriv == 0 else (c.out1 if deriv == 1 else 0.0)
        else:
            fill = c.p1 if deriv == 0 else 0.0
        res = np.where(after, fill, res)
    return res

def compile_keys(keys: Sequence[Key]) -> Compiled:
    """Everything evaluation needs for these keys (sorted by time)."""
    n = len(keys)
    times = np.array([k.time for k in keys], dtype=np.float64)
    values = np.array([k.value for k in keys], dtype=np.float64)
    s_in, s_out = resolve_slopes(keys, times, values)
    a = np.zeros(n)
    b = np.zeros(n)
    c = np.zeros(n)
    d = values.copy()
    if n >= 2:
        dt = np.diff(times)
        p0, p1 = values[:-1], values[1:]
        interp = [k.interpolation for k in keys[:-1]]
        cubic = np.array([m is Interpolation.CUBIC for m in interp])
        linear = np.array([m is Interpolation.LINEAR for m in interp])
        # Hermite coefficients over u in [0, 1] (notes §8.2), then scaled to seconds.
        v0 = dt * s_out[:-1]
        v1 = dt * s_in[1:]
        A = np.where(cubic, 2 * p0 - 2 * p1 + v0 + v1, 0.0)
        B = np.where(cubic, -3 * p0 + 3 * p1 - 2 * v0 - v1, 0.0)
        C = np.where(cubic, v0, np.where(linear, p1 - p0, 0.0))
        inv = 1.0 / dt
        a[:-1] = A * inv ** 3
        b[:-1] = B * inv ** 2
        c[:-1] = C * inv
        # The sentinel continues the derivatives of the last span at its end.
        h = dt[-1]
        b[-1] = 3.0 * a[-2] * h + b[-2]
        c[-1] = (3.0 * a[-2] * h + 2.0 * b[-2]) * h + c[-2]
    t0 = float(times[0]) if n else 0.0
    t1 = float(times[-1]) if n else 0.0
    rel = times - t0
    weighted = weighted_spans(keys) if n >= 2 else None
    extra: dict[str, Any] = {}
    if weighted is not None:
        extra = _bezier_spans(weighted, rel, values, s_in, s_out, keys)
        if weighted[-2]:
            # The sentinel continues the last (Bézier) span's derivatives at its end.
            fwd, bwd = extra["bez_l"][-2]
            b[-1] = 0.5 * bezier.evaluate_span(fwd[7], fwd, bwd, 2)
            c[-1] = bezier.evaluate_span(fwd[7], fwd, bwd, 1)
    comp = Compiled(
        times, values, s_in, s_out, rel, a, b, c, d,
        rel.tolist(), list(zip(a.tolist(), b.tolist(), c.tolist(), d.tolist())),
        t0, t1, t1 - t0,
        float(values[0]) if n else 0.0, float(values[-1]) if n else 0.0,
        float(values[-1] - values[0]) if n else 0.0,
        float(s_in[0]) if n else 0.0, float(s_out[-1]) if n else 0.0,
        **extra,
    )
    return comp


def _poly(coef: tuple[float, float, float, float], x: float, deriv: int) -> float:
    a, b, c, d = coef
    if deriv == 0:
        return ((a * x + b) * x + c) * x + d
    if deriv == 1:
        return (3.0 * a * x + 2.0 * b) * x + c
    return 6.0 * a * x + 2.0 * b


def _poly_array(comp: Compiled, i: npt.NDArray[np.intp], x: FloatArray, deriv: int) -> FloatArray:
    """Evaluate span ``i`` at offset ``x`` (in place on temporaries, same order as _poly)."""
    a = comp.a.take(i)
    if deriv == 0:
        a *= x
        a += comp.b.take(i)
        a *= x
        a += comp.c.take(i)
        a *= x
        a += comp.d.take(i)
        return a
    if deriv == 1:
        a *= 3.0
        a *= x
        a += 2.0 * comp.b.take(i)
        a *= x
        a += comp.c.take(i)
        return a
    a *= 6.0
    a *= x
    a += 2.0 * comp.b.take(i)
    return a


def hermite(p0: Any, p1: Any, v0: Any, v1: Any, u: Any) -> Any:
    """The Hermite cubic with end values ``p0, p1`` and tangents ``v0, v1`` (per unit u)."""
    u2 = u * u
    u3 = u2 * u
    return (2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * v0 + (-2 * u3 + 3 * u2) * p1 + (u3 - u2) * v1


def _span_array(comp: Compiled, i: npt.NDArray[np.intp], x: FloatArray, deriv: int) -> FloatArray:
    """Evaluate span ``i`` at offset ``x``: the Hermite polynomial, then the Bézier spans
    (only where the channel has any) in place of theirs."""
    res = _poly_array(comp, i, x, deriv)
    if comp.weighted is not None:
        sel = np.flatnonzero(comp.weighted.take(i))
        if sel.size:
            res[sel] = bezier.evaluate_span_array(x.take(sel), comp.bez, i.take(sel), deriv)
    return res


def _bezier(forms: tuple[tuple[float, ...], tuple[float, ...]], x: float, deriv: int) -> float:
    return bezier.evaluate_span(x, forms[0], forms[1], deriv)


def weighted_spans(keys: Sequence[Key]) -> npt.NDArray[np.bool_] | None:
    """Per span (plus the sentinel, never weighted): a cubic span with a weight on either
    side. None when there is none."""
    if all(k.in_weight is None and k.out_weight is None for k in keys):
        return None
    mask = np.zeros(len(keys), dtype=bool)
    for i, (ka, kb) in enumerate(zip(keys, keys[1:])):
        mask[i] = ka.interpolation is Interpolation.CUBIC and (ka.out_weight is not None or kb.in_weight is not None)
    return mask if mask.any() else None


def _bezier_spans(weighted: npt.NDArray[np.bool_], rel: FloatArray, values: FloatArray, s_in: FloatArray,
                  s_out: FloatArray, keys: Sequence[Key]) -> dict[str, Any]:
    """The Bézier data of :class:`Compiled` for a channel with weighted spans."""
    n = len(keys)
    span = np.diff(rel)  # as the evaluation measures offsets into a span
    third = span / 3.0
    wa = np.array([third[i] if k.out_weight is None else k.out_weight for i, k in enumerate(keys[:-1])])
    wb = np.array([third[i] if k.in_weight is None else k.in_weight for i, k in enumerate(keys[1:])])
    wa, wb = bezier.effective_weights(span, wa, wb)
    # Unweighted spans keep their exact third (they are drawn and evaluated as Hermite).
    w = weighted[:-1]
    wa = np.where(w, wa, third)
    wb = np.where(w, wb, third)
    forward, backward = bezier.span_forms(span, wa, wb, np.diff(values), s_out[:-1], s_in[1:], values[:-1])
    # Interleaved (forward of span i at 2i, backward at 2i + 1), plus the sentinel's pair.
    bez = tuple(np.append(np.column_stack([f, b]).reshape(-1), [0.0, 0.0]) for f, b in zip(forward, backward))
    fwd_rows = list(zip(*(arr.tolist() for arr in forward)))
    bwd_rows = list(zip(*(arr.tolist() for arr in backward)))
    bez_l: list[tuple[tuple[float, ...], tuple[float, ...]] | None] = [
        (fwd_rows[i], bwd_rows[i]) if weighted[i] else None for i in range(n - 1)]
    bez_l.append(None)
    return {"weighted": weighted, "bez": bez, "bez_l": bez_l, "handle_out": wa, "handle_in": wb}
