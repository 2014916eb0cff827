"""Display-only normalisation of curves: each channel's keyed range scaled to −1…1.

Channels are immutable, so a channel's ``(offset, scale)`` is cached per channel object.
"""

from __future__ import annotations

import numpy as np

from qtanimator.core.channel import Channel


class NormalisationCache:
    """``(offset, scale)`` per channel id, valid while the channel object is the same."""

    def __init__(self) -> None:
        self._entries: dict[str, tuple[Channel, float, float]] = {}

    def get(self, cid: str, channel: Channel) -> tuple[float, float]:
        """``(offset, scale)`` so that ``(value - offset) * scale`` spans −1…1 over the keyed range."""
        hit = self._entries.get(cid)
        if hit is not None and hit[0] is channel:
            return hit[1], hit[2]
        offset, scale = channel_normalisation(channel)
        self._entries[cid] = (channel, offset, scale)
        return offset, scale

    def drop(self, cid: str) -> None:
        self._entries.pop(cid, None)

    def clear(self) -> None:
        self._entries.clear()


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
    v = np.asarray(v, dtype=np.float64)
    v = v[np.isfinite(v)]  # a channel the reader's bounds did not make (or an overflow): never NaN
    if not v.size:
        return 0.0, 1.0
    lo, hi = float(np.min(v)), float(np.max(v))
    half = 0.5 * hi - 0.5 * lo  # halves first: hi - lo of ±1e308 would overflow
    mid = 0.5 * hi + 0.5 * lo
    if not half > 1e-12 * max(1.0, abs(mid)) or not np.isfinite(1.0 / half):
        return mid, 1.0
    return mid, 1.0 / half


# ------------------------------------------------------------------ display units
#: DOFs whose channels hold angles in radians (2D joint angles, 3D joint rotations). The
#: curve editor shows them in degrees, like the DOF sliders and the properties dock.
ROTATION_DOFS = frozenset({"angle", "rx", "ry", "rz"})
DEGREES = 180.0 / np.pi


def is_rotation(cid: str) -> bool:
    """True for a channel that holds an angle in radians."""
    return cid.rsplit("/", 1)[-1] in ROTATION_DOFS


def unit_scale(cid: str) -> float:
    """Displayed value per document value: 180/π for rotations (degrees), else 1."""
    return DEGREES if is_rotation(cid) else 1.0


def unit_suffix(cid: str) -> str:
    """The unit the curve editor shows a channel's values in ("°" or "")."""
    return "°" if is_rotation(cid) else ""
