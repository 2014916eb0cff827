"""Clean exits: SIGTERM / SIGINT during ``qtanimator render`` leave no process and no
temporary file, and never replace an existing output (issue #15)."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from qtanimator.render.interrupt import RenderInterrupted, interrupt_on_signals

SCENES = Path(__file__).resolve().parents[2] / "scenes"
OLD = b"an existing video that must survive\n"

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="reads /proc and sends POSIX signals")


def _children(pid: int) -> list[int]:
    """The processes whose parent is ``pid``."""
    out = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            stat = Path(f"/proc/{entry}/stat").read_text()
        except OSError:
            continue
        if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
            out.append(int(entry))
    return out


def _alive(pid: int) -> bool:
    """Running, and not a zombie waiting to be reaped."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


def _cmdline(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
    except OSError:
        return ""


def _x_lock_files(pid: int) -> list[Path]:
    """``/tmp/.X<N>-lock`` files naming ``pid`` (an Xvfb's display)."""
    out = []
    for lock in Path("/tmp").glob(".X*-lock"):
        try:
            if lock.read_text().strip() == str(pid):
                out.append(lock)
        except OSError:
            pass
    return out


def _temporaries(folder: Path) -> list[Path]:
    return [p for p in folder.iterdir() if p.name.startswith((".out.", ".qtanim-"))]


def _interrupt_render(tmp_path: Path, scene: str, view: str, out_name: str, signum: int,
                      wait_for_xvfb: bool) -> tuple[int, str, list[int], list[int], list[Path]]:
    """Start a render into an existing ``out_name``, send ``signum`` once it is writing; returns
    (exit status, stderr, the render's children and its Xvfb children seen before the signal,
    their lock files)."""
    out = tmp_path / out_name
    out.write_bytes(OLD)
    env = dict(os.environ)
    env.pop("WAYLAND_DISPLAY", None)
    if wait_for_xvfb:
        env.pop("DISPLAY", None)  # so the render starts its own private Xvfb
    env["QT_QPA_PLATFORM"] = "" if wait_for_xvfb else "offscreen"
    cmd = [sys.executable, "-m", "qtanimator", "render", str(SCENES / scene), "--view", view,
           "-o", str(out), "--frames", "0:5000", "--size", "160x120"]
    proc = subprocess.Popen(cmd, cwd=tmp_path, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 60
        children: list[int] = []
        while time.monotonic() < deadline and proc.poll() is None:
            children = _children(proc.pid)
            xvfb_ready = not wait_for_xvfb or any("Xvfb" in _cmdline(c) for c in children)
            if xvfb_ready and (_temporaries(tmp_path) or not out_name.endswith(".mp4")):
                break
            time.sleep(0.1)
        else:
            pytest.fail(f"the render did not start writing: {proc.stderr.read().decode() if proc.stderr else ''}")
        time.sleep(1.0)  # a few frames in
        children = _children(proc.pid)
        xvfbs = [c for c in children if "Xvfb" in _cmdline(c)]
        locks = [lock for c in xvfbs for lock in _x_lock_files(c)]
        assert proc.poll() is None, "the render ended before the signal"
        proc.send_signal(signum)
        started = time.monotonic()
        _, err = proc.communicate(timeout=15)
        assert time.monotonic() - started < 10
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    return proc.returncode, err.decode(errors="replace"), children, xvfbs, locks


def _assert_clean(tmp_path: Path, out_name: str, children: list[int]) -> None:
    assert (tmp_path / out_name).read_bytes() == OLD
    assert _temporaries(tmp_path) == []
    deadline = time.monotonic() + 5  # a reparented child may take a moment to go
    while time.monotonic() < deadline and any(_alive(c) for c in children):
        time.sleep(0.1)
    assert [c for c in children if _alive(c)] == [], "a child of the render is still running"


@pytest.mark.skipif(shutil.which("Xvfb") is None, reason="needs Xvfb")
def test_sigterm_during_3d_render_stops_xvfb_and_leaves_no_temporary(tmp_path):
    rc, err, children, xvfbs, locks = _interrupt_render(tmp_path, "arm3d/arm3d.qtanim", "3d", "out.mp4",
                                                 signal.SIGTERM, wait_for_xvfb=True)
    assert rc == 128 + signal.SIGTERM, err
    assert xvfbs, "the render started no private Xvfb"
    assert err.strip().splitlines()[-1].startswith("qtanimator render: stopped by SIGTERM")
    _assert_clean(tmp_path, "out.mp4", children)
    assert [lock for lock in locks if lock.exists()] == [], "the Xvfb's lock file was left behind"


@pytest.mark.parametrize(("out_name", "signum"), [("out.mp4", signal.SIGTERM), ("out.gif", signal.SIGINT)])
def test_signal_during_2d_render_leaves_the_old_output(tmp_path, out_name, signum):
    rc, err, children, _, _ = _interrupt_render(tmp_path, "demo/demo.qtanim", "2d", out_name, signum,
                                             wait_for_xvfb=False)
    assert rc == 128 + signum, err
    assert f"stopped by {signal.Signals(signum).name}" in err
    _assert_clean(tmp_path, out_name, children)


def test_interrupt_on_signals_raises_once_and_restores_handlers():
    before = signal.getsignal(signal.SIGTERM)
    with pytest.raises(RenderInterrupted) as info, interrupt_on_signals():
        try:
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(1)  # the handler runs here
        finally:
            os.kill(os.getpid(), signal.SIGTERM)  # a second signal during cleanup is ignored
            time.sleep(0.05)
    assert info.value.signum == signal.SIGTERM and info.value.exit_status == 143
    assert isinstance(info.value, KeyboardInterrupt) and not isinstance(info.value, Exception)
    assert signal.getsignal(signal.SIGTERM) == before


def _maps(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/maps").read_text(errors="replace")
    except OSError:
        return ""


@pytest.mark.skipif(not Path("/proc/self/maps").exists(), reason="needs /proc")
def test_a_signal_while_the_render_starts_stops_it_with_its_message(tmp_path):
    """Ctrl+C while `qtanimator render` is still loading Qt's bindings: the same message and
    status as later, the old output untouched (it aborted Python inside PySide6's
    initialisation, or exited 130 without a word)."""
    out = tmp_path / "out.gif"
    out.write_bytes(OLD)
    env = {**os.environ, "QT_QPA_PLATFORM": "offscreen"}
    env.pop("WAYLAND_DISPLAY", None)
    proc = subprocess.Popen([sys.executable, "-m", "qtanimator", "render", str(SCENES / "demo/demo.qtanim"),
                             "-o", str(out), "--frames", "0:5000", "--size", "160x120"], cwd=tmp_path, env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and "shiboken6" not in _maps(proc.pid) and proc.poll() is None:
            time.sleep(0.002)
        proc.send_signal(signal.SIGINT)  # PySide6 is loading (or just loaded)
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    text = err.decode(errors="replace")
    assert proc.returncode == 130, text
    assert "stopped by SIGINT" in text and "Fatal Python error" not in text, text
    assert out.read_bytes() == OLD


def test_an_error_that_a_signal_caused_inside_native_code_is_a_stop():
    """A signal raised inside a C extension's call can come out as another error (PySide6 6.8:
    SystemError, the RenderInterrupted lost); after a signal, any error ends as the stop."""
    with pytest.raises(RenderInterrupted) as info, interrupt_on_signals():
        try:
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(1)
        except RenderInterrupted:
            pass  # what a C extension does: swallow it and fail in its own way
        raise SystemError("bad argument to internal function")
    assert info.value.signum == signal.SIGTERM and isinstance(info.value.__cause__, SystemError)
    with pytest.raises(ValueError), interrupt_on_signals():  # no signal: errors stay themselves
        raise ValueError("no signal here")


def test_signals_held_during_a_native_import_raise_when_it_ends():
    """A signal while PySide6 initialises is held (a KeyboardInterrupt there aborts Python),
    then ends the render as usual."""
    from qtanimator.render.interrupt import signals_held

    before = signal.getsignal(signal.SIGINT)
    reached_the_end = False
    with pytest.raises(RenderInterrupted) as info:
        with signals_held():
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.2)  # a plain handler would raise here
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(0.05)
            reached_the_end = True
    assert reached_the_end and info.value.signum == signal.SIGINT  # the first one
    assert signal.getsignal(signal.SIGINT) == before
    with signals_held():  # no signal: nothing raised
        pass


def test_stop_private_xvfbs_waits_for_the_server(monkeypatch):
    if shutil.which("Xvfb") is None:
        pytest.skip("needs Xvfb")
    from qtanimator.render import xvfb

    monkeypatch.setattr(xvfb, "_RUNNING", [])  # leave alone the server this test session's Qt uses
    display = xvfb.start_private_xvfb("64x64x24")
    proc, number = xvfb._RUNNING[-1]
    socket = Path(f"/tmp/.X11-unix/X{number}")
    assert display == f":{number}" and socket.exists()
    xvfb.stop_private_xvfbs()
    assert proc.poll() is not None and not socket.exists()
    assert not Path(f"/tmp/.X{number}-lock").exists()
    assert xvfb._RUNNING == []
