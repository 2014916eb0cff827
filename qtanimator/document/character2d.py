"""2D characters in the document: assets, channels, key edits, IK drags and the pendulum cache.

One asset of kind ``character2d`` per character (``source`` = the SVG file or folder,
property ``index`` = which character of a folder). Channels:

* ``"<asset>/<joint name>/angle"`` — a keyframed joint's local angle (radians);
* ``"<asset>//x"``, ``"<asset>//y"`` — the character's translation from the rest pose;
* a dynamic (pendulum) joint may have an angle channel too: it holds the joint's **world**
  angle θ and sets the simulation's state at its keys (θ from the key, ω = 0), so the
  animator can pose a pendulum's starting angle. Between keys physics drives it.

With auto-key off, posing writes no key: the values are the document's *pending pose*
(:mod:`qtanimator.document.pose`), which every evaluation here shows at its time (a
dynamic joint's pending value is its world angle) until the frame changes or it is keyed.

Keys use smooth tangents with constant extrapolation, which is the reference program's
Catmull-Rom spline. Per-joint keys by default; with the parameter ``animation.key_all``
true an edit sets the reference program's universal keyframe (every joint of every 2D
character and every position keyed at that time).

Pendulum parameters are document parameters ``"<asset>.pendulum.<name>"`` (see
:class:`qtanimator.core.pendulum.PendulumParams`); :func:`set_pendulum_preset` applies a
named preset (``physical`` or ``handout``).
"""

from __future__ import annotations

import math
import threading
import time
import weakref
from collections import Counter
from collections.abc import Callable, Hashable, Iterable
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.core.channel import Channel, Key
from qtanimator.core.ik import gradient_descent_step, solve_ik
from qtanimator.core.pendulum import PRESETS, PendulumBlowUp, PendulumParams, PendulumSystem, check_state
from qtanimator.core.rig2d import Character, Pose
from qtanimator.document.commands import AddAsset, Command, DeleteKeys, Macro, SetKeys, SetParameter
from qtanimator.document.document import Asset, Document, DocumentChange, channel_id, split_channel_id
from qtanimator.document.pose import pending_value, pending_values
from qtanimator.document.simulation import SimulationWorker, ui_idle

ASSET_KIND = "character2d"
KEY_ALL_PARAMETER = "animation.key_all"

#: IK solver settings: document parameters with their defaults (edited in the properties
#: dock). ``ik.solver`` is "dls" (damped least squares, limits respected) or "handout" (the
#: course handout's gradient descent); ``ik.gradient_arrow_scale`` only scales the debug arrows.
IK_DEFAULTS: dict[str, Any] = {
    "ik.solver": "dls",
    "ik.freeze_root": True,
    "ik.max_iterations": 100,
    "ik.damping": 1e-3,
    "ik.handout_step": 1e-6,
    "ik.handout_iterations": 10,
    "ik.gradient_arrow_scale": 0.1,
}


def ik_setting(doc: Document, name: str) -> Any:
    """One IK setting of the document (its default when unset)."""
    return doc.parameter(name, IK_DEFAULTS[name])
DELETE_TOLERANCE_FRAMES = 0.1
FloatArray = npt.NDArray[np.float64]


# ------------------------------------------------------------------------ assets
def load_character_asset(asset: Asset) -> Character:
    """Loader for ``character2d`` assets (registered in :mod:`qtanimator.document.loaders`)."""
    from qtanimator.formats.errors import FormatError
    from qtanimator.formats.svg_rig import load_characters, load_rigged_character

    if asset.source is None:
        raise FormatError(f"the 2D character '{asset.id}' has no source file.")
    index = int(asset.properties.get("index", 0))
    rig = asset.properties.get("rig")
    if rig is not None:  # rigged in the program (qtanimator.document.rigging): the SVG is unchanged
        return load_rigged_character(asset.source, index, rig)
    chars = load_characters(asset.source)
    if not 0 <= index < len(chars):
        raise FormatError(f"the 2D character '{asset.id}' refers to character {index + 1}, but the "
                          f"source holds {len(chars)}.", asset.source)
    return chars[index]


def add_characters_command(doc: Document, path: str | Path) -> Command:
    """A command adding every character of an SVG file or folder (FormatError if unreadable)."""
    from qtanimator.formats.svg_rig import load_characters

    source = str(Path(path).resolve())
    chars = load_characters(source)
    taken = set(doc.assets)
    commands: list[Command] = []
    for i, ch in enumerate(chars):
        asset_id = doc.unique_asset_id(ch.name)
        k = 2
        base = asset_id
        while asset_id in taken:
            asset_id = f"{base}_{k}"
            k += 1
        taken.add(asset_id)
        asset = Asset(asset_id, ASSET_KIND, source, {"index": i})
        commands.append(AddAsset(asset, ch))
    if len(commands) == 1:
        return commands[0]
    return Macro(f"Add {len(commands)} characters", commands)


