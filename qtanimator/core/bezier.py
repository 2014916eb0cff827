"""Cubic Bézier spans in time and value: the weighted tangents of issue 13.

A weighted span from ``(ta, va)`` to ``(tb, vb)`` is the cubic Bézier with control points

    P0 = (ta, va),  P1 = (ta + wa, va + wa·sa),  P2 = (tb − wb, vb − wb·sb),  P3 = (tb, vb)

where ``sa`` / ``sb`` are the out slope of the first key and the in slope of the second and
``wa`` / ``wb`` the handles' extents along the time axis (seconds). Both coordinates are
cubics in the Bézier parameter ``u``; the value at a time ``t`` is ``y(u)`` for the ``u``
with ``x(u) = t``. With ``wa = wb = Δt/3`` the x control points are evenly spaced, x is
linear in u and the span is exactly the Hermite span of the same slopes.

Each coordinate is held relative to an end point in power form, ``((a·u + b)·u + c)·u``:
``c = 3·(P1 − P0)``, ``b = 3·(P2 − 2·P1 + P0)``, ``a = P3 − 3·P2 + 3·P1 − P0``. A span has
two such forms, one from its start (*forward*) and one from its end running back in time
(*backward*: the control points reversed, ``x̃ = Δt − x``, and ``y`` stored as ``vb −
ỹ``, i.e. with its y coefficients negated). An offset in the first half of the span is
solved in the forward form and one in the second half in the backward form, so that the
parameter is always small where the handles are short and precision does not depend on
which end of the span a time is near. The solver and the evaluation below do the same
floating-point operations in the same order for a float and for an array, so the scalar
and the array paths of a channel agree to the bit.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]

#: A Newton or bisection step no larger than this (in u) ends the solve. The last Newton
#: step's error is the square of the one before, so u is good to well below 1e-14.
STEP_TOLERANCE = 1e-15
#: Bisection alone shrinks [0, 1] to one float in 53 halvings; Newton needs far fewer.
MAX_ITERATIONS = 100
#: Samples solved together: the solver's dozen temporaries stay in the CPU cache.
CHUNK = 16384


def effective_weights(span: FloatArray, wa: FloatArray, wb: FloatArray) -> tuple[FloatArray, FloatArray]:
    """The handle extents evaluation uses: when ``wa + wb`` exceeds the span, both scaled
    down in proportion so that they fill it exactly (time stays monotonic, as Blender
    clamps its handles). ``wa`` and ``wb`` must be positive."""
    total = wa + wb
    over = total > span
    scale = np.where(over, span / np.where(over, total, 1.0), 1.0)
    return np.where(over, wa * scale, wa), np.where(over, wb * scale, wb)


def span_forms(span: FloatArray, wa: FloatArray, wb: FloatArray, dv: FloatArray, sa: FloatArray,
               sb: FloatArray, va: FloatArray) -> tuple[tuple[FloatArray, ...], tuple[FloatArray, ...]]:
    """The forward and backward forms ``(ax, bx, cx, ay, by, cy, y0, span)`` of spans with
    handle extents ``wa`` / ``wb`` (already clamped), rise ``dv = vb − va`` and slopes
    ``sa`` / ``sb``."""
    fx = power_coefficients(wa, span - wb, span)
    fy = power_coefficients(wa * sa, dv - wb * sb, dv)
    bx = power_coefficients(wb, span - wa, span)
    by = power_coefficients(wb * sb, dv - wa * sa, dv)
    return (*fx, *fy, va, span), (*bx, *(-c for c in by), va + dv, span)


def power_coefficients(p1: FloatArray, p2: FloatArray, p3: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """``(a, b, c)`` of ``((a·u + b)·u + c)·u`` for control points ``0, p1, p2, p3``."""
    return p3 - 3.0 * p2 + 3.0 * p1, 3.0 * (p2 - 2.0 * p1), 3.0 * p1


def solve(x: float, ax: float, bx: float, cx: float, span: float) -> float:
    """The parameter ``u`` in [0, 1] with ``x(u) = x`` (``x`` in [0, span]), by Newton's
    method kept inside a shrinking bracket (a step that leaves it is a bisection).
    ``x(u)`` is increasing, so the root is unique."""
    if not x > 0.0:
        return 0.0
    if not x < span:
        return 1.0
    u = x / span
    lo, hi = 0.0, 1.0
    a3, b2 = 3.0 * ax, 2.0 * bx
    for _ in range(MAX_ITERATIONS):
        f = ((ax * u + bx) * u + cx) * u - x
        if f == 0.0:
            break
        if f < 0.0:
            lo = u
        else:
            hi = u
        d = (a3 * u + b2) * u + cx
        nxt = u - f / d if d > 0.0 else -math.inf
        # A step too small to change u is convergence, not a step out of the bracket.
        if not (lo < nxt < hi or nxt == u):
            nxt = 0.5 * (lo + hi)
        done = abs(nxt - u) <= STEP_TOLERANCE
        u = nxt
        if done:
            break
    return u


def solve_array(x: FloatArray, ax: FloatArray, bx: FloatArray, cx: FloatArray, span: FloatArray) -> FloatArray:
    """:func:`solve` for arrays (one span per sample), operation for operation: each sample
    stops at the iteration where the scalar solve would."""
    u = np.where(x > 0.0, 1.0, 0.0)
    act = np.flatnonzero((x > 0.0) & (x < span))
    if not act.size:
        return u
    xs, a, b, c = x[act], ax[act], bx[act], cx[act]
    uu = xs / span[act]
    a3, b2 = 3.0 * a, 2.0 * b
    lo = np.zeros_like(uu)
    hi = np.ones_like(uu)
    f = np.empty_like(uu)
    d = np.empty_like(uu)
    nxt = np.empty_like(uu)
    for _ in range(MAX_ITERATIONS):
        np.multiply(a, uu, out=f)
        f += b
        f *= uu
        f += c
        f *= uu
        f -= xs
        np.copyto(lo, uu, where=f < 0.0)
        np.copyto(hi, uu, where=f > 0.0)
        np.multiply(a3, uu, out=d)
        d += b2
        d *= uu
        d += c
        np.subtract(uu, np.divide(f, d, out=np.full_like(f, np.inf), where=d > 0.0), out=nxt)
        ok = (lo < nxt) & (nxt < hi)
        ok |= nxt == uu
        np.copyto(nxt, 0.5 * (lo + hi), where=~ok)
        zero = f == 0.0
        np.copyto(nxt, uu, where=zero)
        done = np.abs(nxt - uu) <= STEP_TOLERANCE
        done |= zero
        uu, nxt = nxt, uu
        if done.any():
            u[act[done]] = uu[done]
            keep = ~done
            if not keep.any():
                return u
            act = act[keep]
            xs, a, b, c, a3, b2, uu, lo, hi = (v[keep] for v in (xs, a, b, c, a3, b2, uu, lo, hi))
            f, d, nxt = np.empty_like(uu), np.empty_like(uu), np.empty_like(uu)
    u[act] = uu
    return u


def evaluate_span(x: float, forward: tuple[float, ...], backward: tuple[float, ...], deriv: int) -> float:
    """Value or derivative of a span at offset ``x`` in [0, span] (see the module notes)."""
    span = forward[7]
    if x <= 0.5 * span:
        return evaluate(solve(x, forward[0], forward[1], forward[2], span), forward, deriv)
    res = evaluate(solve(span - x, backward[0], backward[1], backward[2], span), backward, deriv)
    return -res if deriv == 1 else res


def evaluate_span_array(x: FloatArray, forms: tuple[FloatArray, ...], index: npt.NDArray[np.intp],
                        deriv: int) -> FloatArray:
    """:func:`evaluate_span` for arrays, operation for operation. ``forms`` interleaves the
    spans' forms (forward of span ``i`` at ``2·i``, backward at ``2·i + 1``); ``index`` is
    each sample's span."""
    if x.size > CHUNK:
        out = np.empty_like(x)
        for s in range(0, x.size, CHUNK):
            out[s:s + CHUNK] = evaluate_span_array(x[s:s + CHUNK], forms, index[s:s + CHUNK], deriv)
        return out
    span = forms[7].take(2 * index)
    back = x > 0.5 * span
    pick = 2 * index + back
    coef = tuple(arr.take(pick) for arr in forms)
    xx = np.where(back, span - x, x)
    res = evaluate_array(solve_array(xx, coef[0], coef[1], coef[2], span), coef, deriv)
    if deriv == 1:
        np.negative(res, out=res, where=back)
    return res


