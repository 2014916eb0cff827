"""SVG rig pivot rules (docs/formats.md, "SVG rigs"), with shapes that tell the rules apart.

* A joint's last element is a ``<circle>``: its centre, with every transform applied, is
  the pivot.
* Any other last element: the centre of its **bounding box** (with a warning) — not the mean
  of its vertices and not its area centroid, which only agree with the box centre for
  symmetric shapes; so the shapes here are lopsided.
* The pivot circle's fill decides dynamic: white (r = g = b = 1) that is visible. A white
  fill made fully transparent (``fill-opacity="0"``) is no fill: keyframed.

Every expected value is worked out by hand in the comments.
"""

from __future__ import annotations

import numpy as np
import pytest

from qtanimator.formats.svg_rig import parse_character


def rig(last: str, group_transform: str = "") -> bytes:
    """A two-joint rig: a body with an ordinary pivot circle, then the joint ``part``
    (one rectangle, then ``last`` as its final element)."""
    gt = f' transform="{group_transform}"' if group_transform else ""
    return ('<svg xmlns="http://www.w3.org/2000/svg"><g>'
            '<g id="body"><rect x="-600" y="-600" width="10" height="10"/><circle cx="-595" cy="-595" r="1"/></g>'
            f'<g id="part"{gt}><rect x="-500" y="-500" width="10" height="10" fill="#808080"/>{last}</g>'
            '</g></svg>').encode()


def part(last: str, group_transform: str = "") -> tuple[np.ndarray, bool, list[str]]:
    """The pivot, dynamic flag and the character's warnings of the joint ``part``."""
    ch = parse_character(rig(last, group_transform), "t")
    assert [j.name for j in ch.joints] == ["body", "part"]
    np.testing.assert_allclose(ch.joints[0].pivot, (-595.0, -595.0))
    j = ch.joints[1]
    return np.asarray(j.pivot, dtype=np.float64), bool(j.is_dynamic), list(ch.warnings)


def pivot_of(last: str, group_transform: str = "") -> np.ndarray:
    return part(last, group_transform)[0]


# ---------------------------------------------------------------- bounding-box centre

# A lopsided polygon: x from 0 to 40, y from 0 to 12, so its box centre is (20, 6).
# Its vertex mean is ((0+40+40+36+2)/5, (0+0+4+4+12)/5) = (23.6, 4); its area centroid is
# elsewhere again. Only the box centre is right.
LOPSIDED = "0,0 40,0 40,4 36,4 2,12"


@pytest.mark.parametrize("element,expected", [
    (f'<polygon points="{LOPSIDED}"/>', (20.0, 6.0)),
    ('<path d="M 0 0 L 40 0 L 40 4 L 36 4 L 2 12 Z"/>', (20.0, 6.0)),
    (f'<polyline points="{LOPSIDED}" fill="none" stroke="black"/>', (20.0, 6.0)),
    # x' = 2x + 100, y' = y + 50: box (100 … 180, 50 … 62), centre (140, 56)
    (f'<polygon points="{LOPSIDED}" transform="translate(100 50) scale(2 1)"/>', (140.0, 56.0)),
    # many vertices bunched at one end (a dense zig-zag near x = 0 … 1) and one far vertex
    # at (90, 30): box (0 … 90, 0 … 30), centre (45, 15); the vertex mean is near x = 8
    ('<polygon points="0,0 1,1 0,2 1,3 0,4 1,5 0,6 1,7 0,8 1,9 0,10 90,30"/>', (45.0, 15.0)),
    # a rectangle (box = itself) in a rotated frame: rotate(90) maps (x, y) to (−y, x), so the
    # rect x 0 … 30, y 0 … 6 lands on x −6 … 0, y 0 … 30: centre (−3, 15)
    ('<rect x="0" y="0" width="30" height="6" transform="rotate(90)"/>', (-3.0, 15.0)),
])
def test_non_circle_last_element_uses_its_bounding_box_centre(element: str, expected: tuple[float, float]) -> None:
    pivot, _dynamic, warnings = part(element)
    np.testing.assert_allclose(pivot, expected, atol=1e-6)
    assert any("bounding-box centre" in w for w in warnings)


def test_lopsided_shape_box_centre_is_not_its_vertex_mean() -> None:
    """The test shape really separates the rules (guards the test itself)."""
    pts = np.array([[float(a) for a in p.split(",")] for p in LOPSIDED.split()])
    box = (pts.min(axis=0) + pts.max(axis=0)) / 2
    np.testing.assert_allclose(box, (20.0, 6.0))
    assert np.linalg.norm(pts.mean(axis=0) - box) > 3.0


