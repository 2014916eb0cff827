"""What the mouse does to keys in the curve editor, without Qt: the drag state machines.

A drag is a small object made at mouse press from the document as it is then (the channels
it edits are kept as ``base``); ``move(cursor)`` returns the command for one cursor
position, built from ``base`` (a :class:`~qtanimator.document.commands.MoveKeys`, a
:class:`~qtanimator.document.curve_commands.SetKeySlopes`, …), or None when that position
changes nothing (the keys have not left their place yet, or a key would land on another
key's time: the last valid position stays). The caller feeds each command to the gesture
protocol (:class:`qtanimator.document.gesture.Gesture`: ``update`` previews it, ``commit``
on release makes the drag one undo step, ``abort`` on Escape takes it back exactly)::

    g = Gesture(doc, "Move Keys", stack.record)
    drag = MoveKeysDrag(doc, {"hero/arm/angle": [1]}, ("hero/arm/angle", 1), Cursor(12, 0.5))
    g.update(drag.move(Cursor(14, 0.75)))
    g.commit()

Coordinates are the plot's: ``frame`` (time · fps) across and the value *as shown* up,
shown = (value − offset) · scale with each channel's display transform ``(offset, scale)``
(:data:`IDENTITY` unless given: the editor passes degrees for rotations, or its −1…1
normalisation, frozen at the press). The Qt view (:mod:`qtanimator.ui.curves.view`) only
picks what is under the press, turns events into :class:`Cursor` points and feeds the
gesture.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, replace

import numpy as np
import numpy.typing as npt

from qtanimator.core.channel import Channel
from qtanimator.document.commands import Command, MoveKeys, SetChannels
from qtanimator.document.curve_commands import SetKeySlopes
from qtanimator.document.document import Document
from qtanimator.document.gesture import Gesture

FloatArray = npt.NDArray[np.float64]
#: A channel's display transform: shown value = (value − offset) · scale.
Transform = tuple[float, float]
IDENTITY: Transform = (0.0, 1.0)
#: Key indices per channel id.
Selection = dict[str, set[int]]
#: (time, value) before and after a drag, per moved key.
MovedPairs = list[tuple[tuple[float, float], tuple[float, float]]]
#: Axis locks of a key drag: free, along time only, along values only.
AXIS_LOCKS = ("none", "time", "value")


@dataclass(frozen=True)
class Cursor:
    """One mouse position in plot coordinates, with what the drag needs of the event.

    ``shift``: Shift is held during this move (a key drag locks to the main axis).
    ``pixel``: the position on screen; the main axis is the one the mouse moved most along
    on screen (in plot units when either end has no pixel position).
    """

    frame: float
    value: float
    shift: bool = False
    pixel: tuple[float, float] | None = None


# --------------------------------------------------------------------- helpers
def handle_extents(channel: Channel) -> tuple[FloatArray, FloatArray] | None:
    """Per key, the time extents (seconds) of the in and out handles drawn at their real
    length — the sides of weighted spans, as evaluation uses them — and NaN for handles
    drawn at the fixed length; None when the channel has no weighted span."""
    if not channel.is_weighted:
        return None
    weighted, h_out, h_in = channel.span_handles()
    n = len(channel.keys)
    ins = np.full(n, np.nan)
    outs = np.full(n, np.nan)
    outs[:-1] = np.where(weighted, h_out, np.nan)
    ins[1:] = np.where(weighted, h_in, np.nan)
    return ins, outs


def press_selection(selection: Mapping[str, Iterable[int]], hit: tuple[str, int],
                    additive: bool) -> Selection | None:
    """The selection a press on key ``hit`` makes before dragging: None (unchanged) when the
    key is selected already, else the key (added to ``selection`` when ``additive``)."""
    cid, i = hit
    if i in set(selection.get(cid, ())):
        return None
    sel = {c: set(s) for c, s in selection.items()} if additive else {}
    sel.setdefault(cid, set()).add(i)
    return sel


def click_selection(selection: Mapping[str, Iterable[int]], hit: tuple[str, int], toggle: bool) -> Selection:
    """The selection after a click on key ``hit``: the key alone, or (``toggle``: Shift)
    the selection with the key toggled."""
    cid, i = hit
    if not toggle:
        return {cid: {i}}
    sel = {c: set(s) for c, s in selection.items()}
    sel.setdefault(cid, set()).symmetric_difference_update({i})
    return sel


def box_selection(doc: Document, corner_a: tuple[float, float], corner_b: tuple[float, float],
                  channels: Iterable[str], display: Mapping[str, Transform] | None = None,
                  selection: Mapping[str, Iterable[int]] | None = None) -> Selection:
    """The keys of ``channels`` inside the box between two plot points (edges included),
    added to ``selection`` when given (Shift box select)."""
    x0, x1 = sorted((float(corner_a[0]), float(corner_b[0])))
    y0, y1 = sorted((float(corner_a[1]), float(corner_b[1])))
    sel = {c: set(s) for c, s in (selection or {}).items()}
    fps = float(doc.fps)
    for cid in channels:
        ch = doc.channels.get(cid)
        if ch is None or not ch.keys:
            continue
        off, scale = (display or {}).get(cid, IDENTITY)
        x = ch.times * fps
        y = (ch.values - off) * scale
        inside = (x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)
        hits = set(np.nonzero(inside)[0].tolist())
        if hits:
            sel.setdefault(cid, set()).update(hits)
    return sel


# ----------------------------------------------------------------------- drags
class KeysDrag:
    """What the key drags share: the selected keys and their channels at the press, the key
    under the press (``anchor``) and where the keys went (:meth:`remap`)."""

    text = "Move Keys"

    def __init__(self, doc: Document, selection: Mapping[str, Iterable[int]], anchor: tuple[str, int],
                 press: Cursor, display: Mapping[str, Transform] | None = None, snap: bool = True) -> None:
        self.doc = doc
        self.selection: dict[str, list[int]] = {c: sorted(idx) for c, idx in selection.items() if idx}
        self.base: dict[str, Channel] = {c: doc.channels[c] for c in self.selection}
        self.anchor = anchor
        self.press = press
        self.display: dict[str, Transform] = {c: (display or {}).get(c, IDENTITY) for c in self.selection}
        self.snap = snap
        self.fps = float(doc.fps)
        #: Commands returned so far (each one is previewed by the caller's gesture).
        self.moves = 0
        #: The time (seconds) a key at time ``t`` before the drag has after the last command.
        self.new_time: Callable[[float], float] = lambda t: t
        #: (time, value) before and after the last command of each moved key (:meth:`remap`).
        self.moved: dict[str, MovedPairs] = {}

    @property
    def anchor_frame(self) -> float:
        cid, i = self.anchor
        return self.base[cid].keys[i].time * self.fps

    def _made(self, command: Command, new_time: Callable[[float], float]) -> Command:
        self.moves += 1
        self.new_time = new_time
        return command

    def remap(self, channels: Mapping[str, Channel]) -> tuple[Selection, tuple[str, int] | None]:
        """The dragged keys in ``channels`` (the document after the last command): keys may
        pass others while moving, so their indices change. Returns the selection and the
        anchor's new place, and keeps each key's (time, value) pairs in :attr:`moved`."""
        new_sel: Selection = {}
        active = None
        self.moved = {}
        for cid, idx in self.selection.items():
            ch = channels[cid]
            times = ch.times
            found = set()
            pairs: MovedPairs = []
            for i in idx:
                t = self.new_time(self.base[cid].keys[i].time)
                j = int(np.argmin(np.abs(times - t)))
                found.add(j)
                a, b = self.base[cid].keys[i], ch.keys[j]
                pairs.append(((a.time, a.value), (b.time, b.value)))
                if self.anchor == (cid, i):
                    active = (cid, j)
            new_sel[cid] = found
            self.moved[cid] = pairs
        return new_sel, active


class MoveKeysDrag(KeysDrag):
    """Drag on a key: the selected keys follow the cursor by (Δframe, Δshown value) — each
    channel by Δshown / its display scale. ``snap``: the key under the press lands on
    whole frames. ``axis_lock`` (``"time"`` / ``"value"``) keeps the other axis; Shift
    held during a move locks to the axis the mouse moved most along."""

    def __init__(self, doc: Document, selection: Mapping[str, Iterable[int]], anchor: tuple[str, int],
                 press: Cursor, display: Mapping[str, Transform] | None = None, snap: bool = True,
                 axis_lock: str = "none") -> None:
        super().__init__(doc, selection, anchor, press, display, snap)
        if axis_lock not in AXIS_LOCKS:
            raise ValueError(f"axis_lock must be one of {AXIS_LOCKS}")
        self.axis_lock = axis_lock

    def lock_for(self, cursor: Cursor) -> str:
        """The axis lock of this move (Shift: the main axis of the motion so far)."""
        if not cursor.shift:
            return self.axis_lock
        if cursor.pixel is not None and self.press.pixel is not None:
            ax = cursor.pixel[0] - self.press.pixel[0]
            ay = cursor.pixel[1] - self.press.pixel[1]
        else:
            ax, ay = cursor.frame - self.press.frame, cursor.value - self.press.value
        return "time" if abs(ax) >= abs(ay) else "value"

    def move(self, cursor: Cursor) -> Command | None:
        dx = cursor.frame - self.press.frame
        dy = cursor.value - self.press.value
        lock = self.lock_for(cursor)
        if lock == "time":
            dy = 0.0
        elif lock == "value":
            dx = 0.0
        if self.snap:
            anchor_frame = self.anchor_frame
            dx = round(anchor_frame + dx) - anchor_frame
        dt = dx / self.fps
        dv = {cid: dy / self.display[cid][1] for cid in self.selection}
        if not self.moves and dt == 0.0 and dy == 0.0:
            return None
        try:
            command = MoveKeys(self.base, self.selection, dt, dv)
        except ValueError:
            return None  # a key would land on another key's time: keep the last valid position
        return self._made(command, lambda t: t + dt)


class ScaleKeysDrag(KeysDrag):
    """Ctrl+drag on a key: scale the selected keys' times about the frame ``pivot`` (the
    current frame), by how far the key under the press moves from it (whole frames with
    ``snap``); a key on the pivot, or a factor ≤ 0, changes nothing."""

    text = "Scale Keys"

    def __init__(self, doc: Document, selection: Mapping[str, Iterable[int]], anchor: tuple[str, int],
                 press: Cursor, pivot: float, display: Mapping[str, Transform] | None = None,
                 snap: bool = True) -> None:
        super().__init__(doc, selection, anchor, press, display, snap)
        self.pivot = float(pivot)

    def move(self, cursor: Cursor, pivot: float | None = None) -> Command | None:
        """``pivot``: the frame to scale about now (default: the one given at the press)."""
        pivot = self.pivot if pivot is None else float(pivot)
        anchor_frame = self.anchor_frame
        target = anchor_frame + cursor.frame - self.press.frame
        if self.snap:
            target = round(target)
        if abs(anchor_frame - pivot) < 1e-9:
            return None
        factor = (target - pivot) / (anchor_frame - pivot)
        if factor <= 0.0 or (factor == 1.0 and not self.moves):
            return None
        p = pivot / self.fps
        try:
            command = MoveKeys(self.base, self.selection, 0.0, 0.0, text="Scale Keys", time_scale=(p, factor))
        except ValueError:
            return None
        return self._made(command, lambda t: p + (t - p) * factor)


class HandleDrag:
    """Drag on a tangent handle: the key's slope on that side becomes the slope of the line
    from the key to the cursor (both sides unless the key's tangents are broken), a fixed
    slope. An out handle stays right of its key and an in handle left of it. On a weighted
    key whose handle is drawn at its real length, the drag sets that length too (this side's
    weight = |Δframe| / fps)."""

    text = "Tangent Handle"

    def __init__(self, doc: Document, cid: str, index: int, side: str,
                 display: Transform = IDENTITY) -> None:
        if side not in ("in", "out"):
            raise ValueError("side must be 'in' or 'out'")
        self.doc = doc
        self.cid = cid
        self.index = index
        self.side = side
        self.display = display
        self.fps = float(doc.fps)
        self.base: dict[str, Channel] = {cid: doc.channels[cid]}
        self.moves = 0

    @property
    def anchor(self) -> tuple[str, int]:
        return self.cid, self.index

    def slope(self, cursor: Cursor, span: float = 1.0) -> tuple[float, float]:
        """(slope in value per second, Δframe from the key) for ``cursor``; ``span`` is the
        width of the plot in frames (the least Δframe is 10⁻⁶ of it)."""
        key = self.base[self.cid].keys[self.index]
        off, scale = self.display
        dx = cursor.frame - key.time * self.fps
        dy = cursor.value - (key.value - off) * scale
        min_dx = 1e-6 * max(1.0, abs(span))
        dx = max(dx, min_dx) if self.side == "out" else min(dx, -min_dx)
        return (dy / dx) * self.fps / scale, dx

    def move(self, cursor: Cursor, span: float = 1.0) -> Command:
        base = self.base[self.cid]
        i, side = self.index, self.side
        key = base.keys[i]
        slope, dx = self.slope(cursor, span)
        if key.broken:
            ins, outs = (slope, None) if side == "in" else (None, slope)
        else:
            ins, outs = slope, slope
        weight = key.in_weight if side == "in" else key.out_weight
        ext = handle_extents(base)
        real = ext is not None and math.isfinite(float(ext[0 if side == "in" else 1][i]))
        command: Command
        if weight is not None and real:
            # A weighted key's handle: the drag sets its slope and its length (this side only).
            edited = SetKeySlopes(self.doc, self.cid, i, ins, outs, base=base).changes[self.cid][1]
            assert edited is not None
            length = abs(dx) / self.fps
            new_key = replace(edited.keys[i], in_weight=length) if side == "in" \
                else replace(edited.keys[i], out_weight=length)
            command = SetChannels(self.text, {self.cid: (base, base.replace_keys({i: new_key}))})
        else:
            command = SetKeySlopes(self.doc, self.cid, i, ins, outs, base=base)
        self.moves += 1
        return command


class BoxSelect:
    """Drag on empty space: a box from the press to the cursor selects the keys inside it
    at the release (added to the selection when ``additive``: Shift at the press)."""

    def __init__(self, press: Cursor, additive: bool = False) -> None:
        self.press = press
        self.additive = additive
        self.base: dict[str, Channel] = {}  # edits no channel

    def rect(self, cursor: Cursor) -> tuple[float, float, float, float]:
        """The box as (left, bottom, width, height) in plot coordinates."""
        x0, x1 = sorted((self.press.frame, cursor.frame))
        y0, y1 = sorted((self.press.value, cursor.value))
        return x0, y0, x1 - x0, y1 - y0

    def finish(self, doc: Document, cursor: Cursor, channels: Iterable[str],
               display: Mapping[str, Transform] | None = None,
               selection: Mapping[str, Iterable[int]] | None = None) -> Selection:
        """The selection at the release among the keys of ``channels`` (``selection`` is
        the one an additive box adds to)."""
        return box_selection(doc, (self.press.frame, self.press.value), (cursor.frame, cursor.value), channels,
                             display, selection if self.additive else None)


#: Any of the curve editor's drags.
CurveDrag = MoveKeysDrag | ScaleKeysDrag | HandleDrag | BoxSelect


@dataclass
class ActiveDrag:
    """The drag in progress in a view: its state machine, the gesture that previews its
    commands (None for a box select) and, after Escape, ``aborted`` (the rest of the mouse
    drag does nothing)."""

    drag: CurveDrag | None
    gesture: Gesture | None = None
    aborted: bool = False

    @property
    def base(self) -> Mapping[str, Channel]:
        """The channels the drag edits, as they were at the press."""
        return {} if self.drag is None else self.drag.base
