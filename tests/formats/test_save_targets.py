"""Saves that always work (issue 31, part 5): short temporary names whatever the target's
name, the target's path in every error, targets that are not regular files refused before
anything is written, a symbolic link written through, leftovers of killed renders removed."""

from __future__ import annotations

import errno
import os
import signal
import stat
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

from qtanimator.formats import atomic
from qtanimator.formats.atomic import TEMP_PREFIX, writable_target, write_atomic
from qtanimator.formats.project import ProjectData, load_project, save_project
from qtanimator.render.export import check_output, write_frames

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX names, pipes and links")


def frames(n: int) -> list[np.ndarray]:
    return [np.full((8, 10, 3), 20 * i, dtype=np.uint8) for i in range(n)]


def names(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


def _dead_pid() -> int:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


# ---------------------------------------------------------------- long names

def test_a_250_character_project_name_saves_and_reopens(tmp_path: Path) -> None:
    target = tmp_path / ("p" * (250 - len(".qtanim")) + ".qtanim")
    assert len(target.name) == 250
    data = ProjectData(parameters={"fps": 30.0})
    save_project(data, target)
    save_project(data, target)  # replacing it works too
    assert load_project(target).parameters == {"fps": 30.0}
    assert names(tmp_path) == [target.name]


def test_the_longest_name_the_filesystem_allows_saves_and_a_longer_one_names_the_target(tmp_path: Path) -> None:
    limit = os.pathconf(tmp_path, "PC_NAME_MAX")
    ok = tmp_path / ("a" * (limit - 4) + ".gif")
    assert write_frames(frames(2), ok, 10) == 2
    write_atomic(ok, b"x")
    too_long = tmp_path / ("b" * (limit - 3) + ".gif")
    for write in (lambda: write_atomic(too_long, b"x"), lambda: save_project(ProjectData(), too_long),
                  lambda: write_frames(frames(2), too_long, 10)):
        with pytest.raises(OSError) as exc:
            write()
        assert exc.value.errno == errno.ENAMETOOLONG
        assert exc.value.filename == str(too_long)
        assert TEMP_PREFIX not in str(exc.value)
    assert names(tmp_path) == [ok.name]


def test_temporary_names_are_short_and_carry_the_process_id(tmp_path: Path) -> None:
    seen: list[str] = []
    target = tmp_path / ("n" * 240 + ".qtanim")
    with atomic.replacing(target) as tmp:
        seen.append(os.path.basename(tmp.path))
        Path(tmp.path).write_bytes(b"new")
    assert target.read_bytes() == b"new"
    assert seen[0].startswith(f"{TEMP_PREFIX}{os.getpid()}-") and seen[0].endswith(".tmp")
    assert len(seen[0]) < 40


def test_every_error_names_the_target_not_the_temporary(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    target = tmp_path / "a.qtanim"
    target.write_bytes(b"old")

    def failing_replace(src: str, dst: str) -> None:
        raise OSError(errno.EXDEV, "Invalid cross-device link", src, None, dst)

    monkeypatch.setattr(atomic.os, "replace", failing_replace)
    for write in (lambda: write_atomic(target, b"new"), lambda: save_project(ProjectData(), target)):
        with pytest.raises(OSError) as exc:
            write()
        assert exc.value.filename == str(target) and exc.value.errno == errno.EXDEV
        assert TEMP_PREFIX not in str(exc.value)
    assert target.read_bytes() == b"old" and names(tmp_path) == ["a.qtanim"]


# ---------------------------------------------------------------- targets that are not regular files

def _writers(target: Path) -> list:  # type: ignore[type-arg]
    return [lambda: write_atomic(target, b"new"), lambda: save_project(ProjectData(), target)]


def test_a_fifo_is_refused_before_anything_is_written(tmp_path: Path) -> None:
    for name in ("p.qtanim", "p.gif", "p.mp4"):
        fifo = tmp_path / name
        os.mkfifo(fifo)
        writers = _writers(fifo)
        if name != "p.qtanim":  # a render output
            writers += [lambda f=fifo: write_frames(frames(2), f, 10), lambda f=fifo: check_output(f)]
        for write in writers:
            with pytest.raises(OSError) as exc:
                write()  # never opened: a pipe would block
            assert exc.value.filename == str(fifo) and "named pipe" in str(exc.value)
        assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    assert names(tmp_path) == ["p.gif", "p.mp4", "p.qtanim"]


def test_a_frame_of_a_sequence_that_is_a_fifo_is_refused(tmp_path: Path) -> None:
    os.mkfifo(tmp_path / "f_01.png")
    with pytest.raises(OSError) as exc:
        write_frames(frames(3), tmp_path / "f_%02d.png", 10)
    assert exc.value.filename == str(tmp_path / "f_01.png")
    assert stat.S_ISFIFO(os.lstat(tmp_path / "f_01.png").st_mode)
    assert names(tmp_path) == ["f_00.png", "f_01.png"]  # the frame before it was written


def test_a_folder_is_refused(tmp_path: Path) -> None:
    for name in ("d.qtanim", "d.gif", "d.mp4"):
        folder = tmp_path / name
        folder.mkdir()
        (folder / "keep").write_text("x")
        writers = _writers(folder)
        if name != "d.qtanim":  # a render output (d.qtanim would be a folder of frames)
            writers += [lambda f=folder: write_frames(frames(2), f, 10)]
        for write in writers:
            with pytest.raises(IsADirectoryError) as exc:
                write()
            assert exc.value.filename == str(folder)
        assert names(folder) == ["keep"]
    assert names(tmp_path) == ["d.gif", "d.mp4", "d.qtanim"]


def test_a_device_is_refused(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # Never a real /dev/full or /dev/null: as root a bug would replace the device. A regular
    # file stands in, reported as a character device by a mocked lstat.
    full = tmp_path / "full"
    full.write_bytes(b"device")
    real_lstat = os.lstat

    def lstat(path, *args, **kwargs):  # type: ignore[no-untyped-def]
        st = real_lstat(path, *args, **kwargs)
        if os.fspath(path) == str(full):
            return os.stat_result((stat.S_IFCHR | 0o666, *tuple(st)[1:]))
        return st

    monkeypatch.setattr(atomic.os, "lstat", lstat)
    for write in [*_writers(full), lambda: write_frames(frames(2), tmp_path / "full", 10)]:
        with pytest.raises(OSError) as exc:
            write()
        assert exc.value.filename == str(full)
    with pytest.raises(OSError, match="character device"):
        writable_target(full)
    assert full.read_bytes() == b"device" and names(tmp_path) == ["full"]


def test_render_to_a_fifo_fails_before_rendering(qapp, tmp_path: Path, capsys, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    from qtanimator.render import cli_render

    monkeypatch.setattr(cli_render, "frames_2d", lambda *a, **k: pytest.fail("rendered before checking"))
    scene = Path(__file__).resolve().parents[2] / "scenes" / "pendulum_clock.svg"
    fifo = tmp_path / "out.mp4"
    os.mkfifo(fifo)
    assert cli_render.render_main([str(scene), "-o", str(fifo), "--frames", "0:1", "--quiet"]) == 1
    err = capsys.readouterr().err
    assert str(fifo) in err and "named pipe" in err and TEMP_PREFIX not in err
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)


# ---------------------------------------------------------------- symbolic links (written through)

def test_a_symlink_is_written_through_and_stays_a_link(tmp_path: Path) -> None:
    real_dir = tmp_path / "real"
    real_dir.mkdir()
    real = real_dir / "p.qtanim"
    save_project(ProjectData(parameters={"fps": 24.0}), real)
    real.chmod(0o640)
    link = tmp_path / "link.qtanim"
    link.symlink_to(real)
    save_project(ProjectData(parameters={"fps": 12.0}), link)
    assert link.is_symlink() and os.readlink(link) == str(real)
    assert load_project(real).parameters == {"fps": 12.0}
    assert stat.S_IMODE(real.stat().st_mode) == 0o640
    assert names(tmp_path) == ["link.qtanim", "real"] and names(real_dir) == ["p.qtanim"]
    gif_link = tmp_path / "a.gif"
    gif_link.symlink_to("real/b.gif")
    (real_dir / "b.gif").write_bytes(b"old")
    assert write_frames(frames(3), gif_link, 10) == 3
    assert gif_link.is_symlink() and (real_dir / "b.gif").read_bytes()[:3] == b"GIF"


def test_a_link_to_nothing_or_to_a_fifo_is_refused(tmp_path: Path) -> None:
    dangling = tmp_path / "d.qtanim"
    dangling.symlink_to(tmp_path / "nowhere" / "x.qtanim")
    os.mkfifo(tmp_path / "pipe")
    to_fifo = tmp_path / "f.qtanim"
    to_fifo.symlink_to(tmp_path / "pipe")
    loop = tmp_path / "loop.qtanim"
    loop.symlink_to(loop)
    for target in (dangling, to_fifo, loop):
        with pytest.raises(OSError) as exc:
            save_project(ProjectData(), target)
        assert exc.value.filename == str(target)
        assert target.is_symlink()
    assert names(tmp_path) == ["d.qtanim", "f.qtanim", "loop.qtanim", "pipe"]


# ---------------------------------------------------------------- leftovers of killed renders

RENDERER = textwrap.dedent("""
    import sys, time
    import numpy as np
    from qtanimator.render.export import write_frames
    def slow():
        for i in range(100000):
            if i == 3:
                print("writing", flush=True)
            yield np.full((16, 16, 3), i % 256, dtype=np.uint8)
            time.sleep(0.01)
    write_frames(slow(), sys.argv[1], 25)
""")


def test_a_killed_video_renders_partial_file_goes_with_the_next_render(tmp_path: Path) -> None:
    out = tmp_path / "out.mp4"
    out.write_bytes(b"old video")
    proc = subprocess.Popen([sys.executable, "-c", RENDERER, str(out)], stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout is not None and proc.stdout.readline().strip() == "writing"
        time.sleep(0.3)
    finally:
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait()
    partial = [n for n in names(tmp_path) if n != "out.mp4"]
    assert partial and all(n.startswith(f"{TEMP_PREFIX}{proc.pid}-") and n.endswith(".mp4") for n in partial)
    assert out.read_bytes() == b"old video"
    # a running process's temporary is left alone; the dead render's goes
    mine = tmp_path / f"{TEMP_PREFIX}{os.getpid()}-abc.mp4"
    mine.write_bytes(b"")
    assert write_frames(frames(3), out, 10) == 3
    assert names(tmp_path) == sorted(["out.mp4", mine.name])


def test_leftovers_of_dead_processes_go_whatever_the_target(tmp_path: Path) -> None:
    dead = _dead_pid()
    leftovers = [tmp_path / f"{TEMP_PREFIX}{dead}-x1.tmp", tmp_path / f"{TEMP_PREFIX}{dead}-y2.mkv"]
    for p in leftovers:
        p.write_bytes(b"")
    keep = [tmp_path / f"{TEMP_PREFIX}{os.getpid()}-z3.tmp", tmp_path / ".qtanim-notes.txt"]
    for p in keep:
        p.write_bytes(b"")
    write_atomic(tmp_path / "a.qtanim", b"{}")
    assert names(tmp_path) == sorted(["a.qtanim", *(p.name for p in keep)])
