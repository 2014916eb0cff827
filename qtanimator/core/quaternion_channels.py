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

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from qtanimator.core.channel import Channel
from qtanimator.core.rotation import normalize, slerp

FloatArray = npt.NDArray[np.float64]

#: Channel names of the components, in the order of the ``channels`` arguments below.
QUATERNION_DOFS = ("qw", "qx", "qy", "qz")

__all__ = ["QUATERNION_DOFS", "quaternion_at", "quaternions_at"]


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
    """One ``(x, y, z, w)`` quaternion at ``time`` (see :func:`quaternions_at`)."""
    return quaternions_at(channels, rest, [time])[0]


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
