"""The cloth against expected values written here (mutation survivors, issue 17).

Closed forms from the documented models (drag rate, stability bound, collision response,
gust amplitude), hand-written steps and a finite-difference spring energy, on a cloth rotated
out of the x–y plane with wind that has a z component, through the numpy path and (when numba
is installed) the compiled one.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.cloth import IMPLICIT_MAX_STEP, MAX_AUTO_SUBSTEPS, Cloth, ClothBlowUp, ClothParams
from qtanimator.core.cloth_collide import _respond, capsules, collide
from qtanimator.core.cloth_forces import drag_rate, stable_dt, turbulence_modes, wind_at
from qtanimator.core.cloth_grid import vertex_normals
from qtanimator.core.cloth_implicit import implicit_pattern
from qtanimator.core.cloth_kernels import HAVE_NUMBA
from qtanimator.document.parameters import CLOTH

ACCELERATE = [False, pytest.param(True, marks=pytest.mark.skipif(not HAVE_NUMBA, reason="numba not installed"))]

TILTED = dict(rows=4, cols=5, width=0.8, height=0.6, total_mass=0.4, structural_stiffness=300.0,
              structural_damping=0.3, shear_stiffness=120.0, shear_damping=0.2, bend_stiffness=25.0,
              bend_damping=0.07, drag_coefficient=1.2, wind=(1.0, -0.5, 2.0), ground_enabled=False,
              orientation=(0.3, 0.5, 0.2), origin=(0.1, 1.5, -0.2))


def _perturbed(cloth: Cloth, seed: int = 1) -> None:
    rng = np.random.default_rng(seed)
    cloth.positions[...] = cloth.rest_positions * 1.1 + rng.normal(0.0, 0.02, size=(cloth.n, 3))
    cloth.velocities[...] = rng.normal(0.0, 0.7, size=(cloth.n, 3))


def _reference_force(cloth: Cloth, x: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Gravity, drag (−½ρc_d·|w|²·area·(ŵ·n̂)·n̂ per triangle, ⅓ per corner) and minus the
    finite-difference gradients of the spring energy and the Rayleigh dissipation."""
    p = cloth.params
    i, j = cloth.springs[:, 0], cloth.springs[:, 1]
    k, c, rest = cloth._spring_k, cloth._spring_c, cloth.rest_lengths

    def energy(y: np.ndarray) -> float:
        return float(np.sum(0.5 * k * (np.linalg.norm(y[j] - y[i], axis=1) - rest) ** 2))

    d = x[j] - x[i]
    u = d / np.linalg.norm(d, axis=1)[:, None]

    def dissipation(w: np.ndarray) -> float:
        return float(np.sum(0.5 * c * np.einsum("ij,ij->i", u, w[j] - w[i]) ** 2))

    f = np.zeros_like(x)
    eps = 1e-6
    for q in range(len(x)):
        for a in range(3):
            e = np.zeros_like(x)
            e[q, a] = eps
            f[q, a] = -(energy(x + e) - energy(x - e)) / (2 * eps) - (dissipation(v + e) - dissipation(v - e)) / (
                2 * eps)
    f[:, 1] -= p.gravity * cloth.particle_mass
    coef = 0.5 * p.air_density * p.drag_coefficient
    for tri in cloth.triangles:
        cross = np.cross(x[tri[1]] - x[tri[0]], x[tri[2]] - x[tri[0]])
        area, n_hat = 0.5 * np.linalg.norm(cross), cross / np.linalg.norm(cross)
        w = (v[tri] - np.asarray(p.wind)).mean(axis=0)
        drag = -coef * np.dot(w, w) * area * np.dot(w / np.linalg.norm(w), n_hat) * n_hat
        f[tri] += drag / 3.0
    return f


@pytest.mark.parametrize("accelerate", ACCELERATE)
def test_forces_on_a_tilted_cloth_in_3d_wind_match_the_reference(accelerate: bool) -> None:
    cloth = Cloth(ClothParams(**TILTED), accelerate=accelerate)  # type: ignore[arg-type]
    _perturbed(cloth)
    x, v = cloth.positions.copy(), cloth.velocities.copy()
    force = cloth._external_forces(x, v)
    cloth._spring_forces(x, v, force)
    np.testing.assert_allclose(force, _reference_force(cloth, x, v), rtol=1e-6, atol=1e-6)


