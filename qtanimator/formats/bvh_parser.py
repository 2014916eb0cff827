"""The BVH reader: text to tokens with their line and column, and the parser that turns
them into a :class:`~qtanimator.formats.bvh_clip.BvhClip` or a
:class:`~qtanimator.formats.FormatError` naming where the file goes wrong.
"""

from __future__ import annotations

import logging
import math
import os
import re
from dataclasses import dataclass
from typing import Any

import numpy as np

from qtanimator.core.keys import KEY_TIME_TOLERANCE, MAX_KEY_TIME, MAX_KEY_VALUE
from qtanimator.formats.bvh_clip import CHANNEL_NAMES, BvhClip, BvhJoint, FloatArray
from qtanimator.formats.errors import FormatError

# The reader's messages keep the logger name of the format module.
log = logging.getLogger("qtanimator.formats.bvh")

_CANONICAL = {n.lower(): n for n in CHANNEL_NAMES}
_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
_INT = re.compile(r"[+-]?\d+")
_LINE_BREAK = re.compile(r"\r\n|\r|\n")
_TOKEN = re.compile(r"\S+")
#: More joints than any real file has; keeps hostile input from building huge structures.
MAX_JOINTS = 100_000


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
        if len(motion) * frame_time > MAX_KEY_TIME:  # the rows read: a declared count may lie
            raise self.error(f"{len(motion)} frames of {frame_time:g} s last beyond qtanimator's limit of "
                             f"{MAX_KEY_TIME:g} seconds.", ftok)
        if motion.size and not float(np.max(np.abs(motion))) <= MAX_KEY_VALUE:
            raise self.error(f"the motion holds a value beyond qtanimator's limit of ±{MAX_KEY_VALUE:g}.", ftok)
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
        if not KEY_TIME_TOLERANCE <= value <= MAX_KEY_TIME:  # keys a channel can hold (issue 31)
            raise self.error(f"the frame time must lie within {KEY_TIME_TOLERANCE:g} and {MAX_KEY_TIME:g} seconds, "
                             f"found {ttok.text}.", ttok)
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
