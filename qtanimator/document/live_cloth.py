"""The interactive live cloths, stepped in real time on their own thread (ARCHITECTURE §3:
simulations never run on the UI thread).

:class:`LiveCloths` runs the interactive cloths (pins moved with the keyboard, a particle
grabbed with the mouse) in real time on a thread; the UI sends it edits (which never wait
for a step in flight) and draws its latest :class:`LiveClothFrame`; views poll
:attr:`LiveCloths.version` from a timer. The cache worker that fills the document's cloth
caches is :mod:`qtanimator.document.cloth_worker`.

The symplectic substep is one numba kernel that releases the GIL (``nogil=True``), and a
thread that holds the GIL hands it over every ``sys.getswitchinterval()`` (5 ms), so the UI
thread keeps running while it works.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from qtanimator.core.cloth import (
    BoolArray,
    Cloth,
    ClothParams,
    FloatArray,
    IntArray,
    nearest_particle,
)
from qtanimator.document.cloth import ASSET_KIND, cloth_params
from qtanimator.document.document import Document


@dataclass(frozen=True)
class LiveClothFrame:
    """A snapshot of a live cloth for drawing and picking (copies, never changed)."""

    positions: FloatArray
    triangles: IntArray
    params: ClothParams
    pinned: BoolArray
    pin_targets: FloatArray
    time: float
    grabbed: int | None
    vertex_normals: FloatArray = field(repr=False)

    def normals(self) -> FloatArray:
        return self.vertex_normals


def _snapshot(cloth: Cloth) -> LiveClothFrame:
    positions = cloth.positions.copy()
    normals = cloth.normals()
    return LiveClothFrame(positions, cloth.triangles, cloth.params, cloth.pinned, cloth.pin_targets.copy(),
                          cloth.time, cloth.grabbed, normals)


class LiveCloths:
    """Interactive cloth simulations, one per cloth asset, stepped in real time on a thread.

    While ``enabled`` (and not ``paused``) a thread steps every cloth by ``dt`` whenever the
    wall clock has moved on by ``dt`` (at most three steps behind: a slow simulation runs in
    slow motion instead of piling up). Edits (:meth:`move_pins`, :meth:`grab`,
    :meth:`drag_grabbed`, :meth:`release`, :meth:`reset`, :meth:`sync`) are applied at once
    when no step is in flight, else queued and applied, in order, before the next step: the
    caller never waits. Views draw :meth:`frame` / :meth:`frames` (snapshots); ``cloths``
    holds the simulations themselves, to be read only while the thread is idle (paused).
    """

    def __init__(self, dt: float = 1.0 / 60.0, clock: Callable[[], float] = time.monotonic) -> None:
        self.dt = float(dt)
        self.cloths: dict[str, Cloth] = {}
        self.errors: dict[str, str] = {}
        #: Bumped whenever a snapshot changes (views poll it).
        self.version = 0
        self._clock = clock
        self._enabled = False
        self._paused = False
        self._closed = False
        self._stepping = False
        self._frames: dict[str, LiveClothFrame] = {}
        self._ops: list[Callable[[], None]] = []
        self._sim = threading.Lock()          # held while stepping or applying edits
        self._cond = threading.Condition()    # guards _ops and the flags, wakes the thread
        self._thread: threading.Thread | None = None

    # ------------------------------------------------------------- switches
    @property
    def enabled(self) -> bool:
        return self._enabled

    @enabled.setter
    def enabled(self, on: bool) -> None:
        with self._cond:
            self._enabled = bool(on)
            if on and self._thread is None and not self._closed:
                self._thread = threading.Thread(target=self._run, name="live-cloth", daemon=True)
                self._thread.start()
            self._cond.notify_all()

    @property
    def paused(self) -> bool:
        return self._paused

    @paused.setter
    def paused(self, on: bool) -> None:
        with self._cond:
            self._paused = bool(on)
            self._cond.notify_all()

    @property
    def stepping(self) -> bool:
        """True while a step is in flight on the thread."""
        return self._stepping

    def close(self, timeout: float = 5.0) -> None:
        with self._cond:
            self._closed = True
            self._cond.notify_all()
            thread = self._thread
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout)

    # ---------------------------------------------------------------- edits
    #: How long an edit may wait for the thread to let go of the cloths (seconds): enough for
    #: it to finish applying edits, far less than a step (then the edit is queued).
    SUBMIT_WAIT_S = 0.005

    def _submit(self, op: Callable[[], None]) -> None:
        """Apply ``op`` now if no step is in flight, else before the next step."""
        with self._cond:
            self._ops.append(op)
            self._cond.notify_all()
        if self._sim.acquire(timeout=self.SUBMIT_WAIT_S):
            try:
                self._apply_ops()
            finally:
                self._sim.release()

    def settle(self, timeout: float = 5.0) -> bool:
        """Wait until no step is in flight (True) or ``timeout`` passed (False). After
        ``paused = True`` and ``settle()`` the thread steps no more: the cloths may be read."""
        if self._sim.acquire(timeout=timeout):
            self._sim.release()
            return True
        return False

    def _running(self) -> bool:
        return self._enabled and not self._paused and not self._closed

    def _apply_ops(self) -> None:
        """With ``_sim`` held: apply the queued edits in order and publish the result."""
        with self._cond:
            ops, self._ops = self._ops, []
        if not ops:
            return
        for op in ops:
            op()
        self._publish()

    def sync(self, doc: Document) -> None:
        """Create live cloths for new cloth assets, drop removed ones, follow parameter edits."""
        wanted: dict[str, ClothParams] = {}
        invalid: dict[str, str] = {}
        for aid, asset in doc.assets.items():
            if asset.kind != ASSET_KIND:
                continue
            try:
                wanted[aid] = cloth_params(doc, aid)
            except (ValueError, TypeError, KeyError) as exc:
                # no live cloth with made-up parameters: the Cloth dock shows why there is none
                invalid[aid] = f"invalid parameters: {exc}"
        fresh = {aid: Cloth(p) for aid, p in wanted.items() if aid not in self.cloths}

        def apply() -> None:
            for aid in [a for a in self.cloths if a not in wanted]:
                del self.cloths[aid]
                self._frames.pop(aid, None)
                self.errors.pop(aid, None)
            self.errors.update(invalid)
            for aid, params in wanted.items():
                cloth = self.cloths.get(aid)
                if cloth is None:
                    self.cloths[aid] = fresh.get(aid) or Cloth(params)
                    self.errors.pop(aid, None)
                elif cloth.params != params:
                    cloth.set_params(params)
                    self.errors.pop(aid, None)

        self._submit(apply)

    def clear(self) -> None:
        """Forget every live cloth (a new document); :meth:`sync` makes them again."""
        def apply() -> None:
            self.cloths.clear()
            self.errors.clear()
            self._frames = {}

        self._submit(apply)

    def reset(self) -> None:
        """Every live cloth back to its rest state."""
        def apply() -> None:
            for cloth in self.cloths.values():
                cloth.reset()
            self.errors.clear()

        self._submit(apply)

    def move_pins(self, translation: Any = (0.0, 0.0, 0.0), rotation: Any = None) -> None:
        def apply() -> None:
            for cloth in self.cloths.values():
                cloth.move_pins(translation, rotation)

        self._submit(apply)

    def grab(self, ray_origin: Any, ray_dir: Any,
             max_distance: Callable[[ClothParams], float] | None = None) -> tuple[str, FloatArray] | None:
        """Grab the particle nearest to a ray in the latest snapshots: ``(asset id, where)``
        or None. ``max_distance(params)`` limits how far from the ray a particle may be."""
        for aid, frame in self.frames().items():
            limit = None if max_distance is None else max_distance(frame.params)
            index = nearest_particle(frame.positions, ray_origin, ray_dir, limit)
            if index is not None:
                def apply(a: str = aid, i: int = index) -> None:
                    cloth = self.cloths.get(a)
                    if cloth is not None and i < cloth.n:
                        cloth.grab_particle(i)

                self._submit(apply)
                return aid, frame.positions[index].copy()
        return None

    def drag_grabbed(self, asset_id: str, target: Any) -> None:
        point = np.asarray(target, dtype=np.float64).reshape(3).copy()

        def apply() -> None:
            cloth = self.cloths.get(asset_id)
            if cloth is not None:
                cloth.drag_grabbed(point)

        self._submit(apply)

    def release(self) -> None:
        def apply() -> None:
            for cloth in self.cloths.values():
                cloth.release()

        self._submit(apply)

    # ------------------------------------------------------------- stepping
    def step(self, dt: float | None = None) -> None:
        """Step every cloth once now, on the calling thread (waits for a step in flight)."""
        with self._sim:
            self._apply_ops()
            self._step_all(self.dt if dt is None else dt)

    def _step_all(self, dt: float) -> None:
        for aid, cloth in list(self.cloths.items()):
            if cloth.error is not None:
                continue
            try:
                cloth.step(dt)
            except RuntimeError as exc:  # ClothBlowUp: the cloth stays stopped until reset
                self.errors[aid] = str(exc)
        self._publish()

    def _publish(self) -> None:
        self._frames = {aid: _snapshot(c) for aid, c in self.cloths.items()}
        self.version += 1

    def frame(self, asset_id: str) -> LiveClothFrame | None:
        """The latest snapshot of one live cloth."""
        return self._frames.get(asset_id)

    def frames(self) -> dict[str, LiveClothFrame]:
        """The latest snapshots of every live cloth (what a view draws)."""
        return dict(self._frames)

    def _run(self) -> None:
        last = self._clock()
        acc = 0.0
        while True:
            with self._cond:
                while not self._closed and not self._ops and not self._running():
                    self._cond.wait()
                    last, acc = self._clock(), 0.0
                if self._closed:
                    return
            running = False
            with self._sim:
                self._apply_ops()
                with self._cond:
                    running = self._running()   # checked again under _sim: see settle()
                if running:
                    now = self._clock()
                    acc = min(acc + (now - last), 3 * self.dt)
                    last = now
                    if acc >= self.dt:
                        acc -= self.dt
                        self._stepping = True
                        try:
                            self._step_all(self.dt)
                        finally:
                            self._stepping = False
            if running and acc < self.dt:
                with self._cond:
                    if not self._ops and self._running():
                        self._cond.wait(self.dt - acc)
