"""Picking a point of a skinned surface and dragging it by IK (document level, Qt-free)."""

from __future__ import annotations

import numpy as np

from qtanimator.core.skinning import skin_positions
from qtanimator.document import character3d
from qtanimator.document.document import Document
from qtanimator.document.surface_pick import dominant_joint, effector_point, pick_surface
from qtanimator.paths import scenes_dir


def _arm() -> Document:
    doc = Document()
    d = scenes_dir() / "arm3d"
    character3d.add_character3d_command(doc, d / "arm.skel", d / "arm.skin", asset_id="arm").do(doc)
    return doc


def test_a_ray_through_a_forearm_triangle_picks_the_elbow_and_the_point_in_its_frame():
    doc = _arm()
    ch = character3d.character(doc, "arm")
    world = character3d.world_matrices(doc, "arm", 0.0)
    pos = skin_positions(ch.skin, ch.skinning_world(world))
    elbow_x = (np.linalg.inv(world[1]) @ np.c_[pos, np.ones(len(pos))].T)[0]
    # a triangle well down the forearm: every corner weighted to the elbow
    tri = next(k for k, t in enumerate(ch.skin.triangles) if (elbow_x[t] > 0.4).all() and (elbow_x[t] < 0.6).all())
    corners = pos[ch.skin.triangles[tri]]
    centre = corners.mean(axis=0)
    normal = np.cross(corners[1] - corners[0], corners[2] - corners[0])
    normal /= np.linalg.norm(normal)
    origin = centre + 2.0 * normal
    hit = pick_surface(doc, "arm", 0.0, origin, centre - origin)
    assert hit is not None and hit.joint == 1
    np.testing.assert_allclose(hit.point, centre, atol=1e-9)
    np.testing.assert_allclose(hit.t, 1.0, atol=1e-9)
    np.testing.assert_allclose(effector_point(doc, "arm", 1, hit.offset, 0.0), centre, atol=1e-9)
    assert dominant_joint(ch, ch.skin.triangles[tri], [1 / 3, 1 / 3, 1 / 3]) == 1
    assert pick_surface(doc, "arm", 0.0, origin + 10 * np.array([0.0, 1.0, 0.0]), centre - origin) is None


def test_dragging_the_picked_point_brings_it_to_the_target():
    doc = _arm()
    ch = character3d.character(doc, "arm")
    skel = ch.skeleton
    world = character3d.world_matrices(doc, "arm", 0.0)
    offset = np.array([0.6, 0.1, 0.05])
    p0 = world[1, :3, :3] @ offset + world[1, :3, 3]
    # a reachable target: the point turned 20° about the elbow's local z
    c, s = np.cos(0.35), np.sin(0.35)
    target = world[1] @ np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]) @ np.append(offset, 1)
    dofs = [(1, a) for a in range(3)]
    values = character3d.ik_values(doc, "arm", 1, target[:3], 0.0, dofs, offset)
    assert values
    character3d.set_dofs_command(doc, "arm", values, 0.0).do(doc)
    reached = effector_point(doc, "arm", 1, offset, 0.0)
    assert np.linalg.norm(reached - target[:3]) < 1e-3
    assert np.linalg.norm(reached - p0) > 0.1
    lo, hi = skel.dof_limits()
    now = character3d.pose_skeleton(doc, "arm", 0.0).dof_values()
    assert (now >= lo - 1e-12).all() and (now <= hi + 1e-12).all()
