"""SVG features drawn as their author drew them (issue 23): one-feature drawings, opened by
the SVG reader and drawn by the program's 2D path, compared with resvg's rendering of the
same file. At most 1% of the drawing's pixels (inked in either image) may differ by more
than 48/255 in a channel."""

from __future__ import annotations

import base64

import numpy as np
import pytest
import resvg_py  # a test dependency: missing is an error, not a skip
from PySide6.QtGui import QColor, QImage, QPainter

from qtanimator.formats.svg_rig import parse_character
from qtanimator.render.painter2d import draw_character, image_to_array

SIZE = 120
HEAD = (f'<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" '
        f'width="{SIZE}" height="{SIZE}" viewBox="0 0 {SIZE} {SIZE}">')


def svg(body: str) -> str:
    return HEAD + body + "</svg>"


def ours(text: str, **kw: object) -> np.ndarray:
    ch = parse_character(text.encode(), "t")
    img = QImage(SIZE, SIZE, QImage.Format.Format_ARGB32_Premultiplied)
    img.fill(QColor("white"))
    p = QPainter(img)
    draw_character(p, ch, ch.rest_pose(), **kw)  # type: ignore[arg-type]
    p.end()
    return image_to_array(img)[..., :3].astype(int)


def reference(text: str) -> np.ndarray:
    png = bytes(resvg_py.svg_to_bytes(svg_string=text, background="#ffffff", width=SIZE, height=SIZE))
    img = QImage.fromData(png)
    assert not img.isNull()
    return image_to_array(img)[..., :3].astype(int)


def differing(a: np.ndarray, b: np.ndarray) -> float:
    """The share of the drawing's pixels (not white in either image) that differ by > 48."""
    inked = (a < 250).any(axis=2) | (b < 250).any(axis=2)
    bad = (np.abs(a - b) > 48).any(axis=2)
    assert inked.sum() > 50, "the test drawing draws almost nothing"
    return float(bad.sum()) / float(inked.sum())


GRAD = ('<defs><linearGradient id="g" x1="0" y1="0" x2="1" y2="0">'
        '<stop offset="0" stop-color="#ff0000"/><stop offset="1" stop-color="#0000ff"/></linearGradient></defs>')

