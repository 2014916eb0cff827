"""Cloth collisions (cloth_collide.py) against hand-worked numbers: the restitution and Coulomb
friction response, sphere and capsule push-outs (placed away from the origin), the "never left
inside" guarantee, kinematic particles and several capsules."""

from __future__ import annotations

import numpy as np
import pytest

from qtanimator.core.cloth_collide import _respond, capsule_depths, capsules, collide
from qtanimator.core.cloth_params import ClothParams

NONE = np.zeros(0, dtype=np.int64)


def test_friction_on_a_slow_tangential_motion() -> None:
    """v = (0.5, −2, 0) on the ground, e = 0.5, μ = 0.1: |Δv_n| = 1.5·2 = 3, the tangential
    speed 0.5 drops by 0.1·3 = 0.3 to 0.2; the normal one becomes 0.5·2 = 1."""
    v = np.array([[0.5, -2.0, 0.0]])
    _respond(v, np.array([0]), np.array([[0.0, 1.0, 0.0]]), 0.5, 0.1)
    np.testing.assert_allclose(v, [[0.2, 1.0, 0.0]], rtol=1e-12)


def test_friction_never_reverses_the_tangential_motion() -> None:
    """μ·|Δv_n| = 0.8·3 = 2.4 > |v_t| = 1: the particle stops sliding (not −1.4)."""
    v = np.array([[0.0, -2.0, 1.0]])
    _respond(v, np.array([0]), np.array([[0.0, 1.0, 0.0]]), 0.5, 0.8)
    np.testing.assert_allclose(v, [[0.0, 1.0, 0.0]], atol=1e-15)


def test_a_particle_leaving_the_surface_keeps_its_velocity() -> None:
    v = np.array([[0.3, 2.0, -0.4]])
    _respond(v, np.array([0]), np.array([[0.0, 1.0, 0.0]]), 0.5, 0.9)
    np.testing.assert_array_equal(v, [[0.3, 2.0, -0.4]])


def test_ground_projects_to_the_floor_plus_margin_except_kinematic_particles() -> None:
    """Ground at y = −1 with margin 0.01: particles below y = −0.99 go there (normal velocity
    reflected with e = 0.2, friction 0); the kinematic particle 1 stays where it is."""
    p = ClothParams(ground_enabled=True, ground_height=-1.0, collision_margin=0.01, ground_restitution=0.2,
                    ground_friction=0.0)
    x = np.array([[0.0, -1.5, 0.0], [1.0, -2.0, 0.0], [2.0, 0.5, 0.0]])
    v = np.array([[1.0, -3.0, 0.5], [0.0, -1.0, 0.0], [0.0, -1.0, 0.0]])
    collide(p, x, v, [], None, np.array([1]))
    np.testing.assert_allclose(x, [[0.0, -0.99, 0.0], [1.0, -2.0, 0.0], [2.0, 0.5, 0.0]], rtol=1e-15)
    np.testing.assert_allclose(v, [[1.0, 0.6, 0.5], [0.0, -1.0, 0.0], [0.0, -1.0, 0.0]], rtol=1e-12)


def test_a_sphere_away_from_the_origin_pushes_out_along_the_radius_and_leaves_nothing_inside() -> None:
    """Sphere at c = (1, 2, 3), radius 0.5 + margin 0.1: a point at c + (0.3, 0, 0.4)·0.5
    (distance 0.25) goes to c + 0.6·(0.6, 0, 0.8); afterwards no point is strictly inside
    (|x − c|² ≥ 0.6², the test collide itself makes), so a second pass changes nothing."""
    centre = np.array([1.0, 2.0, 3.0])
    p = ClothParams(ground_enabled=False, collision_margin=0.1)
    rng = np.random.default_rng(4)
    dirs = rng.normal(size=(50, 3))
    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    x = np.vstack([centre + 0.5 * np.array([0.3, 0.0, 0.4]), centre + dirs * rng.uniform(0.01, 0.59, (50, 1))])
    v = np.zeros_like(x)
    sphere = (centre, 0.5, 0.0, 0.0)
    collide(p, x, v, [sphere], None, NONE)
    np.testing.assert_allclose(x[0], centre + 0.6 * np.array([0.6, 0.0, 0.8]), rtol=1e-12)
    rel = x - centre
    assert (np.einsum("ij,ij->i", rel, rel) >= 0.6 * 0.6).all()
    np.testing.assert_allclose(np.linalg.norm(rel, axis=1), 0.6, rtol=1e-11)
    before = x.copy()
    collide(p, x, v, [sphere], None, NONE)
    np.testing.assert_array_equal(x, before)


def test_a_particle_at_a_sphere_centre_goes_straight_up() -> None:
    centre = np.array([0.5, 1.0, -1.0])
    p = ClothParams(ground_enabled=False, collision_margin=0.0)
    x = centre[None].copy()
    v = np.zeros((1, 3))
    collide(p, x, v, [(centre, 0.4, 0.0, 0.0)], None, NONE)
    np.testing.assert_allclose(x[0], centre + [0.0, 0.4, 0.0], rtol=1e-11)