def character(doc: Document, asset_id: str) -> Character:
    ch = doc.runtime.get(asset_id)
    if ch is None:
        asset = doc.assets[asset_id]
        if asset.kind != ASSET_KIND:
            raise KeyError(f"{asset_id} is not a 2D character")
        ch = load_character_asset(asset)
        doc.runtime[asset_id] = ch
    if not isinstance(ch, Character):
        raise KeyError(f"{asset_id} is not a 2D character")
    return ch


def character_assets(doc: Document) -> list[str]:
    return [a.id for a in doc.assets.values() if a.kind == ASSET_KIND]


def angle_channel_id(asset_id: str, joint_name: str) -> str:
    return channel_id(asset_id, joint_name, "angle")


def position_channel_ids(asset_id: str) -> tuple[str, str]:
    return channel_id(asset_id, "", "x"), channel_id(asset_id, "", "y")


def _value(doc: Document, cid: str, time: float, derivative: int = 0) -> float:
    if derivative == 0:
        held = pending_value(doc, cid, time)  # an unkeyed pose shown at this time
        if held is not None:
            return held
    ch = doc.channels.get(cid)
    return 0.0 if ch is None or not ch.keys else float(ch.evaluate(time, derivative))


# ------------------------------------------------------------------ evaluation
def translation(doc: Document, asset_id: str, time: float, derivative: int = 0) -> FloatArray:
    cx, cy = position_channel_ids(asset_id)
    return np.array([_value(doc, cx, time, derivative), _value(doc, cy, time, derivative)])


def keyframed_angles(doc: Document, asset_id: str, time: float, derivative: int = 0) -> FloatArray:
    """Channel values (J,) of every joint (dynamic joints' channels hold world angles)."""
    ch = character(doc, asset_id)
    return np.array([_value(doc, angle_channel_id(asset_id, j.name), time, derivative) for j in ch.joints])


def _local_from_world_dynamic(ch: Character, angles: FloatArray, dyn_world: FloatArray) -> FloatArray:
    out = angles.copy()
    world = np.empty_like(out)
    for k, j in enumerate(ch.joints):
        parent = 0.0 if j.parent is None else world[j.parent]
        if j.is_dynamic:
            out[k] = dyn_world[k] - parent
        world[k] = parent + out[k]
    return out


def joint_angles(doc: Document, asset_id: str, time: float, block: bool = True) -> FloatArray:
    """Local angles (J,) at ``time``: channels for keyframed joints, the simulation for
    dynamic ones. ``block`` False (views): the latest simulated state, never stepping on
    this thread (see :meth:`PendulumCache.latest_state`)."""
    ch = character(doc, asset_id)
    angles = keyframed_angles(doc, asset_id, time)
    if ch.dynamic.any():
        world = simulation(doc).world_angles(asset_id, time, wait=block)
        held = pending_values(doc, time)
        if held:  # a pendulum posed without a key shows its posed world angle
            world = np.array(world, dtype=np.float64)
            for k in np.flatnonzero(ch.dynamic):
                v = held.get(angle_channel_id(asset_id, ch.joints[int(k)].name))
                if v is not None:
                    world[k] = v
        angles = _local_from_world_dynamic(ch, angles, world)
    return angles


def evaluate_pose(doc: Document, asset_id: str, time: float, block: bool = True) -> Pose:
    """The character's pose at ``time`` (keyframes, pendulums and translation).

    ``block`` True is exact: pendulum frames not simulated yet are simulated on the calling
    thread (render, export, commands). ``block`` False is for views: the pendulums show the
    latest state the background worker has (exact once it has caught up); nothing is
    simulated on the calling thread.
    """
    ch = character(doc, asset_id)
    return ch.pose(joint_angles(doc, asset_id, time, block), translation(doc, asset_id, time))


# ------------------------------------------------------------------- key edits
def _key(time: float, value: float) -> Key:
    return Key(float(time), float(value))


def _key_all_values(doc: Document, time: float) -> dict[str, Key]:
    """The universal keyframe: every keyframed joint and position of every 2D character."""
    keys: dict[str, Key] = {}
    for aid in character_assets(doc):
        ch = character(doc, aid)
        vals = keyframed_angles(doc, aid, time)
        for j, v in zip(ch.joints, vals):
            if not j.is_dynamic:
                keys[angle_channel_id(aid, j.name)] = _key(time, v)
        cx, cy = position_channel_ids(aid)
        t = translation(doc, aid, time)
        keys[cx] = _key(time, t[0])
        keys[cy] = _key(time, t[1])
    return keys


def key_values(doc: Document, values: dict[str, float], time: float, text: str,
               gesture: Hashable | None = None) -> Command:
    """Key channel ``values`` at ``time`` — the one place a 2D edit becomes keys. With
    key-all (``animation.key_all``) the edit sets the universal keyframe: every keyframed
    joint and position of every 2D character keyed at ``time`` as well."""
    keys = {cid: _key(time, v) for cid, v in values.items()}
    if keys and bool(doc.parameter(KEY_ALL_PARAMETER, False)):
        merged = _key_all_values(doc, time)
        merged.update(keys)
        keys = merged
    return SetKeys(doc, keys, text=text, gesture=gesture)