FEATURES = {
    "linear gradient, bounding-box units": GRAD + '<rect x="10" y="20" width="100" height="80" fill="url(#g)"/>',
    "linear gradient, user space, transform, reflect": (
        '<defs><linearGradient id="u" gradientUnits="userSpaceOnUse" x1="20" y1="0" x2="50" y2="0" '
        'spreadMethod="reflect" gradientTransform="rotate(30 60 60)">'
        '<stop offset="0" stop-color="gold"/><stop offset="1" stop-color="#008000"/></linearGradient></defs>'
        '<rect x="5" y="5" width="110" height="110" fill="url(#u)"/>'),
    "radial gradient, repeat": (
        '<defs><radialGradient id="r" cx="0.5" cy="0.5" r="0.25" fx="0.4" fy="0.4" spreadMethod="repeat">'
        '<stop offset="0" stop-color="white"/><stop offset="1" stop-color="#800080"/></radialGradient></defs>'
        '<circle cx="60" cy="60" r="50" fill="url(#r)"/>'),
    "gradient on a stroke": GRAD + '<rect x="20" y="20" width="80" height="80" fill="none" stroke="url(#g)" '
                                   'stroke-width="14"/>',
    "evenodd hole": '<path fill-rule="evenodd" fill="navy" d="M10 10H110V110H10Z M40 40H80V80H40Z"/>',
    "nonzero reversed hole": '<path fill="navy" d="M10 10H110V110H10Z M40 40V80H80V40Z"/>',
    "round caps and joins": '<polyline points="20,100 60,20 100,100" fill="none" stroke="teal" '
                            'stroke-width="16" stroke-linecap="round" stroke-linejoin="round"/>',
    "square caps, bevel joins": '<polyline points="20,100 60,30 100,100" fill="none" stroke="teal" '
                                'stroke-width="14" stroke-linecap="square" stroke-linejoin="bevel"/>',
    "miter limit 4 (SVG default)": '<polyline points="20,110 60,20 70,110" fill="none" stroke="black" '
                                   'stroke-width="8"/>',
    "dash array and offset": '<path d="M10 30H110 M10 60H110 M10 90 Q60 20 110 90" fill="none" stroke="crimson" '
                             'stroke-width="6" stroke-dasharray="12 6 3 6" stroke-dashoffset="5"/>',
    "group opacity": '<g opacity="0.5"><rect x="10" y="10" width="70" height="70" fill="red"/>'
                     '<rect x="40" y="40" width="70" height="70" fill="blue"/></g>',
    "nested group opacity multiplies": '<g opacity="0.5"><g opacity="0.5"><rect x="10" y="10" width="100" '
                                       'height="100" fill="black"/></g></g>'
                                       '<rect x="10" y="50" width="20" height="20" fill="black"/>',
    "visibility hidden": '<rect x="10" y="10" width="100" height="100" fill="green"/>'
                         '<rect x="30" y="30" width="60" height="60" fill="red" visibility="hidden"/>',
    "clipPath": '<defs><clipPath id="c"><circle cx="60" cy="60" r="40"/></clipPath></defs>'
                '<rect x="0" y="0" width="120" height="120" fill="orange" clip-path="url(#c)"/>',
    "mask": '<defs><mask id="m"><rect x="0" y="0" width="120" height="120" fill="white"/>'
            '<circle cx="60" cy="60" r="30" fill="black"/></mask></defs>'
            '<rect x="10" y="10" width="100" height="100" fill="purple" mask="url(#m)"/>',
    "use": '<defs><rect id="b" width="40" height="40" fill="olive"/></defs>'
           '<use xlink:href="#b" x="10" y="10"/><use href="#b" x="60" y="60"/>',
    "symbol": '<defs><symbol id="s" viewBox="0 0 10 10"><circle cx="5" cy="5" r="5" fill="maroon"/></symbol></defs>'
              '<use href="#s" x="10" y="10" width="50" height="50"/>'
              '<use href="#s" x="60" y="60" width="40" height="20"/>',
    "markers": '<defs><marker id="a" viewBox="0 0 10 10" refX="5" refY="5" markerWidth="6" markerHeight="6" '
               'orient="0"><path d="M0 0L10 5L0 10z" fill="black"/></marker></defs>'
               '<polyline points="20,100 60,30 100,100" fill="none" stroke="gray" stroke-width="3" '
               'marker-start="url(#a)" marker-mid="url(#a)" marker-end="url(#a)"/>',
    "blur filter": '<defs><filter id="f" x="-50%" y="-50%" width="200%" height="200%">'
                   '<feGaussianBlur stdDeviation="4"/></filter></defs>'
                   '<rect x="30" y="30" width="60" height="60" fill="blue" filter="url(#f)"/>',
    "drop shadow": '<defs><filter id="d" x="-50%" y="-50%" width="200%" height="200%">'
                   '<feGaussianBlur in="SourceAlpha" stdDeviation="3"/><feOffset dx="8" dy="8" result="o"/>'
                   '<feMerge><feMergeNode in="o"/><feMergeNode in="SourceGraphic"/></feMerge></filter></defs>'
                   '<rect x="20" y="20" width="60" height="60" fill="tomato" filter="url(#d)"/>',
    "rgba and hsl colours": '<rect x="10" y="10" width="70" height="70" fill="hsl(120, 100%, 25%)"/>'
                            '<rect x="40" y="40" width="70" height="70" style="fill:rgba(255,0,0,0.5)"/>',
}


@pytest.mark.parametrize("name", list(FEATURES))
def test_feature_drawn_as_resvg_draws_it(qapp, name: str) -> None:  # type: ignore[no-untyped-def]
    text = svg(FEATURES[name])
    share = differing(ours(text), reference(text))
    assert share <= 0.01, f"{name}: {share:.1%} of the drawing differs from resvg"


