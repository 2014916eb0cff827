"""Joint limits of 2D characters.

Joint limits are document parameters ``"<asset>.limits.<joint name>"`` holding ``[lo, hi]``,
the range of the joint's **local** angle (relative to its parent, radians). A keyframed
joint's angle is clamped to its range wherever it is evaluated (the channel keeps its keys,
as Maya's transform limits do) and every edit that keys or poses a joint clamps the value it
writes (:func:`qtanimator.document.keys2d.clamp_values`); :func:`joint_limits` gives them by
joint index to the IK solvers and the pendulums.
"""

from __future__ import annotations

import math
from collections.abc import Hashable
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.document.character2d_asset import character
from qtanimator.document.commands import Command, SetParameter
from qtanimator.document.document import Document

FloatArray = npt.NDArray[np.float64]


def limits_parameter(asset_id: str, joint_name: str) -> str:
    """The document parameter holding a joint's limits ``[lo, hi]`` (local angle, radians)."""
    return f"{asset_id}.limits.{joint_name}"


def limit_pair(value: Any) -> tuple[float, float] | None:
    """A stored ``[lo, hi]`` as floats; None for anything else (a hand-edited project's
    malformed entry leaves the joint free rather than breaking every evaluation)."""
    if not isinstance(value, (list, tuple)) or len(value) != 2 or any(isinstance(v, bool) for v in value):
        return None
    try:
        lo, hi = float(value[0]), float(value[1])
    except (TypeError, ValueError):
        return None
    if not (math.isfinite(lo) and math.isfinite(hi)) or lo > hi:
        return None
    return lo, hi


def joint_limits(doc: Document, asset_id: str) -> list[tuple[float, float] | None]:
    """Each joint's limits ``(lo, hi)`` on its local angle (radians, relative to its
    parent), by joint index; None for a free joint."""
    ch = character(doc, asset_id)
    params = doc.parameters
    return [limit_pair(params.get(limits_parameter(asset_id, j.name))) for j in ch.joints]


def limits_array(doc: Document, asset_id: str) -> FloatArray:
    """:func:`joint_limits` as a (J, 2) array, ±inf for free joints (``solve_ik``'s form)."""
    out = np.tile(np.array([-math.inf, math.inf]), (len(character(doc, asset_id).joints), 1))
    for k, lim in enumerate(joint_limits(doc, asset_id)):
        if lim is not None:
            out[k] = lim
    return out


def set_joint_limits_command(doc: Document, asset_id: str, joint: int | str, lo: float | None,
                             hi: float | None = None, gesture: Hashable | None = None) -> Command:
    """Limit ``joint`` (index or name) to local angles ``lo``…``hi`` (radians), or free it
    with ``lo`` and ``hi`` None: one undo step, saved with the project as a parameter.
    ValueError for an unknown joint, a missing, non-finite or reversed bound."""
    ch = character(doc, asset_id)
    if isinstance(joint, str):
        index = ch.joint_index(joint) if joint in {j.name for j in ch.joints} else -1
    else:
        index = int(joint)
    if not 0 <= index < len(ch.joints):
        raise ValueError(f"'{asset_id}' has no joint {joint!r}")
    name = ch.joints[index].name
    path = limits_parameter(asset_id, name)
    if lo is None and hi is None:
        return SetParameter(doc, path, None, text=f"Free {name}", gesture=gesture)
    if lo is None or hi is None:
        raise ValueError("a joint limit needs both a minimum and a maximum")
    lo_f, hi_f = float(lo), float(hi)
    if not (math.isfinite(lo_f) and math.isfinite(hi_f)):
        raise ValueError("joint limits must be finite numbers")
    if lo_f > hi_f:
        raise ValueError(f"the minimum ({math.degrees(lo_f):.6g}°) is above the maximum ({math.degrees(hi_f):.6g}°)")
    return SetParameter(doc, path, [lo_f, hi_f], text=f"Limit {name}", gesture=gesture)


def clamp_angle(doc: Document, asset_id: str, joint_index: int, angle: float) -> float:
    """A local ``angle`` of a joint clamped to its limits."""
    lim = joint_limits(doc, asset_id)[joint_index]
    return float(angle) if lim is None else min(max(float(angle), lim[0]), lim[1])