def joint_value(doc: Document, asset_id: str, joint_index: int, angle: float, time: float) -> dict[str, float]:
    """The channel value that poses a joint at local ``angle`` (a dynamic joint's channel
    holds the matching world angle)."""
    ch = character(doc, asset_id)
    j = ch.joints[joint_index]
    value = float(angle)
    if j.is_dynamic and j.parent is not None:
        # The parent's world angle needs the simulation only under a dynamic ancestor.
        exact = bool(ch.dynamic[ch.ancestors(j.parent)].any())
        angles = joint_angles(doc, asset_id, time) if exact else keyframed_angles(doc, asset_id, time)
        value = float(ch.pose(angles).world_angles[j.parent]) + value
    return {angle_channel_id(asset_id, j.name): value}


def key_joint(doc: Document, asset_id: str, joint_index: int, angle: float, time: float,
              gesture: Hashable | None = None) -> Command:
    """Key a joint's local ``angle`` at ``time``. For a dynamic joint the key holds the
    matching world angle and restarts the pendulum there."""
    name = character(doc, asset_id).joints[joint_index].name
    return key_values(doc, joint_value(doc, asset_id, joint_index, angle, time), time, f"Rotate {name}", gesture)


def position_values(asset_id: str, xy: npt.ArrayLike) -> dict[str, float]:
    """The channel values that put the character at offset ``xy`` from its rest pose."""
    x, y = (float(v) for v in np.asarray(xy, dtype=np.float64).reshape(2))
    cx, cy = position_channel_ids(asset_id)
    return {cx: x, cy: y}


def move_character(doc: Document, asset_id: str, xy: npt.ArrayLike, time: float,
                   gesture: Hashable | None = None) -> Command:
    """Key the character's translation (offset from the rest pose) to ``xy`` at ``time``."""
    return key_values(doc, position_values(asset_id, xy), time, f"Move {asset_id}", gesture)


def ik_values(doc: Document, asset_id: str, joint_index: int, local_point: npt.ArrayLike,
              target: npt.ArrayLike, time: float, limits: npt.ArrayLike | None = None) -> dict[str, float]:
    """Solve IK from the pose shown at ``time`` with the document's IK settings
    (``IK_DEFAULTS``): the new angles of the keyframed joints that moved, by channel.
    Every IK path (a drag that keys, one that only poses) gets its values here."""
    ch = character(doc, asset_id)
    if ch.dynamic[ch.ancestors(joint_index)].any():
        before = joint_angles(doc, asset_id, time)
    else:
        # The chain's pose needs only its own (keyframed) angles: no simulation to run.
        before = keyframed_angles(doc, asset_id, time)
    position = translation(doc, asset_id, time)
    if str(ik_setting(doc, "ik.solver")) == "handout":
        after = gradient_descent_step(ch, before, position, joint_index, local_point, target,
                                      step=float(ik_setting(doc, "ik.handout_step")),
                                      iterations=int(ik_setting(doc, "ik.handout_iterations")))
    else:
        after = solve_ik(ch, before, position, joint_index, local_point, target, limits=limits,
                         freeze_root=bool(ik_setting(doc, "ik.freeze_root")),
                         max_iterations=int(ik_setting(doc, "ik.max_iterations")),
                         damping=float(ik_setting(doc, "ik.damping")))
    return {angle_channel_id(asset_id, j.name): float(after[k])
            for k, j in enumerate(ch.joints)
            if not j.is_dynamic and abs(after[k] - before[k]) > 1e-12}


def ik_drag(doc: Document, asset_id: str, joint_index: int, local_point: npt.ArrayLike,
            target: npt.ArrayLike, time: float, gesture: Hashable | None = None,
            limits: npt.ArrayLike | None = None) -> Command:
    """The keys of an IK drag, whatever the solver settings: the joints :func:`ik_values`
    moved, through :func:`key_values` (every joint in key-all mode)."""
    values = ik_values(doc, asset_id, joint_index, local_point, target, time, limits)
    return key_values(doc, values, time, "IK drag", gesture)


def delete_keys_at(doc: Document, asset_id: str | None, time: float) -> Command | None:
    """Delete the keys within 0.1 frame of ``time`` from a character's channels (every 2D
    character's with ``asset_id`` None or in key-all mode); None when there are none."""
    tol = DELETE_TOLERANCE_FRAMES / doc.fps
    if asset_id is None or bool(doc.parameter(KEY_ALL_PARAMETER, False)):
        assets = set(character_assets(doc))
    else:
        assets = {asset_id}
    selection: dict[str, Iterable[int]] = {}
    for cid, chn in doc.channels.items():
        if split_channel_id(cid)[0] not in assets:
            continue
        idx = [i for i, k in enumerate(chn.keys) if abs(k.time - time) < tol]
        if idx:
            selection[cid] = idx
    if not selection:
        return None
    return DeleteKeys(doc, selection, text="Delete Keyframe")


