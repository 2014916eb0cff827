"""A whitespace token stream with line numbers, shared by the CSE 169 readers.

Line structure carries no meaning in these formats, but error messages need a line: any
token can tell the line it came from. Line breaks are LF, CRLF or bare CR (so
``\\r\\r\\n`` counts as two breaks, as text editors show it). ``{`` and ``}`` are split
off as tokens of their own (``channel 14{``). ``#`` and ``//`` start comments that run
to the end of the line.

Tokenizing is linear and runs in C: comments go in one regular-expression pass, braces are
padded with ``str.replace`` and the text is split with ``str.split`` in blocks (so a file
with more than ``MAX_TOKENS`` tokens is refused before they all exist). Line numbers are
found only when a message needs one, by scanning the block that holds the token.
"""

from __future__ import annotations

import bisect
import math
import os
import re
import stat
from pathlib import Path
from typing import NoReturn

import numpy as np
import numpy.typing as npt

from qtanimator.formats import limits
from qtanimator.formats.errors import FormatError

_LINE_BREAK = re.compile(r"\r\n|\r|\n")
#: A comment to the end of its line (the line break stays, so line numbers do not move).
_COMMENT_TO_EOL = re.compile(r"(?:#|//)[^\r\n]*")
#: White space as ``str.split`` sees it (both use Py_UNICODE_ISSPACE), and a token.
_SPACE = re.compile(r"\s")
_TOKEN = re.compile(r"\S+")
_isfinite = math.isfinite
#: Characters per block of ``str.split``: the unit of the token limit and of a line lookup.
_BLOCK = 1 << 18

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
        try:
            return raw.decode("utf-8")
        except UnicodeDecodeError:
            return raw.decode("latin-1")  # decodes any byte
    except MemoryError:
        del raw
        raise FormatError("the file is too large to read: memory ran out.", p) from None


def split_lines(text: str) -> list[str]:
    if text.startswith("\ufeff"):
        text = text[1:]
    return _LINE_BREAK.split(text)


