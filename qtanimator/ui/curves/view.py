"""The curve plot: channels against time in frames, keys, handles and their interaction.

:class:`CurveView` owns the pyqtgraph plot (objectName ``curvePlot``), the per-channel
channel drawings, the key selection and the gestures. A click edit is one command pushed
with ``ctx.push``. A drag (keys, a tangent handle, Ctrl+drag time scaling) is a gesture
(``ctx.begin_gesture``): each mouse move previews a command built from the channels as
they were when the drag began, the release commits them as one undo step (nothing when
the keys end where they started), and Escape aborts it, putting the document back exactly.

Mouse: left click selects a key (Shift adds / toggles), left drag on a key moves the
selected keys (hold Shift once moving to lock to the main axis), Ctrl+drag on a key
scales the selected keys in time about the current frame, drag on a handle sets a fixed
slope (and, on a weighted key, the handle's length), on empty space box-selects;
Ctrl+click inserts a key on the curve under the cursor; right click selects the key or
curve under the cursor (a key already selected keeps the selection) and opens the menu;
middle drag or Alt+left drag pans; right drag zooms each axis; the wheel zooms (Ctrl:
time only, Shift: values only). The playhead moves by its handle (the triangle at the top)
or by a click or drag on the time axis; a key on the playhead drags like any other.
Keys: A frame all, F frame selected, N normalise, Delete removes selected keys, Ctrl+A
selects all keys, Escape aborts a drag.

Units: rotations (``angle``, ``rx``, ``ry``, ``rz``; radians in the document) are shown in
degrees, other channels in their own units (see :mod:`~.normalisation`); the display
transform of a channel carries the unit, so picking, drags and handles all work in what
is shown.

The key selection is shared with the other editors through ``ctx.key_selection``: the
view publishes its selection (source: the view) and takes the selection another editor
sets, for the channels it shows.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import QEvent, QObject, QPointF, QRectF, Qt, Signal
from PySide6.QtGui import QColor, QKeyEvent, QMouseEvent, QPen, QTransform
from PySide6.QtWidgets import QGraphicsItem, QGraphicsRectItem, QWidget

from qtanimator.core.channel import Channel, Key
from qtanimator.document.commands import Command, DeleteKeys, InsertKey, MoveKeys, SetChannels
from qtanimator.document.curve_commands import SetKeySlopes
from qtanimator.document.document import DocumentChange, split_channel_id
from qtanimator.document.gesture import Gesture
from qtanimator.ui.curves.items import (
    HANDLE_SIZE,
    MAX_HANDLES,
    ChannelDrawing,
    CurveLayer,
    HoverLayer,
    HoverMark,
    channel_colour,
    handle_extents,
    handle_offsets,
    map_points,
)
from qtanimator.ui.curves.normalisation import NormalisationCache, unit_scale

PLAYHEAD_HANDLE = 14.0  # pixels: the playhead's handle at the top of the plot
PICK_RADIUS = 7.0       # pixels: how close a click must be to a key or handle
CURVE_PICK_RADIUS = 8.0  # pixels: how close to a curve Ctrl+click must be
MOVE_HISTORY = 4096      # (before, after) pairs of dragged keys remembered per channel
BACKGROUND = QColor(38, 40, 44)


@dataclass
class _Drag:
    kind: str                       # "keys", "scale", "handle", "box" or "aborted"
    gesture: Gesture | None = None
    base: dict[str, Channel] = field(default_factory=dict)
    selection: dict[str, list[int]] = field(default_factory=dict)
    anchor: tuple[str, int] | None = None
    side: str = ""
    start_scene: QPointF = field(default_factory=QPointF)
    additive: bool = False
    moved: dict[str, list[tuple[tuple[float, float], tuple[float, float]]]] = field(default_factory=dict)


class FrameLine(pg.InfiniteLine):
    """The current-frame line (the playhead). Only its handle, the triangle at the top of
    the plot, drags it (and the time axis scrubs): a key or a handle on the line takes
    the mouse like any other, and clicks on the line go to what is under it."""

    def __init__(self, view: CurveView, **kw: Any) -> None:
        super().__init__(**kw)
        self._view = view
        self.addMarker("v", position=1.0, size=PLAYHEAD_HANDLE)

    def handle_scene_pos(self) -> QPointF:
        """Scene position of the middle of the handle."""
        vb = self._view.vb
        x = vb.mapViewToScene(QPointF(self.value(), 0.0)).x()
        return QPointF(x, vb.sceneBoundingRect().top() + PLAYHEAD_HANDLE / 4.0)

    def at_handle(self, scene: QPointF) -> bool:
        """True when ``scene`` is on the handle (a little larger than drawn)."""
        top = self._view.vb.sceneBoundingRect().top()
        x = self._view.vb.mapViewToScene(QPointF(self.value(), 0.0)).x()
        reach = PLAYHEAD_HANDLE / 2.0 + 3.0
        return abs(scene.x() - x) <= reach and top - 3.0 <= scene.y() <= top + PLAYHEAD_HANDLE / 2.0 + 4.0

    def hoverEvent(self, ev: Any) -> None:
        if not ev.isExit() and self.movable and self.at_handle(ev.scenePos()) \
                and ev.acceptDrags(Qt.MouseButton.LeftButton):
            self.setMouseHover(True)
        else:
            self.setMouseHover(False)

    def mouseDragEvent(self, ev: Any) -> None:
        if ev.isStart() and not self.at_handle(ev.buttonDownScenePos()):
            ev.ignore()
            return
        super().mouseDragEvent(ev)

    def mouseClickEvent(self, ev: Any) -> None:
        ev.ignore()  # a click on the line is a click on the plot (select, deselect, menu)


class CurveViewBox(pg.ViewBox):
    """A ViewBox whose left-button gestures edit keys; the rest zooms and pans."""

    def __init__(self, view: CurveView) -> None:
        super().__init__(enableMenu=False)
        self._view = view

    def mouseClickEvent(self, ev: Any) -> None:
        if not self.sceneBoundingRect().contains(ev.scenePos()):
            # A click forwarded by an axis: on the time axis it sets the current frame.
            if ev.button() == Qt.MouseButton.LeftButton and ev.scenePos().y() > self.sceneBoundingRect().bottom():
                ev.accept()
                self._view.ctx.set_frame(float(round(self.mapSceneToView(ev.scenePos()).x())))
            return
        if ev.button() == Qt.MouseButton.LeftButton:
            ev.accept()
            self._view.click(ev.scenePos(), ev.modifiers())
        elif ev.button() == Qt.MouseButton.RightButton:
            ev.accept()
            self._view.select_under(ev.scenePos())  # the menu acts on what was clicked
            self._view.context_menu_requested.emit(ev.screenPos())
        else:
            super().mouseClickEvent(ev)

    def mouseDragEvent(self, ev: Any, axis: int | None = None) -> None:
        if axis is None and self._view.drag_event(ev):
            return
        if axis == 0 and ev.button() == Qt.MouseButton.LeftButton:
            # A left drag forwarded by the time axis scrubs (middle / right drags still pan / zoom it).
            ev.accept()
            self._view.scrub(ev.scenePos(), finish=ev.isFinish())
            return
        super().mouseDragEvent(ev, axis)

    def wheelEvent(self, ev: Any, axis: int | None = None) -> None:
        if axis is None:
            mods = ev.modifiers()
            if mods & Qt.KeyboardModifier.ControlModifier:
                axis = 0
            elif mods & Qt.KeyboardModifier.ShiftModifier:
                axis = 1
        super().wheelEvent(ev, axis)


class CurvePlot(pg.PlotWidget):
    """The plot widget (objectName ``curvePlot``); keys go to the curve view first."""

    def __init__(self, view: CurveView, parent: QWidget | None = None) -> None:
        self._view = view
        super().__init__(parent, background=BACKGROUND, viewBox=CurveViewBox(view))
        self.setObjectName("curvePlot")
        self.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        #: The buttons pressed on this widget (from its own press and release events).
        self._pressed = Qt.MouseButton.NoButton

    def mousePressEvent(self, ev: QMouseEvent) -> None:
        # pyqtgraph's drag events carry the modifiers of each move; Shift-to-add is decided
        # by the modifiers held when the button went down.
        self._view.press_modifiers = ev.modifiers()
        self._pressed = ev.buttons()
        super().mousePressEvent(ev)

    def mouseReleaseEvent(self, ev: QMouseEvent) -> None:
        self._pressed = ev.buttons() & self._pressed
        super().mouseReleaseEvent(ev)

    def mouseMoveEvent(self, ev: QMouseEvent) -> None:
        super().mouseMoveEvent(ev)
        # Hover while no button pressed *here* is down. A move's own buttons() can name a
        # button pressed on another widget whose release never came (QTest keeps that state
        # across tests: the hover test failed in full runs after such a test).
        if not (ev.buttons() & self._pressed):
            self._view.hover_at(self.mapToScene(ev.position().toPoint()))

    def leaveEvent(self, ev: QEvent) -> None:
        self._view.hover_at(None)
        super().leaveEvent(ev)

    def event(self, ev: QEvent) -> bool:
        # Keys the curve editor uses win over window shortcuts while the plot has focus.
        if ev.type() == QEvent.Type.ShortcutOverride and self._view.handles_key(ev):  # type: ignore[arg-type]
            ev.accept()
            return True
        return super().event(ev)

    def keyPressEvent(self, ev: QKeyEvent) -> None:
        if self._view.key_press(ev):
            ev.accept()
            return
        super().keyPressEvent(ev)


class CurveView(QObject):
    """Plot, items, selection and gestures of the curve editor."""

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
        self.selection: dict[str, set[int]] = {}
        self.active: tuple[str, int] | None = None
        self.normalised = False
        self.snap = True
        self.axis_lock = "none"   # "none", "time" or "value"
        self._frozen_norm: dict[str, tuple[float, float]] = {}
        self._drag: _Drag | None = None
        self._drawings: dict[str, ChannelDrawing] = {}
        self._live: set[str] = set()
        self._syncing_frame = False
        self.press_modifiers = Qt.KeyboardModifier.NoModifier
        # The channel object each selection's indices refer to, and (time, value) pairs of
        # keys moved by drags, so that the selection follows the same keys through undo / redo.
        self._selection_base: dict[str, Channel] = {}
        self._moves: dict[str, list[tuple[tuple[float, float], tuple[float, float]]]] = {}
        #: What the mouse is over: ("key", cid, index), ("handle", cid, index, side) or None.
        self.hover: tuple[Any, ...] | None = None
        self._scrubbing = False
        self._units: dict[str, float] = {}
        #: True while the view takes a selection another editor set (not published back).
        self._adopting = False

        self.widget = CurvePlot(self)
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
        self.frame_line = FrameLine(self, pos=ctx.frame, angle=90, movable=True,
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
        ctx.documentChanged.connect(self._document_changed)
        self.keySelectionChanged.connect(self._publish_selection)
        ctx.key_selection.changed.connect(self._shared_selection_changed)
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

    def set_visible(self, cids: Iterable[str]) -> None:
        """Plot exactly these channels (in this order)."""
        wanted = [c for c in cids if c in self.doc.channels]
        self.visible = wanted
        for cid in set(self._drawings) - set(wanted):
            del self._drawings[cid]
        self._prune_selection()
        self._adopt_shared()  # keys another editor selected on channels now shown
        self.refresh_all()

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

    def _document_changed(self, change: DocumentChange) -> None:
        """Refresh the channels the change names (one change per command, or per frame
        during a gesture); the other channels keep their paths and cached pixels."""
        if "fps" in change.parameters:
            self.refresh_all()
        for cid in change.channels:
            if cid not in self.doc.channels:
                self.norm.drop(cid)
            if self._drag is None:
                self._map_selection(cid)
        if change.channels:
            self._prune_selection()
        for cid in change.channels:
            if cid in self.visible:
                self.refresh_channel(cid)
        if self.hover is not None and self.hover[1] in change.channels:
            self.hover_layer.update()

    def _map_selection(self, cid: str) -> None:
        """Channel ``cid`` changed (an undo, another editor): keep its selected keys selected.

        A key is found again by its time and value; a key moved by a drag (or put back by
        undoing one) by the time and value it had at the other end of the move; a key whose
        value alone changed by its time. Keys that cannot be found are dropped from the
        selection.
        """
        old = self._selection_base.get(cid)
        new = self.doc.channels.get(cid)
        idx = self.selection.get(cid)
        if old is None or new is None or not idx or old is new:
            return
        where = {(k.time, k.value): j for j, k in enumerate(new.keys)}
        at_time = {k.time: j for j, k in enumerate(new.keys)}
        moves = self._moves.get(cid, [])
        mapped: set[int] = set()
        active = None
        for i in sorted(idx):
            if i >= len(old.keys):
                continue
            tv = (old.keys[i].time, old.keys[i].value)
            j = where.get(tv)
            if j is None:
                for a, b in reversed(moves):
                    if b == tv and a in where:
                        j = where[a]
                        break
                    if a == tv and b in where:
                        j = where[b]
                        break
            if j is None:
                j = at_time.get(tv[0])  # same time, new value (a typed value, a slider)
            if j is not None:
                mapped.add(j)
                if self.active == (cid, i):
                    active = (cid, j)
        if mapped:
            self.selection[cid] = mapped
        else:
            del self.selection[cid]
        self._selection_base[cid] = new
        if self.active is not None and self.active[0] == cid:
            self.active = active or self._first_selected()
        self._update_live()
        self.keySelectionChanged.emit()

    def _note_selection_base(self) -> None:
        self._selection_base = {cid: self.doc.channels[cid] for cid, idx in self.selection.items()
                                if idx and cid in self.doc.channels}

    def _prune_selection(self) -> None:
        changed = False
        for cid in list(self.selection):
            ch = self.doc.channels.get(cid)
            if ch is None or cid not in self.visible:
                del self.selection[cid]
                changed = True
                continue
            keep = {i for i in self.selection[cid] if i < len(ch.keys)}
            if keep != self.selection[cid]:
                changed = True
                if keep:
                    self.selection[cid] = keep
                else:
                    del self.selection[cid]
        if self.active is not None and self.active[1] not in self.selection.get(self.active[0], set()):
            self.active = self._first_selected()
            changed = True
        if changed:
            self.keySelectionChanged.emit()

    def reset(self) -> None:
        """The document was replaced: forget caches and selection."""
        self.norm.clear()
        self._drawings.clear()
        self.selection.clear()
        self._selection_base.clear()
        self._moves.clear()
        self.hover = None
        self.active = None
        self._drag = None
        self._frozen_norm.clear()
        self._frame_changed(self.ctx.frame)
        self.keySelectionChanged.emit()

    # ------------------------------------------------------------- drawing
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

    # ------------------------------------------------------------ picking
    def _key_frames(self, cid: str, ch: Channel) -> np.ndarray:
        d = self._drawings.get(cid)
        if d is not None and d.channel is ch and d.fps == self.fps:
            return d.frames
        return ch.times * self.fps

    def key_at(self, scene: QPointF, radius: float = PICK_RADIUS) -> tuple[str, int] | None:
        """The key drawn nearest to ``scene`` within ``radius`` pixels (selected keys win
        a tie). Each channel looks only at its keys within ``radius`` in time."""
        tr = self.view_to_scene()
        best: tuple[float, str, int] | None = None
        reach = radius / abs(tr.m11()) if tr.m11() else math.inf
        fx = self.vb.mapSceneToView(scene).x()
        for cid in self.visible:
            ch = self.doc.channels.get(cid)
            if ch is None or not ch.keys:
                continue
            frames = self._key_frames(cid, ch)
            i0 = int(np.searchsorted(frames, fx - reach, side="left"))
            i1 = int(np.searchsorted(frames, fx + reach, side="right"))
            if i1 <= i0:
                continue
            off, scale = self.display_transform(cid)
            px, py = map_points(tr, frames[i0:i1], (ch.values[i0:i1] - off) * scale)
            d = np.hypot(px - scene.x(), py - scene.y())
            j = int(np.argmin(d))
            i = i0 + j
            # Prefer selected keys when two overlap.
            dist = float(d[j]) - (0.5 if i in self.selection.get(cid, ()) else 0.0)
            if d[j] <= radius and (best is None or dist < best[0]):
                best = (dist, cid, i)
        return None if best is None else (best[1], best[2])

    def handle_positions(self, cid: str, index: int) -> tuple[QPointF, QPointF, QPointF]:
        """Scene positions of a key and its in and out handle ends."""
        ch = self.doc.channels[cid]
        off, scale = self.display_transform(cid)
        tr = self.view_to_scene()
        s_in, s_out = ch.slopes()
        k = scale / self.fps
        x = np.array([ch.keys[index].time * self.fps])
        y = np.array([(ch.keys[index].value - off) * scale])
        px, py = map_points(tr, x, y)
        ext = handle_extents(ch)
        e_in, e_out = (None, None) if ext is None else (ext[0][index:index + 1] * self.fps,
                                                       ext[1][index:index + 1] * self.fps)
        ox, oy = handle_offsets(tr, np.array([s_out[index] * k]), e_out)
        ix, iy = handle_offsets(tr, np.array([s_in[index] * k]), e_in)
        key = QPointF(px[0], py[0])
        return key, QPointF(px[0] - ix[0], py[0] - iy[0]), QPointF(px[0] + ox[0], py[0] + oy[0])

    def handle_at(self, scene: QPointF) -> tuple[str, int, str] | None:
        best: tuple[float, str, int, str] | None = None
        for cid, idx in self.selection.items():
            # Handles are drawn (so can be taken) for at most MAX_HANDLES keys per channel.
            if cid not in self.doc.channels or cid not in self.visible or len(idx) > MAX_HANDLES:
                continue
            for i in idx:
                _key, hin, hout = self.handle_positions(cid, i)
                for side, h in (("in", hin), ("out", hout)):
                    d = math.hypot(h.x() - scene.x(), h.y() - scene.y())
                    if d <= max(PICK_RADIUS, HANDLE_SIZE) and (best is None or d < best[0]):
                        best = (d, cid, i, side)
        return None if best is None else (best[1], best[2], best[3])

    def curve_at(self, scene: QPointF) -> str | None:
        """The visible channel whose curve passes closest (vertically) to ``scene``."""
        tr = self.view_to_scene()
        view = self.vb.mapSceneToView(scene)
        t = view.x() / self.fps
        best: tuple[float, str] | None = None
        for cid in self.visible:
            ch = self.doc.channels.get(cid)
            if ch is None or not ch.keys:
                continue
            off, scale = self.display_transform(cid)
            y = (ch.evaluate(t) - off) * scale
            _px, py = map_points(tr, np.array([view.x()]), np.array([y]))
            d = abs(float(py[0]) - scene.y())
            if d <= CURVE_PICK_RADIUS and (best is None or d < best[0]):
                best = (d, cid)
        return None if best is None else best[1]

    # ---------------------------------------------------------- selection
    def selected_keys(self) -> dict[str, list[int]]:
        return {cid: sorted(idx) for cid, idx in self.selection.items() if idx}

    def _first_selected(self) -> tuple[str, int] | None:
        for cid in self.visible:
            if self.selection.get(cid):
                return cid, min(self.selection[cid])
        return None

    def set_selection(self, selection: Mapping[str, Iterable[int]], active: tuple[str, int] | None = None) -> None:
        self.selection = {cid: set(idx) for cid, idx in selection.items() if idx}
        if active is not None and active[1] in self.selection.get(active[0], set()):
            self.active = active
        elif self.active is None or self.active[1] not in self.selection.get(self.active[0], set()):
            self.active = self._first_selected()
        self._note_selection_base()
        self._update_live()
        self.keySelectionChanged.emit()

    def clear_selection(self) -> None:
        self.set_selection({})

    def select_all(self) -> None:
        self.set_selection({cid: range(len(self.doc.channels[cid].keys)) for cid in self.visible})

    def select_under(self, scene: QPointF) -> None:
        """Right click: select what is under the cursor, so that the menu acts on it. A key
        that is selected already keeps the selection (it becomes the active key); another
        key becomes the selection; a curve away from keys is selected as a channel (its
        keys are deselected); empty space and handles keep the selection."""
        if self.handle_at(scene) is not None:
            return
        hit = self.key_at(scene)
        if hit is not None:
            cid, i = hit
            if i in self.selection.get(cid, ()):
                if self.active != hit:
                    self.active = hit
                    self.keySelectionChanged.emit()
            else:
                self.set_selection({cid: [i]}, hit)
            return
        curve = self.curve_at(scene)
        if curve is not None:
            asset, joint, _dof = split_channel_id(curve)
            self.ctx.select(asset, joint)
            self.ctx.select_channels([curve])
            self.clear_selection()

    # ------------------------------------------------------- shared selection
    def _publish_selection(self) -> None:
        """Our selection changed: share it (``ctx.key_selection``). Keys another editor
        selected on channels this view does not show stay selected there."""
        shared = self.ctx.key_selection
        if self._adopting:
            return
        channels = self.doc.channels
        shown = set(self.visible)
        keys: dict[str, Iterable[int]] = {cid: idx for cid, idx in shared.valid(channels).items()
                                          if cid not in shown}
        keys.update({cid: idx for cid, idx in self.selection.items() if idx})
        shared.set(keys, channels, self)

    def _shared_selection_changed(self, source: object) -> None:
        """Another editor (the dope sheet) selected keys: select those we show."""
        if source is self or source is None:
            return
        self._adopt_shared()

    def _adopt_shared(self) -> None:
        shared = self.ctx.key_selection
        if self._drag is not None:
            return
        shown = set(self.visible)
        wanted = {cid: set(idx) for cid, idx in shared.valid(self.doc.channels).items() if cid in shown}
        if wanted == {c: s for c, s in self.selection.items() if s}:
            return
        self._adopting = True
        try:
            self.set_selection(wanted)
        finally:
            self._adopting = False

    # ------------------------------------------------------------- editing
    def push(self, command: Command) -> None:
        self.ctx.push(command)

    def delete_selected(self) -> None:
        sel = self.selected_keys()
        if not sel:
            return
        self.selection.clear()
        self._selection_base.clear()
        self.active = None
        self.push(DeleteKeys(self.doc, sel))
        self.keySelectionChanged.emit()

    def insert_key_at(self, scene: QPointF) -> tuple[str, int] | None:
        """Ctrl+click: a key on the curve under the cursor (or the one highlighted channel)."""
        view = self.vb.mapSceneToView(scene)
        frame = round(view.x()) if self.snap else view.x()
        t = frame / self.fps
        cid = self.curve_at(scene)
        if cid is not None:
            value = float(self.doc.channels[cid].evaluate(t))
        else:
            candidates = [c for c in self.visible if c in self.highlighted]
            if len(candidates) != 1:
                return None
            cid = candidates[0]
            off, scale = self.display_transform(cid)
            value = view.y() / scale + off
        self.push(InsertKey(self.doc, cid, Key(t, value), text="Insert Key"))
        index = self.doc.channels[cid].key_index(t)
        if index is None:
            return None
        self.set_selection({cid: [index]}, (cid, index))
        return cid, index

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
        if not xs:
            return None
        return min(xs), max(xs), min(ys), max(ys)

    def _frame_bounds(self, b: tuple[float, float, float, float] | None) -> None:
        if b is None:
            start, end = self.doc.frame_range
            b = (float(start), float(end), -1.0, 1.0)
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

    # ---------------------------------------------------------------- hover
    def hover_at(self, scene: QPointF | None) -> None:
        """Highlight the key or handle under the mouse and show a cursor that says what a
        drag will do there: move (keys), point (handles), move sideways (the playhead's
        handle, which takes the drag there), arrow elsewhere."""
        hit: tuple[Any, ...] | None = None
        if scene is not None and not self.dragging and self.frame_line.at_handle(scene):
            hit = ("playhead", "", -1)
        elif scene is not None and not self.dragging and self.vb.sceneBoundingRect().contains(scene):
            handle = self.handle_at(scene)
            if handle is not None:
                hit = ("handle", *handle)
            else:
                key = self.key_at(scene)
                if key is not None:
                    hit = ("key", *key)
        if hit == self.hover:
            return
        self.hover = hit
        shape = {None: None, "key": Qt.CursorShape.SizeAllCursor, "handle": Qt.CursorShape.PointingHandCursor,
                 "playhead": Qt.CursorShape.SizeHorCursor}[hit[0] if hit else None]
        viewport = self.widget.viewport()
        if shape is None:
            viewport.unsetCursor()
        else:
            viewport.setCursor(shape)
        self.hover_layer.update()

    def scrub(self, scene: QPointF, finish: bool = False) -> None:
        """A drag along the time axis: the current frame follows the mouse (whole frames)."""
        frame = float(round(self.vb.mapSceneToView(scene).x()))
        self._scrubbing = not finish
        if frame != self.ctx.frame:
            self.ctx.set_frame(frame)

    # ------------------------------------------------------------- gestures
    def click(self, scene: QPointF, mods: Qt.KeyboardModifier) -> None:
        self.widget.setFocus()
        shift = bool(mods & Qt.KeyboardModifier.ShiftModifier)
        if mods & Qt.KeyboardModifier.ControlModifier:
            self.insert_key_at(scene)
            return
        if self.handle_at(scene) is not None:
            return
        hit = self.key_at(scene)
        if hit is not None:
            cid, i = hit
            sel = {c: set(s) for c, s in self.selection.items()}
            if shift:
                s = sel.setdefault(cid, set())
                s.symmetric_difference_update({i})
            else:
                sel = {cid: {i}}
            self.set_selection(sel, hit)
            return
        curve = self.curve_at(scene)
        if curve is not None and not shift:
            asset, joint, _dof = split_channel_id(curve)
            self.ctx.select(asset, joint)
            self.ctx.select_channels([curve])
        if not shift:
            self.clear_selection()

    def drag_event(self, ev: Any) -> bool:
        """Handle a pyqtgraph drag event; False lets the ViewBox pan or zoom."""
        button = ev.button()
        mods = ev.modifiers()
        if ev.isStart():
            self._drag = None
            if button != Qt.MouseButton.LeftButton or mods & Qt.KeyboardModifier.AltModifier:
                return False
            self.widget.setFocus()
            self._drag = self._begin_drag(ev.buttonDownScenePos(), mods | self.press_modifiers)
            self._update_live()
        drag = self._drag
        if drag is None:
            return False
        ev.accept()
        if drag.kind == "aborted":
            if ev.isFinish():
                self._drag = None
            return True
        if drag.kind == "keys":
            self._drag_keys(drag, ev.scenePos(), mods)
        elif drag.kind == "scale":
            self._drag_scale(drag, ev.scenePos())
        elif drag.kind == "handle":
            self._drag_handle(drag, ev.scenePos())
        elif drag.kind == "box":
            self._drag_box(drag, ev.scenePos(), finish=ev.isFinish())
        if ev.isFinish():
            self._finish_drag(drag)
        return True

    def _begin_drag(self, scene: QPointF, mods: Qt.KeyboardModifier) -> _Drag:
        shift = bool(mods & Qt.KeyboardModifier.ShiftModifier)
        handle = self.handle_at(scene)
        if handle is not None:
            cid, i, side = handle
            self._frozen_norm = {cid: self.display_transform(cid)}
            return _Drag("handle", self.ctx.begin_gesture("Tangent Handle"), anchor=(cid, i), side=side,
                         start_scene=scene, base={cid: self.doc.channels[cid]})
        hit = self.key_at(scene)
        if hit is not None:
            cid, i = hit
            if i not in self.selection.get(cid, set()):
                sel = {c: set(s) for c, s in self.selection.items()} if shift else {}
                sel.setdefault(cid, set()).add(i)
                self.set_selection(sel, hit)
            selection = self.selected_keys()
            base = {c: self.doc.channels[c] for c in selection}
            self._frozen_norm = {c: self.display_transform(c) for c in selection}
            kind = "scale" if mods & Qt.KeyboardModifier.ControlModifier else "keys"
            gesture = self.ctx.begin_gesture("Scale Keys" if kind == "scale" else "Move Keys")
            return _Drag(kind, gesture, base=base, selection=selection, anchor=hit, start_scene=scene)
        return _Drag("box", start_scene=scene, additive=shift)

    def _preview(self, drag: _Drag, command: Command) -> None:
        """One mouse move of a gesture: the document shows ``command`` (built from the
        channels as they were when the drag began), folded into the drag's one step."""
        assert drag.gesture is not None
        drag.gesture.update(command)
        # The editor doing the gesture redraws its own preview now; the other views (and
        # this one again, at no cost: the channel object is the same) hear of the change at
        # the next tick of the frame clock, which would add up to a frame to every move.
        changes = getattr(command, "changes", None)
        if isinstance(changes, dict):
            for cid in changes:
                self.refresh_channel(cid)

    def _drag_keys(self, drag: _Drag, scene: QPointF, mods: Qt.KeyboardModifier) -> None:
        start = self.vb.mapSceneToView(drag.start_scene)
        cur = self.vb.mapSceneToView(scene)
        dx = cur.x() - start.x()
        dy = cur.y() - start.y()
        lock = self.axis_lock
        if mods & Qt.KeyboardModifier.ShiftModifier:
            # Shift held while dragging: constrain to the axis the mouse moved most along.
            lock = "time" if abs(scene.x() - drag.start_scene.x()) >= abs(scene.y() - drag.start_scene.y()) \
                else "value"
        if lock == "time":
            dy = 0.0
        elif lock == "value":
            dx = 0.0
        assert drag.anchor is not None and drag.gesture is not None
        anchor_frame = drag.base[drag.anchor[0]].keys[drag.anchor[1]].time * self.fps
        if self.snap:
            dx = round(anchor_frame + dx) - anchor_frame
        dt = dx / self.fps
        dv = {cid: dy / self.display_transform(cid)[1] for cid in drag.selection}
        if not drag.gesture.updates and dt == 0.0 and dy == 0.0:
            return
        try:
            cmd = MoveKeys(drag.base, drag.selection, dt, dv)
        except ValueError:
            return  # a key would land on another key's time: keep the last valid position
        self._preview(drag, cmd)
        self._remap_selection(drag, lambda t: t + dt)

    def _drag_scale(self, drag: _Drag, scene: QPointF) -> None:
        """Ctrl+drag on a key: scale the selected keys' times about the current frame."""
        assert drag.anchor is not None and drag.gesture is not None
        pivot = self.ctx.frame
        anchor_frame = drag.base[drag.anchor[0]].keys[drag.anchor[1]].time * self.fps
        start = self.vb.mapSceneToView(drag.start_scene).x()
        target = anchor_frame + self.vb.mapSceneToView(scene).x() - start
        if self.snap:
            target = round(target)
        if abs(anchor_frame - pivot) < 1e-9:
            return
        factor = (target - pivot) / (anchor_frame - pivot)
        if factor <= 0.0 or (factor == 1.0 and not drag.gesture.updates):
            return
        p = pivot / self.fps
        try:
            cmd = MoveKeys(drag.base, drag.selection, 0.0, 0.0, text="Scale Keys", time_scale=(p, factor))
        except ValueError:
            return
        self._preview(drag, cmd)
        self._remap_selection(drag, lambda t: p + (t - p) * factor)

    def _remap_selection(self, drag: _Drag, new_time: Callable[[float], float]) -> None:
        """Keys may pass others while moving: find the moved keys' new indices."""
        new_sel: dict[str, set[int]] = {}
        active = None
        drag.moved = {}
        for cid, idx in drag.selection.items():
            ch = self.doc.channels[cid]
            times = ch.times
            found = set()
            pairs = []
            for i in idx:
                t = new_time(drag.base[cid].keys[i].time)
                j = int(np.argmin(np.abs(times - t)))
                found.add(j)
                a, b = drag.base[cid].keys[i], ch.keys[j]
                pairs.append(((a.time, a.value), (b.time, b.value)))
                if drag.anchor == (cid, i):
                    active = (cid, j)
            new_sel[cid] = found
            drag.moved[cid] = pairs
        self.selection = new_sel
        self._note_selection_base()
        self.active = active or self._first_selected()
        self._update_live()
        self.keySelectionChanged.emit()

    def _drag_handle(self, drag: _Drag, scene: QPointF) -> None:
        assert drag.anchor is not None
        cid, i = drag.anchor
        base = drag.base[cid]
        key = base.keys[i]
        off, scale = self.display_transform(cid)
        kview = QPointF(key.time * self.fps, (key.value - off) * scale)
        cur = self.vb.mapSceneToView(scene)
        dx = cur.x() - kview.x()
        dy = cur.y() - kview.y()
        # An out handle stays right of its key and an in handle left of it.
        min_dx = 1e-6 * max(1.0, abs(self.vb.viewRange()[0][1] - self.vb.viewRange()[0][0]))
        if drag.side == "out":
            dx = max(dx, min_dx)
        else:
            dx = min(dx, -min_dx)
        slope = (dy / dx) * self.fps / scale
        if key.broken:
            ins, outs = (slope, None) if drag.side == "in" else (None, slope)
        else:
            ins, outs = slope, slope
        weight = key.in_weight if drag.side == "in" else key.out_weight
        ext = handle_extents(base)
        real = ext is not None and math.isfinite(float(ext[0 if drag.side == "in" else 1][i]))
        if weight is not None and real:
            # A weighted key's handle: the drag sets its slope and its length (this side only).
            edited = SetKeySlopes(self.doc, cid, i, ins, outs, base=base).changes[cid][1]
            assert edited is not None
            new_key = replace(edited.keys[i], **{f"{drag.side}_weight": abs(dx) / self.fps})
            self._preview(drag, SetChannels("Tangent Handle", {cid: (base, base.replace_keys({i: new_key}))}))
        else:
            self._preview(drag, SetKeySlopes(self.doc, cid, i, ins, outs, base=base))
        self._update_live()
        self.keySelectionChanged.emit()

    def _drag_box(self, drag: _Drag, scene: QPointF, finish: bool) -> None:
        a = self.vb.mapSceneToView(drag.start_scene)
        b = self.vb.mapSceneToView(scene)
        rect = QRectF(a, b).normalized()
        if not finish:
            self.box.setRect(rect)
            self.box.show()
            return
        self.box.hide()
        sel = {c: set(s) for c, s in self.selection.items()} if drag.additive else {}
        fps = self.fps
        for cid in self.visible:
            ch = self.doc.channels.get(cid)
            if ch is None or not ch.keys:
                continue
            off, scale = self.display_transform(cid)
            x = ch.times * fps
            y = (ch.values - off) * scale
            inside = (x >= rect.left()) & (x <= rect.right()) & (y >= rect.top()) & (y <= rect.bottom())
            hits = set(np.nonzero(inside)[0].tolist())
            if hits:
                sel.setdefault(cid, set()).update(hits)
        self.set_selection(sel)

    def _finish_drag(self, drag: _Drag) -> None:
        if drag.gesture is not None:
            # Commit while the drag is still current: the views catch up on the last moves
            # (one change) without mapping the selection, which the drag kept itself.
            drag.gesture.commit()
        self._drag = None
        if drag.kind in ("keys", "scale"):
            self._frozen_norm.clear()
            if any(self.doc.channels.get(c) != ch for c, ch in drag.base.items()):
                for cid, pairs in drag.moved.items():
                    history = self._moves.setdefault(cid, [])
                    history.extend((a, b) for a, b in pairs if a != b)
                    del history[:-MOVE_HISTORY]
        elif drag.kind == "handle":
            self._frozen_norm.clear()
            self._note_selection_base()
        # The dragged channels stay live while selected; the cached layer is redrawn only
        # if some leave the live layer.
        self._update_live()

    @property
    def dragging(self) -> bool:
        return self._drag is not None and self._drag.kind != "aborted"

    def abort_drag(self) -> bool:
        """Escape: put everything back as it was before the drag and record nothing."""
        drag = self._drag
        if drag is None or drag.kind == "aborted":
            return False
        if drag.gesture is not None:
            drag.gesture.abort()
            if drag.kind != "handle":
                self.set_selection(drag.selection, drag.anchor)
            else:
                self._note_selection_base()
        self.box.hide()
        self._frozen_norm.clear()
        self._drag = _Drag("aborted")
        self._update_live()
        return True

    # ------------------------------------------------------------------ keys
    _KEYS = {Qt.Key.Key_A, Qt.Key.Key_F, Qt.Key.Key_Home, Qt.Key.Key_Delete, Qt.Key.Key_Backspace,
             Qt.Key.Key_N, Qt.Key.Key_Escape}

    def handles_key(self, ev: QKeyEvent) -> bool:
        mods = ev.modifiers() & ~Qt.KeyboardModifier.KeypadModifier
        if ev.key() == Qt.Key.Key_A and mods == Qt.KeyboardModifier.ControlModifier:
            return True
        if ev.key() == Qt.Key.Key_Escape:
            return self.dragging
        return mods == Qt.KeyboardModifier.NoModifier and ev.key() in self._KEYS

    def key_press(self, ev: QKeyEvent) -> bool:
        key = ev.key()
        mods = ev.modifiers() & ~Qt.KeyboardModifier.KeypadModifier
        if key == Qt.Key.Key_Escape:
            return self.abort_drag()
        if mods not in (Qt.KeyboardModifier.NoModifier,):
            if key == Qt.Key.Key_A and mods == Qt.KeyboardModifier.ControlModifier:
                self.select_all()
                return True
            return False
        actions: dict[int, Callable[[], None]] = {
            Qt.Key.Key_A: self.frame_all,
            Qt.Key.Key_F: self.frame_selected,
            Qt.Key.Key_Home: self.frame_all,
            Qt.Key.Key_Delete: self.delete_selected,
            Qt.Key.Key_Backspace: self.delete_selected,
            Qt.Key.Key_N: lambda: self.set_normalised(not self.normalised),
        }
        fn = actions.get(key)
        if fn is None:
            return False
        fn()
        return True
