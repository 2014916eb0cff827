import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from qtanimator.formats import FormatError
from qtanimator.formats.skel import detect_dialect, load_skel, parse_skel, summarize

SMALL = """balljoint root {
\toffset 0 0 0
\tpose 0 0.1 0
\tballjoint knee {
\t\toffset 0 -0.3 0
\t\trotxlimit -2 0
\t\trotylimit 0 0
\t\tpose -3 1 2
\t}
\tboxmin -0.2 -0.3 -0.15
\tballjoint other { }
}
"""


def test_balljoint_defaults_order_and_clamping():
    s = parse_skel(SMALL)
    assert s.rotation_order == "zyx" and s.dialect == "balljoint"
    assert s.names == ["root", "knee", "other"]
    assert s.parents == [-1, 0, 0]
    assert np.allclose(s.joints[1].pose, [-2, 0, 2])  # z has no limit
    assert s.joints[1].dofs[2].max == 100000
    assert np.allclose(s.joints[0].boxmin, [-0.2, -0.3, -0.15])
    assert np.allclose(s.joints[0].boxmax, [0.1, 0.1, 0.1])
    assert np.allclose(s.joints[2].boxmin, [-0.1] * 3)


@pytest.mark.parametrize("transform", [
    lambda s: s.replace("\n", "\r\n"), lambda s: s.replace("\n", "\r"), lambda s: s.replace("\n", "\r\r\n"),
    lambda s: s.rstrip(), lambda s: s.replace("\t", "  "), lambda s: s.replace(" {", "{"),
])
def test_line_ending_quirks(transform):
    a, b = parse_skel(SMALL), parse_skel(transform(SMALL))
    assert a.names == b.names and np.array_equal(a.world_matrices(), b.world_matrices())


@pytest.mark.parametrize("text,fragment", [
    ("balljoint root {\n offset 0 0\n}", "expected a number"),
    ("balljoint root {\n offset 0 0 0\n", "truncated"),
    ("balljoint root {\n offset 0 0 0\n offset 1 1 1\n}", "appears twice"),
    ("balljoint root {\n rotxlimit 1 -1\n}", "above its maximum"),
    ("balljoint root {\n color 1 1 1\n}", "unknown item"),
    ("balljoint root { } balljoint two { }", "exactly one root"),
    ("balljoint {", "needs a name"),
    ("0 0 0 -1\n0 1 0 5\n", "not an earlier joint"),
    ("0 0 0 -1\n0 1 0\n", "4 fields"),
    ("0 0 0 -1\n0 x 0 0\n", "three numbers"),
    ("0 0 0 0\n", "not an earlier joint"),
    ("0 0 0 -1\n0 0 0 -1\n", "only the first joint"),
    ("hello", "not a skeleton"),
    ("", "empty"),
])
def test_errors(text, fragment):
    with pytest.raises(FormatError) as info:
        parse_skel(text, "bad.skel")
    assert fragment in str(info.value)
    assert info.value.line is not None


def test_deep_nesting_does_not_recurse():
    depth = 5000
    text = "balljoint j {\n offset 0 1 0\n" * depth + "}\n" * depth
    s = parse_skel(text)
    assert len(s.joints) == depth
    assert s.world_matrices()[-1][1, 3] == pytest.approx(depth)


def test_mit_dialect():
    s = parse_skel("0.5 0.5 0.5 -1\n0 0.1 0 0\n0.1 0 0 1\n0 0 0.1 0\n")
    assert s.dialect == "mit" and s.rotation_order == "xyz"
    assert s.parents == [-1, 0, 1, 0]
    assert s.joints[1].dofs[0].min == pytest.approx(-math.pi)
    assert detect_dialect("\n\n  balljoint x {}") == "balljoint"


@settings(max_examples=150, deadline=None)
@given(st.data())
def test_fuzz_only_format_error(data):
    base = data.draw(st.sampled_from([SMALL, "0 0 0 -1\n0 1 0 0\n1 0 0 1\n"]))
    i = data.draw(st.integers(0, len(base)))
    junk = data.draw(st.text(alphabet="{}0123456789.- \n\rballjointxyzfs", max_size=10))
    text = data.draw(st.sampled_from([base[:i], base[:i] + junk + base[i:], base[:i] + junk + base[i + 3:]]))
    try:
        parse_skel(text, "f.skel")
    except FormatError as err:
        assert err.line is not None


@settings(max_examples=60, deadline=None)
@given(st.text(max_size=120))
def test_fuzz_random(text):
    try:
        parse_skel(text)
    except FormatError:
        pass


# ------------------------------------------------------------------- real files
def test_every_shared_skel_loads(shared_data):
    files = sorted(shared_data.rglob("*.skel"))
    assert len(files) >= 11
    for f in files:
        s = load_skel(f)
        assert np.all(np.isfinite(s.world_matrices()))
        assert summarize(f)["joints"] == len(s.joints)


def test_known_skeletons(shared_data):
    d = shared_data / "cse169"
    test = load_skel(d / "skeleton/test.skel")
    assert len(test.joints) == 6
    assert np.allclose(test.joints[test.index_of("knee_r")].pose, [-2, 0, 0])
    wasp = load_skel(d / "skeleton/wasp.skel")
    walk = load_skel(d / "wasp_walk/wasp.skel")
    assert len(wasp.joints) == len(walk.joints) == 23
    assert np.allclose(wasp.world_matrices(), walk.world_matrices())
    assert walk.names.index("hip_03_r") < walk.names.index("hip_01_r")
    dragon = load_skel(d / "skeleton/dragon.skel")
    mixed = load_skel(d / "skeleton/dragon_mixed_eol.skel")
    assert len(dragon.joints) == 81 and len(set(dragon.names)) == 65
    assert np.array_equal(dragon.world_matrices(), mixed.world_matrices())
    keys = dragon.joint_keys()
    assert len(set(keys)) == 81
    lo, hi = dragon.dof_limits()
    assert np.any(lo == hi)  # pinned limits
    assert len(load_skel(d / "head/head.skel").joints) == 1


def test_mit_models(shared_data):
    for i in range(1, 5):
        s = load_skel(shared_data / f"mit6837/Model{i}.skel")
        assert s.parents == [-1, 0, 1, 0, 2, 4, 5, 6, 2, 8, 9, 10, 0, 12, 13, 0, 15, 16]
        assert s.names[4] == "Right hip"
        assert np.all(s.world_matrices()[:, :3, 3] >= 0) and np.all(s.world_matrices()[:, :3, 3] <= 1)
