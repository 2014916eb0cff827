"""The SVG rig reader: conformance with the CMU sample scenes, full SVG, and bad input."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from qtanimator.formats.errors import FormatError
from qtanimator.formats.svg_rig import load_characters, parse_character, summarize

# (file, joints, dynamic) from notes/cmu-animator.md section 12
SCENES = [
    ("arm.svg", 6, 0), ("candle.svg", 4, 0), ("character.svg", 36, 10), ("clock.svg", 8, 3),
    ("notails.svg", 7, 0), ("owl.svg", 95, 86), ("pencil.svg", 1, 0), ("pocketwatch.svg", 24, 1),
    ("simple.svg", 2, 0), ("testscene/bunny.svg", 17, 0), ("testscene/cloud.svg", 1, 0),
    ("testscene/ground.svg", 1, 0), ("testscene/strange.svg", 16, 0), ("testscene/telescope.svg", 6, 0),
    ("testscene/tree.svg", 19, 0),
]


@pytest.mark.parametrize("name,joints,dynamic", SCENES)
def test_sample_scene_counts(shared_data: Path, name: str, joints: int, dynamic: int) -> None:
    [ch] = load_characters(shared_data / "cmu-animator" / "scenes" / name)
    assert len(ch.joints) == joints
    assert int(ch.dynamic.sum()) == dynamic
    assert ch.joints[0].parent is None
    assert all(j.parent is not None and j.parent < i for i, j in enumerate(ch.joints) if i)
    assert len({j.name for j in ch.joints}) == joints
    if name != "clock.svg":
        assert ch.warnings == []


def test_totals_and_dynamic_indices(shared_data: Path) -> None:
    root = shared_data / "cmu-animator" / "scenes"
    chars = [c for n, _, _ in SCENES for c in load_characters(root / n)]
    assert sum(len(c.joints) for c in chars) == 243
    assert sum(int(c.dynamic.sum()) for c in chars) == 100
    [ch] = load_characters(root / "character.svg")
    assert list(np.flatnonzero(ch.dynamic)) == [10, 11, 12, 13, 14, 22, 23, 24, 25, 26]
    [clock] = load_characters(root / "clock.svg")
    assert list(np.flatnonzero(clock.dynamic)) == [1, 2, 5]
    [watch] = load_characters(root / "pocketwatch.svg")
    assert list(np.flatnonzero(watch.dynamic)) == [13]


def test_folder_loads_sorted_by_name(shared_data: Path) -> None:
    chars = load_characters(shared_data / "cmu-animator" / "scenes" / "testscene")
    assert [c.name for c in chars] == ["bunny", "cloud", "ground", "strange", "telescope", "tree"]
    assert [len(c.joints) for c in chars] == [17, 1, 1, 16, 6, 19]


def test_clock_short_hand_uses_bounding_box_centre_and_warns(shared_data: Path, caplog) -> None:  # type: ignore[no-untyped-def]
    with caplog.at_level("WARNING"):
        [clock] = load_characters(shared_data / "cmu-animator" / "scenes" / "clock.svg")
    assert len(clock.warnings) == 1 and "bounding-box" in clock.warnings[0]
    assert any("bounding-box" in r.getMessage() for r in caplog.records)
    np.testing.assert_allclose(clock.joints[3].pivot, (291.248, 342.127), atol=0.01)


def test_arm_pivots_and_shapes(shared_data: Path) -> None:
    [arm] = load_characters(shared_data / "cmu-animator" / "scenes" / "arm.svg")
    np.testing.assert_allclose(arm.rest_pivots, [[40, 380], [40, 340], [40, 140], [0, 60], [40, 60], [80, 60]])
    assert [j.parent for j in arm.joints] == [None, 0, 1, 2, 2, 2]
    assert [len(j.shapes) for j in arm.joints] == [1, 1, 1, 3, 3, 3]
    assert arm.joints[0].shapes[0].kind == "ellipse"


SVG_FEATURES = b"""<svg xmlns="http://www.w3.org/2000/svg">
  <g id="body" fill="navy" transform="translate(100, 0)">
    <g>
      <path d="M 0 0 A 10 10 0 0 1 20 0 A 10 10 0 0 1 0 0 Z" transform="translate(-10, 0)"/>
      <rect x="0" y="0" width="10" height="10" fill="#f00" opacity="0.5" stroke="#0f0" stroke-width="2"/>
      <circle cx="0" cy="0" r="1"/>
    </g>
    <g><g>
      <g><polyline points="0,0 0,20" fill="none" stroke="black"/><circle cx="0" cy="0" r="1" fill="white"/></g>
    </g></g>
    <g>
      <polygon points="0,0 10,0 10,10" fill="rgb(0,128,0)"/>
      <circle cx="5" cy="5" r="1" fill="#FFFFFF" transform="translate(10 0)"/>
    </g>
  </g>
