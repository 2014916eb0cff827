"""What the mouse and the edit keys do to keys in the dope sheet, without Qt.

Selections are ``{channel id: key indices}`` into the document's channels; positions are
frames (or plain pixel numbers where the rule is about the screen: the S gesture's factor).

* :func:`press_key` / :func:`box_select`: the selection a click on a diamond or a box makes.
* :class:`RetimeDrag` / :class:`ScaleDrag`: made at the start of a drag from the document as
  it is then (the channels they edit are kept as ``base``); ``move(…)`` returns the
  :class:`~qtanimator.document.keying.KeyEdit` for one mouse position, built from ``base``,
  or None when that position changes nothing. The caller feeds each edit's command to the
  gesture protocol (:class:`qtanimator.document.gesture.Gesture`: ``update`` previews it,
  ``commit`` on release makes the drag one undo step, ``abort`` on Escape takes it back
  exactly) and selects ``edit.selection``::

      g = Gesture(doc, "Retime Keys", stack.record)
      drag = RetimeDrag(doc, {"hero/arm/angle": {1}}, snap=True)
      g.update(drag.move(2.4).command)    # two frames later
      g.commit()

* :func:`paste_edit`, :func:`copy_message`, :func:`paste_message`: the clipboard maths
  (where a paste goes) and what the user is told.
* :func:`remap_selection`: keep the same keys selected after another editor replaced the
  channels.

The Qt view (:mod:`qtanimator.ui.dope_view`) only picks what is under the mouse, turns
pixels into frames and feeds the gesture.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

from qtanimator.core.channel import Channel
from qtanimator.document.document import Document
from qtanimator.document.keying import (
    TIME_TOLERANCE,
    KeyClip,
    KeyEdit,
    animatable_channel_ids,
    paste_keys_command,
    retarget,
    retime_keys_command,
    scale_keys_command,
)

Selection = dict[str, set[int]]

MIN_SCALE = 0.01         # the smallest time scale factor the S gesture gives
SCALE_REFERENCE = 24.0   # pixels: below this distance from the playhead, S scales by mouse travel


def _copy(selection: Mapping[str, Iterable[int]]) -> Selection:
    return {cid: set(idx) for cid, idx in selection.items()}


# ------------------------------------------------------------------ selection
class KeyPress:
    """What a left press on a diamond does.

    ``selection``: the selection to make now (None: unchanged). ``reselect``: the selection
    to make on release when the press did not become a drag (a click on a selected key
    selects only its keys). ``drag``: the press may become a retime.
    """

    __slots__ = ("drag", "reselect", "selection")

    def __init__(self, selection: Selection | None, reselect: Selection | None, drag: bool) -> None:
        self.selection = selection
        self.reselect = reselect
        self.drag = drag


def press_key(selection: Mapping[str, Iterable[int]], keys: Mapping[str, Iterable[int]],
              toggle: bool) -> KeyPress:
    """A press on the diamond standing for ``keys``; ``toggle``: Shift is held (the keys
    are added, or removed when all of them are selected already)."""
    sel = _copy(selection)
    hit = _copy(keys)
    under_selected = all(i in sel.get(c, set()) for c, idx in hit.items() for i in idx)
    if toggle:
        for cid, idx in hit.items():
            if under_selected:
                sel[cid] = sel.get(cid, set()) - idx
            else:
                sel.setdefault(cid, set()).update(idx)
        return KeyPress(sel, None, not under_selected)
    if not under_selected:
        return KeyPress(hit, None, True)
    return KeyPress(None, hit, True)


def box_select(selection: Mapping[str, Iterable[int]], hits: Mapping[str, Iterable[int]],
               add: bool = False, remove: bool = False) -> Selection:
    """The selection after a box over ``hits``: the hits alone, or added to (``add``:
    Shift) or taken from (``remove``: Ctrl) ``selection``."""
    if add:
        sel = _copy(selection)
        for cid, idx in hits.items():
            sel.setdefault(cid, set()).update(idx)
        return sel
    if remove:
        sel = _copy(selection)
        for cid, idx in hits.items():
            sel[cid] = sel.get(cid, set()) - set(idx)
        return sel
    return _copy(hits)


def remap_selection(keys: Mapping[str, Iterable[int]], old: Mapping[str, Channel | None],
                    channels: Mapping[str, Channel]) -> Selection | None:
    """The keys ``keys`` selected in the channels ``old`` (per channel id), found in
    ``channels`` (by index when the key count is unchanged, else by time); None when every
    channel is still the same object (nothing to do)."""
    if all(old.get(cid) is channels.get(cid) for cid in keys):
        return None
    mapped: Selection = {}
    for cid, idx in keys.items():
        before, now = old.get(cid), channels.get(cid)
        if now is None or before is None:
            continue
        if now is before or len(now.keys) == len(before.keys):
            mapped[cid] = set(idx)
            continue
        found = {now.key_index(before.keys[i].time, TIME_TOLERANCE) for i in idx}
        mapped[cid] = {j for j in found if j is not None}
    return mapped


# ---------------------------------------------------------------------- drags
class KeyDrag:
    """A drag of the selected keys, built from the channels as they were at its start."""

    #: The gesture's name (its undo step).
    text = "Edit Keys"

    def __init__(self, doc: Document, selection: Mapping[str, Iterable[int]], snap: bool = True) -> None:
        self.doc = doc
        self.selection = _copy(selection)
        self.base: dict[str, Channel] = {cid: doc.channels[cid] for cid in self.selection}
        self.snap = snap

    @property
    def snap_fps(self) -> float | None:
        return float(self.doc.fps) if self.snap else None


class RetimeDrag(KeyDrag):
    """Drag selected keys along time (whole frames of offset when ``snap``)."""

    text = "Retime Keys"

    def __init__(self, doc: Document, selection: Mapping[str, Iterable[int]], snap: bool = True) -> None:
        super().__init__(doc, selection, snap)
        #: The offset (frames) of the last move; None before the first.
        self.frames: float | None = None

    def move(self, offset_frames: float) -> KeyEdit | None:
        """The edit moving the keys ``offset_frames`` from where they were (rounded when
        snapping); None when that is the offset of the last move."""
        frames = float(round(offset_frames)) if self.snap else float(offset_frames)
        if frames == self.frames:
            return None
        self.frames = frames
        fps = float(self.doc.fps)
        return retime_keys_command(self.doc, self.selection, frames / fps, self.snap_fps, base=self.base)


def scale_factor(x: float, pivot_x: float, origin_x: float) -> float:
    """The S gesture's factor with the mouse at ``x`` (pixels): the distance to the
    playhead (``pivot_x``) now over the distance when S was pressed (``origin_x``), or by
    mouse travel when that began within :data:`SCALE_REFERENCE` pixels of the playhead;
    rounded to 3 decimals, at least :data:`MIN_SCALE`."""
    d0 = origin_x - pivot_x
    if abs(d0) >= SCALE_REFERENCE:
        factor = (x - pivot_x) / d0
    else:
        factor = 1.0 + (x - origin_x) / (4 * SCALE_REFERENCE)
    return max(MIN_SCALE, round(factor, 3))


class ScaleDrag(KeyDrag):
    """Scale selected keys in time about a pivot (each key snapped to a whole frame when
    ``snap``)."""

    text = "Scale Keys"

    def __init__(self, doc: Document, selection: Mapping[str, Iterable[int]], snap: bool = True) -> None:
        super().__init__(doc, selection, snap)
        self.factor = 1.0
        self.moves = 0

    def move(self, factor: float, pivot_time: float) -> KeyEdit | None:
        """The edit scaling the keys by ``factor`` about ``pivot_time`` (seconds); None
        when the factor is the last move's."""
        if factor == self.factor and self.moves:
            return None
        self.factor = factor
        self.moves += 1
        return scale_keys_command(self.doc, self.selection, pivot_time, factor, self.snap_fps, base=self.base)


