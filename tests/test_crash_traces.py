"""Native crashes reach the log (issue 30: PySide6 6.12.0 aborted the interpreter and nothing
said where): the command line leaves the Python stack on stderr, the GUI in crash.log."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

CRASH = "import ctypes; ctypes.string_at(0)"  # a segfault in native code


def _run(code: str, **env: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                          env={**os.environ, **env})


def test_the_command_line_prints_the_stack_of_a_native_crash() -> None:
    code = ("import faulthandler; from qtanimator import cli; status = cli.main(['--version'])\n"
            "print('enabled', faulthandler.is_enabled(), status, flush=True)\n"
            "def render_frame(): " + CRASH + "\nrender_frame()")
    proc = _run(code)
    assert proc.returncode < 0 or proc.returncode == 139, proc  # killed by SIGSEGV
    assert "enabled True 0" in proc.stdout
    assert "Fatal Python error: Segmentation fault" in proc.stderr
    assert "render_frame" in proc.stderr  # the Python frame that was running


def test_the_gui_writes_native_crashes_beside_its_log(tmp_path: Path) -> None:
    code = ("from qtanimator import applog; path = applog.enable_crash_traces(to_log_folder=True)\n"
            "print(path, flush=True)\n"
            "def paint_gl(): " + CRASH + "\npaint_gl()")
    proc = _run(code, XDG_STATE_HOME=str(tmp_path))
    crash_log = tmp_path / "qtanimator" / "crash.log"
    assert proc.stdout.strip() == str(crash_log)
    text = crash_log.read_text(encoding="utf-8")
    assert "Fatal Python error: Segmentation fault" in text and "paint_gl" in text
    assert "Segmentation fault" not in proc.stderr.replace("Segmentation fault (core dumped)", "")
