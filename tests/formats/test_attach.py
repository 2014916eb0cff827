import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from qtanimator.formats import FormatError
from qtanimator.formats.attach import load_attach, parse_attach, summarize


def test_root_column_is_zero_and_lines_do_not_matter():
    text = "0.5 0.5 \n1 0 \n"
    w = parse_attach(text, 2, 3)
    assert w.tolist() == [[0, 0.5, 0.5], [0, 1, 0]]
    assert np.array_equal(parse_attach("0.5 0.5 1 0", 2, 3), w)
    assert np.array_equal(parse_attach(text.replace("\n", "\r\n"), 2, 3), w)


def test_weights_are_not_renormalised():
    assert parse_attach("0.3 0.3", 1, 3).sum() == pytest.approx(0.6)


@pytest.mark.parametrize("text,fragment", [
    ("0.5 0.5\n1\n", "found 3"),
    ("0.5 0.5\n1 0 0\n", "found 5"),
    ("0.5 x\n1 0\n", "expected a weight"),
    ("0.5 nan\n1 0\n", "finite"),
])
def test_errors(text, fragment):
    with pytest.raises(FormatError) as info:
        parse_attach(text, 2, 3, "bad.attach")
    assert fragment in str(info.value)


def test_error_line_of_a_bad_token():
    with pytest.raises(FormatError) as info:
        parse_attach("0 1\n1 0\n0.5 oops\n", 3, 3)
    assert info.value.line == 3


@settings(max_examples=100, deadline=None)
@given(st.text(alphabet="0123456789.-e \n\rx", max_size=60), st.integers(0, 5), st.integers(1, 5))
def test_fuzz(text, nv, nj):
    try:
        w = parse_attach(text, nv, nj)
    except FormatError:
        return
    assert w.shape == (nv, nj) and np.all(w[:, 0] == 0)


def test_mit_attachments(shared_data):
    stats = {1: 13, 2: 13, 3: 11, 4: 13}
    for i, most in stats.items():
        w = load_attach(shared_data / f"mit6837/Model{i}.attach", 13336, 18)
        assert (w != 0).sum(axis=1).max() == most
        assert np.all((w[:, 1:] != 0).any(axis=0))  # every column used
        s = w.sum(axis=1)
        assert 0.9995 <= s.min() and s.max() <= 1.0004
    with pytest.raises(FormatError, match="13336 vertices × 16"):
        load_attach(shared_data / "mit6837/Model1.attach", 13336, 17)
    assert summarize(shared_data / "mit6837/Model1.attach")["joints"] == 18


@pytest.mark.parametrize("text,fragment,line", [
    ("", "holds no weights", 1),
    ("\n  \n", "holds no weights", 1),
    ("0.5 0.5\n1 0\n0 0 1\n", "this line has 3 weights but the first has 2", 3),
])
def test_summary_of_a_broken_file_says_where(tmp_path, text, fragment, line):
    f = tmp_path / "bad.attach"
    f.write_text(text)
    with pytest.raises(FormatError) as info:
        summarize(f)
    assert fragment in str(info.value) and info.value.line == line
