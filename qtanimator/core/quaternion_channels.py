"""A rotation keyed as a quaternion: four scalar channels ``qw, qx, qy, qz`` read as one.

glTF keeps rotations as quaternion keys, and so does a joint with
:attr:`~qtanimator.core.skeleton.Joint.quaternion` set. The four components are ordinary
:class:`~qtanimator.core.channel.Channel` objects (so the curve editor, the dope sheet and
undo treat them like any other curve, as Blender's graph editor shows W, X, Y, Z), but the
span between two keys is evaluated as a rotation, as the glTF 2.0 specification says:

* a span whose keys are **linear** in all four channels is the shortest-path **slerp** of the
  two key quaternions;
* a **constant** (stepped) span holds the first key;
* a **cubic** span is each component's Hermite curve (a glTF CUBICSPLINE's in / out
  tangents are the keys' fixed slopes), normalised.

This needs the four channels to share their key times. When they do not (a key deleted in
one component), or outside the keys, each component is evaluated on its own and the result
normalised (nlerp): still a rotation, close to the slerp.
"""

from __future__ import annotations

import math
from bisect import bisect_right
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from qtanimator.core.channel import Channel, Extrapolation, Interpolation, Key
from qtanimator.core.rotation import euler_filter, euler_to_quaternions, normalize, quaternions_to_euler, slerp

FloatArray = npt.NDArray[np.float64]

#: Channel names of the components, in the order of the ``channels`` arguments below.
QUATERNION_DOFS = ("qw", "qx", "qy", "qz")

__all__ = ["QUATERNION_DOFS", "euler_channels", "quaternion_at", "quaternion_channels", "quaternions_at"]


def _aligned(channels: Sequence[Channel | None]) -> FloatArray | None:
    """The shared key times of four channels, or None when any is missing or differs."""
    first = channels[0]
    if first is None or len(first.keys) < 2:
        return None
    times = first.times
    for c in channels[1:]:
        if c is None or len(c.keys) != len(first.keys) or not np.array_equal(c.times, times):
            return None
    return times


def quaternions_at(channels: Sequence[Channel | None], rest: npt.ArrayLike, times: npt.ArrayLike) -> FloatArray:
    """(T, 4) unit ``(x, y, z, w)`` quaternions at ``times`` from the ``qw, qx, qy, qz``
    channels (None where a component has no channel: ``rest``'s component holds)."""
    t = np.asarray(times, dtype=np.float64).reshape(-1)
    r = np.asarray(rest, dtype=np.float64).reshape(4)
    out = np.empty((len(t), 4))
    # (x, y, z, w) slots of qw, qx, qy, qz
    for slot, ch in zip((3, 0, 1, 2), channels):
        out[:, slot] = r[slot] if ch is None or not ch.keys else ch.evaluate(t)
    key_times = _aligned(channels)
    if key_times is not None:
        inside = (t > key_times[0]) & (t < key_times[-1])
        if np.any(inside):
            i = np.clip(np.searchsorted(key_times, t[inside], side="right") - 1, 0, len(key_times) - 2)
            linear = _linear_spans(channels)
            use = linear[i]
            if np.any(use):
                ii = i[use]
                keys = _key_quaternions(channels)
                t0, t1 = key_times[ii], key_times[ii + 1]
                u = (t[inside][use] - t0) / (t1 - t0)
                rows = np.flatnonzero(inside)[use]
                out[rows] = slerp(keys[ii], keys[ii + 1], u)
    return normalize(out)


def quaternion_at(channels: Sequence[Channel | None], rest: npt.ArrayLike, time: float) -> FloatArray:
    """One ``(x, y, z, w)`` quaternion at ``time`` (see :func:`quaternions_at`).

    The common case, a slerp span of aligned channels, runs in plain Python floats on
    key arrays prepared once per set of channels: posing a character evaluates every joint
    at one time, and numpy's per-call cost would dominate."""
    plan = _plan(channels)
    t = float(time)
    if plan is not None:
        times, keys, linear, hold_before, hold_after = plan
        if times[0] < t < times[-1]:
            i = bisect_right(times, t) - 1
            if linear[i]:
                u = (t - times[i]) / (times[i + 1] - times[i])
                return np.array(_slerp_floats(keys[i], keys[i + 1], u))
        # at or outside the end keys with constant extrapolation: the end key itself (what
        # evaluating each component there and normalising gives, without compiling them)
        elif t <= times[0] and hold_before:
            return np.array(keys[0])
        elif t >= times[-1] and hold_after:
            return np.array(keys[-1])
    return quaternions_at(channels, rest, [t])[0]


_Plan = tuple[list[float], list[tuple[float, float, float, float]], list[bool], bool, bool]


