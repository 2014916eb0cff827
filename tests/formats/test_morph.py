import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from qtanimator.formats import FormatError
from qtanimator.formats.morph import apply_morphs, load_morph, parse_morph, summarize
from qtanimator.formats.skin import load_skin

TEXT = "positions 2 {\n 1 1 1 1\n 3 0 2 0\n}\nnormals 2 {\n 1 0 1 0\n 3 1 0 0\n}\n"


def test_parse_and_blend():
    m = parse_morph(TEXT)
    assert m.indices.tolist() == [1, 3]
    base = np.zeros((4, 3))
    normals = np.tile([0.0, 0.0, 1.0], (4, 1))
    p, n = apply_morphs(base, normals, [(m, 0.5)])
    assert p.tolist() == [[0, 0, 0], [0.5, 0.5, 0.5], [0, 0, 0], [0, 1, 0]]
    assert np.allclose(np.linalg.norm(n, axis=1), 1.0)
    assert np.allclose(n[0], [0, 0, 1])
    with pytest.raises(ValueError):
        apply_morphs(np.zeros((2, 3)), None, [(m, 1.0)])


@pytest.mark.parametrize("text,fragment", [
    ("positions 1 {\n 1.5 0 0 0\n}", "whole number"),
    ("positions 2 {\n 1 0 0 0\n 1 1 1 1\n}", "listed twice"),
    ("positions 1 {\n 1 0 0\n}", "ends early"),
    ("normals 0 { }", "no 'positions'"),
    ("shapes 1 { }", "unknown section"),
])
def test_errors(text, fragment):
    with pytest.raises(FormatError, match=fragment):
        parse_morph(text, "bad.morph")


@settings(max_examples=100, deadline=None)
@given(st.integers(0, len(TEXT)), st.text(alphabet="{}0123456789.- \nposintrmal", max_size=8))
def test_fuzz(i, junk):
    for text in (TEXT[:i], TEXT[:i] + junk + TEXT[i:]):
        try:
            parse_morph(text)
        except FormatError:
            pass


def test_head_morphs(shared_data):
    d = shared_data / "cse169/head"
    skin = load_skin(d / "head.skin")
    for name, count, most in (("head1.morph", 259, 0.22), ("head2.morph", 223, 0.16)):
        m = load_morph(d / name)
        assert len(m.indices) == count and np.array_equal(m.indices, m.normal_indices)
        m.check(skin.num_vertices)
        moved = np.abs(m.positions - skin.positions[m.indices]).max()
        assert 0.5 * most < moved <= most + 0.005
        assert summarize(d / name)["positions"] == count
