"""Cloth assets in the document: creation, parameter edits and a per-frame simulation cache.

A cloth asset has ``kind == "cloth"``, no source file, and ``ClothParams.to_dict()`` as its
properties. Its runtime object (``doc.runtime[asset_id]``) is a :class:`ClothCache`: the live
simulation plus the positions of every frame simulated so far. Frame ``frame_start`` is the
rest state; frame ``f`` is ``f − frame_start`` steps of ``1/fps`` later (fractional frames
round down). Asking for a frame past the cache steps forward from the last cached frame. The
cache is rebuilt when the asset's properties, the fps or ``frame_start`` change (undo included),
because it compares them with the ones it was built from on every call.

When the simulation blows up, :func:`cloth_state` keeps returning the last good frame and
:func:`cloth_problem` returns the :class:`~qtanimator.core.cloth.ClothBlowUp` whose message
says which parameter to change.

Threads: a :class:`ClothCache` may be filled by a worker thread
(:mod:`qtanimator.document.cloth_worker`) while the UI thread reads it. Stepping is
serialised by the cache's lock, one frame at a time; :meth:`ClothCache.latest` never waits
(it returns the newest frame already there), :meth:`ClothCache.positions` steps (or waits
for the worker's current frame) until the frame asked for exists, as headless rendering
and export need.
"""

from __future__ import annotations

import copy
import math
import threading
from collections.abc import Callable, Hashable, Mapping
from typing import Any

import numpy as np

from qtanimator.core.cloth import Cloth, ClothBlowUp, ClothParams, ClothStepCancelled, FloatArray
from qtanimator.document.cloth_attach import ClothDriver, build_driver, driver_key
from qtanimator.document.commands import AddAsset, Command, SetAssetProperty
from qtanimator.document.document import Asset, Document
from qtanimator.formats.errors import FormatError

ASSET_KIND = "cloth"


class ClothCache:
    """The runtime object of a cloth asset: a :class:`Cloth` and the positions of every
    frame simulated so far (read-only arrays; frame ``frame_start`` is the rest state)."""

    def __init__(self, properties: dict[str, Any], fps: float = 60.0, frame_start: int = 0,
                 driver: ClothDriver | None = None) -> None:
        self.properties = copy.deepcopy(properties)
        self.params = ClothParams.from_dict(properties)
        self.fps = float(fps)
        self.frame_start = int(frame_start)
        self.cloth = Cloth(self.params)
        #: The character joint and capsules an attached cloth follows (document.cloth_attach).
        self.driver = driver
        self.driver_key = None if driver is None else driver.key
        self._local = np.zeros((0, 3))
        if driver is not None:
            self._local = driver.pin_locals(self.cloth)
            driver.place(self.cloth, self._local)
        self.frames: list[FloatArray] = [self._freeze(self.cloth.positions)]
        self.error: ClothBlowUp | None = None
        self._lock = threading.Lock()
        #: frames simulated in another process, by cache slot (see :meth:`load_baked`)
        self._baked: dict[int, FloatArray] = {}

    @staticmethod
    def _freeze(a: FloatArray) -> FloatArray:
        out = np.array(a, dtype=np.float64)
        out.flags.writeable = False
        return out

    def matches(self, properties: dict[str, Any], fps: float, frame_start: int) -> bool:
        # Hiding or locking a cloth in the outliner does not change its simulation.
        def simulated(props: dict[str, Any]) -> dict[str, Any]:
            return {k: v for k, v in props.items() if k not in ("hidden", "locked")}
        return (simulated(self.properties) == simulated(properties) and self.fps == float(fps)
                and self.frame_start == int(frame_start))

    @property
    def triangles(self) -> Any:
        return self.cloth.triangles

    def index_of(self, frame: float) -> int:
        """The cache slot of ``frame``: whole frames from ``frame_start`` (rounded down, ≥ 0)."""
        if not math.isfinite(frame):
            raise ValueError("frame must be finite")
        return max(0, math.floor(frame + 1e-9) - self.frame_start)

    def step_frame(self, should_stop: Callable[[], bool] | None = None) -> bool:
        """Simulate the next frame and cache it. False when nothing was added: the
        simulation has blown up (see :attr:`error`) or ``should_stop`` cancelled the step
        (the cloth is then as it was, so the next call computes the same frame)."""
        with self._lock:
            if self.error is not None:
                return False
            try:
                if self.driver is not None:
                    self.driver.apply(self.cloth, self._local, len(self.frames))
                self.cloth.step(1.0 / self.fps, should_stop)
            except ClothStepCancelled:
                return False
            except ClothBlowUp as exc:
                self.error = exc
                return False
            self.frames.append(self._freeze(self.cloth.positions))
            return True

    def fill(self, count: int, should_stop: Callable[[], bool] | None = None) -> bool:
        """Simulate until ``count`` frames are cached; False if stopped or blown up first."""
        while len(self.frames) < count:
            if should_stop is not None and should_stop():
                return False
            if not self.step_frame(should_stop):
                return False
        return True

    def load_baked(self, frames: Mapping[int, FloatArray]) -> None:
        """Use frames simulated elsewhere, by cache slot: ``render --jobs`` simulates the cloth
        once in the parent and hands each worker the frames its chunk shows, which
        :meth:`positions` then returns without simulating."""
        self._baked = {int(k): self._freeze(v) for k, v in frames.items()}

    def positions(self, frame: float) -> FloatArray:
        """Positions at ``frame`` (read-only array), simulating forward as needed."""
        k = self.index_of(frame)
        baked = self._baked.get(k)
        if baked is not None:
            return baked
        self.fill(k + 1)
        return self.frames[min(k, len(self.frames) - 1)]

    def latest(self, frame: float) -> tuple[FloatArray, bool]:
        """Positions at ``frame`` if cached, else the newest cached frame; never waits.

        Returns ``(positions, exact)``; ``exact`` is False when an earlier frame stands in.
        """
        k = self.index_of(frame)
        frames = self.frames
        n = len(frames)
        return frames[min(k, n - 1)], k < n

    @property
    def cached_frames(self) -> int:
        """How many frames (from ``frame_start``) are cached, the rest state included."""
        return len(self.frames)


