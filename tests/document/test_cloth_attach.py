"""Cloth on a character (issue 14): pins follow a joint exactly, capsules keep the cloth out of
the body over a 10 s walk, with both integrators, and the energy stays bounded."""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest
from docfix import set_parameters

from qtanimator.core.cloth import Cloth, ClothParams
from qtanimator.document import Document
from qtanimator.document.character3d import add_character3d_command, set_dofs_command, world_matrices
from qtanimator.document.cloth import add_cloth_command, cloth_cache
from qtanimator.document.cloth_attach import (
    ATTACH,
    build_driver,
    capsule_radii,
    set_capsule_radius_command,
    transform_points,
)
from qtanimator.document.cloth_worker import ClothWorker
from qtanimator.document.commands import SetAssetProperty

SCENES = Path(__file__).resolve().parents[2] / "scenes"


def _cape_params() -> ClothParams:
    spec = importlib.util.spec_from_file_location("_make_demo_for_tests", SCENES / "make_demo.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    params: ClothParams = module.cape_params()
    return params


def _doc(frames: int = 600, integrator: str = "implicit") -> Document:
    doc = Document()
    set_parameters(doc, fps=60.0, frame_start=0, frame_end=frames)
    w = SCENES / "walker"
    add_character3d_command(doc, w / "walker.skel", w / "walker.skin", w / "walker_walk.anim",
                            asset_id="walker").do(doc)
    add_cloth_command(doc, _cape_params().replace(integrator=integrator), asset_id="cape").do(doc)
    SetAssetProperty(doc, "cape", ATTACH, {"asset": "walker", "joint": "chest"}).do(doc)
    return doc


def test_pinned_particles_follow_the_joint_exactly_over_a_walk():
    doc = _doc(120)
    cache = cloth_cache(doc, "cape")
    assert cache.driver is not None
    cloth = cache.cloth
    pins = cloth.pinned_indices
    assert len(pins) == cloth.cols
    w0 = world_matrices(doc, "walker", 0.0)[1]          # chest
    local = transform_points(np.linalg.inv(w0), cloth.rest_positions[pins])
    moved = 0.0
    for f in range(0, 121, 7):
        positions = cache.positions(f)
        w = world_matrices(doc, "walker", f / 60.0)[1]
        expected = local @ w[:3, :3].T + w[:3, 3]
        assert np.array_equal(positions[pins], expected), f
        moved = max(moved, float(np.abs(expected - cloth.rest_positions[pins]).max()))
    assert moved > 1.0   # the character walked on: the pins went with it


@pytest.mark.parametrize("integrator", ["implicit", "symplectic"])
@pytest.mark.parametrize("accelerate", [True, False])
def test_a_ten_second_walk_stays_outside_the_capsules_finite_and_bounded(integrator, accelerate):
    doc = _doc(600, integrator)
    cache = cloth_cache(doc, "cape")
    if not accelerate:
        cache.cloth.accelerated = False
    margin = cache.params.collision_margin
    energies, deepest = [], -math.inf
    for _ in range(600):
        assert cache.step_frame(), cache.error
        c = cache.cloth
        assert np.isfinite(c.positions).all() and np.isfinite(c.velocities).all()
        deepest = max(deepest, c.capsule_penetration())
        kinetic, gravity, spring = c.energy()
        # kinetic in the walker's frame would be fairer; the walk is 0.8 m/s, so this bounds it too
        energies.append(kinetic + gravity + spring)
    assert deepest <= margin + 1e-9
    e = np.array(energies)
    first, last = e[60:300], e[300:]
    assert last.max() <= first.max() + 0.5 * abs(first.max()) and e.max() < 10.0
    # the cape hangs behind the walker, touching it (the capsules are in use)
    assert deepest > -0.05


def test_capsule_radii_default_from_the_skin_and_are_editable():
    doc = _doc(10)
    radii = capsule_radii(doc, "walker")
    assert radii["chest"] == pytest.approx(0.15, abs=1e-3)     # the torso tube hips → chest
    assert radii["knee_l"] == pytest.approx(0.07, abs=1e-3)
    before = cloth_cache(doc, "cape")
    set_capsule_radius_command(doc, "walker", "chest", 0.2).do(doc)
    assert capsule_radii(doc, "walker")["chest"] == 0.2
    after = cloth_cache(doc, "cape")
    assert after is not before and 0.2 in after.driver.radii
    with pytest.raises(ValueError):
        set_capsule_radius_command(doc, "walker", "chest", -1.0)
    with pytest.raises(ValueError):
        set_capsule_radius_command(doc, "walker", "nope", 0.1)


def test_a_change_to_the_walk_rebuilds_the_attached_cloth_in_the_worker():
    doc = _doc(30)
    worker = ClothWorker(doc)
    try:
        assert worker.wait(60)
        first = cloth_cache(doc, "cape")
        assert first.cached_frames == 31
        set_dofs_command(doc, "walker", {(1, "x"): 0.4}, 0.2).do(doc)
        assert worker.wait(60)
        second = cloth_cache(doc, "cape")
        assert second is not first and second.cached_frames == 31
        assert not np.array_equal(first.frames[-1], second.frames[-1])
    finally:
        worker.close()


def test_a_missing_character_or_joint_is_named():
    doc = _doc(10)
    props = dict(doc.assets["cape"].properties)
    with pytest.raises(ValueError, match="joint 'tail'"):
        build_driver(doc, {**props, ATTACH: {"asset": "walker", "joint": "tail"}})
    with pytest.raises(ValueError, match="'ghost'"):
        build_driver(doc, {**props, ATTACH: {"asset": "ghost", "joint": "chest"}})


def test_capsules_push_particles_out_and_remove_inward_velocity():
    for accelerate in (True, False):
        cloth = Cloth(ClothParams(rows=6, cols=6, pin_mode="none", ground_enabled=False, gravity=0.0,
                                  origin=(0.0, 0.5, 0.0)), accelerate=accelerate)
        cloth.velocities[:] = (0.0, 0.0, -3.0)   # flying into a capsule lying along x at z = -0.2
        cloth.set_capsules([[-1.0, 0.25, -0.2]], [[1.0, 0.25, -0.2]], [0.15])
        for _ in range(30):
            cloth.step(1 / 60)
            assert cloth.capsule_penetration() <= 1e-12 - cloth.params.collision_margin + 1e-9
        assert np.isfinite(cloth.positions).all()
