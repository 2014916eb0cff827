"""Atomic file writes: a failed save leaves the old file intact."""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterable
from pathlib import Path

# Read once at import (os.umask can only be read by setting it, which is not thread-safe).
_UMASK = os.umask(0o022)
os.umask(_UMASK)


def write_atomic(path: str | os.PathLike[str], data: bytes) -> None:
    """Write ``data`` to a temporary file beside ``path``, flush it, then ``os.replace``."""
    write_chunks_atomic(path, (data,))


def write_chunks_atomic(path: str | os.PathLike[str], chunks: Iterable[bytes]) -> None:
    """Write every chunk to a temporary file beside ``path``, flush and sync it, then swap
    it in with ``os.replace``; the old file's permissions are kept.

    The bytes are written as they come, so a project serialised channel by channel never
    sits whole in memory and a writer on a worker thread never holds the GIL for long. When
    the chunks raise (a value JSON cannot store, a background save called off) the
    temporary file is removed, the exception goes on and the old file is left as it was.
    The temporary file's name carries this process's id, so a save killed half-way
    (``kill -9``, a power cut) leaves a file the next save recognises and removes.
    """
    target = Path(path)
    remove_stale_temporaries(target)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.{os.getpid()}.", suffix=".tmp", dir=target.parent or ".")
    try:
        # mkstemp makes the file private (0600); a save must not change who may read it.
        os.chmod(tmp, mode_for(target))
        with os.fdopen(fd, "wb") as fh:
            for chunk in chunks:
                fh.write(chunk)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, target)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def remove_stale_temporaries(target: Path) -> list[Path]:
    """Delete the temporary files of saves of ``target`` whose process no longer runs;
    returns what was removed. Temporaries of running processes are left alone."""
    removed: list[Path] = []
    prefix = f".{target.name}."
    try:
        candidates = [p for p in (target.parent or Path(".")).iterdir()
                      if p.name.startswith(prefix) and p.name.endswith(".tmp")]
    except OSError:
        return removed
    for p in candidates:
        pid_text = p.name[len(prefix):].split(".", 1)[0]
        if not pid_text.isdigit() or _running(int(pid_text)):
            continue
        try:
            p.unlink()
            removed.append(p)
        except OSError:
            pass
    return removed


def _running(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # it exists but belongs to someone else
        return True
    return True


def mode_for(path: str | os.PathLike[str]) -> int:
    """The permission bits a new version of ``path`` should get: the old file's, or the
    mode a plain ``open()`` would give under the umask."""
    try:
        return os.stat(path).st_mode & 0o7777
    except OSError:
        return 0o666 & ~_UMASK


def write_text_atomic(path: str | os.PathLike[str], text: str) -> None:
    write_atomic(path, text.encode("utf-8"))
