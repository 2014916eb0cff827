"""A private virtual X server, for OpenGL without a screen (headless 3D renders, tests,
screenshots). Imports no Qt, so it can run before Qt chooses its platform."""

from __future__ import annotations

import atexit
import os
import shutil
import subprocess


def start_private_xvfb(screen: str = "1920x1080x24") -> str:
    """Start ``Xvfb -displayfd`` (the server picks a free display) and return ``":N"``.

    The server is stopped when the process exits. Raises OSError with a sentence saying why
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
    atexit.register(proc.terminate)
    return f":{number}"
