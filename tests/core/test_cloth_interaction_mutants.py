"""Pins, grabbing and capsules on a running cloth (cloth_interaction.py): the documented
"move during the next step, land exactly" behaviour, rigid pin motion about the pins'
centroid, and the capsule penetration read-out, on tiny weightless cloths."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.cloth import Cloth, ClothParams

SMALL = dict(rows=3, cols=3, width=0.4, height=0.4, gravity=0.0, ground_enabled=False, drag_coefficient=0.0,
             integrator="symplectic", substeps=2)


def _cloth(**extra: object) -> Cloth:
    return Cloth(ClothParams(**{**SMALL, **extra}), accelerate=False)  # type: ignore[arg-type]


def test_move_pins_waits_for_the_step_then_lands_exactly() -> None:
    cloth = _cloth()
    pins = cloth.pinned_indices
    start = cloth.positions[pins].copy()
    cloth.move_pins((0.1, -0.05, 0.2))
    np.testing.assert_array_equal(cloth.positions[pins], start)  # not immediate: nothing moved yet
    np.testing.assert_allclose(cloth.pin_targets, start + [0.1, -0.05, 0.2], rtol=1e-15)
    cloth.step(1.0 / 60.0)
    np.testing.assert_array_equal(cloth.positions[pins], cloth.pin_targets)
    np.testing.assert_allclose(cloth.velocities[pins], np.tile([0.1, -0.05, 0.2], (2, 1)) * 60.0, rtol=1e-9)


def test_move_pins_rotates_about_the_pins_centroid() -> None:
    """Top corners at x = ∓0.2 (y = 2): a half turn about y through their centroid swaps them."""
    cloth = _cloth()
    a, b = cloth.pin_targets.copy()
    np.testing.assert_allclose(cloth.pin_centroid(), (a + b) / 2, rtol=1e-15)
    cloth.move_pins(rotation=(0.0, math.pi, 0.0), immediate=True)
    np.testing.assert_allclose(cloth.pin_targets, [b, a], atol=1e-12)
    np.testing.assert_allclose(cloth.positions[cloth.pinned_indices], [b, a], atol=1e-12)
    np.testing.assert_array_equal(cloth.velocities[cloth.pinned_indices], 0.0)


def test_move_pins_without_pins_does_nothing() -> None:
    cloth = _cloth(pin_mode="none")
    before = cloth.positions.copy()
    cloth.move_pins((1.0, 0.0, 0.0), immediate=True)
    np.testing.assert_array_equal(cloth.positions, before)
    np.testing.assert_allclose(cloth.pin_centroid(), before.mean(axis=0), rtol=1e-15)


def test_set_pin_targets_checks_the_shape_and_lands_there() -> None:
    cloth = _cloth()
    targets = cloth.pin_targets + [[0.0, 0.1, 0.0], [0.0, -0.1, 0.05]]
    with pytest.raises(ValueError):
        cloth.set_pin_targets(targets[:1])
    with pytest.raises(ValueError):
        cloth.set_pin_targets(np.zeros((2, 4)))
    want = targets.copy()
    cloth.set_pin_targets(targets)
    targets[0, 0] = 9.0  # the cloth keeps its own copy
    cloth.step(1.0 / 60.0)
    np.testing.assert_array_equal(cloth.positions[cloth.pinned_indices], want)


def test_a_grabbed_free_particle_is_dragged_to_the_target_and_released() -> None:
    cloth = _cloth()
    with pytest.raises(ValueError):
        cloth.grab_particle(-1)
    cloth.grab_particle(0)  # index 0 exists (a pinned one)
    assert cloth.grabbed == 0
    cloth.release()
    i = 4  # the centre particle, free
    cloth.grab_particle(i)
    np.testing.assert_array_equal(cloth._kinematics()[0], [0, 2, 4])
    target = cloth.positions[i] + [0.0, 0.0, 0.1]
    cloth.drag_grabbed(target)
    cloth.step(1.0 / 60.0)
    np.testing.assert_array_equal(cloth.positions[i], target)
    np.testing.assert_allclose(cloth.velocities[i], [0.0, 0.0, 6.0], rtol=1e-9)
    cloth.release()
    assert cloth.grabbed is None
    assert len(cloth._kinematics()[0]) == 2


def test_dragging_a_grabbed_pin_moves_its_pin_target() -> None:
    cloth = _cloth()
    cloth.grab_particle(2)  # the top-right corner, pinned
    cloth.drag_grabbed((1.0, 2.0, 3.0))
    np.testing.assert_array_equal(cloth.pin_targets[1], [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(cloth._kinematics()[0], [0, 2])  # not twice


def test_drag_without_a_grab_does_nothing() -> None:
    cloth = _cloth()
    cloth.drag_grabbed((1.0, 2.0, 3.0))
    assert cloth.grabbed is None and cloth._kinematics()[0].tolist() == [0, 2]


def test_grab_picks_the_particle_nearest_the_ray() -> None:
    cloth = _cloth()
    target = cloth.positions[5]
    i = cloth.grab(target + [0.0, 0.0, 3.0], (0.0, 0.0, -1.0))
    assert i == 5 and cloth.grabbed == 5
    assert cloth.grab(target + [0.0, 0.0, 3.0], (0.0, 0.0, 1.0)) is None


def test_capsule_penetration_is_the_deepest_free_particle() -> None:
    """A capsule of radius 0.1 along z through the centre particle (free): depth 0.1; the pinned
    particles never count, so a capsule only around a pin gives a negative depth."""
    cloth = _cloth()
    c = cloth.positions[4]
    cloth.set_capsules([c - [0, 0, 1]], [c + [0, 0, 1]], [0.1])
    assert cloth.capsule_penetration() == pytest.approx(0.1, abs=1e-12)
    pin = cloth.positions[0]
    cloth.set_capsules([pin - [0, 0, 1]], [pin + [0, 0, 1]], [0.05])
    assert cloth.capsule_penetration() == pytest.approx(0.05 - 0.2, abs=1e-12)  # nearest free is 0.2 away
    cloth.set_capsules(np.zeros((0, 3)), np.zeros((0, 3)), [])
    assert cloth.capsule_penetration() == -math.inf


def test_a_cloth_of_only_pins_has_no_penetration() -> None:
    cloth = Cloth(ClothParams(rows=2, cols=2, pin_mode="custom", custom_pins=[0, 1, 2, 3]), accelerate=False)
    c = cloth.positions[0]
    cloth.set_capsules([c - [0, 0, 1]], [c + [0, 0, 1]], [0.5])
    assert cloth.capsule_penetration() == -math.inf
