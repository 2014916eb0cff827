"""The program's log: a rotating file under the XDG state folder, and stderr.

``$XDG_STATE_HOME/qtanimator/qtanimator.log`` (``~/.local/state`` when the variable is
unset or not absolute, as the XDG Base Directory specification says), at most
:data:`MAX_BYTES` per file and :data:`BACKUPS` older files. Help ▸ Report a Problem opens
that folder; the GUI's exception hook writes every unexpected error there.
"""

from __future__ import annotations

import logging
import logging.handlers
import os
import sys
from pathlib import Path

LOG_NAME = "qtanimator.log"
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


def close_logging() -> None:
    """Remove and close the handlers :func:`setup_logging` added (tests; the end of a run)."""
    root = logging.getLogger()
    for handler in _handlers:
        root.removeHandler(handler)
        handler.close()
    _handlers.clear()