def test_sphere_response_reflects_the_normal_velocity_with_its_restitution() -> None:
    """A particle at c + (0, 0.2, 0) inside r = 0.5, moving (1, −2, 0): normal +y, e = 0.5,
    μ = 0.25: v_n −2 → 1, |Δv_n| = 3, tangential 1 → 1 − 0.75 = 0.25."""
    centre = np.array([0.0, 1.0, 0.0])
    p = ClothParams(ground_enabled=False, collision_margin=0.0)
    x = np.array([[0.0, 1.2, 0.0]])
    v = np.array([[1.0, -2.0, 0.0]])
    collide(p, x, v, [(centre, 0.5, 0.5, 0.25)], None, NONE)
    np.testing.assert_allclose(v, [[0.25, 1.0, 0.0]], rtol=1e-12)


# ------------------------------------------------------------------ capsules
def test_capsule_push_out_away_from_the_origin() -> None:
    """Capsule from a = (1, 1, 1) to b = (3, 1, 1), radius 0.2, margin 0.05: a point at
    (2, 1.1, 1) (0.1 from the axis) goes to (2, 1.25, 1); its inward velocity −1 along y is
    removed, the rest kept. A point 0.3 from the axis and one beyond the end stay."""
    p = ClothParams(ground_enabled=False, collision_margin=0.05)
    a, b, r = np.array([[1.0, 1.0, 1.0]]), np.array([[3.0, 1.0, 1.0]]), np.array([0.2])
    x = np.array([[2.0, 1.1, 1.0], [2.0, 1.0, 1.3], [3.3, 1.0, 1.0]])
    v = np.array([[0.5, -1.0, 0.25], [0.0, 0.0, -1.0], [-1.0, 0.0, 0.0]])
    x0, v0 = x.copy(), v.copy()
    collide(p, x, v, [], (a, b, r), NONE)
    np.testing.assert_allclose(x[0], [2.0, 1.25, 1.0], rtol=1e-11)
    np.testing.assert_allclose(v[0], [0.5, 0.0, 0.25], rtol=1e-12)
    np.testing.assert_array_equal(x[1:], x0[1:])
    np.testing.assert_array_equal(v[1:], v0[1:])
    closest, normal, which, depth = capsule_depths(x, a, b, r + 0.05)
    assert (depth <= 0).all()


def test_capsule_depths_of_a_point_beyond_an_end_are_measured_from_that_end() -> None:
    """Segment (1, 0, 0)-(2, 0, 0), radius 0.5: the point (2.3, 0.4, 0) is nearest the end b,
    at distance 0.5 (depth 0), normal (0.6, 0.8, 0); (0.5, 0, 0) is 0.5 from a (depth 0)."""
    a, b = np.array([[1.0, 0.0, 0.0]]), np.array([[2.0, 0.0, 0.0]])
    x = np.array([[2.3, 0.4, 0.0], [0.5, 0.0, 0.0], [1.5, 0.0, 0.1]])
    closest, normal, which, depth = capsule_depths(x, a, b, np.array([0.5]))
    np.testing.assert_allclose(closest, [[2.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.5, 0.0, 0.0]], atol=1e-15)
    np.testing.assert_allclose(normal, [[0.6, 0.8, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]], atol=1e-12)
    np.testing.assert_allclose(depth, [0.0, 0.0, 0.4], atol=1e-12)
    assert which.tolist() == [0, 0, 0]


def test_the_deepest_of_two_capsules_wins() -> None:
    """Capsules along x at y = 0 (r = 0.3) and at y = 1 (r = 0.6): the point (0, 0.5, 0) is
    0.5 from each axis, depths −0.2 and 0.1, so capsule 1 pushes it, to
    (0, 1 − 0.6, 0) = (0, 0.4, 0), where it is 0.4 from capsule 0's axis: outside both."""
    a = np.array([[-1.0, 0.0, 0.0], [-1.0, 1.0, 0.0]])
    b = np.array([[1.0, 0.0, 0.0], [1.0, 1.0, 0.0]])
    r = np.array([0.3, 0.6])
    caps = capsules(a, b, r)
    assert caps is not None and caps[4].tolist() == [0.3, 0.6]
    x = np.array([[0.0, 0.5, 0.0]])
    closest, normal, which, depth = capsule_depths(x, a, b, r)
    assert which.tolist() == [1]
    assert depth[0] == pytest.approx(0.1, abs=1e-12)
    v = np.zeros((1, 3))
    collide(ClothParams(ground_enabled=False, collision_margin=0.0), x, v, [], (a, b, r), NONE)
    np.testing.assert_allclose(x, [[0.0, 0.4, 0.0]], atol=1e-11)


def test_kinematic_particles_ignore_capsules() -> None:
    p = ClothParams(ground_enabled=False, collision_margin=0.0)
    a, b, r = np.array([[0.0, 0.0, 0.0]]), np.array([[1.0, 0.0, 0.0]]), np.array([0.5])
    x = np.array([[0.5, 0.1, 0.0], [0.5, -0.1, 0.0]])
    v = np.zeros((2, 3))
    collide(p, x, v, [], (a, b, r), np.array([0]))
    np.testing.assert_array_equal(x[0], [0.5, 0.1, 0.0])
    np.testing.assert_allclose(x[1], [0.5, -0.5, 0.0], rtol=1e-11)


