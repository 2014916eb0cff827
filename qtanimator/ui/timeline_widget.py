"""The timeline's ruler (:class:`TimelineWidget`, object name ``timeline``: frame ruler,
key ticks, the current-frame cursor; press or drag to scrub) and the simulation cache bar
under it (:class:`CacheBar`, ``cacheBar``), with :func:`key_frames`, the frames holding
keys. The panel, the play controls and their keys are :mod:`qtanimator.ui.timeline`.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt
from PySide6.QtCore import QElapsedTimer, QLineF, QPointF, QRectF, QSize, Qt, QTimer, Signal
from PySide6.QtGui import QColor, QFont, QMouseEvent, QPainter, QPaintEvent, QPen, QResizeEvent
from PySide6.QtWidgets import QSizePolicy, QWidget

from qtanimator.core.channel import Channel
from qtanimator.document.document import Document, DocumentChange, split_channel_id
from qtanimator.ui.context import EditorContext
from qtanimator.ui.playback import Playback

__all__ = ["CACHE_BAR_HEIGHT", "CACHE_COLOR", "FAILED_COLOR", "CacheBar", "FrameCache", "TimelineWidget",
           "key_frames"]

MARGIN = 10
#: The cache bar: a strip this high in the timeline's bottom margin, under the ruler.
CACHE_BAR_HEIGHT = 4
#: Simulated frames (Blender draws its simulation caches as a coloured band too).
CACHE_COLOR = QColor(80, 170, 255)
FAILED_COLOR = QColor(230, 60, 50)
#: How often the cache bar checks the simulations even when no worker reported (ms).
SLOW_REFRESH_MS = 250
FloatArray = npt.NDArray[np.float64]


#: Per channel id: the channel object and its key frames at an fps. Channels are immutable
#: (an edit makes a new object), so a drag recomputes only the dragged channels.
FrameCache = dict[str, tuple[Channel, float, FloatArray]]


def key_frames(ctx: EditorContext, asset: str | None = None, cache: FrameCache | None = None) -> list[float]:
    """Sorted frames that hold a key in any channel (of ``asset`` when given). ``cache``
    keeps each channel's frames between calls (entries of removed channels are dropped)."""
    fps = ctx.doc.fps
    arrays = []
    for cid, ch in ctx.doc.channels.items():
        if not ch.keys or (asset is not None and split_channel_id(cid)[0] != asset):
            continue
        hit = cache.get(cid) if cache is not None else None
        if hit is not None and hit[0] is ch and hit[1] == fps:
            frames = hit[2]
        else:
            frames = _interned(np.round(ch.times * fps, 6))
            if cache is not None:
                cache[cid] = (ch, fps, frames)
        arrays.append(frames)
    if cache is not None and len(cache) > len(ctx.doc.channels):
        for cid in [c for c in cache if c not in ctx.doc.channels]:
            del cache[cid]
    if not arrays:
        return []
    # Channels keyed on the same frames (every channel of a mocap clip) share one interned
    # array: merge each distinct array once, not 96 copies of it.
    distinct = list({id(a): a for a in arrays}.values())
    return np.unique(np.concatenate(distinct)).tolist()


#: Key-frame arrays by content, so that channels keyed on the same frames share one array.
_FRAME_ARRAYS: dict[tuple[int, bytes], FloatArray] = {}
_FRAME_ARRAYS_MAX = 4096


def _interned(frames: FloatArray) -> FloatArray:
    key = (len(frames), frames.tobytes())
    hit = _FRAME_ARRAYS.get(key)
    if hit is not None:
        return hit
    if len(_FRAME_ARRAYS) >= _FRAME_ARRAYS_MAX:
        _FRAME_ARRAYS.clear()
    frames.setflags(write=False)
    _FRAME_ARRAYS[key] = frames
    return frames


