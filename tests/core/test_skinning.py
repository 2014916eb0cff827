import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from qtanimator.core.matrix_stack import rotation_x, rotation_z, translation
from qtanimator.core.skeleton import Joint, Skeleton
from qtanimator.core.skinning import (
    Skin,
    SkinBinding,
    bind_to_skeleton,
    faceted_normals,
    skin_normals,
    skin_positions,
    transform_normals,
    vertex_normals,
)
from qtanimator.formats.attach import load_attach
from qtanimator.formats.obj import load_obj
from qtanimator.formats.skel import load_skel
from qtanimator.formats.skin import load_skin


def two_bone() -> tuple[Skeleton, Skin]:
    skel = Skeleton([Joint("root"), Joint("arm", 0, [0, 1, 0])], rotation_order="zyx")
    pos = np.array([[0.0, 0.5, 0.0], [0.0, 1.5, 0.0], [0.2, 1.0, 0.0], [0.0, 2.0, 0.1]])
    tris = np.array([[0, 1, 2], [1, 3, 2]])
    binding = SkinBinding([0, 1, 2, 2, 3], [0, 1, 0, 1, 1], [1.0, 1.0, 0.5, 0.5, 1.0], 4, 2)
    normals = np.array([[0, 0, 1.0], [0, 0, 1.0], [1.0, 0, 0], [0, 0, 1.0]])
    skin = bind_to_skeleton(pos, tris, binding, skel.bind_world_matrices(), normals=normals)
    return skel, skin


def test_bind_pose_reproduces_the_mesh():
    skel, skin = two_bone()
    assert np.allclose(skin_positions(skin, skel.world_matrices()), skin.positions, atol=1e-15)


@settings(max_examples=25, deadline=None)
@given(st.floats(-3, 3), st.floats(-3, 3), st.floats(-2, 2))
def test_a_vertex_bound_to_one_joint_moves_rigidly(a, b, tx):
    skel, skin = two_bone()
    skel.set_dof(0, "x", a)
    skel.set_dof(1, "z", b)
    skel.root_translation = np.array([tx, 0.0, 0.0])
    w = skel.world_matrices()
    p = skin_positions(skin, w)
    m1 = w[1] @ np.linalg.inv(skel.bind_world_matrices()[1])
    assert np.allclose(p[1], (m1 @ np.append(skin.positions[1], 1))[:3])
    assert np.allclose(p[3], (m1 @ np.append(skin.positions[3], 1))[:3])
    # distances between rigidly bound vertices are kept
    assert math.isclose(np.linalg.norm(p[1] - p[3]), np.linalg.norm(skin.positions[1] - skin.positions[3]))
    n = skin_normals(skin, w)
    assert np.allclose(n[1], m1[:3, :3] @ skin.normals[1])
    assert np.allclose(np.linalg.norm(n, axis=1), 1.0)


def test_blend_is_the_weighted_sum_of_joint_transforms():
    skel, skin = two_bone()
    skel.set_dof(1, "z", 0.8)
    w = skel.world_matrices()
    inv = np.linalg.inv(skel.bind_world_matrices())
    v = np.append(skin.positions[2], 1)
    expected = 0.5 * (w[0] @ inv[0] @ v) + 0.5 * (w[1] @ inv[1] @ v)
    assert np.allclose(skin_positions(skin, w)[2], expected[:3])
    f32 = skin_positions(skin, w, dtype=np.float32)
    assert f32.dtype == np.float32 and np.allclose(f32, skin_positions(skin, w), atol=1e-6)


def test_normals_use_the_inverse_transpose():
    # A non-uniform scale: the inverse transpose keeps normals perpendicular to the surface.
    m = np.diag([2.0, 1.0, 1.0])[None]
    tangent = np.array([1.0, 1.0, 0.0])
    normal = np.array([[1.0, -1.0, 0.0]]) / math.sqrt(2)
    out = transform_normals(m, normal)[0]
    assert abs(out @ (m[0] @ tangent)) < 1e-12
    assert math.isclose(np.linalg.norm(out), 1.0)
    # A mirror (negative determinant) keeps the normal on the transformed side.
    mirror = np.diag([-1.0, 1.0, 1.0])[None]
    assert np.allclose(transform_normals(mirror, [[1.0, 0, 0]]), [[-1.0, 0, 0]])


