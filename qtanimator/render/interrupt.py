"""Clean exits from a render: SIGTERM and SIGINT become an exception.

Python's default SIGTERM ends the process at once, so ``finally`` blocks, context managers
and ``atexit`` never run: a partial temporary video stays beside the output and the private
Xvfb (:mod:`qtanimator.render.xvfb`) outlives its parent. Inside :func:`interrupt_on_signals`
both signals raise :class:`RenderInterrupted` in the main thread instead, so the writers
remove their temporary files (the existing output is never replaced) and the process exits
normally, which stops the Xvfb. Imports no Qt.
"""

from __future__ import annotations

import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType
from typing import Any

HANDLED = (signal.SIGTERM, signal.SIGINT)


class RenderInterrupted(KeyboardInterrupt):
    """A render ended by a signal. A KeyboardInterrupt (not an Exception), so ``except
    Exception`` does not swallow it while ``finally`` and ``except BaseException`` clean up."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum

    @property
    def name(self) -> str:
        return signal.Signals(self.signum).name

    @property
    def exit_status(self) -> int:
        """``128 + signal``, as a shell reports a process ended by that signal."""
        return 128 + self.signum


@contextmanager
def interrupt_on_signals() -> Iterator[None]:
    """SIGTERM / SIGINT raise :class:`RenderInterrupted` while the block runs.

    Only the first signal raises; later ones are ignored so they cannot break the cleanup
    that the first one started. The previous handlers come back afterwards. Outside the
    main thread (where Python cannot set handlers) the block runs unchanged.

    The exception is raised wherever the main thread is, which may be inside a call into Qt:
    PySide6 6.8 then reports another error (``SystemError: ... bad argument to internal
    function``) with the RenderInterrupted lost. Whatever leaves the block after a signal
    fired is therefore turned back into :class:`RenderInterrupted` for that signal.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    fired: list[int] = []

    def handler(signum: int, frame: FrameType | None) -> None:
        if fired:
            return
        fired.append(signum)
        raise RenderInterrupted(signum)

    previous = {s: signal.signal(s, handler) for s in HANDLED}
    try:
        yield
    except RenderInterrupted:
        raise
    except Exception as exc:
        if fired:
            raise RenderInterrupted(fired[0]) from exc
        raise
    finally:
        _restore(previous)


@contextmanager
def signals_held() -> Iterator[None]:
    """SIGTERM / SIGINT wait until the block ends, then raise :class:`RenderInterrupted`.

    For native imports: a KeyboardInterrupt raised while PySide6 initialises aborts the
    interpreter ("libshiboken/signature: could not initialize part 2", exit 134), which a
    Ctrl+C in the first second of a render on a loaded machine did. Outside the main thread
    the block runs unchanged.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    held: list[int] = []

    def handler(signum: int, frame: FrameType | None) -> None:
        held.append(signum)

    previous = {s: signal.signal(s, handler) for s in HANDLED}
    try:
        yield
    finally:
        _restore(previous)
    if held:
        raise RenderInterrupted(held[0])


def _restore(previous: dict[signal.Signals, Any]) -> None:
    for s, old in previous.items():
        signal.signal(s, old if old is not None else signal.SIG_DFL)


def report_interrupted(exc: RenderInterrupted) -> int:
    """Say that the render was stopped (on stderr) and return its exit status."""
    print(f"qtanimator render: stopped by {exc.name}; a GIF or video output was not written "
          "(an existing file is left as it was)", file=sys.stderr)
    return exc.exit_status
