"""Writing rendered frames: a PNG sequence, a GIF or a video (imageio + imageio-ffmpeg).

``write_frames`` takes any iterable of H×W×3 or H×W×4 uint8 arrays, so the 2D renderer,
the 3D viewport and the GUI export dialog all share it. Formats by ``out``:

* an existing folder, or a path without a suffix: ``out/frame_0000.png`` …;
* a pattern with a ``%`` field such as ``shots/frame_%04d.png``;
* ``*.gif`` (looping, transparency flattened onto white). GIF frame delays are whole
  centiseconds of at least 2, so a GIF plays at most 50 fps: faster clips are written at
  50 fps with frames dropped evenly, and rates that are not 100/n fps get delays that
  alternate (30 fps: 3, 3, 4 cs …); either way the total duration stays the clip's;
* ``*.mp4`` / ``*.mov`` / ``*.mkv`` / ``*.webm`` / ``*.avi`` (H.264 or the container's
  default codec, odd sizes padded to even, transparency flattened onto white).

Any other suffix is an error listing these formats (``check_output``, which also checks that
the output location can be written before anything is rendered).
"""

from __future__ import annotations

import errno
import io
import math
import os
import tempfile
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.formats.atomic import (
    remove_stale_temporaries,
    replacing,
    writable_target,
    write_atomic,
    write_chunks_atomic,
)

VIDEO_SUFFIXES = {".mp4": "libx264", ".mov": "libx264", ".mkv": "libx264", ".avi": "mpeg4",
                  ".webm": "libvpx-vp9"}