def test_a_rig_joint_draws_its_gradient_without_its_pivot_marker(qapp) -> None:  # type: ignore[no-untyped-def]
    body = GRAD + ('<g><g id="body"><rect x="10" y="20" width="100" height="40" fill="url(#g)"/>'
                   '<circle cx="60" cy="60" r="3" fill="black"/></g>'
                   '<g id="leg"><rect x="50" y="60" width="20" height="50" fill="url(#g)" stroke="black" '
                   'stroke-width="4" stroke-linejoin="round"/><circle cx="60" cy="62" r="3" fill="white"/></g></g>')
    unmarked = GRAD + ('<rect x="10" y="20" width="100" height="40" fill="url(#g)"/>'
                       '<rect x="50" y="60" width="20" height="50" fill="url(#g)" stroke="black" '
                       'stroke-width="4" stroke-linejoin="round"/>')
    ch = parse_character(svg(body).encode(), "t")
    assert [j.name for j in ch.joints] == ["body", "leg"] and list(ch.dynamic) == [False, True]
    assert differing(ours(svg(body)), reference(svg(unmarked))) <= 0.01


def test_markers_turned_along_the_line_are_reported(qapp) -> None:  # type: ignore[no-untyped-def]
    text = svg(FEATURES["markers"].replace('orient="0"', 'orient="auto"'))
    assert any("orient" in w for w in parse_character(text.encode(), "t").warnings)


def test_text_is_reported(qapp) -> None:  # type: ignore[no-untyped-def]
    ch = parse_character(svg('<rect width="50" height="50"/><text x="10" y="100">hello</text>').encode(), "t")
    assert any("<text>" in w and "paths" in w for w in ch.warnings)


def test_image_is_drawn(qapp) -> None:  # type: ignore[no-untyped-def]
    img = QImage(8, 8, QImage.Format.Format_RGB32)
    img.fill(QColor("#3060c0"))
    from PySide6.QtCore import QBuffer, QByteArray, QIODevice

    data = QByteArray()
    buf = QBuffer(data)
    buf.open(QIODevice.OpenModeFlag.WriteOnly)
    img.save(buf, "PNG")
    uri = "data:image/png;base64," + base64.b64encode(bytes(data.data())).decode()
    text = svg(f'<rect x="0" y="0" width="10" height="10"/><image x="20" y="20" width="80" height="80" '
               f'xlink:href="{uri}"/>')
    assert differing(ours(text), reference(text)) <= 0.01


def test_selection_hover_and_tint_stay_visible(qapp) -> None:  # type: ignore[no-untyped-def]
    text = svg(GRAD + '<rect x="10" y="20" width="100" height="80" fill="url(#g)"/>')
    plain = ours(text)
    lit = ours(text, highlight=0)
    hover = ours(text, hover=0)
    tinted = ours(text, tint=QColor(0, 255, 0, 255))
    inside = (slice(30, 90), slice(20, 100))
    assert np.abs(lit[inside] - plain[inside]).mean() > 60
    assert (hover[inside] >= plain[inside]).all() and (hover[inside] - plain[inside]).mean() > 40
    assert (tinted[inside] == [0, 255, 0]).all()
    assert (lit[5, 5] == 255).all() and (tinted[5, 5] == 255).all()  # outside the drawing: untouched


def test_onion_skin_opacity_multiplies(qapp) -> None:  # type: ignore[no-untyped-def]
    text = svg('<g opacity="0.5"><rect x="10" y="10" width="100" height="100" fill="black"/></g>')
    full, faint = ours(text), ours(text, opacity=0.5)
    assert 120 <= full[60, 60, 0] <= 135 and 185 <= faint[60, 60, 0] <= 200


def test_text_in_the_same_font_on_both_sides_is_drawn_as_resvg_draws_it(qapp) -> None:  # type: ignore[no-untyped-def]
    """Text drawn by QtSvg and by resvg with the same installed font (DejaVu Sans, which
    the CI machine has). At 28 px the glyphs agree within the 1% budget; at 20 px the two
    renderers place glyphs a subpixel apart and about 5% of the ink differs (not asserted)."""
    text = svg('<rect width="10" height="10"/>'
               '<text x="10" y="70" font-family="DejaVu Sans" font-size="28" fill="black">Hello</text>')
    a, b = ours(text), reference(text)
    assert (a < 128).any(axis=2).sum() > 500      # the word is drawn, not dropped
    assert differing(a, b) <= 0.01