</svg>"""


def test_full_svg_features() -> None:
    ch = parse_character(SVG_FEATURES, "features")
    assert [j.name for j in ch.joints] == ["body", "joint1", "joint2"]
    assert [j.parent for j in ch.joints] == [None, 0, 0]
    assert [j.is_dynamic for j in ch.joints] == [False, True, True]
    circle, rect = ch.joints[0].shapes
    # group transform baked in and inherited fill (navy) on the arc path
    assert circle.closed and circle.fill[:3] == pytest.approx((0, 0, 128 / 255))
    area = 0.5 * abs(np.sum(circle.points[:, 0] * np.roll(circle.points[:, 1], -1)
                            - np.roll(circle.points[:, 0], -1) * circle.points[:, 1]))
    assert area == pytest.approx(math.pi * 100, rel=0.02)
    assert circle.points[:, 0].mean() == pytest.approx(100, abs=0.5)
    # 3-digit hex, opacity, stroke
    assert rect.fill == pytest.approx((1, 0, 0, 1)) and rect.opacity == 0.5
    assert rect.stroke == pytest.approx((0, 1, 0, 1)) and rect.stroke_width == 2
    np.testing.assert_allclose(ch.joints[0].pivot, (100, 0))
    # the pivot circle's own transform is baked in too
    np.testing.assert_allclose(ch.joints[2].pivot, (115, 5))
    assert ch.joints[2].shapes[0].fill == pytest.approx((0, 128 / 255, 0, 1))
    # a nested chain of single groups collapses to the joint
    line = ch.joints[1].shapes[0]
    assert not line.closed and line.kind == "polyline"


def test_duplicate_ids_get_unique_names() -> None:
    joint = b'<rect width="1" height="1"/><circle r="1"/>'
    svg = (b'<svg><g><g id="a">' + joint + b'</g><g id="a">' + joint + b'</g><g>' + joint + b'</g></g></svg>')
    ch = parse_character(svg, "dup")
    assert [j.name for j in ch.joints] == ["a", "a_2", "joint2"]


@pytest.mark.parametrize("data,message", [
    (b"this is not xml", "well-formed"),
    (b"<html><body/></html>", "not <svg>"),
    (b"<svg></svg>", "no elements"),
    # (ordinary art, a first element that is not a group or an empty child group, now opens:
    # tests/formats/test_svg_ordinary_art.py)
    (b"<svg><g></g></svg>", "empty group"),
    (b"<svg><g><rect width='1' height='1'/><circle r='1'/>", "well-formed"),
    # areas and moments of such shapes overflow: refused here, not NaN in a pendulum later
    (b"<svg><g><rect width='1e300' height='1e300'/><circle r='1' fill='white'/></g></svg>", "too large"),
    (b"<svg><g><path d='M 0 0 L 1e308 3 L 4 1e308 Z'/><circle r='1'/></g></svg>", "too large"),
])
def test_bad_svg_raises_format_error(data: bytes, message: str) -> None:
    with pytest.raises(FormatError, match=message):
        parse_character(data, "bad", "bad.svg")


def test_bad_paths(tmp_path: Path) -> None:
    with pytest.raises(FormatError, match="no such"):
        load_characters(tmp_path / "missing.svg")
    with pytest.raises(FormatError, match="no .svg"):
        load_characters(tmp_path)
    err = None
    (tmp_path / "x.svg").write_bytes(b"<svg><g>")
    try:
        load_characters(tmp_path / "x.svg")
    except FormatError as exc:
        err = exc
    assert err is not None and err.path is not None and err.path.endswith("x.svg") and err.line == 1


GOOD = SVG_FEATURES


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.one_of(st.binary(max_size=300), st.integers(0, len(GOOD)).map(lambda n: GOOD[:n]),
                 st.tuples(st.integers(0, len(GOOD) - 1), st.binary(min_size=1, max_size=8)).map(
                     lambda t: GOOD[:t[0]] + t[1] + GOOD[t[0] + len(t[1]):])))
def test_fuzz_only_format_error(data: bytes) -> None:
    try:
        ch = parse_character(data, "fuzz")
    except FormatError:
        return
    assert len(ch.joints) >= 1
    assert all(np.all(np.isfinite(s.points)) for j in ch.joints for s in j.shapes)


def test_summarize(shared_data: Path) -> None:
    from qtanimator.formats.info import summarize as info_summarize

    assert info_summarize(shared_data / "cmu-animator" / "scenes" / "arm.svg")["joints"] == 6
    s = summarize(shared_data / "cmu-animator" / "scenes" / "testscene")
    assert s["joints"] == 60 and s["dynamic"] == 0 and len(s["characters"]) == 6
    s = summarize(shared_data / "cmu-animator" / "scenes" / "clock.svg")
    assert s["characters"][0]["dynamic"] == 3 and s["characters"][0]["warnings"]


def test_project_scenes_load() -> None:
    root = Path(__file__).resolve().parents[2] / "scenes"
    [clock] = load_characters(root / "pendulum_clock.svg")
    assert [j.name for j in clock.joints if j.is_dynamic] == ["pendulum"]
    [pip] = load_characters(root / "demo" / "pip.svg")
    assert [j.name for j in pip.joints if j.is_dynamic] == ["earring", "lantern_chain", "lantern"]
    assert pip.warnings == [] and clock.warnings == []


GROUP_OPACITY = b"""<svg xmlns="http://www.w3.org/2000/svg"><style>.faint { opacity: 0.25 }</style>
  <g>
    <g><rect x="0" y="0" width="10" height="10"/><circle cx="0" cy="0" r="1"/></g>
    <g opacity="0.5"><rect x="0" y="0" width="10" height="10"/><circle cx="0" cy="0" r="1" fill="#fff"/></g>
    <g opacity="0.5"><rect x="0" y="0" width="10" height="10" opacity="0.8"/><circle cx="0" cy="0" r="1"/></g>
    <g opacity="0.5"><rect x="0" y="0" width="10" height="10" style="opacity:0.4"/><circle cx="0" cy="0" r="1"/></g>
    <g><rect class="faint" x="0" y="0" width="10" height="10"/><circle cx="0" cy="0" r="1"/></g>
  </g>
</svg>"""


def test_group_opacity_is_a_look_not_a_mass() -> None:
    """Issue 18 item 7: a group's opacity changes how a shape looks, never its mass; the
    element's own opacity (attribute, style or CSS class) scales its fill density, as the
    reference program's starter rule does."""
    ch = parse_character(GROUP_OPACITY, "faded")
    assert [j.mass for j in ch.joints] == pytest.approx([100.0, 100.0, 80.0, 40.0, 25.0])
    assert [j.shapes[0].opacity for j in ch.joints[:2]] == [1.0, 0.5]  # still drawn faded