class Tokens:
    """Tokens of a text, a read cursor, and the 1-based line of any token on demand."""

    def __init__(self, text: str, path: str | os.PathLike[str] | None, braces: bool = True,
                 comments: bool = True) -> None:
        self.path = os.fspath(path) if path is not None else None
        if text.startswith("\ufeff"):
            text = text[1:]
        if comments and ("#" in text or "//" in text):
            text = _COMMENT_TO_EOL.sub(" ", text)  # not "": "\r#…\n" must stay two line breaks
        if braces and ("{" in text or "}" in text):
            text = text.replace("{", " { ").replace("}", " } ")
        # Comments end before their line break and padding adds only spaces, so lines in
        # ``text`` are the lines of the file.
        self._text = text
        self._blocks: list[int] = []  # index of each block's first token
        self._starts: list[int] = []  # offset in ``_text`` where each block starts
        self.toks: list[str] = []
        self._block_lines: dict[int, list[int]] = {}  # block → line of each of its tokens
        self._block_first_line: list[int] = [1]  # line where each block starts (filled in order)
        self._split()
        self.last_line = 1 + _breaks(text, len(text))
        self.pos = 0

    def _split(self) -> None:
        text, toks = self._text, self.toks
        n, start = len(text), 0
        while start < n:
            end = n
            if start + _BLOCK < n:
                m = _SPACE.search(text, start + _BLOCK)  # a block ends on white space: no token is cut
                if m is not None:
                    end = m.start()
            self._blocks.append(len(toks))
            self._starts.append(start)
            try:
                toks.extend(text[start:end].split())
            except MemoryError:
                count = len(toks)
                toks.clear()  # give the memory back before anything else is allocated
                raise FormatError(f"the file is too large to read: memory ran out after {count:,} words and "
                                  "numbers.", self.path) from None
            if len(toks) > limits.MAX_TOKENS:
                err = limits.exceeded(f"the number of words and numbers ({len(toks):,}+)",
                                      f"{limits.MAX_TOKENS:,} (MAX_TOKENS)", self.path)
                raise FormatError(err.message, self.path, self._line_of(limits.MAX_TOKENS))
            start = end

    def _line_of(self, index: int) -> int:
        """The line of token ``index`` (which exists). The first question about a block
        finds the lines of all its tokens at once (one pass over the block), so a reader
        that asks for every row's line stays linear in the file's size."""
        b = bisect.bisect_right(self._blocks, index) - 1
        lines = self._block_lines.get(b)
        if lines is None:
            lines = self._lines_of_block(b)
            self._block_lines[b] = lines
        return lines[index - self._blocks[b]]

    def _lines_of_block(self, b: int) -> list[int]:
        text, starts = self._text, self._starts
        while len(self._block_first_line) <= b:  # lines where the blocks start, in order
            k = len(self._block_first_line)
            self._block_first_line.append(self._block_first_line[k - 1] + _breaks(text, starts[k], starts[k - 1]))
        start = starts[b]
        end = starts[b + 1] if b + 1 < len(starts) else len(text)
        offsets = np.fromiter((m.start() for m in _TOKEN.finditer(text, start, end)), dtype=np.int64)
        breaks = np.fromiter((m.end() for m in _LINE_BREAK.finditer(text, start, end)), dtype=np.int64)
        # A CRLF split by the block's start counts once: _breaks above counted its CR.
        if 0 < start < len(text) and text[start - 1] == "\r" and text[start] == "\n" and len(breaks):
            breaks = breaks[1:]
        first = self._block_first_line[b]
        return (first + np.searchsorted(breaks, offsets, side="right")).tolist()

    @property
    def lines(self) -> list[int]:
        """The line of every token (slow: for tests and debugging; readers use :meth:`line`)."""
        out: list[int] = []
        text, line, last = self._text, 1, 0
        for m in _TOKEN.finditer(text):
            line += _breaks(text, m.start(), last)
            last = m.start()
            out.append(line)
        return out

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
        if i < len(self.toks):
            return self._line_of(i)
        return self._line_of(len(self.toks) - 1) if self.toks else 1

    def error(self, message: str, index: int | None = None) -> NoReturn:
        raise FormatError(message, self.path, self.line(index))

    # peek, next and number run once per token: they index first and handle the end rarely.
    def peek(self) -> str | None:
        try:
            return self.toks[self.pos]
        except IndexError:
            return None

    def next(self, what: str) -> str:
        pos = self.pos
        try:
            tok = self.toks[pos]
        except IndexError:
            raise FormatError(f"the file ends where {what} was expected; it may be truncated.",
                              self.path, self.line()) from None
        self.pos = pos + 1
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
        pos = self.pos
        try:
            tok = self.toks[pos]
        except IndexError:
            raise FormatError(f"the file ends where {what} was expected; it may be truncated.",
                              self.path, self.line()) from None
        self.pos = pos + 1
        try:
            v = float(tok)
        except ValueError:
            self.error(f"expected a number for {what}, found '{show(tok)}'.", self.pos - 1)
        if not _isfinite(v):
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


def _breaks(text: str, end: int, start: int = 0) -> int:
    """Line breaks (LF, CRLF or CR) in ``text[start:end]``, counted in C."""
    n = text.count("\n", start, end) + text.count("\r", start, end) - text.count("\r\n", start, end)
    if 0 < start < end and text[start - 1] == "\r" and text[start] == "\n":
        n -= 1  # the LF of a CRLF that started before ``start`` was counted as a break of its own
    return n


def show(tok: str, limit: int = 40) -> str:
    """A token as it may appear in a message (shortened, no control characters)."""
    clean = "".join(c if c.isprintable() else "?" for c in tok)
    return clean if len(clean) <= limit else clean[: limit - 1] + "…"
