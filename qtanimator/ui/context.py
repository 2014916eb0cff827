"""The editing context every editor shares: document, undo stack, current frame, selection.

Editors talk to each other only through this object: they read the document, push
commands with :meth:`EditorContext.push` or drive a gesture from
:meth:`EditorContext.begin_gesture`, and listen to the signals below.

Change notification: the document announces one :class:`DocumentChange` per command.
Outside gestures the context passes it on at once (``documentChanged``). While a gesture
previews (a drag sends a command per mouse move), the context folds the changes and emits
``documentChanged`` at most once per displayed frame (the frame clock below), so every
view refreshes at most once per frame, from one change that names everything that moved.
"""

from __future__ import annotations

import sys

from PySide6.QtCore import QAbstractEventDispatcher, QCoreApplication, QElapsedTimer, QEvent, QObject, QTimer, Signal
from PySide6.QtGui import QUndoStack

from qtanimator.core.rig2d import Character
from qtanimator.document.character3d_model import Character3D
from qtanimator.document.commands import Command
from qtanimator.document.document import Document, DocumentChange
from qtanimator.document.gesture import Gesture
from qtanimator.document.pendulum_cache import ensure_caches
from qtanimator.document.pose import clear_pending
from qtanimator.document.simulation import (
    pause_workers,
    resume_workers,
    stop_simulations,
    ui_busy,
    ui_idle,
)
from qtanimator.document.simulation import progress as simulation_progress
from qtanimator.ui.key_selection import KeySelection
from qtanimator.ui.undo import push_command, record_command

#: The frame clock's period: views refresh at most once per 60 Hz frame during a gesture.
FRAME_INTERVAL_MS = 16


class _BusyMarker(QObject):
    """Marks the UI thread busy as soon as it delivers an event (an application-wide event
    filter): with the GLib dispatcher the events of one iteration are delivered after
    ``aboutToBlock`` and before ``awake``."""

    def eventFilter(self, _watched: QObject, _event: QEvent) -> bool:
        ui_busy()
        return False


def gate_workers_on_idle() -> bool:
    """Let the simulation workers run while the UI thread's event loop idles (see
    ``document.simulation.ui_idle``): the event dispatcher of the application's thread says
    when it is about to wait and when it woke up. Once per application; False when there is
    no application or dispatcher yet."""
    app = QCoreApplication.instance()
    dispatcher = QAbstractEventDispatcher.instance(app.thread()) if app is not None else None
    if app is None or dispatcher is None:
        return False
    if not dispatcher.property("qtanimatorWorkerGate"):
        # When a worker does run beside a busy UI thread (it waited its longest), hand the
        # interpreter over every millisecond, not every 5 ms (Python's default).
        sys.setswitchinterval(min(sys.getswitchinterval(), 0.001))
        dispatcher.aboutToBlock.connect(ui_idle)
        dispatcher.awake.connect(ui_busy)
        marker = _BusyMarker(app)
        app.installEventFilter(marker)
        dispatcher.setProperty("qtanimatorWorkerGate", True)
    return True