def test_capsules_keep_start_and_end_places_apart() -> None:
    """Two capsules with start places: (start a, start b, end a, end b, radii) in that order."""
    a = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]
    b = [[1.0, 0.0, 0.0], [2.0, 1.0, 1.0]]
    sa = [[0.0, 0.5, 0.0], [1.0, 1.5, 1.0]]
    sb = [[1.0, 0.5, 0.0], [2.0, 1.5, 1.0]]
    caps = capsules(a, b, [0.1, 0.2], a_start=sa, b_start=sb)
    assert caps is not None
    for got, want in zip(caps, (sa, sb, a, b, [0.1, 0.2])):
        np.testing.assert_array_equal(got, want)
    assert capsules(np.zeros((0, 3)), np.zeros((0, 3)), []) is None


def test_overlapping_capsules_get_three_passes() -> None:
    """Two parallel capsules along x: A at y = 0 (r = 0.1), B at y = 0.3 (r = 0.205, reaching
    down to 0.095). A point at y = 0.09 is deepest in A (0.01 vs −0.005): pass 1 puts it on A
    (y = 0.1, 0.005 inside B), pass 2 on B (y = 0.095, 0.005 inside A), pass 3 on A again,
    where the documented three passes stop (y = 0.1)."""
    a = np.array([[-1.0, 0.0, 0.0], [-1.0, 0.3, 0.0]])
    b = np.array([[1.0, 0.0, 0.0], [1.0, 0.3, 0.0]])
    r = np.array([0.1, 0.205])
    x = np.array([[0.0, 0.09, 0.0]])
    v = np.zeros((1, 3))
    collide(ClothParams(ground_enabled=False, collision_margin=0.0), x, v, [], (a, b, r), NONE)
    np.testing.assert_allclose(x, [[0.0, 0.1, 0.0]], atol=1e-11)


def test_a_particle_exactly_on_a_capsule_surface_is_not_inside() -> None:
    """Depth > 0 is inside: a particle at distance exactly r from the axis (depth 0.0) moving
    inwards is left alone (it is caught next substep if it goes in)."""
    a, b, r = np.array([[0.0, 0.0, 0.0]]), np.array([[1.0, 0.0, 0.0]]), np.array([0.5])
    x = np.array([[0.5, 0.5, 0.0]])
    v = np.array([[0.0, -1.0, 0.0]])
    assert capsule_depths(x, a, b, r)[3][0] == 0.0
    collide(ClothParams(ground_enabled=False, collision_margin=0.0), x, v, [], (a, b, r), NONE)
    np.testing.assert_array_equal(x, [[0.5, 0.5, 0.0]])
    np.testing.assert_array_equal(v, [[0.0, -1.0, 0.0]])


@pytest.mark.parametrize("speed", [0.5, 3.0])
def test_a_particle_inside_a_capsule_moving_out_keeps_its_velocity(speed: float) -> None:
    """Only inward velocity is dropped: a point 0.1 inside the capsule (1, 1, 1) → (3, 1, 1),
    radius 0.2 (margin 0), moving straight out along +y at 0.5 or 3 m/s (below and above
    1 m/s), is pushed to the surface (2, 1.2, 1) and keeps (0, speed, 0.25)."""
    p = ClothParams(ground_enabled=False, collision_margin=0.0)
    a, b, r = np.array([[1.0, 1.0, 1.0]]), np.array([[3.0, 1.0, 1.0]]), np.array([0.2])
    x = np.array([[2.0, 1.1, 1.0]])
    v = np.array([[0.0, speed, 0.25]])
    collide(p, x, v, [], (a, b, r), NONE)
    np.testing.assert_allclose(x[0], [2.0, 1.2, 1.0], rtol=1e-11)
    np.testing.assert_array_equal(v[0], [0.0, speed, 0.25])


def test_kinematic_particles_ignore_spheres() -> None:
    """Kinematic particles never collide (module docstring): a pinned particle 0 at a sphere's
    centre and a pinned particle 1 far outside keep their places and velocities, while the
    free particle 2 at c + (0.3, 0, 0) is pushed to the surface, c + (radius + margin)·x̂ =
    c + (0.5 + 0.1, 0, 0)."""
    p = ClothParams(ground_enabled=False, collision_margin=0.1)
    centre = np.array([1.0, 2.0, 3.0])
    x = np.array([[1.0, 2.0, 3.0], [9.0, 9.0, 9.0], [1.3, 2.0, 3.0]])
    v = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    x0, v0 = x.copy(), v.copy()
    collide(p, x, v, [(centre, 0.5, 0.0, 0.0)], None, np.array([0, 1]))
    np.testing.assert_array_equal(x[:2], x0[:2])
    np.testing.assert_array_equal(v[:2], v0[:2])
    np.testing.assert_allclose(x[2], [1.6, 2.0, 3.0], rtol=1e-9)