@pytest.mark.parametrize("accelerate", ACCELERATE)
def test_symplectic_steps_match_hand_steps_when_the_step_changes(accelerate: bool) -> None:
    # Two frames of different lengths: the cached h/m must follow the step.
    cloth = Cloth(ClothParams(**TILTED, integrator="symplectic", substeps=1), accelerate=accelerate)  # type: ignore[arg-type]
    _perturbed(cloth)
    pins = cloth.pinned_indices
    for dt in (1.0 / 600.0, 1.0 / 400.0):
        x, v = cloth.positions.copy(), cloth.velocities.copy()
        v_new = v + _reference_force(cloth, x, v) * (dt / cloth.particle_mass)
        v_new[pins] = (cloth.pin_targets - x[pins]) / dt
        x_new = x + v_new * dt
        x_new[pins] = cloth.pin_targets
        cloth.step(dt)
        np.testing.assert_allclose(cloth.velocities, v_new, rtol=1e-6, atol=1e-7)
        np.testing.assert_allclose(cloth.positions, x_new, rtol=1e-9, atol=1e-10)


@pytest.mark.parametrize("accelerate", ACCELERATE)
def test_an_implicit_step_with_nothing_to_do_takes_zero_iterations(accelerate: bool) -> None:
    p = ClothParams(rows=4, cols=4, gravity=0.0, wind=(0.0, 0.0, 0.0), ground_enabled=False, substeps=1)
    cloth = Cloth(p, accelerate=accelerate)
    cloth.step(1.0 / 60.0)
    assert cloth.last_iterations == 0
    np.testing.assert_array_equal(cloth.positions, cloth.rest_positions)


def test_stretch_is_length_over_rest_length_minus_one() -> None:
    cloth = Cloth(ClothParams(**TILTED))  # type: ignore[arg-type]
    centre = cloth.rest_positions.mean(axis=0)
    cloth.positions[...] = centre + 1.25 * (cloth.rest_positions - centre)
    for kind in ("structural", "shear", "bend"):
        np.testing.assert_allclose(cloth.stretch(kind), 0.25, rtol=1e-12)


# ------------------------------------------------------------------ steps per frame
def test_implicit_steps_per_frame_round_exact_multiples_down() -> None:
    p = ClothParams(rows=4, cols=4, drag_coefficient=0.0, integrator="implicit")
    cloth = Cloth(p)
    assert cloth.substeps_for(2 * IMPLICIT_MAX_STEP) == 2
    assert cloth.substeps_for(IMPLICIT_MAX_STEP) == 1
    assert cloth.substeps_for(1.0 / 24.0) == 3


def test_drag_rate_is_the_documented_bound() -> None:
    p = ClothParams(rows=5, cols=7, width=1.5, height=1.2, drag_coefficient=0.5, air_density=1.1,
                    wind=(3.0, 0.0, 4.0), turbulence=2.0)
    m = 0.01
    area = 1.5 * 1.2 / (2 * 4 * 6)  # one triangle
    speed = 5.0 + 5.0 * 2.0 + 5.0  # |wind| + 5·turbulence + 5 m/s of the cloth's own
    assert drag_rate(p, 5, 7, m) == pytest.approx(4 * 0.5 * 1.1 * 0.5 * speed * area / m, rel=1e-12)


def test_a_very_light_cloth_in_wind_takes_the_drag_limited_implicit_step() -> None:
    p = ClothParams(rows=6, cols=6, width=2.0, height=2.0, total_mass=0.02, drag_coefficient=1.0,
                    air_density=1.2, wind=(0.0, 0.0, 10.0), integrator="implicit")
    cloth = Cloth(p)
    m = cloth.particle_mass
    rate = 4 * 0.5 * 1.2 * 1.0 * (10.0 + 5.0) * (4.0 / 50.0) / m
    longest = min(IMPLICIT_MAX_STEP, 1.8 / rate)
    assert longest < IMPLICIT_MAX_STEP / 2
    assert cloth.substeps_for(1.0 / 60.0) == math.ceil(1.0 / 60.0 / longest - 1e-9)


