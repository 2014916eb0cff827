"""skin_normals with normals passed in (core/skinning.py)."""

from __future__ import annotations

import numpy as np

from qtanimator.core.matrix_stack import rotation_z
from qtanimator.core.skeleton import Joint, Skeleton
from qtanimator.core.skinning import SkinBinding, bind_to_skeleton, skin_normals


def _one_joint_skin():
    skel = Skeleton([Joint("root")], rotation_order="zyx")
    pos = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    binding = SkinBinding([0, 1, 2], [0, 0, 0], [1.0, 1.0, 1.0], 3, 1)
    skin = bind_to_skeleton(pos, [[0, 1, 2]], binding, skel.bind_world_matrices())
    return skel, skin


def test_given_normals_in_any_layout_are_transformed():
    # A rigid quarter turn about z takes x to y and y to -x; the normals given (not the
    # mesh's, which is +z) are turned with it, whatever their array layout.
    skel, skin = _one_joint_skin()
    world = np.asarray(rotation_z(np.pi / 2))[None]
    given = np.array([[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 1.0]])
    expected = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    for layout in (given, given.reshape(-1), given.tolist()):
        np.testing.assert_allclose(skin_normals(skin, world, normals=layout), expected, atol=1e-15)
    # without normals: the face's own, +z, unchanged by a turn about z
    np.testing.assert_allclose(skin_normals(skin, world), np.tile([0.0, 0.0, 1.0], (3, 1)), atol=1e-15)


def test_from_padded_reads_rows_as_vertices_and_drops_zero_weights():
    """Three vertices with two slots each (V != K): vertex i owns row i; zero weights go."""
    b = SkinBinding.from_padded([[0, 1], [2, 0], [1, 1]], [[0.25, 0.75], [1.0, 0.0], [0.5, 0.5]], 3)
    assert (b.num_vertices, b.num_joints, len(b)) == (3, 3, 5)
    np.testing.assert_array_equal(b.counts(), [2, 1, 2])
    dense = np.zeros((3, 3))
    np.add.at(dense, (b.vertex, b.joint), b.weight)
    np.testing.assert_allclose(dense, [[0.25, 0.75, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]])
