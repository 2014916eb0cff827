"""Parallel rendering for ``qtanimator render --jobs N`` and ``--dask ADDRESS``, 2D and 3D.

The parent loads the scene, runs the simulations over the rendered frames once and fixes the
camera: for the 2D view the pendulums (:meth:`PendulumCache.baked_states`) and the view
rectangle, for the 3D view the cloths (each shown frame's positions, handed to the worker's
:meth:`ClothCache.load_baked`) and the orbit camera and floor grid of the first frame. Each
chunk of contiguous frames becomes a :class:`ChunkSpec` or :class:`Chunk3D` (plain, picklable
data: the scene's path, the fps, the baked states, the camera, the times); :func:`render_chunk`
renders it in a worker process (its own ``QGuiApplication``: offscreen for 2D; for 3D the
parent's display, e.g. its private Xvfb, which a spawned worker inherits through ``DISPLAY``,
or a private Xvfb of its own) and returns the RGBA frames. Frames come back in order, so the
output is byte for byte what one process renders.

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
    from qtanimator.document.pendulum_cache import simulation
    from qtanimator.render.painter2d import animation_bounds

    view = animation_bounds(doc, times)  # evaluates every pose: the pendulums are simulated here
    return simulation(doc).baked_states(), (view.x(), view.y(), view.width(), view.height())


def chunk_specs(scene: str, doc: Any, times: Sequence[float], size: tuple[int, int], background: str,
                chunks: int, encode: bool = False) -> list[ChunkSpec]:
    """``times`` cut into ``chunks`` contiguous, nearly equal pieces, baked once."""
    states, view = bake_2d(doc, times)
    return [ChunkSpec(os.path.abspath(scene), float(doc.fps), states, view, (size[0], size[1]), background,
                      tuple(times[a:b]), encode) for a, b in _bounds(len(times), chunks)]


@dataclass(frozen=True)
class Chunk3D:
    """A chunk of the 3D view: the camera, view options (background, grid) and each cloth's
    positions at the chunk's frames (cloth asset id -> cache slot -> positions), all from
    the parent."""

    scene: str
    fps: float
    cloth: dict[str, dict[int, np.ndarray]]
    camera: Any  # render.gl.camera.OrbitCamera (a dataclass of floats and an array)
    options: Any  # render.gl.renderer.ViewOptions
    size: tuple[int, int]
    times: tuple[float, ...]
    encode: bool = False


def bake_3d(doc: Any, times: Sequence[float],
            background: str | None) -> tuple[Any, Any, dict[str, list[tuple[int, Any]]]]:
    """The camera and view options of the first frame (as :func:`render_frames_3d` frames
    them) and every visible cloth simulated over ``times`` in this process:
    ``(camera, options, {cloth id: [(cache slot, positions) at each time]})``."""
    from qtanimator.document import cloth
    from qtanimator.render.gl.renderer import grid_scale_for
    from qtanimator.render.headless import options_3d
    from qtanimator.render.render3d import default_camera
    from qtanimator.render.scene3d import scene_bounds, scene_items

    options = options_3d(background)
    items = scene_items(doc, float(times[0]))
    camera = default_camera(items, doc)
    bounds = scene_bounds(items)
    if bounds is not None:
        options.grid_scale = grid_scale_for(*bounds)
    baked: dict[str, list[tuple[int, Any]]] = {}
    for aid, asset in doc.assets.items():
        if asset.kind == cloth.ASSET_KIND and not asset.properties.get("hidden"):
            cache = cloth.cloth_cache(doc, aid)
            frames = [doc.time_to_frame(float(t)) for t in times]
            baked[aid] = [(cache.index_of(f), cache.positions(f)) for f in frames]
    return camera, options, baked


def chunk_specs_3d(scene: str, doc: Any, times: Sequence[float], size: tuple[int, int], background: str | None,
                   chunks: int, encode: bool = False) -> list[Chunk3D]:
    """``times`` cut into ``chunks`` contiguous pieces of the 3D view, simulated once."""
    camera, options, baked = bake_3d(doc, times, background)
    out = []
    for a, b in _bounds(len(times), chunks):
        cloths = {aid: dict(shown[a:b]) for aid, shown in baked.items()}
        out.append(Chunk3D(os.path.abspath(scene), float(doc.fps), cloths, camera, options, (size[0], size[1]),
                           tuple(float(t) for t in times[a:b]), encode))
    return out


def _bounds(n: int, chunks: int) -> list[tuple[int, int]]:
    chunks = max(1, min(chunks, n))
    bounds = [round(i * n / chunks) for i in range(chunks + 1)]
    return [(a, b) for a, b in zip(bounds, bounds[1:], strict=False) if b > a]


_LOCAL = threading.local()  # a Dask worker may run chunks on several threads


def _worker_document(scene: str, fps: float) -> Any:
    key = (scene, fps, os.stat(scene).st_mtime_ns)  # a re-saved project is loaded again
    cached = getattr(_LOCAL, "doc", None)
    if cached is not None and cached[0] == key:
        return cached[1]
    from qtanimator.document.commands import SetParameter
    from qtanimator.render.headless import load_scene

    doc = load_scene(scene)
    SetParameter(doc, "fps", fps).do(doc)
    _LOCAL.doc = (key, doc)
    return doc


def _encoded(frames: list[Any], encode: bool) -> list[Any]:
    if encode:
        from qtanimator.render.export import EncodedPng

        return [EncodedPng.of(a) for a in frames]
    return frames


def render_chunk(spec: ChunkSpec | Chunk3D) -> list[Any]:
    """RGBA frames of one chunk, or PNG-encoded ones (``spec.encode``); runs in a worker."""
    if isinstance(spec, Chunk3D):
        return _render_chunk_3d(spec)
    from qtanimator.render.headless import ensure_gui_app

    ensure_gui_app()
    from PySide6.QtCore import QRectF

    from qtanimator.document.pendulum_cache import simulation
    from qtanimator.render.painter2d import image_to_array, render_frame

    doc = _worker_document(spec.scene, spec.fps)
    simulation(doc).load_baked_states(spec.states)
    view = QRectF(*spec.view)
    frames = [image_to_array(render_frame(doc, t, spec.size, spec.background, view=view)) for t in spec.times]
    return _encoded(frames, spec.encode)


def _render_chunk_3d(spec: Chunk3D) -> list[Any]:
    import copy

    from qtanimator.render.render3d import ensure_gui_application, render_frames_3d

    ensure_gui_application()
    from qtanimator.document import cloth

    doc = _worker_document(spec.scene, spec.fps)
    for aid, frames in spec.cloth.items():
        cloth.cloth_cache(doc, aid).load_baked(frames)
    frames_3d = list(render_frames_3d(doc, spec.times, spec.size, camera=copy.deepcopy(spec.camera),
                                      options=spec.options))
    return _encoded(frames_3d, spec.encode)


def _ordered(submit: Callable[[Any], Any], result: Callable[[Any], list[np.ndarray]],
             specs: Sequence[Any], ahead: int) -> Iterator[np.ndarray]:
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


def _specs_for(view: str, scene: str, doc: Any, times: Sequence[float], size: tuple[int, int],
               background: str | None, chunks: int, encode: bool) -> list[Any]:
    if view == "3d":
        return chunk_specs_3d(scene, doc, times, size, background, chunks, encode)
    return chunk_specs(scene, doc, times, size, "white" if background is None else background, chunks, encode)


def frames_jobs(view: str, scene: str, doc: Any, times: Sequence[float], size: tuple[int, int],
                background: str | None, jobs: int, chunk_frames: int = 24, encode: bool = False) -> Iterator[Any]:
    """The frames of the ``view`` ("2d" or "3d") that one process renders, rendered in
    ``jobs`` spawned processes."""
    n_chunks = max(jobs, -(-len(times) // chunk_frames))
    specs = _specs_for(view, scene, doc, times, size, background, n_chunks, encode)
    jobs = max(1, min(jobs, len(specs)))
    pool = ProcessPoolExecutor(max_workers=jobs, mp_context=multiprocessing.get_context("spawn"))
    try:
        def submit(spec: Any) -> Future[list[np.ndarray]]:
            return pool.submit(render_chunk, spec)

        yield from _ordered(submit, lambda f: f.result(), specs, 2 * jobs)
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def frames_dask(view: str, scene: str, doc: Any, times: Sequence[float], size: tuple[int, int],
                background: str | None, address: str | Any, chunk_frames: int = 24,
                encode: bool = False) -> Iterator[Any]:
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
        specs = _specs_for(view, scene, doc, times, size, background, n_chunks, encode)

        def submit(spec: Any) -> Any:
            return client.submit(render_chunk, spec, pure=False)

        yield from _ordered(submit, lambda f: f.result(), specs, 2 * workers)
    finally:
        if own:
            client.close()
