import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from qtanimator.core.matrix_stack import rotation_x, rotation_y, rotation_z, translation
from qtanimator.core.skeleton import Dof, Joint, Skeleton, rotation_matrices


def chain(order: str = "zyx") -> Skeleton:
    joints = [
        Joint("root", None, [0, 0, 0]),
        Joint("a", 0, [0, 1, 0]),
        Joint("b", 1, [0, 1, 0], (Dof(0, -1, 1), Dof(), Dof())),
        Joint("c", 0, [1, 0, 0]),
    ]
    return Skeleton(joints, rotation_order=order)


def test_dofs_clamp_on_set():
    d = Dof(5, -2, 0)
    assert d.value == 0
    d.value = -3
    assert d.value == -2
    pinned = Dof(1, -0.11, -0.11)
    assert pinned.value == -0.11
    s = chain()
    assert s.set_dof(2, "x", 4.0) == 1.0
    assert s.get_dof(2, "x") == 1.0
    with pytest.raises(ValueError):
        Dof(0, 1, -1)
    with pytest.raises(ValueError):
        s.set_dof(0, "w", 1.0)


@pytest.mark.parametrize("order,factors", [
    ("zyx", lambda x, y, z: rotation_z(z) @ rotation_y(y) @ rotation_x(x)),
    ("xyz", lambda x, y, z: rotation_x(x) @ rotation_y(y) @ rotation_z(z)),
])
def test_local_matrix_is_offset_then_rotations_in_order(order, factors):
    s = chain(order)
    s.set_dof(1, "x", 0.3)
    s.set_dof(1, "y", -0.5)
    s.set_dof(1, "z", 0.7)
    expected = translation(0, 1, 0) @ factors(0.3, -0.5, 0.7)
    assert np.allclose(s.local_matrices()[1], expected, atol=1e-15)


def test_world_matrices_include_root_translation_and_parents():
    s = chain()
    s.root_translation = np.array([1.0, 2.0, 3.0])
    s.set_dof(0, "z", math.pi / 2)
    w = s.world_matrices()
    # Root rotated 90° about z: child offset (0, 1, 0) points along −x.
    assert np.allclose(w[1][:3, 3], [1 - 1, 2, 3])
    assert np.allclose(w[2][:3, 3], [1 - 2, 2, 3])
    assert np.allclose(w[3][:3, 3], [1, 2 + 1, 3])
    lm = s.local_matrices()
    assert np.allclose(w[2], translation(1, 2, 3) @ lm[0] @ lm[1] @ lm[2])


def test_non_depth_first_order_uses_the_right_parents():
    # MIT order: parents precede children but siblings' subtrees interleave.
    joints = [Joint("r", None, [0, 0, 0]), Joint("a", 0, [1, 0, 0]), Joint("b", 0, [0, 1, 0]),
              Joint("a1", 1, [1, 0, 0]), Joint("b1", 2, [0, 1, 0]), Joint("a2", 3, [1, 0, 0])]
    s = Skeleton(joints, "xyz")
    s.set_dof(1, "z", 0.4)
    w = s.world_matrices()
    lm = s.local_matrices()
    for i, j in enumerate(joints):
        parent = np.eye(4) if j.parent is None else w[j.parent]
        assert np.allclose(w[i], parent @ lm[i])


@settings(max_examples=30, deadline=None)
@given(st.lists(st.floats(-3, 3), min_size=12, max_size=12), st.sampled_from(["zyx", "xyz", "yxz"]))
def test_world_matrices_equal_the_product_along_the_chain(angles, order):
    s = chain(order)
    s.set_dof_values(np.array(angles).reshape(4, 3))
    w = s.world_matrices()
    lm = s.local_matrices()
    assert np.allclose(w[2], lm[0] @ lm[1] @ lm[2])
    assert np.allclose(w[3], lm[0] @ lm[3])
    # rotations stay orthonormal
    r = w[:, :3, :3]
    assert np.allclose(r @ r.transpose(0, 2, 1), np.eye(3), atol=1e-12)


def test_rotation_matrices_vectorised_matches_factors():
    a = np.array([[0.1, 0.2, 0.3], [-1.0, 0.5, 2.0]])
    m = rotation_matrices(a, "yzx")
    for k in range(2):
        x, y, z = a[k]
        assert np.allclose(m[k], (rotation_y(y) @ rotation_z(z) @ rotation_x(x))[:3, :3])


def test_reset_copy_and_keys():
    s = chain()
    s.set_dof(1, "y", 0.5)
    s.root_translation[:] = 1
    c = s.copy()
    s.reset_pose()
    assert c.get_dof(1, "y") == 0.5 and np.all(c.root_translation == 1)
    assert s.get_dof(1, "y") == 0 and np.all(s.root_translation == 0)
    dup = Skeleton([Joint("x"), Joint("x", 0), Joint("y", 1)])
    assert dup.joint_keys() == ["x#0", "x#1", "y"]
    assert s.children(0) == [1, 3]
    with pytest.raises(ValueError):
        Skeleton([Joint("a", 1)])


def test_deep_skeleton_uses_a_big_enough_stack():
    joints = [Joint("j0")] + [Joint(f"j{i}", i - 1, [0, 1, 0]) for i in range(1, 300)]
    s = Skeleton(joints)
    assert np.allclose(s.world_matrices()[-1][:3, 3], [0, 299, 0])
