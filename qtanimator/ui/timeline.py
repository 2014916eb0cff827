"""The timeline: frame ruler, key ticks, the current-frame cursor, the simulation cache
bar, the play controls and the auto-key button.

Auto-key (``autoKeyButton`` / ``actionAutoKey``, red while on, like Blender's record
button): on, posing keys at once; off, a drag only poses and S keys (see
:mod:`qtanimator.document.pose`). Per project, saved with it as view state.

Keys follow the reference animator: Space play / pause, ←/→ step and Shift+←/→ ±10
frames (both wrapping around the range), Alt+←/→ previous / next key, Home or ↑ start, End or ↓ end, ``[`` / ``]``
shorten / lengthen the range by 100 frames (an undoable parameter change).

This module holds the panel, the frame-stepping controller, the actions and ``install``;
the ruler and the cache bar are :mod:`qtanimator.ui.timeline_widget`.
"""

from __future__ import annotations

import bisect
from typing import TYPE_CHECKING

from PySide6.QtCore import QRectF, Qt
from PySide6.QtGui import QAction, QBrush, QColor, QIcon, QKeySequence, QPainter, QPen, QPixmap
from PySide6.QtWidgets import QHBoxLayout, QLabel, QSpinBox, QToolButton, QVBoxLayout, QWidget

from qtanimator.document import pose
from qtanimator.document.commands import Macro, SetParameter
from qtanimator.ui.context import EditorContext
from qtanimator.ui.playback import Playback, playback_frame
from qtanimator.ui.timeline_widget import (
    CACHE_BAR_HEIGHT,
    CACHE_COLOR,
    FAILED_COLOR,
    CacheBar,
    FrameCache,
    TimelineWidget,
    key_frames,
)

if TYPE_CHECKING:
    from qtanimator.ui.main_window import MainWindow

__all__ = ["CACHE_BAR_HEIGHT", "CACHE_COLOR", "FAILED_COLOR", "CacheBar", "FrameCache", "Playback",
           "TimelineController", "TimelinePanel", "TimelineWidget", "install", "key_frames", "make_autokey_action",
           "playback_frame"]

RANGE_STEP = 100

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
