"""The properties dock's 3D group: the selected joint or skeleton of a 3D character.

Besides read-only facts (offset, limits) it edits asset properties, each change one undoable
command: a bone's collision radius for attached cloth, a BVH character's position
convention, the clip a glTF character plays and how rotations are keyed.
"""

from __future__ import annotations

import math

from PySide6.QtCore import QTimer
from PySide6.QtWidgets import QComboBox, QFormLayout, QGroupBox, QHBoxLayout, QLabel, QToolButton, QWidget

from qtanimator.document import character3d
from qtanimator.ui.clip_picker import ClipCombo, clip_characters
from qtanimator.ui.properties_form import PanelForm
from qtanimator.ui.widgets import CheckedDoubleSpinBox, format_number


def joint3d_group(panel: PanelForm, asset: str, joint: str) -> QGroupBox:
    doc = panel.ctx.doc
    group = QGroupBox(f"Joint: {joint}" if joint else f"Skeleton: {asset}")
    group.setObjectName("jointProperties")
    form = QFormLayout(group)
    skeleton = character3d.character(doc, asset).skeleton
    names = [j.name for j in skeleton.joints]
    if joint in names:
        j = skeleton.joints[names.index(joint)]
        form.addRow("Offset", QLabel("({:.3f}, {:.3f}, {:.3f})".format(*(float(v) for v in j.offset))))
        for axis, dof in zip("xyz", j.dofs):
            form.addRow(f"Limits {axis}", QLabel(_limits_text(float(dof.min), float(dof.max))))
        _capsule_radius_editor(panel, form, asset, joint)
    else:
        form.addRow("Joints", QLabel(str(len(names))))
    _bvh_positions_editor(panel, form, asset)
    _clip_editor(panel, form, asset)
    _rotation_mode_editor(panel, form, asset)
    return group


def _capsule_radius_editor(panel: PanelForm, form: QFormLayout, asset: str, joint: str) -> None:
    """The collision radius of the bone ending at ``joint`` (issue 14 item 5): the capsule
    from its parent to it that an attached cloth collides with. It shows the character's
    ``capsule_radii`` override or the skin's default (with a hint); a typed value and Reset
    are one undoable command each."""
    from qtanimator.document import cloth_attach as ca

    doc = panel.ctx.doc
    if doc.assets[asset].kind != character3d.ASSET_KIND:
        return
    defaults = ca.default_capsule_radii(character3d.character(doc, asset))  # once: it reads the whole skin
    if joint not in defaults:  # the root: no bone ends here
        return

    def override() -> float | None:
        value = (doc.assets[asset].properties.get(ca.CAPSULE_RADII) or {}).get(joint)
        return None if value is None else float(value)

    def shown() -> float:
        value = override()
        return defaults[joint] if value is None else value

    def push(radius: float | None) -> None:
        if radius is None and override() is None:
            return
        if radius is not None and (radius <= 0.0 or abs(shown() - radius) <= 1e-12):
            return
        command = ca.set_capsule_radius_command(doc, asset, joint, radius)
        # The change rebuilds this panel, deleting the field: push after its signal returns.
        QTimer.singleShot(0, lambda: panel.ctx.push(command))

    row = QWidget()
    layout = QHBoxLayout(row)
    layout.setContentsMargins(0, 0, 0, 0)
    box = CheckedDoubleSpinBox(label="Collision radius")
    box.setObjectName("capsuleRadius")
    box.setKeyboardTracking(False)
    box.setDecimals(4)
    box.setRange(1e-4, 1e4)
    magnitude = defaults[joint]
    box.setSingleStep(10 ** math.floor(math.log10(magnitude)) if magnitude > 0 else 0.01)
    box.setToolTip(f"Radius of the capsule around the bone ending at {joint} (from its parent joint), "
                   "which cloth attached to this character collides with. Default: the median distance "
                   f"of the skin to the bone ({format_number(defaults[joint])}).")
    box.valueChanged.connect(lambda v: push(float(v)))
    hint = QLabel()
    hint.setObjectName("capsuleRadiusHint")
    reset = QToolButton()
    reset.setObjectName("capsuleRadiusReset")
    reset.setText("Reset")
    reset.setToolTip("Go back to the radius from the skin")
    reset.clicked.connect(lambda: push(None))
    layout.addWidget(box, 1)
    layout.addWidget(hint)
    layout.addWidget(reset)
    form.addRow("Collision radius", row)
    panel.editors["capsule_radius"] = box

    def refresh() -> None:
        box.blockSignals(True)
        box.setValue(shown())
        box.blockSignals(False)
        overridden = override() is not None
        hint.setText("" if overridden else "default")
        reset.setEnabled(overridden)

    panel.refreshers.append(refresh)


