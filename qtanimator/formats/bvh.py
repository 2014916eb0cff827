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

The format is split by idea: :mod:`~qtanimator.formats.bvh_clip` (the joints, the motion
table and the pose maths) and :mod:`~qtanimator.formats.bvh_parser` (the reader); every
public name is importable from here.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from qtanimator.formats._tokens import read_bytes
from qtanimator.formats.bvh_clip import CHANNEL_NAMES, POSITION_CONVENTIONS, BvhClip, BvhJoint, detect_positions
from qtanimator.formats.bvh_clip import STILL_TOLERANCE as STILL_TOLERANCE
from qtanimator.formats.bvh_clip import FloatArray as FloatArray
from qtanimator.formats.bvh_parser import MAX_JOINTS as MAX_JOINTS
from qtanimator.formats.bvh_parser import _Parser

__all__ = ["BvhClip", "BvhJoint", "CHANNEL_NAMES", "POSITION_CONVENTIONS", "detect_positions", "load_bvh",
           "parse_bvh", "summarize"]


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
