"""The properties dock: the selected joint (with its limits) and character, pendulum parameters, IK settings.

Everything editable is a document parameter changed through a command (SetParameter, or
``character2d.set_pendulum_preset`` for a preset), or an asset property changed through its
own command (a BVH character's position convention, the clip a glTF character plays, the
collision radius of a 3D character's bone that attached cloth collides with), so it
is undoable and saved with the project. Read-only facts (mass, inertia, pivot…) are shown as labels.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from PySide6.QtCore import Qt, QTimer
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDoubleSpinBox,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QScrollArea,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from qtanimator.document import character2d, character3d
from qtanimator.document.character2d import ik_setting
from qtanimator.document.commands import SetParameter
from qtanimator.document.document import DocumentChange
from qtanimator.document.parameters import IK, PENDULUM, SPRING, Param
from qtanimator.ui.clip_picker import ClipCombo, clip_characters
from qtanimator.ui.context import EditorContext
from qtanimator.ui.param_fields import editor_for, spin_for
from qtanimator.ui.widgets import CheckedDoubleSpinBox, CheckedSpinBox, format_number

if TYPE_CHECKING:
    from qtanimator.ui.main_window import MainWindow

# Labels in the animator's words, tool tips that keep the physics and course names, units,
# ranges and choices of the IK, pendulum and spring settings: the parameter schema
# (qtanimator.document.parameters IK, PENDULUM, SPRING).
#: What drives a 2D joint, in the animator's words (``rigging.JOINT_MODES``).
JOINT_MODE_LABELS = {"keyframed": "Keys", "dynamic": "Pendulum (physics)", "spring": "Spring (follows keys)"}
#: How far the joint limit fields go either way (degrees): two turns.
LIMIT_RANGE_DEGREES = 720.0


class PropertiesPanel(QWidget):
    """A form rebuilt when the selection changes; values refresh on document events."""

    def __init__(self, ctx: EditorContext, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("propertiesPanel")
        self.ctx = ctx
        outer = QVBoxLayout(self)
        outer.setContentsMargins(0, 0, 0, 0)
        self.scroll_area = QScrollArea(self)
        self.scroll_area.setWidgetResizable(True)
        outer.addWidget(self.scroll_area)
        self.body: QWidget | None = None
        self._simulation_refreshers: list[Callable[[], None]] = []
        self._refreshers: list[Callable[[], None]] = []
        self.editors: dict[str, QWidget] = {}
        ctx.selectionChanged.connect(lambda _a, _j: self.rebuild())
        ctx.documentReset.connect(self.rebuild)
        ctx.documentChanged.connect(self._on_document)
        ctx.frameChanged.connect(lambda _f: self.refresh())
        ctx.simulationProgressed.connect(self._simulation_progressed)
        self.rebuild()

    # ------------------------------------------------------------ structure
    def _on_document(self, change: DocumentChange) -> None:
        if change.assets:
            self.rebuild()
        elif self._shows_changed(change):
            self.refresh()

    def _shows_changed(self, change: DocumentChange) -> bool:
        """True when the change touches what the dock shows: the selected asset's channels
        or any parameter (IK, pendulum and project settings are shown for every selection)."""
        if change.parameters:
            return True
        asset = self.ctx.selection[0]
        return bool(asset) and asset in change.channel_assets()

    def _simulation_progressed(self) -> None:
        for fn in self._simulation_refreshers:
            fn()

    def refresh(self) -> None:
        for fn in self._refreshers:
            fn()

    def rebuild(self) -> None:
        self._refreshers = []
        self._simulation_refreshers = []
        self.editors = {}
        body = QWidget()
        layout = QVBoxLayout(body)
        asset, joint = self.ctx.selection
        doc = self.ctx.doc
        kind = doc.assets[asset].kind if asset in doc.assets else ""
        if kind == character2d.ASSET_KIND and asset in doc.runtime:
            if joint:
                layout.addWidget(self._joint2d_group(asset, joint))
            layout.addWidget(self._character2d_group(asset))
            if bool(doc.runtime[asset].simulated.any()):
                layout.addWidget(self._pendulum_group(asset))
            if bool(doc.runtime[asset].spring.any()):
                layout.addWidget(self._spring_group(asset))
            layout.addWidget(self._placement_group(asset, 2))
        elif kind == character3d.ASSET_KIND and asset in doc.runtime:
            layout.addWidget(self._joint3d_group(asset, joint))
            layout.addWidget(self._placement_group(asset, 3))
        elif not asset:
            label = QLabel("Select a joint or a character.")
            label.setObjectName("propertiesHint")
            layout.addWidget(label)
        layout.addWidget(self._ik_group())
        layout.addStretch(1)
        self.scroll_area.setWidget(body)  # deletes the previous body
        self.body = body
        self.refresh()

    # -------------------------------------------------------------- helpers
    def _label(self, form: QFormLayout, title: str, value: Callable[[], str], name: str) -> QLabel:
        label = QLabel()
        label.setObjectName(name)
        label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        form.addRow(title, label)

        def refresh() -> None:
            try:
                label.setText(value())
            except (KeyError, IndexError, ValueError):
                label.setText("—")

        self._refreshers.append(refresh)
        return label

    def _parameter_editor(self, form: QFormLayout, title: str, path: str, default: Any,
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

            self._refreshers.append(refresh_combo)
            widget = combo
        elif kind == "bool":
            box = QCheckBox()
            box.toggled.connect(lambda on: push(bool(on)))

            def refresh_check() -> None:
                box.blockSignals(True)
                box.setChecked(bool(current()))
                box.blockSignals(False)

            self._refreshers.append(refresh_check)
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

            self._refreshers.append(refresh_int)
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

            self._refreshers.append(refresh_float)
            widget = dspin
        widget.setObjectName(name)
        self.editors[path] = widget
        form.addRow(title, widget)
        return widget

    # ---------------------------------------------------------------- groups
    def _joint2d_group(self, asset: str, joint: str) -> QGroupBox:
        doc = self.ctx.doc
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
        form.addRow("Driven by", self._joint_mode_editor(asset, joint, index))
        form.addRow("Pivot (rest)", QLabel(f"({j.pivot[0]:.2f}, {j.pivot[1]:.2f})"))
        form.addRow("Shapes", QLabel(str(len(j.shapes))))
        form.addRow("Mass", QLabel(f"{j.mass:.6g}"))
        form.addRow("Moment of inertia", QLabel(f"{j.inertia:.6g}"))
        com = j.centroid
        form.addRow("Centre of mass", QLabel(f"({com[0]:.2f}, {com[1]:.2f})"))
        form.addRow("Pendulum length L", QLabel(f"{float(np.hypot(*(com - j.pivot))):.3f}"))

        def angle() -> str:
            a = float(np.asarray(character2d.joint_angles(doc, asset, self.ctx.time, block=False))[index])
            return f"{math.degrees(a):.3f}°"

        self._label(form, "Angle (local)", angle, "jointAngle")
        if j.is_dynamic or j.is_spring:  # the simulation catching up changes it too
            self._simulation_refreshers.append(self._refreshers[-1])
        self._joint_limits_editor(form, asset, index)
        return group

    def _joint_limits_editor(self, form: QFormLayout, asset: str, index: int) -> None:
        """A 2D joint's limits on its local angle, in degrees: the check box turns them on
        (with a range that holds the angle shown) or off, the fields edit one bound each;
        every change is one undo step (``character2d.set_joint_limits_command``)."""
        doc = self.ctx.doc
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
        self.editors["joint_limits"] = enabled

        def current() -> tuple[float, float] | None:
            return character2d.joint_limits(doc, asset)[index]

        def free_range() -> tuple[float, float]:
            """What the fields offer while the joint is free: ±90° widened to the angle shown."""
            a = math.degrees(float(np.asarray(character2d.joint_angles(doc, asset, self.ctx.time, block=False))[index]))
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
            self.ctx.push(command)

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
                self.ctx.push(character2d.set_joint_limits_command(doc, asset, index, bounds[0], bounds[1]))

        enabled.toggled.connect(toggled)
        boxes[0].valueChanged.connect(lambda _v: edited(0))
        boxes[1].valueChanged.connect(lambda _v: edited(1))
        self._refreshers.append(refresh)

    def _character2d_group(self, asset: str) -> QGroupBox:
        doc = self.ctx.doc
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
            t = character2d.translation(doc, asset, self.ctx.time)
            return f"({t[0]:.2f}, {t[1]:.2f})"

        def velocity() -> str:
            t = character2d.translation(doc, asset, self.ctx.time, 1)
            return f"({t[0]:.2f}, {t[1]:.2f}) /s"

        self._label(form, "Position", position, "characterPosition")
        self._label(form, "Velocity", velocity, "characterVelocity")
        key_all = character2d.KEY_ALL_PARAMETER
        self._parameter_editor(form, "Key every joint (universal keyframe)", key_all, False)
        return group

    def _pendulum_group(self, asset: str) -> QGroupBox:
        doc = self.ctx.doc
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
                self.ctx.push(character2d.set_pendulum_preset(doc, asset, name))

        def refresh_preset() -> None:
            preset.blockSignals(True)
            preset.setCurrentText(current_preset())
            preset.blockSignals(False)

        preset.currentTextChanged.connect(apply_preset)
        self._refreshers.append(refresh_preset)
        self.editors["preset"] = preset
        form.addRow("Preset", preset)
        for key, param in PENDULUM.items():
            path = PENDULUM.path(key, asset)
            default = getattr(character2d.pendulum_params(doc, asset), key)
            editor = self._parameter_editor(form, param.label, path, default, check=self._pendulum_check(asset, key),
                                            param=param)
            editor.setToolTip(_tool_tip(param))
            # What is shown is the effective value (preset + overrides).
            self._refreshers.append(self._effective_refresher(editor, asset, key))
        problem = QLabel()
        problem.setObjectName("pendulumProblem")
        problem.setWordWrap(True)
        problem.setStyleSheet("color: #c0392b;")

        def refresh_problem() -> None:
            report = character2d.simulation(doc).problem(asset)
            problem.setText("" if report is None else f"Stopped: {report.message}")
            problem.setVisible(report is not None)

        refresh_problem()
        self._simulation_refreshers.append(refresh_problem)
        self._refreshers.append(refresh_problem)
        form.addRow(problem)
        return group

    def _joint_mode_editor(self, asset: str, joint: str, index: int) -> QComboBox:
        """Keys, a pendulum or a spring: one undo step (``rigging.set_joint_mode_command``);
        a refusal (the root cannot swing) goes to the status bar."""
        from qtanimator.document import rigging

        doc = self.ctx.doc
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
                window = self.window()
                bar = getattr(window, "statusBar", None)
                if callable(bar):
                    bar().showMessage(str(exc), 5000)
                QTimer.singleShot(0, self.rebuild)
                return
            # After the combo's signal returns: the change rebuilds this panel, combo included.
            QTimer.singleShot(0, lambda: self.ctx.push(command))

        combo.currentIndexChanged.connect(chosen)
        self.editors["joint_mode"] = combo
        return combo

    def _spring_group(self, asset: str) -> QGroupBox:
        """The character's spring constants: a preset and each value (document parameters
        ``<asset>.spring.<name>``)."""
        doc = self.ctx.doc
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
                self.ctx.push(character2d.set_spring_preset(doc, asset, name))

        def refresh_preset() -> None:
            preset.blockSignals(True)
            preset.setCurrentText(current_preset())
            preset.blockSignals(False)

        preset.currentTextChanged.connect(apply_preset)
        self._refreshers.append(refresh_preset)
        self.editors["spring_preset"] = preset
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
            editor = self._parameter_editor(form, param.label, path, value, check=check, param=param)
            editor.setToolTip(_tool_tip(param))

            def refresh(editor: QWidget = editor, name: str = key) -> None:
                if isinstance(editor, QDoubleSpinBox):
                    editor.blockSignals(True)
                    editor.setValue(float(getattr(character2d.spring_params(doc, asset), name)))
                    editor.blockSignals(False)

            self._refreshers.append(refresh)
        return group

    def _pendulum_check(self, asset: str, name: str) -> Callable[[Any], str | None]:
        """The pendulum parameters' own validation (``PendulumParams``) as a field check."""
        doc = self.ctx.doc

        def check(value: Any) -> str | None:
            try:
                replace(character2d.pendulum_params(doc, asset), **{name: value})
            except (TypeError, ValueError) as exc:
                return str(exc)
            return None

        return check

    def _effective_refresher(self, editor: QWidget, asset: str, name: str) -> Callable[[], None]:
        doc = self.ctx.doc

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

    def _joint3d_group(self, asset: str, joint: str) -> QGroupBox:
        doc = self.ctx.doc
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
            self._capsule_radius_editor(form, asset, joint)
        else:
            form.addRow("Joints", QLabel(str(len(names))))
        self._bvh_positions_editor(form, asset)
        self._clip_editor(form, asset)
        self._rotation_mode_editor(form, asset)
        return group

    def _capsule_radius_editor(self, form: QFormLayout, asset: str, joint: str) -> None:
        """The collision radius of the bone ending at ``joint`` (issue 14 item 5): the capsule
        from its parent to it that an attached cloth collides with. It shows the character's
        ``capsule_radii`` override or the skin's default (with a hint); a typed value and Reset
        are one undoable command each."""
        from qtanimator.document import cloth_attach as ca

        doc = self.ctx.doc
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
            QTimer.singleShot(0, lambda: self.ctx.push(command))

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
        self.editors["capsule_radius"] = box

        def refresh() -> None:
            box.blockSignals(True)
            box.setValue(shown())
            box.blockSignals(False)
            overridden = override() is not None
            hint.setText("" if overridden else "default")
            reset.setEnabled(overridden)

        self._refreshers.append(refresh)

    def _placement_group(self, asset: str, dims: int) -> QGroupBox:
        """The character's authored placement (issue 14): translate, rotate (degrees; one angle
        in 2D, X Y Z in 3D) and a uniform scale. Each typed value is one undo step."""
        from qtanimator.document import placement as pl

        doc = self.ctx.doc
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
            QTimer.singleShot(0, lambda: self.ctx.push(command))

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
            self.editors[name] = box
            boxes.append((box, field, index))

        def refresh() -> None:
            for box, field, index in boxes:
                box.blockSignals(True)
                box.setValue(shown(field, index))
                box.blockSignals(False)

        self._refreshers.append(refresh)
        return group

    def _rotation_mode_editor(self, form: QFormLayout, asset: str) -> None:
        """How a 3D character's rotations are keyed (issue 21): quaternion curves (W X Y Z, as
        a glTF file has them) or Euler curves (X Y Z angles); one undoable conversion."""
        doc = self.ctx.doc
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
            QTimer.singleShot(0, lambda: self.ctx.push(command))

        combo.currentTextChanged.connect(push)
        form.addRow("Rotation keys", combo)
        self.editors["rotation_mode"] = combo

    def _clip_editor(self, form: QFormLayout, asset: str) -> None:
        """The clip a glTF character plays (issue 21): one undoable command per choice. The
        combo shows the document; a change of the asset rebuilds this panel."""
        if asset not in clip_characters(self.ctx.doc):
            return
        combo = ClipCombo(self.ctx, asset, deferred=True)
        combo.setObjectName("characterClip")
        form.addRow("Clip", combo)
        self.editors["clip"] = combo

    def _bvh_positions_editor(self, form: QFormLayout, asset: str) -> None:
        """A BVH character's position convention (issue 21): one undoable command per change."""
        doc = self.ctx.doc
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
            QTimer.singleShot(0, lambda: self.ctx.push(command))

        combo.currentTextChanged.connect(push)
        form.addRow("BVH positions", combo)
        self.editors["bvh_positions"] = combo

    def _ik_group(self) -> QGroupBox:
        group = QGroupBox("IK solver")
        group.setObjectName("ikProperties")
        form = QFormLayout(group)
        for path, param in IK.items():
            editor = self._parameter_editor(form, param.label, path, param.default, param=param)
            editor.setToolTip(param.help)
        return group


def _tool_tip(param: Param) -> str:
    """A schema field's tool tip: its help, its unit and its default."""
    default = f"{param.default:.6g}" if isinstance(param.default, float) else repr(param.default)
    unit = f" {param.unit}" if param.unit else ""
    return f"{param.help} (default {default}{unit})" if param.help else f"default {default}{unit}"


def _limits_text(lo: float, hi: float) -> str:
    """Limits in degrees; the skeleton's "unlimited" defaults (huge values) read as none."""
    def one(v: float) -> str:
        return "none" if not math.isfinite(v) or abs(v) >= 1e3 else f"{math.degrees(v):.1f}°"
    if lo >= hi:
        return f"locked at {one(lo)}"
    return f"{one(lo)} … {one(hi)}"


def install(window: MainWindow) -> None:
    panel = PropertiesPanel(window.ctx)
    window.properties_panel = panel  # type: ignore[attr-defined]
    window.add_dock("propertiesDock", "Properties", panel, Qt.DockWidgetArea.RightDockWidgetArea)


__all__ = ["PropertiesPanel", "install", "ik_setting"]