# -------------------------------------------------------------- pendulum params
def pendulum_params(doc: Document, asset_id: str) -> PendulumParams:
    prefix = f"{asset_id}.pendulum."
    # list() copies in one step: the simulation worker may read while the UI thread edits.
    values = {k[len(prefix):]: v for k, v in list(doc.parameters.items()) if k.startswith(prefix)}
    preset = PRESETS.get(str(values.pop("preset", "physical")), PRESETS["physical"])
    try:
        return PendulumParams.from_dict({**preset.to_dict(), **values})
    except (TypeError, ValueError):
        return preset


def set_pendulum_preset(doc: Document, asset_id: str, name: str) -> Command:
    """Set all of a character's pendulum parameters to a named preset (one undo step)."""
    if name not in PRESETS:
        raise ValueError(f"unknown pendulum preset '{name}' (known: {', '.join(PRESETS)})")
    prefix = f"{asset_id}.pendulum."
    cmds: list[Command] = [SetParameter(doc, prefix + "preset", name)]
    for k, v in PRESETS[name].to_dict().items():
        cmds.append(SetParameter(doc, prefix + k, v))
    return Macro(f"Pendulum preset: {name}", cmds)


# ------------------------------------------------------------ simulation cache
class _AssetSim:
    """One character's simulation: the system, its per-frame states and a kinematics plan.

    World angles: a joint's world angle is the world angle θ_D of its nearest dynamic
    ancestor-or-self D plus the local angles of the keyframed joints after D on its path
    (from the root when there is no D). ``key_sum`` (J, J) and ``dyn_pick`` (J, J) are those
    two sums as matrices, so every sub-step's kinematics is a few array operations. Pivot
    accelerations are only needed at the groups' top joints: one term per (top, ancestor).
    """

    def __init__(self, ch: Character, params: PendulumParams) -> None:
        self.system = PendulumSystem(ch, params)
        self.theta: list[FloatArray] = []  # per frame (world angles, J)
        self.omega: list[FloatArray] = []
        #: Bumped by an invalidation that reaches the frame being computed (see PendulumCache).
        self.generation = 0
        #: Why the simulation stopped after its last cached frame (a blow-up), or None.
        self.problem: PendulumBlowUp | None = None
        n = len(ch.joints)
        key_sum = np.zeros((n, n))
        dyn_pick = np.zeros((n, n))
        nearest = [-1] * n
        for k, j in enumerate(ch.joints):
            p = j.parent
            if j.is_dynamic:
                nearest[k] = k
            else:
                if p is not None:
                    key_sum[k] = key_sum[p]
                    nearest[k] = nearest[p]
                key_sum[k, k] = 1.0
            if nearest[k] >= 0:
                dyn_pick[k, nearest[k]] = 1.0
        self.key_sum = key_sum
        self.dyn_pick = dyn_pick
        self.tops = np.array([g.top for g in self.system.groups], dtype=np.intp)
        top_of, anc, vec = [], [], []
        for ti, t in enumerate(self.tops):
            child, m = int(t), ch.joints[int(t)].parent
            while m is not None:
                top_of.append(ti)
                anc.append(m)
                vec.append(ch.joints[child].pivot - ch.joints[m].pivot)
                child, m = m, ch.joints[m].parent
        self.pair_top = np.array(top_of, dtype=np.intp)
        self.pair_anc = np.array(anc, dtype=np.intp)
        self.pair_vec = np.array(vec, dtype=np.float64).reshape(-1, 2)
        self.pair_sum = np.zeros((len(self.tops), len(anc)))
        self.pair_sum[self.pair_top, np.arange(len(anc))] = 1.0


