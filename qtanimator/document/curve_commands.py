"""Commands the curve editor needs beyond :mod:`qtanimator.document.commands`.

All of them are :class:`SetChannels` (old and new channel objects), so undo is exact and
commands of one gesture merge into one undo step.

Key moves (a time offset, a value offset per channel, or times scaled about a pivot) are
:class:`~qtanimator.document.commands.MoveKeys`.

* :class:`SetKeySlopes` sets fixed in / out slopes of one key (a handle drag).
* :class:`SetKeysBroken` breaks or unifies tangents.
"""

from __future__ import annotations

from collections.abc import Hashable, Iterable, Mapping
from dataclasses import replace

from qtanimator.core.channel import Channel, Key, Tangent
from qtanimator.document.commands import SetChannels
from qtanimator.document.document import Document


class SetKeySlopes(SetChannels):
    """Set fixed slopes (value per second) on one key's in and / or out side.

    ``base`` is the channel to edit (default: the document's); a handle drag passes the
    channel as it was when the drag began, so that every mouse move's command is built
    from the same state.
    """

    def __init__(self, doc: Document, cid: str, index: int, in_slope: float | None = None,
                 out_slope: float | None = None, gesture: Hashable | None = None,
                 text: str = "Tangent Handle", base: Channel | None = None) -> None:
        old = doc.channels[cid] if base is None else base
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