def test_stable_dt_of_one_spring_solves_the_damped_oscillator_condition() -> None:
    k, c, m = 400.0, 0.3, 0.02
    springs = np.array([[0, 1]])
    rest = np.array([[0.0, 0.0, 0.0], [0.25, 0.0, 0.0]])
    lam_k, lam_c = 2 * k / m, 2 * c / m + 1.5
    # h²·λ_K/4 + h·λ_C/2 = 1, the positive root, times 0.9.
    roots = np.roots([lam_k / 4.0, lam_c / 2.0, -1.0])
    expected = 0.9 * float(roots[roots > 0][0])
    assert stable_dt(springs, rest, np.array([k]), np.array([c]), m, 1.5) == pytest.approx(expected, rel=1e-12)


def test_symplectic_default_frame_is_a_sixtieth() -> None:
    cloth = Cloth(ClothParams(rows=12, cols=12, structural_stiffness=5000.0, integrator="symplectic"))
    expected = math.ceil((1.0 / 60.0) / cloth._stable_dt() - 1e-9)
    assert expected > 2
    assert cloth.stable_substeps() == expected


# ------------------------------------------------------------------ wind
def test_gusts_have_the_turbulence_as_rms_amplitude() -> None:
    p = ClothParams(turbulence=2.0, wind=(1.0, 0.0, -1.0))
    modes = turbulence_modes(7)
    point = np.array([[0.3, 1.2, -0.4]])
    times = np.arange(0.0, 400.0, 0.013)
    samples = np.array([wind_at(p, modes, t, point)[0] for t in times]) - np.array(p.wind)
    rms = np.sqrt((samples ** 2).mean(axis=0))
    np.testing.assert_allclose(rms, 2.0, rtol=0.1)


def test_a_default_cloth_is_in_still_air() -> None:
    cloth = Cloth(ClothParams())
    force = cloth._external_forces(cloth.positions, cloth.velocities).copy()
    expected = np.zeros((cloth.n, 3))
    expected[:, 1] = -cloth.params.gravity * cloth.particle_mass
    np.testing.assert_allclose(force, expected, atol=1e-15)


# ------------------------------------------------------------------ collisions
def test_ground_response_restitution_and_coulomb_friction() -> None:
    v = np.array([[3.0, -2.0, 0.0], [0.0, -1.0, 4.0]])
    normal = np.array([[0.0, 1.0, 0.0], [0.0, 1.0, 0.0]])
    _respond(v, np.array([0, 1]), normal, 0.5, 0.3)
    # |Δv_n| = 1.5·2 = 3: tangential 3 → 3 − 0.3·3; |Δv_n| = 1.5: 4 → 4 − 0.3·1.5.
    np.testing.assert_allclose(v, [[2.1, 1.0, 0.0], [0.0, 0.5, 3.55]], rtol=1e-12)


def test_capsules_are_checked() -> None:
    a, b = np.zeros((1, 3)), np.ones((1, 3))
    with pytest.raises(ValueError):
        capsules([[np.nan, 0.0, 0.0]], b, [0.1])
    with pytest.raises(ValueError):
        capsules(a, [[1.0, np.inf, 0.0]], [0.1])
    with pytest.raises(ValueError):
        capsules(a, b, [0.0])
    with pytest.raises(ValueError):
        capsules(a, b, [0.1], a_start=np.zeros((2, 3)))
    caps = capsules(a, b, [0.1], a_start=[[0.0, 0.5, 0.0]], b_start=[[1.0, 1.5, 1.0]])
    assert caps is not None
    np.testing.assert_array_equal(caps[0], [[0.0, 0.5, 0.0]])
    np.testing.assert_array_equal(caps[3], b)


