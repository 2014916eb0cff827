"""``qtanimator render``: headless rendering of SVG scenes and projects."""

from __future__ import annotations

from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest

from qtanimator.render.cli_render import render_main
from qtanimator.render.export import count_video_frames

SCENES = Path(__file__).resolve().parents[2] / "scenes"


def test_render_clock_to_mp4(qapp, tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    out = tmp_path / "clock.mp4"
    rc = render_main([str(SCENES / "pendulum_clock.svg"), "-o", str(out), "--frames", "0:29",
                      "--size", "120x200"])
    assert rc == 0
    assert count_video_frames(out) == 30
    err = capsys.readouterr().err
    assert "wrote 30 frames" in err and "\r" not in err  # stderr is not a terminal: no progress bar


def test_render_clock_frames_show_the_pendulum_moving(qapp, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    out = tmp_path / "frames"
    assert render_main([str(SCENES / "pendulum_clock.svg"), "-o", str(out), "--frames", "0:40",
                        "--size", "100x160", "--quiet", "--background", "#202020"]) == 0
    files = sorted(out.iterdir())
    assert len(files) == 41 and files[0].name == "frame_0000.png"
    imgs = [iio.imread(f).astype(int) for f in (files[0], files[20], files[40])]
    assert imgs[0][0, 0, 0] == 0x20  # background colour
    bottom = slice(90, 160)
    assert np.abs(imgs[0][bottom] - imgs[1][bottom]).sum() > 500
    assert np.abs(imgs[1][bottom] - imgs[2][bottom]).sum() > 500


def test_render_project_to_gif(qapp, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    out = tmp_path / "demo.gif"
    assert render_main([str(SCENES / "demo" / "demo.qtanim"), "-o", str(out), "--frames", "0:9",
                        "--size", "160x90", "--fps", "30", "--quiet"]) == 0
    assert count_video_frames(out) == 10


@pytest.mark.parametrize("args,message", [
    (["missing.svg", "-o", "x.mp4"], "no such"),
    (["{clock}", "-o", "x.mp4", "--size", "big"], "--size"),
    (["{clock}", "-o", "x.mp4", "--frames", "9:3"], "--frames"),
    (["{clock}", "-o", "one.png"], "pattern"),
    (["{clock}", "-o", "x.mp4", "--background", "nocolour"], "colour"),
])
def test_errors_are_one_line(qapp, tmp_path: Path, capsys, args: list[str], message: str) -> None:  # type: ignore[no-untyped-def]
    args = [a.replace("{clock}", str(SCENES / "pendulum_clock.svg")) for a in args]
    args = [str(tmp_path / a) if a.endswith((".mp4", ".png")) else a for a in args]
    assert render_main(args) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0] and err[0].startswith("qtanimator render:")


def test_view_3d_renders_or_says_why(qapp, tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    rc = render_main([str(SCENES / "arm3d" / "arm3d.qtanim"), "-o", str(tmp_path / "f"), "--frames", "0:1",
                      "--size", "64x48", "--view", "3d", "--quiet"])
    if rc != 0:
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1
    else:
        assert sorted(p.name for p in (tmp_path / "f").iterdir()) == ["frame_0000.png", "frame_0001.png"]


@pytest.mark.parametrize("scene,view,message", [
    ("pendulum_clock.svg", "3d", "no 3D characters"),
    ("arm3d/arm3d.qtanim", "2d", "no 2D characters"),
])
def test_a_view_that_would_show_nothing_is_refused(qapp, tmp_path: Path, capsys, scene: str, view: str,  # type: ignore[no-untyped-def]
                                                   message: str) -> None:
    out = tmp_path / "f"
    assert render_main([str(SCENES / scene), "-o", str(out), "--frames", "0:1", "--view", view, "--quiet"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0]
    assert not out.exists()


def test_the_default_view_follows_the_scene() -> None:
    from qtanimator.document import open_document
    from qtanimator.render.cli_render import choose_view, load_scene

    assert choose_view(load_scene(SCENES / "pendulum_clock.svg"), "auto") == "2d"
    assert choose_view(open_document(SCENES / "arm3d" / "arm3d.qtanim"), "auto") == "3d"
    assert choose_view(open_document(SCENES / "cloth" / "cloth.qtanim"), "auto") == "3d"


def test_negative_frames_and_broken_patterns(qapp, tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    out = tmp_path / "neg"
    assert render_main([str(SCENES / "pendulum_clock.svg"), "-o", str(out / "f_%03d.png"), "--frames", "-2:0",
                        "--size", "40x40", "--quiet"]) == 0
    assert sorted(p.name for p in out.iterdir()) == ["f_-01.png", "f_-02.png", "f_000.png"]
    assert render_main([str(SCENES / "pendulum_clock.svg"), "-o", str(tmp_path / "f_%d%d.png"), "--quiet"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "not a frame pattern" in err[0]


@pytest.mark.parametrize("args", [["--frobnicate"], [], ["--view", "4d"]])
def test_usage_errors_are_one_line(tmp_path: Path, capsys, args: list[str]) -> None:  # type: ignore[no-untyped-def]
    argv = [str(SCENES / "pendulum_clock.svg"), *args] + ([] if not args else ["-o", str(tmp_path / "x")])
    with pytest.raises(SystemExit) as exc:
        render_main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("qtanimator render:") and "--help" in err[0]


def test_an_unwritable_output_is_one_line(qapp, tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert render_main([str(SCENES / "pendulum_clock.svg"), "-o", str(blocker / "out.gif"), "--frames", "0:1",
                        "--quiet"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "cannot write" in err[0] and "Errno" not in err[0]
