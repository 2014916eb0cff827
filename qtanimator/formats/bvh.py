"""BVH motion capture: hierarchy and motion.

Conventions (notes/mit6837-and-interchange.md §3), column vectors, angles in the file in
degrees::

    local_j = T(offset_j + position channels of j) · R_c1 · R_c2 · …

where ``R_c1, R_c2, …`` are the joint's rotation channels **in the order the file lists
them** ("Zrotation Yrotation Xrotation" gives Rz·Ry·Rx, so X acts on a vector first). Each
joint has its own order. Position channels translate the joint wherever they appear in the
list (rotation-first roots such as ``Zrotation Xrotation Yrotation Xposition …`` still move
the joint in its parent's frame), as every common BVH reader does. ``world_j =
world_parent · local_j``.

Position conventions. Exporters disagree on what a position channel holds. **Relative**
(the reading above, most mocap converters): the channel is added to the joint's OFFSET.
**Absolute** (Blender's exporter, and what bvhio and Blender's importer assume): the channel
*replaces* the OFFSET on its axis. :func:`detect_positions` picks one per file from the
root's first frame (see there); :attr:`BvhClip.positions` holds it and every pose method
uses it unless told otherwise. With a zero root OFFSET the two agree.

Rows after the declared ``Frames:`` count (an exporter's extra row, QAvimator's appended key
lists) are ignored; :attr:`BvhClip.warnings` names how many. Too few numbers, or a token that
is not a number inside the declared frames, is still an error.

Frame ``i`` plays at ``i · frame_time`` seconds. :attr:`BvhClip.channels` turns the motion
into channels of the channel engine (one key per frame, linear spans, constant
extrapolation); rotation channels hold **radians**, position channels file units, so they
can drive a skeleton's DOFs directly. :attr:`BvhClip.motion` keeps the numbers as written
(degrees).

Every malformed file raises :class:`~qtanimator.formats.FormatError` with its line and column.
"""

from __future__ import annotations

import logging
import math
import os
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.core.channel import Channel, Extrapolation, Interpolation, Key, Tangent
from qtanimator.core.skeleton import Joint, Skeleton, axis_rotations
from qtanimator.formats._tokens import read_bytes
from qtanimator.formats.errors import FormatError

FloatArray = npt.NDArray[np.float64]

__all__ = ["BvhClip", "BvhJoint", "CHANNEL_NAMES", "POSITION_CONVENTIONS", "detect_positions", "load_bvh",
           "parse_bvh", "summarize"]

log = logging.getLogger(__name__)

#: How position channels combine with the OFFSET: added ("relative") or replacing it ("absolute").
POSITION_CONVENTIONS = ("relative", "absolute")
#: Below the root a joint's position channels must stay within this fraction of the
#: skeleton's size of their first frame's value (qtanimator's 3D joints below the root only turn).
STILL_TOLERANCE = 1e-4

#: The six BVH channel names, in their canonical spelling.
CHANNEL_NAMES = ("Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation")
_CANONICAL = {n.lower(): n for n in CHANNEL_NAMES}
_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
_INT = re.compile(r"[+-]?\d+")
_LINE_BREAK = re.compile(r"\r\n|\r|\n")
_TOKEN = re.compile(r"\S+")
#: More joints than any real file has; keeps hostile input from building huge structures.
MAX_JOINTS = 100_000


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


# ===================================================================== parser
@dataclass(frozen=True)
class _Tok:
    text: str
    line: int
    column: int


