"""2D characters in the document: adding them, and the one place their API is imported from.

One asset of kind ``character2d`` per character (``source`` = the SVG file or folder,
property ``index`` = which character of a folder). Channels:

* ``"<asset>/<joint name>/angle"`` — a keyframed joint's local angle (radians);
* ``"<asset>//x"``, ``"<asset>//y"`` — the character's translation from the rest pose;
* a dynamic (pendulum) joint may have an angle channel too: it holds the joint's **world**
  angle θ and sets the simulation's state at its keys (θ from the key, ω = 0), so the
  animator can pose a pendulum's starting angle. Between keys physics drives it.

This module adds characters from SVG files (:func:`add_characters_command`) and re-exports
the rest, which lives in one module per idea:

* :mod:`~qtanimator.document.character2d_asset`: the asset kind, its loader, lookup, channel ids;
* :mod:`~qtanimator.document.joint_limits`: joint limits (``"<asset>.limits.<joint name>"``);
* :mod:`~qtanimator.document.evaluation2d`: joint angles, translation and the pose at a time
  (pending poses included);
* :mod:`~qtanimator.document.keys2d`: key edits and IK drags (key-all, clamping to limits);
* :mod:`~qtanimator.document.pendulum_presets`: pendulum and spring constants and presets;
* :mod:`~qtanimator.document.pendulum_step`: stepping one character's pendulums and springs;
* :mod:`~qtanimator.document.pendulum_cache`: the simulated frames and their worker.

IK settings (``IK_DEFAULTS``, ``ik_setting``) and the solver they pick live in
:mod:`qtanimator.document.ik_settings` (shared with 3D); re-exported here for existing callers.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.core.rig2d import Character
from qtanimator.document.character2d_asset import (
    ASSET_KIND,
    angle_channel_id,
    channel_for,
    character,
    character_assets,
    load_character_asset,
    position_channel_ids,
    summary,
)
from qtanimator.document.commands import AddAsset, Command, Macro, SetParameter
from qtanimator.document.document import PROJECT_DEFAULTS, Asset, Document
from qtanimator.document.evaluation2d import (
    evaluate_pose,
    joint_angles,
    keyframed_angles,
    placement_matrix,
    to_character_frame,
    translation,
)
from qtanimator.document.ik_settings import IK_DEFAULTS, ik_setting
from qtanimator.document.joint_limits import (
    clamp_angle,
    joint_limits,
    limits_array,
    limits_parameter,
    set_joint_limits_command,
)
from qtanimator.document.keys2d import (
    DELETE_TOLERANCE_FRAMES,
    KEY_ALL_PARAMETER,
    clamp_values,
    delete_keys_at,
    ik_drag,
    ik_values,
    joint_value,
    key_joint,
    key_values,
    move_character,
    position_values,
)
from qtanimator.document.pendulum_cache import (
    PENDULUM_CACHE,
    PendulumCache,
    ensure_caches,
    pendulum_problems,
    simulated_frames,
    simulation,
    simulation_ready,
)
from qtanimator.document.pendulum_presets import (
    pendulum_params,
    set_pendulum_preset,
    set_spring_preset,
    spring_params,
)
from qtanimator.document.placement import PLACEMENT

__all__ = [
    "ASSET_KIND", "BESIDE_GAP", "DELETE_TOLERANCE_FRAMES", "IK_DEFAULTS", "KEY_ALL_PARAMETER", "NEW_PROJECT_RANGE",
    "PENDULUM_CACHE", "PendulumCache", "SVG_PROJECT_FRAME_END", "add_characters_command", "angle_channel_id",
    "channel_for", "character", "character_assets", "clamp_angle", "clamp_values", "delete_keys_at",
    "ensure_caches", "evaluate_pose", "ik_drag", "ik_setting", "ik_values", "joint_angles", "joint_limits",
    "joint_value", "key_joint", "key_values", "keyframed_angles", "limits_array", "limits_parameter",
    "load_character_asset", "move_character", "pendulum_params", "pendulum_problems", "placement_matrix",
    "position_channel_ids", "position_values", "set_joint_limits_command", "set_pendulum_preset",
    "set_spring_preset", "shown_bounds", "simulated_frames", "simulation", "simulation_ready", "spring_params",
    "summary", "to_character_frame", "translation",
]

FloatArray = npt.NDArray[np.float64]


#: The frame range of a new, empty document (``PROJECT_DEFAULTS``).
NEW_PROJECT_RANGE = (int(PROJECT_DEFAULTS["frame_start"]), int(PROJECT_DEFAULTS["frame_end"]))
#: The last frame of a new project of SVG characters: the CMU animator's timeline starts at 300.
SVG_PROJECT_FRAME_END = 300


def add_characters_command(doc: Document, path: str | Path, new_project_range: bool = False) -> Command:
    """A command adding every character of an SVG file or folder (FormatError if unreadable).

    With ``new_project_range`` (opening in the GUI, ``qtanimator render``), characters added
    to a new, empty document (no assets, no channels, the default range) also set the range
    to the CMU animator's 0…300, in the same undo step."""
    from qtanimator.formats.svg_rig import load_characters

    source = str(Path(path).resolve())
    chars = load_characters(source)
    new_project = (new_project_range and not doc.assets and not doc.channels
                   and doc.frame_range == NEW_PROJECT_RANGE)
    taken = set(doc.assets)
    commands: list[Command] = []
    offset = _beside_offset(doc, chars)
    for i, ch in enumerate(chars):
        asset_id = doc.unique_asset_id(ch.name)
        k = 2
        base = asset_id
        while asset_id in taken:
            asset_id = f"{base}_{k}"
            k += 1
        taken.add(asset_id)
        props: dict[str, Any] = {"index": i}
        if offset is not None:  # beside the characters already there (issue 14)
            props[PLACEMENT] = {"translate": [float(offset[0]), float(offset[1])], "rotate": 0.0, "scale": 1.0}
        asset = Asset(asset_id, ASSET_KIND, source, props)
        commands.append(AddAsset(asset, ch))
    text = commands[0].text if len(commands) == 1 else f"Add {len(commands)} characters"
    if new_project and commands:
        # A new project of SVG characters gets the CMU animator's range, 0…300, in the same step.
        commands.append(SetParameter(doc, "frame_end", SVG_PROJECT_FRAME_END))
    if len(commands) == 1:
        return commands[0]
    return Macro(text, commands)