@pytest.mark.parametrize("axis", [(1.0, 0.0, 1.0), (0.0, 1.0, 1.0), (1.0, 1.0, 0.0), (0.0, 0.0, 1.0)])
def test_a_particle_on_a_capsule_axis_is_pushed_out_across_it(axis: tuple[float, float, float]) -> None:
    a = np.array([[0.0, 0.0, 0.0]])
    b = np.array([axis])
    x = 0.5 * b.copy()
    v = np.zeros((1, 3))
    p = ClothParams(ground_enabled=False, collision_margin=0.01)
    collide(p, x, v, [], (a, b, np.array([0.2])), np.zeros(0, dtype=np.int64))
    u = b[0] / np.linalg.norm(b[0])
    off = x[0] - 0.5 * b[0]
    assert abs(np.dot(off, u)) < 1e-12
    assert np.linalg.norm(off) == pytest.approx(0.21, rel=1e-9)


# ------------------------------------------------------------------ interaction
def test_pin_centroid_without_pins_is_the_cloth_centroid() -> None:
    cloth = Cloth(ClothParams(**TILTED, pin_mode="none"))  # type: ignore[arg-type]
    np.testing.assert_allclose(cloth.pin_centroid(), cloth.rest_positions.mean(axis=0), rtol=1e-12)


def test_a_single_pin_moves() -> None:
    cloth = Cloth(ClothParams(**TILTED, pin_mode="custom", custom_pins=[3]))  # type: ignore[arg-type]
    start = cloth.positions[3].copy()
    cloth.move_pins((0.1, -0.2, 0.3), immediate=True)
    np.testing.assert_allclose(cloth.positions[3], start + [0.1, -0.2, 0.3], rtol=1e-12)


def test_capsule_penetration_without_capsules_is_minus_infinity() -> None:
    cloth = Cloth(ClothParams(**TILTED))  # type: ignore[arg-type]
    assert cloth.capsule_penetration() == -math.inf


def test_grabbing_a_particle_past_the_end_is_refused() -> None:
    cloth = Cloth(ClothParams(**TILTED))  # type: ignore[arg-type]
    with pytest.raises(ValueError):
        cloth.grab_particle(cloth.n)
    cloth.grab_particle(cloth.n - 1)
    assert cloth.grabbed == cloth.n - 1


# ------------------------------------------------------------------ grid, params, solver setup
def test_vertex_normals_are_unit_even_without_area() -> None:
    x = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [5.0, 5.0, 5.0]])
    nrm = vertex_normals(x, np.array([[0, 1, 2]]))
    np.testing.assert_allclose(np.linalg.norm(nrm, axis=1), 1.0, rtol=1e-12)
    np.testing.assert_allclose(nrm[:3], [[0.0, 0.0, 1.0]] * 3, atol=1e-15)


def test_the_smallest_grid_the_editor_offers_is_the_smallest_valid_one() -> None:
    for name in ("rows", "cols"):
        lo = int(CLOTH[name].minimum or 0)
        ClothParams(**{name: lo}).validate()
        with pytest.raises(ValueError):
            ClothParams(**{name: lo - 1}).validate()


def test_the_three_spring_kinds_share_their_ranges() -> None:
    for what in ("stiffness", "damping"):
        params = [CLOTH[f"{kind}_{what}"] for kind in ("structural", "shear", "bend")]
        ranges = {(p.minimum, p.maximum) for p in params}
        assert len(ranges) == 1


def test_the_solver_iteration_cap_is_max_200_or_8_sqrt_n() -> None:
    springs = np.array([[0, 1]], dtype=np.int64)
    assert implicit_pattern(16, springs, accelerated=True)["maxiter"] == 200
    assert implicit_pattern(4096, springs, accelerated=True)["maxiter"] == 8 * 64


def test_a_sphere_pushes_out_only_the_points_inside_its_radius() -> None:
    """A sphere of radius 0.3 (margin 0) at the origin: a point 0.2 away goes to the surface
    along its direction, one 0.5 away (inside a unit sphere, outside this one) stays put."""
    p = ClothParams(ground_enabled=False, collision_margin=0.0)
    x = np.array([[0.2, 0.0, 0.0], [0.0, 0.5, 0.0], [0.0, 0.0, -0.9]])
    v = np.zeros_like(x)
    sphere = (np.zeros(3), 0.3, 0.0, 0.0)
    collide(p, x, v, [sphere], None, np.zeros(0, dtype=np.int64))
    assert x[0] == pytest.approx([0.3, 0.0, 0.0], abs=1e-9)
    assert x[1].tolist() == [0.0, 0.5, 0.0] and x[2].tolist() == [0.0, 0.0, -0.9]


