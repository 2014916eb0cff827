"""Stepping one 2D character's pendulums and spring joints, frame by frame.

:class:`AssetSim` is one character's simulation (the
:class:`~qtanimator.core.pendulum.PendulumSystem`, its springs, its per-frame states and a
kinematics plan); :func:`advance` computes the state one frame on from the document's keys
and constants, :func:`initial_state` the state at the project's first frame. The
:class:`~qtanimator.document.pendulum_cache.PendulumCache` keeps the frames and runs them on
its worker. A spring joint's channel holds its keyed local angle; the simulation makes the
joint follow it through a damped spring (secondary motion,
:mod:`qtanimator.core.spring_joint`), with the pendulums' sub-step.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import numpy.typing as npt

from qtanimator.core.channel import Channel
from qtanimator.core.pendulum import PendulumBlowUp, PendulumParams, PendulumSystem, rotation_pivot_terms
from qtanimator.core.rig2d import Character, angle_sums
from qtanimator.core.spring_joint import SpringParams, SpringSystem
from qtanimator.document.character2d_asset import angle_channel_id, position_channel_ids
from qtanimator.document.document import Document
from qtanimator.document.joint_limits import joint_limits, limit_pair, limits_parameter
from qtanimator.document.pendulum_presets import pendulum_params, spring_params

FloatArray = npt.NDArray[np.float64]


def keyed_angles_at(channels: Mapping[str, Channel], asset_id: str, ch: Character, times: FloatArray,
                    limits: list[tuple[float, float] | None]) -> FloatArray:
    """(3, len(times), J): every non-dynamic joint's keyed local angle, rate and acceleration
    at ``times``, clamped to its limits (still while clamped), as :func:`advance` reads them."""
    out = np.zeros((3, len(times), len(ch.joints)))
    for k, j in enumerate(ch.joints):
        if j.is_dynamic:
            continue
        chn = channels.get(angle_channel_id(asset_id, j.name))
        if chn is not None and chn.keys:
            for d in range(3):
                out[d, :, k] = chn.evaluate(times, d)
        lim = limits[k]
        if lim is not None:
            held = (out[0, :, k] < lim[0]) | (out[0, :, k] > lim[1])
            out[0, :, k] = np.clip(out[0, :, k], lim[0], lim[1])
            out[1:, held, k] = 0.0
    return out


def keyed_translation_accelerations(channels: Mapping[str, Channel], asset_id: str, times: FloatArray) -> FloatArray:
    """(len(times), 2): the keyed acceleration of the character's position (x, y) at ``times``."""
    out = np.zeros((len(times), 2))
    for col, cid in enumerate(position_channel_ids(asset_id)):
        chn = channels.get(cid)
        if chn is not None and chn.keys:
            out[:, col] = chn.evaluate(times, 2)
    return out


def new_sim(doc: Document, asset_id: str, ch: Character) -> AssetSim:
    limits = joint_limits(doc, asset_id) if ch.simulated.any() else None
    return AssetSim(ch, pendulum_params(doc, asset_id), limits,
                    spring_params(doc, asset_id) if ch.spring.any() else None)


class AssetSim:
    """One character's simulation: the system, its per-frame states and a kinematics plan.

    World angles: a joint's world angle is the world angle θ_D of its nearest dynamic
    ancestor-or-self D plus the local angles of the keyframed joints after D on its path
    (from the root when there is no D). ``key_sum`` (J, J) and ``dyn_pick`` (J, J) are those
    two sums as matrices, so every sub-step's kinematics is a few array operations. Pivot
    accelerations are only needed at the groups' top joints: one term per (top, ancestor).
    """

    def __init__(self, ch: Character, params: PendulumParams,
                 limits: list[tuple[float, float] | None] | None = None,
                 springs: SpringParams | None = None) -> None:
        self.system = PendulumSystem(ch, params, limits)
        #: The spring joints (None without any); their entries of ``theta`` / ``omega`` are
        #: their simulated local angles and rates.
        self.springs = (SpringSystem(ch, springs, limits, params.restitution)
                        if springs is not None and ch.spring.any() else None)
        self.theta: list[FloatArray] = []  # per frame (world angles, J)
        self.omega: list[FloatArray] = []
        #: Bumped by an invalidation that reaches the frame being computed (see PendulumCache).
        self.generation = 0
        #: Why the simulation stopped after its last cached frame (a blow-up), or None.
        self.problem: PendulumBlowUp | None = None
        self.key_sum, self.dyn_pick = angle_sums(ch)
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
        parents = np.array([-1 if j.parent is None else j.parent for j in ch.joints], dtype=np.intp)
        self.has_parent = parents >= 0
        self.parent_of = np.maximum(parents, 0)

    def spring_substep(self, s: int, theta: FloatArray, omega: FloatArray, tau: float, ang: FloatArray,
                       mid: FloatArray, tacc_mid: FloatArray, w_key: FloatArray, r_key: FloatArray,
                       a_key: FloatArray) -> None:
        """Step the spring joints over sub-step ``s`` (their entries of ``theta`` and
        ``omega``), then put their shown angles into the keyed kinematics of sub-step ``s``
        (``w_key``, ``r_key``, ``a_key``) that the pendulums read."""
        springs = self.springs
        assert springs is not None
        q = springs.joints
        before_t, before_w = theta[q].copy(), omega[q].copy()
        key, key_rate, key_acc = mid[0, s].copy(), mid[1, s].copy(), mid[2, s].copy()
        springs.step(theta, omega, tau, key, key_rate, key_acc, theta, omega, tacc_mid[s])
        mix = springs.params.mix
        if mix:
            avg_acc = (omega[q] - before_w) / tau
            cols = self.key_sum[:, q]
            w_key[s] += cols @ (mix * (before_t - ang[0, s, q]))
            r_key[s] += cols @ (mix * (before_w - ang[1, s, q]))
            a_key[s] += cols @ (mix * (avg_acc - ang[2, s, q]))

    def parent_motion(self, s: int, theta: FloatArray, omega: FloatArray, w_key: FloatArray, r_key: FloatArray,
                      ang: FloatArray, end: FloatArray) -> FloatArray:
        """(J, 4): the keyed part of every joint's parent's world angle and rate at the
        start and end of sub-step ``s`` (``PendulumSystem.step``'s ``parent_motion``), the
        springs stepped already. ``end`` (3, J): the keyed angles at the frame's end."""
        n = len(self.has_parent)
        nxt = end if s + 1 >= len(w_key) else ang[:, s + 1]
        w1 = nxt[0] @ self.key_sum.T
        r1 = nxt[1] @ self.key_sum.T
        if self.springs is not None and self.springs.params.mix:
            # Springs after this sub-step (what the next sub-step's correction will add).
            q = self.springs.joints
            mix = self.springs.params.mix
            cols = self.key_sum[:, q]
            w1 = w1 + cols @ (mix * (theta[q] - nxt[0, q]))
            r1 = r1 + cols @ (mix * (omega[q] - nxt[1, q]))
        out = np.zeros((n, 4))
        p, has = self.parent_of, self.has_parent
        out[has, 0] = w_key[s][p[has]]
        out[has, 1] = r_key[s][p[has]]
        out[has, 2] = w1[p[has]]
        out[has, 3] = r1[p[has]]
        return out


