"""Driving the 3D view's cloth simulations, which never run on the UI thread.

A :class:`~qtanimator.document.cloth_worker.ClothWorker` fills the document's cloth caches in
the background (the view draws the newest frame there and never waits), and the interactive
cloth is a :class:`~qtanimator.document.live_cloth.LiveCloths` stepping in real time on its
own thread. A timer polls both and repaints when something new is there; the Cloth dock
hears the progress (``clothProgressChanged``). Keys W/A/S/D/Q/E move the live cloth's pins
(CSE169), Z/C rotate them, P pauses it, Shift+R resets it; a left drag on it grabs it.
"""

from __future__ import annotations

import math

from PySide6.QtCore import QElapsedTimer, Qt, QTimer

from qtanimator.document.cloth_worker import cloth_worker
from qtanimator.document.document import Document
from qtanimator.document.live_cloth import LiveCloths
from qtanimator.ui.view3d_base import ViewPart

#: Cloth pin moves per key press: metres and radians.
PIN_STEP = 0.05
PIN_TURN = math.radians(5.0)
#: Keyed by the ``int`` that ``QKeyEvent.key()`` returns (``Qt.Key`` is an IntEnum).
PIN_KEYS: dict[int, tuple[float, float, float]] = {
    # As the CSE169 cloth project: W/S up/down (y), A/D left/right (x), Q/E in/out (z).
    Qt.Key.Key_W: (0.0, PIN_STEP, 0.0), Qt.Key.Key_S: (0.0, -PIN_STEP, 0.0),
    Qt.Key.Key_A: (-PIN_STEP, 0.0, 0.0), Qt.Key.Key_D: (PIN_STEP, 0.0, 0.0),
    Qt.Key.Key_Q: (0.0, 0.0, -PIN_STEP), Qt.Key.Key_E: (0.0, 0.0, PIN_STEP),
}
PIN_TURNS: dict[int, float] = {Qt.Key.Key_Z: PIN_TURN, Qt.Key.Key_C: -PIN_TURN}
#: The live cloth's fixed simulation step (seconds).
SIM_DT = 1.0 / 60.0


class LiveClothDriving(ViewPart):
    """The cloth threads of the view: started with it, polled while they run, stopped with it."""

    #: How often the simulations are polled while they run (ms).
    POLL_MS = 16
    #: How often the progress is announced while the worker runs (ms).
    PROGRESS_MS = 100

    #: The last paint showed an earlier cloth frame (still simulating).
    cloth_stale: bool

    def _start_simulations(self, doc: Document) -> None:
        """Make the live cloths and the cache worker, and the timer polling them (``__init__``)."""
        self.live = LiveCloths(SIM_DT)
        self.cloth_worker = cloth_worker(doc)
        self.cloth_stale = False
        self._seen_live = -1
        self._seen_worker = -1
        self._progress_clock = QElapsedTimer()
        self._progress_clock.start()
        self._was_busy = False
        self._sim_timer = QTimer(self)
        self._sim_timer.setInterval(self.POLL_MS)
        self._sim_timer.timeout.connect(self._poll_simulations)
        self._sim_timer.start()
        worker, live = self.cloth_worker, self.live

        def stop_threads(*_args: object) -> None:
            # The threads stop with the view (the cache worker starts again when asked).
            worker.shutdown(1.0)
            live.close(1.0)

        self.destroyed.connect(stop_threads)

    def set_live_cloth(self, enabled: bool) -> None:
        changed = enabled != self.live.enabled
        self.live.enabled = enabled
        if enabled:
            self.live.sync(self.ctx.doc)
        self.watch_simulations()
        if changed:
            self.liveClothChanged.emit(enabled)
        self.update()

    def watch_simulations(self) -> None:
        """Poll the cloth threads (until they have nothing new to show)."""
        if not self._sim_timer.isActive():
            self._sim_timer.start()

    def _poll_simulations(self) -> None:
        """Repaint when a simulation thread has something new; announce the progress."""
        live, worker = self.live, self.cloth_worker
        if live.enabled and live.version != self._seen_live:
            self._seen_live = live.version
            self.update()
        busy = worker.busy
        live_errors = tuple(sorted(live.errors.items()))
        if live_errors != getattr(self, "_seen_live_errors", ()):
            self._seen_live_errors = live_errors   # a live cloth blew up: the Cloth dock says why
            self.clothProgressChanged.emit(worker.progress())
        if worker.version != self._seen_worker:
            self._seen_worker = worker.version
            if self.cloth_stale:
                self.update()
            if busy != self._was_busy or self._progress_clock.elapsed() >= self.PROGRESS_MS:
                self._progress_clock.restart()
                self.clothProgressChanged.emit(worker.progress())
        elif busy != self._was_busy:
            self.clothProgressChanged.emit(worker.progress())
        self._was_busy = busy
        if not busy and not live.enabled:
            self._sim_timer.stop()

    def pin_key(self, key: int) -> None:
        """W/A/S/D/Q/E (:data:`PIN_KEYS`) or Z/C (:data:`PIN_TURNS`): move or turn the live
        cloth's pins, switching the live cloth on first."""
        if not self.live.enabled:
            self.set_live_cloth(True)
        if key in PIN_KEYS:
            self.live.move_pins(PIN_KEYS[key])
        else:
            self.live.move_pins((0.0, 0.0, 0.0), (0.0, PIN_TURNS[key], 0.0))
        self.update()

    def reset_cloth(self) -> None:
        """Shift+R (and the Cloth dock's Reset): every live cloth back to its rest shape."""
        self.live.reset()
        self.update()


__all__ = ["PIN_KEYS", "PIN_STEP", "PIN_TURN", "PIN_TURNS", "SIM_DT", "LiveClothDriving"]
