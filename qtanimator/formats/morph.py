"""CSE 169 ``.morph`` targets (sparse, absolute).

``positions N { index x y z ... }`` then ``normals N { index nx ny nz ... }``. Values are
the target's absolute positions and normals for the listed vertices; unlisted vertices
keep their base values. Blend as ``base + w·(target − base)``.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.formats._tokens import Tokens, read_text, show
from qtanimator.formats.errors import FormatError

__all__ = ["MorphTarget", "load_morph", "parse_morph", "apply_morphs", "summarize"]

FloatArray = npt.NDArray[np.float64]


@dataclass(eq=False)
class MorphTarget:
    """Sparse target: ``indices`` (N,), ``positions`` (N, 3), ``normals`` (M, 3) at ``normal_indices``."""

    indices: npt.NDArray[np.int64]
    positions: FloatArray
    normal_indices: npt.NDArray[np.int64]
    normals: FloatArray
    name: str = ""

    def check(self, num_vertices: int) -> None:
        """Raise ValueError if an index does not fit a mesh of ``num_vertices``."""
        for idx in (self.indices, self.normal_indices):
            if len(idx) and (idx.min() < 0 or idx.max() >= num_vertices):
                raise ValueError(f"the morph target refers to vertex {int(idx.max())}, "
                                 f"but the mesh has {num_vertices}")


def load_morph(path: str | os.PathLike[str]) -> MorphTarget:
    return parse_morph(read_text(path), path)


def parse_morph(text: str, path: str | os.PathLike[str] | None = None) -> MorphTarget:
    tk = Tokens(text, path)
    if tk.at_end():
        raise FormatError("the file is empty; a morph target starts with 'positions N {'.", path, 1)
    blocks: dict[str, tuple[npt.NDArray[np.int64], FloatArray]] = {}
    while not tk.at_end():
        word = tk.next("'positions' or 'normals'")
        if word not in ("positions", "normals"):
            tk.error(f"unknown section '{show(word)}' (expected 'positions' or 'normals').", tk.pos - 1)
        if word in blocks:
            tk.error(f"the '{word}' section appears twice.", tk.pos - 1)
        n = tk.count(f"the {word} count", 4)
        tk.expect("{", f"after '{word} {n}'")
        start = tk.pos
        data = tk.numbers(4 * n, f"the {word} block").reshape(n, 4)
        idx = data[:, 0]
        bad = np.nonzero((idx != np.round(idx)) | (idx < 0))[0]
        if len(bad):
            tk.error(f"a vertex index must be a whole number ≥ 0, found {idx[bad[0]]!r}.", start + 4 * int(bad[0]))
        ints = idx.astype(np.int64)
        dup = np.nonzero(np.diff(np.sort(ints)) == 0)[0]
        if len(dup):
            tk.error(f"vertex {int(np.sort(ints)[dup[0]])} is listed twice in the {word} block.", start)
        tk.expect("}", f"to close the {word} block (is the count {n} right?)")
        blocks[word] = (ints, data[:, 1:].copy())
    if "positions" not in blocks:
        tk.error("the morph target has no 'positions' section.")
    pi, pv = blocks["positions"]
    ni, nv = blocks.get("normals", (np.zeros(0, np.int64), np.zeros((0, 3))))
    return MorphTarget(pi, pv, ni, nv, Path(path).stem if path is not None else "")


def apply_morphs(base_positions: npt.ArrayLike, base_normals: npt.ArrayLike | None,
                 targets: list[tuple[MorphTarget, float]]) -> tuple[FloatArray, FloatArray | None]:
    """``base + Σ w·(target − base)`` for positions and (renormalised) normals."""
    p = np.array(base_positions, dtype=np.float64)
    base_p = p.copy()
    n = None if base_normals is None else np.array(base_normals, dtype=np.float64)
    base_n = None if n is None else n.copy()
    for target, w in targets:
        target.check(len(p))
        p[target.indices] += w * (target.positions - base_p[target.indices])
        if n is not None and base_n is not None and len(target.normal_indices):
            n[target.normal_indices] += w * (target.normals - base_n[target.normal_indices])
    if n is not None:
        length = np.linalg.norm(n, axis=1)
        n /= np.where(length > 0, length, 1.0)[:, None]
    return p, n


def summarize(path: str | os.PathLike[str]) -> dict[str, Any]:
    m = load_morph(path)
    return {
        "file": str(Path(path)),
        "kind": "morph target",
        "positions": len(m.indices),
        "normals": len(m.normal_indices),
        "vertex_range": [int(m.indices.min()), int(m.indices.max())] if len(m.indices) else None,
    }
