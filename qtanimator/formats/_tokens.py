"""A whitespace token stream with line numbers, shared by the CSE 169 readers.

Line structure carries no meaning in these formats, but error messages need a line:
every token remembers the line it came from. Line breaks are LF, CRLF or bare CR (so
``\\r\\r\\n`` counts as two breaks, as text editors show it). ``{`` and ``}`` are split
off as tokens of their own (``channel 14{``). ``#`` and ``//`` start comments that run
to the end of the line.
"""

from __future__ import annotations

import math
import os
import re
import stat
from pathlib import Path
from typing import NoReturn

import numpy as np
import numpy.typing as npt

from qtanimator.formats.errors import FormatError

_LINE_BREAK = re.compile(r"\r\n|\r|\n")
_BRACES = re.compile(r"([{}])")
_COMMENT = re.compile(r"#|//")

#: Largest file the readers accept (a guard against reading something that is not a model).
MAX_BYTES = 512 * 1024 * 1024


def read_bytes(path: str | os.PathLike[str], max_bytes: int = MAX_BYTES) -> bytes:
    """The bytes of a regular file; FormatError for folders, devices, pipes, unreadable or huge files.

    Reading ``/dev/zero`` or a named pipe would never end, so only regular files are read,
    and never more than ``max_bytes``.
    """
    p = Path(path)
    try:
        mode = p.stat().st_mode
        if stat.S_ISDIR(mode):
            raise FormatError("cannot read the file: it is a folder.", p)
        if not stat.S_ISREG(mode):
            raise FormatError("cannot read the file: it is a device or a pipe, not a regular file.", p)
        if p.stat().st_size > max_bytes:
            raise FormatError("the file is too large to be a model or animation file.", p)
        with p.open("rb") as fh:
            raw = fh.read(max_bytes + 1)
    except FormatError:
        raise
    except (OSError, ValueError) as exc:  # ValueError: a NUL byte in the path
        raise FormatError(f"cannot read the file ({getattr(exc, 'strerror', None) or exc}).", p) from exc
    if len(raw) > max_bytes:
        raise FormatError("the file is too large to be a model or animation file.", p)
    return raw


def read_text(path: str | os.PathLike[str]) -> str:
    """The file's text, or FormatError for unreadable, binary or non-UTF-8 files."""
    p = Path(path)
    raw = read_bytes(p)
    if b"\0" in raw:
        raise FormatError("the file contains binary data, not text.", p)
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError:
        try:
            return raw.decode("latin-1")
        except UnicodeDecodeError as exc:  # pragma: no cover - latin-1 decodes any byte
            raise FormatError("the file is not text.", p) from exc


def split_lines(text: str) -> list[str]:
    if text.startswith("\ufeff"):
        text = text[1:]
    return _LINE_BREAK.split(text)