def test_any_number_of_influences():
    rng = np.random.default_rng(3)
    nv, nj = 50, 20
    w = rng.random((nv, nj)) * (rng.random((nv, nj)) < 0.7)
    w[:, 0] += 0.01
    binding = SkinBinding.from_dense(w)
    assert binding.max_influences > 13
    mats = np.stack([translation(*rng.normal(size=3)) @ rotation_x(rng.normal()) @ rotation_z(rng.normal())
                     for _ in range(nj)])
    skin = Skin(rng.normal(size=(nv, 3)), np.zeros((0, 3), dtype=int), binding, np.tile(np.eye(4), (nj, 1, 1)))
    got = skin_positions(skin, mats)
    vh = np.c_[skin.positions, np.ones(nv)]
    expected = np.einsum("vj,jab,vb->va", w, mats, vh)[:, :3]
    assert np.allclose(got, expected)
    indptr, joints, weights = binding.csr()
    assert indptr[-1] == len(joints) == np.count_nonzero(w)
    assert np.allclose(binding.dense(), w)
    idx, pw = binding.padded()
    assert np.allclose(pw.sum(axis=1), w.sum(axis=1))


def test_binding_validates_indices():
    with pytest.raises(ValueError):
        SkinBinding([0], [3], [1.0], 1, 2)
    with pytest.raises(ValueError):
        SkinBinding([2], [0], [1.0], 1, 2)
    padded = SkinBinding.from_padded([[0, 1], [1, 0]], [[0.25, 0.75], [1.0, 0.0]], 2)
    assert len(padded) == 3
    assert np.allclose(SkinBinding([0, 0], [0, 1], [1.0, 1.0], 1, 2).renormalized().weight, [0.5, 0.5])


def test_faceted_and_vertex_normals_guard_zero_area():
    p = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [2, 0, 0]], dtype=float)
    tris = np.array([[0, 1, 2], [0, 1, 3]])  # the second is degenerate
    fn = faceted_normals(p, tris)
    assert np.allclose(fn, [[0, 0, 1], [0, 0, 0]])
    vn = vertex_normals(p, tris)
    assert np.allclose(vn[:3], [[0, 0, 1]] * 3) and np.allclose(vn[3], 0)


# ------------------------------------------------------------- real data
def wasp_bind_pose(shared_data):
    skel = load_skel(shared_data / "cse169/wasp_walk/wasp.skel")
    skel.reset_pose()
    skel.root_translation = np.array([0.0, 0.95, -0.15])
    return skel


@pytest.mark.parametrize("name", ["skin/wasp.skin", "wasp_walk/wasp.skin", "wasp_walk/wasp_4weights.skin"])
def test_wasp_bind_pose_reproduces_the_file(shared_data, name):
    skel = wasp_bind_pose(shared_data)
    skin = load_skin(shared_data / "cse169" / name)
    w = skel.world_matrices()
    # every binding translation is the zero-pose joint position
    assert np.allclose(skin.bind_matrices[:, :3, 3], w[:, :3, 3], atol=1e-12)
    p = skin_positions(skin, w)
    if "4weights" in name:
        # two vertices' weights sum to 1.000001 in that file: exact once renormalised
        assert np.abs(p - skin.positions).max() < 1e-5
        skin = Skin(skin.positions, skin.triangles, skin.binding.renormalized(), skin.inverse_bind_matrices)
        p = skin_positions(skin, w)
    assert np.abs(p - skin.positions).max() < 1e-9
    if skin.normals is not None:
        n = skin_normals(skin, w)
        unit = skin.normals / np.linalg.norm(skin.normals, axis=1)[:, None]
        assert np.abs(n - unit).max() < 1e-9


def mit_model(shared_data, i=1):
    skel = load_skel(shared_data / f"mit6837/Model{i}.skel")
    mesh = load_obj(shared_data / f"mit6837/Model{i}.obj")
    w = load_attach(shared_data / f"mit6837/Model{i}.attach", mesh.num_vertices, len(skel.joints))
    skin = bind_to_skeleton(mesh.positions, mesh.triangles, SkinBinding.from_dense(w), skel.bind_world_matrices())
    return skel, mesh, skin


