"""The clip controls under the 3D view: the clip a glTF character plays, play / pause, speed,
play mode and a progress bar over the document's frame range (click it to seek).

Playing here drives ``ctx.frame`` (every editor follows); starting it pauses the timeline's
playback, and the timeline starting pauses this (``ctx.playingChanged``).
"""

from __future__ import annotations

from typing import Any

from PySide6.QtCore import QElapsedTimer, Qt, QTimer
from PySide6.QtGui import QMouseEvent
from PySide6.QtWidgets import QComboBox, QDoubleSpinBox, QHBoxLayout, QLabel, QProgressBar, QToolButton, QWidget

from qtanimator.core.clip import ClipPlayer, PlayMode
from qtanimator.ui.clip_picker import ClipPicker
from qtanimator.ui.context import EditorContext


class ClipControls(QWidget):
    """The clip picker (:class:`~qtanimator.ui.clip_picker.ClipPicker`), play / pause, speed,
    play mode and a progress bar over the document's frame range, synced with ``ctx.frame``
    (the timeline sees every frame it shows)."""

    MODES = ("loop", "once", "ping-pong", "continue")

    def __init__(self, ctx: EditorContext, parent: QWidget | None = None, window: Any = None) -> None:
        super().__init__(parent)
        self.ctx = ctx
        self.window_ = window
        self._announcing = False
        self.player = ClipPlayer(0.0, 1.0)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(4, 2, 4, 2)
        self.play_button = QToolButton(self)
        self.play_button.setObjectName("viewportPlay")
        self.play_button.setCheckable(True)
        self.play_button.setText("Play")
        self.play_button.toggled.connect(self.set_playing)
        self.speed = QDoubleSpinBox(self)
        self.speed.setObjectName("viewportSpeed")
        self.speed.setRange(-4.0, 4.0)
        self.speed.setSingleStep(0.25)
        self.speed.setValue(1.0)
        self.speed.setSuffix("×")
        self.speed.valueChanged.connect(self._on_speed)
        self.mode = QComboBox(self)
        self.mode.setObjectName("viewportPlayMode")
        self.mode.addItems(list(self.MODES))
        self.mode.currentTextChanged.connect(self._on_mode)
        self.progress = QProgressBar(self)
        self.progress.setObjectName("viewportProgress")
        self.progress.setRange(0, 1000)
        self.progress.setTextVisible(True)
        self.progress.setFormat("%p%")
        self.progress.mousePressEvent = self._seek_click  # type: ignore[method-assign]
        # The clip the selected (or only) glTF character plays, before Play (the progress bar
        # runs over its duration); hidden while no character has clips. Here rather than in the
        # display bar above, which already fills the default window's width.
        self.clip = ClipPicker(ctx, self)
        self.clip.combo.setObjectName("viewportClip")
        layout.addWidget(self.clip)
        layout.addWidget(self.play_button)
        layout.addWidget(QLabel("Speed", self))
        layout.addWidget(self.speed)
        layout.addWidget(self.mode)
        layout.addWidget(self.progress, 1)
        self._clock = QElapsedTimer()
        self._timer = QTimer(self)
        self._timer.setTimerType(Qt.TimerType.PreciseTimer)
        self._timer.setInterval(8)
        self._timer.timeout.connect(self._tick)
        self._setting_frame = False
        ctx.frameChanged.connect(self._on_frame)
        ctx.playingChanged.connect(self._on_other_playing)
        self._on_frame(ctx.frame)

    def clip_range(self) -> tuple[float, float]:
        first, last = self.ctx.doc.frame_range
        return self.ctx.doc.frame_to_time(first), self.ctx.doc.frame_to_time(max(last, first))

    @property
    def playing(self) -> bool:
        return self._timer.isActive()

    def set_playing(self, playing: bool, announce: bool = True) -> None:
        """Start or stop playback; ``announce`` tells the other editors (ctx.playingChanged)."""
        if playing == self.playing:
            self.play_button.setChecked(playing)
            return
        if playing:
            other = getattr(self.window_, "playback", None)   # the timeline's playback
            if other is not None and getattr(other, "playing", False):
                other.pause()
            start, end = self.clip_range()
            self.player = ClipPlayer(start, end, self.mode.currentText(), self.speed.value())
            t = self.ctx.time
            if self.mode.currentText() == "once" and t >= end:
                t = start
            self.player.elapsed = t - start if start <= t <= end or self.mode.currentText() == "continue" else 0.0
            self._clock.start()
            self._timer.start()
        else:
            self._timer.stop()
        self.play_button.setChecked(playing)
        self.play_button.setText("Pause" if playing else "Play")
        if announce:
            self._announcing = True
            try:
                self.ctx.playingChanged.emit(playing)
            finally:
                self._announcing = False

    def step(self, dt: float) -> None:
        """Advance playback by ``dt`` wall seconds (the timer calls this; tests may too)."""
        t = self.player.advance(dt)
        self._setting_frame = True
        try:
            self.ctx.set_frame(self.ctx.doc.time_to_frame(t))
        finally:
            self._setting_frame = False
        if self.player.finished:
            self.set_playing(False)

    def _tick(self) -> None:
        self.step(self._clock.restart() / 1000.0)

    def _on_speed(self, value: float) -> None:
        self.player.speed = float(value)

    def _on_mode(self, mode: str) -> None:
        t = self.player.time
        self.player.mode = PlayMode(mode)
        self._seek_time(t)

    def _seek_time(self, t: float) -> None:
        start = self.player.start
        self.player.elapsed = max(t - start, 0.0) if self.player.mode.value != "continue" else t - start

    def _on_frame(self, frame: float) -> None:
        start, end = self.clip_range()
        t = self.ctx.doc.frame_to_time(frame)
        u = 0.0 if end <= start else (t - start) / (end - start)
        self.progress.setValue(int(round(1000 * min(max(u, 0.0), 1.0))))
        if not self._setting_frame and self.playing:
            self._seek_time(t)

    def _on_other_playing(self, playing: bool) -> None:
        if playing and self.playing and not self._announcing:
            self.set_playing(False, announce=False)

    def _seek_click(self, event: QMouseEvent) -> None:
        start, end = self.clip_range()
        u = min(max(event.position().x() / max(self.progress.width(), 1), 0.0), 1.0)
        self.ctx.set_frame(round(self.ctx.doc.time_to_frame(start + u * (end - start))))


__all__ = ["ClipControls"]
