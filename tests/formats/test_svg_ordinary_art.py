"""Ordinary art opens (issue 23): a drawing that does not follow the rig rules opens as one
joint drawing the whole drawing, with a message on how to rig it; layers and top-level
groups are offered as joints; empty layers are skipped; pivots only where the rules mark
them."""

from __future__ import annotations

import numpy as np
import pytest

from qtanimator.formats.errors import FormatError
from qtanimator.formats.svg_rig import parse_character

INK = 'xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"'


def doc(body: str) -> bytes:
    return f'<svg xmlns="http://www.w3.org/2000/svg" {INK} viewBox="0 0 100 100">{body}</svg>'.encode()


def test_first_element_a_path_opens_as_one_joint_with_advice() -> None:
    ch = parse_character(doc('<path d="M10 10H50V50H10Z" fill="red"/><circle cx="70" cy="70" r="20"/>'), "art")
    assert len(ch.joints) == 1 and not ch.dynamic.any()
    j = ch.joints[0]
    # the whole drawing: the circle is drawn, not taken as a pivot
    assert len(j.shapes) == 2 and "<circle" in (j.svg or "") and "<path" in (j.svg or "")
    np.testing.assert_allclose(j.pivot, [50.0, 50.0])
    np.testing.assert_allclose(j.mass, 1600 + np.pi * 400, rtol=1e-2)
    assert "not rigged" in ch.warnings[0] and "<circle>" in ch.warnings[0]


def test_empty_first_layer_and_several_layers() -> None:
    ch = parse_character(doc(
        '<g inkscape:groupmode="layer" inkscape:label="Empty"/>'
        '<g inkscape:groupmode="layer" inkscape:label="Body"><rect width="30" height="30"/>'
        '<rect x="40" width="10" height="10" fill="blue"/></g>'
        '<g inkscape:groupmode="layer" inkscape:label="Hat"><rect y="60" width="20" height="20"/></g>'), "art")
    assert len(ch.joints) == 1
    assert ch.joint_candidates == ["Body", "Hat"]
    assert "Body, Hat" in ch.warnings[0]
    assert len(ch.joints[0].shapes) == 3  # nothing dropped: both layers, every shape drawn


def test_groups_holding_groups_draw_everything() -> None:
    ch = parse_character(doc('<g id="a"><g><rect width="10" height="10"/></g><g><rect x="20" width="10" '
                             'height="10"/></g></g>'), "art")
    assert len(ch.joints) == 1 and len(ch.joints[0].shapes) == 2


def test_a_rig_after_an_empty_layer_is_still_a_rig() -> None:
    ch = parse_character(doc(
        '<g inkscape:groupmode="layer"/>'
        '<g><g id="body"><rect width="40" height="40"/><circle cx="20" cy="40" r="2"/></g>'
        '<g id="arm"><rect x="40" width="30" height="10"/><circle cx="40" cy="5" r="2" fill="#fff"/></g></g>'), "r")
    assert [j.name for j in ch.joints] == ["body", "arm"] and list(ch.dynamic) == [False, True]
    assert "<circle" not in (ch.joints[0].svg or "") and "<rect" in (ch.joints[0].svg or "")
    assert (ch.joints[0].svg or "").count("<rect") == 1  # the child joint is not in the parent's drawing


def test_nothing_to_draw_is_still_refused() -> None:
    with pytest.raises(FormatError, match="draws nothing.*empty group"):
        parse_character(doc('<g inkscape:groupmode="layer"/><g/>'), "empty")
