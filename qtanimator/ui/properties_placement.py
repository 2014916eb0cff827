"""The properties dock's placement group: a character's authored translate, rotate and scale."""

from __future__ import annotations

from PySide6.QtCore import QTimer
from PySide6.QtWidgets import QDoubleSpinBox, QFormLayout, QGroupBox

from qtanimator.ui.properties_form import PanelForm
from qtanimator.ui.widgets import CheckedDoubleSpinBox


def placement_group(panel: PanelForm, asset: str, dims: int) -> QGroupBox:
    """The character's authored placement (issue 14): translate, rotate (degrees; one angle
    in 2D, X Y Z in 3D) and a uniform scale. Each typed value is one undo step."""
    from qtanimator.document import placement as pl

    doc = panel.ctx.doc
    group = QGroupBox("Placement")
    group.setObjectName("placementProperties")
    form = QFormLayout(group)
    axes = "xyz"[:dims]
    fields: list[tuple[str, int | None, str, str]] = [
        ("translate", i, f"Translate {a.upper()}", f"placementTranslate{a.upper()}") for i, a in enumerate(axes)]
    if dims == 2:
        fields.append(("rotate", None, "Rotate", "placementRotate"))
    else:
        fields += [("rotate", i, f"Rotate {a.upper()}", f"placementRotate{a.upper()}") for i, a in enumerate(axes)]
    fields.append(("scale", None, "Scale", "placementScale"))
    boxes: list[tuple[QDoubleSpinBox, str, int | None]] = []

    def shown(field: str, index: int | None) -> float:
        value = pl.placement_of(doc, asset, dims)[field]
        return float(value if index is None else value[index])

    def push(field: str, index: int | None, value: float) -> None:
        if field == "scale" and value <= 0.0:
            return
        if abs(shown(field, index) - value) <= 1e-12:
            return
        command = pl.set_field_command(doc, asset, dims, field, index, value)
        # The change rebuilds this panel, deleting the field: push after its signal returns.
        QTimer.singleShot(0, lambda: panel.ctx.push(command))

    for field, index, title, name in fields:
        box = CheckedDoubleSpinBox(label=title)
        box.setObjectName(name)
        box.setKeyboardTracking(False)
        box.setDecimals(4 if field == "scale" else 3)
        if field == "scale":
            box.setRange(1e-4, 1e4)
            box.setSingleStep(0.1)
        elif field == "rotate":
            box.setRange(-3600.0, 3600.0)
            box.setSuffix("°")
            box.setSingleStep(5.0)
        else:
            box.setRange(-1e7, 1e7)
            box.setSingleStep(10.0 if dims == 2 else 0.1)
        box.valueChanged.connect(lambda v, f=field, i=index: push(f, i, float(v)))
        form.addRow(title, box)
        panel.editors[name] = box
        boxes.append((box, field, index))

    def refresh() -> None:
        for box, field, index in boxes:
            box.blockSignals(True)
            box.setValue(shown(field, index))
            box.blockSignals(False)

    panel.refreshers.append(refresh)
    return group