def test_mit_model1_regression_numbers(shared_data):
    skel, mesh, skin = mit_model(shared_data)
    rest = skin_positions(skin, skel.world_matrices())
    off = np.abs(rest - mesh.positions)
    assert 2.7e-4 < off.max() <= 2.75e-4 + 1e-9  # Σw·v, weights not renormalised
    assert np.linalg.norm(rest - mesh.positions, axis=1).max() == pytest.approx(4.0e-4, abs=0.1e-4)
    assert skin.binding.max_influences == 13

    s = skel.copy()
    s.set_dof(4, "x", 0.3)
    s.set_dof(4, "y", -0.5)
    s.set_dof(4, "z", 0.7)
    assert np.allclose(s.world_matrices()[7][:3, 3], [0.64567, 0.10592, 0.49948], atol=1e-5)

    s = skel.copy()
    s.set_dof(14, "z", 1.2)
    p = skin_positions(skin, s.world_matrices())
    d = np.linalg.norm(p - rest, axis=1)
    assert d.max() == pytest.approx(0.2037, abs=1e-4)
    assert int((d > 1e-4).sum()) == 1589
    assert int((np.linalg.norm(p - mesh.positions, axis=1) > 1e-4).sum()) == 3869


def test_mit_model3_zero_area_triangles_give_finite_normals(shared_data):
    skel, mesh, skin = mit_model(shared_data, 3)
    fn = faceted_normals(mesh.positions, mesh.triangles)
    assert np.all(np.isfinite(fn))
    assert int((np.linalg.norm(fn, axis=1) == 0).sum()) == 4
    n = skin_normals(skin, skel.world_matrices())
    assert np.all(np.isfinite(n))


def test_extra_bind_matrices_are_harmless_but_missing_joints_are_not():
    skel, skin = two_bone()
    w = skel.world_matrices()
    extra = Skin(skin.positions, skin.triangles, skin.binding, np.concatenate([skin.inverse_bind_matrices,
                                                                              np.eye(4)[None]]))
    assert np.allclose(skin_positions(extra, w), skin_positions(skin, w))
    with pytest.raises(ValueError, match="refer to 2 joints"):
        skin_positions(skin, w[:1])


def test_cached_layout_follows_replaced_arrays():
    skel, skin = two_bone()
    w = skel.world_matrices()
    skin_positions(skin, w)
    skin.positions = skin.positions + 1.0
    assert np.allclose(skin_positions(skin, w), skin.positions)
    skin.positions[:] = 0.0  # in place: needs invalidate_caches
    skin.invalidate_caches()
    assert np.allclose(skin_positions(skin, w), 0.0)


@settings(max_examples=25, deadline=None)
@given(st.integers(1, 60), st.integers(1, 9), st.integers(0, 10_000), st.sampled_from([3, 7, 8192]))
def test_blocked_permuted_layout_matches_dense_reference(nv, nj, seed, chunk):
    import qtanimator.core.skinning as sk

    rng = np.random.default_rng(seed)
    w = rng.random((nv, nj)) * (rng.random((nv, nj)) < 0.4)  # varied counts, some vertices with none
    mats = np.stack([translation(*rng.normal(size=3)) @ rotation_x(rng.normal()) @ rotation_z(rng.normal())
                     @ np.diag([*rng.uniform(0.5, 2, 3), 1.0]) for _ in range(nj)])
    normals = rng.normal(size=(nv, 3))
    skin = Skin(rng.normal(size=(nv, 3)), np.zeros((0, 3), dtype=int), SkinBinding.from_dense(w),
                np.tile(np.eye(4), (nj, 1, 1)), normals=normals)
    old = sk.CHUNK
    sk.CHUNK = chunk
    try:
        got64 = skin_positions(skin, mats)
        got32 = skin_positions(skin, mats, dtype=np.float32)
        n64 = skin_normals(skin, mats)
        blended = sk.blended_matrices(skin, mats)
    finally:
        sk.CHUNK = old
    a = np.einsum("vj,jab->vab", w, mats)
    expected = np.einsum("vab,vb->va", a, np.c_[skin.positions, np.ones(nv)])[:, :3]
    assert np.allclose(got64, expected, atol=1e-12)
    assert np.allclose(got32, expected, atol=1e-4)
    assert np.allclose(blended, a[:, :3, :], atol=1e-12)
    ref_n = np.zeros((nv, 3))
    for i in range(nv):
        if abs(np.linalg.det(a[i, :3, :3])) > 1e-9:
            v = np.linalg.inv(a[i, :3, :3]).T @ normals[i]
            ref_n[i] = v / np.linalg.norm(v)
            assert np.allclose(n64[i], ref_n[i], atol=1e-6)


def test_positions_and_normals_together_match_separate_calls():
    from qtanimator.core.skinning import skin_positions_and_normals

    skel, skin = two_bone()
    skel.set_dof(1, "z", 0.9)
    skel.set_dof(0, "y", -0.4)
    w = skel.world_matrices()
    p, n = skin_positions_and_normals(skin, w)
    assert np.allclose(p, skin_positions(skin, w)) and np.allclose(n, skin_normals(skin, w))
