"""The properties dock's simulation settings: the IK solver, a 2D character's pendulums and springs.

Labels in the animator's words, tool tips that keep the physics and course names, units,
ranges and choices come from the parameter schema (qtanimator.document.parameters IK,
PENDULUM, SPRING); a preset is one command (``character2d.set_pendulum_preset``,
``character2d.set_spring_preset``), every field a SetParameter.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import replace
from typing import Any

from PySide6.QtWidgets import QCheckBox, QComboBox, QDoubleSpinBox, QFormLayout, QGroupBox, QLabel, QWidget

from qtanimator.core.pendulum_params import PRESETS
from qtanimator.core.spring_joint import SPRING_PRESETS
from qtanimator.document import character2d
from qtanimator.document.commands import Command
from qtanimator.document.parameters import IK, PENDULUM, SPRING
from qtanimator.ui.properties_form import PanelForm, tool_tip


def ik_group(panel: PanelForm) -> QGroupBox:
    group = QGroupBox("IK solver")
    group.setObjectName("ikProperties")
    form = QFormLayout(group)
    for path, param in IK.items():
        editor = panel.parameter_editor(form, param.label, path, param.default, param=param)
        editor.setToolTip(param.help)
    return group


def pendulum_group(panel: PanelForm, asset: str) -> QGroupBox:
    doc = panel.ctx.doc

    group = QGroupBox("Pendulums")
    group.setObjectName("pendulumProperties")
    form = QFormLayout(group)
    _preset_row(panel, form, "pendulumPreset", "preset", PRESETS,
                lambda: character2d.pendulum_params(doc, asset),
                lambda name: character2d.set_pendulum_preset(doc, asset, name))
    for key, param in PENDULUM.items():
        path = PENDULUM.path(key, asset)
        default = getattr(character2d.pendulum_params(doc, asset), key)
        check = _params_check(lambda: character2d.pendulum_params(doc, asset), key)
        editor = panel.parameter_editor(form, param.label, path, default, check=check, param=param)
        editor.setToolTip(tool_tip(param))
        # What is shown is the effective value (preset + overrides).
        panel.refreshers.append(_effective_refresher(panel, editor, asset, key))
    problem = QLabel()
    problem.setObjectName("pendulumProblem")
    problem.setWordWrap(True)
    problem.setStyleSheet("color: #c0392b;")

    def refresh_problem() -> None:
        report = character2d.simulation(doc).problem(asset)
        problem.setText("" if report is None else f"Stopped: {report.message}")
        problem.setVisible(report is not None)

    refresh_problem()
    panel.simulation_refreshers.append(refresh_problem)
    panel.refreshers.append(refresh_problem)
    form.addRow(problem)
    return group


def _params_check(params: Callable[[], Any], name: str) -> Callable[[Any], str | None]:
    """The constants' own validation (``PendulumParams``, ``SpringParams``) as a field check:
    the sentence of the error ``name = value`` raises, or None."""
    def check(value: Any) -> str | None:
        try:
            replace(params(), **{name: value})
        except (TypeError, ValueError) as exc:
            return str(exc)
        return None

    return check


def _preset_row(panel: PanelForm, form: QFormLayout, object_name: str, editor_key: str,
                presets: Mapping[str, Any], params: Callable[[], Any],
                command: Callable[[str], Command]) -> QComboBox:
    """A "Preset" row: the preset the current constants equal ("custom" when none); choosing
    one pushes ``command(name)`` (one undo step)."""
    preset = QComboBox()
    preset.setObjectName(object_name)
    preset.addItems([*presets, "custom"])

    def current() -> str:
        now = params()
        return next((name for name, p in presets.items() if p == now), "custom")

    def apply(name: str) -> None:
        if name in presets and name != current():
            panel.ctx.push(command(name))

    def refresh() -> None:
        preset.blockSignals(True)
        preset.setCurrentText(current())
        preset.blockSignals(False)

    preset.currentTextChanged.connect(apply)
    panel.refreshers.append(refresh)
    panel.editors[editor_key] = preset
    form.addRow("Preset", preset)
    return preset


def _effective_refresher(panel: PanelForm, editor: QWidget, asset: str, name: str) -> Callable[[], None]:
    doc = panel.ctx.doc

    def refresh() -> None:
        value = getattr(character2d.pendulum_params(doc, asset), name)
        editor.blockSignals(True)
        if isinstance(editor, QComboBox):
            editor.setCurrentText(str(value))
        elif isinstance(editor, QCheckBox):
            editor.setChecked(bool(value))
        elif isinstance(editor, QDoubleSpinBox):
            editor.setValue(float(value))
        editor.blockSignals(False)

    return refresh


def spring_group(panel: PanelForm, asset: str) -> QGroupBox:
    """The character's spring constants: a preset and each value (document parameters
    ``<asset>.spring.<name>``)."""
    doc = panel.ctx.doc

    group = QGroupBox("Springs")
    group.setObjectName("springProperties")
    form = QFormLayout(group)
    _preset_row(panel, form, "springPreset", "spring_preset", SPRING_PRESETS,
                lambda: character2d.spring_params(doc, asset),
                lambda name: character2d.set_spring_preset(doc, asset, name))
    for key, param in SPRING.items():
        path = SPRING.path(key, asset)

        value = getattr(character2d.spring_params(doc, asset), key)
        check = _params_check(lambda: character2d.spring_params(doc, asset), key)
        editor = panel.parameter_editor(form, param.label, path, value, check=check, param=param)
        editor.setToolTip(tool_tip(param))

        def refresh(editor: QWidget = editor, name: str = key) -> None:
            if isinstance(editor, QDoubleSpinBox):
                editor.blockSignals(True)
                editor.setValue(float(getattr(character2d.spring_params(doc, asset), name)))
                editor.blockSignals(False)

        panel.refreshers.append(refresh)
    return group
