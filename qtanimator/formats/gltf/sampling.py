"""The times the character exports sample: a regular grid at the frame rate plus every key
time of the channels (cycled keys included)."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from qtanimator.core.channel import Channel, Extrapolation

FloatArray = npt.NDArray[np.float64]


def grid_times(start: float, end: float, fps: float) -> FloatArray:
    """``start``, ``start + 1 / fps``, … up to ``end`` (both included)."""
    if not (math.isfinite(start) and math.isfinite(end) and math.isfinite(fps)) or fps <= 0 or end < start:
        raise ValueError(f"need finite start <= end and fps > 0, got start={start}, end={end}, fps={fps}")
    n = int(math.floor((end - start) * fps + 1e-9)) + 1
    times = start + np.arange(n, dtype=np.float64) / fps
    if end - times[-1] > 1e-9:
        times = np.append(times, end)
    return times


def with_key_times(grid: FloatArray, channels: Sequence[Channel], start: float, end: float,
                    tolerance: float = 1e-6, limit: int = 100_000) -> FloatArray:
    """The sample grid plus every key time (cycled keys included) inside [start, end]; a
    grid time within ``tolerance`` of a key time gives way to it."""
    periodic = (Extrapolation.CYCLE, Extrapolation.CYCLE_OFFSET, Extrapolation.BOUNCE)
    found: list[FloatArray] = []
    total = 0
    for ch in channels:
        if len(ch.keys) < 2:
            continue
        kt = ch.times
        t0, t1 = float(kt[0]), float(kt[-1])
        d = t1 - t0
        found.append(kt[(kt >= start) & (kt <= end)])
        for mode, lo, hi in ((ch.pre, start, t0), (ch.post, t1, end)):
            if mode not in periodic or hi <= lo:
                continue
            m0 = math.floor((lo - t0) / d) - 1
            m1 = math.ceil((hi - t0) / d) + 1
            base = np.concatenate([kt, t0 + t1 - kt]) if mode is Extrapolation.BOUNCE else kt
            total += (m1 - m0 + 1) * len(base)
            if total > limit:
                break
            shifted = (base[None, :] + d * np.arange(m0, m1 + 1, dtype=np.float64)[:, None]).reshape(-1)
            found.append(shifted[(shifted >= lo) & (shifted <= hi)])
    if not found:
        return grid
    keys = np.unique(np.concatenate(found))
    if len(keys) == 0:
        return grid
    # Merge keys closer than the tolerance, then drop grid times next to a key.
    keys = keys[np.concatenate([[True], np.diff(keys) > tolerance])]
    i = np.clip(np.searchsorted(keys, grid), 1, len(keys) - 1) if len(keys) > 1 else np.zeros(len(grid), int)
    near = np.abs(keys[i] - grid) <= tolerance
    if len(keys) > 1:
        near |= np.abs(keys[i - 1] - grid) <= tolerance
    merged: FloatArray = np.union1d(grid[~near], keys)
    return merged


def sample_times(start: float, end: float, fps: float, channels: Sequence[Channel] = ()) -> FloatArray:
    """Times from ``start`` to ``end`` (both included) every ``1 / fps`` seconds, plus every
    key time of ``channels`` (cycled keys included) inside that range; what the exports sample."""
    return with_key_times(grid_times(start, end, fps), channels, start, end)
