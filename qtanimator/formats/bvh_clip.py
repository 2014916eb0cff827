"""The BVH model: a parsed file's joints and motion table, and the pose maths on them.

:class:`BvhClip` holds what :mod:`qtanimator.formats.bvh_parser` read; its conventions
(rotation order per joint, relative and absolute position channels, frame times, channels
in radians) are those described in :mod:`qtanimator.formats.bvh`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.core.channel import Channel, Extrapolation, Interpolation, Key, Tangent
from qtanimator.core.skeleton import Joint, Skeleton, axis_rotations

FloatArray = npt.NDArray[np.float64]

#: How position channels combine with the OFFSET: added ("relative") or replacing it ("absolute").
POSITION_CONVENTIONS = ("relative", "absolute")
#: Below the root a joint's position channels must stay within this fraction of the
#: skeleton's size of their first frame's value (qtanimator's 3D joints below the root only turn).
STILL_TOLERANCE = 1e-4

#: The six BVH channel names, in their canonical spelling.
CHANNEL_NAMES = ("Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation")


@dataclass(frozen=True, eq=False)
class BvhJoint:
    """One ``ROOT`` or ``JOINT``.

    ``channels`` are the canonical channel names in file order; ``first_column`` is the
    index of the first one in a motion row. ``end_site`` is the End Site offset, or None
    (a leaf may have no End Site). ``key`` is the name made unique within the file.
    """

    name: str
    key: str
    parent: int | None
    offset: FloatArray
    channels: tuple[str, ...]
    first_column: int
    end_site: FloatArray | None
    line: int

    @property
    def rotation_order(self) -> str:
        """The rotation axes in multiplication order, e.g. ``"zyx"`` for Rz·Ry·Rx."""
        return "".join(c[0].lower() for c in self.channels if c.endswith("rotation"))

    @property
    def columns(self) -> range:
        return range(self.first_column, self.first_column + len(self.channels))


class BvhClip:
    """A parsed BVH file: joints in file (depth-first) order and the motion table."""

    def __init__(self, joints: Sequence[BvhJoint], frame_time: float, motion: FloatArray,
                 path: str | None = None, warnings: Sequence[str] = ()) -> None:
        self.path = path
        #: Things the reader let pass, for the user (rows after the declared frames).
        self.warnings: list[str] = list(warnings)
        self.joints: tuple[BvhJoint, ...] = tuple(joints)
        self.frame_time = float(frame_time)
        #: (frame_count, channel_count) values exactly as written: degrees and file units.
        self.motion: FloatArray = motion
        self._channels: dict[str, Channel] | None = None
        self._radians: FloatArray | None = None
        self._kinds, self._axes, self._owner = _column_tables(self.joints)
        #: The position convention every pose method uses: detected from the file.
        self.positions: str = detect_positions(self)

    # ----------------------------------------------------------------- layout
    @property
    def frame_count(self) -> int:
        return int(self.motion.shape[0])

    @property
    def channel_count(self) -> int:
        return int(self.motion.shape[1])

    @property
    def fps(self) -> float:
        return 1.0 / self.frame_time

    @property
    def duration(self) -> float:
        """Time of the last frame in seconds (0 for a single frame)."""
        return max(self.frame_count - 1, 0) * self.frame_time

    @property
    def joint_names(self) -> list[str]:
        return [j.name for j in self.joints]

    @property
    def parents(self) -> list[int | None]:
        return [j.parent for j in self.joints]

    @property
    def offsets(self) -> FloatArray:
        return np.array([j.offset for j in self.joints], dtype=np.float64).reshape(-1, 3)

    @property
    def channel_layout(self) -> list[tuple[int, str]]:
        """``(joint index, channel name)`` for every motion column."""
        return [(ji, c) for ji, j in enumerate(self.joints) for c in j.channels]

    @property
    def channel_names(self) -> list[str]:
        """``"joint key/channel"`` for every motion column, e.g. ``"Hips/Zrotation"``."""
        return [f"{j.key}/{c}" for j in self.joints for c in j.channels]

    def joint_index(self, name: str) -> int:
        for i, j in enumerate(self.joints):
            if j.key == name or j.name == name:
                return i
        raise KeyError(name)

    def frame_times(self) -> FloatArray:
        return np.arange(self.frame_count, dtype=np.float64) * self.frame_time

    # --------------------------------------------------------------- channels
    @property
    def channels(self) -> dict[str, Channel]:
        """One channel per motion column, keyed like :attr:`channel_names`.

        Keys at ``i · frame_time`` with linear spans and constant extrapolation; rotation
        values in radians, positions in file units.
        """
        if self._channels is None:
            times = self.frame_times().tolist()
            values = self.channel_values_radians()
            chans: dict[str, Channel] = {}
            for col, name in enumerate(self.channel_names):
                column = values[:, col].tolist()
                keys = [Key(t, v, Tangent.LINEAR, Tangent.LINEAR, interpolation=Interpolation.LINEAR)
                        for t, v in zip(times, column)]
                chans[name] = Channel(keys, Extrapolation.CONSTANT, Extrapolation.CONSTANT)
            self._channels = chans
        return self._channels

    def channel_values_radians(self) -> FloatArray:
        """The motion table with rotation columns converted to radians (a read-only array)."""
        if self._radians is None:
            out = self.motion.copy()
            rot = self._kinds == 1
            out[:, rot] = np.radians(out[:, rot])
            out.setflags(write=False)
            self._radians = out
        return self._radians

    def values_at(self, time: float) -> FloatArray:
        """Channel values (radians / file units) at ``time`` seconds, by linear interpolation
        between frames and holding the first / last frame outside the clip."""
        n = self.frame_count
        if n == 0:
            return np.zeros(self.channel_count)
        values = self.channel_values_radians()
        if n == 1:
            return values[0].copy()
        f = float(time) / self.frame_time
        if math.isnan(f):
            raise ValueError("time is NaN")
        if f <= 0.0:
            return values[0].copy()
        if f >= n - 1:
            return values[-1].copy()
        i = int(math.floor(f))
        u = f - i
        if u == 0.0:
            return values[i].copy()
        return values[i] * (1.0 - u) + values[i + 1] * u

    # ------------------------------------------------------------------- pose
    def world_matrices(self, time: float | None = None, *, frame: int | None = None,
                       positions: str | None = None) -> FloatArray:
        """(J, 4, 4) world matrices at ``time`` seconds (channels interpolated linearly) or at
        motion row ``frame`` (the file's numbers, exactly). With neither, frame 0 (or the
        rest pose for a file with no frames). ``positions`` overrides :attr:`positions`."""
        if time is not None and frame is not None:
            raise ValueError("give a time or a frame, not both")
        if frame is not None:
            if not -self.frame_count <= frame < self.frame_count:
                raise IndexError(f"frame {frame} is outside 0..{self.frame_count - 1}")
            row = self._row_radians(self.motion[frame])
        elif time is not None:
            row = self.values_at(time)
        elif self.frame_count:
            row = self._row_radians(self.motion[0])
        else:
            return self.rest_world_matrices()
        return self._world(row[None, :], positions)[0]

    def all_world_matrices(self, positions: str | None = None) -> FloatArray:
        """(F, J, 4, 4) world matrices of every frame."""
        return self._world(self.channel_values_radians(), positions)

    def size(self) -> float:
        """The skeleton's size: the largest extent of its rest pose (joints and End Sites),
        1 for a skeleton with no extent."""
        rest = self.rest_world_matrices()
        points = [rest[:, :3, 3], *[p[None, :] for p in self.end_site_positions(rest).values()]]
        extent = float(np.ptp(np.concatenate(points), axis=0).max()) if len(self.joints) else 0.0
        return extent if extent > 0.0 else 1.0

    def rest_world_matrices(self) -> FloatArray:
        """(J, 4, 4) world matrices with every channel at 0 (offsets only)."""
        return self._world(np.zeros((1, self.channel_count)), "relative")[0]

    def end_site_positions(self, world: FloatArray) -> dict[int, FloatArray]:
        """World position of every End Site, keyed by its joint, from (J, 4, 4) matrices."""
        out: dict[int, FloatArray] = {}
        for i, j in enumerate(self.joints):
            if j.end_site is not None:
                out[i] = world[i, :3, :3] @ j.end_site + world[i, :3, 3]
        return out

    def _row_radians(self, row: FloatArray) -> FloatArray:
        out = np.array(row, dtype=np.float64)
        rot = self._kinds == 1
        out[rot] = np.radians(out[rot])
        return out

    def local_translations(self, values: FloatArray, joint: int, positions: str | None = None) -> FloatArray:
        """(F, 3) translation of ``joint`` in its parent's frame for rows of channel values:
        the OFFSET plus (relative) or replaced by (absolute) its position channels."""
        absolute = _convention(positions or self.positions) == "absolute"
        j = self.joints[joint]
        trans = np.broadcast_to(j.offset, (values.shape[0], 3)).copy()
        for col in j.columns:
            if self._kinds[col] == 0:
                axis = int(self._axes[col])
                trans[:, axis] = values[:, col] if absolute else trans[:, axis] + values[:, col]
        return trans

    def _world(self, values: FloatArray, positions: str | None = None) -> FloatArray:
        """World matrices for rows of channel values (radians): (F, C) -> (F, J, 4, 4)."""
        absolute = _convention(positions or self.positions) == "absolute"
        frames = values.shape[0]
        nj = len(self.joints)
        world = np.empty((frames, nj, 4, 4))
        for ji, joint in enumerate(self.joints):
            local = np.zeros((frames, 4, 4))
            local[:, 3, 3] = 1.0
            rot = np.broadcast_to(np.eye(3), (frames, 3, 3)).copy()
            trans = np.broadcast_to(joint.offset, (frames, 3)).copy()
            for col in joint.columns:
                axis = int(self._axes[col])
                v = values[:, col]
                if self._kinds[col] == 0:
                    if absolute:
                        trans[:, axis] = v
                    else:
                        trans[:, axis] += v
                else:
                    rot = rot @ axis_rotations(axis, v)
            local[:, :3, :3] = rot
            local[:, :3, 3] = trans
            if joint.parent is None:
                world[:, ji] = local
            else:
                world[:, ji] = world[:, joint.parent] @ local
        return world

    def to_skeleton(self, positions: str | None = None
                    ) -> tuple[Skeleton, list[Channel | None], dict[int, list[Channel | None]]]:
        """A :class:`~qtanimator.core.skeleton.Skeleton` (one rotation order per joint),
        channels in the ``.anim`` layout of :mod:`qtanimator.core.clip` (root translation
        x, y, z, then x, y, z rotation per joint, radians) and, per joint below the root that
        moves, its x, y, z translation channels (None where the file has no channel), that
        pose it like this clip under the position convention ``positions`` (default
        :attr:`positions`).

        The root's position channels become the root translation. A joint below the root
        whose position channels stay still (within :data:`STILL_TOLERANCE` of the size;
        Blender writes them equal to the OFFSET) gets that translation as its offset; one
        that moves gets translation channels (:attr:`Joint.translates`) holding the file's
        numbers, added to its offset. Absolute positions replace the OFFSET on their axes, so
        the offset is 0 there. Raises ValueError for several roots.
        """
        convention = _convention(positions or self.positions)
        roots = [i for i, j in enumerate(self.joints) if j.parent is None]
        if len(roots) != 1:
            raise ValueError(f"a skeleton has one root; this BVH has {len(roots)}")
        joints: list[Joint] = []
        channels: list[Channel | None] = [None] * (3 + 3 * len(self.joints))
        moving: dict[int, list[Channel | None]] = {}
        by_name = self.channels
        values = self.channel_values_radians() if self.frame_count else np.zeros((1, self.channel_count))
        tolerance = STILL_TOLERANCE * self.size()
        for ji, j in enumerate(self.joints):
            offset = j.offset.copy()
            moves = any(c.endswith("position") for c in j.channels)
            translates = False
            if moves and ji != roots[0]:
                trans = self.local_translations(values, ji, convention)
                translates = float(np.abs(trans - trans[0]).max()) > tolerance
                if not translates:
                    offset = trans[0].copy()
            if moves and (ji == roots[0] or translates) and convention == "absolute":
                for c in j.channels:
                    if c.endswith("position"):
                        offset["xyz".index(c[0].lower())] = 0.0
            order = j.rotation_order
            order += "".join(a for a in "xyz" if a not in order)
            joints.append(Joint(j.name, j.parent, offset, rotation_order=order,
                                boxmin=np.zeros(3), boxmax=np.zeros(3), translates=translates))
            for c in j.channels:
                axis = "xyz".index(c[0].lower())
                if c.endswith("position"):
                    if ji == roots[0]:
                        channels[axis] = by_name[f"{j.key}/{c}"]
                    elif translates:
                        moving.setdefault(ji, [None, None, None])[axis] = by_name[f"{j.key}/{c}"]
                else:
                    channels[3 + 3 * ji + axis] = by_name[f"{j.key}/{c}"]
        skeleton = Skeleton(joints, rotation_order="zyx", name=Path(self.path).stem if self.path else "")
        if self.frame_count:
            first = self.values_at(0.0)
            for col, (ji, c) in enumerate(self.channel_layout):
                axis = "xyz".index(c[0].lower())
                if c.endswith("position"):
                    if ji == roots[0]:
                        skeleton.root_translation[axis] = first[col]
                    elif ji in moving:
                        skeleton.joints[ji].translation[axis] = first[col]
                else:
                    skeleton.set_dof(ji, axis, first[col])
        return skeleton, channels, moving

    def summary(self) -> dict[str, Any]:
        roots = [j.name for j in self.joints if j.parent is None]
        orders = sorted({j.rotation_order for j in self.joints if j.rotation_order})
        return {
            "kind": "BVH motion",
            "joints": len(self.joints),
            "end_sites": sum(1 for j in self.joints if j.end_site is not None),
            "roots": roots,
            "channels": self.channel_count,
            "frames": self.frame_count,
            "frame_time": self.frame_time,
            "fps": self.fps,
            "duration": self.duration,
            "rotation_orders": orders,
            "positions": self.positions,
            "warnings": list(self.warnings),
        }


def _convention(name: str) -> str:
    if name not in POSITION_CONVENTIONS:
        raise ValueError(f"unknown BVH position convention {name!r}; expected 'relative' or 'absolute'")
    return name


def detect_positions(clip: BvhClip) -> str:
    """The position convention of a file: ``"absolute"`` or ``"relative"``.

    Both kinds of writer put the root's rest position in its OFFSET; an absolute file's first
    frame repeats it, a relative file's first frame holds a displacement near zero. So the
    file is absolute when the first frame's root position is within half the OFFSET's length
    of the OFFSET: compared on the vertical (y) axis when the OFFSET lifts the root by more
    than 5% of the skeleton's size (the horizontal start of a walk is arbitrary), else on all
    position axes. An OFFSET shorter than 5% of the size (or a root without position
    channels, or no frames) gives ``"relative"``: then the two conventions differ by less.
    """
    root = next((i for i, j in enumerate(clip.joints) if j.parent is None), None)
    if root is None or not clip.frame_count:
        return "relative"
    joint = clip.joints[root]
    cols = [c for c in joint.columns if clip._kinds[c] == 0]
    if not cols:
        return "relative"
    axes = [int(clip._axes[c]) for c in cols]
    offset = joint.offset[axes]
    first = clip.motion[0, cols]
    size = clip.size()
    if 1 in axes and abs(float(joint.offset[1])) > 0.05 * size:
        k = axes.index(1)
        return "absolute" if abs(first[k] - offset[k]) <= 0.5 * abs(offset[k]) else "relative"
    length = float(np.linalg.norm(offset))
    if length <= 0.05 * size:
        return "relative"
    return "absolute" if float(np.linalg.norm(first - offset)) <= 0.5 * length else "relative"


def _column_tables(joints: Sequence[BvhJoint]) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64],
                                                        npt.NDArray[np.int64]]:
    kinds: list[int] = []
    axes: list[int] = []
    owner: list[int] = []
    for ji, j in enumerate(joints):
        for c in j.channels:
            kinds.append(0 if c.endswith("position") else 1)
            axes.append("XYZ".index(c[0]))
            owner.append(ji)
    return (np.array(kinds, dtype=np.int64), np.array(axes, dtype=np.int64),
            np.array(owner, dtype=np.int64))
