"""Channel (core/channel.py): linear spans, and the column form's interp / broken entries."""

from __future__ import annotations

import numpy as np
import pytest

from qtanimator.core.channel import Channel, Interpolation, Key


def _keys(interps, broken=(False, False, False)):
    return [Key(float(i), float(i * i), "smooth", "smooth", interpolation=m, broken=b)
            for i, (m, b) in enumerate(zip(interps, broken))]


def test_linear_spans_flag_the_spans_that_start_at_a_linear_key():
    ch = Channel(_keys(["linear", "cubic", "constant"]) + [Key(3.0, 1.0, interpolation="linear")])
    np.testing.assert_array_equal(ch.linear_spans, [True, False, False])
    assert ch.linear_spans.dtype == bool
    # the last key's interpolation starts no span
    assert Channel(_keys(["cubic", "cubic", "linear"])).linear_spans.tolist() == [False, False]


def test_columns_leave_interp_out_when_every_span_is_cubic():
    d = Channel(_keys(["cubic"] * 3)).to_dict(columns=True)
    assert "interp" not in d


@pytest.mark.parametrize("interps, expected", [
    (["linear"] * 3, "linear"),
    (["constant"] * 3, "constant"),
    (["linear", "cubic", "constant"], ["linear", "cubic", "constant"]),
])
def test_columns_write_interp_otherwise(interps, expected):
    ch = Channel(_keys(interps))
    d = ch.to_dict(columns=True)
    assert d["interp"] == expected
    back = Channel.from_dict(d)
    assert [k.interpolation for k in back.keys] == [Interpolation(m) for m in interps]


def test_columns_leave_broken_out_when_no_key_is_broken():
    assert "broken" not in Channel(_keys(["cubic"] * 3)).to_dict(columns=True)


@pytest.mark.parametrize("broken, expected", [
    ((True, True, True), True),
    ((False, True, False), [False, True, False]),
])
def test_columns_write_broken_when_some_key_is(broken, expected):
    ch = Channel(_keys(["cubic"] * 3, broken))
    d = ch.to_dict(columns=True)
    assert d["broken"] == expected
    assert [k.broken for k in Channel.from_dict(d).keys] == list(broken)
