"""The dope sheet: every key of every channel as a diamond on a row, against frames.

``install(window)`` adds the dock ``dopeSheetDock`` holding a :class:`DopeSheetPanel` (a
toolbar and the painted view ``dopeSheet``, a :class:`DopeSheetView`).

Rows: a summary row per character (asset), a summary row per joint, a row per channel.
A summary row's diamonds stand for every key below it at that frame; its arrow collapses
or expands it (joints start collapsed). Clicking a row's name selects that character or
joint in the other editors.

Mouse: click a diamond to select its keys (a summary diamond: every key under it), Shift
toggles; drag on empty space box-selects (Shift adds, Ctrl removes); drag a selected key
to retime the selection (snapped to whole frames unless Snap is off); click or drag in the
ruler to set the current frame; wheel scrolls rows, Ctrl+wheel zooms time, Shift+wheel or
middle drag pans. Keys: S scales the selected keys about the current frame (move the
mouse, click or Enter to confirm, Escape or right click to cancel), Delete / X deletes,
Ctrl+C copies, Ctrl+V pastes at the current frame (merge), Ctrl+Shift+V pastes replacing
the pasted range, Ctrl+A selects all, A frames all, F frames the selection, Escape aborts
a drag. A retime or scale is one gesture (``ctx.begin_gesture``): one undo step; a paste
or delete is one command. The edits themselves are :mod:`qtanimator.document.keying`.

The key selection is ``ctx.key_selection``, shared with the curve editor: the view paints
it and sets it (as its source); it follows selection changes from other editors.

Drawing: only the visible rows; each channel's key frames are cached per channel object
(like the timeline's FrameCache), each summary row's per tuple of channel objects; the
rows and keys are rendered into a pixmap that is kept until the content, the view or the
selection changes, so moving the playhead (playback) only draws a line over it.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
from PySide6.QtCore import QEvent, QMimeData, QPoint, QPointF, QRect, QRectF, QSize, Qt, Signal
from PySide6.QtGui import (
    QAction,
    QColor,
    QContextMenuEvent,
    QCursor,
    QFont,
    QGuiApplication,
    QKeyEvent,
    QKeySequence,
    QMouseEvent,
    QPainter,
    QPaintEvent,
    QPen,
    QPixmap,
    QPolygonF,
    QResizeEvent,
    QWheelEvent,
)
from PySide6.QtWidgets import QDockWidget, QLabel, QMenu, QScrollBar, QSizePolicy, QToolBar, QVBoxLayout, QWidget

from qtanimator.core.channel import Channel
from qtanimator.document.document import DocumentChange, split_channel_id
from qtanimator.document.gesture import Gesture
from qtanimator.document.keying import (
    TIME_TOLERANCE,
    KeyClip,
    KeyEdit,
    animatable_channel_ids,
    copy_keys,
    delete_keys_command,
    paste_keys_command,
    retarget,
    retime_keys_command,
    scale_keys_command,
)
from qtanimator.ui.curves.items import SELECTED_FILL, channel_colour, draw_symbols

FloatArray = npt.NDArray[np.float64]
Selection = dict[str, set[int]]

ROW_HEIGHT = 20
HEADER_HEIGHT = 24
NAME_WIDTH = 190
INDENT = 14
KEY_PICK = 6.0           # pixels: how close a click must be to a diamond
DRAG_START = 4           # pixels the mouse moves before a press becomes a drag
MIN_PX_PER_FRAME = 0.02
MAX_PX_PER_FRAME = 120.0
MIN_SCALE = 0.01         # the smallest time scale factor the S gesture gives
SCALE_REFERENCE = 24.0   # pixels: below this distance from the playhead, S scales by mouse travel
FRAME_DECIMALS = 6       # key frames are compared after rounding to this many decimals

BACKGROUND = QColor(38, 40, 44)
NAME_BACKGROUND = QColor(32, 34, 38)
ROW_COLOURS = (QColor(44, 46, 51), QColor(40, 42, 47))
ASSET_ROW = QColor(62, 66, 78)
JOINT_ROW = QColor(50, 53, 61)
CURRENT_ROW = QColor(70, 90, 120)
OUTSIDE_RANGE = QColor(0, 0, 0, 70)
GRID = QColor(56, 59, 66)        # opaque: a 1-pixel alpha fill is a slow path in the raster engine
TEXT = QColor(222, 222, 222)
DIM_TEXT = QColor(160, 160, 165)
RULER = QColor(30, 32, 36)
PLAYHEAD = QColor(80, 170, 255)
BOX_LINE = QColor(255, 255, 255, 200)
BOX_FILL = QColor(255, 255, 255, 30)
KEY_FILL = QColor(205, 205, 210)
SUMMARY_FILL = QColor(150, 160, 180)
DIAMOND_OUTLINE = QColor(10, 10, 10)

#: The clipboard format of copied keys (JSON of :meth:`KeyClip.to_dict`).
KEY_CLIP_MIME = "application/x-qtanimator-keys"
_clip_fallback: list[KeyClip] = []


# ----------------------------------------------------------------- clipboard
def put_key_clip(clip: KeyClip) -> None:
    """Put copied keys on the clipboard (any editor that copies keys calls this)."""
    _clip_fallback[:] = [clip]
    mime = QMimeData()
    mime.setData(KEY_CLIP_MIME, json.dumps(clip.to_dict()).encode())
    clipboard = QGuiApplication.clipboard()
    if clipboard is not None:
        clipboard.setMimeData(mime)


def key_clip() -> KeyClip | None:
    """The keys on the clipboard, or None when it holds something else."""
    clipboard = QGuiApplication.clipboard()
    mime = clipboard.mimeData() if clipboard is not None else None
    if mime is None:
        return _clip_fallback[0] if _clip_fallback else None
    if not mime.hasFormat(KEY_CLIP_MIME):
        return None
    try:
        return KeyClip.from_dict(json.loads(bytes(mime.data(KEY_CLIP_MIME).data()).decode()))
    except (ValueError, KeyError, TypeError):
        return None


# ----------------------------------------------------------------------- rows
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


def _frames_of(ch: Channel, fps: float) -> FloatArray:
    return np.round(ch.times * fps, FRAME_DECIMALS)


# ---------------------------------------------------------------------- symbols
_diamonds: dict[str, QPixmap] = {}


def _diamond(kind: str) -> QPixmap:
    """A pre-rendered diamond: "key", "selected", "summary" or "summary_selected"."""
    hit = _diamonds.get(kind)
    if hit is not None:
        return hit
    summary = kind.startswith("summary")
    size = 13 if summary else 11
    pm = QPixmap(size, size)
    pm.fill(Qt.GlobalColor.transparent)
    q = QPainter(pm)
    q.setRenderHint(QPainter.RenderHint.Antialiasing, True)
    c = size / 2.0
    r = c - 0.8
    q.setPen(QPen(DIAMOND_OUTLINE, 1.2))
    q.setBrush(SELECTED_FILL if kind.endswith("selected") else (SUMMARY_FILL if summary else KEY_FILL))
    q.drawPolygon(QPolygonF([QPointF(c, c - r), QPointF(c + r, c), QPointF(c, c + r), QPointF(c - r, c)]))
    q.end()
    _diamonds[kind] = pm
    return pm


def _tick_step(px_per_frame: float, min_px: float = 60.0) -> int:
    """Frames between ruler ticks: 1, 2, 5, 10, 20, 50… at least ``min_px`` pixels apart."""
    base = 1
    while True:
        for m in (1, 2, 5):
            if base * m * px_per_frame >= min_px:
                return base * m
        base *= 10


# ------------------------------------------------------------------------ view
class DopeSheetView(QWidget):
    """The painted dope sheet (object name ``dopeSheet``)."""

    #: A sentence for the user (copied / pasted / skipped); the panel shows it.
    message = Signal(str)

    def __init__(self, ctx: Any, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("dopeSheet")
        self.ctx = ctx
        self.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        self.setMouseTracking(True)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Expanding)
        self.setMinimumHeight(HEADER_HEIGHT + 2 * ROW_HEIGHT)
        self.snap = True
        self.left_frame = 0.0           # frame at the left edge of the key area
        self.px_per_frame = 4.0
        #: Frame everything again on resize until the user zooms or pans.
        self._auto_frame = True
        self._scroll = 0
        self.scrollbar = QScrollBar(Qt.Orientation.Vertical, self)
        self.scrollbar.setObjectName("dopeSheetScrollBar")
        self.scrollbar.valueChanged.connect(self._scrolled)
        self._tree: list[Row] = []
        self._cids: list[str] = []
        self._open: dict[tuple[str, str], bool] = {}
        self.rows: list[Row] = []
        self._frame_cache: dict[str, tuple[Channel, float, FloatArray]] = {}
        self._summary_cache: dict[tuple[str, str], tuple[tuple[Channel | None, ...], float, FloatArray]] = {}
        self._layer: QPixmap | None = None
        self._selected_cache: dict[tuple[str, Any], tuple[list[tuple[frozenset[int], Channel | None]], FloatArray]] = {}
        #: How many times the rows were rendered (tests check what invalidates it).
        self.renders = 0
        # Interaction state.
        self._mode = ""                  # "", "press_key", "retime", "box", "scrub", "scale", "pan"
        self._pressed = Qt.MouseButton.NoButton
        self._press_pos = QPointF()
        self._last_pos: QPointF | None = None
        self._reselect: Selection | None = None
        self._box_mods = Qt.KeyboardModifier.NoModifier
        self._box = QRectF()
        self._gesture: Gesture | None = None
        self._base: dict[str, Channel] = {}
        self._drag_sel: Selection = {}
        self._drag_value: float | None = None
        self._scale_origin = 0.0
        self._scale_factor = 1.0
        self._pan_start: tuple[QPointF, float, int] | None = None
        self._eat_context_menu = False
        self._own_edit = False
        self._shown_frame = 0.0          # where the playhead was last drawn

        ctx.documentChanged.connect(self._document_changed)
        ctx.documentReset.connect(self.reset)
        ctx.frameChanged.connect(self._frame_changed)
        ctx.selectionChanged.connect(lambda _a, _j: self.invalidate())
        ctx.key_selection.changed.connect(self._key_selection_changed)
        self.reset()

    # ------------------------------------------------------------ geometry
    @property
    def doc(self) -> Any:
        return self.ctx.doc

    @property
    def fps(self) -> float:
        return float(self.ctx.doc.fps)

    def sizeHint(self) -> QSize:
        return QSize(900, 260)

    def key_area(self) -> QRectF:
        right = self.width() - (self.scrollbar.width() if self.scrollbar.isVisible() else 0)
        return QRectF(NAME_WIDTH, HEADER_HEIGHT, max(1.0, right - NAME_WIDTH), max(1, self.height() - HEADER_HEIGHT))

    def x_of(self, frame: float | FloatArray) -> Any:
        return NAME_WIDTH + (frame - self.left_frame) * self.px_per_frame

    def frame_at(self, x: float) -> float:
        return self.left_frame + (x - NAME_WIDTH) / self.px_per_frame

    def row_y(self, index: int) -> int:
        """Top of visible row ``index`` in widget pixels."""
        return HEADER_HEIGHT + index * ROW_HEIGHT - self._scroll

    def row_index_at(self, y: float) -> int | None:
        if y < HEADER_HEIGHT:
            return None
        i = int((y - HEADER_HEIGHT + self._scroll) // ROW_HEIGHT)
        return i if 0 <= i < len(self.rows) else None

    def row_at(self, y: float) -> Row | None:
        i = self.row_index_at(y)
        return None if i is None else self.rows[i]

    def row_index(self, kind: str, asset: str, joint: str = "", dof: str = "") -> int | None:
        """Index of a visible row (tests and scripts find rows with it)."""
        for i, r in enumerate(self.rows):
            if r.kind == kind and r.asset == asset and r.joint == joint and (kind != "channel" or r.label == dof):
                return i
        return None

    def key_pos(self, row_index: int, frame: float) -> QPoint:
        """Widget position of the diamond at ``frame`` on visible row ``row_index``."""
        return QPoint(int(round(self.x_of(frame))), self.row_y(row_index) + ROW_HEIGHT // 2)

    def _visible_range(self) -> tuple[int, int]:
        first = max(0, self._scroll // ROW_HEIGHT)
        last = min(len(self.rows), (self._scroll + self.height() - HEADER_HEIGHT) // ROW_HEIGHT + 1)
        return first, last

    # --------------------------------------------------------------- rows
    def reset(self) -> None:
        """The document was replaced: forget caches and interaction, rebuild, frame all."""
        if self._gesture is not None:
            self._gesture = None
        self._mode = ""
        self._frame_cache.clear()
        self._summary_cache.clear()
        self._selected_cache.clear()
        self._cids = []
        self._rebuild_rows()
        self.frame_all()

    def _rebuild_rows(self) -> None:
        cids = list(self.doc.channels)
        if cids != self._cids:
            self._cids = cids
            self._tree = build_rows(cids)
        self._layout_rows()

    def is_open(self, path: tuple[str, str]) -> bool:
        return self._open.get(path, not path[1])

    def set_open(self, asset: str, joint: str, on: bool) -> None:
        """Expand or collapse a summary row."""
        self._open[(asset, joint)] = on
        self._layout_rows()

    def toggle_row(self, row: Row) -> None:
        if row.summary:
            self.set_open(row.asset, row.joint, not self.is_open(row.path))

    def _layout_rows(self) -> None:
        rows: list[Row] = []
        closed_depth: int | None = None
        for r in self._tree:
            if closed_depth is not None:
                if r.depth > closed_depth:
                    continue
                closed_depth = None
            rows.append(r)
            if r.summary and not self.is_open(r.path):
                closed_depth = r.depth
        self.rows = rows
        self._update_scrollbar()
        self.invalidate()

    def _update_scrollbar(self) -> None:
        content = len(self.rows) * ROW_HEIGHT
        page = max(1, self.height() - HEADER_HEIGHT)
        self.scrollbar.setRange(0, max(0, content - page))
        self.scrollbar.setPageStep(page)
        self.scrollbar.setSingleStep(ROW_HEIGHT)
        self.scrollbar.setVisible(content > page)
        self.scrollbar.setGeometry(self.width() - self.scrollbar.sizeHint().width(), HEADER_HEIGHT,
                                   self.scrollbar.sizeHint().width(), page)
        self._scroll = self.scrollbar.value()

    def _scrolled(self, value: int) -> None:
        self._scroll = value
        self.invalidate()

    def resizeEvent(self, event: QResizeEvent) -> None:
        super().resizeEvent(event)
        self._update_scrollbar()
        if self._auto_frame:
            self.frame_all()
        self.invalidate()

    # --------------------------------------------------------------- keys
    def frames(self, cid: str) -> FloatArray:
        """Key frames of a channel (cached per channel object and fps)."""
        ch = self.doc.channels.get(cid)
        if ch is None:
            return np.empty(0)
        fps = self.fps
        hit = self._frame_cache.get(cid)
        if hit is not None and hit[0] is ch and hit[1] == fps:
            return hit[2]
        frames = _frames_of(ch, fps)
        self._frame_cache[cid] = (ch, fps, frames)
        return frames

    def row_frames(self, row: Row) -> FloatArray:
        """Sorted frames with a key in the row (a summary: in any channel under it)."""
        if not row.summary:
            return self.frames(row.cids[0])
        channels = tuple(self.doc.channels.get(c) for c in row.cids)
        fps = self.fps
        hit = self._summary_cache.get(row.path)
        if hit is not None and hit[1] == fps and len(hit[0]) == len(channels) \
                and all(a is b for a, b in zip(hit[0], channels)):
            return hit[2]
        arrays = [self.frames(c) for c in row.cids]
        frames = np.unique(np.concatenate(arrays)) if arrays else np.empty(0)
        self._summary_cache[row.path] = (channels, fps, frames)
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
        out: Selection = {}
        for row in rows:
            for cid in row.cids:
                fr = self.frames(cid)
                hits = np.nonzero((fr >= f0) & (fr <= f1))[0]
                if len(hits):
                    out.setdefault(cid, set()).update(int(i) for i in hits)
        return out

    def key_at(self, pos: QPointF) -> tuple[Row, float] | None:
        """The row and frame of the diamond under ``pos`` (nearest within KEY_PICK pixels)."""
        if pos.x() < NAME_WIDTH:
            return None
        row = self.row_at(pos.y())
        if row is None:
            return None
        frames = self.row_frames(row)
        if not len(frames):
            return None
        f = self.frame_at(pos.x())
        i = int(np.searchsorted(frames, f))
        best = None
        for j in (i - 1, i):
            if 0 <= j < len(frames):
                d = abs(float(frames[j]) - f) * self.px_per_frame
                if d <= KEY_PICK and (best is None or d < best[0]):
                    best = (d, float(frames[j]))
        return None if best is None else (row, best[1])

    # ----------------------------------------------------------- selection
    def selection(self) -> Selection:
        """The shared key selection that refers to the document's channels now."""
        valid = self.ctx.key_selection.valid(self.doc.channels)
        return {cid: set(idx) for cid, idx in valid.items()}

    def set_selection(self, keys: Mapping[str, Iterable[int]]) -> None:
        self.ctx.key_selection.set({c: i for c, i in keys.items()}, self.doc.channels, self)
        self.invalidate()

    def select_all(self) -> None:
        self.set_selection({cid: range(len(ch.keys)) for cid, ch in self.doc.channels.items() if ch.keys})

    def _key_selection_changed(self, source: object) -> None:
        self.invalidate()

    def _map_stale_selection(self) -> None:
        """Another editor or an undo replaced channels with selected keys: keep the same
        keys selected (by index when the key count is unchanged, else by time)."""
        sel = self.ctx.key_selection
        channels = self.doc.channels
        keys = sel.keys
        if all(sel.channel(cid) is channels.get(cid) for cid in keys):
            return
        mapped: dict[str, set[int]] = {}
        for cid, idx in keys.items():
            old, new = sel.channel(cid), channels.get(cid)
            if new is None or old is None:
                continue
            if new is old or len(new.keys) == len(old.keys):
                mapped[cid] = set(idx)
                continue
            found = {new.key_index(old.keys[i].time, TIME_TOLERANCE) for i in idx}
            mapped[cid] = {j for j in found if j is not None}
        sel.set(mapped, channels, self)

    # ------------------------------------------------------------ document
    def _document_changed(self, change: DocumentChange) -> None:
        structure = bool(change.channels or change.assets) and list(self.doc.channels) != self._cids
        if structure:
            self._rebuild_rows()
        if change.channels and not self._own_edit and self._gesture is None:
            self._map_stale_selection()
        params = {"fps", "frame_start", "frame_end"} & set(change.parameters)
        if structure or params or self._shows(change.channels):
            self.invalidate()

    def _shows(self, cids: Iterable[str]) -> bool:
        """True when a visible row draws one of ``cids``."""
        wanted = set(cids)
        if not wanted:
            return False
        first, last = self._visible_range()
        return any(not wanted.isdisjoint(r.cids) for r in self.rows[first:last])

    # --------------------------------------------------------------- view
    def frame_range(self, lo: float, hi: float) -> None:
        """Show frames ``lo``…``hi`` across the key area (with a small margin)."""
        width = self.key_area().width()
        span = max(hi - lo, 1.0)
        margin = span * 0.04 + 1.0
        self.px_per_frame = float(np.clip(width / (span + 2 * margin), MIN_PX_PER_FRAME, MAX_PX_PER_FRAME))
        self.left_frame = lo - margin
        self._auto_frame = False
        self.invalidate()

    def frame_all(self) -> None:
        """Show the frame range and every key."""
        lo, hi = (float(v) for v in self.doc.frame_range)
        fps = self.fps
        for ch in self.doc.channels.values():
            if ch.keys:
                lo = min(lo, ch.keys[0].time * fps)
                hi = max(hi, ch.keys[-1].time * fps)
        self.frame_range(lo, hi)
        self._auto_frame = True

    def frame_selected(self) -> None:
        sel = self.selection()
        if not sel:
            self.frame_all()
            return
        times = [self.doc.channels[c].keys[i].time for c, idx in sel.items() for i in idx]
        self.frame_range(min(times) * self.fps, max(times) * self.fps)

    def zoom(self, factor: float, about_x: float) -> None:
        f = self.frame_at(about_x)
        self.px_per_frame = float(np.clip(self.px_per_frame * factor, MIN_PX_PER_FRAME, MAX_PX_PER_FRAME))
        self.left_frame = f - (about_x - NAME_WIDTH) / self.px_per_frame
        self._auto_frame = False
        self.invalidate()

    def invalidate(self) -> None:
        """The rows must be drawn again at the next paint."""
        self._layer = None
        self.update()

    # ------------------------------------------------------------ painting
    def _playhead_rect(self, frame: float) -> QRect:
        x = int(self.x_of(frame))
        half = max(24, self.fontMetrics().horizontalAdvance(f"{frame:g}") // 2 + 8)
        return QRect(x - half, 0, 2 * half, self.height())

    def _frame_changed(self, frame: float) -> None:
        """Only the strips under the old and the new playhead are drawn again."""
        if self._mode in ("scale",):
            self.update()  # the hint names the frame
        else:
            self.update(self._playhead_rect(self._shown_frame))
            self.update(self._playhead_rect(frame))

    def paintEvent(self, event: QPaintEvent) -> None:
        if self._layer is None or self._layer.size() != self.size() * self.devicePixelRatioF():
            self._layer = self.render_layer()
        p = QPainter(self)
        p.setClipRegion(event.region())
        p.drawPixmap(0, 0, self._layer)
        self._paint_overlay(p)
        p.end()

    def render_layer(self) -> QPixmap:
        """Everything but the playhead and the box, in a pixmap."""
        self.renders += 1
        ratio = self.devicePixelRatioF()
        pm = QPixmap(self.size() * ratio)
        pm.setDevicePixelRatio(ratio)
        pm.fill(BACKGROUND)
        p = QPainter(pm)
        try:
            self._paint_rows(p)
            self._paint_ruler(p)
        finally:
            p.end()
        return pm

    def _paint_rows(self, p: QPainter) -> None:
        area = self.key_area()
        w = int(area.right())
        x0 = int(area.left())
        first, last = self._visible_range()
        sel = self.ctx.key_selection.valid(self.doc.channels)
        if len(self._selected_cache) > 4 * len(self._tree) + 16:
            self._selected_cache.clear()
        f_lo, f_hi = self.frame_at(area.left() - KEY_PICK), self.frame_at(area.right() + KEY_PICK)
        current = self.ctx.selection
        font = QFont(self.font())
        bold = QFont(font)
        bold.setBold(True)
        step = _tick_step(self.px_per_frame)
        # Frame range shading and grid.
        start, end = self.doc.frame_range
        top = HEADER_HEIGHT
        bottom = self.height()
        for i in range(first, last):
            r = self.rows[i]
            y = self.row_y(i)
            colour = ASSET_ROW if r.kind == "asset" else JOINT_ROW if r.kind == "joint" else ROW_COLOURS[i % 2]
            p.fillRect(QRect(0, y, w, ROW_HEIGHT), colour)
        xs, xe = self.x_of(float(start)), self.x_of(float(end))
        if xs > x0:
            p.fillRect(QRectF(x0, top, xs - x0, bottom - top), OUTSIDE_RANGE)
        if xe < w:
            p.fillRect(QRectF(max(xe, x0), top, w - max(xe, x0), bottom - top), OUTSIDE_RANGE)
        f = math.floor(f_lo / step) * step
        while f <= f_hi:
            x = int(self.x_of(float(f)))
            if x >= x0:
                p.fillRect(QRect(x, top, 1, bottom - top), GRID)  # a fill is much faster than a line
            f += step
        # Keys.
        for i in range(first, last):
            r = self.rows[i]
            centre_y = self.row_y(i) + ROW_HEIGHT / 2.0
            frames = self.row_frames(r)
            a, b = np.searchsorted(frames, [f_lo, f_hi])
            if a >= b:
                continue
            shown = frames[a:b]
            chosen = self._selected_frames(r, sel)
            mask = np.isin(shown, chosen) if len(chosen) else np.zeros(len(shown), dtype=bool)
            px = np.round(self.x_of(shown))
            kind = "summary" if r.summary else "key"
            for pick, symbol in ((~mask, kind), (mask, kind + "_selected")):
                if pick.any():
                    xs_ = np.unique(px[pick])
                    draw_symbols(p, _diamond(symbol), xs_, np.full(len(xs_), centre_y))
        # Names.
        p.fillRect(QRect(0, top, NAME_WIDTH, bottom - top), NAME_BACKGROUND)
        for i in range(first, last):
            r = self.rows[i]
            y = self.row_y(i)
            rect = QRect(0, y, NAME_WIDTH, ROW_HEIGHT)
            if r.summary:
                highlighted = current == (r.asset, r.joint) or (r.kind == "asset" and current == (r.asset, ""))
                p.fillRect(rect, CURRENT_ROW if highlighted else (ASSET_ROW if r.kind == "asset" else JOINT_ROW))
                self._paint_arrow(p, r, y)
            elif i % 2:
                p.fillRect(rect, ROW_COLOURS[1])
            x = 6 + r.depth * INDENT + INDENT
            if not r.summary:
                p.fillRect(QRect(x - 10, y + 6, 6, ROW_HEIGHT - 12), channel_colour(r.cids[0]))
            p.setFont(bold if r.kind == "asset" else font)
            p.setPen(TEXT if r.summary else DIM_TEXT)
            p.drawText(QRect(x, y, NAME_WIDTH - x - 4, ROW_HEIGHT),
                       int(Qt.AlignmentFlag.AlignVCenter | Qt.AlignmentFlag.AlignLeft), r.label)
        p.setPen(QPen(QColor(0, 0, 0), 1))
        p.drawLine(NAME_WIDTH, 0, NAME_WIDTH, bottom)
        if not self.rows:
            p.setPen(DIM_TEXT)
            p.drawText(QRectF(area.left() + 12, top + 8, area.width() - 24, 3 * ROW_HEIGHT),
                       int(Qt.AlignmentFlag.AlignLeft | Qt.AlignmentFlag.AlignTop | Qt.TextFlag.TextWordWrap),
                       "No keys yet. Key a pose in the 2D rig editor (S) or import an animation; "
                       "every channel then shows its keys here.")

    def _paint_arrow(self, p: QPainter, r: Row, y: int) -> None:
        cx = 6 + r.depth * INDENT + 4
        cy = y + ROW_HEIGHT / 2.0
        if self.is_open(r.path):
            tri = [QPointF(cx - 4, cy - 2), QPointF(cx + 4, cy - 2), QPointF(cx, cy + 3)]
        else:
            tri = [QPointF(cx - 2, cy - 4), QPointF(cx + 3, cy), QPointF(cx - 2, cy + 4)]
        p.setPen(Qt.PenStyle.NoPen)
        p.setBrush(TEXT)
        p.drawPolygon(QPolygonF(tri))

    def _selected_frames(self, row: Row, sel: Mapping[str, frozenset[int]]) -> FloatArray:
        """Frames of the row's selected keys (cached per row while the selected index sets
        and the channels under the row stay the same objects)."""
        parts = []
        token = []
        for cid in row.cids:
            idx = sel.get(cid)
            if idx:
                token.append((idx, self.doc.channels.get(cid)))
        if not token:
            return np.empty(0)
        key = (row.kind, row.path if row.summary else row.cids[0])
        hit = self._selected_cache.get(key)
        if hit is not None and len(hit[0]) == len(token) and all(
                a[0] is b[0] and a[1] is b[1] for a, b in zip(hit[0], token)):
            return hit[1]
        for cid in row.cids:
            idx = sel.get(cid)
            if idx:
                fr = self.frames(cid)
                at = np.fromiter(idx, dtype=np.intp, count=len(idx))
                parts.append(fr[at[at < len(fr)]])
        frames = parts[0] if len(parts) == 1 else np.unique(np.concatenate(parts))
        self._selected_cache[key] = (token, frames)
        return frames

    def _paint_ruler(self, p: QPainter) -> None:
        area = self.key_area()
        p.fillRect(QRect(0, 0, self.width(), HEADER_HEIGHT), RULER)
        step = _tick_step(self.px_per_frame)
        f_lo, f_hi = self.frame_at(area.left()), self.frame_at(area.right())
        p.setPen(DIM_TEXT)
        f = math.floor(f_lo / step) * step
        while f <= f_hi:
            x = self.x_of(float(f))
            if x >= area.left():
                p.drawLine(QPointF(x, HEADER_HEIGHT - 6), QPointF(x, HEADER_HEIGHT))
                p.drawText(QPointF(x + 3, HEADER_HEIGHT - 8), str(int(f)))
            f += step
        p.setPen(TEXT)
        p.drawText(QRect(6, 0, NAME_WIDTH - 8, HEADER_HEIGHT),
                   int(Qt.AlignmentFlag.AlignVCenter | Qt.AlignmentFlag.AlignLeft), "Channels")

    def _paint_overlay(self, p: QPainter) -> None:
        area = self.key_area()
        self._shown_frame = self.ctx.frame
        x = self.x_of(self.ctx.frame)
        if area.left() <= x <= area.right():
            p.setPen(QPen(PLAYHEAD, 1.5))
            p.drawLine(QPointF(x, HEADER_HEIGHT), QPointF(x, self.height()))
            label = f"{self.ctx.frame:g}"
            tw = p.fontMetrics().horizontalAdvance(label) + 8
            box = QRectF(x - tw / 2, 2, tw, HEADER_HEIGHT - 4)
            p.fillRect(box, PLAYHEAD)
            p.setPen(QColor(10, 10, 10))
            p.drawText(box, int(Qt.AlignmentFlag.AlignCenter), label)
        if self._mode == "box":
            p.setPen(QPen(BOX_LINE, 1, Qt.PenStyle.DashLine))
            p.setBrush(BOX_FILL)
            p.drawRect(self._box)
        hint = ""
        if self._mode == "scale":
            hint = (f"Scale ×{self._scale_factor:.2f} about frame {self.ctx.frame:g}: "
                    "click or Enter to confirm, Esc or right click to cancel")
        elif self._mode == "retime" and self._drag_value is not None:
            hint = f"Retime {self._drag_value:+g} frames (Esc cancels)"
        if hint:
            p.setPen(TEXT)
            p.fillRect(QRect(NAME_WIDTH + 4, self.height() - ROW_HEIGHT - 4,
                             p.fontMetrics().horizontalAdvance(hint) + 12, ROW_HEIGHT), QColor(0, 0, 0, 170))
            p.drawText(QPointF(NAME_WIDTH + 10, self.height() - 10), hint)

    # --------------------------------------------------------------- mouse
    def mousePressEvent(self, ev: QMouseEvent) -> None:
        pos = ev.position()
        button = ev.button()
        self._pressed |= button
        self._last_pos = pos
        if self._mode == "scale":
            if button == Qt.MouseButton.LeftButton:
                self.finish_scale()
            elif button == Qt.MouseButton.RightButton:
                self._eat_context_menu = True
                self.cancel()
            ev.accept()
            return
        if self._mode == "retime":
            if button == Qt.MouseButton.RightButton:
                self._eat_context_menu = True
                self.cancel()
            ev.accept()
            return
        if button == Qt.MouseButton.MiddleButton:
            self._mode = "pan"
            self._pan_start = (pos, self.left_frame, self._scroll)
            return
        if button != Qt.MouseButton.LeftButton:
            super().mousePressEvent(ev)
            return
        self._press_pos = pos
        mods = ev.modifiers()
        if pos.y() < HEADER_HEIGHT:
            if pos.x() >= NAME_WIDTH:
                self._mode = "scrub"
                self._scrub(pos.x())
            return
        if pos.x() < NAME_WIDTH:
            row = self.row_at(pos.y())
            if row is None:
                return
            if row.summary and pos.x() < 6 + row.depth * INDENT + INDENT:
                self.toggle_row(row)
            else:
                self.ctx.select(row.asset, row.joint)
                self.invalidate()
            return
        hit = self.key_at(pos)
        if hit is None:
            self._mode = "box"
            self._box_mods = mods
            self._box = QRectF(pos, pos)
            return
        keys = self.keys_at(*hit)
        sel = self.selection()
        under_selected = all(i in sel.get(c, set()) for c, idx in keys.items() for i in idx)
        self._reselect = None
        if mods & Qt.KeyboardModifier.ShiftModifier:
            for cid, idx in keys.items():
                if under_selected:
                    sel[cid] = sel.get(cid, set()) - idx
                else:
                    sel.setdefault(cid, set()).update(idx)
            self.set_selection(sel)
        elif not under_selected:
            self.set_selection(keys)
        else:
            self._reselect = keys  # a click (no drag) on a selected key selects only it
        self._mode = "press_key" if not (mods & Qt.KeyboardModifier.ShiftModifier and under_selected) else ""
        ev.accept()

    def mouseMoveEvent(self, ev: QMouseEvent) -> None:
        pos = ev.position()
        self._last_pos = pos
        mode = self._mode
        if mode == "scale":
            self.update_scale(pos.x())
        elif not (ev.buttons() & self._pressed):
            return  # hover (a move's buttons can name a press made on another widget)
        elif mode == "scrub":
            self._scrub(pos.x())
        elif mode == "press_key":
            if (pos - self._press_pos).manhattanLength() >= DRAG_START and self.selection():
                self._begin_retime()
                self._update_retime(pos.x())
        elif mode == "retime":
            self._update_retime(pos.x())
        elif mode == "box":
            self._box = QRectF(self._press_pos, pos).normalized()
            self.update()
        elif mode == "pan" and self._pan_start is not None:
            start, left, scroll = self._pan_start
            self.left_frame = left - (pos.x() - start.x()) / self.px_per_frame
            self._auto_frame = False
            self.scrollbar.setValue(int(scroll - (pos.y() - start.y())))
            self.invalidate()

    def mouseReleaseEvent(self, ev: QMouseEvent) -> None:
        button = ev.button()
        self._pressed &= ~button
        mode = self._mode
        if button == Qt.MouseButton.MiddleButton and mode == "pan":
            self._mode = ""
            return
        if button != Qt.MouseButton.LeftButton:
            return
        if mode == "press_key":
            if self._reselect is not None:
                self.set_selection(self._reselect)
            self._mode = ""
        elif mode == "retime":
            self.finish_retime()
        elif mode == "box":
            self._finish_box(ev.position())
        elif mode == "scrub":
            self._mode = ""
        self._reselect = None

    def contextMenuEvent(self, event: QContextMenuEvent) -> None:
        if self._eat_context_menu or self._mode:
            self._eat_context_menu = False
            event.accept()
            return
        panel = self.parent()
        menu = panel.context_menu() if isinstance(panel, DopeSheetPanel) else None
        if menu is not None:
            menu.popup(event.globalPos())

    def wheelEvent(self, ev: QWheelEvent) -> None:
        delta = ev.angleDelta()
        mods = ev.modifiers()
        steps = (delta.y() or delta.x()) / 120.0
        if mods & Qt.KeyboardModifier.ControlModifier:
            self.zoom(1.25 ** steps, ev.position().x())
        elif mods & Qt.KeyboardModifier.ShiftModifier or (delta.x() and not delta.y()):
            self.left_frame -= steps * 40.0 / self.px_per_frame
            self._auto_frame = False
            self.invalidate()
        else:
            self.scrollbar.setValue(int(self.scrollbar.value() - steps * 3 * ROW_HEIGHT))
        ev.accept()

    def _scrub(self, x: float) -> None:
        start, end = self.doc.frame_range
        self.ctx.set_frame(float(min(max(round(self.frame_at(x)), start), max(end, start))))

    def _finish_box(self, pos: QPointF) -> None:
        self._mode = ""
        rect = QRectF(self._press_pos, pos).normalized()
        mods = self._box_mods
        if rect.width() < DRAG_START and rect.height() < DRAG_START:
            if not mods & (Qt.KeyboardModifier.ShiftModifier | Qt.KeyboardModifier.ControlModifier):
                self.ctx.key_selection.clear(self)
            self.update()
            return
        rows = [r for i, r in enumerate(self.rows)
                if rect.top() <= self.row_y(i) + ROW_HEIGHT / 2.0 <= rect.bottom()]
        hits = self.keys_in(rows, self.frame_at(rect.left()), self.frame_at(rect.right()))
        if mods & Qt.KeyboardModifier.ShiftModifier:
            sel = self.selection()
            for cid, idx in hits.items():
                sel.setdefault(cid, set()).update(idx)
        elif mods & Qt.KeyboardModifier.ControlModifier:
            sel = self.selection()
            for cid, idx in hits.items():
                sel[cid] = sel.get(cid, set()) - idx
        else:
            sel = hits
        self.set_selection(sel)

    # ------------------------------------------------------------- gestures
    def _begin_gesture(self, mode: str, text: str) -> bool:
        sel = self.selection()
        if not sel:
            return False
        self._base = {cid: self.doc.channels[cid] for cid in sel}
        self._drag_sel = sel
        self._drag_value = None
        self._gesture = self.ctx.begin_gesture(text)
        self._mode = mode
        return True

    def _preview(self, edit: KeyEdit) -> None:
        assert self._gesture is not None
        self._gesture.update(edit.command)
        self.set_selection(edit.selection)

    def _begin_retime(self) -> None:
        self._reselect = None
        if not self._begin_gesture("retime", "Retime Keys"):
            self._mode = ""

    def _update_retime(self, x: float) -> None:
        frames = (x - self._press_pos.x()) / self.px_per_frame
        if self.snap:
            frames = float(round(frames))
        if frames == self._drag_value:
            return
        self._drag_value = frames
        fps = self.fps
        self._preview(retime_keys_command(self.doc, self._drag_sel, frames / fps, fps if self.snap else None,
                                          base=self._base))

    def finish_retime(self) -> None:
        self._end_gesture(commit=True)

    def begin_scale(self) -> bool:
        """S: scale the selected keys about the current frame as the mouse moves."""
        if self._mode:
            return False
        pos = self._last_pos
        if pos is None or not self.rect().contains(pos.toPoint()):
            pos = QPointF(self.mapFromGlobal(QCursor.pos()))
        if not self._begin_gesture("scale", "Scale Keys"):
            self.message.emit("Select keys to scale first.")
            return False
        self._scale_origin = pos.x()
        self._scale_factor = 1.0
        self.setFocus()
        self.update()
        return True

    def scale_factor_at(self, x: float) -> float:
        """The factor the S gesture gives with the mouse at ``x``: the distance to the
        playhead now over the distance when S was pressed (by mouse travel when that began
        near the playhead)."""
        pivot = float(self.x_of(self.ctx.frame))
        d0 = self._scale_origin - pivot
        if abs(d0) >= SCALE_REFERENCE:
            factor = (x - pivot) / d0
        else:
            factor = 1.0 + (x - self._scale_origin) / (4 * SCALE_REFERENCE)
        return max(MIN_SCALE, round(factor, 3))

    def update_scale(self, x: float) -> None:
        factor = self.scale_factor_at(x)
        if factor == self._scale_factor and self._gesture is not None and self._gesture.updates:
            return
        self._scale_factor = factor
        fps = self.fps
        self._preview(scale_keys_command(self.doc, self._drag_sel, self.ctx.time, factor,
                                         fps if self.snap else None, base=self._base))
        self.update()

    def finish_scale(self) -> None:
        self._end_gesture(commit=True)

    def cancel(self) -> bool:
        """Escape: abort a retime or scale (the document goes back exactly), or a box."""
        if self._mode in ("retime", "scale"):
            self._end_gesture(commit=False)
            return True
        if self._mode == "box":
            self._mode = ""
            self.update()
            return True
        return False

    def _end_gesture(self, commit: bool) -> None:
        gesture, self._gesture = self._gesture, None
        self._mode = ""
        self._drag_value = None
        if gesture is None:
            return
        if commit:
            gesture.commit()
        else:
            gesture.abort()
            self.set_selection(self._drag_sel)
        self._base = {}
        self.invalidate()

    # ----------------------------------------------------------------- keys
    def _handles_key(self, ev: QKeyEvent) -> bool:
        key = ev.key()
        if key == Qt.Key.Key_Escape:
            return bool(self._mode)
        return self._mode == "scale" and key in (Qt.Key.Key_Return, Qt.Key.Key_Enter)

    def event(self, ev: QEvent) -> bool:
        if ev.type() == QEvent.Type.ShortcutOverride and self._handles_key(ev):  # type: ignore[arg-type]
            ev.accept()
            return True
        return super().event(ev)

    def keyPressEvent(self, ev: QKeyEvent) -> None:
        key = ev.key()
        if key == Qt.Key.Key_Escape and self.cancel():
            ev.accept()
            return
        if self._mode == "scale" and key in (Qt.Key.Key_Return, Qt.Key.Key_Enter):
            self.finish_scale()
            ev.accept()
            return
        super().keyPressEvent(ev)

    def focusOutEvent(self, ev: Any) -> None:
        if self._mode == "scale":
            self.finish_scale()  # like a click elsewhere: keep what the user sees
        super().focusOutEvent(ev)

    # ---------------------------------------------------------------- edits
    def _push(self, edit: KeyEdit) -> bool:
        if edit.is_noop():
            return False
        self._own_edit = True
        try:
            self.ctx.push(edit.command)
        finally:
            self._own_edit = False
        self.set_selection(edit.selection)
        return True

    def delete_selected(self) -> None:
        sel = self.selection()
        if sel and self._mode == "":
            self._push(delete_keys_command(self.doc, sel))

    def copy_selected(self) -> KeyClip | None:
        sel = self.selection()
        if not sel:
            self.message.emit("Select keys to copy first.")
            return None
        clip = copy_keys(self.doc, sel)
        put_key_clip(clip)
        self.message.emit(f"Copied {clip.key_count} key{'s' if clip.key_count != 1 else ''} "
                          f"from {len(clip.channels)} channel{'s' if len(clip.channels) != 1 else ''}.")
        return clip

    def paste(self, mode: str = "merge") -> KeyEdit | None:
        """Paste the clipboard's keys at the current frame (onto the selected character
        when none of the copied channels is in the document)."""
        if self._mode:
            return None
        clip = key_clip()
        if clip is None or not clip:
            self.message.emit("No keys to paste: copy keys first.")
            return None
        doc = self.doc
        target = None
        asset = self.ctx.selection[0]
        if asset in doc.assets and not any(cid in doc.channels for cid in clip.channels):
            target = retarget(clip, asset, animatable_channel_ids(doc, asset))
        edit = paste_keys_command(doc, clip, self.ctx.time, mode, target)
        self._push(edit)
        pasted = sum(len(v) for v in edit.selection.values())
        text = f"Pasted {pasted} key{'s' if pasted != 1 else ''} at frame {self.ctx.frame:g}"
        if edit.skipped:
            text += (f"; skipped {len(edit.skipped)} channel{'s' if len(edit.skipped) != 1 else ''} "
                     "not in this document (select a character to paste onto it)")
        self.message.emit(text + ".")
        return edit


# ----------------------------------------------------------------------- panel
class DopeSheetPanel(QWidget):
    """Toolbar, message line and the view; owns the dope sheet's actions."""

    def __init__(self, ctx: Any, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("dopeSheetPanel")
        self.ctx = ctx
        self.view = DopeSheetView(ctx, self)
        self.status = QLabel(self)
        self.status.setObjectName("dopeSheetMessage")
        self.status.setStyleSheet("color: #aaa; padding-left: 8px;")
        self._build_actions()
        self.toolbar = QToolBar("Dope Sheet", self)
        self.toolbar.setObjectName("dopeSheetToolBar")
        for a in (self.action_frame_all, self.action_snap, None, self.action_scale, self.action_copy,
                  self.action_paste, self.action_paste_replace, self.action_delete):
            if a is None:
                self.toolbar.addSeparator()
            else:
                self.toolbar.addAction(a)
        self.toolbar.addWidget(self.status)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.setSpacing(0)
        layout.addWidget(self.toolbar)
        layout.addWidget(self.view, 1)
        self.view.message.connect(self.status.setText)
        ctx.key_selection.changed.connect(lambda _s: self._update_enabled())
        ctx.documentChanged.connect(lambda _c: self._update_enabled())
        self._update_enabled()

    def _action(self, name: str, text: str, slot: Any, keys: list[str] | None = None, tip: str = "",
                checkable: bool = False) -> QAction:
        action = QAction(text, self)
        action.setObjectName(name)
        action.setToolTip(tip or text)
        if keys:
            action.setShortcuts([QKeySequence(k) for k in keys])
            action.setShortcutContext(Qt.ShortcutContext.WidgetWithChildrenShortcut)
            action.setToolTip(f"{tip or text} ({', '.join(keys)})")
        action.setCheckable(checkable)
        if checkable:
            action.toggled.connect(slot)
        else:
            action.triggered.connect(lambda _c=False: slot())
        self.addAction(action)
        return action

    def _build_actions(self) -> None:
        v = self.view
        self.action_copy = self._action("actionDopeSheetCopyKeys", "Copy Keys", v.copy_selected, ["Ctrl+C"])
        self.action_paste = self._action("actionDopeSheetPasteKeys", "Paste (Merge)", lambda: v.paste("merge"),
                                         ["Ctrl+V"], "Paste keys at the current frame, replacing keys on "
                                         "the same frames")
        self.action_paste_replace = self._action(
            "actionDopeSheetPasteKeysReplace", "Paste (Replace)", lambda: v.paste("replace"), ["Ctrl+Shift+V"],
            "Paste keys at the current frame, clearing the pasted range first")
        self.action_delete = self._action("actionDopeSheetDeleteKeys", "Delete Keys", v.delete_selected,
                                          ["Delete", "X", "Backspace"])
        self.action_scale = self._action("actionDopeSheetScaleKeys", "Scale", self._scale, ["S"],
                                         "Scale the selected keys about the current frame: move the mouse, "
                                         "click to confirm")
        self.action_select_all = self._action("actionDopeSheetSelectAll", "Select All Keys", v.select_all,
                                              ["Ctrl+A"])
        self.action_frame_all = self._action("actionDopeSheetFrameAll", "Frame All", v.frame_all, ["A"])
        self.action_frame_selected = self._action("actionDopeSheetFrameSelected", "Frame Selected",
                                                  v.frame_selected, ["F"])
        self.action_snap = self._action("actionDopeSheetSnap", "Snap", self._set_snap, None,
                                        "Snap retimed and scaled keys to whole frames", checkable=True)
        self.action_snap.setChecked(True)

    def _scale(self) -> None:
        if self.view.begin_scale():
            self.view.update_scale(self.view._scale_origin)

    def _set_snap(self, on: bool) -> None:
        self.view.snap = on

    def _update_enabled(self) -> None:
        has = bool(self.ctx.key_selection)
        for a in (self.action_copy, self.action_delete, self.action_scale):
            a.setEnabled(has)

    def context_menu(self) -> QMenu:
        menu = QMenu(self)
        menu.setObjectName("dopeSheetMenu")
        for a in (self.action_copy, self.action_paste, self.action_paste_replace, None, self.action_delete,
                  self.action_scale, None, self.action_select_all, self.action_frame_all,
                  self.action_frame_selected):
            if a is None:
                menu.addSeparator()
            else:
                menu.addAction(a)
        return menu


def install(window: Any) -> DopeSheetPanel:
    panel = DopeSheetPanel(window.ctx, window)
    window.dope_sheet = panel
    dock: QDockWidget = window.add_dock("dopeSheetDock", "Dope Sheet", panel, Qt.DockWidgetArea.BottomDockWidgetArea)
    # Beside the curve editor as a tab (both show keys), else above the timeline.
    curve = window.findChild(QDockWidget, "curveEditorDock")
    timeline = window.findChild(QDockWidget, "timelineDock")
    if curve is not None:
        window.tabifyDockWidget(curve, dock)
        curve.raise_()
    elif timeline is not None:
        window.splitDockWidget(timeline, dock, Qt.Orientation.Vertical)
        window.splitDockWidget(dock, timeline, Qt.Orientation.Vertical)
    panel.view.message.connect(lambda text: window.statusBar().showMessage(text, 5000))
    from qtanimator.ui.timeline import add_timeline_keys

    add_timeline_keys(window, panel.view)  # ←/→, Home/End… while the dope sheet has focus
    return panel


__all__ = ["DopeSheetPanel", "DopeSheetView", "KEY_CLIP_MIME", "Row", "build_rows", "install", "key_clip",
           "put_key_clip"]