class TimelineWidget(QWidget):
    """The ruler with key ticks and cursor; press or drag to scrub."""

    def __init__(self, ctx: EditorContext, playback: Playback, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("timeline")
        self.ctx = ctx
        self.playback = playback
        self.setMinimumHeight(48)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Expanding)
        self.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        self.setMouseTracking(False)
        self._keys: list[float] | None = None
        self._frame_cache: FrameCache = {}
        self._selected_keys: list[float] | None = None
        ctx.frameChanged.connect(lambda _f: self.update())
        ctx.documentChanged.connect(self._on_document_changed)
        ctx.documentReset.connect(self._invalidate)
        ctx.selectionChanged.connect(lambda _a, _j: self._invalidate())
        self.cache_bar = CacheBar(self)
        self._place_cache_bar()

    def sizeHint(self) -> QSize:
        return QSize(800, 52)

    def resizeEvent(self, event: QResizeEvent) -> None:
        super().resizeEvent(event)
        self._place_cache_bar()

    def _place_cache_bar(self) -> None:
        # In the bottom margin, right under the ruler (drawn down to height − 6).
        self.cache_bar.setGeometry(0, self.height() - 5, self.width(), CACHE_BAR_HEIGHT)

    # --------------------------------------------------------------- keys
    def _on_document_changed(self, change: DocumentChange) -> None:
        if change:
            self._invalidate()

    def _invalidate(self) -> None:
        self._keys = None
        self._selected_keys = None
        self.update()

    def keys(self) -> list[float]:
        if self._keys is None:
            self._keys = key_frames(self.ctx, cache=self._frame_cache)
        return self._keys

    def selected_keys(self) -> list[float]:
        if self._selected_keys is None:
            asset = self.ctx.selection[0]
            self._selected_keys = key_frames(self.ctx, asset, self._frame_cache) if asset else []
        return self._selected_keys

    def _tick_lines(self, frames: list[float], top: float, bottom: float) -> list[QLineF]:
        """Vertical lines at the pixel columns of ``frames`` inside the frame range."""
        if not frames:
            return []
        first, last = self._span()
        f = np.asarray(frames, dtype=np.float64)
        f = f[(f >= first) & (f <= last)]
        width = max(self.width() - 2 * MARGIN, 1)
        xs = np.unique(np.round(MARGIN + (f - first) / (last - first) * width, 1))
        return [QLineF(x, top, x, bottom) for x in xs.tolist()]

    # ---------------------------------------------------------- geometry
    def _span(self) -> tuple[int, int]:
        first, last = self.ctx.doc.frame_range
        return first, max(last, first + 1)

    def frame_to_x(self, frame: float) -> float:
        first, last = self._span()
        width = max(self.width() - 2 * MARGIN, 1)
        return MARGIN + (frame - first) / (last - first) * width

    def x_to_frame(self, x: float) -> float:
        first, last = self._span()
        width = max(self.width() - 2 * MARGIN, 1)
        frame = first + (x - MARGIN) / width * (last - first)
        return float(min(max(round(frame), first), last))

    # -------------------------------------------------------------- mouse
    def mousePressEvent(self, event: QMouseEvent) -> None:
        if event.button() == Qt.MouseButton.LeftButton:
            self.playback.pause()
            self.ctx.set_frame(self.x_to_frame(event.position().x()))
            event.accept()
        else:
            super().mousePressEvent(event)

    def mouseMoveEvent(self, event: QMouseEvent) -> None:
        if event.buttons() & Qt.MouseButton.LeftButton:
            self.ctx.set_frame(self.x_to_frame(event.position().x()))
            event.accept()

    # ------------------------------------------------------------ drawing
    def paintEvent(self, _event: QPaintEvent) -> None:
        p = QPainter(self)
        p.setRenderHint(QPainter.RenderHint.Antialiasing, False)
        w, h = self.width(), self.height()
        p.fillRect(self.rect(), QColor(48, 48, 52))
        bar = QRectF(MARGIN, 18, w - 2 * MARGIN, h - 24)
        p.fillRect(bar, QColor(235, 235, 240, 204))

        first, last = self._span()
        px_per_frame = bar.width() / (last - first)
        step = 1
        for candidate in (1, 2, 5, 10, 20, 25, 50, 100, 200, 250, 500, 1000, 2000, 5000):
            step = candidate
            if candidate * px_per_frame >= 48:
                break
        minor = max(step // 5, 1) if step >= 5 else step
        font = QFont(self.font())
        font.setPointSizeF(max(font.pointSizeF() * 0.8, 6.0))
        p.setFont(font)
        p.setPen(QPen(QColor(90, 90, 96), 1))
        f = math.ceil(first / minor) * minor
        while f <= last:
            x = self.frame_to_x(f)
            major = f % step == 0
            p.drawLine(QPointF(x, bar.top()), QPointF(x, bar.top() + (8 if major else 4)))
            if major:
                p.setPen(QColor(220, 220, 220))
                label = str(f)
                tw = p.fontMetrics().horizontalAdvance(label)
                p.drawText(QPointF(min(x + 2, w - tw - 2), 13), label)
                p.setPen(QPen(QColor(90, 90, 96), 1))
            f += minor

        # Key ticks: every key in red, the selected character's keys taller. One line per
        # pixel column, drawn in one call (a mocap clip has a key on every frame).
        p.setPen(QPen(QColor(200, 30, 30), 1))
        p.drawLines(self._tick_lines(self.keys(), bar.top() + 10, bar.bottom()))
        p.setPen(QPen(QColor(255, 140, 0), 2))
        p.drawLines(self._tick_lines(self.selected_keys(), bar.top() + 4, bar.bottom()))

        x = self.frame_to_x(self.ctx.frame)
        p.setPen(QPen(QColor(230, 0, 0), 2))
        p.drawLine(QPointF(x, bar.top() - 2), QPointF(x, bar.bottom()))
        p.end()


class CacheBar(QWidget):
    """The simulation cache bar: a thin strip under the frame ruler whose coloured band
    spans the frames the pendulums are simulated for (every 2D character with pendulums).

    It follows the background worker through ``ctx.simulationProgressed`` (at most once per
    frame) and document changes; :meth:`simulated` is the range it draws, also given as its
    tool tip and accessible description. It lets mouse presses through to the ruler.
    """

    #: The messages of the blow-ups that stopped a simulation (empty when none did).
    problemsChanged = Signal(list)

    def __init__(self, timeline: TimelineWidget) -> None:
        super().__init__(timeline)
        self.setObjectName("cacheBar")
        self.setAccessibleName("Simulation cache")
        self.setAttribute(Qt.WidgetAttribute.WA_TransparentForMouseEvents, True)
        self.timeline = timeline
        self.ctx = timeline.ctx
        self._range: tuple[int, int] | None = None
        #: Frames where a simulation blew up (drawn as red marks after the good frames).
        self._failed: list[tuple[int, str]] = []
        #: How many times the band was recomputed (tests: at most once per progress signal).
        self.refreshes = 0
        self.ctx.simulationProgressed.connect(self.refresh)
        # Workers report through polls that stop when they go idle; a slow timer makes sure
        # the last state (a blow-up included) is shown whatever the order of events.
        self._slow_refresh = QTimer(self)
        self._slow_refresh.setObjectName("cacheBarRefresh")
        self._slow_refresh.setInterval(SLOW_REFRESH_MS)
        self._slow_refresh.timeout.connect(self._refresh_if_quiet)
        self._slow_refresh.start()
        self._since_refresh = QElapsedTimer()
        self._since_refresh.start()
        self.ctx.documentChanged.connect(lambda _change: self.refresh())
        self.ctx.documentReset.connect(self.refresh)
        self.refresh()

    def simulated(self) -> tuple[int, int] | None:
        """``(first, last)`` simulated frames (last < first: none yet); None when no 2D
        character has pendulums."""
        return self._range

    def failures(self) -> list[tuple[int, str]]:
        """``(frame, message)`` of each blow-up that stopped a simulation."""
        return list(self._failed)

    def _refresh_if_quiet(self) -> None:
        if self._since_refresh.elapsed() >= SLOW_REFRESH_MS:
            self.refresh()

    def refresh(self) -> None:
        from qtanimator.document import character2d as c2d
        from qtanimator.document.simulation import progress

        self.refreshes += 1
        self._since_refresh.restart()
        doc = self.ctx.doc
        simulated = c2d.simulated_frames(doc)
        if progress(doc)[1]:
            self.ctx.watch_simulation()  # follow the worker while it runs
        failed = sorted((int(round(p.time * doc.fps)), p.message) for p in c2d.pendulum_problems(doc).values())
        failed += _cloth_failures(doc)
        failed.sort()
        if simulated != self._range or failed != self._failed:
            problems_changed = failed != self._failed
            self._range, self._failed = simulated, failed
            if simulated is None:
                text = "No simulation"
            elif simulated[1] < simulated[0]:
                text = "Simulation: no frame simulated yet"
            else:
                text = f"Simulated frames {simulated[0]}–{simulated[1]}"
            text = "\n".join([text] + [f"Stopped at frame {f}: {m}" for f, m in failed])
            self.setToolTip(text)
            self.setAccessibleDescription(text)
            self.update()
            if problems_changed:
                self.problemsChanged.emit([m for _f, m in failed])

    def paintEvent(self, _event: QPaintEvent) -> None:
        p = QPainter(self)
        first, last = self.timeline._span()
        x0, x1 = self.timeline.frame_to_x(first), self.timeline.frame_to_x(last)
        h = self.height()
        p.fillRect(QRectF(x0, 0, x1 - x0, h), QColor(70, 70, 76))
        if self._range is not None and self._range[1] >= self._range[0]:
            a = self.timeline.frame_to_x(max(self._range[0], first))
            b = self.timeline.frame_to_x(min(self._range[1], last))
            if b >= a:
                p.fillRect(QRectF(a, 0, max(b - a, 1.0), h), CACHE_COLOR)
        for frame, _message in self._failed:
            if first <= frame <= last:
                x = self.timeline.frame_to_x(frame)
                p.fillRect(QRectF(x - 1.5, 0, 3.0, h), FAILED_COLOR)
        p.end()


def _cloth_failures(doc: Document) -> list[tuple[int, str]]:
    """``(frame, message)`` of each cloth whose cached simulation blew up."""
    from qtanimator.document import cloth as cloth_doc

    out = []
    for aid, asset in list(doc.assets.items()):
        if asset.kind != cloth_doc.ASSET_KIND:
            continue
        try:
            problem = cloth_doc.cloth_problem(doc, aid)
        except (KeyError, ValueError):  # not loadable: the 3D view reports it
            continue
        if problem is not None:
            frame = doc.frame_range[0] + int(round(problem.time * doc.fps))
            out.append((frame, f"cloth '{aid}': {problem.message}"))
    return out
