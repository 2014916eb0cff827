"""The properties dock's simulation settings: the IK solver, a 2D character's pendulums and springs.

Labels in the animator's words, tool tips that keep the physics and course names, units,
ranges and choices come from the parameter schema (qtanimator.document.parameters IK,
PENDULUM, SPRING); a preset is one command (``character2d.set_pendulum_preset``,
``character2d.set_spring_preset``), every field a SetParameter.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from typing import Any

from PySide6.QtWidgets import QCheckBox, QComboBox, QDoubleSpinBox, QFormLayout, QGroupBox, QLabel, QWidget

from qtanimator.document import character2d
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
    from qtanimator.core.pendulum import PRESETS

    group = QGroupBox("Pendulums")
    group.setObjectName("pendulumProperties")
    form = QFormLayout(group)
    preset = QComboBox()
    preset.setObjectName("pendulumPreset")
    preset.addItems(list(PRESETS))
    preset.addItem("custom")

    def current_preset() -> str:
        params = character2d.pendulum_params(doc, asset)
        for name, p in PRESETS.items():
            if p == params:
                return name
        return "custom"

    def apply_preset(name: str) -> None:
        if name in PRESETS and name != current_preset():
            panel.ctx.push(character2d.set_pendulum_preset(doc, asset, name))

    def refresh_preset() -> None:
        preset.blockSignals(True)
        preset.setCurrentText(current_preset())
        preset.blockSignals(False)

    preset.currentTextChanged.connect(apply_preset)
    panel.refreshers.append(refresh_preset)
    panel.editors["preset"] = preset
    form.addRow("Preset", preset)
    for key, param in PENDULUM.items():
        path = PENDULUM.path(key, asset)
        default = getattr(character2d.pendulum_params(doc, asset), key)
        editor = panel.parameter_editor(form, param.label, path, default, check=_pendulum_check(panel, asset, key),
                                        param=param)
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


def _pendulum_check(panel: PanelForm, asset: str, name: str) -> Callable[[Any], str | None]:
    """The pendulum parameters' own validation (``PendulumParams``) as a field check."""
    doc = panel.ctx.doc

    def check(value: Any) -> str | None:
        try:
            replace(character2d.pendulum_params(doc, asset), **{name: value})
        except (TypeError, ValueError) as exc:
            return str(exc)
        return None

    return check


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
    from qtanimator.core.spring_joint import SPRING_PRESETS

    group = QGroupBox("Springs")
    group.setObjectName("springProperties")
    form = QFormLayout(group)
    preset = QComboBox()
    preset.setObjectName("springPreset")
    preset.addItems([*SPRING_PRESETS, "custom"])

    def current_preset() -> str:
        params = character2d.spring_params(doc, asset)
        return next((name for name, p in SPRING_PRESETS.items() if p == params), "custom")

    def apply_preset(name: str) -> None:
        if name in SPRING_PRESETS and name != current_preset():
            panel.ctx.push(character2d.set_spring_preset(doc, asset, name))

    def refresh_preset() -> None:
        preset.blockSignals(True)
        preset.setCurrentText(current_preset())
        preset.blockSignals(False)

    preset.currentTextChanged.connect(apply_preset)
    panel.refreshers.append(refresh_preset)
    panel.editors["spring_preset"] = preset
    form.addRow("Preset", preset)
    for key, param in SPRING.items():
        path = SPRING.path(key, asset)

        def check(value: Any, name: str = key) -> str | None:
            try:
                replace(character2d.spring_params(doc, asset), **{name: value})
            except (TypeError, ValueError) as exc:
                return str(exc)
            return None

        value = getattr(character2d.spring_params(doc, asset), key)
        editor = panel.parameter_editor(form, param.label, path, value, check=check, param=param)
        editor.setToolTip(tool_tip(param))

        def refresh(editor: QWidget = editor, name: str = key) -> None:
            if isinstance(editor, QDoubleSpinBox):
                editor.blockSignals(True)
                editor.setValue(float(getattr(character2d.spring_params(doc, asset), name)))
                editor.blockSignals(False)

        panel.refreshers.append(refresh)
    return group
