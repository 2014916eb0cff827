"""A private virtual X server, for OpenGL without a screen (headless 3D renders, tests,
screenshots). Imports no Qt, so it can run before Qt chooses its platform."""

from __future__ import annotations

import atexit
import contextlib
import os
import shutil
import subprocess

# the servers this process started, with their display numbers; stopped at exit
_RUNNING: list[tuple[subprocess.Popen[bytes], str]] = []


def start_private_xvfb(screen: str = "1920x1080x24") -> str:
    """Start ``Xvfb -displayfd`` (the server picks a free display) and return ``":N"``.

    The server is stopped (and waited for) when the process exits normally, which includes
    a render ended by SIGTERM / SIGINT (:mod:`qtanimator.render.interrupt`). Raises OSError with a sentence saying why
    when Xvfb is missing or does not start.
    """
    exe = shutil.which("Xvfb")
    if exe is None:
        raise OSError("OpenGL without a display needs Xvfb (apt-get install xvfb)")
    read_fd, write_fd = os.pipe()
    try:
        proc = subprocess.Popen(
            [exe, "-displayfd", str(write_fd), "-screen", "0", screen, "-nolisten", "tcp",
             "+extension", "GLX", "-noreset"],
            pass_fds=(write_fd,), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    except OSError as exc:
        os.close(read_fd)
        raise OSError(f"Xvfb did not start: {exc}") from exc
    finally:
        os.close(write_fd)
    with os.fdopen(read_fd) as fh:
        number = fh.readline().strip()
    if not number:
        proc.kill()
        raise OSError("Xvfb started but reported no display")
    if not _RUNNING:
        atexit.register(stop_private_xvfbs)
    _RUNNING.append((proc, number))
    return f":{number}"


def stop_private_xvfbs(timeout: float = 3.0) -> None:
    """Terminate every Xvfb this process started and wait for it; one that does not stop
    within ``timeout`` seconds is killed and its lock file and socket removed."""
    while _RUNNING:
        proc, number = _RUNNING.pop()
        if proc.poll() is not None:
            continue
        with contextlib.suppress(OSError):
            proc.terminate()
        try:
            proc.wait(timeout)
        except subprocess.TimeoutExpired:
            with contextlib.suppress(OSError):
                proc.kill()
            with contextlib.suppress(subprocess.TimeoutExpired):
                proc.wait(timeout)
            _remove_server_files(proc.pid, number)


def _remove_server_files(pid: int, number: str) -> None:
    """Remove ``/tmp/.X<N>-lock`` and ``/tmp/.X11-unix/X<N>``, which Xvfb removes itself when
    it stops on SIGTERM but not when killed; nothing is removed when the lock names another
    process."""
    lock = f"/tmp/.X{number}-lock"
    try:
        with open(lock) as fh:
            if fh.read().strip() != str(pid):
                return
    except OSError:
        pass
    for path in (lock, f"/tmp/.X11-unix/X{number}"):
        with contextlib.suppress(OSError):
            os.unlink(path)