# ------------------------------------------------------------------ clipboard
def paste_edit(doc: Document, clip: KeyClip, at_time: float, mode: str = "merge",
               selected_asset: str = "") -> KeyEdit:
    """Paste ``clip`` at ``at_time``: onto the same channels, or onto ``selected_asset``
    when none of the copied channels is in the document."""
    target = None
    if selected_asset in doc.assets and not any(cid in doc.channels for cid in clip.channels):
        target = retarget(clip, selected_asset, animatable_channel_ids(doc, selected_asset))
    return paste_keys_command(doc, clip, at_time, mode, target)


def _plural(n: int, word: str) -> str:
    return f"{n} {word}{'s' if n != 1 else ''}"


def copy_message(clip: KeyClip) -> str:
    return f"Copied {_plural(clip.key_count, 'key')} from {_plural(len(clip.channels), 'channel')}."


def paste_message(edit: KeyEdit, frame: float) -> str:
    pasted = sum(len(v) for v in edit.selection.values())
    text = f"Pasted {_plural(pasted, 'key')} at frame {frame:g}"
    if edit.skipped:
        text += (f"; skipped {_plural(len(edit.skipped), 'channel')} "
                 "not in this document (select a character to paste onto it)")
    return text + "."


__all__ = ["MIN_SCALE", "SCALE_REFERENCE", "KeyDrag", "KeyPress", "RetimeDrag", "ScaleDrag", "Selection",
           "box_select", "copy_message", "paste_edit", "paste_message", "press_key", "remap_selection",
           "scale_factor"]
