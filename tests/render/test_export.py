"""Writing frames: PNG folders and patterns, GIF and MP4 read back with the right count."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest

from qtanimator.render.export import count_video_frames, flatten_alpha, output_kind, write_frames


def frames(n: int, w: int = 33, h: int = 21, alpha: bool = False) -> list[np.ndarray]:
    out = []
    for i in range(n):
        a = np.zeros((h, w, 4 if alpha else 3), dtype=np.uint8)
        a[..., 0] = (i * 40) % 256
        a[:, : (i * 3) % w, 1] = 255
        if alpha:
            a[..., 3] = 255
        out.append(a)
    return out


def test_output_kinds(tmp_path: Path) -> None:
    assert output_kind(tmp_path) == "folder"
    assert output_kind(tmp_path / "f_%03d.png") == "pattern"
    assert output_kind("a.GIF") == "gif" and output_kind("a.mp4") == "video"
    with pytest.raises(ValueError):
        output_kind("one.png")


@pytest.mark.parametrize("name", ["f_%d%d.png", "f_%%.png", "50%.png", "f_%(n)d.png"])
def test_a_broken_pattern_is_a_value_error_before_anything_is_written(tmp_path: Path, name: str) -> None:
    with pytest.raises(ValueError, match="pattern|same name"):
        output_kind(tmp_path / name)
    with pytest.raises(ValueError):
        write_frames(frames(2), tmp_path / "seq" / name, 24)
    assert not (tmp_path / "seq").exists()


def test_png_folder_and_pattern(tmp_path: Path) -> None:
    seen: list[int] = []
    assert write_frames(frames(4, alpha=True), tmp_path / "out", 24, progress=seen.append) == 4
    assert seen == [1, 2, 3, 4]
    names = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert names == [f"frame_{i:04d}.png" for i in range(4)]
    back = iio.imread(tmp_path / "out" / "frame_0002.png")
    assert np.array_equal(back, frames(4, alpha=True)[2])
    assert write_frames(frames(3), tmp_path / "seq" / "s_%02d.png", 24, start=10) == 3
    assert sorted(p.name for p in (tmp_path / "seq").iterdir()) == ["s_10.png", "s_11.png", "s_12.png"]


def test_gif_and_mp4_frame_counts(tmp_path: Path) -> None:
    assert write_frames(frames(7, alpha=True), tmp_path / "a.gif", 20) == 7
    assert count_video_frames(tmp_path / "a.gif") == 7
    # odd sizes are padded for H.264
    assert write_frames(frames(12), tmp_path / "a.mp4", 30) == 12
    assert count_video_frames(tmp_path / "a.mp4") == 12
    first = iio.imread(tmp_path / "a.mp4", index=0, plugin="pyav") if _has_pyav() else None
    if first is not None:
        assert first.shape[:2] == (22, 34)


def _has_pyav() -> bool:
    try:
        import av  # noqa: F401
    except ImportError:
        return False
    return True


def test_cancel_and_bad_frames(tmp_path: Path) -> None:
    calls = {"n": 0}

    def cancel() -> bool:
        calls["n"] += 1
        return calls["n"] > 2

    assert write_frames(frames(10), tmp_path / "c", 10, cancel=cancel) == 2
    with pytest.raises(ValueError):
        write_frames([np.zeros((4, 4), dtype=np.uint8)], tmp_path / "bad", 10)
    with pytest.raises(ValueError):
        write_frames([np.zeros((4, 4, 3), dtype=np.uint8), np.zeros((5, 4, 3), dtype=np.uint8)], tmp_path / "b2", 10)
    with pytest.raises(ValueError):
        write_frames(frames(1), tmp_path / "x.mp4", 0)


def test_flatten_alpha() -> None:
    a = np.zeros((1, 2, 4), dtype=np.uint8)
    a[0, 0] = (255, 0, 0, 255)
    a[0, 1] = (0, 0, 0, 0)
    f = flatten_alpha(a)
    assert f.shape == (1, 2, 3) and tuple(f[0, 0]) == (255, 0, 0) and tuple(f[0, 1]) == (255, 255, 255)


@pytest.mark.parametrize("name", ["old.gif", "old.mp4"])
def test_a_failed_export_leaves_the_old_file_and_no_temporary(tmp_path: Path, name: str) -> None:
    out = tmp_path / name
    assert write_frames(frames(3), out, 10) == 3
    out.chmod(0o640)
    before = out.read_bytes()

    def broken() -> Iterator[np.ndarray]:
        yield from frames(2)
        raise RuntimeError("the renderer failed")

    with pytest.raises(RuntimeError):
        write_frames(broken(), out, 10)
    assert out.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == [name]
    # a good export replaces it, keeping its permissions
    assert write_frames(frames(5), out, 10) == 5
    assert count_video_frames(out) == 5 and (out.stat().st_mode & 0o777) == 0o640
    assert sorted(p.name for p in tmp_path.iterdir()) == [name]


def test_a_video_cancelled_before_the_first_frame_writes_nothing(tmp_path: Path) -> None:
    assert write_frames(frames(3), tmp_path / "v.mp4", 10, cancel=lambda: True) == 0
    assert list(tmp_path.iterdir()) == []
