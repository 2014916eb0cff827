"""Vectorised, cached sampling of channels for drawing.

A :class:`SampleCache` keeps, per channel id, the samples of the channel object it was
computed from and the view span it covers. Channels are immutable, so an entry is valid as
long as ``entry.channel is channel``: an edit replaces only that channel's object and only
that channel is sampled again. Panning or zooming changes the span and resamples what is
visible, each channel with one ``Channel.evaluate`` call over an array of times.

Times here are in frames (``seconds * fps``); values are the channel's own units.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from qtanimator.core.channel import Channel

FloatArray = npt.NDArray[np.float64]

_EMPTY = np.zeros(0)
#: How far before a key the sampler adds a point, in frames, so stepped spans draw upright.
_STEP_EPS = 1e-6


@dataclass(frozen=True, eq=False)
class Samples:
    """Polylines of one channel: ``x`` / ``y`` inside the keyed range (solid) and
    ``ext_x`` / ``ext_y`` for the extrapolated parts (dashed; NaN separates pre and post)."""

    channel: Channel
    span: tuple[float, float, int, float]
    x: FloatArray
    y: FloatArray
    ext_x: FloatArray
    ext_y: FloatArray


def sample_channel(channel: Channel, fps: float, x0: float, x1: float, n: int) -> Samples:
    """Sample ``channel`` over frames ``[x0, x1]`` with about ``n`` points across the view."""
    span = (x0, x1, n, fps)
    if not channel.keys or not x1 > x0:
        return Samples(channel, span, _EMPTY, _EMPTY, _EMPTY, _EMPTY)
    frames = channel.times * fps
    f0, f1 = float(frames[0]), float(frames[-1])
    width = x1 - x0
    lo, hi = max(x0, f0), min(x1, f1)
    inside = _EMPTY
    if hi >= lo:
        count = max(2, int(n * (hi - lo) / width) + 2)
        inner = frames[(frames > lo) & (frames < hi)]
        inside = np.unique(np.concatenate([np.linspace(lo, hi, count), inner, inner - _STEP_EPS]))
    pre = _EMPTY
    if x0 < f0:
        end = min(f0, x1)
        pre = np.linspace(x0, end, _extrapolated_count(channel.pre.value, n, (end - x0) / width))
    post = _EMPTY
    if x1 > f1:
        start = max(f1, x0)
        post = np.linspace(start, x1, _extrapolated_count(channel.post.value, n, (x1 - start) / width))
    allx = np.concatenate([inside, pre, post])
    ally = channel.evaluate(allx / fps)
    ni, npre = len(inside), len(pre)
    y_in = ally[:ni]
    y_pre = ally[ni:ni + npre]
    y_post = ally[ni + npre:]
    if npre and len(post):
        ext_x = np.concatenate([pre, [np.nan], post])
        ext_y = np.concatenate([y_pre, [np.nan], y_post])
    else:
        ext_x = pre if npre else post
        ext_y = y_pre if npre else y_post
    return Samples(channel, span, inside, y_in, ext_x, ext_y)


def _extrapolated_count(mode: str, n: int, fraction: float) -> int:
    if mode in ("constant", "linear"):
        return 2  # a straight line needs only its ends
    return max(2, int(n * max(fraction, 0.0)) + 2)


class SampleCache:
    """Per-channel samples, valid while the channel object and the view span are the same."""

    def __init__(self) -> None:
        self._entries: dict[str, Samples] = {}
        self._norm: dict[str, tuple[Channel, float, float]] = {}
        #: Number of channels sampled since creation (tests and benchmarks read it).
        self.sampled = 0

    def get(self, cid: str, channel: Channel, fps: float, x0: float, x1: float, n: int) -> Samples:
        entry = self._entries.get(cid)
        span = (x0, x1, n, fps)
        if entry is not None and entry.channel is channel and entry.span == span:
            return entry
        entry = sample_channel(channel, fps, x0, x1, n)
        self._entries[cid] = entry
        self.sampled += 1
        return entry

    def cached(self, cid: str) -> Samples | None:
        return self._entries.get(cid)

    def drop(self, cid: str) -> None:
        self._entries.pop(cid, None)
        self._norm.pop(cid, None)

    def clear(self) -> None:
        self._entries.clear()
        self._norm.clear()

    def normalisation(self, cid: str, channel: Channel) -> tuple[float, float]:
        """``(offset, scale)`` so that ``(value - offset) * scale`` spans −1…1 over the keyed range."""
        hit = self._norm.get(cid)
        if hit is not None and hit[0] is channel:
            return hit[1], hit[2]
        offset, scale = channel_normalisation(channel)
        self._norm[cid] = (channel, offset, scale)
        return offset, scale


def channel_normalisation(channel: Channel) -> tuple[float, float]:
    """Offset and scale mapping the channel's values between its first and last key to −1…1."""
    if not channel.keys:
        return 0.0, 1.0
    times = channel.times
    if len(times) > 1:
        t = np.concatenate([np.linspace(times[0], times[-1], 256), times])
        v = channel.evaluate(t)
    else:
        v = channel.values
    lo, hi = float(np.min(v)), float(np.max(v))
    half = 0.5 * (hi - lo)
    mid = 0.5 * (hi + lo)
    if half <= 1e-12 * max(1.0, abs(mid)):
        return mid, 1.0
    return mid, 1.0 / half