def evaluate(u: float, coef: tuple[float, ...], deriv: int) -> float:
    """Value (``deriv`` 0), dy/dt (1) or d²y/dt² (2) at parameter ``u``.

    ``coef`` is ``(ax, bx, cx, ay, by, cy, y0, span)`` of one span.
    """
    ax, bx, cx, ay, by, cy, y0, _span = coef
    if deriv == 0:
        return ((ay * u + by) * u + cy) * u + y0
    dx = (3.0 * ax * u + 2.0 * bx) * u + cx
    dy = (3.0 * ay * u + 2.0 * by) * u + cy
    if deriv == 1:
        return dy / dx
    ddx = 6.0 * ax * u + 2.0 * bx
    ddy = 6.0 * ay * u + 2.0 * by
    return (ddy * dx - dy * ddx) / (dx * dx * dx)


def evaluate_array(u: FloatArray, coef: tuple[FloatArray, ...], deriv: int) -> FloatArray:
    """:func:`evaluate` for arrays (``coef`` gathered per sample), operation for operation."""
    ax, bx, cx, ay, by, cy, y0, _span = coef
    if deriv == 0:
        return ((ay * u + by) * u + cy) * u + y0
    dx = (3.0 * ax * u + 2.0 * bx) * u + cx
    dy = (3.0 * ay * u + 2.0 * by) * u + cy
    if deriv == 1:
        result: FloatArray = dy / dx
        return result
    ddx = 6.0 * ax * u + 2.0 * bx
    ddy = 6.0 * ay * u + 2.0 * by
    result = (ddy * dx - dy * ddx) / (dx * dx * dx)
    return result
