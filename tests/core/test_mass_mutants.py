"""Mass properties against hand-computed closed forms (targets mutation-test survivors):
the moment about the centroid (parallel axis), ellipse shapes through the shape dispatcher,
and the reference program's polygon/rect and line quirks (notes section 5.4) with a pivot
away from the origin."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.mass import (
    polygon_properties,
    reference_shape_mass_properties,
    shape_mass_properties,
)
from qtanimator.core.rig2d import Shape

RECT = np.array([[1.0, 2.0], [5.0, 2.0], [5.0, 8.0], [1.0, 8.0]])  # 4 x 6, centre (3, 5)


def test_moment_about_the_centroid_of_a_rectangle_is_m_w2_plus_h2_over_12() -> None:
    m = polygon_properties(RECT, 2.0, (-3.0, 7.0))
    mass = 2.0 * 24.0
    assert m.inertia_about_centroid == pytest.approx(mass * (4.0 ** 2 + 6.0 ** 2) / 12.0)  # 208


def test_moment_about_the_centroid_of_a_disc_is_m_r2_over_2() -> None:
    disc = Shape(np.zeros((0, 2)), True, fill=(0.0, 0.0, 0.0, 0.5), kind="ellipse",
                 ellipse=(np.array([3.0, 4.0]), np.diag([2.0, 2.0])))
    m = shape_mass_properties(disc, (0.0, 0.0))
    mass = 0.5 * math.pi * 4.0
    assert m.mass == pytest.approx(mass)
    np.testing.assert_allclose(m.centroid, (3.0, 4.0))
    assert m.inertia == pytest.approx(mass * 4.0 / 2.0 + mass * 25.0)
    assert m.inertia_about_centroid == pytest.approx(mass * 4.0 / 2.0)


def test_reference_rect_moment_subtracts_the_pivot_twice() -> None:
    """Notes 5.4 items 1-2 by hand: corners − 2c with c = (0.5, 0.5) are (0,1), (4,1), (4,7),
    (0,7); x_i = −4, 24, 28, 0 (Σ 48); |a_i + a_i+1|² = 20, 128, 212, 64;
    Σ |.|²·x_i / 6 = 8928 / 6 = 1488; / 48 = 31; times ρ_f = 2: 62."""
    rect = Shape(RECT.copy(), True, fill=(0.0, 0.0, 0.0, 2.0), kind="rect")
    m = reference_shape_mass_properties(rect, (0.5, 0.5))
    assert m.inertia == pytest.approx(62.0)
    assert m.mass == pytest.approx(48.0)
    np.testing.assert_allclose(m.centroid, (3.0, 5.0))


def test_reference_polygon_moment_by_hand() -> None:
    """Same rectangle as a polygon about the origin: x_i = −8, 30, 32, −6 (Σ 48);
    |a_i + a_i+1|² = 52, 200, 292, 104; Σ = 14304; / 6 / 48 = 149/3; ρ_f = 2."""
    poly = Shape(RECT.copy(), True, fill=(0.0, 0.0, 0.0, 2.0), kind="polygon")
    assert reference_shape_mass_properties(poly, (0.0, 0.0)).inertia == pytest.approx(2.0 * 149.0 / 3.0)


def test_reference_line_moment_is_four_thirds_rho_l_d2() -> None:
    """Notes 5.4 item 3: ρ_s·(4/3)·ℓ·|d|²; ℓ = 10, midpoint (3, 4), pivot (1, 1): |d|² = 13;
    ρ_s = 1e-4 (opaque stroke, width 1)."""
    line = Shape(np.array([[0.0, 0.0], [6.0, 8.0]]), False, fill=(0.0, 0.0, 0.0, 0.0),
                 stroke=(0.0, 0.0, 0.0, 1.0), stroke_width=1.0, kind="line")
    m = reference_shape_mass_properties(line, (1.0, 1.0))
    assert m.mass == pytest.approx(1e-4 * 10.0)
    np.testing.assert_allclose(m.centroid, (3.0, 4.0))
    assert m.inertia == pytest.approx(1e-4 * (4.0 / 3.0) * 10.0 * 13.0)