def initial_state(doc: Document, asset_id: str, sim: AssetSim) -> tuple[FloatArray, FloatArray]:
    """The state at the project's first frame (:func:`initial_angles`, :func:`initial_rates`)."""
    ch = sim.system.character
    t0 = doc.frame_range[0] / doc.fps
    return initial_angles(doc, asset_id, ch, t0), initial_rates(doc, asset_id, ch, t0)


def advance(doc: Document, asset_id: str, sim: AssetSim, frame: int, theta0: FloatArray,
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
    times = np.asarray(t0 + tau * np.arange(n_steps), dtype=np.float64)
    theta, omega = theta0.copy(), omega0.copy()
    dyn_idx = np.flatnonzero(ch.dynamic)
    # Channel values and derivatives at every sub-step time, evaluated at once.
    stored = doc.parameters
    limits = [limit_pair(stored.get(limits_parameter(asset_id, j.name))) for j in ch.joints]
    ang = keyed_angles_at(channels, asset_id, ch, times, limits)
    tacc = keyed_translation_accelerations(channels, asset_id, times)
    # Keyframed parts of the world angles, rates and accelerations for every sub-step.
    w_key = ang[0] @ sim.key_sum.T
    r_key = ang[1] @ sim.key_sum.T
    a_key = ang[2] @ sim.key_sum.T
    springs, bounded = sim.springs, bool(system.bounded.any())
    mid, tacc_mid, end = ang, tacc, ang[:, 0]
    if springs is not None:  # keys and the body's acceleration at the sub-steps' midpoints
        mids = np.asarray(times + 0.5 * tau, dtype=np.float64)
        mid = keyed_angles_at(channels, asset_id, ch, mids, limits)
        tacc_mid = keyed_translation_accelerations(channels, asset_id, mids)
    if bounded:  # limits: the parents' motion to the frame's end
        end = keyed_angles_at(channels, asset_id, ch, np.array([t1]), limits)[:, 0]
    tacc = tacc * params.accel_scale
    pa = np.zeros((len(ch.joints), 2))
    rs = params.rotation_accel_scale
    for s in range(n_steps):
        if springs is not None:
            sim.spring_substep(s, theta, omega, tau, ang, mid, tacc_mid, w_key, r_key, a_key)
        if len(sim.pair_anc):
            world = w_key[s] + sim.dyn_pick @ theta
            rate = r_key[s] + sim.dyn_pick @ omega
            contrib = rotation_pivot_terms(world[sim.pair_anc], rate[sim.pair_anc], a_key[s][sim.pair_anc],
                                           sim.pair_vec, rs)
            pa[sim.tops] = tacc[s] + sim.pair_sum @ contrib
        else:
            pa[sim.tops] = tacc[s]
        motion = sim.parent_motion(s, theta, omega, w_key, r_key, ang, end) if bounded else None
        system.step(theta, omega, pa, tau, motion)
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


def initial_angles(doc: Document, asset_id: str, ch: Character, t0: float) -> FloatArray:
    """The simulation's start state: dynamic joints' keyed world angles at ``t0`` (else 0),
    spring joints on their keyed local angle (clamped to their limits)."""
    theta = np.zeros(len(ch.joints))
    for k, j in enumerate(ch.joints):
        if j.is_dynamic:
            chn = doc.channels.get(angle_channel_id(asset_id, j.name))
            if chn is not None and chn.keys:
                theta[k] = float(chn.evaluate(t0))
    if ch.spring.any():
        limits = joint_limits(doc, asset_id)
        keyed = keyed_angles_at(doc.channels, asset_id, ch, np.array([t0]), limits)
        theta[ch.spring] = keyed[0, 0, ch.spring]
    return theta


def initial_rates(doc: Document, asset_id: str, ch: Character, t0: float) -> FloatArray:
    """The start rates: 0 for pendulums; spring joints move with their keys."""
    omega = np.zeros(len(ch.joints))
    if ch.spring.any():
        keyed = keyed_angles_at(doc.channels, asset_id, ch, np.array([t0]), joint_limits(doc, asset_id))
        omega[ch.spring] = keyed[1, 0, ch.spring]
    return omega
