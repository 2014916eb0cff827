"""CSE 169 ``.skin`` files.

::

    positions N { x y z ... }          normals N { ... }          texcoords N { u v ... }
    skinweights N { K j0 w0 j1 w1 ... (one per vertex) }
    material NAME { texture FILE }
    triangles T { i j k ... }          (0-based)
    bindings J { matrix { a b c d } ... }   (12 numbers; a, b, c, d are COLUMNS of the
                                             bind world matrix B = [a b c d; 0 0 0 1])

Sections may come in any order; counts must agree (normals, texcoords and skinweights
with positions). Indices are checked against the vertex and binding counts.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from qtanimator.core.skinning import Skin, SkinBinding
from qtanimator.formats._tokens import Tokens, read_text, show
from qtanimator.formats.errors import FormatError

__all__ = ["load_skin", "parse_skin", "summarize"]

_SECTIONS = ("positions", "normals", "texcoords", "skinweights", "material", "triangles", "bindings")


def load_skin(path: str | os.PathLike[str], num_joints: int | None = None) -> Skin:
    """Read a ``.skin``. With ``num_joints`` (the skeleton's), joint indices are checked against it too."""
    return parse_skin(read_text(path), path, num_joints)


def parse_skin(text: str, path: str | os.PathLike[str] | None = None, num_joints: int | None = None) -> Skin:
    tk = Tokens(text, path)
    if tk.at_end():
        raise FormatError("the file is empty; a skin starts with 'positions N {'.", path, 1)
    found: dict[str, Any] = {}
    where: dict[str, int] = {}
    while not tk.at_end():
        word = tk.next("a section name")
        if word not in _SECTIONS:
            tk.error(f"unknown section '{show(word)}' (expected one of {', '.join(_SECTIONS)}).", tk.pos - 1)
        if word in found:
            tk.error(f"the '{word}' section appears twice.", tk.pos - 1)
        where[word] = tk.pos - 1
        if word in ("positions", "normals"):
            n = tk.count(f"the {word} count", 3)
            tk.expect("{", f"after '{word} {n}'")
            found[word] = tk.numbers(3 * n, f"the {word} block").reshape(n, 3)
            tk.expect("}", f"to close the {word} block (is the count {n} right?)")
        elif word == "texcoords":
            n = tk.count("the texcoords count", 2)
            tk.expect("{", f"after 'texcoords {n}'")
            found[word] = tk.numbers(2 * n, "the texcoords block").reshape(n, 2)
            tk.expect("}", f"to close the texcoords block (is the count {n} right?)")
        elif word == "triangles":
            n = tk.count("the triangle count", 3)
            tk.expect("{", f"after 'triangles {n}'")
            found[word] = tk.integers(3 * n, "the triangles block").reshape(n, 3)
            tk.expect("}", f"to close the triangles block (is the count {n} right?)")
        elif word == "skinweights":
            found[word] = _parse_weights(tk)
        elif word == "material":
            mname = tk.next("a material name")
            if mname in ("{", "}"):
                tk.error("a 'material' needs a name before its '{'.", tk.pos - 1)
            tk.expect("{", f"after 'material {show(mname)}'")
            props: dict[str, str] = {"name": mname}
            while True:
                key = tk.next(f"'texture' or the closing '}}' of material '{show(mname)}'")
                if key == "}":
                    break
                if key == "{":
                    tk.error(f"unexpected '{{' in material '{show(mname)}'.", tk.pos - 1)
                value = tk.next(f"a value for '{show(key)}' in material '{show(mname)}'")
                if value in ("{", "}"):
                    tk.error(f"'{show(key)}' in material '{show(mname)}' needs a value.", tk.pos - 1)
                props[key] = value
            found[word] = props
        else:  # bindings
            found[word] = _parse_bindings(tk)
    if "positions" not in found:
        tk.error("the skin has no 'positions' section.")
    positions = found["positions"]
    nv = len(positions)
    for name in ("normals", "texcoords"):
        if name in found and len(found[name]) != nv:
            tk.error(f"there are {len(found[name])} {name} but {nv} positions.", where[name])
    bind = found.get("bindings")
    if bind is None:
        bind = np.eye(4)[None].repeat(1, axis=0)
    nj = len(bind)
    triangles = found.get("triangles", np.zeros((0, 3), dtype=np.int64))
    bad_mask = ((triangles < 0) | (triangles >= nv)).reshape(-1)
    if bad_mask.any():
        i = int(np.argmax(bad_mask))
        tk.error(f"triangle {i // 3 + 1} refers to vertex {int(triangles.reshape(-1)[i])}, but there are only "
                 f"{nv} vertices (indices start at 0).", where["triangles"] + 3 + i)
    if "skinweights" in found:
        counts, verts, joints, weights, wline = found["skinweights"]
        if len(counts) != nv:
            tk.error(f"there are {len(counts)} skin weight lines but {nv} positions.", where["skinweights"])
        limit = nj if num_joints is None else min(nj, num_joints)
        if len(joints) and (joints.min() < 0 or joints.max() >= limit):
            i = int(np.argmax((joints < 0) | (joints >= limit)))
            what = "bindings" if limit == nj else "joints in the skeleton"
            raise FormatError(f"vertex {int(verts[i])} is weighted to joint {int(joints[i])}, but there are only "
                              f"{limit} {what} (joint indices start at 0).", tk.path, wline[i])
        binding = SkinBinding(verts, joints, weights, nv, nj)
    else:
        # No weights: every vertex follows joint 0 rigidly.
        binding = SkinBinding(np.arange(nv), np.zeros(nv, dtype=np.intp), np.ones(nv), nv, nj)
    try:
        inverse = np.linalg.inv(bind)
    except np.linalg.LinAlgError:
        tk.error("a binding matrix cannot be inverted (its a, b, c axes are not independent).", where["bindings"])
    if not np.all(np.isfinite(inverse)):
        tk.error("a binding matrix cannot be inverted (its a, b, c axes are not independent).", where["bindings"])
    return Skin(positions, triangles, binding, inverse, normals=found.get("normals"),
                texcoords=found.get("texcoords"), material=found.get("material"), bind_matrices=bind)


def _parse_weights(tk: Tokens) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, list[int]]:
    n = tk.count("the skinweights count", 1)
    tk.expect("{", f"after 'skinweights {n}'")
    counts = np.zeros(n, dtype=np.intp)
    verts: list[int] = []
    joints: list[int] = []
    weights: list[float] = []
    lines: list[int] = []
    for v in range(n):
        if tk.peek() == "}":
            tk.error(f"the skinweights block says {n} vertices but lists only {v}.")
        k = tk.count(f"the number of weights of vertex {v}", 2)
        counts[v] = k
        for _ in range(k):
            line = tk.line()
            joints.append(tk.integer(f"a joint index of vertex {v}"))
            w = tk.number(f"a weight of vertex {v}")
            verts.append(v)
            weights.append(w)
            lines.append(line)
    tk.expect("}", f"to close the skinweights block (is the count {n} right?)")
    return (counts, np.array(verts, dtype=np.intp), np.array(joints, dtype=np.intp),
            np.array(weights, dtype=np.float64), lines)