class Tokens:
    """Tokens of a text with their 1-based line numbers and a read cursor."""

    def __init__(self, text: str, path: str | os.PathLike[str] | None, braces: bool = True,
                 comments: bool = True) -> None:
        self.path = os.fspath(path) if path is not None else None
        toks: list[str] = []
        lines: list[int] = []
        for number, line in enumerate(split_lines(text), start=1):
            if comments and ("#" in line or "//" in line):
                m = _COMMENT.search(line)
                if m is not None:
                    line = line[: m.start()]
            if braces and ("{" in line or "}" in line):
                line = _BRACES.sub(r" \1 ", line)
            parts = line.split()
            if parts:
                toks.extend(parts)
                lines.extend([number] * len(parts))
        self.toks = toks
        self.lines = lines
        self.last_line = max(1, len(split_lines(text)))
        self.pos = 0

    # ----------------------------------------------------------------- cursor
    def __len__(self) -> int:
        return len(self.toks)

    @property
    def remaining(self) -> int:
        return len(self.toks) - self.pos

    def at_end(self) -> bool:
        return self.pos >= len(self.toks)

    def line(self, index: int | None = None) -> int:
        i = self.pos if index is None else index
        if i < len(self.lines):
            return self.lines[i]
        return self.lines[-1] if self.lines else 1

    def error(self, message: str, index: int | None = None) -> NoReturn:
        raise FormatError(message, self.path, self.line(index))

    def peek(self) -> str | None:
        return self.toks[self.pos] if self.pos < len(self.toks) else None

    def next(self, what: str) -> str:
        if self.pos >= len(self.toks):
            raise FormatError(f"the file ends where {what} was expected; it may be truncated.",
                              self.path, self.line())
        tok = self.toks[self.pos]
        self.pos += 1
        return tok

    def expect(self, word: str, context: str = "") -> None:
        where = f" {context}" if context else ""
        if self.pos >= len(self.toks):
            raise FormatError(f"the file ends where '{word}' was expected{where}; it may be truncated.",
                              self.path, self.line())
        tok = self.toks[self.pos]
        if tok != word:
            self.error(f"expected '{word}'{where}, found '{show(tok)}'.")
        self.pos += 1

    def accept(self, word: str) -> bool:
        if self.pos < len(self.toks) and self.toks[self.pos] == word:
            self.pos += 1
            return True
        return False

    # ---------------------------------------------------------------- numbers
    def number(self, what: str) -> float:
        tok = self.next(what)
        try:
            v = float(tok)
        except ValueError:
            self.error(f"expected a number for {what}, found '{show(tok)}'.", self.pos - 1)
        if not math.isfinite(v):
            self.error(f"{what} must be a finite number, found '{show(tok)}'.", self.pos - 1)
        return v

    def integer(self, what: str, lo: int | None = None, hi: int | None = None) -> int:
        tok = self.next(what)
        try:
            v = int(tok)
        except ValueError:
            try:
                f = float(tok)
            except ValueError:
                f = math.nan
            if not (math.isfinite(f) and f == int(f) and abs(f) < 2**53):
                self.error(f"expected a whole number for {what}, found '{show(tok)}'.", self.pos - 1)
            v = int(f)
        if abs(v) >= 2**53:  # no count or index is this large; numpy could not hold it either
            self.error(f"{what} is out of range, found '{show(tok)}'.", self.pos - 1)
        if lo is not None and v < lo:
            self.error(f"{what} must be at least {lo}, found {v}.", self.pos - 1)
        if hi is not None and v > hi:
            self.error(f"{what} must be at most {hi}, found {v}.", self.pos - 1)
        return v

    def count(self, what: str, per_item: int) -> int:
        """A non-negative count of items of ``per_item`` tokens that must fit in the file."""
        n = self.integer(what, lo=0)
        if per_item > 0 and n > self.remaining // per_item:
            self.error(f"{what} says {n}, but the file is too short for that many; it may be truncated.",
                       self.pos - 1)
        return n

    def numbers(self, n: int, what: str) -> npt.NDArray[np.float64]:
        """The next ``n`` tokens as a float64 array (fast path for big blocks)."""
        if n > self.remaining:
            raise FormatError(f"the file ends inside {what}; it may be truncated.", self.path,
                              self.line(len(self.toks)))
        start = self.pos
        chunk = self.toks[start:start + n]
        try:
            arr = np.array(chunk, dtype=np.float64)
        except ValueError:
            for i, tok in enumerate(chunk):
                if tok == "}":
                    self.error(f"{what} ends early: '}}' after {i} numbers where {n} were expected "
                               "(is the count right?).", start + i)
                try:
                    float(tok)
                except ValueError:
                    self.error(f"expected a number in {what}, found '{show(tok)}'.", start + i)
            raise  # pragma: no cover - numpy and float() agree on what a number is
        if not np.all(np.isfinite(arr)):
            bad = int(np.argmin(np.isfinite(arr)))
            self.error(f"{what} must hold finite numbers, found '{show(chunk[bad])}'.", start + bad)
        self.pos += n
        return arr

    def integers(self, n: int, what: str) -> npt.NDArray[np.int64]:
        """The next ``n`` tokens as whole numbers."""
        start = self.pos
        arr = self.numbers(n, what)
        bad = np.nonzero((arr != np.round(arr)) | (np.abs(arr) > 2**53))[0]
        if len(bad):
            i = int(bad[0])
            self.error(f"expected a whole number in {what}, found '{show(self.toks[start + i])}'.", start + i)
        return arr.astype(np.int64)


def show(tok: str, limit: int = 40) -> str:
    """A token as it may appear in a message (shortened, no control characters)."""
    clean = "".join(c if c.isprintable() else "?" for c in tok)
    return clean if len(clean) <= limit else clean[: limit - 1] + "…"
