"""Wavefront ``.obj`` meshes (the subset a skinned character needs).

``v x y z [w]`` positions, ``f`` faces with 1-based (or negative, relative) indices in any
of the forms ``i``, ``i/t``, ``i//n``, ``i/t/n``; polygons are fan-triangulated. ``vn``
and ``vt`` are read when present; every other statement (``o``, ``g``, ``s``, ``usemtl``,
``mtllib``, ``l``, ``p``…) and ``#`` comments are ignored. Lines ending in ``\\`` continue.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.formats._tokens import read_text, show, split_lines
from qtanimator.formats.errors import FormatError

__all__ = ["Mesh", "load_obj", "parse_obj", "summarize"]

FloatArray = npt.NDArray[np.float64]


@dataclass(eq=False)
class Mesh:
    """Positions (V, 3), triangles (T, 3) of 0-based indices, optional normals / texcoords.

    ``normals`` and ``texcoords`` are per-file lists; ``triangle_normals`` and
    ``triangle_texcoords`` (T, 3) index them when the faces referenced them (else None).
    """

    positions: FloatArray
    triangles: npt.NDArray[np.int64]
    normals: FloatArray | None = None
    texcoords: FloatArray | None = None
    triangle_normals: npt.NDArray[np.int64] | None = None
    triangle_texcoords: npt.NDArray[np.int64] | None = None
    polygons: int = 0
    extras: dict[str, Any] = field(default_factory=dict)

    @property
    def num_vertices(self) -> int:
        return len(self.positions)


def load_obj(path: str | os.PathLike[str]) -> Mesh:
    """Read an ``.obj``. Raises FormatError, and nothing else, on bad input."""
    return parse_obj(read_text(path), path)


def _floats(words: list[str], n: int, what: str, path: str | os.PathLike[str] | None, number: int) -> list[float]:
    if len(words) < n:
        raise FormatError(f"'{what}' needs {n} numbers, found {len(words)}.", path, number)
    try:
        vals = [float(w) for w in words[:n]]
    except ValueError:
        bad = next(w for w in words[:n] if not _is_float(w))
        raise FormatError(f"expected a number in the '{what}' line, found '{show(bad)}'.", path, number) from None
    if not all(math.isfinite(v) for v in vals):
        raise FormatError(f"the '{what}' line holds a value that is not a finite number.", path, number)
    return vals


def _is_float(w: str) -> bool:
    try:
        float(w)
    except ValueError:
        return False
    return True


def parse_obj(text: str, path: str | os.PathLike[str] | None = None) -> Mesh:
    positions: list[list[float]] = []
    normals: list[list[float]] = []
    texcoords: list[list[float]] = []
    faces: list[tuple[int, list[int], list[int], list[int]]] = []  # line, v, t, n (raw indices)
    pending = ""
    pending_line = 0
    for number, raw in enumerate(split_lines(text), start=1):
        line = raw.split("#", 1)[0]
        if line.rstrip().endswith("\\"):
            if not pending:
                pending_line = number
            pending += line.rstrip()[:-1] + " "
            continue
        if pending:
            line = pending + line
            number, pending = pending_line, ""
        words = line.split()
        if not words:
            continue
        head = words[0]
        if head == "v":
            vals = _floats(words[1:], 3, "v", path, number)
            positions.append(vals)
        elif head == "vn":
            normals.append(_floats(words[1:], 3, "vn", path, number))
        elif head == "vt":
            vt = _floats(words[1:], 1, "vt", path, number)
            extra = [float(w) for w in words[2:3] if _is_float(w)]
            texcoords.append((vt + extra + [0.0])[:2])
        elif head == "f":
            if len(words) < 4:
                raise FormatError(f"a face needs at least 3 corners, this one has {len(words) - 1}.", path, number)
            vi: list[int] = []
            ti: list[int] = []
            ni: list[int] = []
            for w in words[1:]:
                parts = w.split("/")
                if len(parts) > 3 or not parts[0]:
                    raise FormatError(f"a face corner looks like 'v', 'v/t', 'v//n' or 'v/t/n', found '{show(w)}'.",
                                      path, number)
                try:
                    vi.append(int(parts[0]))
                    if len(parts) > 1 and parts[1]:
                        ti.append(int(parts[1]))
                    if len(parts) > 2 and parts[2]:
                        ni.append(int(parts[2]))
                except ValueError:
                    raise FormatError(f"face indices must be whole numbers, found '{show(w)}'.", path, number) from None
            for lst, kind in ((ti, "texture"), (ni, "normal")):
                if lst and len(lst) != len(vi):
                    raise FormatError(f"some corners of this face have {kind} indices and some do not.", path, number)
            faces.append((number, vi, ti, ni))
    if pending:
        raise FormatError("the file ends with a '\\' line continuation.", path, pending_line)
    if not positions:
        raise FormatError("the file has no vertices ('v x y z' lines), so it is not an OBJ mesh.", path, 1)
    nv = len(positions)
    tris: list[list[int]] = []
    tri_t: list[list[int]] = []
    tri_n: list[list[int]] = []
    counts = {"v": nv, "vt": len(texcoords), "vn": len(normals)}
    seen = {"v": 0, "vt": 0, "vn": 0}
    # Relative (negative) indices refer to the elements read before the face: recount in file order.
    order = _element_counts_before_faces(text, faces)
    for (number, vi, ti, ni), before in zip(faces, order):
        seen.update(before)
        v0 = [_resolve(i, seen["v"], counts["v"], "vertex", path, number) for i in vi]
        t0 = [_resolve(i, seen["vt"], counts["vt"], "texture coordinate", path, number) for i in ti]
        n0 = [_resolve(i, seen["vn"], counts["vn"], "normal", path, number) for i in ni]
        for k in range(1, len(v0) - 1):
            tris.append([v0[0], v0[k], v0[k + 1]])
            if t0:
                tri_t.append([t0[0], t0[k], t0[k + 1]])
            if n0:
                tri_n.append([n0[0], n0[k], n0[k + 1]])
    mesh = Mesh(
        np.array(positions, dtype=np.float64).reshape(-1, 3),
        np.array(tris, dtype=np.int64).reshape(-1, 3),
        np.array(normals, dtype=np.float64).reshape(-1, 3) if normals else None,
        np.array(texcoords, dtype=np.float64).reshape(-1, 2) if texcoords else None,
        np.array(tri_n, dtype=np.int64).reshape(-1, 3) if tri_n and len(tri_n) == len(tris) else None,
        np.array(tri_t, dtype=np.int64).reshape(-1, 3) if tri_t and len(tri_t) == len(tris) else None,
        polygons=len(faces),
    )
    return mesh


_Face = tuple[int, list[int], list[int], list[int]]


def _element_counts_before_faces(text: str, faces: list[_Face]) -> list[dict[str, int]]:
    """How many v / vt / vn precede each face (only needed when a face uses negative indices)."""
    if not any(i < 0 for _, vi, ti, ni in faces for i in (*vi, *ti, *ni)):
        return [{} for _ in faces]
    face_lines = {f[0] for f in faces}
    counts = {"v": 0, "vt": 0, "vn": 0}
    out: dict[int, dict[str, int]] = {}
    for number, raw in enumerate(split_lines(text), start=1):
        words = raw.split("#", 1)[0].split()
        if not words:
            continue
        if words[0] in counts:
            counts[words[0]] += 1
        elif number in face_lines:
            out[number] = dict(counts)
    return [out.get(f[0], {}) for f in faces]


def _resolve(i: int, before: int, total: int, what: str, path: str | os.PathLike[str] | None, number: int) -> int:
    if i > 0:
        idx = i - 1
    elif i < 0:
        idx = before + i
    else:
        raise FormatError(f"{what} index 0 in a face: .obj indices start at 1.", path, number)
    if not 0 <= idx < total:
        raise FormatError(f"a face refers to {what} {i}, but the file has {total}.", path, number)
    return idx


def summarize(path: str | os.PathLike[str]) -> dict[str, Any]:
    mesh = load_obj(path)
    p = mesh.positions
    return {
        "file": str(Path(path)),
        "kind": "obj mesh",
        "vertices": mesh.num_vertices,
        "faces": mesh.polygons,
        "triangles": len(mesh.triangles),
        "normals": 0 if mesh.normals is None else len(mesh.normals),
        "texcoords": 0 if mesh.texcoords is None else len(mesh.texcoords),
        "bounding_box": [p.min(axis=0).tolist(), p.max(axis=0).tolist()] if len(p) else None,
    }
