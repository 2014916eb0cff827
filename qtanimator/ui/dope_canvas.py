"""The dope sheet's canvas (:class:`DopeSheetCanvas`): the widget's geometry (frames
across, rows down, zoom, scroll, framing), its rows (collapsed or expanded) and their key
frames, the shared key selection, and keeping up with the document; the base of
:class:`~qtanimator.ui.dope_view.DopeSheetView`, which adds the mouse, the keys and the edits.

The rows and keys are rendered (:mod:`qtanimator.ui.dope_paint`) into a pixmap that is
kept until the content, the view or the selection changes, so moving the playhead
(playback) only draws a line over it.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np
import numpy.typing as npt
from PySide6.QtCore import QPoint, QPointF, QRectF, QSize, Qt
from PySide6.QtGui import QPainter, QPaintEvent, QPixmap, QResizeEvent
from PySide6.QtWidgets import QScrollBar, QSizePolicy, QWidget

from qtanimator.document.document import DocumentChange
from qtanimator.document.gesture import Gesture
from qtanimator.ui import dope_drags as drags
from qtanimator.ui.dope_paint import BACKGROUND, paint_layer, paint_overlay, playhead_rect
from qtanimator.ui.dope_rows import (
    HEADER_HEIGHT,
    KEY_PICK,
    NAME_WIDTH,
    ROW_HEIGHT,
    KeyFrames,
    Row,
    Selection,
    build_rows,
    nearest_frame,
    visible_rows,
)

FloatArray = npt.NDArray[np.float64]

MIN_PX_PER_FRAME = 0.02
MAX_PX_PER_FRAME = 120.0
#: The farthest frame the sheet frames (a project's keys lie within 1e6 s × 10000 fps).
MAX_FRAME = 1e12


class DopeSheetCanvas(QWidget):
    """The painted dope sheet without its interaction (object name ``dopeSheet``)."""

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
        self.key_frames = KeyFrames(lambda: self.ctx.doc)
        self._layer: QPixmap | None = None
        #: How many times the rows were rendered (tests check what invalidates it).
        self.renders = 0
        # The interaction state drawing and document changes look at (the view sets it).
        self._mode = ""                  # "", "press_key", "retime", "box", "scrub", "scale", "pan"
        self._box = QRectF()
        self._gesture: Gesture | None = None
        self._drag: drags.RetimeDrag | drags.ScaleDrag | None = None
        self._own_edit = False           # a change the view pushed itself
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

    def visible_range(self) -> tuple[int, int]:
        """Indices of the first and past the last row on screen."""
        first = max(0, self._scroll // ROW_HEIGHT)
        last = min(len(self.rows), (self._scroll + self.height() - HEADER_HEIGHT) // ROW_HEIGHT + 1)
        return first, last

    _visible_range = visible_range

    def tree_size(self) -> int:
        return len(self._tree)

    # --------------------------------------------------------------- rows
    def reset(self) -> None:
        """The document was replaced: forget caches and interaction, rebuild, frame all."""
        self._gesture = None
        self._drag = None
        self._mode = ""
        self.key_frames.clear()
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
        self.rows = visible_rows(self._tree, self.is_open)
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
        return self.key_frames.frames(cid)

    def row_frames(self, row: Row) -> FloatArray:
        """Sorted frames with a key in the row (a summary: in any channel under it)."""
        return self.key_frames.row_frames(row)

    def keys_at(self, row: Row, frame: float) -> Selection:
        """The keys (channel id → indices) the diamond at ``frame`` on ``row`` stands for."""
        return self.key_frames.keys_at(row, frame)

    def keys_in(self, rows: Iterable[Row], f0: float, f1: float) -> Selection:
        return self.key_frames.keys_in(rows, f0, f1)

    def _selected_frames(self, row: Row, sel: Mapping[str, frozenset[int]]) -> FloatArray:
        return self.key_frames.selected_frames(row, sel)

    def key_at(self, pos: QPointF) -> tuple[Row, float] | None:
        """The row and frame of the diamond under ``pos`` (nearest within KEY_PICK pixels)."""
        if pos.x() < NAME_WIDTH:
            return None
        row = self.row_at(pos.y())
        if row is None:
            return None
        frame = nearest_frame(self.row_frames(row), self.frame_at(pos.x()), self.px_per_frame, KEY_PICK)
        return None if frame is None else (row, frame)

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
        keys = sel.keys
        mapped = drags.remap_selection(keys, {cid: sel.channel(cid) for cid in keys}, self.doc.channels)
        if mapped is not None:
            sel.set(mapped, self.doc.channels, self)

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
        first, last = self.visible_range()
        return any(not wanted.isdisjoint(r.cids) for r in self.rows[first:last])

    # --------------------------------------------------------------- view
    def frame_range(self, lo: float, hi: float) -> None:
        """Show frames ``lo``…``hi`` across the key area (with a small margin). A bound
        that is not finite, or beyond :data:`MAX_FRAME`, gives the document's frame range:
        no NaN reaches the drawing (issue 31)."""
        if not (math.isfinite(lo) and math.isfinite(hi) and abs(lo) <= MAX_FRAME and abs(hi) <= MAX_FRAME):
            lo, hi = (float(v) for v in self.doc.frame_range)
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
    def _frame_changed(self, frame: float) -> None:
        """Only the strips under the old and the new playhead are drawn again."""
        if self._mode in ("scale",):
            self.update()  # the hint names the frame
        else:
            self.update(playhead_rect(self, self._shown_frame))
            self.update(playhead_rect(self, frame))

    def paintEvent(self, event: QPaintEvent) -> None:
        if self._layer is None or self._layer.size() != self.size() * self.devicePixelRatioF():
            self._layer = self.render_layer()
        p = QPainter(self)
        p.setClipRegion(event.region())
        p.drawPixmap(0, 0, self._layer)
        self._shown_frame = self.ctx.frame
        paint_overlay(self, p, self._box if self._mode == "box" else None, self._hint())
        p.end()

    def _hint(self) -> str:
        drag = self._drag
        if self._mode == "scale" and isinstance(drag, drags.ScaleDrag):
            return (f"Scale ×{drag.factor:.2f} about frame {self.ctx.frame:g}: "
                    "click or Enter to confirm, Esc or right click to cancel")
        if self._mode == "retime" and isinstance(drag, drags.RetimeDrag) and drag.frames is not None:
            return f"Retime {drag.frames:+g} frames (Esc cancels)"
        return ""

    def render_layer(self) -> QPixmap:
        """Everything but the playhead and the box, in a pixmap."""
        self.renders += 1
        ratio = self.devicePixelRatioF()
        pm = QPixmap(self.size() * ratio)
        pm.setDevicePixelRatio(ratio)
        pm.fill(BACKGROUND)
        p = QPainter(pm)
        try:
            paint_layer(self, p)
        finally:
            p.end()
        return pm
