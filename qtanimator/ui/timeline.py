"""The timeline: frame ruler, key ticks, the current-frame cursor, the simulation cache
bar, the play controls and the auto-key button.

Auto-key (``autoKeyButton`` / ``actionAutoKey``, red while on, like Blender's record
button): on, posing keys at once; off, a drag only poses and S keys (see
:mod:`qtanimator.document.pose`). Per project, saved with it as view state.

Keys follow the reference animator: Space play / pause, ←/→ step and Shift+←/→ ±10
frames (both wrapping around the range), Alt+←/→ previous / next key, Home or ↑ start, End or ↓ end, ``[`` / ``]``
shorten / lengthen the range by 100 frames (an undoable parameter change).
"""

from __future__ import annotations

import bisect
import math
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt
from PySide6.QtCore import QElapsedTimer, QLineF, QPointF, QRectF, QSize, Qt, QTimer, Signal
from PySide6.QtGui import (
    QAction,
    QBrush,
    QColor,
    QFont,
    QIcon,
    QKeySequence,
    QMouseEvent,
    QPainter,
    QPaintEvent,
    QPen,
    QPixmap,
    QResizeEvent,
)
from PySide6.QtWidgets import (
    QHBoxLayout,
    QLabel,
    QSizePolicy,
    QSpinBox,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from qtanimator.core.channel import Channel
from qtanimator.document import pose
from qtanimator.document.commands import Macro, SetParameter
from qtanimator.document.document import Document, DocumentChange, split_channel_id
from qtanimator.ui.context import EditorContext
from qtanimator.ui.playback import Playback, playback_frame

if TYPE_CHECKING:
    from qtanimator.ui.main_window import MainWindow

__all__ = ["CacheBar", "Playback", "TimelineWidget", "TimelinePanel", "install", "key_frames",
           "make_autokey_action", "playback_frame"]

RANGE_STEP = 100
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


class TimelinePanel(QWidget):
    """Buttons, the frame readout and the ruler, as one dock widget."""

    def __init__(self, ctx: EditorContext, playback: Playback, actions: dict[str, QAction],
                 parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("timelinePanel")
        self.ctx = ctx
        self.timeline = TimelineWidget(ctx, playback, self)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(4, 2, 4, 2)
        layout.setSpacing(2)
        row = QHBoxLayout()
        row.setSpacing(2)
        for name in ("actionRewind", "actionStepBack", "actionPlay", "actionStop", "actionStepForward",
                     "actionLoop"):
            button = QToolButton(self)
            button.setDefaultAction(actions[name])
            button.setObjectName(name.replace("action", "button"))
            button.setAutoRaise(True)
            row.addWidget(button)
        autokey = actions.get("actionAutoKey")
        self.autokey_button: QToolButton | None = None
        if autokey is not None:
            row.addSpacing(6)
            self.autokey_button = QToolButton(self)
            self.autokey_button.setDefaultAction(autokey)
            self.autokey_button.setObjectName("autoKeyButton")
            self.autokey_button.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextBesideIcon)
            self.autokey_button.setStyleSheet(AUTOKEY_STYLE)
            row.addWidget(self.autokey_button)
        row.addSpacing(12)
        row.addWidget(QLabel("Frame", self))
        self.frame_box = QSpinBox(self)
        self.frame_box.setObjectName("frameSpinBox")
        self.frame_box.setKeyboardTracking(False)
        row.addWidget(self.frame_box)
        self.range_label = QLabel(self)
        self.range_label.setObjectName("frameRangeLabel")
        row.addWidget(self.range_label)
        self.fps_label = QLabel(self)
        self.fps_label.setObjectName("playbackRateLabel")
        row.addStretch(1)
        row.addWidget(self.fps_label)
        layout.addLayout(row)
        layout.addWidget(self.timeline, 1)
        self.frame_box.valueChanged.connect(lambda v: ctx.set_frame(float(v)))
        ctx.frameChanged.connect(self._sync)
        ctx.documentChanged.connect(lambda _e: self._sync())
        ctx.documentReset.connect(self._sync)
        self._sync()

    def _sync(self, *_args: object) -> None:
        first, last = self.ctx.doc.frame_range
        self.frame_box.blockSignals(True)
        self.frame_box.setRange(first, max(last, first))
        self.frame_box.setValue(int(round(self.ctx.frame)))
        self.frame_box.blockSignals(False)
        self.range_label.setText(f"{first} – {last} @ {self.ctx.doc.fps:g} fps")


class TimelineController:
    """The frame-stepping and range logic behind the timeline's keys and buttons."""

    def __init__(self, ctx: EditorContext, playback: Playback) -> None:
        self.ctx = ctx
        self.playback = playback

    def _go(self, frame: float) -> None:
        self.playback.pause()
        self.ctx.set_frame(frame)

    def step(self, delta: int, wrap: bool = True) -> None:
        first, last = self.ctx.doc.frame_range
        frame = int(round(self.ctx.frame)) + delta
        if wrap:
            span = last - first + 1
            frame = first + (frame - first) % span if span > 0 else first
        else:
            frame = min(max(frame, first), last)
        self._go(float(frame))

    def to_start(self) -> None:
        self._go(float(self.ctx.doc.frame_range[0]))

    def to_end(self) -> None:
        self._go(float(self.ctx.doc.frame_range[1]))

    def next_key(self) -> None:
        keys = key_frames(self.ctx)
        i = bisect.bisect_right(keys, self.ctx.frame + 1e-6)
        if i < len(keys):
            self._go(keys[i])

    def previous_key(self) -> None:
        keys = key_frames(self.ctx)
        i = bisect.bisect_left(keys, self.ctx.frame - 1e-6)
        if i > 0:
            self._go(keys[i - 1])

    def change_length(self, delta: int) -> None:
        doc = self.ctx.doc
        first, last = doc.frame_range
        new_last = last + delta
        if new_last - first < RANGE_STEP and delta < 0:
            return  # the reference only shortens a range longer than 100 frames
        self.ctx.push(Macro("Timeline Length", [SetParameter(doc, "frame_end", new_last)]))
        if self.ctx.frame > new_last:
            self.ctx.set_frame(float(new_last))


def _make_actions(window: MainWindow, playback: Playback, control: TimelineController) -> dict[str, QAction]:
    style = window.style()
    from PySide6.QtWidgets import QStyle

    def action(name: str, text: str, slot: object, keys: list[str], icon: QStyle.StandardPixmap | None = None,
               context: Qt.ShortcutContext = Qt.ShortcutContext.WidgetWithChildrenShortcut) -> QAction:
        a = QAction(text, window)
        a.setObjectName(name)
        if icon is not None:
            a.setIcon(style.standardIcon(icon))
        if keys:
            a.setShortcuts([QKeySequence(k) for k in keys])
            a.setShortcutContext(context)
            a.setAutoRepeat(True)
        a.triggered.connect(lambda _checked=False: slot())  # type: ignore[operator]
        return a

    def other_player() -> object | None:
        """The 3D viewport's clip controls when they are the ones playing."""
        panel = getattr(window, "viewport_panel", None)
        controls = getattr(panel, "controls", None)
        return controls if getattr(controls, "playing", False) else None

    def play_pause() -> None:
        # The Play button shows "Pause" while any player plays (ctx.playingChanged), so
        # Space / Play must pause the 3D clip controls too, not start the timeline over them.
        clip = other_player()
        if clip is not None:
            clip.set_playing(False)  # type: ignore[attr-defined]
        else:
            playback.toggle()

    def stop() -> None:
        clip = other_player()
        if clip is not None:
            clip.set_playing(False)  # type: ignore[attr-defined]
        playback.stop()

    sp = QStyle.StandardPixmap
    actions = {
        "actionPlay": action("actionPlay", "Play / Pause", play_pause, ["Space"], sp.SP_MediaPlay,
                             Qt.ShortcutContext.WindowShortcut),
        "actionStop": action("actionStop", "Stop", stop, [], sp.SP_MediaStop),
        "actionRewind": action("actionRewind", "Rewind", control.to_start, ["Home", "Up"], sp.SP_MediaSkipBackward),
        "actionEnd": action("actionEnd", "Go to End", control.to_end, ["End", "Down"], sp.SP_MediaSkipForward),
        "actionStepBack": action("actionStepBack", "Step Back", lambda: control.step(-1), ["Left"],
                                 sp.SP_MediaSeekBackward),
        "actionStepForward": action("actionStepForward", "Step Forward", lambda: control.step(1), ["Right"],
                                    sp.SP_MediaSeekForward),
        "actionStepBack10": action("actionStepBack10", "Back 10 Frames", lambda: control.step(-10),
                                   ["Shift+Left"]),
        "actionStepForward10": action("actionStepForward10", "Forward 10 Frames",
                                      lambda: control.step(10), ["Shift+Right"]),
        "actionPreviousKey": action("actionPreviousKey", "Previous Key", control.previous_key, ["Alt+Left"]),
        "actionNextKey": action("actionNextKey", "Next Key", control.next_key, ["Alt+Right"]),
        "actionShorterRange": action("actionShorterRange", "Shorten Range by 100", lambda: control.change_length(
            -RANGE_STEP), ["["]),
        "actionLongerRange": action("actionLongerRange", "Lengthen Range by 100", lambda: control.change_length(
            RANGE_STEP), ["]"]),
        "actionLoop": action("actionLoop", "Loop", lambda: None, [], sp.SP_BrowserReload),
    }
    actions["actionPlay"].setAutoRepeat(False)
    loop = actions["actionLoop"]
    loop.setCheckable(True)
    loop.setChecked(playback.loop)
    loop.toggled.connect(playback.set_loop)
    play = actions["actionPlay"]

    def on_playing(playing: bool) -> None:
        play.setIcon(style.standardIcon(sp.SP_MediaPause if playing else sp.SP_MediaPlay))
        play.setText("Pause" if playing else "Play")

    window.ctx.playingChanged.connect(on_playing)
    return actions


#: The auto-key button: red while on (Blender's record button).
AUTOKEY_STYLE = ("QToolButton#autoKeyButton:checked { background-color: rgb(200, 30, 30); color: white; "
                 "border: 1px solid rgb(120, 0, 0); border-radius: 3px; }")


def _record_icon() -> QIcon:
    icon = QIcon()
    for state, color in ((QIcon.State.On, QColor(230, 30, 30)), (QIcon.State.Off, QColor(130, 130, 130))):
        pixmap = QPixmap(16, 16)
        pixmap.fill(Qt.GlobalColor.transparent)
        p = QPainter(pixmap)
        p.setRenderHint(QPainter.RenderHint.Antialiasing, True)
        p.setPen(QPen(QColor(255, 255, 255) if state == QIcon.State.On else QColor(90, 90, 90), 1))
        p.setBrush(QBrush(color))
        p.drawEllipse(QRectF(2.5, 2.5, 11, 11))
        p.end()
        icon.addPixmap(pixmap, QIcon.Mode.Normal, state)
    return icon


def make_autokey_action(ctx: EditorContext, parent: QWidget) -> QAction:
    """The checkable auto-key action (``actionAutoKey``), kept in step with the document:
    the toggle is the project's (``document.pose.autokey``), a new or opened project
    brings its own."""
    action = QAction("Auto-Key", parent)
    action.setObjectName("actionAutoKey")
    action.setCheckable(True)
    action.setIcon(_record_icon())
    action.setToolTip("Auto-key: when on (red), posing keys at once; when off, posing only shows the pose "
                      "until the frame changes, and S / I (Shift+S: the whole character) keys it")
    action.setChecked(pose.autokey(ctx.doc))
    action.toggled.connect(lambda on: pose.set_autokey(ctx.doc, on))
    ctx.documentReset.connect(lambda: action.setChecked(pose.autokey(ctx.doc)))
    return action


#: Widgets (by object name) that get the timeline's keys when they have the focus. Trees,
#: lists and sliders (the Joints dock, the curve editor's channel tree) keep their arrow keys.
KEY_TARGETS = ("rigEditorView", "viewport3d", "curvePlot")


def add_timeline_keys(window: MainWindow, widget: QWidget) -> None:
    """Give ``widget`` the timeline's keys (arrows, Home/End, [ ]) while it has the focus.

    Editors installed after the timeline call this themselves; editors installed before it
    are found by object name (:data:`KEY_TARGETS`) when the timeline is installed.
    """
    actions = getattr(window, "timeline_actions", None)
    if actions:
        present = set(widget.actions())
        widget.addActions([a for a in actions.values() if a not in present])


def install(window: MainWindow) -> None:
    ctx = window.ctx
    playback = Playback(ctx, window)
    control = TimelineController(ctx, playback)
    actions = _make_actions(window, playback, control)
    autokey = make_autokey_action(ctx, window)
    panel = TimelinePanel(ctx, playback, {**actions, "actionAutoKey": autokey})
    panel.addActions(list(actions.values()))
    window.autokey_action = autokey  # type: ignore[attr-defined]
    window.edit_menu.addAction(autokey)
    window.playback = playback  # type: ignore[attr-defined]
    window.timeline_control = control  # type: ignore[attr-defined]
    window.timeline_actions = actions  # type: ignore[attr-defined]
    window.timeline_dock = window.add_dock(  # type: ignore[attr-defined]
        "timelineDock", "Timeline", panel, Qt.DockWidgetArea.BottomDockWidgetArea)
    menu = window.view_menu.addMenu("&Playback")
    menu.setObjectName("menuPlayback")
    for a in actions.values():
        menu.addAction(a)
    window.addAction(actions["actionPlay"])
    for name in KEY_TARGETS:
        target = window.findChild(QWidget, name)
        if target is not None:
            add_timeline_keys(window, target)

    def update_rate(_frame: float, _skipped: int) -> None:
        panel.fps_label.setText(f"{playback.measured_fps():.0f} fps, {playback.dropped_frames} dropped")

    playback.ticked.connect(update_rate)

    def show_problems(messages: list[str]) -> None:
        if messages:
            window.statusBar().showMessage("Simulation stopped: " + messages[0])
        else:
            window.statusBar().clearMessage()

    panel.timeline.cache_bar.problemsChanged.connect(show_problems)
    view3d = getattr(window, "viewport3d", None)
    if view3d is not None:  # the cloth cache's worker reports through the 3D view
        view3d.clothProgressChanged.connect(lambda _progress: panel.timeline.cache_bar.refresh())
    # Stop playing when the document is replaced.
    ctx.documentReset.connect(playback.pause)
