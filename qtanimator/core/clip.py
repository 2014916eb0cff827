"""Animation clips for 3D skeletons, the channel → DOF mapping, and playback modes.

An ``.anim`` clip is a list of channels: 0, 1, 2 are the root translation x, y, z; then
three per joint (x, y, z rotation) in the skeleton's depth-first order, so joint k uses
channels ``3 + 3k``, ``4 + 3k``, ``5 + 3k`` (notes/cse169-formats.md §6.1).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from enum import StrEnum

import numpy as np
import numpy.typing as npt

from qtanimator.core.channel import Channel
from qtanimator.core.skeleton import AXES, Skeleton

FloatArray = npt.NDArray[np.float64]

ROOT = -1  #: joint index used for the root translation channels


@dataclass
class AnimationClip:
    """Channels plus the intended playback interval ``[start, end]`` (seconds).

    Key times may lie outside the interval; each channel extrapolates on its own.
    """

    channels: list[Channel] = field(default_factory=list)
    start: float = 0.0
    end: float = 0.0

    @property
    def duration(self) -> float:
        return self.end - self.start

    def evaluate(self, time: float | npt.ArrayLike) -> FloatArray:
        """Every channel at ``time``: shape (C,) for a float, (C, N) for N times."""
        if np.ndim(time) == 0:
            return np.array([ch.evaluate(float(time)) for ch in self.channels], dtype=np.float64)  # type: ignore[arg-type]
        t = np.asarray(time, dtype=np.float64)
        return np.array([ch.evaluate(t) for ch in self.channels], dtype=np.float64).reshape(len(self.channels), -1)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, AnimationClip):
            return NotImplemented
        return (self.start == other.start and self.end == other.end
                and list(self.channels) == list(other.channels))

    __hash__ = None  # type: ignore[assignment]


def channel_count(num_joints: int) -> int:
    """Channels a full clip for a skeleton of ``num_joints`` joints has."""
    return 3 + 3 * num_joints


def channel_target(index: int) -> tuple[int, str]:
    """Channel index → ``(joint, axis)``; joint is :data:`ROOT` for the root translation."""
    if index < 0:
        raise ValueError("channel index must not be negative")
    if index < 3:
        return ROOT, AXES[index]
    joint, axis = divmod(index - 3, 3)
    return joint, AXES[axis]


def channel_index(joint: int, axis: str | int) -> int:
    """Inverse of :func:`channel_target`."""
    a = AXES.index(axis) if isinstance(axis, str) else int(axis)
    if not 0 <= a <= 2:
        raise ValueError(f"axis must be x, y or z, got {axis!r}")
    return a if joint == ROOT else 3 + 3 * joint + a


def pose_values(channels: Sequence[Channel | None], num_joints: int, time: float,
                skeleton: Skeleton | None = None) -> tuple[FloatArray, FloatArray]:
    """``(root_translation (3,), dof_values (J, 3))`` from the channels at ``time``.

    Missing channels (short clips or None entries) keep the skeleton's current value, or
    0 without a skeleton. Values are not clamped here.
    """
    root = skeleton.root_translation.copy() if skeleton is not None else np.zeros(3)
    dofs = skeleton.dof_values() if skeleton is not None else np.zeros((num_joints, 3))
    flat = dofs.reshape(-1)
    for i, ch in enumerate(channels[: channel_count(num_joints)]):
        if ch is None:
            continue
        v = ch.evaluate(float(time))
        if i < 3:
            root[i] = v
        else:
            flat[i - 3] = v
    return root, dofs


def apply_clip(skeleton: Skeleton, channels: Sequence[Channel | None] | AnimationClip, time: float) -> Skeleton:
    """Pose ``skeleton`` in place from the channels at ``time`` (DOFs clamped); returns it."""
    chs = channels.channels if isinstance(channels, AnimationClip) else channels
    root, dofs = pose_values(chs, len(skeleton.joints), time, skeleton)
    skeleton.root_translation = root
    skeleton.set_dof_values(dofs)
    return skeleton


class PlayMode(StrEnum):
    LOOP = "loop"            #: wrap into [start, end]
    ONCE = "once"            #: play to the end and stop there
    PING_PONG = "ping-pong"  #: forwards, then backwards
    CONTINUE = "continue"    #: keep going; the channels extrapolate


class ClipPlayer:
    """Maps elapsed playback time to clip time for a play mode and speed.

    ``advance(dt)`` moves the playhead by ``dt`` wall seconds; ``time`` is the clip time
    to evaluate. ``clip_time(elapsed)`` is the pure mapping used by both.
    """

    def __init__(self, start: float, end: float, mode: PlayMode | str = PlayMode.LOOP,
                 speed: float = 1.0) -> None:
        if not (math.isfinite(start) and math.isfinite(end)) or end < start:
            raise ValueError(f"a playback range needs start <= end, got [{start}, {end}]")
        if not math.isfinite(speed):
            raise ValueError("speed must be finite")
        self.start = float(start)
        self.end = float(end)
        self.mode = PlayMode(mode)
        self.speed = float(speed)
        self.elapsed = 0.0

    @classmethod
    def for_clip(cls, clip: AnimationClip, mode: PlayMode | str = PlayMode.LOOP, speed: float = 1.0) -> ClipPlayer:
        return cls(clip.start, clip.end, mode, speed)

    @property
    def duration(self) -> float:
        return self.end - self.start

    def clip_time(self, elapsed: float) -> float:
        """Clip time after ``elapsed`` seconds of clip-speed playback from ``start``."""
        d = self.duration
        if self.mode is PlayMode.CONTINUE:
            return self.start + elapsed
        if d <= 0.0:
            return self.start
        if self.mode is PlayMode.ONCE:
            return min(max(self.start + elapsed, self.start), self.end)
        if self.mode is PlayMode.LOOP:
            k = math.floor(elapsed / d)
            u = min(max(elapsed - k * d, 0.0), d)
            # The end of the range is the start of the next loop.
            return self.start + (0.0 if u >= d else u)
        # ping-pong: period 2d, forwards then backwards
        k = math.floor(elapsed / (2.0 * d))
        u = min(max(elapsed - k * 2.0 * d, 0.0), 2.0 * d)
        return self.start + (u if u <= d else 2.0 * d - u)

    @property
    def time(self) -> float:
        return self.clip_time(self.elapsed)

    @property
    def finished(self) -> bool:
        """True in "once" mode when the playhead has reached the end it is moving towards."""
        if self.mode is not PlayMode.ONCE:
            return False
        return (self.speed > 0 and self.elapsed >= self.duration) or (self.speed < 0 and self.elapsed <= 0.0)

    def advance(self, dt: float) -> float:
        """Move by ``dt`` wall seconds (scaled by ``speed``) and return the new clip time."""
        self.elapsed += dt * self.speed
        if self.mode is PlayMode.ONCE:
            self.elapsed = min(max(self.elapsed, 0.0), self.duration)
        return self.time

    def seek(self, clip_time: float) -> None:
        """Put the playhead at ``clip_time`` (clamped into the range except in continue mode)."""
        if self.mode is PlayMode.CONTINUE:
            self.elapsed = clip_time - self.start
        else:
            self.elapsed = min(max(clip_time, self.start), self.end) - self.start

    def reset(self) -> None:
        self.elapsed = 0.0