def load_cloth_asset(asset: Asset) -> ClothCache:
    """The loader for cloth assets (registered in ``qtanimator.document.loaders``).

    The sizes and placement that reach the 3D camera (:data:`PLACED`) must lie within the
    schema's ranges (a cloth 1e308 m wide has no finite bounding box); the other parameters
    are checked by :meth:`ClothParams.validate`."""
    from qtanimator.document.parameters import CLOTH

    try:
        for name in PLACED:
            if asset.properties.get(name) is not None:
                CLOTH[name].validate(asset.properties[name], f"{asset.id}.{name}")
        return ClothCache(asset.properties)
    except (ValueError, TypeError, KeyError, ArithmeticError) as exc:
        raise FormatError(f"cloth '{asset.id}' has an invalid parameter: {exc}") from exc


#: Cloth properties whose schema range is enforced when a project is opened.
PLACED = ("width", "height", "origin")


def add_cloth_command(doc: Document, params: ClothParams | None = None, asset_id: str | None = None) -> Command:
    """A command that adds a cloth asset (id ``cloth``, ``cloth_2``… unless given)."""
    params = ClothParams() if params is None else params
    params.validate()
    aid = asset_id if asset_id is not None else doc.unique_asset_id("cloth")
    if aid in doc.assets:
        raise ValueError(f"there is already an asset called {aid!r}")
    asset = Asset(aid, ASSET_KIND, None, params.to_dict())
    start = doc.frame_range[0]
    return AddAsset(asset, runtime=ClothCache(asset.properties, doc.fps, start), text="Add Cloth")


def cloth_params(doc: Document, asset_id: str) -> ClothParams:
    """The parameters of a cloth asset as a ClothParams."""
    asset = doc.assets[asset_id]
    if asset.kind != ASSET_KIND:
        raise ValueError(f"asset {asset_id!r} is a {asset.kind}, not a cloth")
    return ClothParams.from_dict(asset.properties)


def set_cloth_param_command(doc: Document, asset_id: str, name: str, value: Any,
                            gesture: Hashable | None = None) -> Command:
    """A command that sets one cloth parameter (validated; ValueError names a bad value).

    Commands with the same ``gesture`` merge into one undo step (a slider drag).
    """
    params = cloth_params(doc, asset_id).replace(**{name: value})
    stored = params.to_dict()[name]
    return SetAssetProperty(doc, asset_id, name, stored, text=f"Set cloth {name.replace('_', ' ')}",
                            gesture=gesture)


def cloth_cache(doc: Document, asset_id: str) -> ClothCache:
    """The up-to-date cache of a cloth asset (rebuilt when its inputs changed)."""
    asset = doc.assets[asset_id]
    if asset.kind != ASSET_KIND:
        raise ValueError(f"asset {asset_id!r} is a {asset.kind}, not a cloth")
    start = doc.frame_range[0]
    cache = doc.runtime.get(asset_id)
    key = driver_key(doc, asset.properties)
    if (not isinstance(cache, ClothCache) or not cache.matches(asset.properties, doc.fps, start)
            or cache.driver_key != key):
        driver = build_driver(doc, asset.properties) if key is not None else None
        cache = ClothCache(asset.properties, doc.fps, start, driver)
        doc.runtime[asset_id] = cache
    return cache


def cloth_state(doc: Document, asset_id: str, frame: float) -> FloatArray:
    """Positions (N, 3) of a cloth asset at ``frame``; a read-only array, never NaN."""
    return cloth_cache(doc, asset_id).positions(frame)


def cloth_problem(doc: Document, asset_id: str) -> ClothBlowUp | None:
    """The blow-up that stopped this cloth's cached simulation, if any."""
    return cloth_cache(doc, asset_id).error