class _Parser:
    def __init__(self, text: str, path: str | None) -> None:
        self.path = path
        self.toks: list[_Tok] = []
        for ln, line in enumerate(_LINE_BREAK.split(text), start=1):
            for m in _TOKEN.finditer(line):
                self.toks.append(_Tok(m.group(), ln, m.start() + 1))
        self.pos = 0
        self.last_line = self.toks[-1].line if self.toks else 1

    # --------------------------------------------------------------- helpers
    def error(self, message: str, tok: _Tok | None = None) -> FormatError:
        if tok is None:
            return FormatError(message, self.path, self.last_line)
        return FormatError(message, self.path, tok.line, tok.column)

    def peek(self) -> _Tok | None:
        return self.toks[self.pos] if self.pos < len(self.toks) else None

    def next(self, what: str) -> _Tok:
        tok = self.peek()
        if tok is None:
            raise self.error(f"the file ends where {what} was expected.")
        self.pos += 1
        return tok

    def expect(self, word: str, what: str | None = None) -> _Tok:
        tok = self.next(f"'{word}'")
        if tok.text.upper() != word.upper():
            raise self.error(f"expected '{word}'{' ' + what if what else ''}, found '{_show(tok.text)}'.", tok)
        return tok

    def number(self, what: str) -> float:
        tok = self.next(what)
        return self.to_float(tok, what)

    def to_float(self, tok: _Tok, what: str) -> float:
        if not _NUMBER.fullmatch(tok.text):
            raise self.error(f"expected {what}, found '{_show(tok.text)}'.", tok)
        value = float(tok.text)
        if not math.isfinite(value):
            raise self.error(f"{what} is too large: '{_show(tok.text)}'.", tok)
        return value

    def integer(self, what: str) -> tuple[int, _Tok]:
        tok = self.next(what)
        if not _INT.fullmatch(tok.text):
            raise self.error(f"expected {what} (a whole number), found '{_show(tok.text)}'.", tok)
        if len(tok.text.lstrip("+-")) > 15:  # beyond any real count (and int() refuses > 4300 digits)
            raise self.error(f"{what} is too large: '{_show(tok.text)}'.", tok)
        return int(tok.text), tok

    def rest_of_line(self, line: int) -> list[_Tok]:
        out = []
        while (tok := self.peek()) is not None and tok.line == line and tok.text != "{":
            out.append(tok)
            self.pos += 1
        return out

    # ------------------------------------------------------------- hierarchy
    def parse(self) -> BvhClip:
        first = self.peek()
        if first is None:
            raise self.error("the file is empty; a BVH file starts with 'HIERARCHY'.")
        self.expect("HIERARCHY", "at the start of a BVH file")
        joints: list[dict[str, Any]] = []
        tok = self.peek()
        if tok is None or tok.text.upper() != "ROOT":
            raise self.error("expected 'ROOT' after 'HIERARCHY'." if tok is None else
                             f"expected 'ROOT' after 'HIERARCHY', found '{_show(tok.text)}'.", tok)
        while (tok := self.peek()) is not None and tok.text.upper() == "ROOT":
            self.pos += 1
            self.parse_joint(tok, None, joints)
        self.expect("MOTION", "after the hierarchy")
        frames, ftok = self.frames_header()
        frame_time = self.frame_time_header()
        built = self.build_joints(joints)
        ncols = sum(len(j.channels) for j in built)
        motion, warnings = self.motion(frames, ncols, ftok)
        for w in warnings:
            log.warning("%s: %s", os.path.basename(self.path) if self.path else "BVH", w)
        return BvhClip(built, frame_time, motion, self.path, warnings)

    def parse_joint(self, head: _Tok, parent: int | None, joints: list[dict[str, Any]]) -> None:
        """Parse ``ROOT|JOINT name { … }`` iteratively (no recursion limit on depth)."""
        stack: list[tuple[int, _Tok]] = []  # (joint index, its opening token)
        self.open_joint(head, parent, joints, stack)
        while stack:
            index, opening = stack[-1]
            tok = self.peek()
            if tok is None:
                raise self.error(f"joint '{joints[index]['name']}' (line {opening.line}) is not closed with '}}'.")
            word = tok.text.upper()
            self.pos += 1
            rec = joints[index]
            if word == "}":
                if rec["offset"] is None:
                    raise self.error(f"joint '{rec['name']}' has no OFFSET.", opening)
                stack.pop()
            elif word == "OFFSET":
                if rec["offset"] is not None:
                    raise self.error(f"joint '{rec['name']}' has a second OFFSET.", tok)
                rec["offset"] = self.vector("OFFSET")
            elif word == "CHANNELS":
                if rec["channels"] is not None:
                    raise self.error(f"joint '{rec['name']}' has a second CHANNELS line.", tok)
                rec["channels"] = self.channel_list()
            elif word == "JOINT":
                self.open_joint(tok, index, joints, stack)
            elif word == "END":
                if rec["end_site"] is not None:
                    raise self.error(f"joint '{rec['name']}' has a second End Site.", tok)
                self.rest_of_line(tok.line)  # "Site" (and anything else on the line)
                self.expect("{", "to open the End Site")
                self.expect("OFFSET", "in the End Site")
                rec["end_site"] = self.vector("the End Site OFFSET")
                self.expect("}", "to close the End Site")
            else:
                raise self.error(f"expected OFFSET, CHANNELS, JOINT, End Site or '}}' in joint "
                                 f"'{rec['name']}', found '{_show(tok.text)}'.", tok)

    def open_joint(self, head: _Tok, parent: int | None, joints: list[dict[str, Any]],
                   stack: list[tuple[int, _Tok]]) -> None:
        name_toks = self.rest_of_line(head.line)
        if not name_toks:
            raise self.error(f"{head.text.upper()} needs a name.", head)
        if len(joints) >= MAX_JOINTS:
            raise self.error(f"more than {MAX_JOINTS} joints.", head)
        opening = self.expect("{", "after the joint name")
        joints.append({"name": " ".join(t.text for t in name_toks), "parent": parent, "offset": None,
                       "channels": None, "end_site": None, "line": head.line})
        stack.append((len(joints) - 1, opening))

    def vector(self, what: str) -> FloatArray:
        return np.array([self.number(f"a number in {what}") for _ in range(3)], dtype=np.float64)

    def channel_list(self) -> tuple[str, ...]:
        count, tok = self.integer("the channel count after CHANNELS")
        if not 0 <= count <= 6:
            raise self.error(f"a joint has 0 to 6 channels, not {count}.", tok)
        names: list[str] = []
        for _ in range(count):
            t = self.next("a channel name")
            name = _CANONICAL.get(t.text.lower())
            if name is None:
                raise self.error(f"unknown channel '{_show(t.text)}'; expected one of "
                                 f"{', '.join(CHANNEL_NAMES)}.", t)
            if name in names:
                raise self.error(f"channel '{name}' is listed twice.", t)
            names.append(name)
        return tuple(names)

    def build_joints(self, recs: list[dict[str, Any]]) -> list[BvhJoint]:
        seen: dict[str, int] = {}
        out: list[BvhJoint] = []
        column = 0
        for r in recs:
            name = r["name"]
            n = seen.get(name, 0)
            seen[name] = n + 1
            key = name if n == 0 else f"{name}.{n}"
            while key in seen and key != name:
                n += 1
                key = f"{name}.{n}"
            seen.setdefault(key, 1)
            channels = r["channels"] or ()
            out.append(BvhJoint(name, key, r["parent"], r["offset"], channels, column, r["end_site"], r["line"]))
            column += len(channels)
        return out

    # ---------------------------------------------------------------- motion
    def frames_header(self) -> tuple[int, _Tok]:
        tok = self.next("'Frames:'")
        if tok.text.upper() == "FRAMES":
            self.expect(":", "after 'Frames'")
        elif tok.text.upper() != "FRAMES:":
            raise self.error(f"expected 'Frames:' after MOTION, found '{_show(tok.text)}'.", tok)
        frames, ftok = self.integer("the number of frames")
        if frames < 0:
            raise self.error("the number of frames cannot be negative.", ftok)
        return frames, ftok

    def frame_time_header(self) -> float:
        self.expect("Frame", "(the 'Frame Time:' line)")
        tok = self.next("'Time:'")
        if tok.text.upper() == "TIME":
            self.expect(":", "after 'Frame Time'")
        elif tok.text.upper() != "TIME:":
            raise self.error(f"expected 'Frame Time:', found 'Frame {_show(tok.text)}'.", tok)
        ttok = self.next("the frame time")
        value = self.to_float(ttok, "the frame time in seconds")
        if not value > 0.0:
            raise self.error(f"the frame time must be positive, found {ttok.text}.", ttok)
        return value

    def motion(self, frames: int, ncols: int, ftok: _Tok) -> tuple[FloatArray, list[str]]:
        """The declared frames and the warnings (rows after them, which are ignored)."""
        rest = self.toks[self.pos:]
        expected = frames * ncols
        warnings: list[str] = []
        if len(rest) < expected:
            got = len(rest)
            row, col = divmod(got, ncols) if ncols else (0, 0)
            raise self.error(f"the motion data ends early: {frames} frames × {ncols} channels need "
                             f"{expected} numbers, found {got} (frame {row + 1} is missing value "
                             f"{col + 1}).")
        if len(rest) > expected:
            # Extra rows: the declared frames must then be whole rows, one per line, so that a
            # short row is never filled from the next one.
            lines: list[list[_Tok]] = []
            for t in rest:
                if lines and lines[-1][0].line == t.line:
                    lines[-1].append(t)
                else:
                    lines.append([t])
            for i, row_toks in enumerate(lines[:frames]):
                if len(row_toks) != ncols:
                    raise self.error(f"frame {i + 1} has {len(row_toks)} numbers, but the hierarchy has "
                                     f"{ncols} channels.", row_toks[min(len(row_toks), ncols) - 1])
            extra = len(lines) - frames
            warnings.append(f"{extra} row{'s' if extra != 1 else ''} after the declared {frames} frame"
                            f"{'s' if frames != 1 else ''} {'were' if extra != 1 else 'was'} ignored.")
            rest = rest[:expected]
        for t in rest:
            if not _NUMBER.fullmatch(t.text):
                raise self.error(f"expected a number in the motion data, found '{_show(t.text)}'.", t)
        values = np.array([t.text for t in rest], dtype=np.float64).reshape(frames, ncols)
        if not np.isfinite(values).all():
            bad = rest[int(np.flatnonzero(~np.isfinite(values.reshape(-1)))[0])]
            raise self.error(f"motion value '{_show(bad.text)}' is too large.", bad)
        return values, warnings


def _show(text: str, limit: int = 40) -> str:
    text = text.encode("unicode_escape").decode("ascii")
    return text if len(text) <= limit else text[:limit] + "…"


def _decode(data: bytes) -> str:
    if data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return data.decode("latin-1")


def parse_bvh(text: str, path: str | os.PathLike[str] | None = None) -> BvhClip:
    """Parse BVH text. Raises :class:`FormatError` for anything malformed."""
    return _Parser(text, os.fspath(path) if path is not None else None).parse()


def load_bvh(path: str | os.PathLike[str]) -> BvhClip:
    """Read a ``.bvh`` file. Raises :class:`FormatError` (never anything else) on bad input."""
    return parse_bvh(_decode(read_bytes(path)), path)


def summarize(path: Path) -> dict[str, Any]:
    clip = load_bvh(path)
    out: dict[str, Any] = {"file": str(path)}
    out.update(clip.summary())
    return out
