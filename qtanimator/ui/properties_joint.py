"""The properties dock's 2D groups: the selected joint (what drives it, its limits) and its character.

A joint's mode and limits are one undo step each (``rigging.set_joint_mode_command``,
``character2d.set_joint_limits_command``); read-only facts (mass, inertia, pivot…) are labels.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from PySide6.QtCore import QTimer
from PySide6.QtWidgets import QCheckBox, QComboBox, QFormLayout, QGroupBox, QLabel

from qtanimator.document import character2d
from qtanimator.ui.properties_form import PanelForm
from qtanimator.ui.widgets import CheckedDoubleSpinBox

#: What drives a 2D joint, in the animator's words (``rigging.JOINT_MODES``).
JOINT_MODE_LABELS = {"keyframed": "Keys", "dynamic": "Pendulum (physics)", "spring": "Spring (follows keys)"}
#: How far the joint limit fields go either way (degrees): two turns.
LIMIT_RANGE_DEGREES = 720.0


def joint2d_group(panel: PanelForm, asset: str, joint: str) -> QGroupBox:
    doc = panel.ctx.doc
    character = doc.runtime[asset]
    index = character.joint_index(joint)
    j = character.joints[index]
    group = QGroupBox(f"Joint: {joint}")
    group.setObjectName("jointProperties")
    form = QFormLayout(group)
    form.addRow("Index", QLabel(str(index)))
    parent = "—" if j.parent is None else character.joints[j.parent].name
    form.addRow("Parent", QLabel(parent))
    kind = QLabel("dynamic (pendulum)" if j.is_dynamic else "spring" if j.is_spring else "keyframed")
    kind.setObjectName("jointType")
    form.addRow("Type", kind)
    form.addRow("Driven by", _joint_mode_editor(panel, asset, joint, index))
    form.addRow("Pivot (rest)", QLabel(f"({j.pivot[0]:.2f}, {j.pivot[1]:.2f})"))
    form.addRow("Shapes", QLabel(str(len(j.shapes))))
    form.addRow("Mass", QLabel(f"{j.mass:.6g}"))
    form.addRow("Moment of inertia", QLabel(f"{j.inertia:.6g}"))
    com = j.centroid
    form.addRow("Centre of mass", QLabel(f"({com[0]:.2f}, {com[1]:.2f})"))
    form.addRow("Pendulum length L", QLabel(f"{float(np.hypot(*(com - j.pivot))):.3f}"))

    def angle() -> str:
        a = float(np.asarray(character2d.joint_angles(doc, asset, panel.ctx.time, block=False))[index])
        return f"{math.degrees(a):.3f}°"

    panel.label(form, "Angle (local)", angle, "jointAngle")
    if j.is_dynamic or j.is_spring:  # the simulation catching up changes it too
        panel.simulation_refreshers.append(panel.refreshers[-1])
    _joint_limits_editor(panel, form, asset, index)
    return group


def _joint_mode_editor(panel: PanelForm, asset: str, joint: str, index: int) -> QComboBox:
    """Keys, a pendulum or a spring: one undo step (``rigging.set_joint_mode_command``);
    a refusal (the root cannot swing) goes to the status bar."""
    from qtanimator.document import rigging

    doc = panel.ctx.doc
    combo = QComboBox()
    combo.setObjectName("jointMode")
    combo.setToolTip("keys: the joint follows its keys; pendulum: gravity and the body's movement swing it "
                     "(its keys only set where it starts); spring: it follows its keys through a damped "
                     "spring, lagging and overshooting")
    for mode in rigging.JOINT_MODES:
        combo.addItem(JOINT_MODE_LABELS[mode], mode)
    j = doc.runtime[asset].joints[index]
    combo.setCurrentIndex(rigging.JOINT_MODES.index("dynamic" if j.is_dynamic else
                                                    "spring" if j.is_spring else "keyframed"))

    def chosen(i: int) -> None:
        mode = str(combo.itemData(i))
        try:
            command = rigging.set_joint_mode_command(doc, asset, joint, mode)
        except rigging.RigError as exc:
            window = panel.owner.window()
            bar = getattr(window, "statusBar", None)
            if callable(bar):
                bar().showMessage(str(exc), 5000)
            QTimer.singleShot(0, panel.rebuild)
            return
        # After the combo's signal returns: the change rebuilds this panel, combo included.
        QTimer.singleShot(0, lambda: panel.ctx.push(command))

    combo.currentIndexChanged.connect(chosen)
    panel.editors["joint_mode"] = combo
    return combo


def _joint_limits_editor(panel: PanelForm, form: QFormLayout, asset: str, index: int) -> None:
    """A 2D joint's limits on its local angle, in degrees: the check box turns them on
    (with a range that holds the angle shown) or off, the fields edit one bound each;
    every change is one undo step (``character2d.set_joint_limits_command``)."""
    doc = panel.ctx.doc
    enabled = QCheckBox("Limit rotation")
    enabled.setObjectName("jointLimitsEnabled")
    enabled.setToolTip("keep the joint's angle relative to its parent within a range: IK, dragging, the "
                       "Joints slider, pasting and playback respect it")
    boxes = (CheckedDoubleSpinBox(label="Minimum angle"), CheckedDoubleSpinBox(label="Maximum angle"))
    for box, name, tip in zip(boxes, ("jointLimitMin", "jointLimitMax"),
                              ("the smallest local angle (counter-clockwise positive)",
                               "the largest local angle (counter-clockwise positive)")):
        box.setObjectName(name)
        box.setRange(-LIMIT_RANGE_DEGREES, LIMIT_RANGE_DEGREES)
        box.setDecimals(2)
        box.setSuffix("°")
        box.setSingleStep(5.0)
        box.setKeyboardTracking(False)
        box.setToolTip(tip)
    form.addRow("Limits", enabled)
    form.addRow("Minimum angle", boxes[0])
    form.addRow("Maximum angle", boxes[1])
    panel.editors["joint_limits"] = enabled

    def current() -> tuple[float, float] | None:
        return character2d.joint_limits(doc, asset)[index]

    def free_range() -> tuple[float, float]:
        """What the fields offer while the joint is free: ±90° widened to the angle shown."""
        a = math.degrees(float(np.asarray(character2d.joint_angles(doc, asset, panel.ctx.time, block=False))[index]))
        return min(-90.0, math.floor(a)), max(90.0, math.ceil(a))

    def refresh() -> None:
        limit = current()
        shown = free_range() if limit is None else (math.degrees(limit[0]), math.degrees(limit[1]))
        for w in (enabled, *boxes):
            w.blockSignals(True)
        enabled.setChecked(limit is not None)
        for box, value in zip(boxes, shown):
            box.setEnabled(limit is not None)
            box.setValue(value)
        for w in (enabled, *boxes):
            w.blockSignals(False)

    def toggled(on: bool) -> None:
        if on:
            lo, hi = boxes[0].value(), boxes[1].value()
            if lo > hi:
                lo, hi = free_range()
            command = character2d.set_joint_limits_command(doc, asset, index, math.radians(lo), math.radians(hi))
        else:
            command = character2d.set_joint_limits_command(doc, asset, index, None, None)
        panel.ctx.push(command)

    def edited(which: int) -> None:
        limit = current()
        if limit is None:
            return
        bounds = list(limit)
        bounds[which] = math.radians(boxes[which].value())
        if bounds[0] > bounds[1]:
            refresh()
            boxes[which].refuse("The minimum angle cannot be above the maximum angle.")
            return
        if tuple(bounds) != limit:
            panel.ctx.push(character2d.set_joint_limits_command(doc, asset, index, bounds[0], bounds[1]))

    enabled.toggled.connect(toggled)
    boxes[0].valueChanged.connect(lambda _v: edited(0))
    boxes[1].valueChanged.connect(lambda _v: edited(1))
    panel.refreshers.append(refresh)


def character2d_group(panel: PanelForm, asset: str) -> QGroupBox:
    doc = panel.ctx.doc
    character = doc.runtime[asset]
    group = QGroupBox(f"Character: {asset}")
    group.setObjectName("characterProperties")
    form = QFormLayout(group)
    source = doc.assets[asset].source
    src = QLabel(Path(source).name if source else "—")
    src.setToolTip(source or "")
    form.addRow("Source", src)
    form.addRow("Joints", QLabel(f"{len(character.joints)} ({int(character.dynamic.sum())} dynamic)"))
    mass = sum(j.mass for j in character.joints)
    form.addRow("Total mass", QLabel(f"{mass:.6g}"))

    def position() -> str:
        t = character2d.translation(doc, asset, panel.ctx.time)
        return f"({t[0]:.2f}, {t[1]:.2f})"

    def velocity() -> str:
        t = character2d.translation(doc, asset, panel.ctx.time, 1)
        return f"({t[0]:.2f}, {t[1]:.2f}) /s"

    panel.label(form, "Position", position, "characterPosition")
    panel.label(form, "Velocity", velocity, "characterVelocity")
    key_all = character2d.KEY_ALL_PARAMETER
    panel.parameter_editor(form, "Key every joint (universal keyframe)", key_all, False)
    return group
