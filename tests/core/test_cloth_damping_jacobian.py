"""The implicit cloth step's damping Jacobian, checked against independent solutions.

The implicit step is backward Euler linearised once (Baraff & Witkin):
``(M − h·∂f/∂v − h²·∂f/∂x)·Δv = h·(f + h·∂f/∂x·v)``. The spring-damper force on i is
``(k·(l − L) + c·(v_j − v_i)·u)·u``, so ∂f/∂v has the blocks ``∓c·uuᵀ``. Leaving that
Jacobian out turns the damping explicit, which these tests see:

* two particles joined by a pure damper (k = 0), the other two springs of a 2×2 cloth
  perpendicular to the motion: the relative velocity w obeys m·w' = −2c·w, whose
  backward-Euler step is w₁ = w₀ / (1 + 2·h·c/m) (explicit Euler: w₀·(1 − 2·h·c/m));
* a stretched 3×3 cloth from rest, compared with the same linear system built here from a
  spring list written in the test and finite-difference Jacobians of its force.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.cloth import Cloth, ClothParams
from qtanimator.core.cloth_kernels import HAVE_NUMBA

PATHS = [pytest.param(False, id="numpy"),
         pytest.param(True, id="compiled", marks=pytest.mark.skipif(not HAVE_NUMBA, reason="numba not installed"))]


def quiet(**kw: object) -> ClothParams:
    """No gravity, drag, ground, pins or automatic steps: springs only."""
    base: dict[str, object] = dict(gravity=0.0, drag_coefficient=0.0, ground_enabled=False, pin_mode="none",
                                   integrator="implicit", substeps=1)
    base.update(kw)
    return ClothParams().replace(**base)


def tight(cloth: Cloth) -> Cloth:
    cloth.solver_rtol = 1e-13
    cloth.solver_atol_acceleration = 1e-14
    return cloth


@pytest.mark.parametrize("accelerate", PATHS)
@pytest.mark.parametrize("c,mass,h", [(5.0, 0.4, 1 / 60), (40.0, 0.1, 1 / 30), (0.5, 4.0, 1 / 120)])
def test_two_particle_damper_has_the_backward_euler_closed_form(accelerate: bool, c: float, mass: float,
                                                                 h: float) -> None:
    p = quiet(rows=2, cols=2, width=1.0, height=1.0, total_mass=4 * mass,
              structural_stiffness=0.0, structural_damping=c, shear_stiffness=0.0, shear_damping=0.0,
              bend_stiffness=0.0, bend_damping=0.0)
    cloth = tight(Cloth(p, accelerate=accelerate))
    assert cloth.particle_mass == pytest.approx(mass)
    x0 = cloth.positions.copy()
    v0 = np.zeros((4, 3))
    # particles 0 and 1 are the top edge, joined along x; 2 and 3 hang below them (y springs
    # see no x motion: their uuᵀ has no x part)
    v0[1, 0] = 1.5
    v0[0, 0] = -0.5
    cloth.velocities[...] = v0
    cloth.step(h)
    w0 = v0[1, 0] - v0[0, 0]
    mean = 0.5 * (v0[1, 0] + v0[0, 0])
    w1 = w0 / (1.0 + 2.0 * h * c / mass)
    expected_v = np.zeros((4, 3))
    expected_v[0, 0] = mean - 0.5 * w1
    expected_v[1, 0] = mean + 0.5 * w1
    np.testing.assert_allclose(cloth.velocities, expected_v, atol=1e-10)
    np.testing.assert_allclose(cloth.positions, x0 + h * expected_v, atol=1e-12)
    # the relative speed decays, never overshoots (explicit Euler at 2hc/m > 2 would flip it)
    assert 0 < cloth.velocities[1, 0] - cloth.velocities[0, 0] < w0


# ------------------------------------------------------------------ a second implementation

def grid_springs(rows: int, cols: int, dx: float, dy: float) -> list[tuple[int, int, float, str]]:
    """(i, j, rest length, kind) for the documented springs of a rows × cols grid."""
    out = []
    diag = math.hypot(dx, dy)
    for r in range(rows):
        for c in range(cols):
            i = r * cols + c
            if c + 1 < cols:
                out.append((i, i + 1, dx, "structural"))
            if r + 1 < rows:
                out.append((i, i + cols, dy, "structural"))
            if r + 1 < rows and c + 1 < cols:
                out.append((i, i + cols + 1, diag, "shear"))
            if r + 1 < rows and c > 0:
                out.append((i, i + cols - 1, diag, "shear"))
            if c + 2 < cols:
                out.append((i, i + 2, 2 * dx, "bend"))
            if r + 2 < rows:
                out.append((i, i + 2 * cols, 2 * dy, "bend"))
    return out


def spring_force(x: np.ndarray, v: np.ndarray, springs: list[tuple[int, int, float, str]],
                 k: dict[str, float], c: dict[str, float]) -> np.ndarray:
    f = np.zeros_like(x)
    for i, j, rest, kind in springs:
        d = x[j] - x[i]
        ln = float(np.linalg.norm(d))
        u = d / ln
        t = k[kind] * (ln - rest) + c[kind] * float((v[j] - v[i]) @ u)
        f[i] += t * u
        f[j] -= t * u
    return f


def fd_jacobian(fn, z: np.ndarray, eps: float) -> np.ndarray:  # type: ignore[no-untyped-def]
    flat = z.ravel()
    out = np.empty((flat.size, flat.size))
    for a in range(flat.size):
        zp, zm = flat.copy(), flat.copy()
        zp[a] += eps
        zm[a] -= eps
        out[:, a] = (fn(zp.reshape(z.shape)) - fn(zm.reshape(z.shape))).ravel() / (2 * eps)
    return out


@pytest.mark.parametrize("accelerate", PATHS)
def test_stretched_cloth_step_equals_backward_euler_with_finite_difference_jacobians(accelerate: bool) -> None:
    k = {"structural": 300.0, "shear": 120.0, "bend": 40.0}
    c = {"structural": 6.0, "shear": 3.0, "bend": 1.5}
    p = quiet(rows=3, cols=3, width=0.6, height=0.5, total_mass=0.9,
              structural_stiffness=k["structural"], structural_damping=c["structural"],
              shear_stiffness=k["shear"], shear_damping=c["shear"], bend_stiffness=k["bend"],
              bend_damping=c["bend"], origin=(0.0, 3.0, 0.0))
    cloth = tight(Cloth(p, accelerate=accelerate))
    m = cloth.particle_mass
    rest = cloth.positions.copy()
    centre = rest.mean(axis=0)
    rng = np.random.default_rng(7)
    # stretched by 25 % and slightly crumpled: every spring is longer than its rest length,
    # where the solver's stiffness block is the true Jacobian
    x0 = centre + 1.25 * (rest - centre) + rng.normal(0.0, 0.01, rest.shape)
    v0 = np.zeros_like(x0)
    springs = grid_springs(3, 3, 0.3, 0.25)
    for i, j, length, _kind in springs:
        assert np.linalg.norm(x0[j] - x0[i]) > length
    cloth.positions[...] = x0
    cloth.velocities[...] = v0
    h = 1.0 / 40.0
    cloth.step(h)

    f0 = spring_force(x0, v0, springs, k, c)
    dfdx = fd_jacobian(lambda z: spring_force(z, v0, springs, k, c), x0, 1e-6)
    dfdv = fd_jacobian(lambda z: spring_force(x0, z, springs, k, c), v0, 1e-3)  # linear in v
    n = 3 * len(x0)
    a = m * np.eye(n) - h * dfdv - h * h * dfdx
    dv = np.linalg.solve(a, h * (f0.ravel() + h * dfdx @ v0.ravel())).reshape(x0.shape)
    np.testing.assert_allclose(cloth.velocities, v0 + dv, rtol=1e-6, atol=1e-8)
    np.testing.assert_allclose(cloth.positions, x0 + h * (v0 + dv), rtol=1e-6, atol=1e-9)
    # the damping matters here: without ∂f/∂v the step would differ clearly
    dv_no_damping_jacobian = np.linalg.solve(m * np.eye(n) - h * h * dfdx, h * f0.ravel()).reshape(x0.shape)
    assert np.max(np.abs(dv_no_damping_jacobian - dv)) > 100 * 1e-8 + 1e-3 * np.max(np.abs(dv))
