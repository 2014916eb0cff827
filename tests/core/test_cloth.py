"""The cloth engine (issue 5): forces, integrators, collisions, pins, grabbing, blow-ups."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from qtanimator.core.cloth import (
    Cloth,
    ClothBlowUp,
    ClothParams,
    Sphere,
    pins_from_cells,
    rotation_matrix,
    vertex_normals,
)
from qtanimator.core.cloth_kernels import HAVE_NUMBA

DT = 1.0 / 60.0


def no_springs(**kw: object) -> ClothParams:
    base: dict[str, object] = dict(structural_stiffness=0.0, structural_damping=0.0, shear_stiffness=0.0,
                                   shear_damping=0.0, bend_stiffness=0.0, bend_damping=0.0)
    base.update(kw)
    return ClothParams().replace(**base)


def horizontal(**kw: object) -> ClothParams:
    """A cloth lying flat (normal +y) with its top edge at z = −height/2, centred on the y axis."""
    base: dict[str, object] = dict(rows=12, cols=12, orientation=(-math.pi / 2, 0.0, 0.0), pin_mode="none")
    base.update(kw)
    p = ClothParams().replace(**base)
    return p.replace(origin=(p.origin[0], p.origin[1], -p.height / 2))


# ------------------------------------------------------------------ structure
def test_grid_springs_triangles_and_uvs() -> None:
    R, C = 5, 7
    cloth = Cloth(ClothParams(rows=R, cols=C, width=1.2, height=0.8))
    kinds = np.bincount(cloth.spring_kinds, minlength=3)
    assert kinds[0] == R * (C - 1) + C * (R - 1)
    assert kinds[1] == 2 * (R - 1) * (C - 1)
    assert kinds[2] == R * (C - 2) + C * (R - 2)
    assert len(np.unique(np.sort(cloth.springs, axis=1), axis=0)) == len(cloth.springs)
    assert np.allclose(cloth.spring_lengths(), cloth.rest_lengths)
    assert cloth.triangles.shape == (2 * (R - 1) * (C - 1), 3)
    assert cloth.positions.shape == (R * C, 3)
    # Top edge centred on the origin, hanging down along −y in the xy plane.
    assert np.allclose(cloth.positions[:C, 1], 2.0)
    assert np.allclose(cloth.positions[-1], (0.6, 2.0 - 0.8, 0.0))
    assert np.allclose(cloth.normals(), (0.0, 0.0, 1.0))
    assert cloth.uvs.min() == 0.0 and cloth.uvs.max() == 1.0


def test_pin_modes() -> None:
    C = 6
    corners = Cloth(ClothParams(rows=4, cols=C, pin_mode="top_corners"))
    assert list(np.flatnonzero(corners.pinned)) == [0, C - 1]
    edge = Cloth(ClothParams(rows=4, cols=C, pin_mode="top_edge"))
    assert list(np.flatnonzero(edge.pinned)) == list(range(C))
    assert not Cloth(ClothParams(rows=4, cols=C, pin_mode="none")).pinned.any()
    pins = pins_from_cells(C, [(1, 2), (3, 5)])
    custom = Cloth(ClothParams(rows=4, cols=C, pin_mode="custom", custom_pins=pins))
    assert list(np.flatnonzero(custom.pinned)) == [1 * C + 2, 3 * C + 5]


def test_params_round_trip_through_json() -> None:
    p = ClothParams(rows=8, cols=9, wind=(1.0, 0.0, -2.0), spheres=[Sphere((0.0, 1.0, 0.0), 0.3, 0.5, 0.1)],
                    pin_mode="custom", custom_pins=[0, 3], integrator="implicit", substeps=2, turbulence=0.5)
    data = json.loads(json.dumps(p.to_dict()))
    assert ClothParams.from_dict(data) == p
    # Spheres may also be given as plain tuples.
    q = ClothParams.from_dict({"spheres": [[[0, 1, 0], 0.3, 0.5, 0.1]]})
    assert q.spheres == [Sphere((0.0, 1.0, 0.0), 0.3, 0.5, 0.1)]
    assert ClothParams.from_dict({"unknown_future_field": 1}) == ClothParams()


@pytest.mark.parametrize("bad", [
    {"rows": 1}, {"pin_mode": "sideways"}, {"integrator": "rk4"}, {"substeps": -1}, {"width": -1.0},
    {"structural_stiffness": -5.0}, {"wind": [1.0, 2.0]}, {"custom_pins": [10_000]}, {"rows": 2.5},
    {"spheres": [{"centre": [0, 0, 0], "radius": 0.0}]}, {"air_density": "thick"},
])
def test_invalid_params_raise_value_error(bad: dict[str, object]) -> None:
    with pytest.raises(ValueError):
        ClothParams.from_dict(bad)


# ------------------------------------------------------------------- physics
@pytest.mark.parametrize("integrator", ["symplectic", "implicit"])
def test_free_fall_matches_half_g_t_squared(integrator: str) -> None:
    p = no_springs(rows=4, cols=4, pin_mode="none", drag_coefficient=0.0, ground_enabled=False,
                   integrator=integrator, substeps=16)
    cloth = Cloth(p)
    y0 = cloth.positions[:, 1].copy()
    frames = 60
    for _ in range(frames):
        cloth.step(DT)
    t = frames * DT
    h = DT / p.substeps
    drop = y0 - cloth.positions[:, 1]
    # Semi-implicit Euler is first order: the error is g·h·t/2.
    assert np.allclose(drop, 0.5 * p.gravity * t * t, atol=0.5 * p.gravity * h * t + 1e-12)
    assert np.allclose(cloth.velocities[:, 1], -p.gravity * t)
    assert np.allclose(cloth.positions[:, [0, 2]], cloth.rest_positions[:, [0, 2]])


ACCELERATE = [False, pytest.param(True, marks=pytest.mark.skipif(not HAVE_NUMBA, reason="numba not installed"))]


@pytest.mark.parametrize("accelerate", ACCELERATE)
def test_spring_forces_match_a_gathered_reference(accelerate: bool) -> None:
    rng = np.random.default_rng(3)
    # One explicit step measures the forces (the default integrator is implicit).
    p = ClothParams(rows=6, cols=7, pin_mode="none", gravity=0.0, drag_coefficient=0.0, ground_enabled=False,
                    substeps=1, structural_damping=0.7, shear_damping=0.3, bend_damping=0.1, integrator="symplectic")
    cloth = Cloth(p, accelerate=accelerate)
    assert cloth.accelerated == accelerate
    x = cloth.positions + rng.normal(0, 0.02, cloth.positions.shape)
    v = rng.normal(0, 0.5, cloth.positions.shape)
    cloth.positions[:] = x
    cloth.velocities[:] = v
    h = 1e-4
    cloth.step(h)
    force = (cloth.velocities - v) * cloth.particle_mass / h
    i, j = cloth.springs[:, 0], cloth.springs[:, 1]
    k = np.array([p.structural_stiffness, p.shear_stiffness, p.bend_stiffness])[cloth.spring_kinds]
    c = np.array([p.structural_damping, p.shear_damping, p.bend_damping])[cloth.spring_kinds]
    d = x[j] - x[i]
    length = np.linalg.norm(d, axis=1)
    u = d / length[:, None]
    tension = k * (length - cloth.rest_lengths) + c * np.einsum("ij,ij->i", v[j] - v[i], u)
    expected = np.zeros_like(x)
    np.add.at(expected, i, tension[:, None] * u)
    np.add.at(expected, j, -tension[:, None] * u)
    assert np.allclose(force, expected, rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("accelerate", ACCELERATE)
def test_drag_matches_the_triangle_formula(accelerate: bool) -> None:
    rho, cd, w, hgt = 1.225, 1.1, 0.8, 0.6
    p = no_springs(rows=2, cols=2, width=w, height=hgt, pin_mode="none", gravity=0.0, ground_enabled=False,
                   drag_coefficient=cd, air_density=rho, substeps=1, integrator="symplectic")
    h = 1e-6

    def total_force(vel: tuple[float, float, float], wind: tuple[float, float, float]) -> np.ndarray:
        cloth = Cloth(p.replace(wind=wind), accelerate=accelerate)
        cloth.velocities[:] = vel
        before = cloth.velocities.copy()
        cloth.step(h)
        return np.asarray(((cloth.velocities - before) * cloth.particle_mass / h).sum(axis=0))

    # Moving along the normal at 2 m/s: F = −½·ρ·c_d·|v|²·area·n̂ for the whole sheet.
    f = total_force((0.0, 0.0, 2.0), (0.0, 0.0, 0.0))
    assert np.allclose(f, (0.0, 0.0, -0.5 * rho * cd * 4.0 * w * hgt), rtol=1e-6)
    # Only the relative velocity counts: still cloth in a wind of −2 m/s feels the same.
    assert np.allclose(total_force((0.0, 0.0, 0.0), (0.0, 0.0, -2.0)), f, rtol=1e-6)
    # At 45°, a = area·cos 45° and the force is along the normal: ½ρc_d|v|²·A·cos45°.
    s = 2.0 / math.sqrt(2.0)
    f45 = total_force((s, 0.0, s), (0.0, 0.0, 0.0))
    assert np.allclose(f45, (0.0, 0.0, -0.5 * rho * cd * 4.0 * w * hgt * math.cos(math.pi / 4)), rtol=1e-6)
    # Edge-on wind does nothing.
    assert np.allclose(total_force((0.0, 0.0, 0.0), (3.0, 0.0, 0.0)), 0.0, atol=1e-12)


@pytest.mark.skipif(not HAVE_NUMBA, reason="numba not installed")
@pytest.mark.parametrize("integrator,substeps", [("symplectic", 8), ("implicit", 1)])
def test_compiled_kernels_match_the_numpy_code(integrator: str, substeps: int) -> None:
    p = ClothParams(rows=9, cols=11, wind=(1.0, 0.5, 3.0), turbulence=1.5, integrator=integrator, substeps=substeps,
                    spheres=[Sphere((0.0, 1.4, 0.1), 0.2, 0.3, 0.5)], ground_height=1.2)
    fast, slow = Cloth(p, accelerate=True), Cloth(p, accelerate=False)
    for _ in range(20):
        fast.step(DT)
        slow.step(DT)
    assert np.allclose(fast.positions, slow.positions, rtol=0, atol=1e-9)
    assert np.allclose(fast.velocities, slow.velocities, rtol=0, atol=1e-7)


@pytest.mark.parametrize("integrator,substeps", [("symplectic", 16), ("implicit", 1)])
def test_hanging_from_top_edge_comes_to_rest_with_little_stretch(integrator: str, substeps: int) -> None:
    cloth = Cloth(ClothParams(pin_mode="top_edge", integrator=integrator, substeps=substeps))
    for _ in range(240):
        cloth.step(DT)
    stretch = cloth.stretch("structural")
    assert stretch.max() < 0.10
    assert np.abs(cloth.velocities).max() < 0.05
    assert np.isfinite(cloth.positions).all()


def test_integrators_agree_on_the_resting_shape() -> None:
    shapes = []
    for integrator, substeps in (("symplectic", 16), ("implicit", 2)):
        cloth = Cloth(ClothParams(rows=10, cols=10, pin_mode="top_edge", integrator=integrator, substeps=substeps))
        for _ in range(180):
            cloth.step(DT)
        shapes.append(cloth.positions.copy())
    assert np.abs(shapes[0] - shapes[1]).max() < 0.01


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_wind_pushes_the_cloth_downwind(sign: float) -> None:
    cloth = Cloth(ClothParams(rows=12, cols=12, pin_mode="top_edge", wind=(0.0, 0.0, 6.0 * sign)))
    for _ in range(90):
        cloth.step(DT)
    free = ~cloth.pinned
    assert sign * cloth.positions[free, 2].mean() > 0.05
    assert np.all(sign * cloth.positions[free, 2] > -1e-9)


def test_turbulence_is_deterministic_and_seeded() -> None:
    def run(seed: int) -> np.ndarray:
        cloth = Cloth(ClothParams(rows=8, cols=8, wind=(0.0, 0.0, 2.0), turbulence=3.0, turbulence_seed=seed))
        for _ in range(30):
            cloth.step(DT)
        return cloth.positions.copy()

    a, b, c = run(1), run(1), run(2)
    assert np.array_equal(a, b)
    assert not np.allclose(a, c)


# ---------------------------------------------------------------- collisions
@pytest.mark.parametrize("integrator,substeps", [("symplectic", 16), ("implicit", 1)])
def test_dropped_cloth_never_goes_under_the_ground(integrator: str, substeps: int) -> None:
    p = horizontal(origin=(0.0, 0.4, 0.0), ground_height=0.1, integrator=integrator, substeps=substeps,
                   ground_restitution=0.3, ground_friction=0.5)
    cloth = Cloth(p)
    for _ in range(90):
        cloth.step(DT)
        assert cloth.positions[:, 1].min() >= p.ground_height + p.collision_margin - 1e-12
    assert cloth.positions[:, 1].max() < 0.2  # it landed
    assert np.abs(cloth.velocities).max() < 0.5


@settings(max_examples=6, deadline=None)
@given(cx=st.floats(-0.3, 0.3), cz=st.floats(-0.3, 0.3), radius=st.floats(0.15, 0.4),
       restitution=st.floats(0.0, 0.8), friction=st.floats(0.0, 1.0), margin=st.sampled_from([0.0, 0.005]))
def test_no_particle_ends_inside_a_sphere(cx: float, cz: float, radius: float, restitution: float,
                                          friction: float, margin: float) -> None:
    sphere = Sphere((cx, 0.6, cz), radius, restitution, friction)
    p = horizontal(rows=10, cols=10, origin=(0.0, 1.1, 0.0), spheres=[sphere], ground_height=0.0,
                   collision_margin=margin)
    cloth = Cloth(p)
    centre = np.array(sphere.centre)
    for _ in range(45):
        cloth.step(DT)
        dist = np.linalg.norm(cloth.positions - centre, axis=1)
        assert dist.min() >= radius
        assert cloth.positions[:, 1].min() >= p.ground_height


def test_sphere_holds_up_a_draped_cloth() -> None:
    sphere = Sphere((0.0, 0.5, 0.0), 0.3, 0.0, 0.8)
    p = horizontal(rows=14, cols=14, origin=(0.0, 0.9, 0.0), spheres=[sphere])
    cloth = Cloth(p)
    for _ in range(120):
        cloth.step(DT)
    centre = cloth.positions[(p.rows // 2) * p.cols + p.cols // 2]
    assert centre[1] > 0.5 + 0.3 - 0.02  # resting on top of the sphere
    assert cloth.positions[:, 1].min() < 0.5  # the edges hang down around it


# --------------------------------------------------------------------- pins
def test_pinned_particles_stay_put() -> None:
    cloth = Cloth(ClothParams(rows=10, cols=10, pin_mode="top_corners", wind=(0.0, 0.0, 3.0)))
    pins = cloth.positions[cloth.pinned].copy()
    for _ in range(60):
        cloth.step(DT)
    assert np.array_equal(cloth.positions[cloth.pinned], pins)
    assert not np.allclose(cloth.positions[~cloth.pinned], cloth.rest_positions[~cloth.pinned])


@pytest.mark.parametrize("integrator,substeps", [("symplectic", 16), ("implicit", 1)])
def test_pins_follow_move_pins_exactly(integrator: str, substeps: int) -> None:
    cloth = Cloth(ClothParams(rows=10, cols=10, pin_mode="top_edge", integrator=integrator, substeps=substeps))
    start = cloth.positions[cloth.pinned].copy()
    centre = start.mean(axis=0)
    rot = rotation_matrix((0.0, 0.3, 0.0))
    expected = (start - centre) @ rot.T + centre + np.array([0.1, 0.05, -0.02])
    cloth.move_pins((0.1, 0.05, -0.02), rotation=(0.0, 0.3, 0.0))
    cloth.step(DT)
    assert np.allclose(cloth.positions[cloth.pinned], expected, rtol=0, atol=1e-12)
    # A 3×3 matrix works the same as the rotation vector.
    cloth.move_pins(rotation=rotation_matrix((0.0, -0.3, 0.0)))
    for _ in range(5):
        cloth.step(DT)
    back = (expected - expected.mean(axis=0)) @ rotation_matrix((0.0, -0.3, 0.0)).T + expected.mean(axis=0)
    assert np.allclose(cloth.positions[cloth.pinned], back, atol=1e-12)
    assert np.isfinite(cloth.positions).all()


def test_rotation_matrix_from_axis_angle() -> None:
    r = rotation_matrix((0.0, 0.0, math.pi / 2))
    assert np.allclose(r @ [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    assert np.allclose(rotation_matrix((0.0, 0.0, 0.0)), np.eye(3))


# -------------------------------------------------------------------- grab
def test_grab_drag_and_release() -> None:
    cloth = Cloth(ClothParams(rows=10, cols=10, pin_mode="top_edge"))
    target_particle = 7 * 10 + 4
    p = cloth.positions[target_particle]
    idx = cloth.grab(p + (0.0, 0.0, 3.0), (0.0, 0.0, -1.0))
    assert idx == target_particle
    goal = p + np.array([0.0, 0.1, 0.3])
    cloth.drag_grabbed(goal)
    for _ in range(3):
        cloth.step(DT)
    assert np.array_equal(cloth.positions[idx], goal)
    neighbour = cloth.positions[idx - 1, 2]
    assert neighbour > 0.05  # the cloth follows the grabbed particle
    cloth.release()
    assert cloth.grabbed is None
    for _ in range(30):
        cloth.step(DT)
    assert not np.allclose(cloth.positions[idx], goal)
    # Rays pointing away from the cloth or missing it by more than max_distance grab nothing.
    assert cloth.grab((0.0, 1.5, 3.0), (0.0, 0.0, 1.0)) is None
    assert cloth.grab((5.0, 1.5, 3.0), (0.0, 0.0, -1.0), max_distance=0.1) is None


# ------------------------------------------------------ stability, blow-ups
STIFF = dict(structural_stiffness=1.0e4, shear_stiffness=1.0e4, bend_stiffness=1.0e4, structural_damping=1.0,
             shear_damping=1.0, bend_damping=1.0, rows=12, cols=12, pin_mode="top_corners")


def test_explicit_blows_up_at_frame_rate_and_says_what_to_change() -> None:
    cloth = Cloth(ClothParams(**STIFF, integrator="symplectic", substeps=1))  # type: ignore[arg-type]
    with pytest.raises(ClothBlowUp) as info:
        for _ in range(120):
            cloth.step(DT)
    err = info.value
    assert err.parameter == "substeps"
    assert "substeps" in err.message and "implicit" in err.message
    assert cloth.error is err
    # The state handed out is the last good one: finite, no NaN.
    assert np.isfinite(cloth.positions).all() and np.isfinite(cloth.velocities).all()
    with pytest.raises(ClothBlowUp):
        cloth.step(DT)  # stays stopped
    cloth.reset()
    assert cloth.error is None
    assert cloth.stable_substeps(DT) > 1


def test_implicit_stays_bounded_where_explicit_blows_up() -> None:
    cloth = Cloth(ClothParams(**STIFF, integrator="implicit", substeps=1))  # type: ignore[arg-type]
    size = math.hypot(cloth.params.width, cloth.params.height)
    for _ in range(120):
        cloth.step(DT)
        assert np.isfinite(cloth.positions).all()
        assert np.linalg.norm(cloth.positions - cloth.rest_positions, axis=1).max() < 2 * size
    assert cloth.stretch().max() < 0.10
    assert np.abs(cloth.velocities).max() < 1.0


def test_determinism_and_state_round_trip() -> None:
    p = ClothParams(rows=10, cols=10, wind=(1.0, 0.0, 2.0), turbulence=1.0,
                    spheres=[Sphere((0.0, 1.2, 0.2), 0.25, 0.2, 0.4)])
    a, b = Cloth(p), Cloth(p)
    for _ in range(20):
        a.step(DT)
        b.step(DT)
    assert np.array_equal(a.positions, b.positions) and np.array_equal(a.velocities, b.velocities)
    saved = a.state()
    for _ in range(10):
        a.step(DT)
    after = a.positions.copy()
    a.set_state(saved)
    for _ in range(10):
        a.step(DT)
    assert np.array_equal(a.positions, after)
    a.reset()
    assert np.array_equal(a.positions, a.rest_positions) and a.time == 0.0


def test_set_params_keeps_state_for_material_changes() -> None:
    cloth = Cloth(ClothParams(rows=8, cols=8))
    positions = cloth.positions  # viewers may keep the array object
    for _ in range(10):
        cloth.step(DT)
    moved = cloth.positions.copy()
    assert cloth.set_params(cloth.params.replace(wind=(0.0, 0.0, 4.0), integrator="implicit", substeps=1)) is False
    assert np.array_equal(cloth.positions, moved)
    cloth.step(DT)
    cloth.reset()
    assert cloth.positions is positions
    assert cloth.set_params(cloth.params.replace(rows=9)) is True
    assert cloth.positions.shape == (72, 3)


def test_dropping_the_cloth_keeps_it_where_it_is() -> None:
    cloth = Cloth(ClothParams(rows=8, cols=8, pin_mode="top_edge", wind=(0.0, 0.0, 3.0)))
    for _ in range(20):
        cloth.step(DT)
    here = cloth.positions.copy()
    assert cloth.set_params(cloth.params.replace(pin_mode="none")) is False
    assert not cloth.pinned.any() and np.array_equal(cloth.positions, here)
    for _ in range(10):
        cloth.step(DT)
    assert cloth.positions[:, 1].max() < here[:, 1].max() - 0.05  # it falls
    # Pinning again holds the particles where they are now.
    cloth.set_params(cloth.params.replace(pin_mode="top_corners"))
    held = cloth.positions[cloth.pinned].copy()
    for _ in range(5):
        cloth.step(DT)
    assert np.array_equal(cloth.positions[cloth.pinned], held)


def test_move_pins_immediately_while_paused() -> None:
    cloth = Cloth(ClothParams(rows=6, cols=6))
    before = cloth.positions[cloth.pinned_indices].copy()
    cloth.move_pins((0.0, 0.5, 0.0), immediate=True)
    assert np.allclose(cloth.positions[cloth.pinned_indices], before + (0.0, 0.5, 0.0), atol=1e-15)
    assert np.allclose(cloth.pin_targets, before + (0.0, 0.5, 0.0), atol=1e-15)


def test_vertex_normals_follow_orientation() -> None:
    cloth = Cloth(horizontal(rows=5, cols=5))
    assert np.allclose(cloth.normals(), (0.0, 1.0, 0.0))
    flipped = vertex_normals(cloth.positions, cloth.triangles[:, ::-1])
    assert np.allclose(flipped, (0.0, -1.0, 0.0))


@settings(max_examples=10, deadline=None)
@given(k=st.floats(1.0, 1.0e5), c=st.floats(0.0, 5.0), substeps=st.integers(1, 20), mass=st.floats(0.01, 5.0),
       wind=st.floats(-30.0, 30.0), integrator=st.sampled_from(["symplectic", "implicit"]))
def test_never_hands_out_nan(k: float, c: float, substeps: int, mass: float, wind: float, integrator: str) -> None:
    p = ClothParams(rows=6, cols=6, structural_stiffness=k, shear_stiffness=k, bend_stiffness=k / 10,
                    structural_damping=c, shear_damping=c, bend_damping=c, substeps=substeps, total_mass=mass,
                    wind=(0.0, 0.0, wind), turbulence=abs(wind) / 10, integrator=integrator)
    cloth = Cloth(p)
    try:
        for _ in range(30):
            cloth.step(DT)
    except ClothBlowUp as err:
        assert err.parameter in {"substeps", "wind"} and err.message
    assert np.isfinite(cloth.positions).all() and np.isfinite(cloth.velocities).all()
    assert np.isfinite(cloth.normals()).all()


def test_dragging_a_grabbed_pin_moves_the_pin() -> None:
    cloth = Cloth(ClothParams(rows=6, cols=6, pin_mode="top_corners"))
    corner = cloth.positions[0].copy()
    assert cloth.grab(corner + (0.0, 0.0, 1.0), (0.0, 0.0, -1.0)) == 0
    cloth.drag_grabbed(corner + (-0.2, 0.1, 0.0))
    cloth.step(DT)
    cloth.release()
    for _ in range(3):
        cloth.step(DT)
    assert np.array_equal(cloth.positions[0], corner + (-0.2, 0.1, 0.0))


@pytest.mark.skipif(not HAVE_NUMBA, reason="numba not installed")
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_drag_kernel_equals_the_numpy_drag_on_a_random_cloth(seed: int) -> None:
    """The compiled per-triangle drag (cloth_kernels.drag_forces) against the numpy fallback:
    a crumpled cloth moving at random through a gusty wind, forces equal to 1e-12."""
    rng = np.random.default_rng(seed)
    p = ClothParams(rows=11, cols=13, wind=tuple(rng.normal(0.0, 4.0, 3)), turbulence=2.5, turbulence_seed=seed,
                    drag_coefficient=1.3, air_density=1.225)
    fast, slow = Cloth(p, accelerate=True), Cloth(p, accelerate=False)
    x = fast.rest_positions + rng.normal(0.0, 0.05, fast.rest_positions.shape)
    v = rng.normal(0.0, 3.0, x.shape)
    for cloth in (fast, slow):
        cloth.time = 0.37
        cloth._air = cloth._wind_at(x)
    assert np.array_equal(fast._air, slow._air)
    f_fast, f_slow = np.zeros_like(x), np.zeros_like(x)
    fast._add_drag(x, v, f_fast)
    slow._add_drag(x, v, f_slow)
    assert np.abs(f_slow).max() > 0.1
    np.testing.assert_allclose(f_fast, f_slow, rtol=1e-12, atol=1e-12)


def test_a_step_asked_to_stop_puts_the_cloth_back_and_resumes_identically() -> None:
    from qtanimator.core.cloth import ClothStepCancelled

    p = ClothParams(rows=7, cols=9, wind=(3.0, 0.0, 1.0), turbulence=1.0, substeps=6)
    ref, cloth = Cloth(p), Cloth(p)
    for _ in range(3):
        ref.step(DT)
        cloth.step(DT)
    before = cloth.state()
    asked = []
    with pytest.raises(ClothStepCancelled):
        cloth.step(DT, should_stop=lambda: asked.append(1) is None and len(asked) > 4)
    after = cloth.state()
    assert len(asked) == 5 and cloth.error is None
    assert np.array_equal(before.positions, after.positions) and np.array_equal(before.velocities, after.velocities)
    assert before.time == after.time
    for _ in range(4):
        ref.step(DT)
        cloth.step(DT, should_stop=lambda: False)
    assert np.array_equal(ref.positions, cloth.positions) and np.array_equal(ref.velocities, cloth.velocities)


def test_nearest_particle_to_a_ray() -> None:
    from qtanimator.core.cloth import nearest_particle

    cloth = Cloth(ClothParams(rows=5, cols=5, pin_mode="none"))
    target = cloth.positions[12]
    origin = target + np.array([0.0, 0.0, 4.0])
    assert nearest_particle(cloth.positions, origin, (0.0, 0.0, -1.0)) == 12
    assert nearest_particle(cloth.positions, origin, (0.0, 0.0, 1.0)) is None       # all behind
    assert nearest_particle(cloth.positions, origin + [0.1, 0, 0], (0.0, 0.0, -1.0), max_distance=0.01) is None
    assert cloth.grab(origin, (0.0, 0.0, -1.0)) == 12 and cloth.grabbed == 12