IMAGE_SUFFIXES = {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff"}

Frame = npt.NDArray[np.uint8]


@dataclass(frozen=True)
class EncodedPng:
    """A frame already encoded as PNG (by a render worker): written to a folder or pattern as
    it is, decoded only for a GIF or a video. ``shape`` is the decoded array's shape."""

    data: bytes
    shape: tuple[int, int, int]

    @classmethod
    def of(cls, frame: npt.ArrayLike) -> EncodedPng:
        import imageio.v3 as iio

        a = np.asarray(frame)
        return cls(bytes(iio.imwrite("<bytes>", a, extension=".png")), (a.shape[0], a.shape[1], a.shape[2]))

    def decoded(self) -> Frame:
        import imageio.v3 as iio

        result: Frame = np.asarray(iio.imread(self.data, extension=".png"), dtype=np.uint8)
        return result

#: A GIF frame delay is a whole number of centiseconds; browsers play 0 or 1 cs as 10 cs.
GIF_MIN_DELAY_CS = 2
GIF_MAX_FPS = 100.0 / GIF_MIN_DELAY_CS
FORMATS_HELP = ("a folder, a pattern such as frame_%04d.png, a .gif, or a video ("
                + ", ".join(VIDEO_SUFFIXES) + ")")


def gif_fps(fps: float) -> float:
    """The frame rate a GIF of a ``fps`` clip is written at (at most 50)."""
    return min(float(fps), GIF_MAX_FPS)


def gif_timing_note(fps: float) -> str | None:
    """One sentence on how a ``fps`` clip's GIF is timed, or None when every frame simply
    gets the same whole-centisecond delay."""
    if fps > GIF_MAX_FPS:
        return (f"a GIF plays at most {GIF_MAX_FPS:g} fps (frame delays are whole centiseconds, at least 2): "
                f"{fps:g} fps is written at {GIF_MAX_FPS:g} fps, dropping frames evenly; the duration is kept")
    step = 100.0 / fps
    if abs(step - round(step)) > 1e-9:
        return (f"GIF frame delays are whole centiseconds: {fps:g} fps is written with delays of "
                f"{math.floor(step)} and {math.ceil(step)} cs in turn; the duration is kept")
    return None


def _gif_cs(i: int, fps: float) -> int:
    """The start of source frame ``i`` in whole centiseconds."""
    return math.floor(i * 100.0 / fps + 0.5)


def _gif_source_index(k: int, fps: float) -> int:
    """The source frame shown as GIF frame ``k`` when ``fps`` is above what a GIF holds."""
    return math.floor(k * fps / GIF_MAX_FPS + 1e-9)


def gif_delays(n_source: int, kept: int, fps: float) -> list[int]:
    """The delays (cs, each ≥ 2) of ``kept`` GIF frames made from ``n_source`` frames at ``fps``;
    they add up to the clip's duration. May return fewer delays than ``kept`` (drop the rest)."""
    total = max(_gif_cs(n_source, fps), GIF_MIN_DELAY_CS)
    if fps <= GIF_MAX_FPS:
        return [_gif_cs(i + 1, fps) - _gif_cs(i, fps) for i in range(kept)]
    if kept <= 1:
        return [total] * kept
    delays = [GIF_MIN_DELAY_CS] * (kept - 1)
    last = total - GIF_MIN_DELAY_CS * (kept - 1)
    if last >= GIF_MIN_DELAY_CS:
        return [*delays, last]
    delays[-1] += max(last, 0)  # too short to show: fold it into the frame before
    return delays


def check_output(out: str | os.PathLike[str]) -> str:
    """``output_kind(out)``, after checking that the output location can be written; raises
    ValueError (a bad name or format) or OSError naming the real path. Creates nothing."""
    kind = output_kind(out)
    path = os.path.abspath(os.fspath(out))
    if kind in ("gif", "video"):
        writable_target(path)  # a folder, a pipe, a device: refused (a link: its file is written)
    folder = path if kind == "folder" else os.path.dirname(path)
    probe = folder
    while not os.path.lexists(probe):
        parent = os.path.dirname(probe)
        if parent == probe:
            break
        probe = parent
    if not os.path.isdir(probe):
        raise NotADirectoryError(errno.ENOTDIR, "not a folder", probe)
    if not os.access(probe, os.W_OK | os.X_OK):
        raise PermissionError(errno.EACCES, "Permission denied", probe)
    try:  # os.access can say yes where a write fails (a read-only mount, root on a network share)
        fd, tmp = tempfile.mkstemp(prefix=".qtanimator-write-check.", dir=probe)
        os.close(fd)
        os.unlink(tmp)
    except OSError as exc:
        raise OSError(exc.errno, exc.strerror, probe) from None
    return kind


def output_kind(out: str | os.PathLike[str]) -> str:
    """``folder``, ``pattern``, ``gif`` or ``video`` for an output path."""
    s = os.fspath(out)
    suffix = Path(s).suffix.lower()
    if "%" in Path(s).name:
        name = Path(s).name
        try:
            first, second = name % 0, name % 1
        except (TypeError, ValueError, OverflowError):
            raise ValueError(f"'{name}' is not a frame pattern; use one number field such as "
                             "frame_%04d.png") from None
        if first == second:
            raise ValueError(f"'{name}' gives every frame the same name; use a number field such as "
                             "frame_%04d.png")
        return "pattern"
    if suffix == ".gif":
        return "gif"
    if suffix in VIDEO_SUFFIXES:
        return "video"
    if suffix in IMAGE_SUFFIXES:
        raise ValueError(f"'{s}' names one image; give a folder or a pattern such as frame_%04d.png")
    if suffix and not os.path.isdir(s):
        raise ValueError(f"'{s}': unknown output format '{suffix}'; give {FORMATS_HELP}")
    return "folder"


def _check_frame(frame: npt.ArrayLike, shape: tuple[int, ...] | None) -> Frame:
    a = np.asarray(frame)
    if a.dtype != np.uint8 or a.ndim != 3 or a.shape[2] not in (3, 4):
        raise ValueError("frames must be H×W×3 or H×W×4 uint8 arrays")
    if shape is not None and a.shape[:2] != shape[:2]:
        raise ValueError("all frames must have the same size")
    return a


def _checked_frames(frames: Iterable[npt.ArrayLike | EncodedPng], progress: Callable[[int], None] | None,
                    cancel: Callable[[], bool] | None, keep_encoded: bool = False) -> Iterator[Any]:
    """``frames`` checked for type and a common size, stopping when ``cancel()`` says so;
    ``progress(n)`` is called once the consumer has written frame ``n``."""
    shape = None
    done = 0
    for frame in frames:
        if cancel is not None and cancel():
            return
        if isinstance(frame, EncodedPng):
            if shape is not None and frame.shape[:2] != shape[:2]:
                raise ValueError("all frames must have the same size")
            shape = frame.shape
            yield frame if keep_encoded else frame.decoded()
        else:
            a = _check_frame(frame, shape)
            shape = a.shape
            yield a
        done += 1
        if progress is not None:
            progress(done)


def flatten_alpha(frame: Frame, background: tuple[int, int, int] = (255, 255, 255)) -> Frame:
    """An RGB copy of an RGBA frame composited over ``background``."""
    if frame.shape[2] == 3:
        return frame
    rgb = frame[..., :3].astype(np.float32)
    a = frame[..., 3:4].astype(np.float32) / 255.0
    bg = np.asarray(background, dtype=np.float32)
    return np.asarray(np.clip(rgb * a + bg * (1 - a) + 0.5, 0, 255), dtype=np.uint8)


def _even(frame: Frame) -> Frame:
    h, w = frame.shape[:2]
    if h % 2 == 0 and w % 2 == 0:
        return frame
    return np.pad(frame, ((0, h % 2), (0, w % 2), (0, 0)), mode="edge")


def write_frames(frames: Iterable[npt.ArrayLike | EncodedPng], out: str | os.PathLike[str], fps: float,
                 progress: Callable[[int], None] | None = None,
                 cancel: Callable[[], bool] | None = None, start: int = 0) -> int:
    """Write ``frames`` to ``out`` at ``fps``; returns the number of frames written.

    ``progress(n)`` is called after each frame; ``cancel()`` returning True stops early
    (what was written stays). ``start`` is the number of the first file of a sequence.
    """
    if not (fps > 0):
        raise ValueError("fps must be positive")
    kind = check_output(out)
    path = os.fspath(out)
    count = 0
    if kind in ("folder", "pattern"):
        import imageio.v3 as iio

        if kind == "folder":
            os.makedirs(path, exist_ok=True)
            pattern = os.path.join(path, "frame_%04d.png")
        else:
            pattern = path
            parent = os.path.dirname(path)
            if parent:
                os.makedirs(parent, exist_ok=True)
        remove_stale_temporaries(Path(pattern))  # once, not per frame
        for a in _checked_frames(frames, progress, cancel, keep_encoded=True):
            name = pattern % (start + count)
            # encoded by a render worker: the bytes as they are; a frame file that is a pipe
            # or a device is refused, a half-written frame never replaces an old one
            data = a.data if isinstance(a, EncodedPng) else bytes(iio.imwrite("<bytes>", a, extension=".png"))
            write_chunks_atomic(name, (data,), sync=False, clean=False)
            count += 1
        return count
    parent = os.path.dirname(os.path.abspath(path))
    os.makedirs(parent, exist_ok=True)
    if kind == "gif":
        from PIL import Image

        images: list[Image.Image] = []
        for a in _checked_frames(frames, progress, cancel):
            # above 50 fps only the frames nearest a 2 cs grid are kept (dropped evenly)
            if fps <= GIF_MAX_FPS or count == _gif_source_index(len(images), fps):
                images.append(Image.fromarray(flatten_alpha(a)).convert("P", palette=Image.Palette.ADAPTIVE))
            count += 1
        if images:
            delays = gif_delays(count, len(images), fps)
            images = images[:len(delays)]
            buffer = io.BytesIO()
            images[0].save(buffer, format="GIF", save_all=True, append_images=images[1:], loop=0,
                           duration=[10 * d for d in delays], optimize=False)
            write_atomic(path, buffer.getvalue())  # a failed export leaves the old file intact
        return count
    import imageio.v2 as iio2

    codec = VIDEO_SUFFIXES[Path(path).suffix.lower()]
    # ffmpeg writes a temporary file beside the target (same suffix: it picks the container
    # from it; the process id in its name lets the next render remove what a killed one
    # left), which replaces the target only once the video is complete.
    writer = None
    with replacing(path, suffix=Path(path).suffix.lower()) as tmp:
        try:
            for a in _checked_frames(frames, progress, cancel):
                if writer is None:
                    writer = iio2.get_writer(tmp.path, format="FFMPEG", mode="I", fps=float(fps), codec=codec,
                                             macro_block_size=1, quality=8, pixelformat="yuv420p",
                                             output_params=["-movflags", "+faststart"] if codec == "libx264"
                                             else None)
                writer.append_data(_even(flatten_alpha(a)))
                count += 1
        finally:
            if writer is not None:
                writer.close()
        if writer is None:
            tmp.discard()  # no frames: the old file stays
    return count


def count_video_frames(path: str | os.PathLike[str]) -> int:
    """The number of frames in a video or GIF file (decoded, not from the header)."""
    p = os.fspath(path)
    if Path(p).suffix.lower() == ".gif":
        from PIL import Image

        with Image.open(p) as im:
            return int(getattr(im, "n_frames", 1))
    import imageio.v2 as iio2

    reader: Any = iio2.get_reader(p, format="FFMPEG")  # imageio's stubs call it an Array
    try:
        n = 0
        for _ in reader:
            n += 1
        return n
    finally:
        reader.close()
