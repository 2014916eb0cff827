"""The curve plot's canvas: the channels drawn against time in frames, and the view range.

:class:`CurveCanvas` owns the plot widget (:mod:`~.plot`), the cached, live and hover
layers (:mod:`~.items`), the playhead and the box of a box select; it keeps each visible
channel's drawing in step with the document (only what changed is built again), maps
values to what is shown (degrees for rotations, the −1…1 normalisation; a drag freezes
the transform of the channels it edits) and frames keys. The selection, picking and
gestures are added by :mod:`~.picking`, :mod:`~.selection` and :mod:`~.view`.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from typing import Any, cast

import pyqtgraph as pg
from PySide6.QtCore import QObject, Signal
from PySide6.QtGui import QColor, QPen, QTransform
from PySide6.QtWidgets import QGraphicsItem, QGraphicsRectItem

from qtanimator.ui.curves.drags import ActiveDrag, handle_extents
from qtanimator.ui.curves.items import ChannelDrawing, CurveLayer, HoverLayer, HoverMark, channel_colour
from qtanimator.ui.curves.normalisation import NormalisationCache, unit_scale
from qtanimator.ui.curves.plot import CurvePlot, CurveViewBox, FrameLine, PlotOwner

#: The largest frame or displayed value the view frames (a project's keys lie far inside:
#: 1e6 s × 10000 fps, 1e9 × 57.3 for degrees; see docs/formats.md).
MAX_VIEW_COORDINATE = 1e12


class CurveCanvas(QObject):
    """Plot widget, layers and drawings of the curve view (see :class:`~.view.CurveView`)."""

    #: The key selection changed.
    keySelectionChanged = Signal()
    #: Right click at a screen position (QPointF): the editor shows its menu.
    context_menu_requested = Signal(object)
    #: Display-only normalisation was switched on or off.
    normalisedChanged = Signal(bool)

    def __init__(self, ctx: Any, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self.ctx = ctx
        self.norm = NormalisationCache()
        self.visible: list[str] = []
        self.highlighted: set[str] = set()
        #: Selected key indices per channel, and the active key (the key fields show it).
        self.selection: dict[str, set[int]] = {}
        self.active: tuple[str, int] | None = None
        self.normalised = False
        #: Display transforms frozen while a drag edits their channels.
        self._frozen_norm: dict[str, tuple[float, float]] = {}
        #: The drag in progress (its channels are drawn live).
        self._drag: ActiveDrag | None = None
        self._drawings: dict[str, ChannelDrawing] = {}
        self._live: set[str] = set()
        self._syncing_frame = False
        #: What the mouse is over: ("key", cid, index), ("handle", cid, index, side) or None.
        self.hover: tuple[Any, ...] | None = None
        self._units: dict[str, float] = {}

        owner = cast(PlotOwner, self)  # the CurveView subclass handles the plot's events
        self.widget = CurvePlot(owner)
        self.plot_item = self.widget.getPlotItem()
        self.vb: CurveViewBox = self.plot_item.getViewBox()
        self.vb.disableAutoRange()
        self.plot_item.showGrid(x=True, y=True, alpha=0.15)
        self.plot_item.setLabel("bottom", "frame")
        self.plot_item.hideButtons()
        self.plot_item.setMenuEnabled(False)
        # The axes draw the grid across the whole view; keep their pixels between range
        # changes instead of replaying their drawing for every redraw during a drag.
        for name in ("left", "bottom"):
            self.plot_item.getAxis(name).setCacheMode(QGraphicsItem.CacheMode.DeviceCoordinateCache)

        # Channels not being edited are drawn by a cached layer; the ones with selected
        # keys or under a drag by a live layer on top of it (see CurveLayer). The key or
        # handle under the mouse is drawn by a third item, so hovering repaints neither.
        self.static_layer = CurveLayer(lambda: self._layer_drawings(False), cached=True)
        self.live_layer = CurveLayer(lambda: self._layer_drawings(True), cached=False)
        self.hover_layer = HoverLayer(self.hover_mark)
        self.static_layer.setZValue(5)
        self.live_layer.setZValue(10)
        self.hover_layer.setZValue(15)
        self.vb.addItem(self.static_layer, ignoreBounds=True)
        self.vb.addItem(self.live_layer, ignoreBounds=True)
        self.vb.addItem(self.hover_layer, ignoreBounds=True)
        self.frame_line = FrameLine(owner, pos=ctx.frame, angle=90, movable=True,
                                    pen=pg.mkPen(QColor(80, 160, 255), width=2),
                                    hoverPen=pg.mkPen(QColor(140, 200, 255), width=3))
        self.frame_line.setZValue(20)
        self.vb.addItem(self.frame_line, ignoreBounds=True)
        self.frame_line.sigPositionChanged.connect(self._frame_line_moved)
        self.box = QGraphicsRectItem()
        self.box.setPen(QPen(QColor(255, 255, 255, 180), 0))
        self.box.setBrush(QColor(255, 255, 255, 30))
        self.box.setZValue(30)
        self.box.hide()
        self.vb.addItem(self.box, ignoreBounds=True)

        ctx.frameChanged.connect(self._frame_changed)
        self.vb.sigRangeChanged.connect(lambda *_: self.refresh_all())
        self.vb.sigResized.connect(lambda *_: self.refresh_all())
        start, end = ctx.doc.frame_range
        self.vb.setRange(xRange=(start, end), yRange=(-1, 1), padding=0.02)

    # ------------------------------------------------------------ document
    @property
    def doc(self) -> Any:
        return self.ctx.doc

    @property
    def fps(self) -> float:
        return float(self.doc.fps)

    def set_highlighted(self, cids: Iterable[str]) -> None:
        self.highlighted = set(cids)
        self.static_layer.update()
        self.live_layer.update()

    def drawing(self, cid: str) -> ChannelDrawing | None:
        """What is drawn for a visible channel (paths in view coordinates, keys)."""
        return self._drawings.get(cid)

    def set_normalised(self, on: bool) -> None:
        if on != self.normalised:
            self.normalised = on
            self.refresh_all()
            self.frame_all()
            self.normalisedChanged.emit(on)

    def display_transform(self, cid: str) -> tuple[float, float]:
        """``(offset, scale)``: display value = (value − offset) · scale."""
        frozen = self._frozen_norm.get(cid)
        if frozen is not None:
            return frozen
        if not self.normalised:
            return 0.0, self.unit(cid)
        return self.norm.get(cid, self.doc.channels[cid])

    def unit(self, cid: str) -> float:
        """Displayed value per document value (180/π for rotations: degrees)."""
        u = self._units.get(cid)
        if u is None:
            u = self._units[cid] = unit_scale(cid)
        return u

    def refresh_channel(self, cid: str, update: bool = True) -> None:
        """Show the document's current version of one channel; only its layer is redrawn,
        and only its paths are built again (when its channel object changed)."""
        ch = self.doc.channels.get(cid)
        if ch is None or cid not in self.visible:
            self._drawings.pop(cid, None)
            return
        d = self._drawings.get(cid)
        if d is None:
            self._drawings[cid] = ChannelDrawing(cid, ch, self.fps)
        elif not d.set_channel(ch, self.fps):
            return
        if update:
            (self.live_layer if cid in self._live else self.static_layer).update()

    def clear_drawings(self) -> None:
        """Forget every built path (they are built again at the next paint, as after a reset)."""
        self._drawings.clear()
        self.refresh_all()

    def refresh_all(self) -> None:
        """Redraw everything (the view moved, the visible set or the display changed).

        Paths are in view coordinates, so a pan or zoom rebuilds only what depends on the
        zoom level (per-column curves of dense channels, extrapolation past its range).
        """
        for cid in self.visible:
            self.refresh_channel(cid, update=False)
        self._live = self._live_channels()
        self.static_layer.update()
        self.live_layer.update()
        self.hover_layer.update()

    def _live_channels(self) -> set[str]:
        live = {cid for cid, idx in self.selection.items() if idx}
        if self._drag is not None:
            live |= set(self._drag.base)
        return live & set(self.visible)

    def _update_live(self) -> None:
        """Move channels between the cached and the live layer when the selection changes."""
        live = self._live_channels()
        if live != self._live:
            self._live = live
            self.static_layer.update()
        self.live_layer.update()

    # ------------------------------------------------------------- layers
    def _layer_drawings(self, live: bool) -> list[ChannelDrawing]:
        """Drawings of the live or the cached layer, highlighted channels last (on top)."""
        out = []
        for cid in sorted(self.visible, key=lambda c: c in self.highlighted):
            if (cid in self._live) != live:
                continue
            if live:
                # A gesture's change reaches the views once per frame; the live layer
                # paints what the document holds now (the dragged key under the mouse).
                self.refresh_channel(cid, update=False)
            d = self._drawings.get(cid)
            if d is None:
                continue
            d.highlighted = cid in self.highlighted
            d.display = self.display_transform(cid)
            d.selected = sorted(i for i in self.selection.get(cid, ()) if i < len(d.channel.keys))
            out.append(d)
        return out

    def hover_mark(self) -> HoverMark | None:
        """The key or handle under the mouse as the hover layer draws it (or None)."""
        h = self.hover
        if h is None or h[0] == "playhead":
            return None
        cid, i = h[1], h[2]
        ch = self.doc.channels.get(cid)
        if ch is None or i >= len(ch.keys) or cid not in self.visible:
            return None
        off, scale = self.display_transform(cid)
        key = ch.keys[i]
        x, y = key.time * self.fps, (key.value - off) * scale
        if h[0] == "key":
            return HoverMark("key", x, y, channel_colour(cid), selected=i in self.selection.get(cid, ()))
        s_in, s_out = ch.slopes()
        slope = float((s_out if h[3] == "out" else s_in)[i]) * scale / self.fps
        ext = handle_extents(ch)
        extent = math.nan if ext is None else float(ext[1 if h[3] == "out" else 0][i]) * self.fps
        return HoverMark("handle", x, y, channel_colour(cid), True, slope, h[3], extent)

    def view_to_scene(self) -> QTransform:
        self.vb.updateMatrix()  # pyqtgraph defers it to the next paint after a range change
        return self.vb.childGroup.sceneTransform()

    # ------------------------------------------------------------- framing
    def selected_keys(self) -> dict[str, list[int]]:
        return {cid: sorted(idx) for cid, idx in self.selection.items() if idx}

    def frame_all(self) -> None:
        self._frame_bounds(self._bounds({cid: None for cid in self.visible}))

    def frame_selected(self) -> None:
        sel = self.selected_keys()
        if sel:
            self._frame_bounds(self._bounds(sel))
        elif self.highlighted & set(self.visible):
            self._frame_bounds(self._bounds({c: None for c in self.visible if c in self.highlighted}))
        else:
            self.frame_all()

    def _bounds(self, which: Mapping[str, list[int] | None]) -> tuple[float, float, float, float] | None:
        xs: list[float] = []
        ys: list[float] = []
        fps = self.fps
        for cid, idx in which.items():
            ch = self.doc.channels.get(cid)
            if ch is None or not ch.keys:
                continue
            off, scale = self.display_transform(cid)
            times, values = ch.times, ch.values
            if idx is None:
                xs += [float(times[0] * fps), float(times[-1] * fps)]
                noff, nscale = self.norm.get(cid, ch)
                lo, hi = noff - 1.0 / nscale, noff + 1.0 / nscale
                ys += [(lo - off) * scale, (hi - off) * scale]
            else:
                xs += [float(times[i] * fps) for i in idx]
                ys += [float((values[i] - off) * scale) for i in idx]
        xs = [x for x in xs if math.isfinite(x)]
        ys = [y for y in ys if math.isfinite(y)]
        if not xs or not ys:
            return None
        return min(xs), max(xs), min(ys), max(ys)

    def _frame_bounds(self, b: tuple[float, float, float, float] | None) -> None:
        """Show ``b`` = (x0, x1, y0, y1), or the frame range when it is None. pyqtgraph
        raises for a non-finite range and draws NaN geometry that can crash its paint
        (issue 31), so a bound that is not finite or too far out gives the default."""
        start, end = self.doc.frame_range
        default = (float(start), float(end), -1.0, 1.0)
        if b is None or not all(math.isfinite(v) and abs(v) <= MAX_VIEW_COORDINATE for v in b):
            b = default
        x0, x1, y0, y1 = b
        if x1 - x0 < 1e-9:
            x0, x1 = x0 - 10.0, x1 + 10.0
        if y1 - y0 < 1e-9:
            pad = max(0.5, abs(y0) * 0.1)
            y0, y1 = y0 - pad, y1 + pad
        self.vb.setRange(xRange=(x0, x1), yRange=(y0, y1), padding=0.08)

    # ---------------------------------------------------------- frame line
    def _frame_changed(self, frame: float) -> None:
        self._syncing_frame = True
        try:
            self.frame_line.setValue(frame)
        finally:
            self._syncing_frame = False

    def _frame_line_moved(self) -> None:
        if self._syncing_frame:
            return
        frame = float(round(self.frame_line.value()))
        if frame != self.frame_line.value():
            self.frame_line.setValue(frame)
            return
        self.ctx.set_frame(frame)
