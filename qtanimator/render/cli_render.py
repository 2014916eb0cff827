"""``qtanimator render SCENE -o OUT``: render without a window.

SCENE is any file the program opens: a project (``.qtanim``), an SVG character file or folder,
or a 3D file (``.skel``, ``.bvh``, ``.glb`` …, imported into a new document as File ▸ Open does).
OUT is a folder, a ``frame_%04d.png`` pattern, a ``.gif`` or a video (``.mp4``). Dynamic joints are simulated
(the pendulum cache steps forward frame by frame). The camera is fixed: the union of the
scene's bounds over the rendered frames, fitted into ``--size``.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Iterator, Sequence
from typing import Any, NoReturn

from qtanimator.document.parameters import RENDER
from qtanimator.formats.errors import FormatError
from qtanimator.render import parallel
from qtanimator.render.headless import ensure_gui_app, frames_2d, load_scene, options_3d

__all__ = ["choose_view", "frames_2d", "load_scene", "options_3d", "render_main"]


class _OneLineParser(argparse.ArgumentParser):
    """argparse, but a usage error is one line on stderr (exit status 2), as in ``qtanimator``."""

    def error(self, message: str) -> NoReturn:
        print(f"{self.prog}: {message} (try '{self.prog} --help')", file=sys.stderr)
        raise SystemExit(2)


def _parser() -> argparse.ArgumentParser:
    p = _OneLineParser(prog="qtanimator render",
                                description="Render a project or SVG character to PNG frames, a GIF or a video.")
    p.add_argument("scene", help="a project (.qtanim), an SVG character, a folder of SVG characters, or a 3D "
                                 "file (.skel, .skin, .anim, .obj, .bvh, .glb, .gltf)")
    p.add_argument("-o", "--output", required=True,
                   help="a folder, a pattern such as frames/frame_%%04d.png, a .gif (at most 50 fps: faster "
                        "clips drop frames evenly, keeping the duration) or a video (.mp4, .mov, .mkv, .webm, .avi)")
    p.add_argument("--frames", help="frame range A:B (inclusive); the project's range by default")
    p.add_argument("--fps", type=float, help="frames per second (the project's by default)")
    size = f"{RENDER['render.width'].default}x{RENDER['render.height'].default}"  # the Export dialog's too
    p.add_argument("--size", default=size, help=f"image size WxH (default {size})")
    p.add_argument("--background",
                   help="a colour name or #rrggbb, or 'transparent' (default: white in 2D, the viewport's "
                        "grey in 3D)")
    p.add_argument("--view", choices=("auto", "2d", "3d"), default="auto",
                   help="the 2D renderer or the 3D viewport (default: 2d when the scene has 2D "
                        "characters, else 3d)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--jobs", type=int,
                   help="render in N processes (default: all cores for 120 PNG frames or more, else 1); "
                        "pendulums and cloth are simulated once, here")
    p.add_argument("--dask", metavar="ADDRESS",
                   help="render on a Dask distributed cluster (scheduler address such as "
                        "tcp://host:8786; needs the 'dask' extra)")
    return p


def _parse_size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise ValueError(f"--size must look like 960x640, got '{text}'") from None
    if w <= 0 or h <= 0 or w > 16384 or h > 16384:
        raise ValueError(f"--size must be between 1x1 and 16384x16384, got '{text}'")
    return w, h


def _parse_frames(text: str | None, default: tuple[int, int]) -> tuple[int, int]:
    if text is None:
        return default
    try:
        a, b = text.split(":")
        first = int(a) if a.strip() else default[0]
        last = int(b) if b.strip() else default[1]
    except ValueError:
        raise ValueError(f"--frames must look like 0:120, got '{text}'") from None
    if last < first:
        raise ValueError(f"--frames: the last frame ({last}) comes before the first ({first})")
    return first, last


class _Progress:
    """The render's progress bar: a tqdm bar on stderr when stderr is a terminal; nothing
    when it is not (a log file or a pipe gets no ``\\r`` lines, only the final summary)."""

    def __init__(self, total: int, enabled: bool) -> None:
        self.total = max(total, 1)
        isatty = getattr(sys.stderr, "isatty", None)
        self.enabled = enabled and bool(isatty and isatty())
        self._bar: Any = None
        if self.enabled:
            from tqdm import tqdm

            self._bar = tqdm(total=self.total, file=sys.stderr, unit="frame", desc="rendering",
                             dynamic_ncols=True, leave=True)

    def __call__(self, done: int) -> None:
        if self._bar is None:
            return
        self._bar.update(done - self._bar.n)
        if done >= self.total:
            self.close()

    def close(self) -> None:
        """End the bar's line (also when the render stops early)."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None


