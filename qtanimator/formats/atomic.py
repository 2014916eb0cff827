"""Atomic file writes: a failed save leaves the old file intact.

Every save, export and render output goes through :func:`replacing` (directly or through
:func:`write_chunks_atomic`): the bytes go to a hidden temporary file beside the target, are
flushed and synced, and replace the target with ``os.replace``. The temporary name is short
and never derived from the target's (``.qtanim-<pid>-<random><suffix>``), so any name the
filesystem allows for the target can be saved; every error names the target, never the
temporary. Only a regular file (or a new name) is replaced: a folder, a named pipe, a device
or a socket is refused before anything is written, and a symbolic link is written through
to the file it leads to (the link stays a link; docs/decisions.md). The process id in the
temporary's name lets the next save into the same folder remove what a killed save
(``kill -9``, a power cut) left behind.
"""

from __future__ import annotations

import errno
import os
import re
import stat
import tempfile
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path

# Read once at import (os.umask can only be read by setting it, which is not thread-safe).
_UMASK = os.umask(0o022)
os.umask(_UMASK)

#: Every temporary file of a save starts with this, then the saving process's id.
TEMP_PREFIX = ".qtanim-"
#: ``.qtanim-<pid>-<random>`` and a short suffix (``.tmp``, or a video's ``.mp4``).
_TEMP_NAME = re.compile(r"\.qtanim-(\d+)-[A-Za-z0-9_]+(\.[A-Za-z0-9]{1,8})?")

_KINDS = ((stat.S_ISFIFO, "a named pipe (FIFO)"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))


class Replacement:
    """The temporary file of one save (:func:`replacing`): write ``path``, or ``discard()``
    to leave the target as it was."""

    def __init__(self, path: str) -> None:
        self.path = path
        self.discarded = False

    def discard(self) -> None:
        self.discarded = True


def write_atomic(path: str | os.PathLike[str], data: bytes) -> None:
    """Write ``data`` to a temporary file beside ``path``, flush it, then ``os.replace``."""
    write_chunks_atomic(path, (data,))


def write_chunks_atomic(path: str | os.PathLike[str], chunks: Iterable[bytes], sync: bool = True,
                        clean: bool = True) -> None:
    """Write every chunk to a temporary file beside ``path``, flush and sync it, then swap
    it in with ``os.replace``; the old file's permissions are kept.

    The bytes are written as they come, so a project serialised channel by channel never
    sits whole in memory and a writer on a worker thread never holds the GIL for long. When
    the chunks raise (a value JSON cannot store, a background save called off) the
    temporary file is removed, the exception goes on and the old file is left as it was.
    ``sync=False`` skips the fsync and ``clean=False`` the look for killed saves' leftovers
    (frames of an image sequence: thousands of small files, the folder cleaned once).
    """
    with replacing(path, sync=False, clean=clean) as tmp, open(tmp.path, "wb") as fh:
        for chunk in chunks:
            fh.write(chunk)
        fh.flush()
        if sync:
            os.fsync(fh.fileno())


@contextmanager
def replacing(path: str | os.PathLike[str], suffix: str = ".tmp", sync: bool = True,
              clean: bool = True) -> Iterator[Replacement]:
    """A temporary file beside ``path`` (created empty, named ``.qtanim-<pid>-<random><suffix>``)
    that replaces ``path`` when the block ends normally, with the old file's mode; removed
    when the block raises or calls ``discard()``. ``sync`` flushes the written file to disk
    before the swap (for a file some other program wrote, such as ffmpeg's video).

    Raises OSError naming ``path`` (never the temporary file): the target is a folder, a
    named pipe, a device or a socket (refused before anything is written), its name is too
    long, its folder cannot be written. Leftovers of killed saves in that folder go first
    (unless ``clean`` is False).
    """
    shown = os.fspath(path)
    target = writable_target(shown)
    folder = os.path.dirname(target) or "."
    if clean:
        remove_stale_temporaries(Path(target))
    try:
        fd, tmp = tempfile.mkstemp(prefix=f"{TEMP_PREFIX}{os.getpid()}-", suffix=suffix, dir=folder)
    except OSError as exc:
        raise _naming(exc, shown) from None
    os.close(fd)
    replacement = Replacement(tmp)
    swapped = False
    try:
        yield replacement
        if not replacement.discarded:
            # mkstemp makes the file private (0600); a save must not change who may read it.
            os.chmod(tmp, mode_for(target))
            if sync:
                fd = os.open(tmp, os.O_RDONLY)
                try:
                    os.fsync(fd)
                finally:
                    os.close(fd)
            writable_target(shown)  # still not a pipe or a device (nothing is swapped over one)
            os.replace(tmp, target)
            swapped = True
    except OSError as exc:
        raise _naming(exc, shown, tmp) from None
    finally:
        if not swapped:
            try:
                os.unlink(tmp)
            except OSError:
                pass