class EditorContext(QObject):
    #: The current frame changed (float frames; the UI shows whole frames).
    frameChanged = Signal(float)
    #: The selected asset / joint changed: (asset id or "", joint name or "").
    selectionChanged = Signal(str, str)
    #: The selected channels changed (list of channel ids).
    channelSelectionChanged = Signal(list)
    #: A document change (a DocumentChange: one per command, one per frame in a gesture).
    documentChanged = Signal(object)
    #: The whole document was replaced (New / Open / Recover).
    documentReset = Signal()
    #: Playback started (True) or stopped (False).
    playingChanged = Signal(bool)
    #: The background simulation added or dropped frames (at most once per frame clock
    #: tick, only while someone watches it: :meth:`watch_simulation`).
    simulationProgressed = Signal()

    def __init__(self, doc: Document | None = None, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self.doc = doc if doc is not None else Document()
        self.undo_stack = QUndoStack(self)
        self._frame = 0.0
        self._selection: tuple[str, str] = ("", "")
        self._channel_selection: list[str] = []
        #: The selected keys, shared by the curve editor and the dope sheet.
        self.key_selection = KeySelection(self)
        self._gestures: list[Gesture] = []
        self._pending: DocumentChange | None = None
        self._since_flush = QElapsedTimer()
        self._since_flush.start()
        self._frame_clock = QTimer(self)
        self._frame_clock.setObjectName("documentFrameClock")
        self._frame_clock.setSingleShot(True)
        self._frame_clock.timeout.connect(self.flush_changes)
        #: How many times ``documentChanged`` was emitted (tests count refreshes with it).
        self.notifications = 0
        ensure_caches(self.doc)  # caches drop invalid frames before views hear of a change
        gate_workers_on_idle()
        self.doc.subscribe(self._on_document_event)
        # Simulation polling: the worker thread cannot touch Qt, so the UI thread compares
        # its revision once per frame while it works (see watch_simulation).
        self._simulation_revision = -1
        self._simulation_poll = QTimer(self)
        self._simulation_poll.setObjectName("simulationPoll")
        self._simulation_poll.setInterval(FRAME_INTERVAL_MS)
        self._simulation_poll.timeout.connect(self._poll_simulation)
        if parent is not None:
            parent.installEventFilter(self)  # the window's close stops the worker threads

    # ---------------------------------------------------------------- document
    def _on_document_event(self, change: DocumentChange) -> None:
        if change.reset:
            self._pending = None
            self._frame_clock.stop()
            self.documentReset.emit()
            return
        self._pending = change if self._pending is None else self._pending.merged(change)
        if not self._gestures:
            self.flush_changes()
        elif not self._frame_clock.isActive():
            wait = max(0, FRAME_INTERVAL_MS - int(self._since_flush.elapsed()))
            self._frame_clock.start(wait)

    def flush_changes(self) -> None:
        """Emit the folded pending change now (if any)."""
        self._frame_clock.stop()
        pending, self._pending = self._pending, None
        if pending:
            if pending.assets:
                self._drop_stale_selection()
            self._since_flush.restart()
            self.notifications += 1
            self.documentChanged.emit(pending)

    def _drop_stale_selection(self) -> None:
        """A change removed the selected asset or joint (an undone "Make Joint", a removed
        character): select what is left before any view hears of the change."""
        asset, joint = self._selection
        if not asset:
            return
        if asset not in self.doc.assets:
            self.select("", "")
            return
        if joint:
            runtime = self.doc.runtime.get(asset)
            names: set[str]
            if isinstance(runtime, Character3D):
                names = set(runtime.joint_keys)
            elif isinstance(runtime, Character):
                names = {j.name for j in runtime.joints}
            else:
                return  # not loaded (or unknown): nothing to check against
            if joint not in names:
                self.select(asset, "")

    def push(self, command: Command) -> None:
        """Do a command and put it on the undo stack (merging drags into one step)."""
        push_command(self.undo_stack, self.doc, command)

    # -------------------------------------------------------------- simulation
    def watch_simulation(self) -> None:
        """Poll the background simulation once per frame until it is idle and emit
        ``simulationProgressed`` when frames arrive. Views call it when they show a frame
        that is not simulated yet."""
        if not self._simulation_poll.isActive():
            self._simulation_poll.start()

    def _poll_simulation(self) -> None:
        revision, busy = simulation_progress(self.doc)
        if revision != self._simulation_revision:
            self._simulation_revision = revision
            self.simulationProgressed.emit()
        elif not busy:
            self._simulation_poll.stop()

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if event.type() == QEvent.Type.Close and watched is self.parent():
            stop_simulations(self.doc)  # they start again if the close is cancelled
        return super().eventFilter(watched, event)

    # ---------------------------------------------------------------- gestures
    def begin_gesture(self, text: str) -> Gesture:
        """Start a gesture (see :mod:`qtanimator.document.gesture`): ``update(command)``
        previews, ``commit()`` is one undo step, ``abort()`` puts everything back.
        While any gesture is active, views refresh at most once per frame."""
        gesture = Gesture(self.doc, text, self._record, on_end=self._gesture_ended)
        self._gestures.append(gesture)
        pause_workers()  # the drag gets the interpreter; simulations catch up at its end
        return gesture

    @property
    def gesture_active(self) -> bool:
        return bool(self._gestures)

    def _record(self, command: Command) -> None:
        record_command(self.undo_stack, self.doc, command)

    def _gesture_ended(self, gesture: Gesture) -> None:
        if gesture in self._gestures:
            self._gestures.remove(gesture)
            resume_workers()
        if not self._gestures:
            self.flush_changes()

    def replace_document(self, new: Document) -> None:
        """Take over ``new`` (already fully loaded) and clear the undo history."""
        for gesture in list(self._gestures):
            gesture.discard()
        self.undo_stack.clear()
        self._selection = ("", "")
        had_channels = bool(self._channel_selection)
        self._channel_selection = []
        self.key_selection.clear()
        self.doc.replace_all(new)
        self.undo_stack.setClean()
        start, _end = self.doc.frame_range
        self.set_frame(float(start))
        self.selectionChanged.emit("", "")
        if had_channels:
            self.channelSelectionChanged.emit([])

    # ------------------------------------------------------------------- time
    @property
    def frame(self) -> float:
        return self._frame

    @property
    def time(self) -> float:
        """Current time in seconds."""
        return self.doc.frame_to_time(self._frame)

    def set_frame(self, frame: float) -> None:
        if frame != self._frame:
            self._frame = float(frame)
            # An unkeyed pose (auto-key off) lasts until the frame changes.
            clear_pending(self.doc)
            self.frameChanged.emit(self._frame)

    # -------------------------------------------------------------- selection
    @property
    def selection(self) -> tuple[str, str]:
        return self._selection

    def select(self, asset: str, joint: str = "") -> None:
        if (asset, joint) != self._selection:
            self._selection = (asset, joint)
            self.selectionChanged.emit(asset, joint)

    @property
    def channel_selection(self) -> list[str]:
        return list(self._channel_selection)

    def select_channels(self, cids: list[str]) -> None:
        if cids != self._channel_selection:
            self._channel_selection = list(cids)
            self.channelSelectionChanged.emit(list(cids))