def _bvh_positions_editor(panel: PanelForm, form: QFormLayout, asset: str) -> None:
    """A BVH character's position convention (issue 21): one undoable command per change."""
    doc = panel.ctx.doc
    current = character3d.bvh_positions(doc, asset)
    if current is None:
        return
    combo = QComboBox()
    combo.setObjectName("bvhPositions")
    combo.addItems(["relative", "absolute"])
    combo.setCurrentText(current)
    combo.setToolTip("How the file's root positions combine with the root's OFFSET: added (relative, "
                     "most mocap) or replacing it (absolute, Blender's exporter). Detected when the file "
                     "was opened.")

    def push(value: str) -> None:
        if value == character3d.bvh_positions(doc, asset):
            return
        try:
            command = character3d.set_bvh_positions_command(doc, asset, value)
        except (OSError, ValueError) as exc:  # FormatError is a ValueError: the file is gone or changed
            combo.blockSignals(True)
            combo.setCurrentText(str(character3d.bvh_positions(doc, asset)))
            combo.blockSignals(False)
            combo.setToolTip(f"Cannot switch: {exc}")
            return
        # The change rebuilds this panel, deleting the combo: push after its signal returns.
        QTimer.singleShot(0, lambda: panel.ctx.push(command))

    combo.currentTextChanged.connect(push)
    form.addRow("BVH positions", combo)
    panel.editors["bvh_positions"] = combo


def _clip_editor(panel: PanelForm, form: QFormLayout, asset: str) -> None:
    """The clip a glTF character plays (issue 21): one undoable command per choice. The
    combo shows the document; a change of the asset rebuilds this panel."""
    if asset not in clip_characters(panel.ctx.doc):
        return
    combo = ClipCombo(panel.ctx, asset, deferred=True)
    combo.setObjectName("characterClip")
    form.addRow("Clip", combo)
    panel.editors["clip"] = combo


def _rotation_mode_editor(panel: PanelForm, form: QFormLayout, asset: str) -> None:
    """How a 3D character's rotations are keyed (issue 21): quaternion curves (W X Y Z, as
    a glTF file has them) or Euler curves (X Y Z angles); one undoable conversion."""
    doc = panel.ctx.doc
    if doc.assets[asset].kind != character3d.ASSET_KIND:
        return
    combo = QComboBox()
    combo.setObjectName("rotationMode")
    combo.addItems(["quaternion", "euler"])
    combo.setCurrentText(character3d.rotation_mode(character3d.character(doc, asset)))
    combo.setToolTip("How rotations are keyed: quaternion curves (W, X, Y, Z; slerp between keys, as glTF "
                     "files have them) or Euler curves (X, Y, Z angles). Switching converts the keys, "
                     "exact at every key and frame.")

    def push(value: str) -> None:
        if value == character3d.rotation_mode(character3d.character(doc, asset)):
            return
        command = character3d.set_rotation_mode_command(doc, asset, value)
        # The change rebuilds this panel, deleting the combo: push after its signal returns.
        QTimer.singleShot(0, lambda: panel.ctx.push(command))

    combo.currentTextChanged.connect(push)
    form.addRow("Rotation keys", combo)
    panel.editors["rotation_mode"] = combo


def _limits_text(lo: float, hi: float) -> str:
    """Limits in degrees; the skeleton's "unlimited" defaults (huge values) read as none."""
    def one(v: float) -> str:
        return "none" if not math.isfinite(v) or abs(v) >= 1e3 else f"{math.degrees(v):.1f}°"
    if lo >= hi:
        return f"locked at {one(lo)}"
    return f"{one(lo)} … {one(hi)}"
