"""GIF timing (whole centiseconds ≥ 2, at most 50 fps, duration kept), unknown output formats,
the output checked for writability before rendering, and no ``\\r`` progress off a terminal."""

from __future__ import annotations

import io
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from qtanimator.render import cli_render
from qtanimator.render.cli_render import render_main
from qtanimator.render.export import check_output, gif_delays, gif_timing_note, output_kind, write_frames

SCENES = Path(__file__).resolve().parents[2] / "scenes"


def frames(n: int) -> list[np.ndarray]:
    out = []
    for i in range(n):
        a = np.zeros((12, 16, 3), dtype=np.uint8)
        a[..., 0] = (i * 37) % 256
        a[:, : i % 16, 1] = 255
        out.append(a)
    return out


def gif_delays_cs(path: Path) -> list[int]:
    out = []
    with Image.open(path) as im:
        for k in range(im.n_frames):
            im.seek(k)
            out.append(int(im.info["duration"]) // 10)
    return out


def ffprobe_duration(path: Path) -> float | None:
    """The duration ffprobe reads, or (no ffprobe on PATH) imageio-ffmpeg's ffmpeg ``Duration:``."""
    exe = shutil.which("ffprobe")
    if exe is not None:
        res = subprocess.run([exe, "-v", "error", "-show_entries", "format=duration", "-of", "json", str(path)],
                             capture_output=True, text=True, check=True)
        return float(json.loads(res.stdout)["format"]["duration"])
    try:
        import imageio_ffmpeg
    except ImportError:
        return None
    res = subprocess.run([imageio_ffmpeg.get_ffmpeg_exe(), "-hide_banner", "-i", str(path)],
                         capture_output=True, text=True)
    m = re.search(r"Duration: (\d+):(\d+):([\d.]+)", res.stderr)
    assert m, res.stderr
    return int(m[1]) * 3600 + int(m[2]) * 60 + float(m[3])


@pytest.mark.parametrize("fps", [24, 30, 60, 12, 25, 50, 59.94, 100, 120])
@pytest.mark.parametrize("seconds", [1, 2.5])
def test_gif_duration_matches_the_clip(tmp_path: Path, fps: float, seconds: float) -> None:
    n = round(fps * seconds)
    out = tmp_path / "clip.gif"
    assert write_frames(frames(n), out, fps) == n
    delays = gif_delays_cs(out)
    assert min(delays) >= 2
    clip = n / fps
    assert sum(delays) / 100 == pytest.approx(clip, rel=0.02)
    probed = ffprobe_duration(out)
    if probed is not None:
        assert probed == pytest.approx(clip, rel=0.02)
    if fps <= 50:
        assert len(delays) == n  # every frame kept
    else:
        assert len(delays) == pytest.approx(n * 50 / fps, abs=1)  # dropped evenly down to 50 fps
        assert set(delays[:-1]) == {2}


def test_gif_frames_are_dropped_evenly_above_50_fps(tmp_path: Path) -> None:
    src = frames(60)
    out = tmp_path / "a.gif"
    write_frames(src, out, 60)
    with Image.open(out) as im:
        reds = []
        for k in range(im.n_frames):
            im.seek(k)
            reds.append(int(np.asarray(im.convert("RGB"))[0, 0, 0]))
    kept = [next(i for i, f in enumerate(src) if int(f[0, 0, 0]) == r) for r in reds]
    gaps = np.diff(kept)
    assert len(kept) == 50 and set(gaps.tolist()) <= {1, 2} and (gaps == 2).sum() == 9


def test_gif_delays_edge_cases() -> None:
    assert gif_delays(1, 1, 60) == [2]
    assert gif_delays(8, 6, 70) == [2, 2, 2, 2, 3]  # an unshowable 1 cs tail folds into the frame before
    assert gif_delays(3, 3, 30) == [3, 4, 3]


def test_gif_timing_notes() -> None:
    assert "50 fps" in (gif_timing_note(60) or "") and "dropping frames evenly" in (gif_timing_note(60) or "")
    assert "3 and 4 cs" in (gif_timing_note(30) or "")
    assert gif_timing_note(25) is None and gif_timing_note(50) is None


def test_unknown_suffix_is_an_error_listing_the_formats(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match=r"\.webp.*\.gif.*\.mp4"):
        output_kind(tmp_path / "x.webp")
    (tmp_path / "renders.v2").mkdir()
    assert output_kind(tmp_path / "renders.v2") == "folder"  # an existing folder with a dot is still a folder


def test_render_to_webp_fails_listing_the_formats_and_writes_nothing(
        qapp, tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    rc = render_main([str(SCENES / "pendulum_clock.svg"), "-o", str(tmp_path / "x.webp"), "--frames", "0:1"])
    assert rc != 0
    err = capsys.readouterr().err
    assert "x.webp" in err and ".gif" in err and ".mp4" in err and "folder" in err
    assert list(tmp_path.iterdir()) == []


def test_an_unwritable_output_fails_before_rendering_naming_the_real_path(
        qapp, tmp_path: Path, capsys, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    blocker = tmp_path / "file"
    blocker.write_text("x")
    rendered: list[int] = []

    def no_rendering(*args, **kwargs):  # type: ignore[no-untyped-def]
        rendered.append(1)
        raise AssertionError("rendered before checking the output")

    monkeypatch.setattr(cli_render, "frames_2d", no_rendering)
    for target in (blocker / "out.gif", blocker / "sub" / "frames", blocker / "v.mp4"):
        assert render_main([str(SCENES / "pendulum_clock.svg"), "-o", str(target), "--frames", "0:1",
                            "--quiet"]) == 1
        err = capsys.readouterr().err.strip()
        assert str(blocker) in err and "cannot write" in err and ".tmp" not in err and "/." not in err
    assert rendered == []
    (tmp_path / "dir.gif").mkdir()
    with pytest.raises(OSError) as exc:
        check_output(tmp_path / "dir.gif")
    assert exc.value.filename == str(tmp_path / "dir.gif")


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX permissions")
def test_a_read_only_folder_is_named(tmp_path: Path) -> None:
    import os

    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    try:
        if os.access(ro, os.W_OK):
            pytest.skip("running as root: permissions are not enforced")
        with pytest.raises(PermissionError) as exc:
            write_frames(frames(2), ro / "a.gif", 10)
        assert exc.value.filename == str(ro)
    finally:
        ro.chmod(0o755)


def test_progress_has_no_carriage_returns_off_a_terminal(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    buf = io.StringIO()
    monkeypatch.setattr(sys, "stderr", buf)
    p = cli_render._Progress(3, True)
    for i in (1, 2, 3):
        p(i)
    assert "\r" not in buf.getvalue()

    class Tty(io.StringIO):
        def isatty(self) -> bool:
            return True

    tty = Tty()
    monkeypatch.setattr(sys, "stderr", tty)
    p = cli_render._Progress(3, True)
    for i in (1, 2, 3):
        p(i)
    out = tty.getvalue()
    assert "\r" in out and "3/3" in out
    assert "frame/s" in out and out.endswith("\n")  # tqdm's rate column; the bar's line is ended


def test_render_gif_at_60_fps_says_so_and_keeps_the_duration(
        qapp, tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    out = tmp_path / "clock.gif"
    assert render_main([str(SCENES / "pendulum_clock.svg"), "-o", str(out), "--frames", "0:59", "--fps", "60",
                        "--size", "40x60"]) == 0
    err = capsys.readouterr().err
    assert "50 fps" in err and "\r" not in err
    delays = gif_delays_cs(out)
    assert min(delays) >= 2 and sum(delays) == 100