class PendulumCache:
    """Per-frame pendulum states of every 2D character, at a fixed internal step.

    Frame f (from the project's ``frame_start``) holds the world angles after simulating up
    to time f / fps. A channel edit drops the frames from the edited time on (once per asset
    and change); a parameter or asset change drops that character's frames.

    Two ways to read:

    * exact (``state``, ``world_angles(..., wait=True)``): a frame not cached yet is
      simulated on the calling thread (headless render, export, commands, tests);
    * latest (``latest_state``, ``world_angles(..., wait=False)``): never steps; returns the
      last frame simulated at or before the one asked for (the keyed start state when
      nothing is), and asks the background worker (:mod:`qtanimator.document.simulation`)
      to fill up to that frame plus :attr:`LOOKAHEAD` seconds. Views use this.

    Threads: the worker and exact reads compute a frame without the lock and append it
    under the lock only if the character's simulation is still the same object, its
    ``generation`` unchanged (an invalidation that reaches the frame being computed bumps
    it) and the frame still the next one; so a frame computed from a dropped state never
    enters the cache, and every cached frame equals the synchronous result exactly.
    """

    MAX_FRAMES = 200_000
    #: Seconds of frames the worker simulates past the frame a view asked for.
    LOOKAHEAD = 1.0

    def __init__(self, doc: Document) -> None:
        self._doc = weakref.ref(doc)
        self._sims: dict[str, _AssetSim] = {}
        self._lock = threading.Lock()
        self._epoch = 0  # bumped when simulations are dropped (a sim built meanwhile is stale)
        self._targets: dict[str, int] = {}  # frame index the worker fills each character to
        #: Sub-steps simulated (by any thread), and per thread id (frames later discarded included).
        self.steps_taken = 0
        self.steps_by_thread: Counter[int] = Counter()
        #: Frame-dropping invalidations (one per character per change at most), and restarts
        #: (worker wake-ups caused by a change: at most one per change).
        self.invalidations = 0
        self.restarts = 0
        #: Changes whenever frames are added or dropped (the UI polls it).
        self.revision = 0
        self._worker = SimulationWorker(self._work, "pendulums")
        weakref.finalize(self, self._worker.shutdown, 0.0)
        doc.subscribe(self._on_change)

    # ---- worker control
    @property
    def worker(self) -> SimulationWorker:
        return self._worker

    @property
    def busy(self) -> bool:
        """True while the worker has frames to simulate."""
        return self._worker.busy

    def shutdown(self, timeout: float | None = 5.0) -> None:
        """Stop the worker thread and forget what it was asked for (cached frames stay;
        a later latest-state read starts it again)."""
        with self._lock:
            self._targets.clear()
        self._worker.shutdown(timeout)

    def wait_idle(self, timeout: float = 30.0) -> bool:
        """Block until the worker has nothing to do (tests); False on timeout."""
        ui_idle()  # the calling thread waits: the worker need not leave it the interpreter
        deadline = time.monotonic() + timeout
        while self._worker.busy:
            if time.monotonic() > deadline:
                return False
            time.sleep(0.001)
        return True

    # ---- invalidation
    def _on_change(self, change: DocumentChange) -> None:
        doc = self._doc()
        if doc is None:
            return
        if change.reset:
            with self._lock:
                self._drop_all()
                self._targets.clear()
            self._worker.shutdown()
            return
        dropped = False
        with self._lock:
            for asset_id in change.assets:
                dropped |= self._drop(asset_id)
                if asset_id not in doc.assets:
                    self._targets.pop(asset_id, None)
            for path in change.parameters:
                if path in ("fps", "frame_start") or path.startswith("simulation."):
                    dropped |= self._drop_all()
                elif ".pendulum." in path:
                    dropped |= self._drop(path.split(".pendulum.", 1)[0])
            for asset_id in change.channel_assets():
                # One invalidation per asset and command, from its earliest edited time.
                dropped |= self._invalidate_locked(doc, asset_id, change.channel_time_from(asset_id))
            restart = dropped and bool(self._targets)
            if restart:
                self.restarts += 1
        if restart:
            self._worker.wake()

    def _drop(self, asset_id: str) -> bool:
        self._epoch += 1  # also when none is cached: one may be under construction
        if self._sims.pop(asset_id, None) is None:
            return False
        self.revision += 1
        self.invalidations += 1
        return True

    def _drop_all(self) -> bool:
        self._epoch += 1
        if not self._sims:
            return False
        self._sims.clear()
        self.revision += 1
        self.invalidations += 1
        return True

    def _invalidate_locked(self, doc: Document | None, asset_id: str, time_from: float) -> bool:
        sim = self._sims.get(asset_id)
        if sim is None or time_from == math.inf:
            return False
        if doc is None or time_from == -math.inf:
            return self._drop(asset_id)
        # Frame i (after the start) integrates inputs at times before its own time and
        # applies keys at its own time, so it is valid while its time < time_from.
        keep = max(math.ceil(time_from * doc.fps - doc.frame_range[0] - 1e-9), 0)
        if keep > len(sim.theta):
            return False  # neither a cached frame nor the one being computed is affected
        # The frame being computed (index len) may read the old inputs: make it stale too.
        sim.generation += 1
        sim.problem = None  # the frame that blew up is recomputed from the new inputs
        del sim.theta[keep:]
        del sim.omega[keep:]
        self.revision += 1
        self.invalidations += 1
        return True

    def invalidate(self, asset_id: str | None = None, time_from: float = -math.inf) -> None:
        """Drop the cached frames whose state depends on inputs at or after ``time_from``
        (every character's with ``asset_id`` None); the worker refills what views asked for."""
        doc = self._doc()
        with self._lock:
            targets = list(self._sims) if asset_id is None else [asset_id]
            dropped = False
            for aid in targets:
                dropped |= self._invalidate_locked(doc, aid, time_from)
            restart = dropped and bool(self._targets)
        if restart:
            self._worker.wake()

    def problem(self, asset_id: str) -> PendulumBlowUp | None:
        """The blow-up that stopped this character's simulation, or None."""
        with self._lock:
            sim = self._sims.get(asset_id)
            return None if sim is None else sim.problem

    def cached_frames(self, asset_id: str) -> int:
        sim = self._sims.get(asset_id)
        return 0 if sim is None else len(sim.theta)

    # ---- exact reads
    def _sim(self, doc: Document, asset_id: str) -> _AssetSim:
        while True:
            with self._lock:
                sim = self._sims.get(asset_id)
                epoch = self._epoch
            if sim is not None:
                return sim
            built = _AssetSim(character(doc, asset_id), pendulum_params(doc, asset_id))
            with self._lock:
                if self._epoch == epoch:  # else a change dropped it meanwhile: build again
                    return self._sims.setdefault(asset_id, built)

    def _index(self, doc: Document, frame: int) -> int:
        return min(max(int(frame) - doc.frame_range[0], 0), self.MAX_FRAMES)

    def state(self, asset_id: str, frame: int) -> tuple[FloatArray, FloatArray]:
        """World angles and rates (J,) of every joint's pendulum state at an integer frame,
        simulated on the calling thread if not cached yet (exact)."""
        doc = self._doc()
        if doc is None:
            raise RuntimeError("the document is gone")
        f = self._index(doc, frame)
        while True:
            sim = self._sim(doc, asset_id)
            with self._lock:
                n = len(sim.theta)
                if n > f:
                    return sim.theta[f], sim.omega[f]
                if sim.problem is not None and n:
                    return sim.theta[-1], sim.omega[-1]  # it stops at the last good frame
                gen = sim.generation
                prev = (sim.theta[-1], sim.omega[-1]) if n else None
            self._step(doc, asset_id, sim, gen, n, prev)

    def world_angles(self, asset_id: str, time: float, wait: bool = True) -> FloatArray:
        """Dynamic joints' world angles at ``time`` (linear between cached frames).

        ``wait`` True: exact, simulating on this thread as needed. False: never steps;
        the latest state available (see :meth:`latest_state`), and the worker is asked to
        catch up.
        """
        doc = self._doc()
        if doc is None:
            raise RuntimeError("the document is gone")
        fr = time * doc.fps
        f0 = math.floor(fr + 1e-9)
        u = fr - f0
        if wait:
            th0 = self.state(asset_id, f0)[0]
            if u <= 1e-9:
                return th0.copy()
            th1 = self.state(asset_id, f0 + 1)[0]
            return np.asarray((1 - u) * th0 + u * th1, dtype=np.float64)
        if u <= 1e-9:
            return self.latest_state(asset_id, f0)[0].copy()
        th1, _om, at = self.latest_state(asset_id, f0 + 1)
        th0, _om, at0 = self.latest_state(asset_id, f0)
        if at < f0 + 1 or at0 < f0:
            return th0.copy()  # f0 + 1 is not simulated yet: the latest state at or before f0
        return np.asarray((1 - u) * th0 + u * th1, dtype=np.float64)

    # ---- latest reads (views)
    def latest_state(self, asset_id: str, frame: int) -> tuple[FloatArray, FloatArray, int]:
        """``(theta, omega, shown_frame)``: the state at ``frame`` if simulated, else at the
        last simulated frame before it (``shown_frame`` says which), or the keyed start
        state when nothing is. Never simulates on the calling thread; asks the worker to
        fill up to ``frame`` plus the look-ahead."""
        doc = self._doc()
        if doc is None:
            raise RuntimeError("the document is gone")
        start = doc.frame_range[0]
        f = self._index(doc, frame)
        with self._lock:
            sim = self._sims.get(asset_id)
            n = 0 if sim is None else len(sim.theta)
            if n:
                assert sim is not None
                k = min(f, n - 1)
                theta, omega = sim.theta[k], sim.omega[k]
            wake = self._request(doc, asset_id, f, n)
        if wake:
            self._worker.wake()
        if n:
            return theta, omega, start + k
        ch = character(doc, asset_id)
        theta = _initial_angles(doc, asset_id, ch, start / doc.fps)
        return theta, np.zeros(len(ch.joints)), start

    def ready(self, asset_id: str, time: float) -> bool:
        """True when ``world_angles(asset_id, time, wait=False)`` is exact (its frames are
        simulated)."""
        doc = self._doc()
        if doc is None:
            return False
        fr = time * doc.fps
        f0 = math.floor(fr + 1e-9)
        need = self._index(doc, f0 + (0 if fr - f0 <= 1e-9 else 1))
        return self.cached_frames(asset_id) > need

    def _request(self, doc: Document, asset_id: str, index: int, cached: int) -> bool:
        """Record that a view shows frame ``index`` (lock held); True if the worker must be
        woken (its target moved and frames up to it are missing)."""
        first, last = doc.frame_range
        end = max(last - first, 0)
        ahead = int(math.ceil(self.LOOKAHEAD * doc.fps))
        want = max(index, min(index + ahead, end))
        old = self._targets.get(asset_id, -1)
        # Grow with the frame shown (playback stays ahead); start over when the view jumped
        # far back (a scrub), so the worker does not fill frames nobody looks at.
        changed = want > old or old > index + 2 * ahead
        if changed:
            self._targets[asset_id] = want
        # Wake it when frames are missing and it is not already on them (or was cancelled).
        return cached <= self._targets[asset_id] and (changed or not self._worker.busy)

    # ---- stepping (any thread)
    def _work(self, should_stop: Callable[[], bool]) -> bool:
        """The worker's job: simulate one frame of the character furthest behind its
        target. False when every target is reached."""
        doc = self._doc()
        if doc is None:
            return False
        with self._lock:
            best: tuple[int, str] | None = None
            for aid, target in list(self._targets.items()):
                sim = self._sims.get(aid)
                n = 0 if sim is None else len(sim.theta)
                if sim is not None and sim.problem is not None:
                    continue  # blown up: nothing more to simulate until an edit
                if n <= target and (best is None or n < best[0]):
                    best = (n, aid)
            if best is None:
                return False
            n, aid = best
            sim = self._sims.get(aid)
            epoch = self._epoch
            gen = -1 if sim is None else sim.generation
            prev = (sim.theta[-1], sim.omega[-1]) if sim is not None and n else None
        if should_stop():
            return False
        if sim is None:
            ch = doc.runtime.get(aid)
            if not isinstance(ch, Character):  # removed, or not loaded: nothing to simulate
                with self._lock:
                    self._targets.pop(aid, None)
                return True
            built = _AssetSim(ch, pendulum_params(doc, aid))
            with self._lock:
                if self._epoch == epoch and aid not in self._sims:
                    self._sims[aid] = built
            return True
        self._step(doc, aid, sim, gen, n, prev)
        return True

    def _step(self, doc: Document, asset_id: str, sim: _AssetSim, generation: int, index: int,
              prev: tuple[FloatArray, FloatArray] | None) -> bool:
        """Compute frame ``index`` from ``prev`` (frame ``index - 1``) without the lock and
        append it if nothing invalidated it meanwhile. True if it was appended."""
        start = doc.frame_range[0]
        if prev is None:
            theta, omega = self._initial(doc, asset_id, sim)
            steps = 0
        else:
            # A blow-up makes inf and NaN on the way; check_state below reports it.
            with np.errstate(over="ignore", invalid="ignore"):
                theta, omega, steps = self._advance(doc, asset_id, sim, start + index - 1, prev[0], prev[1])
        ident = threading.get_ident()
        problem = check_state(sim.system.character, sim.system.params, theta, omega, (start + index) / doc.fps)
        with self._lock:
            self.steps_taken += steps
            self.steps_by_thread[ident] += steps
            if self._sims.get(asset_id) is not sim or sim.generation != generation or len(sim.theta) != index:
                return False
            if problem is not None:
                # Stop at the last good frame: nothing non-finite reaches a view or a file.
                sim.problem = problem
                self.revision += 1
                return False
            sim.theta.append(theta)
            sim.omega.append(omega)
            self.revision += 1
            return True

    def _initial(self, doc: Document, asset_id: str, sim: _AssetSim) -> tuple[FloatArray, FloatArray]:
        ch = sim.system.character
        t0 = doc.frame_range[0] / doc.fps
        return _initial_angles(doc, asset_id, ch, t0), np.zeros(len(ch.joints))

    def _advance(self, doc: Document, asset_id: str, sim: _AssetSim, frame: int, theta0: FloatArray,
                 omega0: FloatArray) -> tuple[FloatArray, FloatArray, int]:
        """The state at ``frame + 1`` from the state at ``frame``, and the sub-steps taken.
        Reads the document only through atomic lookups (it may run on the worker thread)."""
        system = sim.system
        ch = system.character
        params = system.params
        fps = doc.fps
        channels = doc.channels
        t0, t1 = frame / fps, (frame + 1) / fps
        n_steps = max(1, int(round((t1 - t0) / params.step)))
        tau = (t1 - t0) / n_steps
        times = t0 + tau * np.arange(n_steps)
        theta, omega = theta0.copy(), omega0.copy()
        dyn_idx = np.flatnonzero(ch.dynamic)
        # Channel values and derivatives at every sub-step time, evaluated at once.
        ang = np.zeros((3, n_steps, len(ch.joints)))
        for k, j in enumerate(ch.joints):
            if j.is_dynamic:
                continue
            chn = channels.get(angle_channel_id(asset_id, j.name))
            if chn is not None and chn.keys:
                for d in range(3):
                    ang[d, :, k] = chn.evaluate(times, d)
        cx, cy = position_channel_ids(asset_id)
        tacc = np.zeros((n_steps, 2))
        for col, cid in enumerate((cx, cy)):
            chn = channels.get(cid)
            if chn is not None and chn.keys:
                tacc[:, col] = chn.evaluate(times, 2)
        # Keyframed parts of the world angles, rates and accelerations for every sub-step.
        w_key = ang[0] @ sim.key_sum.T
        r_key = ang[1] @ sim.key_sum.T
        a_key = ang[2] @ sim.key_sum.T
        tacc = tacc * params.accel_scale
        pa = np.zeros((len(ch.joints), 2))
        rs = params.rotation_accel_scale
        for s in range(n_steps):
            if len(sim.pair_anc):
                world = w_key[s] + sim.dyn_pick @ theta
                rate = r_key[s] + sim.dyn_pick @ omega
                th = world[sim.pair_anc]
                c, sn = np.cos(th), np.sin(th)
                v = sim.pair_vec
                rv = np.stack([c * v[:, 0] + sn * v[:, 1], -sn * v[:, 0] + c * v[:, 1]], axis=1)
                jrv = np.stack([rv[:, 1], -rv[:, 0]], axis=1)
                contrib = rs * (a_key[s][sim.pair_anc][:, None] * jrv - (rate[sim.pair_anc] ** 2)[:, None] * rv)
                pa[sim.tops] = tacc[s] + sim.pair_sum @ contrib
            else:
                pa[sim.tops] = tacc[s]
            system.step(theta, omega, pa, tau)
        # Keys on a dynamic joint's channel pose the pendulum at that frame.
        for kd in dyn_idx:
            k = int(kd)
            chn = channels.get(angle_channel_id(asset_id, ch.joints[k].name))
            if chn is None:
                continue
            for key in chn.keys:
                if abs(key.time * fps - (frame + 1)) < 0.5:
                    theta[k] = key.value
                    omega[k] = 0.0
        return theta, omega, n_steps


