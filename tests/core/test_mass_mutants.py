"""Mass properties against hand-computed closed forms (targets mutation-test survivors):
the moment about the centroid (parallel axis), ellipse shapes through the shape dispatcher,
and the reference program's polygon/rect and line quirks (notes section 5.4) with a pivot
away from the origin."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.mass import (
    MassProperties,
    combine,
    point_properties,
    polygon_properties,
    polyline_properties,
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


def test_combine_sums_masses_and_moments_and_weighs_the_centroids() -> None:
    """Masses 1 at (0, 0) and 3 at (4, 0): total 4, centroid (3, 0); moments add. With no mass
    at all the centroid is the pivot and the mass 0."""
    pivot = np.array([1.0, 1.0])
    a = MassProperties(1.0, np.array([0.0, 0.0]), 2.0, pivot)
    b = MassProperties(3.0, np.array([4.0, 0.0]), 5.0, pivot)
    both = combine([a, b], pivot)
    assert both.mass == 4.0 and both.inertia == 7.0
    np.testing.assert_allclose(both.centroid, [3.0, 0.0])
    np.testing.assert_array_equal(both.pivot, pivot)
    empty = combine([MassProperties(0.0, np.array([5.0, 5.0]), 0.5, pivot)], pivot)
    assert empty.mass == 0.0 and empty.inertia == 0.5
    np.testing.assert_array_equal(empty.centroid, pivot)
    assert combine([], pivot).mass == 0.0


def test_length_offset_and_moment_about_the_centroid() -> None:
    """Centroid (4, 5) from pivot (1, 1): offset (3, 4), length 5; a mass of 2 with I = 60
    about the pivot has 60 − 2·25 = 10 about its centroid (parallel axes), clamped at 0."""
    p = MassProperties(2.0, np.array([4.0, 5.0]), 60.0, np.array([1.0, 1.0]))
    np.testing.assert_array_equal(p.offset, [3.0, 4.0])
    assert p.length == 5.0
    assert p.inertia_about_centroid == pytest.approx(10.0)
    assert MassProperties(2.0, np.array([4.0, 5.0]), 40.0, np.array([1.0, 1.0])).inertia_about_centroid == 0.0


def test_polyline_of_one_or_no_point_has_no_mass() -> None:
    """A single point, or points all in one place: no length, so no mass or moment, the
    centroid on the point; no points: the centroid at the pivot."""
    one = polyline_properties([[2.0, 3.0]], 5.0, [0.0, 0.0])
    assert one.mass == 0.0 and one.inertia == 0.0
    np.testing.assert_array_equal(one.centroid, [2.0, 3.0])
    same = polyline_properties([[2.0, 3.0], [2.0, 3.0], [2.0, 3.0]], 5.0, [0.0, 0.0])
    assert same.mass == 0.0 and same.inertia == 0.0
    np.testing.assert_array_equal(same.centroid, [2.0, 3.0])
    none = polyline_properties(np.zeros((0, 2)), 5.0, [1.0, 1.0])
    assert none.mass == 0.0
    np.testing.assert_array_equal(none.centroid, [1.0, 1.0])
    # a 3-4-5 segment of density 2 about its midpoint: m = 10, I = m·ℓ²/12 = 250/12
    seg = polyline_properties([[0.0, 0.0], [3.0, 4.0]], 2.0, [1.5, 2.0])
    assert seg.mass == pytest.approx(10.0) and seg.inertia == pytest.approx(250.0 / 12.0)


def test_point_shape_is_a_point_mass_of_its_stroke_alpha() -> None:
    """A "point" shape weighs its stroke alpha (2) at its point (3, 4): about the origin
    I = m·d² = 2·25 = 50, in the exact and in the starter's reference table alike."""
    pt = Shape(np.array([[3.0, 4.0]]), False, stroke=(0.0, 0.0, 0.0, 2.0), kind="point")
    for props in (shape_mass_properties(pt, [0.0, 0.0]), reference_shape_mass_properties(pt, [0.0, 0.0])):
        assert props.mass == 2.0 and props.inertia == pytest.approx(50.0)
        np.testing.assert_array_equal(props.centroid, [3.0, 4.0])


def test_point_mass_moment_about_a_pivot_away_from_the_origin() -> None:
    """A point mass m at q has I = m·|q − c|² about c: m = 2 at (4, 6) about (1, 2) gives
    2·(3² + 4²) = 50; at its own pivot it has none."""
    mp = point_properties((4.0, 6.0), 2.0, (1.0, 2.0))
    assert mp.mass == 2.0
    assert mp.inertia == pytest.approx(50.0, rel=1e-12)
    np.testing.assert_array_equal(mp.centroid, [4.0, 6.0])
    assert point_properties((1.0, 2.0), 3.0, (1.0, 2.0)).inertia == 0.0
