"""Commands the curve editor needs beyond :mod:`qtanimator.document.commands`.

All of them are :class:`SetChannels` (old and new channel objects), so undo is exact and
commands of one gesture merge into one undo step.

* :class:`MoveCurveKeys` moves keys by a time offset and a value offset *per channel*
  (a drag in the normalised view moves each channel by its own amount), or scales their
  times about a pivot. Every key keeps its rules and span shape; when times are scaled,
  fixed slopes are divided by the factor so each handle keeps its shape relative to the
  stretched spans.
* :class:`SetKeySlopes` sets fixed in / out slopes of one key (a handle drag).
* :class:`SetKeysBroken` breaks or unifies tangents.
"""

from __future__ import annotations

from collections.abc import Hashable, Iterable, Mapping, Sequence
from dataclasses import replace

from qtanimator.core.channel import Channel, Key, Tangent
from qtanimator.document.commands import SetChannels
from qtanimator.document.document import Document


def moved_key(key: Key, dt: float, dv: float, time_scale: tuple[float, float] | None = None) -> Key:
    """``key`` moved by ``(dt, dv)`` or with its time scaled about a pivot, handles kept."""
    if time_scale is None:
        return key.moved(key.time + dt, key.value + dv)
    pivot, factor = time_scale
    if factor == 0.0:
        raise ValueError("a time scale factor must not be zero")
    new = key.moved(pivot + (key.time - pivot) * factor, key.value + dv)
    in_slope = key.in_slope / factor if key.in_tangent is Tangent.FIXED else key.in_slope
    out_slope = key.out_slope / factor if key.out_tangent is Tangent.FIXED else key.out_slope
    return replace(new, in_slope=in_slope, out_slope=out_slope)


class MoveCurveKeys(SetChannels):
    """Move (or scale in time) selected keys of several channels, keeping their handles.

    ``base`` holds the channels as they were when the gesture began, so that every merged
    step of a drag is computed from the same start and the last offset wins. ``dv`` is one
    value offset for all channels or a mapping channel id → offset. Raises ValueError if a
    key would land on another key's time.
    """

    def __init__(self, base: Mapping[str, Channel], selection: Mapping[str, Sequence[int]], dt: float,
                 dv: float | Mapping[str, float] = 0.0, gesture: Hashable | None = None,
                 text: str = "Move Keys", time_scale: tuple[float, float] | None = None) -> None:
        changes: dict[str, tuple[Channel | None, Channel | None]] = {}
        for cid, idx in selection.items():
            old = base[cid]
            offset = dv if isinstance(dv, (int, float)) else float(dv.get(cid, 0.0))
            moved = {i: moved_key(old.keys[i], dt, float(offset), time_scale) for i in idx}
            changes[cid] = (old, old.replace_keys(moved))
        super().__init__(text, changes, gesture)


class SetKeySlopes(SetChannels):
    """Set fixed slopes (value per second) on one key's in and / or out side."""

    def __init__(self, doc: Document, cid: str, index: int, in_slope: float | None = None,
                 out_slope: float | None = None, gesture: Hashable | None = None,
                 text: str = "Tangent Handle") -> None:
        old = doc.channels[cid]
        key = old.keys[index]
        if in_slope is not None:
            key = replace(key, in_tangent=Tangent.FIXED, in_slope=float(in_slope))
        if out_slope is not None:
            key = replace(key, out_tangent=Tangent.FIXED, out_slope=float(out_slope))
        super().__init__(text, {cid: (old, old.replace_keys({index: key}))}, gesture)


class SetKeysBroken(SetChannels):
    """Break (``broken=True``) or unify tangents of selected keys.

    Unifying a key whose resolved in and out slopes differ sets both sides to the fixed
    mean slope, so the curve becomes smooth through the key; equal sides keep their rules.
    """

    def __init__(self, doc: Document, selection: Mapping[str, Iterable[int]], broken: bool,
                 text: str | None = None) -> None:
        changes: dict[str, tuple[Channel | None, Channel | None]] = {}
        for cid, idx in selection.items():
            old = doc.channels[cid]
            s_in, s_out = old.slopes()
            edits: dict[int, Key] = {}
            for i in idx:
                k = replace(old.keys[i], broken=broken)
                if not broken and abs(float(s_in[i]) - float(s_out[i])) > 1e-12:
                    mean = 0.5 * (float(s_in[i]) + float(s_out[i]))
                    k = replace(k, in_tangent=Tangent.FIXED, out_tangent=Tangent.FIXED,
                                in_slope=mean, out_slope=mean)
                edits[i] = k
            changes[cid] = (old, old.replace_keys(edits))
        super().__init__(text or ("Break Tangents" if broken else "Unify Tangents"), changes)
