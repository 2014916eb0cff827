"""``.skel`` skeletons, both dialects, detected from the content.

* CSE 169 balljoint (nested blocks)::

      balljoint root {
          offset 0 0 0   boxmin ...   boxmax ...
          rotxlimit lo hi   rotylimit ...   rotzlimit ...   pose x y z
          balljoint child { ... }
      }

  Items in any order, all optional (defaults: offset 0, box ±0.1, limits ±100000,
  pose 0). Joint order is the order of the ``balljoint`` keywords (depth-first). Poses
  are clamped to the limits. Rotation order ``zyx``: L = T(offset)·Rz·Ry·Rx.

* MIT 6.837 line format: one joint per line ``x y z parent`` (parent 0-based, −1 for
  the root, parents precede children). Rotation order ``xyz``: L = T(offset)·Rx·Ry·Rz;
  DOF limits −π…π (the reference's sliders).
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from qtanimator.core.skeleton import DEFAULT_BOXMAX, DEFAULT_BOXMIN, DEFAULT_LIMIT, Dof, Joint, Skeleton
from qtanimator.formats._tokens import Tokens, read_text, show, split_lines
from qtanimator.formats.errors import FormatError

__all__ = ["load_skel", "parse_skel", "summarize", "MIT_JOINT_NAMES"]

#: Joint names the MIT starter's GUI uses (index order) for its 18-joint models.
MIT_JOINT_NAMES = (
    "Root", "Chest", "Waist", "Neck", "Right hip", "Right leg", "Right knee", "Right foot",
    "Left hip", "Left leg", "Left knee", "Left foot", "Right collarbone", "Right shoulder",
    "Right elbow", "Left collarbone", "Left shoulder", "Left elbow",
)

_VECTORS = ("offset", "boxmin", "boxmax", "pose")
_LIMITS = {"rotxlimit": 0, "rotylimit": 1, "rotzlimit": 2}


def load_skel(path: str | os.PathLike[str]) -> Skeleton:
    """Read either ``.skel`` dialect. Raises FormatError, and nothing else, on bad input."""
    return parse_skel(read_text(path), path)


def detect_dialect(text: str) -> str:
    """``"balljoint"`` or ``"mit"`` (or ``"unknown"``) from the first word."""
    for line in split_lines(text):
        words = line.split()
        if not words or words[0].startswith("#"):
            continue
        if words[0].startswith("balljoint"):
            return "balljoint"
        try:
            float(words[0])
        except ValueError:
            return "unknown"
        return "mit"
    return "unknown"


def parse_skel(text: str, path: str | os.PathLike[str] | None = None) -> Skeleton:
    name = Path(path).stem if path is not None else ""
    dialect = detect_dialect(text)
    if dialect == "balljoint":
        return _parse_balljoint(text, path, name)
    if dialect == "mit":
        return _parse_mit(text, path, name)
    tk = Tokens(text, path)
    if tk.at_end():
        raise FormatError("the file is empty; a skeleton starts with 'balljoint' or a joint line 'x y z parent'.",
                          path, 1)
    tk.error(f"this is not a skeleton: expected 'balljoint' or a joint line 'x y z parent', "
             f"found '{show(tk.toks[0])}'.", 0)


class _Pending:
    __slots__ = ("name", "parent", "values", "limits")

    def __init__(self, name: str, parent: int | None) -> None:
        self.name = name
        self.parent = parent
        self.values: dict[str, tuple[float, float, float]] = {}
        self.limits: list[tuple[float, float] | None] = [None, None, None]


def _parse_balljoint(text: str, path: str | os.PathLike[str] | None, name: str) -> Skeleton:
    tk = Tokens(text, path)
    pending: list[_Pending] = []
    open_stack: list[int] = []  # indices of joints whose block is open (iterative: no recursion limit)
    while True:
        if not open_stack:
            if pending:
                if not tk.at_end():
                    tk.error(f"unexpected '{show(tk.toks[tk.pos])}' after the root joint's closing '}}'; "
                             "a skeleton has exactly one root.")
                break
            tk.expect("balljoint", "to start the skeleton")
            pending.append(_open_joint(tk, None, len(pending)))
            open_stack.append(len(pending) - 1)
            continue
        current = pending[open_stack[-1]]
        word = tk.next(f"an item or the closing '}}' of joint '{current.name}'")
        if word == "}":
            open_stack.pop()
        elif word == "balljoint":
            pending.append(_open_joint(tk, open_stack[-1], len(pending)))
            open_stack.append(len(pending) - 1)
        elif word in _VECTORS:
            if word in current.values:
                tk.error(f"'{word}' appears twice in joint '{current.name}'.", tk.pos - 1)
            current.values[word] = (tk.number(f"{word} x of joint '{current.name}'"),
                                    tk.number(f"{word} y of joint '{current.name}'"),
                                    tk.number(f"{word} z of joint '{current.name}'"))
        elif word in _LIMITS:
            axis = _LIMITS[word]
            if current.limits[axis] is not None:
                tk.error(f"'{word}' appears twice in joint '{current.name}'.", tk.pos - 1)
            at = tk.pos - 1
            lo = tk.number(f"the {word} minimum of joint '{current.name}'")
            hi = tk.number(f"the {word} maximum of joint '{current.name}'")
            if lo > hi:
                tk.error(f"{word} of joint '{current.name}' has its minimum {lo} above its maximum {hi}.", at)
            current.limits[axis] = (lo, hi)
        else:
            tk.error(f"unknown item '{show(word)}' in joint '{current.name}' (expected offset, boxmin, boxmax, "
                     "rotxlimit, rotylimit, rotzlimit, pose, balljoint or '}').", tk.pos - 1)
    joints = []
    for p in pending:
        dofs = []
        pose = p.values.get("pose", (0.0, 0.0, 0.0))
        for axis in range(3):
            lo, hi = p.limits[axis] or (-DEFAULT_LIMIT, DEFAULT_LIMIT)
            dofs.append(Dof(pose[axis], lo, hi))
        joints.append(Joint(p.name, p.parent, np.array(p.values.get("offset", (0.0, 0.0, 0.0))),
                            (dofs[0], dofs[1], dofs[2]),
                            np.array(p.values.get("boxmin", DEFAULT_BOXMIN)),
                            np.array(p.values.get("boxmax", DEFAULT_BOXMAX))))
    return Skeleton(joints, rotation_order="zyx", name=name, dialect="balljoint")


def _open_joint(tk: Tokens, parent: int | None, index: int) -> _Pending:
    name = tk.next("a joint name after 'balljoint'")
    if name in ("{", "}"):
        tk.error("a 'balljoint' needs a name before its '{'.", tk.pos - 1)
    tk.expect("{", f"after 'balljoint {show(name)}'")
    return _Pending(name, parent)


def _parse_mit(text: str, path: str | os.PathLike[str] | None, name: str) -> Skeleton:
    joints: list[Joint] = []
    for number, line in enumerate(split_lines(text), start=1):
        words = line.split()
        if not words or words[0].startswith("#"):
            continue
        if len(words) != 4:
            raise FormatError(f"a joint line has 4 fields 'x y z parent', this one has {len(words)}.", path, number)
        try:
            x, y, z = (float(w) for w in words[:3])
        except ValueError:
            raise FormatError(f"expected three numbers then a parent index, found '{show(line.strip())}'.",
                              path, number) from None
        if not all(math.isfinite(v) for v in (x, y, z)):
            raise FormatError("joint offsets must be finite numbers.", path, number)
        try:
            parent = int(words[3])
        except ValueError:
            raise FormatError(f"the parent index must be a whole number, found '{show(words[3])}'.",
                              path, number) from None
        index = len(joints)
        if parent == -1:
            if index != 0:
                raise FormatError("only the first joint may be the root (parent −1).", path, number)
            par: int | None = None
        elif 0 <= parent < index:
            par = parent
        else:
            raise FormatError(f"joint {index} has parent {parent}, which is not an earlier joint "
                              "(parents must come before their children).", path, number)
        jname = MIT_JOINT_NAMES[index] if index < len(MIT_JOINT_NAMES) else f"joint{index}"
        dofs = (Dof(0.0, -math.pi, math.pi), Dof(0.0, -math.pi, math.pi), Dof(0.0, -math.pi, math.pi))
        joints.append(Joint(jname, par, np.array([x, y, z]), dofs))
    if not joints:
        raise FormatError("the skeleton file has no joints.", path, 1)
    if len(joints) != len(MIT_JOINT_NAMES):
        # Other models: generic names.
        for i, j in enumerate(joints):
            j.name = "Root" if i == 0 else f"joint{i}"
    return Skeleton(joints, rotation_order="xyz", name=name, dialect="mit")


def summarize(path: str | os.PathLike[str]) -> dict[str, Any]:
    skel = load_skel(path)
    names = skel.names
    limited = sum(1 for j in skel.joints for d in j.dofs if d.min > -DEFAULT_LIMIT or d.max < DEFAULT_LIMIT)
    return {
        "file": str(Path(path)),
        "kind": "skeleton",
        "dialect": skel.dialect,
        "joints": len(skel.joints),
        "distinct_names": len(set(names)),
        "depth": max(skel.depths) + 1 if skel.joints else 0,
        "rotation_order": skel.rotation_order,
        "limited_dofs": limited,
        "root": names[0] if names else None,
    }