def shown_bounds(doc: Document, asset_id: str, time: float = 0.0) -> tuple[float, float, float, float]:
    """(xmin, ymin, xmax, ymax) of the character's setup pose at its position and placement
    at ``time`` (what an import places new characters beside; nothing is simulated)."""
    ch = character(doc, asset_id)
    pose = ch.pose(np.zeros(len(ch.joints)), translation(doc, asset_id, time))
    return ch.bounds(pose.placed(placement_matrix(doc, asset_id)))


def _beside_offset(doc: Document, chars: list[Character]) -> FloatArray | None:
    """The translation that puts newly read characters (keeping their layout in the file)
    to the right of the document's 2D characters, bottoms aligned; None when there are none."""
    existing = [shown_bounds(doc, aid) for aid in character_assets(doc) if aid in doc.runtime]
    if not existing or not chars:
        return None
    new = [c.bounds() for c in chars]
    right = max(b[2] for b in existing)
    bottom = max(b[3] for b in existing)
    left = min(b[0] for b in new)
    height = max(max(b[3] for b in new) - min(b[1] for b in new), 1.0)
    return np.array([right + BESIDE_GAP * height - left, bottom - max(b[3] for b in new)])


#: The gap between an imported 2D character and the ones there, as a fraction of its height.
BESIDE_GAP = 0.1