def _frames_any(ns: argparse.Namespace, doc: Any, times: Sequence[float], size: tuple[int, int]) -> Iterator[Any]:
    """The frames of ``ns.view`` in this process, in ``--jobs`` processes or on a ``--dask``
    cluster (the same frames, byte for byte)."""
    from qtanimator.render.export import output_kind

    if ns.jobs is not None and ns.jobs < 1:
        raise ValueError("--jobs must be at least 1")
    # PNG frames are encoded by the workers (the parent only writes the bytes); a GIF or a
    # video needs the raw frames in the parent.
    encode = output_kind(ns.output) in ("folder", "pattern")
    if ns.dask:
        return parallel.frames_dask(ns.view, ns.scene, doc, times, size, ns.background, ns.dask, encode=encode)
    # By default all cores for PNG frames (encoded by the workers: 1.5-1.7x on 2 cores,
    # benchmarks/results/issue15_render_jobs.txt) of 120 frames or more (a worker takes about
    # a second to start); one process for a GIF or a video, which the parent encodes.
    jobs = ns.jobs if ns.jobs is not None else (os.cpu_count() or 1) if encode and len(times) >= 120 else 1
    if jobs > 1 and len(times) > 1:
        return parallel.frames_jobs(ns.view, ns.scene, doc, times, size, ns.background, jobs, encode=encode)
    if ns.view == "3d":
        from qtanimator.render.render3d import render_frames_3d

        return render_frames_3d(doc, times, size, options=options_3d(ns.background))
    return frames_2d(doc, times, size, "white" if ns.background is None else ns.background)


_KINDS_2D = ("character2d",)
_KINDS_3D = ("character3d", "cloth")


def choose_view(doc: Any, view: str) -> str:
    """``2d`` or ``3d`` for ``--view``; ValueError when that view would show nothing."""
    kinds = {a.kind for a in doc.assets.values()}
    has_2d = any(k in kinds for k in _KINDS_2D)
    has_3d = any(k in kinds for k in _KINDS_3D)
    if view == "auto":
        if not (has_2d or has_3d):
            raise ValueError("the scene has nothing to render (no 2D characters, 3D characters or cloth)")
        return "2d" if has_2d else "3d"
    if view == "2d" and not has_2d:
        raise ValueError("the scene has no 2D characters to render; try --view 3d")
    if view == "3d" and not has_3d:
        raise ValueError("the scene has no 3D characters or cloth to render; try --view 2d")
    return view


def _negative_frames(argv: Sequence[str]) -> list[str]:
    """``--frames -5:3`` as ``--frames=-5:3`` (argparse takes ``-5:3`` for an option)."""
    out: list[str] = []
    args = list(argv)
    i = 0
    while i < len(args):
        if args[i] == "--frames" and i + 1 < len(args) and args[i + 1].startswith("-") and ":" in args[i + 1]:
            out.append(f"--frames={args[i + 1]}")
            i += 2
            continue
        out.append(args[i])
        i += 1
    return out


def _os_message(exc: OSError) -> str:
    if exc.strerror and exc.filename:
        return f"cannot write '{exc.filename}': {exc.strerror}"
    return str(exc)


def render_main(argv: Sequence[str]) -> int:
    """Entry point of ``qtanimator render``; returns the exit status.

    SIGTERM / SIGINT end the render cleanly (temporary files removed, an existing GIF or
    video left as it was, the private Xvfb stopped at exit) with status 128 + signal.
    """
    from qtanimator.render.interrupt import RenderInterrupted, interrupt_on_signals, report_interrupted

    try:
        with interrupt_on_signals():
            return _render_main(argv)
    except RenderInterrupted as exc:
        return report_interrupted(exc)


def _render_main(argv: Sequence[str]) -> int:
    ns = _parser().parse_args(_negative_frames(argv))
    try:
        size = _parse_size(ns.size)
        doc = load_scene(ns.scene)
        ns.view = choose_view(doc, ns.view)
        if ns.fps is not None:
            if not ns.fps > 0:
                raise ValueError("--fps must be positive")
            from qtanimator.document.commands import SetParameter

            SetParameter(doc, "fps", float(ns.fps)).do(doc)  # the frame numbers stay (not set_fps_command)
        first, last = _parse_frames(ns.frames, doc.frame_range)
        fps = doc.fps
        times = [f / fps for f in range(first, last + 1)]
        from qtanimator.render.export import check_output, gif_timing_note, write_frames

        kind = check_output(ns.output)  # a bad format or an unwritable place fails before rendering
        note = gif_timing_note(fps) if kind == "gif" else None
        if note and not ns.quiet:
            print(f"qtanimator render: {note}", file=sys.stderr)
        if ns.view == "3d":
            try:
                from qtanimator.render import render3d
            except ImportError as exc:
                print(f"qtanimator render: the 3D view is not available ({exc}).", file=sys.stderr)
                return 2
            # the 3D renderer knows how to get a GL-capable platform (a private Xvfb headless)
            render3d.ensure_gui_application()
        else:
            ensure_gui_app()
        from qtanimator.render.painter2d import background_color

        if ns.background is not None:
            background_color(ns.background)  # a bad colour fails before rendering
        frames = _frames_any(ns, doc, times, size)
        progress = _Progress(len(times), not ns.quiet)
        try:
            n = write_frames(frames, ns.output, fps, progress=progress, start=first)
        finally:
            progress.close()
    except (FormatError, ValueError) as exc:
        print(f"qtanimator render: {exc}", file=sys.stderr)
        return 1
    except OSError as exc:
        print(f"qtanimator render: {_os_message(exc)}", file=sys.stderr)
        return 1
    if not ns.quiet:
        print(f"wrote {n} frames to {ns.output}", file=sys.stderr)
    return 0
