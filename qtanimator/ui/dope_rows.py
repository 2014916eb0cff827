"""The dope sheet's rows and the key frames on them, without Qt.

Rows (:class:`Row`): a summary row per character (asset), a summary row per joint, a row
per channel. :func:`build_rows` lists every row in order; :func:`visible_rows` drops the
rows under collapsed summaries. :class:`KeyFrames` gives each row's key frames (rounded to
:data:`FRAME_DECIMALS` decimals), cached per channel object, and answers which keys a
diamond or a frame range stands for (``{channel id: key indices}``).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.core.channel import Channel
from qtanimator.document.document import split_channel_id

FloatArray = npt.NDArray[np.float64]
Selection = dict[str, set[int]]

FRAME_DECIMALS = 6       # key frames are compared after rounding to this many decimals

# The layout, in pixels: a ruler on top, row names on the left, keys right of them.
ROW_HEIGHT = 20
HEADER_HEIGHT = 24
NAME_WIDTH = 190
INDENT = 14              # per depth, for a row's name (and a summary's arrow)
KEY_PICK = 6.0           # how close a click must be to a diamond


@dataclass(frozen=True)
class Row:
    """One row: a character or joint summary, or a channel."""

    kind: str                 # "asset", "joint" or "channel"
    asset: str
    joint: str
    cids: tuple[str, ...]     # the channels under the row (a channel row: itself)
    depth: int
    label: str

    @property
    def summary(self) -> bool:
        return self.kind != "channel"

    @property
    def path(self) -> tuple[str, str]:
        return self.asset, self.joint


def build_rows(cids: Iterable[str]) -> list[Row]:
    """Every row in order: per asset its summary, its asset-level channels, then per
    joint a summary and the joint's channels."""
    groups: dict[str, dict[str, list[str]]] = {}
    for cid in cids:
        asset, joint, _dof = split_channel_id(cid)
        groups.setdefault(asset, {}).setdefault(joint, [])
        groups[asset][joint].append(cid)
    rows: list[Row] = []
    for asset, joints in groups.items():
        top = joints.get("", [])
        under = [c for j, cs in joints.items() if j for c in cs]
        rows.append(Row("asset", asset, "", tuple(top + under), 0, asset))
        for cid in top:
            rows.append(Row("channel", asset, "", (cid,), 1, split_channel_id(cid)[2]))
        for joint, cs in joints.items():
            if not joint:
                continue
            rows.append(Row("joint", asset, joint, tuple(cs), 1, joint))
            rows.extend(Row("channel", asset, joint, (cid,), 2, split_channel_id(cid)[2]) for cid in cs)
    return rows


def visible_rows(tree: Iterable[Row], is_open: Callable[[tuple[str, str]], bool]) -> list[Row]:
    """The rows of ``tree`` (from :func:`build_rows`) not under a collapsed summary."""
    rows: list[Row] = []
    closed_depth: int | None = None
    for r in tree:
        if closed_depth is not None:
            if r.depth > closed_depth:
                continue
            closed_depth = None
        rows.append(r)
        if r.summary and not is_open(r.path):
            closed_depth = r.depth
    return rows


def frames_of(ch: Channel, fps: float) -> FloatArray:
    """The channel's key frames, rounded to :data:`FRAME_DECIMALS` decimals."""
    return np.round(ch.times * fps, FRAME_DECIMALS)


def nearest_frame(frames: FloatArray, frame: float, px_per_frame: float, pick: float) -> float | None:
    """The frame of sorted ``frames`` nearest ``frame`` within ``pick`` pixels, else None."""
    if not len(frames):
        return None
    i = int(np.searchsorted(frames, frame))
    best = None
    for j in (i - 1, i):
        if 0 <= j < len(frames):
            d = abs(float(frames[j]) - frame) * px_per_frame
            if d <= pick and (best is None or d < best[0]):
                best = (d, float(frames[j]))
    return None if best is None else best[1]


def tick_step(px_per_frame: float, min_px: float = 60.0) -> int:
    """Frames between ruler ticks: 1, 2, 5, 10, 20, 50… at least ``min_px`` pixels apart."""
    base = 1
    while True:
        for m in (1, 2, 5):
            if base * m * px_per_frame >= min_px:
                return base * m
        base *= 10


