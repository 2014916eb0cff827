"""The degrees of freedom of a selected joint, as plain data (no Qt): what the outliner's DOF
panel (:mod:`qtanimator.ui.dof_panel`) shows and keys.

:func:`dof_specs` gives one :class:`DofSpec` per DOF within its limits: a 2D joint's angle
(a character's own row: its position), a 3D joint's rotation as Euler angles in its
rotation order (also when it is keyed as a quaternion) and its translation and scale where
it moves or scales, a 3D character's root translation. Also the joints of an asset
(:func:`joint_names`) and the Reset Pose command (:func:`reset_pose_command`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from qtanimator.document import character2d, character3d
from qtanimator.document.commands import Command, Macro
from qtanimator.document.document import Document

SLIDER_STEPS_PER_UNIT = 10  # 0.1° (or 0.1 unit) per slider step
TRANSLATION_LIMIT = 5000.0


@dataclass
class DofSpec:
    """One editable degree of freedom of the selected joint.

    ``value`` and the limits are in display units (degrees for angles); ``make`` builds
    the keying command from a display value, the current time and a gesture token.
    """

    label: str
    value: float
    minimum: float
    maximum: float
    make: Callable[[float, float, object], Command]
    suffix: str = "°"
    #: The channel this DOF keys and how a display value becomes its value: with auto-key
    #: off the slider only poses (the pending, unkeyed pose) through them.
    channel: str = ""
    to_doc: Callable[[float], float] = float
    #: The unkeyed pose of a display value at a time, as channel values, where one value
    #: does not map to one channel (a 3D joint keyed as a quaternion: its four components).
    #: None: ``{channel: to_doc(value)}``.
    preview: Callable[[float, float], dict[str, float]] | None = None
    #: Slider steps per display unit and the spin box's decimals.
    steps: int = SLIDER_STEPS_PER_UNIT
    decimals: int = 2
    #: A wider range for typed values than the slider's (None: the slider's).
    typed_range: tuple[float, float] | None = None

    def pose_values(self, value: float, time: float) -> dict[str, float]:
        """The channel values an unkeyed pose of ``value`` at ``time`` shows."""
        if self.preview is not None:
            return self.preview(value, time)
        return {self.channel: self.to_doc(value)}


def asset_kind(doc: Document, asset: str) -> str:
    a = doc.assets.get(asset)
    return a.kind if a is not None else ""


def dof_specs(doc: Document, asset: str, joint: str, time: float) -> list[DofSpec]:
    """The DOFs of ``(asset, joint)`` at ``time``; a character's own row (joint "") has
    its position."""
    kind = asset_kind(doc, asset)
    runtime = doc.runtime.get(asset)
    if kind == character2d.ASSET_KIND and runtime is not None:
        pose = character2d.evaluate_pose(doc, asset, time, block=False)  # a view: never simulates
        if joint == "":
            tx, ty = (float(v) for v in pose.translation)

            def move(axis: int) -> Callable[[float, float, object], Command]:
                def make(value: float, t: float, gesture: object) -> Command:
                    cur = character2d.translation(doc, asset, t)
                    xy = (value, float(cur[1])) if axis == 0 else (float(cur[0]), value)
                    return character2d.move_character(doc, asset, xy, t, gesture=gesture)
                return make

            cx, cy = character2d.position_channel_ids(asset)
            return [DofSpec("x", tx, -TRANSLATION_LIMIT, TRANSLATION_LIMIT, move(0), "", cx),
                    DofSpec("y", ty, -TRANSLATION_LIMIT, TRANSLATION_LIMIT, move(1), "", cy)]
        index = runtime.joint_index(joint)
        angle = float(np.asarray(character2d.joint_angles(doc, asset, time, block=False))[index])

        def key(value: float, t: float, gesture: object) -> Command:
            return character2d.key_joint(doc, asset, index, math.radians(value), t, gesture=gesture)

        def preview(value: float, t: float) -> dict[str, float]:
            # Clamped, and a pendulum's channel holds its world angle (as keying does).
            return dict(character2d.joint_value(doc, asset, index, math.radians(value), t))

        # The slider (and typed values) span the joint's limits when it has some.
        limit = character2d.joint_limits(doc, asset)[index]
        lo, hi = (-360.0, 360.0) if limit is None else (math.degrees(limit[0]), math.degrees(limit[1]))
        return [DofSpec("angle", math.degrees(angle), lo, hi, key, "°",
                        character2d.angle_channel_id(asset, joint), math.radians, preview)]
    if kind == character3d.ASSET_KIND and runtime is not None:
        return _dof_specs_3d(doc, asset, joint, time)
    return []


def _dof_specs_3d(doc: Document, asset: str, joint: str, time: float) -> list[DofSpec]:
    """A 3D character's root translation (joint ""), or a joint's rotation (Euler angles in
    its rotation order, also for a joint keyed as a quaternion), translation and scale.

    Every DOF keys through ``set_dof_command`` and previews (auto-key off) through
    ``dof_values``, which turn one Euler angle of a quaternion joint into its four components."""
    posed = character3d.pose_skeleton(doc, asset, time)

    def dof(key: tuple[int | None, str], scale: Callable[[float], float],
            ) -> tuple[Callable[[float, float, object], Command], Callable[[float, float], dict[str, float]]]:
        def make(value: float, t: float, gesture: object) -> Command:
            return character3d.set_dof_command(doc, asset, key[0], key[1], scale(value), t, gesture=gesture)

        def preview(value: float, t: float) -> dict[str, float]:
            return dict(character3d.dof_values(doc, asset, {key: scale(value)}, t))

        return make, preview

    specs: list[DofSpec] = []
    if not joint:
        for axis_i, axis in enumerate("xyz"):
            make, preview = dof((None, "t" + axis), float)
            specs.append(DofSpec(f"translate {axis}", float(posed.root_translation[axis_i]), -TRANSLATION_LIMIT,
                                 TRANSLATION_LIMIT, make, "", character3d.dof_channel_id(doc, asset, None, axis),
                                 preview=preview))
        return specs
    keys = posed.joint_keys()
    names = [j.name for j in posed.joints]
    if joint in keys:
        index = keys.index(joint)
    elif joint in names:
        index = names.index(joint)
    else:
        return []
    j = posed.joints[index]
    order = j.rotation_order or posed.rotation_order
    for axis_i, axis in enumerate("xyz"):
        d = j.dofs[axis_i]
        lo, hi = float(d.min), float(d.max)
        if lo >= hi:
            continue  # a locked DOF
        # A quaternion is shown as the Euler angles of its joint's order, whose middle angle
        # lies within ±90°: a slider beyond that would jump back once keyed.
        bound = math.pi / 2 if j.quaternion and order[1] == axis else math.pi
        lo, hi = max(lo, -bound), min(hi, bound) if math.isfinite(hi) else bound
        make, preview = dof((index, axis), math.radians)
        specs.append(DofSpec(f"rotate {axis}", math.degrees(float(d.value)), math.degrees(lo), math.degrees(hi),
                             make, "°", character3d.dof_channel_id(doc, asset, index, axis), math.radians, preview))
    if j.translates or j.scales:
        rest = character3d.character(doc, asset).skeleton
    if j.translates:
        # The slider spans the skeleton's size either side of the rest position (fine enough
        # to drag); a typed value may go anywhere.
        reach = _reach(rest)
        steps = _steps_for(2.0 * reach)
        for axis_i, axis in enumerate("xyz"):
            make, preview = dof((index, "t" + axis), float)
            middle = float(rest.joints[index].translation[axis_i])
            specs.append(DofSpec(f"translate {axis}", float(j.translation[axis_i]), middle - reach, middle + reach,
                                 make, "", character3d.dof_channel_id(doc, asset, index, "t" + axis), preview=preview,
                                 steps=steps, decimals=_decimals(steps),
                                 typed_range=(-TRANSLATION_LIMIT * reach, TRANSLATION_LIMIT * reach)))
    if j.scales:
        biggest = max(1.0, float(np.abs(rest.joints[index].scale).max()))
        hi = 4.0 * biggest
        lo = -hi if float(rest.joints[index].scale.min()) < 0 else 0.0
        for axis_i, axis in enumerate("xyz"):
            make, preview = dof((index, "s" + axis), float)
            specs.append(DofSpec(f"scale {axis}", float(j.scale[axis_i]), lo, hi, make, "",
                                 character3d.dof_channel_id(doc, asset, index, "s" + axis), preview=preview, steps=100,
                                 decimals=2))
    return specs


def _reach(skeleton: Any) -> float:
    """A length that suits a skeleton's translation sliders: its rest size (1 for a
    skeleton of one point)."""
    world = np.asarray(skeleton.world_matrices(), dtype=np.float64)
    reach = float(np.linalg.norm(np.ptp(world[:, :3, 3], axis=0))) if len(world) else 0.0
    return reach if math.isfinite(reach) and reach > 1e-6 else 1.0


def _steps_for(span: float) -> int:
    """Slider steps per unit (a power of ten, at least 1) giving a slider over ``span``
    units about 1000 to 10000 steps."""
    return int(10 ** max(0, math.ceil(math.log10(1000.0 / span)))) if span > 0 else SLIDER_STEPS_PER_UNIT


def _decimals(steps: int) -> int:
    return max(2, round(math.log10(steps)))


def joint_names(doc: Document, asset: str) -> list[tuple[str, int | None, bool]]:
    """``(name, parent index, is_dynamic)`` for the joints of a 2D or 3D asset."""
    runtime = doc.runtime.get(asset)
    if runtime is None:
        return []
    joints = getattr(runtime, "joints", None)
    if joints is None and hasattr(runtime, "skeleton"):
        joints = runtime.skeleton.joints
    if joints is None:
        return []
    out = []
    for j in joints:
        parent = j.parent if j.parent is None or j.parent >= 0 else None
        out.append((str(j.name), parent, bool(getattr(j, "is_dynamic", False))))
    return out


def reset_pose_command(doc: Document, asset: str, time: float, gesture: object = None) -> Command | None:
    """Every joint of ``asset`` back to its rest angle, keyed at ``time`` (one step)."""
    kind = asset_kind(doc, asset)
    commands: list[Command] = []
    if kind == character2d.ASSET_KIND:
        n = len(doc.runtime[asset].joints)
        for j in range(n):
            cmd = character2d.key_joint(doc, asset, j, 0.0, time, gesture=gesture)
            cmd.do(doc)  # later keys build on this one; undone below
            commands.append(cmd)
    elif kind == character3d.ASSET_KIND:
        # Course skeletons reset to zero angles (CSE169's R); a glTF character to the
        # file's rest pose, translations and scales included.
        skel = character3d.character(doc, asset).skeleton
        rest_from_file = skel.dialect == "gltf"
        values: dict[tuple[int | None, str | int], float] = {}
        for j, joint in enumerate(skel.joints):
            for a, axis in enumerate("xyz"):
                values[(j, axis)] = float(joint.pose[a]) if rest_from_file else 0.0
                if joint.translates:
                    values[(j, "t" + axis)] = float(joint.translation[a])
                if joint.scales:
                    values[(j, "s" + axis)] = float(joint.scale[a])
        if values:
            return Macro("Reset Pose", [character3d.set_dofs_command(doc, asset, values, time, gesture=gesture)])
    for cmd in reversed(commands):
        cmd.undo(doc)
    return Macro("Reset Pose", commands) if commands else None
