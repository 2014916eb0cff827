"""2D characters in the document: assets, channels, key edits, IK drags and the pendulum cache.

One asset of kind ``character2d`` per character (``source`` = the SVG file or folder,
property ``index`` = which character of a folder). Channels:

* ``"<asset>/<joint name>/angle"`` — a keyframed joint's local angle (radians);
* ``"<asset>//x"``, ``"<asset>//y"`` — the character's translation from the rest pose;
* a dynamic (pendulum) joint may have an angle channel too: it holds the joint's **world**
  angle θ and sets the simulation's state at its keys (θ from the key, ω = 0), so the
  animator can pose a pendulum's starting angle. Between keys physics drives it.

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
import weakref
from collections.abc import Hashable, Iterable
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.core.channel import Channel, Key
from qtanimator.core.ik import gradient_descent_step, solve_ik
from qtanimator.core.pendulum import PRESETS, PendulumParams, PendulumSystem
from qtanimator.core.rig2d import Character, Pose
from qtanimator.document.commands import AddAsset, Command, DeleteKeys, Macro, SetKeys, SetParameter
from qtanimator.document.document import Asset, Document, DocumentChange, channel_id, split_channel_id

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
    from qtanimator.formats.svg_rig import load_characters

    if asset.source is None:
        raise FormatError(f"the 2D character '{asset.id}' has no source file.")
    chars = load_characters(asset.source)
    index = int(asset.properties.get("index", 0))
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


def joint_angles(doc: Document, asset_id: str, time: float) -> FloatArray:
    """Local angles (J,) at ``time``: channels for keyframed joints, the simulation for
    dynamic ones."""
    ch = character(doc, asset_id)
    angles = keyframed_angles(doc, asset_id, time)
    if ch.dynamic.any():
        world = simulation(doc).world_angles(asset_id, time)
        angles = _local_from_world_dynamic(ch, angles, world)
    return angles


def evaluate_pose(doc: Document, asset_id: str, time: float) -> Pose:
    """The character's pose at ``time`` (keyframes, pendulums and translation)."""
    ch = character(doc, asset_id)
    return ch.pose(joint_angles(doc, asset_id, time), translation(doc, asset_id, time))


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


def _set_keys(doc: Document, keys: dict[str, Key], text: str, gesture: Hashable | None) -> Command:
    if bool(doc.parameter(KEY_ALL_PARAMETER, False)):
        time = next(iter(keys.values())).time
        merged = _key_all_values(doc, time)
        merged.update(keys)
        keys = merged
    return SetKeys(doc, keys, text=text, gesture=gesture)


def key_joint(doc: Document, asset_id: str, joint_index: int, angle: float, time: float,
              gesture: Hashable | None = None) -> Command:
    """Key a joint's local ``angle`` at ``time``. For a dynamic joint the key holds the
    matching world angle and restarts the pendulum there."""
    ch = character(doc, asset_id)
    j = ch.joints[joint_index]
    value = float(angle)
    if j.is_dynamic:
        pose = evaluate_pose(doc, asset_id, time)
        parent = 0.0 if j.parent is None else float(pose.world_angles[j.parent])
        value = parent + value
    return _set_keys(doc, {angle_channel_id(asset_id, j.name): _key(time, value)},
                     f"Rotate {j.name}", gesture)


def move_character(doc: Document, asset_id: str, xy: npt.ArrayLike, time: float,
                   gesture: Hashable | None = None) -> Command:
    """Key the character's translation (offset from the rest pose) to ``xy`` at ``time``."""
    x, y = (float(v) for v in np.asarray(xy, dtype=np.float64).reshape(2))
    cx, cy = position_channel_ids(asset_id)
    return _set_keys(doc, {cx: _key(time, x), cy: _key(time, y)}, f"Move {asset_id}", gesture)


