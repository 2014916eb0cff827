"""MIT 6.837 ``.attach`` files: per-vertex joint weights, the root column left out.

Each vertex has ``num_joints − 1`` weights; column c is joint c + 1 and the root's weight
is 0. Like the reference, line structure is ignored: the file is one whitespace stream
reshaped to (vertices, joints − 1), so CRLF, trailing spaces and a missing final newline
are harmless. Weights are **not** renormalised (the reference does not).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.formats._tokens import read_text, show, split_lines
from qtanimator.formats.errors import FormatError

__all__ = ["load_attach", "parse_attach", "summarize"]


def load_attach(path: str | os.PathLike[str], num_vertices: int, num_joints: int) -> npt.NDArray[np.float64]:
    """(num_vertices, num_joints) weights with column 0 (the root) all zero."""
    return parse_attach(read_text(path), num_vertices, num_joints, path)


def parse_attach(text: str, num_vertices: int, num_joints: int,
                 path: str | os.PathLike[str] | None = None) -> npt.NDArray[np.float64]:
    if num_joints < 1 or num_vertices < 0:
        raise ValueError("an attachment needs at least one joint and a vertex count")
    cols = num_joints - 1
    words = text.lstrip("\ufeff").split()
    expected = num_vertices * cols
    if len(words) != expected:
        lines = [ln for ln in split_lines(text) if ln.strip()]
        per_line = {len(ln.split()) for ln in lines}
        hint = ""
        if len(per_line) == 1 and lines:
            hint = f" (the file has {len(lines)} lines of {per_line.pop()} weights)"
        raise FormatError(f"expected {num_vertices} vertices × {cols} weights = {expected} numbers for a "
                          f"{num_joints}-joint skeleton, found {len(words)}{hint}.", path)
    try:
        values = np.array(words, dtype=np.float64)
    except ValueError:
        for i, w in enumerate(words):
            try:
                float(w)
            except ValueError:
                raise FormatError(f"expected a weight, found '{show(w)}'.", path,
                                  _line_of_token(text, i)) from None
        raise  # pragma: no cover
    finite = np.isfinite(values)
    if not finite.all():
        i = int(np.argmin(finite))
        raise FormatError(f"weights must be finite numbers, found '{show(words[i])}'.", path, _line_of_token(text, i))
    out = np.zeros((num_vertices, num_joints))
    out[:, 1:] = values.reshape(num_vertices, cols)
    return out


def _line_of_token(text: str, index: int) -> int:
    seen = 0
    for number, line in enumerate(split_lines(text), start=1):
        seen += len(line.split())
        if seen > index:
            return number
    return max(1, number)


def summarize(path: str | os.PathLike[str]) -> dict[str, Any]:
    text = read_text(path)
    numbered = [(n, ln.split()) for n, ln in enumerate(split_lines(text), start=1) if ln.strip()]
    if not numbered:
        raise FormatError("the file holds no weights; an .attach file has one line of weights per vertex.",
                          path, 1)
    lines = [words for _, words in numbered]
    widths = sorted({len(ln) for ln in lines})
    if len(widths) != 1:
        first = len(lines[0])
        number, words = next((n, w) for n, w in numbered if len(w) != first)
        raise FormatError(f"this line has {len(words)} weights but the first has {first}; every vertex "
                          "needs one weight per joint after the root.", path, number)
    weights = parse_attach(text, len(lines), widths[0] + 1, path)
    nonzero = (weights != 0).sum(axis=1)
    sums = weights.sum(axis=1)
    return {
        "file": str(Path(path)),
        "kind": "attachment weights",
        "vertices": len(lines),
        "joints": widths[0] + 1,
        "max_influences": int(nonzero.max()) if len(lines) else 0,
        "mean_influences": float(nonzero.mean()) if len(lines) else 0.0,
        "weight_sum_range": [float(sums.min()), float(sums.max())] if len(lines) else None,
    }