def writable_target(path: str | os.PathLike[str]) -> str:
    """The file a save of ``path`` replaces: ``path`` itself (an existing regular file or a
    new name), or the file a symbolic link at ``path`` leads to. Raises OSError naming
    ``path`` for a folder, a named pipe, a device, a socket, a link that leads nowhere (or
    in a loop) and a name the filesystem refuses (too long)."""
    shown = os.fspath(path)
    try:
        st = os.lstat(shown)
    except FileNotFoundError:
        return shown
    except OSError as exc:  # ENAMETOOLONG, ENOTDIR, EACCES
        raise OSError(exc.errno, exc.strerror, shown) from None
    target = shown
    if stat.S_ISLNK(st.st_mode):
        try:
            st = os.stat(shown)
        except FileNotFoundError:
            raise OSError(errno.ENOENT, "it is a symbolic link to a file that does not exist; "
                          "nothing was written (save to the file itself)", shown) from None
        except OSError as exc:  # ELOOP
            raise OSError(exc.errno, exc.strerror, shown) from None
        target = os.path.realpath(shown)
    if stat.S_ISDIR(st.st_mode):
        raise IsADirectoryError(errno.EISDIR, "it is a folder", shown)
    if not stat.S_ISREG(st.st_mode):
        kind = next((name for test, name in _KINDS if test(st.st_mode)), "not a regular file")
        raise OSError(errno.EINVAL, f"it is {kind}, not a regular file; nothing was written", shown)
    return target


def _naming(exc: OSError, path: str, tmp: str | None = None) -> OSError:
    """``exc`` reported under the target's name instead of the temporary file's (``tmp``;
    None: any file, the temporary's name not yet known)."""
    if exc.filename is None:
        return OSError(str(exc).replace(tmp, path)) if tmp and tmp in str(exc) else exc
    if tmp is None or tmp in (exc.filename, exc.filename2):
        return OSError(exc.errno, exc.strerror, path)
    return exc


def remove_stale_temporaries(target: Path) -> list[Path]:
    """Delete the temporary files that saves in ``target``'s folder left when their process
    was killed; returns what was removed. Temporaries of running processes are left alone.
    (Also those of the earlier naming, ``.<target name>.<pid>.<random>.tmp``.)"""
    removed: list[Path] = []
    folder = target.parent or Path(".")
    old_prefix = f".{target.name}."
    try:
        names = [e.name for e in os.scandir(folder) if e.name.startswith((TEMP_PREFIX, old_prefix))]
    except OSError:
        return removed
    for name in names:
        match = _TEMP_NAME.fullmatch(name)
        if match is not None:
            pid_text = match.group(1)
        elif name.startswith(old_prefix) and name.endswith(".tmp"):
            pid_text = name[len(old_prefix):].split(".", 1)[0]
        else:
            continue
        if not pid_text.isdigit() or _running(int(pid_text)):
            continue
        p = folder / name
        try:
            if p.is_file() and not p.is_symlink():
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
    except (ProcessLookupError, OverflowError):  # no such process (or no such process id at all)
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