def _parse_bindings(tk: Tokens) -> np.ndarray:
    n = tk.count("the bindings count", 15)
    tk.expect("{", f"after 'bindings {n}'")
    mats = np.zeros((n, 4, 4))
    for j in range(n):
        if tk.peek() == "}":
            tk.error(f"the bindings block says {n} matrices but lists only {j}.")
        tk.expect("matrix", f"for binding {j}")
        tk.expect("{", f"after 'matrix' of binding {j}")
        cols = tk.numbers(12, f"the matrix of binding {j}").reshape(4, 3)
        tk.expect("}", f"to close the matrix of binding {j} (a matrix has 12 numbers)")
        mats[j, :3, :] = cols.T  # each group a, b, c, d is a column
        mats[j, 3, 3] = 1.0
    tk.expect("}", f"to close the bindings block (is the count {n} right?)")
    return mats


def summarize(path: str | os.PathLike[str]) -> dict[str, Any]:
    skin = load_skin(path)
    counts = skin.binding.counts()
    lo = skin.positions.min(axis=0).tolist() if skin.num_vertices else None
    hi = skin.positions.max(axis=0).tolist() if skin.num_vertices else None
    return {
        "file": str(Path(path)),
        "kind": "skin",
        "vertices": skin.num_vertices,
        "triangles": len(skin.triangles),
        "bindings": skin.num_joints,
        "normals": skin.normals is not None,
        "texcoords": skin.texcoords is not None,
        "material": dict(skin.material) if skin.material else None,
        "max_influences": int(counts.max()) if len(counts) else 0,
        "bounding_box": [lo, hi] if lo is not None else None,
    }