def _initial_angles(doc: Document, asset_id: str, ch: Character, t0: float) -> FloatArray:
    """The simulation's start state: dynamic joints' keyed world angles at ``t0`` (else 0)."""
    theta = np.zeros(len(ch.joints))
    for k, j in enumerate(ch.joints):
        if j.is_dynamic:
            chn = doc.channels.get(angle_channel_id(asset_id, j.name))
            if chn is not None and chn.keys:
                theta[k] = float(chn.evaluate(t0))
    return theta


PENDULUM_CACHE = "pendulums"


def simulation(doc: Document) -> PendulumCache:
    """The document's pendulum cache, ``doc.caches["pendulums"]`` (created on first use)."""
    cache = doc.caches.get(PENDULUM_CACHE)
    if not isinstance(cache, PendulumCache):
        cache = PendulumCache(doc)
        doc.caches[PENDULUM_CACHE] = cache
    return cache


def simulation_ready(doc: Document, times: float | Iterable[float]) -> bool:
    """True when every 2D character's pendulums are simulated at ``times`` (so views that
    read the latest state show the exact one). Cheap; steps nothing."""
    cache = doc.caches.get(PENDULUM_CACHE)
    ts = [float(times)] if isinstance(times, (int, float)) else [float(t) for t in times]
    for aid in character_assets(doc):
        ch = doc.runtime.get(aid)
        if not isinstance(ch, Character) or not ch.dynamic.any():
            continue
        if not isinstance(cache, PendulumCache) or not all(cache.ready(aid, t) for t in ts):
            return False
    return True


