"""Parallel 2D rendering for ``qtanimator render --jobs N`` and ``--dask ADDRESS``.

The parent loads the scene, bakes the pendulum simulation over the rendered frames once
(:meth:`PendulumCache.baked_states`) and fixes the camera. Each chunk of contiguous frames
becomes a :class:`ChunkSpec` (plain, picklable data: the scene's path, the fps, the baked
states, the camera rectangle, the times); :func:`render_chunk` renders it in a worker process
(its own offscreen ``QGuiApplication``) and returns the RGBA frames. Frames come back in order,
so the output is byte for byte what one process renders.

Workers are ``spawn``-ed processes (never ``fork``: the parent has Qt and simulation threads)
of :class:`concurrent.futures.ProcessPoolExecutor`, or the workers of a Dask distributed
cluster (the optional ``dask`` extra).
"""

from __future__ import annotations

import multiprocessing
import os
import threading
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import Future, ProcessPoolExecutor
from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass(frozen=True)
class ChunkSpec:
    scene: str
    fps: float
    states: dict[str, Any]
    view: tuple[float, float, float, float]
    size: tuple[int, int]
    background: str
    times: tuple[float, ...]
    #: the worker encodes its frames as PNG (the output is a folder or pattern of PNGs), so the
    #: parent only writes bytes
    encode: bool = False


def bake_2d(doc: Any, times: Sequence[float]) -> tuple[dict[str, Any], tuple[float, float, float, float]]:
    """Simulate the pendulums over ``times`` in this process and fix the camera:
    ``(baked states, (x, y, w, h))``."""
    from qtanimator.document.character2d import simulation
    from qtanimator.render.painter2d import animation_bounds

    view = animation_bounds(doc, times)  # evaluates every pose: the pendulums are simulated here
    return simulation(doc).baked_states(), (view.x(), view.y(), view.width(), view.height())


def chunk_specs(scene: str, doc: Any, times: Sequence[float], size: tuple[int, int], background: str,
                chunks: int, encode: bool = False) -> list[ChunkSpec]:
    """``times`` cut into ``chunks`` contiguous, nearly equal pieces, baked once."""
    states, view = bake_2d(doc, times)
    n = len(times)
    chunks = max(1, min(chunks, n))
    bounds = [round(i * n / chunks) for i in range(chunks + 1)]
    return [ChunkSpec(os.path.abspath(scene), float(doc.fps), states, view, (size[0], size[1]), background,
                      tuple(times[a:b]), encode) for a, b in zip(bounds, bounds[1:], strict=False) if b > a]


_LOCAL = threading.local()  # a Dask worker may run chunks on several threads


def _worker_document(spec: ChunkSpec) -> Any:
    key = (spec.scene, spec.fps, os.stat(spec.scene).st_mtime_ns)  # a re-saved project is loaded again
    cached = getattr(_LOCAL, "doc", None)
    if cached is not None and cached[0] == key:
        return cached[1]
    from qtanimator.render.cli_render import load_scene

    doc = load_scene(spec.scene)
    doc.parameters["fps"] = spec.fps
    _LOCAL.doc = (key, doc)
    return doc


def render_chunk(spec: ChunkSpec) -> list[Any]:
    """RGBA frames of one chunk, or PNG-encoded ones (``spec.encode``); runs in a worker."""
    from qtanimator.render.cli_render import _ensure_gui_app

    _ensure_gui_app()
    from PySide6.QtCore import QRectF

    from qtanimator.document.character2d import simulation
    from qtanimator.render.painter2d import image_to_array, render_frame

    doc = _worker_document(spec)
    simulation(doc).load_baked_states(spec.states)
    view = QRectF(*spec.view)
    frames = [image_to_array(render_frame(doc, t, spec.size, spec.background, view=view)) for t in spec.times]
    if spec.encode:
        from qtanimator.render.export import EncodedPng

        return [EncodedPng.of(a) for a in frames]
    return frames


def _ordered(submit: Callable[[ChunkSpec], Any], result: Callable[[Any], list[np.ndarray]],
             specs: Sequence[ChunkSpec], ahead: int) -> Iterator[np.ndarray]:
    """Frames of ``specs`` in order, with at most ``ahead`` chunks submitted and not yet read."""
    pending: deque[Any] = deque()
    todo = iter(specs)
    for spec in todo:
        pending.append(submit(spec))
        if len(pending) >= ahead:
            break
    while pending:
        frames = result(pending.popleft())
        following = next(todo, None)
        if following is not None:
            pending.append(submit(following))
        yield from frames


def frames_2d_jobs(scene: str, doc: Any, times: Sequence[float], size: tuple[int, int], background: str,
                   jobs: int, chunk_frames: int = 24, encode: bool = False) -> Iterator[Any]:
    """The frames of :func:`qtanimator.render.cli_render.frames_2d`, rendered in ``jobs``
    spawned processes."""
    n_chunks = max(jobs, -(-len(times) // chunk_frames))
    specs = chunk_specs(scene, doc, times, size, background, n_chunks, encode)
    jobs = max(1, min(jobs, len(specs)))
    pool = ProcessPoolExecutor(max_workers=jobs, mp_context=multiprocessing.get_context("spawn"))
    try:
        def submit(spec: ChunkSpec) -> Future[list[np.ndarray]]:
            return pool.submit(render_chunk, spec)

        yield from _ordered(submit, lambda f: f.result(), specs, 2 * jobs)
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def frames_2d_dask(scene: str, doc: Any, times: Sequence[float], size: tuple[int, int], background: str,
                   address: str | Any, chunk_frames: int = 24, encode: bool = False) -> Iterator[Any]:
    """The same chunks sent to a Dask distributed scheduler at ``address`` (or an existing
    ``distributed.Client``)."""
    try:
        from distributed import Client
    except ImportError:
        raise ValueError("--dask needs the 'distributed' package: pip install 'qtanimator[dask]'") from None
    own = not isinstance(address, Client)
    client: Any = Client(address) if own else address
    try:
        workers = max(1, sum(client.nthreads().values()))
        n_chunks = max(workers, -(-len(times) // chunk_frames))
        specs = chunk_specs(scene, doc, times, size, background, n_chunks, encode)

        def submit(spec: ChunkSpec) -> Any:
            return client.submit(render_chunk, spec, pure=False)

        yield from _ordered(submit, lambda f: f.result(), specs, 2 * workers)
    finally:
        if own:
            client.close()
