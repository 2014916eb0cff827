"""Cubic Bézier spans (core/bezier.py) against an independent reference: de Casteljau on the
control points and on their hodographs, and the parameter found by plain bisection."""

from __future__ import annotations

import numpy as np
import pytest

from qtanimator.core import bezier


def casteljau(points, u):
    pts = list(points)
    while len(pts) > 1:
        pts = [(1.0 - u) * a + u * b for a, b in zip(pts, pts[1:])]
    return pts[0]


def hodograph(points):
    n = len(points) - 1
    return [n * (b - a) for a, b in zip(points, points[1:])]


def reference(xs, ys, x):
    """Value, dy/dx and d²y/dx² of the Bézier (xs, ys) at abscissa x (u by bisection)."""
    lo, hi = 0.0, 1.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if casteljau(xs, mid) < x:
            lo = mid
        else:
            hi = mid
    u = 0.5 * (lo + hi)
    dx, dy = casteljau(hodograph(xs), u), casteljau(hodograph(ys), u)
    ddx, ddy = casteljau(hodograph(hodograph(xs)), u), casteljau(hodograph(hodograph(ys)), u)
    return casteljau(ys, u), dy / dx, (ddy * dx - dy * ddx) / dx ** 3


# A span of 2 s from value 1 to value 4, out slope 3 with a long handle 1.2 s, in slope -1
# with a short handle 0.3 s: x is far from linear in u.
SPAN, VA, VB, SA, SB, WA, WB = 2.0, 1.0, 4.0, 3.0, -1.0, 1.2, 0.3
XS = [0.0, WA, SPAN - WB, SPAN]
YS = [VA, VA + WA * SA, VB - WB * SB, VB]


def _forms():
    f = bezier.span_forms(*(np.array([v]) for v in (SPAN, WA, WB, VB - VA, SA, SB, VA)))
    return tuple(tuple(float(c[0]) if isinstance(c, np.ndarray) else float(c) for c in form) for form in f)


def test_power_coefficients_reproduce_the_control_polygon():
    """((a u + b) u + c) u equals de Casteljau on 0, p1, p2, p3; points 0, 1, 2, 3 give 3u."""
    assert bezier.power_coefficients(1.0, 2.0, 3.0) == (0.0, 0.0, 3.0)
    a, b, c = bezier.power_coefficients(0.7, -0.4, 2.5)
    for u in (0.1, 0.5, 0.9):
        assert ((a * u + b) * u + c) * u == pytest.approx(casteljau([0.0, 0.7, -0.4, 2.5], u), abs=1e-14)


@pytest.mark.parametrize("x", [0.05, 0.4, 0.9, 1.0, 1.3, 1.7, 1.95])
@pytest.mark.parametrize("deriv", [0, 1, 2])
def test_scalar_span_evaluation_matches_the_reference(x, deriv):
    forward, backward = _forms()
    assert bezier.evaluate_span(x, forward, backward, deriv) == pytest.approx(reference(XS, YS, x)[deriv],
                                                                               rel=1e-9, abs=1e-9)


@pytest.mark.parametrize("deriv", [0, 1, 2])
def test_array_span_evaluation_matches_the_reference(deriv):
    """Two spans interleaved (forward 2i, backward 2i + 1): samples of the second span in
    both halves pick the right forms."""
    f = bezier.span_forms(*(np.array(v) for v in ([1.0, SPAN], [0.3, WA], [0.3, WB], [0.5, VB - VA],
                                                     [0.0, SA], [0.0, SB], [7.0, VA])))
    forms = tuple(np.array([[a, b] for a, b in zip(fw, bw)]).reshape(-1) for fw, bw in zip(*f))
    x = np.array([0.05, 0.4, 0.9, 1.3, 1.7, 1.95])
    got = bezier.evaluate_span_array(x, forms, np.ones(len(x), dtype=np.intp), deriv)
    expected = [reference(XS, YS, xi)[deriv] for xi in x]
    np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-9)


def test_solve_finds_the_parameter_and_clamps_outside_the_span():
    forward, _ = _forms()
    ax, bx, cx = forward[:3]
    for x in (0.01, 0.5, 1.0, 1.5, 1.99):
        u = bezier.solve(x, ax, bx, cx, SPAN)
        assert casteljau(XS, u) == pytest.approx(x, abs=1e-13)
        ua = bezier.solve_array(np.array([x]), np.array([ax]), np.array([bx]), np.array([cx]), np.array([SPAN]))
        assert float(ua[0]) == pytest.approx(u, abs=1e-14)
    assert bezier.solve(0.0, ax, bx, cx, SPAN) == 0.0
    assert bezier.solve(-1.0, ax, bx, cx, SPAN) == 0.0
    assert bezier.solve(SPAN, ax, bx, cx, SPAN) == 1.0
    out = bezier.solve_array(np.array([-1.0, 0.0, SPAN, 3.0]), *(np.full(4, v) for v in (ax, bx, cx, SPAN)))
    np.testing.assert_array_equal(out, [0.0, 0.0, 1.0, 1.0])


def test_evaluate_at_a_parameter_matches_de_casteljau():
    """evaluate / evaluate_array at a given u: y(u), y'(u)/x'(u) and the curvature formula."""
    forward, _ = _forms()
    for u in (0.2, 0.6, 0.95):
        dx, dy = casteljau(hodograph(XS), u), casteljau(hodograph(YS), u)
        ddx, ddy = casteljau(hodograph(hodograph(XS)), u), casteljau(hodograph(hodograph(YS)), u)
        expected = (casteljau(YS, u), dy / dx, (ddy * dx - dy * ddx) / dx ** 3)
        coef = tuple(np.array([c]) for c in forward)
        for deriv in range(3):
            assert bezier.evaluate(u, forward, deriv) == pytest.approx(expected[deriv], rel=1e-12, abs=1e-12)
            got = float(bezier.evaluate_array(np.array([u]), coef, deriv)[0])
            assert got == pytest.approx(expected[deriv], rel=1e-12, abs=1e-12)


def test_effective_weights_scale_overlong_handles_to_fill_the_span():
    """1.5 + 0.5 > 1: both scaled by 1/2; 0.2 + 0.3 <= 1: kept."""
    wa, wb = bezier.effective_weights(np.array([1.0, 1.0]), np.array([1.5, 0.2]), np.array([0.5, 0.3]))
    np.testing.assert_allclose(wa, [0.75, 0.2])
    np.testing.assert_allclose(wb, [0.25, 0.3])


@pytest.mark.parametrize("wa, wb", [(1.2, 0.3), (0.05, 1.9), (1.0, 1.0), (1.9, 0.02)])
def test_scalar_and_array_solves_agree_to_the_bit(wa, wb):
    """The module promises the same operations in the same order in both paths, so the
    parameters (and the values) are identical floats, for handles short and long."""
    span = 2.0
    ax, bx, cx = (float(v) for v in bezier.power_coefficients(wa, span - wb, span))
    x = np.linspace(0.0, span, 41)[1:-1]
    x = np.concatenate([x, [1e-9, 1e-3, span - 1e-3, span - 1e-9]])
    scalar = np.array([bezier.solve(float(xi), ax, bx, cx, span) for xi in x])
    array = bezier.solve_array(x, *(np.full(len(x), v) for v in (ax, bx, cx, span)))
    np.testing.assert_array_equal(scalar, array)
    xs = [0.0, wa, span - wb, span]
    np.testing.assert_allclose([casteljau(xs, u) for u in scalar], x, rtol=0, atol=1e-13)