def simulated_frames(doc: Document) -> tuple[int, int] | None:
    """The frames ``(first, last)`` simulated for every 2D character with pendulums (last
    < first when none is yet); None when no character has pendulums."""
    cache = doc.caches.get(PENDULUM_CACHE)
    first = doc.frame_range[0]
    counts = []
    for aid in character_assets(doc):
        ch = doc.runtime.get(aid)
        if isinstance(ch, Character) and ch.dynamic.any():
            counts.append(cache.cached_frames(aid) if isinstance(cache, PendulumCache) else 0)
    if not counts:
        return None
    return first, first + min(counts) - 1


def pendulum_problems(doc: Document) -> dict[str, PendulumBlowUp]:
    """The blow-ups that stopped the pendulum simulations, by character."""
    cache = doc.caches.get(PENDULUM_CACHE)
    if not isinstance(cache, PendulumCache):
        return {}
    found = {aid: cache.problem(aid) for aid in character_assets(doc)}
    return {aid: p for aid, p in found.items() if p is not None}


def channel_for(doc: Document, asset_id: str, joint_index: int) -> Channel | None:
    ch = character(doc, asset_id)
    return doc.channels.get(angle_channel_id(asset_id, ch.joints[joint_index].name))


def summary(doc: Document, asset_id: str) -> dict[str, Any]:
    ch = character(doc, asset_id)
    return {"joints": len(ch.joints), "dynamic": int(ch.dynamic.sum())}
