"""Camera and picking maths of the 3D viewport (no GL needed)."""

from __future__ import annotations

import numpy as np
import pytest

from qtanimator.render.gl.camera import OrbitCamera
from qtanimator.render.gl.picking import pick_joint, ray_box, ray_sphere
from qtanimator.render.gl.renderer import CharacterDraw


def test_ray_through_a_projected_point_passes_through_it():
    cam = OrbitCamera(azimuth=37.0, inclination=25.0, distance=5.0, target=np.array([0.3, 1.0, -0.2]))
    rng = np.random.default_rng(1)
    for p in rng.uniform(-1, 1, (10, 3)):
        x, y, _z = cam.project(p, 640, 480)[0]
        o, d = cam.ray(x, y, 640, 480)
        closest = o + ((p - o) @ d) * d
        assert np.linalg.norm(closest - p) < 1e-9


def test_orbit_pan_zoom_and_frame():
    cam = OrbitCamera(azimuth=0.0, inclination=0.0, distance=4.0)
    np.testing.assert_allclose(cam.eye(), [0, 0, 4])
    cam.orbit(90.0, 0.0)
    np.testing.assert_allclose(cam.eye(), [4, 0, 0], atol=1e-12)
    cam.orbit(0.0, 200.0)
    assert cam.inclination == 89.0
    cam.zoom(0.5)
    assert cam.distance == 2.0
    cam = OrbitCamera(azimuth=0.0, inclination=0.0, distance=4.0)
    cam.pan(100, 0, 400)          # drag right: the scene follows, the target moves left
    assert cam.target[0] < 0 and cam.target[1] == pytest.approx(0.0)
    cam.frame(np.array([-1.0, 0, -1]), np.array([1.0, 2, 1]))
    np.testing.assert_allclose(cam.target, [0, 1, 0])
    # the whole box is in view
    for corner in np.array(np.meshgrid([-1, 1], [0, 2], [-1, 1])).reshape(3, -1).T:
        x, y, _ = cam.project(corner, 400, 400)[0]
        assert 0 <= x <= 400 and 0 <= y <= 400


def test_ray_primitives():
    assert ray_box(np.array([0, 0, 5.0]), np.array([0, 0, -1.0]), -np.ones(3), np.ones(3)) == pytest.approx(4.0)
    assert ray_box(np.array([3, 0, 5.0]), np.array([0, 0, -1.0]), -np.ones(3), np.ones(3)) is None
    assert ray_sphere(np.array([0, 0, 5.0]), np.array([0, 0, -1.0]), np.zeros(3), 1.0) == pytest.approx(4.0)
    assert ray_sphere(np.array([0, 0, 5.0]), np.array([0, 0, 1.0]), np.zeros(3), 1.0) is None


def _two_boxes() -> CharacterDraw:
    world = np.tile(np.eye(4), (2, 1, 1))
    world[1, :3, 3] = [0.0, 0.0, -2.0]              # joint 1 sits behind joint 0 seen from +z
    c, s = np.cos(0.5), np.sin(0.5)
    world[1, :3, :3] = [[c, 0, s], [0, 1, 0], [-s, 0, c]]
    return CharacterDraw("a", world, [-1, 0], boxmin=np.full((2, 3), -0.5), boxmax=np.full((2, 3), 0.5))


def test_pick_takes_the_nearest_box_in_the_joints_frame():
    item = _two_boxes()
    hit = pick_joint([item], np.array([0, 0, 5.0]), np.array([0, 0, -1.0]))
    assert hit[:2] == ("a", 0)
    # just beside box 0 but inside the rotated box 1 (half-diagonal reaches 0.5·(cos+sin) ≈ 0.68)
    hit = pick_joint([item], np.array([0.6, 0, 5.0]), np.array([0, 0, -1.0]))
    assert hit[:2] == ("a", 1)
    assert pick_joint([item], np.array([0.75, 0, 5.0]), np.array([0, 0, -1.0])) is None


def test_pick_spheres_and_bones():
    world = np.tile(np.eye(4), (3, 1, 1))
    world[1, :3, 3] = [1.0, 0, 0]
    world[2, :3, 3] = [2.0, 0, 0]
    item = CharacterDraw("m", world, [-1, 0, 1], joint_radius=0.05)
    down = np.array([0, 0, -1.0])
    assert pick_joint([item], np.array([1.0, 0.0, 3.0]), down)[:2] == ("m", 1)
    assert pick_joint([item], np.array([1.5, 0.0, 3.0]), down)[:2] == ("m", 2)   # on the bone 1→2
    assert pick_joint([item], np.array([1.5, 0.5, 3.0]), down) is None