# ------------------------------------------------------------------ step details (seed 104)
def test_warm_start_reuses_the_last_velocity_change() -> None:
    """Free fall of an unstretched cloth: every step needs the same Δv = −g·h (springs see no
    relative motion), so a solve warm-started from the last one has nothing left to do."""
    p = ClothParams(rows=3, cols=3, pin_mode="none", ground_enabled=False, drag_coefficient=0.0, substeps=1)
    cloth = Cloth(p, accelerate=False)
    assert cloth.warm_start
    cloth.step(1.0 / 60.0)
    assert cloth.last_iterations > 0
    cloth.step(1.0 / 60.0)
    assert cloth.last_iterations == 0
    np.testing.assert_allclose(cloth.velocities[:, 1], -9.8 * 2.0 / 60.0, rtol=1e-3)


@pytest.mark.parametrize("accelerate", ACCELERATE)
def test_the_solver_floor_is_a_rms_acceleration_of_1e_3(accelerate: bool) -> None:
    """atol = 1e-3 m/s² × h × m × √N: with gravity 5e-4 m/s² on a free 4 × 4 cloth at rest the
    right-hand side |h·m·g|·√N is below it (no iteration); with 2e-3 m/s² it is above (iterations)."""
    for g, none in ((5e-4, True), (2e-3, False)):
        p = ClothParams(rows=4, cols=4, gravity=g, pin_mode="none", ground_enabled=False, substeps=1)
        cloth = Cloth(p, accelerate=accelerate)
        cloth.step(1.0 / 60.0)
        assert (cloth.last_iterations == 0) == none, g


def test_stretch_picks_its_own_kind() -> None:
    """A 3 × 4 cloth (dx = 0.3, dy = 0.4) stretched by 1.5 along x only: horizontal structural
    and bend springs stretch by 0.5, vertical ones not at all, the diagonals by
    √(0.45² + 0.4²)/0.5 − 1."""
    p = ClothParams(rows=3, cols=4, width=0.9, height=0.8, ground_enabled=False)
    cloth = Cloth(p, accelerate=False)
    cloth.positions[:, 0] *= 1.5
    structural = np.sort(cloth.stretch("structural"))
    assert len(structural) == 3 * 3 + 2 * 4
    np.testing.assert_allclose(structural, [0.0] * 8 + [0.5] * 9, atol=1e-12)
    np.testing.assert_allclose(cloth.stretch("shear"), [math.hypot(0.45, 0.4) / 0.5 - 1.0] * 12, rtol=1e-12)
    bend = np.sort(cloth.stretch("bend"))
    np.testing.assert_allclose(bend, [0.0] * 4 + [0.5] * 6, atol=1e-12)


def test_a_cloth_without_forces_that_limit_the_step_takes_one_substep() -> None:
    p = ClothParams(rows=3, cols=3, integrator="symplectic", structural_stiffness=0.0, structural_damping=0.0,
                    shear_stiffness=0.0, shear_damping=0.0, bend_stiffness=0.0, bend_damping=0.0,
                    drag_coefficient=0.0)
    cloth = Cloth(p, accelerate=False)
    assert cloth._stable_dt() == math.inf
    assert cloth.stable_substeps(1.0 / 24.0) == 1
    assert cloth.substeps_for(1.0 / 24.0) == 1


def test_reset_keeps_the_position_arrays() -> None:
    """A viewer may hold ``positions`` / ``velocities``: reset and set_state refill them."""
    cloth = Cloth(ClothParams(rows=3, cols=3), accelerate=False)
    pos, vel = cloth.positions, cloth.velocities
    state = cloth.state()
    cloth.step(1.0 / 60.0)
    cloth.reset()
    assert cloth.positions is pos and cloth.velocities is vel
    cloth.set_state(state)
    assert cloth.positions is pos and cloth.velocities is vel


