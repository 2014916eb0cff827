"""Cloth forces (cloth_forces.py) against closed forms written here: the drag-rate bound without
air, the gust field's modes and its still-air case, the Gershgorin stability bound of small
spring systems worked by hand, and the drag of one triangle."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.cloth_forces import add_drag, drag_rate, stable_dt, turbulence_modes, wind_at
from qtanimator.core.cloth_params import ClothParams


# ------------------------------------------------------------------ drag rate
@pytest.mark.parametrize("change", [{"drag_coefficient": 0.0}, {"air_density": 0.0}])
def test_drag_rate_without_air_or_drag_is_zero(change: dict[str, float]) -> None:
    """½·ρ·c_d = 0: the drag force is identically zero, so is its rate bound (not 1/s)."""
    p = ClothParams(rows=4, cols=4, wind=(3.0, 0.0, 4.0), turbulence=1.0, **change)  # type: ignore[arg-type]
    assert drag_rate(p, 4, 4, 0.01) == 0.0


def test_drag_rate_scales_with_the_triangle_area() -> None:
    """2 m × 1 m over a 3 × 5 grid: 2·4 quads, 16 triangles of 2/16 m²; rate 4·½ρc_d·|w|·area/m
    with |w| = |wind| + 5·turbulence + 5 m/s = 5 + 2 + 5."""
    p = ClothParams(rows=3, cols=5, width=2.0, height=1.0, drag_coefficient=1.0, air_density=1.0,
                    wind=(0.0, 3.0, -4.0), turbulence=0.4)
    assert drag_rate(p, 3, 5, 0.5) == pytest.approx(4 * 0.5 * 1.0 * 1.0 * 12.0 * (2.0 / 16.0) / 0.5, rel=1e-12)


# ------------------------------------------------------------------ wind
def test_still_turbulence_free_wind_is_the_steady_wind_everywhere() -> None:
    """Turbulence 0: the wind at any point and time is ``p.wind`` (no gusts)."""
    p = ClothParams(wind=(1.5, -0.5, 2.0), turbulence=0.0)
    pts = np.array([[0.0, 1.0, 2.0], [3.0, -1.0, 0.5], [0.1, 0.2, 0.3]])
    w = wind_at(p, turbulence_modes(3), 2.7, pts)
    np.testing.assert_array_equal(np.asarray(w), np.tile([1.5, -0.5, 2.0], (3, 1)))


def test_gust_modes_are_four_waves_per_component_in_the_0_5_to_3_hz_band() -> None:
    """The gust field: 4 travelling waves per wind component, wave vectors N(0, 1.5²) per axis (1/m),
    frequencies uniform over 0.5-3 Hz (the step samples gusts once per frame, which needs ≤ 3 Hz),
    phases uniform over [0, 2π). Checked statistically over 200 seeds (2400 frequencies, 7200
    wave-vector components): a band of 1.5-3 Hz or 0.75-4.5 Hz, or a wrong spread, fails."""
    ks, ws, phases = [], [], []
    for seed in range(200):
        k, w, ph = turbulence_modes(seed)
        assert k.shape == (4, 3, 3) and w.shape == (4, 3) and ph.shape == (4, 3)
        ks.append(k)
        ws.append(w)
        phases.append(ph)
    hz = np.concatenate([w.ravel() for w in ws]) / (2 * math.pi)
    assert hz.min() >= 0.5 and hz.max() <= 3.0
    assert hz.min() < 0.52 and hz.max() > 2.98  # the whole band is used
    assert hz.mean() == pytest.approx(1.75, abs=0.05)
    kk = np.concatenate([k.ravel() for k in ks])
    assert kk.mean() == pytest.approx(0.0, abs=0.06)
    assert kk.std() == pytest.approx(1.5, rel=0.05)
    ph = np.concatenate([p.ravel() for p in phases])
    assert ph.min() >= 0.0 and ph.max() < 2 * math.pi
    assert ph.min() < 0.05 and ph.max() > 2 * math.pi - 0.05
    assert ph.mean() == pytest.approx(math.pi, abs=0.15)


def test_gusts_are_a_sum_of_travelling_sines() -> None:
    """wind + turbulence·Σ_m sin(k_m·x + ω_m·t + φ_m)/√(M/2) per component (M = 4 modes: unit
    RMS per unit turbulence), written out here mode by mode, at two points and two times."""
    p = ClothParams(wind=(1.0, -2.0, 0.5), turbulence=1.7)
    k, w, ph = turbulence_modes(9)
    pts = np.array([[0.2, 1.1, -0.3], [-1.0, 0.4, 2.0]])
    for t in (0.0, 1.37):
        want = np.tile(np.array(p.wind), (2, 1))
        for q in range(2):
            for comp in range(3):
                total = sum(math.sin(float(np.dot(k[m, comp], pts[q])) + w[m, comp] * t + ph[m, comp])
                            for m in range(4))
                want[q, comp] += 1.7 * total / math.sqrt(2.0)
        np.testing.assert_allclose(wind_at(p, (k, w, ph), t, pts), want, rtol=1e-12, atol=1e-12)


def test_the_same_seed_gives_the_same_modes() -> None:
    a, b = turbulence_modes(11), turbulence_modes(11)
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x, y)


# ------------------------------------------------------------------ stability bound
def _root(lam_k: float, lam_c: float) -> float:
    """0.9 × the positive root of h²·λ_K/4 + h·λ_C/2 = 1 (λ_K > 0)."""
    roots = np.roots([lam_k / 4.0, lam_c / 2.0, -1.0])
    return 0.9 * float(roots[roots > 0][0])


ONE = np.array([[0, 1]])
X_SPRING = np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0]])


def test_stable_dt_of_a_soft_undamped_spring() -> None:
    """k = 0.2, m = 1, no damping: λ_K = 2k/m = 0.4 (q_a = 0.1 < 1), h = 0.9·√(4/λ_K)."""
    h = stable_dt(ONE, X_SPRING, np.array([0.2]), np.array([0.0]), 1.0, 0.0)
    assert h == pytest.approx(0.9 * math.sqrt(4.0 / 0.4), rel=1e-12)


def test_stable_dt_of_a_soft_damped_spring() -> None:
    """k = 0.2, c = 0.3, m = 1: λ_K = 0.4, λ_C = 0.6 (both quarter/half below 1)."""
    h = stable_dt(ONE, X_SPRING, np.array([0.2]), np.array([0.3]), 1.0, 0.0)
    assert h == pytest.approx(_root(0.4, 0.6), rel=1e-12)


def test_stable_dt_of_pure_damping_is_two_over_lambda_c() -> None:
    """No stiffness: h·λ_C/2 ≤ 1 gives h = 2/λ_C; c = 0.3, m = 1, drag 0.2: λ_C = 0.6 + 0.2."""
    h = stable_dt(ONE, X_SPRING, np.array([0.0]), np.array([0.3]), 1.0, 0.2)
    assert h == pytest.approx(0.9 * 2.0 / 0.8, rel=1e-12)


def test_stable_dt_without_stiffness_damping_or_drag_is_unbounded() -> None:
    assert stable_dt(ONE, X_SPRING, np.array([0.0]), np.array([0.0]), 1.0, 0.0) == math.inf


def test_stable_dt_gershgorin_rows_of_a_slanted_chain() -> None:
    """Springs 0-1 and 1-2 along u = (0.6, 0.8, 0) (lengths 0.5 and 1): |u_a|·Σ|u_b| =
    (0.84, 1.12, 0); the middle particle has both springs, row y = 2·k·1.12, so
    λ = 2·(2·k·1.12)/m with k = 100, m = 0.1 (both matrices, c = 0.5)."""
    springs = np.array([[0, 1], [1, 2]])
    x = np.array([[0.0, 0.0, 0.0], [0.3, 0.4, 0.0], [0.9, 1.2, 0.0]])
    k, c, m = 100.0, 0.5, 0.1
    lam_k = 2.0 * (2 * k * 1.12) / m
    lam_c = 2.0 * (2 * c * 1.12) / m
    h = stable_dt(springs, x, np.full(2, k), np.full(2, c), m, 0.0)
    assert h == pytest.approx(_root(lam_k, lam_c), rel=1e-12)


# ------------------------------------------------------------------ drag of flat grids
def _flat_grid(rows: int, cols: int, dx: float, dy: float) -> np.ndarray:
    r, c = np.divmod(np.arange(rows * cols), cols)
    return np.stack([c * dx, -r * dy, np.zeros(rows * cols)], axis=1)


@pytest.mark.parametrize("rows,cols", [(2, 2), (3, 4), (4, 3)])
def test_drag_on_a_flat_grid_facing_the_wind(rows: int, cols: int) -> None:
    """A flat grid in the x-y plane (row r at y = −r·dy), wind 2 m/s along +z (velocity
    relative to the air w = (0, 0, −2) everywhere): each triangle (area dx·dy/2, normal ±z)
    feels −½ρc_d·|w|²·area·(ŵ·n̂)·n̂ = coef·4·area along +z, a third per corner. The expected
    force is summed here quad by quad over the triangles (a, c, d) and (a, d, b)."""
    dx, dy, coef = 0.3, 0.2, 0.6
    x = _flat_grid(rows, cols, dx, dy)
    rel = np.tile([0.0, 0.0, -2.0], (rows * cols, 1))
    force = np.zeros((rows * cols, 3))
    add_drag(x, rel, rows, cols, coef, force)
    expected = np.zeros((rows * cols, 3))
    per_corner = coef * 4.0 * (dx * dy / 2.0) / 3.0
    for r in range(rows - 1):
        for c in range(cols - 1):
            a, b, cc, d = r * cols + c, r * cols + c + 1, (r + 1) * cols + c, (r + 1) * cols + c + 1
            for tri in ((a, cc, d), (a, d, b)):
                expected[list(tri), 2] += per_corner
    np.testing.assert_allclose(force, expected, rtol=1e-12, atol=1e-15)


def test_drag_on_a_grid_edge_on_to_the_wind_is_zero() -> None:
    """Relative velocity in the cloth's plane: a = area·(v̂·n̂) = 0, no drag."""
    x = _flat_grid(3, 4, 0.3, 0.2)
    rel = np.tile([3.0, 1.0, 0.0], (12, 1))
    force = np.zeros((12, 3))
    add_drag(x, rel, 3, 4, 0.6, force)
    np.testing.assert_allclose(force, 0.0, atol=1e-15)


def test_drag_of_one_corner_moving_falls_on_its_triangles_only() -> None:
    """Only particle 0 (corner a of quad 0, in both its triangles and in no other) moves,
    at (0, 0, −3) relative to the air: each triangle holding it has mean relative velocity
    (0, 0, −1), so feels coef·1·area along +z; particles outside quad 0 feel nothing."""
    rows, cols, dx, dy, coef = 3, 3, 0.5, 0.4, 0.7
    x = _flat_grid(rows, cols, dx, dy)
    rel = np.zeros((9, 3))
    rel[0] = [0.0, 0.0, -3.0]
    force = np.zeros((9, 3))
    add_drag(x, rel, rows, cols, coef, force)
    tri = coef * 1.0 * (dx * dy / 2.0) / 3.0
    expected = np.zeros((9, 3))
    expected[[0, 3, 4], 2] += tri  # (a, c, d) = (0, 3, 4)
    expected[[0, 4, 1], 2] += tri  # (a, d, b) = (0, 4, 1)
    np.testing.assert_allclose(force, expected, rtol=1e-12, atol=1e-15)