def _plan(channels: Sequence[Channel | None]) -> _Plan | None:
    """Key times, key quaternions and linear-span flags of four aligned channels (cached on
    the first channel, with the identities of the other three), or None."""
    first = channels[0]
    if first is None:
        return None
    cached = first._derived.get("quaternion_plan")
    ids = tuple(id(c) for c in channels)
    if cached is not None and cached[0] == ids:
        plan: _Plan | None = cached[1]
        return plan
    # Straight from the keys: the channels need not be compiled for this.
    plan = None
    if all(c is not None and len(c.keys) == len(first.keys) for c in channels) and len(first.keys) >= 2:
        times = [k.time for k in first.keys]
        if all([k.time for k in c.keys] == times for c in channels[1:] if c is not None):
            w, x, y, z = ([k.value for k in c.keys] for c in channels if c is not None)
            keys = [tuple(q) for q in normalize(np.array([x, y, z, w]).T).tolist()]
            linear = [all(c.keys[i].interpolation is Interpolation.LINEAR for c in channels if c is not None)
                      for i in range(len(times) - 1)]
            chans = [c for c in channels if c is not None]
            plan = (times, keys, linear, all(c.pre is Extrapolation.CONSTANT for c in chans),
                    all(c.post is Extrapolation.CONSTANT for c in chans))
    # the other channels are kept alive with the plan, so their ids stay theirs
    first._derived["quaternion_plan"] = (ids, plan, tuple(channels))
    return plan


def _slerp_floats(a: Sequence[float], b: Sequence[float], u: float) -> list[float]:
    """:func:`qtanimator.core.rotation.slerp` for one pair, in floats (same formula)."""
    d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
    if d < 0.0:
        b = [-x for x in b]
        d = -d
    if d > 0.9995:
        out = [(1.0 - u) * x + u * y for x, y in zip(a, b)]
        n = math.sqrt(sum(x * x for x in out)) or 1.0
        return [x / n for x in out]
    theta = math.acos(min(d, 1.0))
    s = math.sin(theta)
    wa, wb = math.sin((1.0 - u) * theta) / s, math.sin(u * theta) / s
    return [wa * x + wb * y for x, y in zip(a, b)]


def _linear_spans(channels: Sequence[Channel | None]) -> npt.NDArray[np.bool_]:
    """Per span (key i to i + 1) whether all four channels interpolate it linearly."""
    flags: npt.NDArray[np.bool_] | None = None
    for ch in channels:
        assert ch is not None
        flags = ch.linear_spans if flags is None else flags & ch.linear_spans
    assert flags is not None
    return flags


def _key_quaternions(channels: Sequence[Channel | None]) -> FloatArray:
    """(K, 4) ``(x, y, z, w)`` key values (normalised) of aligned channels."""
    cols = []
    for ch in channels:
        assert ch is not None
        cols.append(ch.values)
    w, x, y, z = cols
    return normalize(np.stack([x, y, z, w], axis=1))


def _sample_times(channels: Sequence[Channel | None], fps: float) -> FloatArray:
    """Key times of the channels plus a grid at ``fps`` between the first and the last."""
    keyed = [c.times for c in channels if c is not None and c.keys]
    if not keyed:
        return np.zeros(0)
    times = np.concatenate(keyed)
    t0, t1 = float(times.min()), float(times.max())
    n = int(np.floor((t1 - t0) * fps + 1e-9)) + 1
    grid = t0 + np.arange(n, dtype=np.float64) / fps
    out = np.unique(np.concatenate([times, grid[grid <= t1]]))
    keep = np.concatenate([[True], np.diff(out) > 1e-9])
    result: FloatArray = out[keep]
    return result


def _linear_keys(times: FloatArray, values: FloatArray) -> Channel:
    return Channel(Key.series(times, values, Interpolation.LINEAR))


def euler_channels(channels: Sequence[Channel | None], rest: npt.ArrayLike, order: str,
                   fps: float) -> list[Channel | None]:
    """The ``rx, ry, rz`` channels (radians, linear keys) of a quaternion-keyed rotation:
    sampled at its key times and ``fps`` between, made continuous (the Euler filter). Exact
    at the samples; between them Euler angles are blended, not slerped."""
    times = _sample_times(channels, fps)
    if len(times) == 0:
        return [None, None, None]
    euler = euler_filter(quaternions_to_euler(quaternions_at(channels, rest, times), order), order)
    return [_linear_keys(times, euler[:, a]) for a in range(3)]


def quaternion_channels(channels: Sequence[Channel | None], rest: npt.ArrayLike, order: str,
                        fps: float) -> list[Channel | None]:
    """The ``qw, qx, qy, qz`` channels (linear keys: slerp spans) of an Euler-keyed rotation
    (``rx, ry, rz``; ``rest`` the Euler angles where one has no channel), sampled at its key
    times and ``fps`` between, each key on the side of the previous one."""
    times = _sample_times(channels, fps)
    if len(times) == 0:
        return [None, None, None, None]
    r = np.asarray(rest, dtype=np.float64).reshape(3)
    # an axis without keys holds its rest angle at every sampled time
    angles = np.stack([np.full(len(times), r[a]) if c is None or not c.keys
                       else np.asarray(c.evaluate(times), dtype=np.float64).reshape(len(times))
                       for a, c in enumerate(channels)], axis=-1)
    q = euler_to_quaternions(angles, order)
    for k in range(1, len(q)):
        if float(np.dot(q[k], q[k - 1])) < 0.0:
            q[k] = -q[k]
    return [_linear_keys(times, q[:, slot]) for slot in (3, 0, 1, 2)]
