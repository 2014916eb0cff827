"""Playback that follows the wall clock at the project's frame rate.

The frame shown is always ``start + floor(elapsed · fps)`` counted from when play was
pressed, so a slow frame makes the next tick skip ahead (frames are dropped) instead of
the animation slowing down (drifting). The clock is a :class:`QElapsedTimer`; a precise
QTimer wakes the loop about twice per frame.
"""

from __future__ import annotations

import math

from PySide6.QtCore import QElapsedTimer, QObject, Qt, QTimer, Signal

from qtanimator.ui.context import EditorContext


def playback_frame(start_frame: float, elapsed_s: float, fps: float, first: int, last: int,
                   loop: bool) -> tuple[float, bool]:
    """The frame to show ``elapsed_s`` seconds after play began at ``start_frame``.

    Returns ``(frame, still_playing)``. Without loop playback stops on ``last``; with loop
    it wraps to ``first`` after ``last`` (frame ``last`` is shown, as in the reference).
    """
    advanced = math.floor(elapsed_s * fps + 1e-9)
    frame = math.floor(start_frame) + advanced
    if frame <= last:
        return float(frame), True
    if not loop:
        return float(last), False
    span = last - first + 1
    if span <= 0:
        return float(first), True
    # Frames beyond the end wrap onto [first, last]; the first lap may begin mid-range.
    return float(first + (frame - first) % span), True


class Playback(QObject):
    """Play / pause / stop / loop over the document's frame range."""

    #: Emitted with each frame playback shows, and the number of frames skipped to keep time.
    ticked = Signal(float, int)

    def __init__(self, ctx: EditorContext, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self.ctx = ctx
        self.loop = True
        self.dropped_frames = 0
        self.shown_frames = 0
        self._clock = QElapsedTimer()
        self._timer = QTimer(self)
        self._timer.setTimerType(Qt.TimerType.PreciseTimer)
        self._timer.timeout.connect(self._tick)
        ctx.frameChanged.connect(self._on_frame_changed)
        ctx.playingChanged.connect(self._on_other_playing)
        self._announcing = False
        self._start_frame = 0.0
        self._origin_frame = 0.0
        self._playing = False
        self._last_shown = 0.0

    # ----------------------------------------------------------------- state
    @property
    def playing(self) -> bool:
        return self._playing

    def measured_fps(self) -> float:
        """Frames shown per wall-clock second since play was pressed."""
        elapsed = self._clock.nsecsElapsed() * 1e-9 if self._clock.isValid() else 0.0
        return self.shown_frames / elapsed if elapsed > 0 else 0.0

    def set_loop(self, loop: bool) -> None:
        if loop != self.loop:
            self.loop = loop
            if self._playing:
                self._restart_clock()

    def play(self) -> None:
        if self._playing:
            return
        first, last = self.ctx.doc.frame_range
        if self.ctx.frame >= last or self.ctx.frame < first:
            self.ctx.set_frame(float(first))  # PLAY at the end starts over
        self._origin_frame = self.ctx.frame
        self._restart_clock()
        self._playing = True
        self.dropped_frames = 0
        self.shown_frames = 0
        interval = max(1, int(500.0 / max(self.ctx.doc.fps, 1.0)))
        self._timer.start(interval)
        self._announce(True)

    def pause(self) -> None:
        if not self._playing:
            return
        self._timer.stop()
        self._playing = False
        self._announce(False)

    def _announce(self, playing: bool) -> None:
        self._announcing = True
        try:
            self.ctx.playingChanged.emit(playing)
        finally:
            self._announcing = False

    def _on_other_playing(self, playing: bool) -> None:
        # Another editor (the 3D viewport's clip player) started playing: only one plays.
        if playing and not self._announcing and self._playing:
            self.pause()

    def toggle(self) -> None:
        if self._playing:
            self.pause()
        else:
            self.play()

    def stop(self) -> None:
        """Stop and return to the frame where playback began."""
        was_playing = self._playing
        origin = self._origin_frame
        self.pause()
        if was_playing:
            self.ctx.set_frame(origin)

    def _restart_clock(self) -> None:
        self._start_frame = self.ctx.frame
        self._last_shown = self.ctx.frame
        self.shown_frames = 0
        self._clock.start()

    def _on_frame_changed(self, frame: float) -> None:
        # Someone else moved the frame while playing (a key, a click): play on from there.
        if self._playing and frame != self._last_shown:
            self._restart_clock()

    # ------------------------------------------------------------------ loop
    def _tick(self) -> None:
        first, last = self.ctx.doc.frame_range
        elapsed = self._clock.nsecsElapsed() * 1e-9
        frame, keep_playing = playback_frame(self._start_frame, elapsed, self.ctx.doc.fps, first, last,
                                             self.loop)
        if frame == self._last_shown and keep_playing:
            return
        skipped = int(frame - self._last_shown) - 1 if frame > self._last_shown else 0
        if skipped > 0:
            self.dropped_frames += skipped
        self._last_shown = frame
        self.shown_frames += 1
        self.ctx.set_frame(frame)
        self.ticked.emit(frame, max(skipped, 0))
        if not keep_playing:
            self.pause()