def test_group_of_shapes_as_last_element_uses_the_box_of_all_of_them() -> None:
    # two squares: x 0 … 2, y 0 … 2 and x 50 … 60, y 20 … 40; union box (0 … 60, 0 … 40)
    last = '<g><rect x="0" y="0" width="2" height="2"/><rect x="50" y="20" width="10" height="20"/></g>'
    np.testing.assert_allclose(pivot_of(last), (30.0, 20.0), atol=1e-6)


# ---------------------------------------------------------------- transformed ellipses

@pytest.mark.parametrize("element,group_transform,expected", [
    # centre (10, 0); rotate(90): (x, y) → (−y, x) gives (0, 10); then + (50, 20): (50, 30).
    # An ellipse is symmetric about its centre, so its box centre is the mapped centre.
    ('<ellipse cx="10" cy="0" rx="6" ry="2" transform="translate(50 20) rotate(90)"/>', "", (50.0, 30.0)),
    # scale(3 0.5) then translate(−7 4): (4, 8) → (12, 4) → (5, 8)
    ('<ellipse cx="4" cy="8" rx="5" ry="1" transform="translate(-7 4) scale(3 0.5)"/>', "", (5.0, 8.0)),
    # the transform on the joint's group applies too: (2, 3) → rotate(180) → (−2, −3)
    # → translate(100 0) → (98, −3)
    ('<ellipse cx="2" cy="3" rx="8" ry="3"/>', "translate(100 0) rotate(180)", (98.0, -3.0)),
    # matrix(a b c d e f): (x, y) → (a·x + c·y + e, b·x + d·y + f); (1, 2) with
    # matrix(0 2 -1 0 5 6) → (0·1 − 1·2 + 5, 2·1 + 0·2 + 6) = (3, 8)
    ('<ellipse cx="1" cy="2" rx="4" ry="1.5" transform="matrix(0 2 -1 0 5 6)"/>', "", (3.0, 8.0)),
])
def test_transformed_ellipse_pivot_is_its_mapped_centre(element: str, group_transform: str,
                                                        expected: tuple[float, float]) -> None:
    np.testing.assert_allclose(pivot_of(element, group_transform), expected, atol=1e-6)


@pytest.mark.parametrize("element,group_transform,expected", [
    ('<circle cx="10" cy="0" r="1" transform="translate(50 20) rotate(90)"/>', "", (50.0, 30.0)),
    ('<circle cx="1" cy="2" r="1" transform="matrix(0 2 -1 0 5 6)"/>', "", (3.0, 8.0)),
    ('<circle cx="2" cy="3" r="1"/>', "translate(100 0) rotate(180)", (98.0, -3.0)),
    # skewX(45): x' = x + y: (3, 4) → (7, 4)
    ('<circle cx="3" cy="4" r="1" transform="skewX(45)"/>', "", (7.0, 4.0)),
])
def test_transformed_circle_pivot_is_its_mapped_centre(element: str, group_transform: str,
                                                       expected: tuple[float, float]) -> None:
    pivot, _dynamic, warnings = part(element, group_transform)
    np.testing.assert_allclose(pivot, expected, atol=1e-6)
    assert not any("bounding-box centre" in w for w in warnings)


# ---------------------------------------------------------------- white markers

@pytest.mark.parametrize("fill,dynamic", [
    ('fill="#ffffff"', True),
    ('fill="white"', True),
    ('fill="#FFF"', True),
    ('style="fill:#ffffff"', True),
    # half-transparent white is still white
    ('fill="#ffffff" fill-opacity="0.5"', True),
    # fully transparent white is no fill at all: keyframed
    ('fill="#ffffff" fill-opacity="0"', False),
    ('fill="white" style="fill-opacity:0"', False),
    ('fill="none"', False),
    ('fill="#fefefe"', False),
    ('', False),  # black by default
    ('fill="#ff0000"', False),
])
def test_white_pivot_marker_makes_the_joint_dynamic(fill: str, dynamic: bool) -> None:
    pivot, is_dynamic, _warnings = part(f'<circle cx="3" cy="4" r="1" {fill}/>')
    assert is_dynamic is dynamic
    np.testing.assert_allclose(pivot, (3.0, 4.0))


def test_transparent_white_on_a_non_circle_marker_is_keyframed_too() -> None:
    pivot, dynamic, _warnings = part(f'<polygon points="{LOPSIDED}" fill="#ffffff" fill-opacity="0"/>')
    assert not dynamic
    np.testing.assert_allclose(pivot, (20.0, 6.0), atol=1e-6)
    assert part(f'<polygon points="{LOPSIDED}" fill="#ffffff"/>')[1]
