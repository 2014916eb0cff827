"""What every group of the properties dock builds with: one :class:`PanelForm` per rebuild.

A form holds what the groups register while they are built (the refreshers run when the
document or the frame changes, those run when a simulation catches up, the editors by
name) and the two field kinds most groups use: a read-only label and a document-parameter
editor built from the parameter schema (``ui/param_fields.py``), whose every change is a
SetParameter.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QCheckBox, QComboBox, QFormLayout, QLabel, QWidget

from qtanimator.document.commands import SetParameter
from qtanimator.document.parameters import Param
from qtanimator.ui.context import EditorContext
from qtanimator.ui.param_fields import editor_for, spin_for
from qtanimator.ui.widgets import CheckedDoubleSpinBox, CheckedSpinBox


class PanelForm:
    """The state one rebuild of the properties dock fills, and the shared field builders.

    ``owner`` is the dock's panel (its window shows refusals in the status bar),
    ``rebuild`` and ``refresh`` are the panel's own (a refused value refreshes the whole
    panel; a refused joint mode rebuilds it)."""

    def __init__(self, ctx: EditorContext, owner: QWidget, rebuild: Callable[[], None],
                 refresh: Callable[[], None]) -> None:
        self.ctx = ctx
        self.owner = owner
        self.rebuild = rebuild
        self.refresh = refresh
        self.refreshers: list[Callable[[], None]] = []
        self.simulation_refreshers: list[Callable[[], None]] = []
        self.editors: dict[str, QWidget] = {}

    def label(self, form: QFormLayout, title: str, value: Callable[[], str], name: str) -> QLabel:
        label = QLabel()
        label.setObjectName(name)
        label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        form.addRow(title, label)

        def refresh() -> None:
            try:
                label.setText(value())
            except (KeyError, IndexError, ValueError):
                label.setText("—")

        self.refreshers.append(refresh)
        return label

    def parameter_editor(self, form: QFormLayout, title: str, path: str, default: Any,
                         choices: list[str] | None = None, decimals: int = 4,
                         check: Callable[[Any], str | None] | None = None,
                         param: Param | None = None) -> QWidget:
        """An editor for one document parameter; every change is a SetParameter.

        With a schema ``param`` the field is built from it (``param_fields``: kind, range,
        step, decimals, choices, reasons); without, from ``default``'s type. ``check(value)``
        gives the reason a value is refused (None: accepted): the parameter's own definition
        decides (e.g. :class:`PendulumParams`), after the schema's range (``SetParameter``
        validates too); a refused value leaves the document as it was and the field says why."""
        doc = self.ctx.doc
        name = "param_" + path.replace(".", "_")
        widget: QWidget
        if param is not None:
            kind = param.kind
            choices = list(param.choices) if kind == "choice" else None
        else:
            kind = ("choice" if choices is not None else "bool" if isinstance(default, bool)
                    else "int" if isinstance(default, int) else "float")

        def current() -> Any:
            return doc.parameter(path, default)

        def push(value: Any) -> None:
            reason = check(value) if check is not None else None
            if reason is not None:
                self.refresh()  # the field shows the document's value again...
                if isinstance(widget, (CheckedSpinBox, CheckedDoubleSpinBox)):
                    widget.refuse(f"{title}: {reason}")  # ...and why the typed one was refused
                return
            if current() != value:
                try:
                    command = SetParameter(doc, path, value, text=f"Set {title}", gesture=("properties", path,
                                                                                          object()))
                except ValueError as exc:  # the schema refuses it
                    self.refresh()
                    if isinstance(widget, (CheckedSpinBox, CheckedDoubleSpinBox)):
                        widget.refuse(str(exc))
                    return
                self.ctx.push(command)

        if kind == "choice":
            if param is not None:
                combo = editor_for(param)
                assert isinstance(combo, QComboBox)
            else:
                combo = QComboBox()
                combo.addItems(choices or [])
            combo.currentTextChanged.connect(push)

            def refresh_combo() -> None:
                combo.blockSignals(True)
                combo.setCurrentText(str(current()))
                combo.blockSignals(False)

            self.refreshers.append(refresh_combo)
            widget = combo
        elif kind == "bool":
            box = QCheckBox()
            box.toggled.connect(lambda on: push(bool(on)))

            def refresh_check() -> None:
                box.blockSignals(True)
                box.setChecked(bool(current()))
                box.blockSignals(False)

            self.refreshers.append(refresh_check)
            widget = box
        elif kind == "int":
            spin: CheckedSpinBox
            if param is not None:
                made = spin_for(param, label=title)
                assert isinstance(made, CheckedSpinBox)
                spin = made
            else:
                spin = CheckedSpinBox(label=title)
                spin.setRange(0, 1_000_000)
                spin.setKeyboardTracking(False)
            spin.valueChanged.connect(lambda v: push(int(v)))

            def refresh_int() -> None:
                spin.blockSignals(True)
                spin.setValue(int(current()))
                spin.blockSignals(False)

            self.refreshers.append(refresh_int)
            widget = spin
        else:
            dspin: CheckedDoubleSpinBox
            if param is not None:
                dmade = spin_for(param, label=title)
                assert isinstance(dmade, CheckedDoubleSpinBox)
                dspin = dmade
            else:
                dspin = CheckedDoubleSpinBox(label=title)
                dspin.setDecimals(decimals if abs(float(default)) >= 1e-3 or default == 0 else 9)
                dspin.setRange(-1e9, 1e9)
                dspin.setKeyboardTracking(False)
                magnitude = abs(float(default)) or 1.0
                dspin.setSingleStep(10 ** math.floor(math.log10(magnitude)))
            dspin.valueChanged.connect(lambda v: push(float(v)))

            def refresh_float() -> None:
                dspin.blockSignals(True)
                dspin.setValue(float(current()))
                dspin.blockSignals(False)

            self.refreshers.append(refresh_float)
            widget = dspin
        widget.setObjectName(name)
        self.editors[path] = widget
        form.addRow(title, widget)
        return widget


def tool_tip(param: Param) -> str:
    """A schema field's tool tip: its help, its unit and its default."""
    default = f"{param.default:.6g}" if isinstance(param.default, float) else repr(param.default)
    unit = f" {param.unit}" if param.unit else ""
    return f"{param.help} (default {default}{unit})" if param.help else f"default {default}{unit}"
