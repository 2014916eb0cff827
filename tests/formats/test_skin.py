import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from qtanimator.formats import FormatError
from qtanimator.formats.skin import load_skin, parse_skin, summarize

TRIANGLE = """positions 3 {
\t0 0 0
\t1 0 0
\t0 1 0
}
normals 3 {
\t-1 -1 1
\t1 -1 1
\t0 1 1
}
skinweights 3 {
\t1 0 1
\t2 0 0.5 1 0.5
\t1 1 1
}
material face {
\ttexture head.bmp
}
triangles 1 {
\t0 1 2
}
bindings 2 {
\tmatrix {
\t\t1 0 0
\t\t0 1 0
\t\t0 0 1
\t\t0 0 0
\t}
\tmatrix {
\t\t0 1 0
\t\t-1 0 0
\t\t0 0 1
\t\t1 2 3
\t}
}
"""


def test_parses_sections():
    s = parse_skin(TRIANGLE)
    assert s.num_vertices == 3 and s.triangles.tolist() == [[0, 1, 2]]
    assert s.binding.max_influences == 2
    assert s.binding.vertex.tolist() == [0, 1, 1, 2]
    assert s.material == {"name": "face", "texture": "head.bmp"}
    # a, b, c, d are columns
    b = s.bind_matrices[1]
    assert np.allclose(b[:3, 0], [0, 1, 0]) and np.allclose(b[:3, 1], [-1, 0, 0])
    assert np.allclose(b[:3, 3], [1, 2, 3]) and np.allclose(b[3], [0, 0, 0, 1])
    assert np.allclose(s.inverse_bind_matrices[1] @ b, np.eye(4))


@pytest.mark.parametrize("transform", [
    lambda s: s.replace("\n", "\r\n"), lambda s: s.replace("\n", "\r"), lambda s: s.rstrip(),
    lambda s: s.replace(" {", "{").replace("\t", "\t\t"),
])
def test_quirks(transform):
    a, b = parse_skin(TRIANGLE), parse_skin(transform(TRIANGLE))
    assert np.array_equal(a.positions, b.positions) and np.array_equal(a.bind_matrices, b.bind_matrices)


@pytest.mark.parametrize("old,new,fragment", [
    ("positions 3", "positions 4", "ends early"),
    ("normals 3", "normals 2", "close the normals"),
    ("\t0 1 2\n", "\t0 1 3\n", "refers to vertex 3"),
    ("\t1 1 1\n", "\t1 2 1\n", "joint 2"),
    ("\t1 1 1\n", "\t1 -1 1\n", "joint -1"),
    ("\t1 1 1\n}", "}", "lists only 2"),
    ("bindings 2", "bindings 3", "too short"),
    ("\t\t1 2 3\n", "\t\t1 2\n", "ends early"),
    ("\t1 0 1\n", "\t1 0 x\n", "expected a number"),
    ("triangles 1", "triangle 1", "unknown section"),
    ("\t0 1 2\n", "\t0 1 2.5\n", "whole number"),
    ("positions 3 {", "positions -3 {", "at least 0"),
    # a whole number too large for numpy's intp must not escape as OverflowError
    ("\t1 1 1\n", "\t1 18446744073709551616 1\n", "out of range"),
    ("positions 3 {", "positions " + "9" * 5000 + " {", "whole number"),
])
def test_errors(old, new, fragment):
    with pytest.raises(FormatError) as info:
        parse_skin(TRIANGLE.replace(old, new, 1), "bad.skin")
    assert fragment in str(info.value)
    assert info.value.line is not None


def test_duplicate_and_missing_sections():
    with pytest.raises(FormatError, match="appears twice"):
        parse_skin(TRIANGLE + "triangles 0 { }")
    with pytest.raises(FormatError, match="no 'positions'"):
        parse_skin("triangles 0 { }")
    with pytest.raises(FormatError, match="empty"):
        parse_skin("")
    with pytest.raises(FormatError, match="joints in the skeleton"):
        parse_skin(TRIANGLE, num_joints=1)
    singular = TRIANGLE.replace("\t\t0 1 0\n\t\t-1 0 0\n", "\t\t0 0 0\n\t\t0 0 0\n")
    with pytest.raises(FormatError, match="cannot be inverted"):
        parse_skin(singular)


@settings(max_examples=150, deadline=None)
@given(st.data())
def test_fuzz_only_format_error(data):
    i = data.draw(st.integers(0, len(TRIANGLE)))
    junk = data.draw(st.text(alphabet="{}0123456789.- \n\rmatrixpositions", max_size=10))
    text = data.draw(st.sampled_from([TRIANGLE[:i], TRIANGLE[:i] + junk + TRIANGLE[i:],
                                      TRIANGLE[:i] + junk + TRIANGLE[i + 4:]]))
    try:
        parse_skin(text, "f.skin")
    except FormatError as err:
        assert err.line is not None or err.path


def test_every_shared_skin_loads(shared_data):
    expected = {"tube.skin": (240, 456, 2), "wasp.skin": (694, 1236, 23), "triangle.skin": (3, 1, 1),
                "head.skin": (3078, 1458, 1), "wasp_4weights.skin": (694, 1236, 23)}
    files = sorted(shared_data.rglob("*.skin"))
    assert len(files) == 8
    for f in files:
        s = load_skin(f)
        if f.name in expected:
            assert (s.num_vertices, len(s.triangles), s.num_joints) == expected[f.name]
        assert np.allclose(s.bind_matrices[:, :3, :3], np.eye(3))  # pure translations in every sample
        assert summarize(f)["vertices"] == s.num_vertices


def test_texcoords_material_and_weights(shared_data):
    s = load_skin(shared_data / "cse169/head/head_tex.skin")
    assert s.texcoords.shape == (3078, 2) and s.texcoords[:, 0].max() > 1.0
    assert s.material["texture"] == "head.bmp"
    w4 = load_skin(shared_data / "cse169/wasp_walk/wasp_4weights.skin")
    w2 = load_skin(shared_data / "cse169/wasp_walk/wasp.skin")
    assert w4.binding.max_influences == 4 and w2.binding.max_influences == 2
    # same mesh; the 4-weight file stores one more digit
    assert np.allclose(w4.positions, w2.positions, atol=1e-5) and np.array_equal(w4.triangles, w2.triangles)
    assert np.allclose(w2.binding.weight_sums(), 1.0)