class KeyFrames:
    """Key frames per channel and per row of a document, cached per channel object.

    ``doc`` is a callable giving the document now (the editor's document may be replaced).
    """

    def __init__(self, doc: Callable[[], Any]) -> None:
        self._doc = doc
        self._frames: dict[str, tuple[Channel, float, FloatArray]] = {}
        self._summary: dict[tuple[str, str], tuple[tuple[Channel | None, ...], float, FloatArray]] = {}
        self._selected: dict[tuple[str, Any], tuple[list[tuple[frozenset[int], Channel | None]], FloatArray]] = {}

    def clear(self) -> None:
        self._frames.clear()
        self._summary.clear()
        self._selected.clear()

    def frames(self, cid: str) -> FloatArray:
        """Key frames of a channel (cached per channel object and fps)."""
        doc = self._doc()
        ch = doc.channels.get(cid)
        if ch is None:
            return np.empty(0)
        fps = float(doc.fps)
        hit = self._frames.get(cid)
        if hit is not None and hit[0] is ch and hit[1] == fps:
            return hit[2]
        frames = frames_of(ch, fps)
        self._frames[cid] = (ch, fps, frames)
        return frames

    def row_frames(self, row: Row) -> FloatArray:
        """Sorted frames with a key in the row (a summary: in any channel under it)."""
        if not row.summary:
            return self.frames(row.cids[0])
        doc = self._doc()
        channels = tuple(doc.channels.get(c) for c in row.cids)
        fps = float(doc.fps)
        hit = self._summary.get(row.path)
        if hit is not None and hit[1] == fps and len(hit[0]) == len(channels) \
                and all(a is b for a, b in zip(hit[0], channels)):
            return hit[2]
        arrays = [self.frames(c) for c in row.cids]
        frames = np.unique(np.concatenate(arrays)) if arrays else np.empty(0)
        self._summary[row.path] = (channels, fps, frames)
        return frames

    def keys_at(self, row: Row, frame: float) -> Selection:
        """The keys (channel id → indices) the diamond at ``frame`` on ``row`` stands for."""
        out: Selection = {}
        for cid in row.cids:
            hits = np.nonzero(self.frames(cid) == frame)[0]
            if len(hits):
                out[cid] = {int(i) for i in hits}
        return out

    def keys_in(self, rows: Iterable[Row], f0: float, f1: float) -> Selection:
        """The keys of ``rows`` on frames ``f0``…``f1`` (both included)."""
        out: Selection = {}
        for row in rows:
            for cid in row.cids:
                fr = self.frames(cid)
                hits = np.nonzero((fr >= f0) & (fr <= f1))[0]
                if len(hits):
                    out.setdefault(cid, set()).update(int(i) for i in hits)
        return out

    def trim_selected(self, max_entries: int) -> None:
        """Forget the cached selected frames when there are more than ``max_entries``."""
        if len(self._selected) > max_entries:
            self._selected.clear()

    def selected_frames(self, row: Row, sel: Mapping[str, frozenset[int]]) -> FloatArray:
        """Frames of the row's selected keys (cached per row while the selected index sets
        and the channels under the row stay the same objects)."""
        channels = self._doc().channels
        token = []
        for cid in row.cids:
            idx = sel.get(cid)
            if idx:
                token.append((idx, channels.get(cid)))
        if not token:
            return np.empty(0)
        key = (row.kind, row.path if row.summary else row.cids[0])
        hit = self._selected.get(key)
        if hit is not None and len(hit[0]) == len(token) and all(
                a[0] is b[0] and a[1] is b[1] for a, b in zip(hit[0], token)):
            return hit[1]
        parts = []
        for cid in row.cids:
            idx = sel.get(cid)
            if idx:
                fr = self.frames(cid)
                at = np.fromiter(idx, dtype=np.intp, count=len(idx))
                parts.append(fr[at[at < len(fr)]])
        frames = parts[0] if len(parts) == 1 else np.unique(np.concatenate(parts))
        self._selected[key] = (token, frames)
        return frames


__all__ = ["FRAME_DECIMALS", "HEADER_HEIGHT", "INDENT", "KEY_PICK", "NAME_WIDTH", "ROW_HEIGHT", "KeyFrames", "Row",
           "Selection", "build_rows", "frames_of", "nearest_frame", "tick_step", "visible_rows"]
