"""The program's log: a rotating file under the XDG state folder, and stderr.

``$XDG_STATE_HOME/qtanimator/qtanimator.log`` (``~/.local/state`` when the variable is
unset or not absolute, as the XDG Base Directory specification says), at most
:data:`MAX_BYTES` per file and :data:`BACKUPS` older files. Help ▸ Report a Problem opens
that folder; the GUI's exception hook writes every unexpected error there.
"""

from __future__ import annotations

import faulthandler
import logging
import logging.handlers
import os
import sys
from pathlib import Path
from typing import TextIO

LOG_NAME = "qtanimator.log"
#: Native crash traces of the GUI (faulthandler: a segfault or an abort in Qt, OpenGL or the
#: interpreter leaves the Python stack of every thread here; issue 30).
CRASH_LOG_NAME = "crash.log"
MAX_BYTES = 1_000_000
BACKUPS = 3
FORMAT = "%(asctime)s %(levelname)s %(name)s: %(message)s"

#: The handlers :func:`setup_logging` added, so that a second call replaces them.
_handlers: list[logging.Handler] = []


def state_dir() -> Path:
    """``$XDG_STATE_HOME`` or ``~/.local/state``."""
    value = os.environ.get("XDG_STATE_HOME", "")
    if value and Path(value).is_absolute():
        return Path(value)
    return Path.home() / ".local" / "state"


def log_dir() -> Path:
    """The folder of the log files (not created here)."""
    return state_dir() / "qtanimator"


def log_path() -> Path:
    return log_dir() / LOG_NAME


def setup_logging(verbose: bool = False) -> Path | None:
    """Log to the rotating file (everything from INFO, DEBUG with ``verbose``) and to stderr
    (warnings, or everything with ``verbose``). Returns the log file, or None when its folder
    cannot be made (then only stderr is used, and a one-line warning says why)."""
    close_logging()
    root = logging.getLogger()
    level = logging.DEBUG if verbose else logging.INFO
    root.setLevel(level)
    console = logging.StreamHandler(sys.stderr)
    console.setLevel(logging.DEBUG if verbose else logging.WARNING)
    console.setFormatter(logging.Formatter("qtanimator: %(levelname)s %(name)s: %(message)s"))
    _add(root, console)
    path = log_path()
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        file_handler = logging.handlers.RotatingFileHandler(path, maxBytes=MAX_BYTES, backupCount=BACKUPS,
                                                            encoding="utf-8", delay=True)
    except OSError as exc:
        logging.getLogger(__name__).warning("no log file (%s): %s", path, exc.strerror or exc)
        return None
    file_handler.setLevel(level)
    file_handler.setFormatter(logging.Formatter(FORMAT))
    _add(root, file_handler)
    return path


def _add(root: logging.Logger, handler: logging.Handler) -> None:
    root.addHandler(handler)
    _handlers.append(handler)


def enable_crash_traces(to_log_folder: bool) -> Path | None:
    """Make a native crash (SIGSEGV, SIGABRT, SIGFPE, SIGBUS, SIGILL) print the Python stack of
    every thread before the process dies. On stderr by default (a terminal, CI's log); with
    ``to_log_folder`` (the GUI, often started without a terminal) appended to
    :data:`CRASH_LOG_NAME` beside the log file, which Help ▸ Report a Problem opens. Returns
    that file, or None when the traces go to stderr."""
    if to_log_folder:
        path = log_dir() / CRASH_LOG_NAME
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            # Kept open for the life of the process: faulthandler writes to its descriptor
            # from the signal handler, where nothing can be opened.
            stream = open(path, "a", encoding="utf-8")
        except OSError as exc:
            logging.getLogger(__name__).warning("no crash log (%s): %s", path, exc.strerror or exc)
        else:
            global _crash_stream
            if _crash_stream is not None:
                _crash_stream.close()
            _crash_stream = stream
            faulthandler.enable(file=stream, all_threads=True)
            return path
    try:
        faulthandler.enable(file=sys.stderr, all_threads=True)
    except (AttributeError, ValueError, OSError):
        pass  # no stderr, or one without a file descriptor (captured by a test runner)
    return None


_crash_stream: TextIO | None = None


def close_logging() -> None:
    """Remove and close the handlers :func:`setup_logging` added (tests; the end of a run)."""
    root = logging.getLogger()
    for handler in _handlers:
        root.removeHandler(handler)
        handler.close()
    _handlers.clear()
