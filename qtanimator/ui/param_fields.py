"""Fields built from the parameter schema (:mod:`qtanimator.document.parameters`).

:func:`editor_for` makes the field of one :class:`~qtanimator.document.parameters.Param`: a
combo box for a choice, a check box for a bool, a checked spin box (refusing typed values
beyond the range with the reason, :mod:`qtanimator.ui.widgets`) for a number, a row of them
for a vector. :func:`spin_for` makes one spin box (also one component of a vector). The
range, step, decimals, special minimum text, the reasons and the tool tip all come from the
Param; the caller names the widget (object names are interface) and connects it.
"""

from __future__ import annotations

from typing import Any

from PySide6.QtWidgets import QCheckBox, QComboBox, QHBoxLayout, QWidget

from qtanimator.document.parameters import Param
from qtanimator.ui.widgets import CheckedDoubleSpinBox, CheckedSpinBox

#: How large a number an int field can hold (a QSpinBox is 32-bit).
_INT_LIMIT = 2**31 - 1


class _ReasonBelow:
    """Adds ``reason_below`` to a refusal for a value below the minimum."""

    reason_below = ""

    def refuse(self, reason: str) -> None:
        if self.reason_below and ("below the smallest value" in reason or "cannot be negative" in reason):
            reason = f"{reason.rstrip('.')} ({self.reason_below})."
        super().refuse(reason)  # type: ignore[misc]


class ParamSpinBox(_ReasonBelow, CheckedSpinBox):
    """A :class:`CheckedSpinBox` of an int Param."""


class ParamDoubleSpinBox(_ReasonBelow, CheckedDoubleSpinBox):
    """A :class:`CheckedDoubleSpinBox` of a float Param (or a vector's component)."""


def spin_for(param: Param, parent: QWidget | None = None, name: str = "",
             label: str = "") -> ParamSpinBox | ParamDoubleSpinBox:
    """A checked spin box with ``param``'s range, step, decimals, special minimum text and
    reasons (for a vector or colour: one component). ``label`` names the field in refusals
    (default: the Param's label); ``name`` is its object name. Typed values are one edit on
    Enter (no keyboard tracking)."""
    box: ParamSpinBox | ParamDoubleSpinBox
    if param.kind == "int":
        box = ParamSpinBox(parent, label=label or param.label)
        lo = -_INT_LIMIT if param.minimum is None else int(max(param.minimum, -_INT_LIMIT))
        hi = _INT_LIMIT if param.maximum is None else int(min(param.maximum, _INT_LIMIT))
        box.setRange(lo, hi)
        box.setSingleStep(int(param.step or 1))
    else:
        box = ParamDoubleSpinBox(parent, label=label or param.label)
        if param.decimals is not None:
            box.setDecimals(param.decimals)  # before the range: the range is rounded to the decimals
        box.setRange(-1e9 if param.minimum is None else float(param.minimum),
                     1e9 if param.maximum is None else float(param.maximum))
        if param.step is not None:
            box.setSingleStep(float(param.step))
    if param.special_minimum:
        box.setSpecialValueText(param.special_minimum)
    box.why_max = param.reason
    box.reason_below = param.reason_below
    if name:
        box.setObjectName(name)
    if param.help:
        box.setToolTip(param.help)
    box.setKeyboardTracking(False)
    return box


class VectorField(QWidget):
    """A row of spin boxes, one per component of a vector or colour Param (``spins``)."""

    def __init__(self, param: Param, parent: QWidget | None = None, name: str = "",
                 axes: str = "xyz") -> None:
        super().__init__(parent)
        row = QHBoxLayout(self)
        row.setContentsMargins(0, 0, 0, 0)
        self.spins: list[ParamSpinBox | ParamDoubleSpinBox] = []
        for axis in axes[:param.size]:
            s = spin_for(param, self, f"{name}_{axis}" if name else "", f"{param.label} {axis}")
            row.addWidget(s)
            self.spins.append(s)

    def values(self) -> list[float]:
        return [float(s.value()) for s in self.spins]

    def set_values(self, values: Any) -> None:
        for s, v in zip(self.spins, values):
            if isinstance(s, ParamSpinBox):
                s.setValue(int(v))
            else:
                s.setValue(float(v))


def editor_for(param: Param, parent: QWidget | None = None, name: str = "") -> QWidget:
    """The field of ``param``: QComboBox (choice), QCheckBox (bool), a checked spin box (int,
    float) or a :class:`VectorField` (vector, colour); ``name`` is its object name (a
    vector's components are ``<name>_x``…). Signals are the caller's to connect."""
    widget: QWidget
    if param.kind == "choice":
        combo = QComboBox(parent)
        combo.addItems(list(param.choices))
        widget = combo
    elif param.kind == "bool":
        widget = QCheckBox(parent)
    elif param.kind in ("int", "float"):
        widget = spin_for(param, parent)
    elif param.kind in ("vector", "color"):
        widget = VectorField(param, parent, name, "xyz" if param.kind == "vector" else "rgb")
    else:
        raise ValueError(f"no field for the {param.kind} parameter {param.key!r}")
    if name:
        widget.setObjectName(name)
    if param.help and not widget.toolTip():
        widget.setToolTip(param.help)
    return widget


__all__ = ["ParamDoubleSpinBox", "ParamSpinBox", "VectorField", "editor_for", "spin_for"]