def ik_drag(doc: Document, asset_id: str, joint_index: int, local_point: npt.ArrayLike,
            target: npt.ArrayLike, time: float, gesture: Hashable | None = None,
            limits: npt.ArrayLike | None = None) -> Command:
    """Solve IK from the pose at ``time`` with the document's IK settings (``IK_DEFAULTS``)
    and key the keyframed joints that moved (every joint in key-all mode)."""
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
    keys = {angle_channel_id(asset_id, j.name): _key(time, after[k])
            for k, j in enumerate(ch.joints)
            if not j.is_dynamic and abs(after[k] - before[k]) > 1e-12}
    if not keys:
        return SetKeys(doc, {}, text="IK drag", gesture=gesture)
    return _set_keys(doc, keys, "IK drag", gesture)


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
    values = {k[len(prefix):]: v for k, v in doc.parameters.items() if k.startswith(prefix)}
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
    to time f / fps. Asking for a later frame steps the simulation forward from the last
    cached frame; an earlier one reads the cache. A channel edit drops the frames after the
    edited time; a parameter or asset change drops that character's frames.
    """

    MAX_FRAMES = 200_000

    def __init__(self, doc: Document) -> None:
        self._doc = weakref.ref(doc)
        self._sims: dict[str, _AssetSim] = {}
        self.steps_taken = 0
        doc.subscribe(self._on_change)

    # ---- invalidation
    def _on_change(self, change: DocumentChange) -> None:
        doc = self._doc()
        if doc is None:
            return
        if change.reset:
            self._sims.clear()
            return
        for asset_id in change.assets:
            self._sims.pop(asset_id, None)
        for path in change.parameters:
            if path in ("fps", "frame_start") or path.startswith("simulation."):
                self._sims.clear()
            elif ".pendulum." in path:
                self._sims.pop(path.split(".pendulum.", 1)[0], None)
        for asset_id in change.channel_assets():
            # One invalidation per asset and command, from its earliest edited time.
            self.invalidate(asset_id, change.channel_time_from(asset_id))

    def invalidate(self, asset_id: str | None = None, time_from: float = -math.inf) -> None:
        """Drop the cached frames whose state depends on inputs at or after ``time_from``
        (every character's with ``asset_id`` None)."""
        doc = self._doc()
        targets = list(self._sims) if asset_id is None else [asset_id]
        for aid in targets:
            sim = self._sims.get(aid)
            if sim is None or time_from == math.inf:
                continue
            if doc is None or time_from == -math.inf:
                del self._sims[aid]
                continue
            # Frame i (after the start) integrates inputs at times before its own time and
            # applies keys at its own time, so it is valid while its time < time_from.
            keep = max(math.ceil(time_from * doc.fps - doc.frame_range[0] - 1e-9), 0)
            if keep < len(sim.theta):
                del sim.theta[keep:]
                del sim.omega[keep:]

    def cached_frames(self, asset_id: str) -> int:
        sim = self._sims.get(asset_id)
        return 0 if sim is None else len(sim.theta)

    # ---- reads
    def _sim(self, doc: Document, asset_id: str) -> _AssetSim:
        sim = self._sims.get(asset_id)
        if sim is None:
            sim = _AssetSim(character(doc, asset_id), pendulum_params(doc, asset_id))
            self._sims[asset_id] = sim
        return sim

    def state(self, asset_id: str, frame: int) -> tuple[FloatArray, FloatArray]:
        """World angles and rates (J,) of every joint's pendulum state at an integer frame."""
        doc = self._doc()
        if doc is None:
            raise RuntimeError("the document is gone")
        sim = self._sim(doc, asset_id)
        start = doc.frame_range[0]
        f = min(max(int(frame) - start, 0), self.MAX_FRAMES)
        if not sim.theta:
            theta, omega = self._initial(doc, asset_id, sim)
            sim.theta.append(theta)
            sim.omega.append(omega)
        while len(sim.theta) <= f:
            i = len(sim.theta)
            theta, omega = self._advance(doc, asset_id, sim, start + i - 1, sim.theta[-1], sim.omega[-1])
            sim.theta.append(theta)
            sim.omega.append(omega)
        return sim.theta[f], sim.omega[f]

    def world_angles(self, asset_id: str, time: float) -> FloatArray:
        """Dynamic joints' world angles at ``time`` (linear between cached frames)."""
        doc = self._doc()
        if doc is None:
            raise RuntimeError("the document is gone")
        fr = time * doc.fps
        f0 = math.floor(fr + 1e-9)
        u = fr - f0
        th0 = self.state(asset_id, f0)[0]
        if u <= 1e-9:
            return th0.copy()
        th1 = self.state(asset_id, f0 + 1)[0]
        return np.asarray((1 - u) * th0 + u * th1, dtype=np.float64)

    # ---- stepping
    def _initial(self, doc: Document, asset_id: str, sim: _AssetSim) -> tuple[FloatArray, FloatArray]:
        ch = sim.system.character
        t0 = doc.frame_range[0] / doc.fps
        theta = np.zeros(len(ch.joints))
        for k, j in enumerate(ch.joints):
            if j.is_dynamic:
                cid = angle_channel_id(asset_id, j.name)
                if cid in doc.channels and doc.channels[cid].keys:
                    theta[k] = _value(doc, cid, t0)
        return theta, np.zeros(len(ch.joints))

    def _advance(self, doc: Document, asset_id: str, sim: _AssetSim, frame: int, theta0: FloatArray,
                 omega0: FloatArray) -> tuple[FloatArray, FloatArray]:
        """The state at ``frame + 1`` from the state at ``frame``."""
        system = sim.system
        ch = system.character
        params = system.params
        fps = doc.fps
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
            chn = doc.channels.get(angle_channel_id(asset_id, j.name))
            if chn is not None and chn.keys:
                for d in range(3):
                    ang[d, :, k] = chn.evaluate(times, d)
        cx, cy = position_channel_ids(asset_id)
        tacc = np.zeros((n_steps, 2))
        for col, cid in enumerate((cx, cy)):
            chn = doc.channels.get(cid)
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
            self.steps_taken += 1
        # Keys on a dynamic joint's channel pose the pendulum at that frame.
        for kd in dyn_idx:
            k = int(kd)
            chn = doc.channels.get(angle_channel_id(asset_id, ch.joints[k].name))
            if chn is None:
                continue
            for key in chn.keys:
                if abs(key.time * fps - (frame + 1)) < 0.5:
                    theta[k] = key.value
                    omega[k] = 0.0
        return theta, omega


_CACHES: weakref.WeakKeyDictionary[Document, PendulumCache] = weakref.WeakKeyDictionary()


def simulation(doc: Document) -> PendulumCache:
    """The document's pendulum cache (created on first use)."""
    cache = _CACHES.get(doc)
    if cache is None:
        cache = PendulumCache(doc)
        _CACHES[doc] = cache
    return cache


def channel_for(doc: Document, asset_id: str, joint_index: int) -> Channel | None:
    ch = character(doc, asset_id)
    return doc.channels.get(angle_channel_id(asset_id, ch.joints[joint_index].name))


def summary(doc: Document, asset_id: str) -> dict[str, Any]:
    ch = character(doc, asset_id)
    return {"joints": len(ch.joints), "dynamic": int(ch.dynamic.sum())}