def test_weak_gusts_blow_on_the_cloth() -> None:
    """Turbulence 0.5 m/s (below 1): one symplectic step of a spring-free cloth in still air
    moves as the drag of the gust field sampled at the start of the frame says."""
    p = ClothParams(rows=3, cols=3, width=0.6, height=0.6, total_mass=0.09, gravity=0.0, ground_enabled=False,
                    pin_mode="none", turbulence=0.5, turbulence_seed=5, integrator="symplectic", substeps=1,
                    structural_stiffness=0.0, structural_damping=0.0, shear_stiffness=0.0, shear_damping=0.0,
                    bend_stiffness=0.0, bend_damping=0.0, orientation=(0.4, 0.0, 0.0))
    cloth = Cloth(p, accelerate=False)
    x = cloth.positions.copy()
    air = wind_at(p, turbulence_modes(5), 0.0, x)
    coef = 0.5 * p.air_density * p.drag_coefficient
    f = np.zeros_like(x)
    for tri in cloth.triangles:
        cross = np.cross(x[tri[1]] - x[tri[0]], x[tri[2]] - x[tri[0]])
        area, n_hat = 0.5 * np.linalg.norm(cross), cross / np.linalg.norm(cross)
        w = (0.0 - air[tri]).mean(axis=0)
        f[tri] += -coef * np.dot(w, w) * area * np.dot(w / np.linalg.norm(w), n_hat) * n_hat / 3.0
    dt = 1.0 / 120.0
    cloth.step(dt)
    assert np.abs(f).max() > 1e-4
    np.testing.assert_allclose(cloth.velocities, f * dt / cloth.particle_mass, rtol=1e-9, atol=1e-15)


@pytest.mark.parametrize("accelerate", ACCELERATE)
def test_pins_move_linearly_over_the_substeps(accelerate: bool) -> None:
    """Two symplectic substeps while the pins move: after the first the pins are half way
    (start + Δ/2, velocity Δ/dt), after the second at their targets; the free particles follow
    the reference forces."""
    cloth = Cloth(ClothParams(**TILTED, integrator="symplectic", substeps=2), accelerate=accelerate)  # type: ignore[arg-type]
    _perturbed(cloth, seed=3)
    pins = cloth.pinned_indices
    cloth.move_pins((0.03, -0.02, 0.05))
    start, end = cloth.positions[pins].copy(), cloth.pin_targets.copy()
    dt = 1.0 / 300.0
    h = dt / 2
    x, v = cloth.positions.copy(), cloth.velocities.copy()
    for s in (1, 2):
        v = v + _reference_force(cloth, x, v) * (h / cloth.particle_mass)
        v[pins] = (end - start) / dt
        x = x + v * h
        x[pins] = end if s == 2 else start + (end - start) * 0.5
    cloth.step(dt)
    np.testing.assert_allclose(cloth.positions, x, rtol=1e-9, atol=1e-10)
    np.testing.assert_allclose(cloth.velocities, v, rtol=1e-6, atol=1e-7)


def test_auto_substeps_are_refused_past_5000_not_at_5000() -> None:
    """docs/user-guide.md: on auto the symplectic integrator "refuses settings that would need
    more than 5000 a frame". A frame of 5000.5 stable substeps needs 5001 (refused before
    stepping, naming the implicit integrator); one of 4999.5 needs 5000 (allowed)."""
    assert MAX_AUTO_SUBSTEPS == 5000
    cloth = Cloth(ClothParams(rows=2, cols=2, integrator="symplectic", ground_enabled=False))
    limit = cloth._stable_dt()
    assert cloth.substeps_for(4999.5 * limit) == 5000
    assert cloth.substeps_for(5000.5 * limit) == 5001
    before = cloth.positions.copy()
    with pytest.raises(ClothBlowUp) as info:
        cloth.step(5000.5 * limit)
    assert info.value.parameter == "integrator"
    np.testing.assert_array_equal(cloth.positions, before)


def test_no_solver_iterations_before_an_implicit_step() -> None:
    """``last_iterations`` counts the conjugate-gradient iterations of the last implicit
    substep: a new cloth has solved nothing (0), and symplectic steps solve nothing either."""
    cloth = Cloth(ClothParams(rows=3, cols=3, integrator="symplectic", substeps=1))
    assert cloth.last_iterations == 0
    cloth.step(1.0 / 60.0)
    assert cloth.last_iterations == 0
