import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from qtanimator.formats import FormatError
from qtanimator.formats.obj import load_obj, parse_obj, summarize

QUAD = """# a unit square and a triangle
o thing
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
s off
usemtl red
f 1/1/1 2/2/1 3/3/1 4/4/1
f -4//1 -3//1 -1//1
"""


def test_polygons_are_fan_triangulated_with_all_index_forms():
    m = parse_obj(QUAD)
    assert m.num_vertices == 4 and m.polygons == 2
    assert m.triangles.tolist() == [[0, 1, 2], [0, 2, 3], [0, 1, 3]]
    assert m.normals.shape == (1, 3)
    assert m.texcoords.shape == (4, 2)
    assert m.triangle_normals.tolist() == [[0, 0, 0]] * 3
    assert m.triangle_texcoords is None  # the last face has no texture indices


def test_plain_mit_style_and_line_endings():
    text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"
    for variant in (text, text.replace("\n", "\r\n"), text.rstrip(), text.replace("\n", "\r")):
        m = parse_obj(variant)
        assert m.triangles.tolist() == [[0, 1, 2]]


@pytest.mark.parametrize("text,fragment,line", [
    ("v 0 0 0\nv 1 0 0\nf 1 2 3\n", "refers to vertex 3", 3),
    ("v 0 0 0\nf 0 1 1\n", "start at 1", 2),
    ("v 0 0\n", "needs 3 numbers", 1),
    ("v 0 zero 0\n", "expected a number", 1),
    ("v 0 0 0\nf 1 1\n", "at least 3 corners", 2),
    ("v 0 0 0\nf 1 a 1\n", "whole numbers", 2),
    ("v 0 0 0\nvt 0 0\nf 1/1 1 1\n", "some corners", 3),
    ("v 0 0 inf\n", "finite", 1),
    ("v 0 0 0\nf 1/1/1/1 1 1\n", "face corner", 2),
    ("", "no vertices", 1),
    ("# only a comment\nhello world\n", "no vertices", 1),
])
def test_errors(text, fragment, line):
    with pytest.raises(FormatError) as info:
        parse_obj(text, "bad.obj")
    assert fragment in str(info.value)
    assert info.value.line == line


@settings(max_examples=150, deadline=None)
@given(st.data())
def test_fuzz_only_format_error(data):
    i = data.draw(st.integers(0, len(QUAD)))
    junk = data.draw(st.text(alphabet="vtnf/0123456789.- \n\r#\\", max_size=10))
    text = data.draw(st.sampled_from([QUAD[:i], QUAD[:i] + junk + QUAD[i:], QUAD[:i] + junk + QUAD[i + 3:]]))
    try:
        m = parse_obj(text)
    except FormatError:
        return
    if len(m.triangles):
        assert m.triangles.min() >= 0 and m.triangles.max() < m.num_vertices


def test_mit_models(shared_data):
    for i in range(1, 5):
        f = shared_data / f"mit6837/Model{i}.obj"
        m = load_obj(f)
        assert (m.num_vertices, len(m.triangles)) == (13336, 26668)
        assert np.all(m.positions >= 0) and np.all(m.positions <= 1)
        # closed genus-0 surface: V − E + F = 2
        edges = np.sort(m.triangles[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
        e = len(np.unique(edges, axis=0))
        assert m.num_vertices - e + len(m.triangles) == 2
    s = summarize(shared_data / "mit6837/Model1.obj")
    assert s["triangles"] == 26668
    assert s["bounding_box"][0] == pytest.approx([0.2, 0.05, 0.356], abs=1e-3)
