"""The joint tree dock: every 2D character and 3D skeleton with its joints, and the DOF panel.

The tree follows ``ctx.selection`` and sets it; keyframed joints carry a key icon (filled
once the joint has keys), dynamic (pendulum) joints a white bob. Below the tree, the DOF
panel shows one slider and spin box per degree of freedom of the selected joint within
its limits (a 3D joint: its rotation as Euler angles in its rotation order, also when it is
keyed as a quaternion, and its translation and scale where it moves or scales); an edit
keys the DOF at the current frame, and one slider drag is one gesture
(``ctx.begin_gesture``): one undo step, and Escape during the drag puts the value back.

Drag a 2D joint onto another joint of the same character to re-parent it (one undo step,
:func:`qtanimator.document.rigging.reparent_command`); a drop that would make a joint hang
from itself is refused with a message in the status bar.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from PySide6.QtCore import QEvent, QPoint, QPointF, Qt, QTimer
from PySide6.QtGui import (
    QAction,
    QBrush,
    QColor,
    QContextMenuEvent,
    QIcon,
    QKeyEvent,
    QKeySequence,
    QMouseEvent,
    QPainter,
    QPainterPath,
    QPalette,
    QPen,
    QPixmap,
    QPolygonF,
)
from PySide6.QtWidgets import (
    QAbstractItemView,
    QApplication,
    QDockWidget,
    QDoubleSpinBox,
    QGridLayout,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QMenu,
    QPushButton,
    QSlider,
    QTreeWidget,
    QTreeWidgetItem,
    QVBoxLayout,
    QWidget,
)

from qtanimator.document import character2d, character3d, outliner
from qtanimator.document.commands import Command, Macro, RemoveAsset
from qtanimator.document.document import Document, DocumentChange, split_channel_id
from qtanimator.document.gesture import Gesture
from qtanimator.document.outliner import HIDDEN, LOCKED
from qtanimator.document.pose import PosePreview, autokey
from qtanimator.ui.context import EditorContext

if TYPE_CHECKING:
    from qtanimator.ui.main_window import MainWindow

ROLE = Qt.ItemDataRole.UserRole
#: What a row is: "asset", "joint" or "light".
KIND_ROLE = Qt.ItemDataRole.UserRole + 1
NAME_COLUMN, EYE_COLUMN, LOCK_COLUMN = 0, 1, 2
TOGGLE_WIDTH = 24
#: Light rows carry ``light:NAME`` as their id (a light is no asset; no asset id holds ':').
LIGHT_PREFIX = "light:"
LIGHT_TITLES = {"light1": "Light 1 (key)", "light2": "Light 2 (fill)"}
SLIDER_STEPS_PER_UNIT = 10  # 0.1° (or 0.1 unit) per slider step
TRANSLATION_LIMIT = 5000.0


# ------------------------------------------------------------------------ DOFs
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


def _asset_kind(doc: Document, asset: str) -> str:
    a = doc.assets.get(asset)
    return a.kind if a is not None else ""


def dof_specs(doc: Document, asset: str, joint: str, time: float) -> list[DofSpec]:
    """The DOFs of ``(asset, joint)`` at ``time``; a character's own row (joint "") has
    its position."""
    kind = _asset_kind(doc, asset)
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
    kind = _asset_kind(doc, asset)
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


# ------------------------------------------------------------------------ icons
def _icon(kind: str) -> QIcon:
    pix = QPixmap(16, 16)
    pix.fill(Qt.GlobalColor.transparent)
    p = QPainter(pix)
    p.setRenderHint(QPainter.RenderHint.Antialiasing)
    if kind == "dynamic":
        p.setPen(QPen(QColor(40, 40, 40), 1.2))
        p.drawLine(QPointF(8, 1), QPointF(8, 8))
        p.setBrush(QBrush(QColor(255, 255, 255)))
        p.drawEllipse(QPointF(8, 11), 4, 4)
    elif kind in ("keyed", "key"):
        diamond = QPolygonF([QPointF(8, 2), QPointF(14, 8), QPointF(8, 14), QPointF(2, 8)])
        p.setPen(QPen(QColor(150, 80, 0), 1.2))
        p.setBrush(QBrush(QColor(255, 160, 0)) if kind == "keyed" else Qt.BrushStyle.NoBrush)
        p.drawPolygon(diamond)
    elif kind in ("shown", "hidden"):
        eye = QPainterPath()
        eye.moveTo(1, 8)
        eye.quadTo(8, 1, 15, 8)
        eye.quadTo(8, 15, 1, 8)
        p.setPen(QPen(QColor(40, 40, 40) if kind == "shown" else QColor(160, 160, 160), 1.3))
        p.setBrush(QBrush(QColor(255, 255, 255)) if kind == "shown" else Qt.BrushStyle.NoBrush)
        p.drawPath(eye)
        if kind == "shown":
            p.setBrush(QBrush(QColor(40, 40, 40)))
            p.drawEllipse(QPointF(8, 8), 2.5, 2.5)
        else:
            p.drawLine(QPointF(2, 14), QPointF(14, 2))
    elif kind in ("locked", "unlocked"):
        color = QColor(40, 40, 40) if kind == "locked" else QColor(175, 175, 175)
        p.setPen(QPen(color, 1.5))
        p.setBrush(Qt.BrushStyle.NoBrush)
        shackle = QPainterPath()
        shackle.moveTo(5, 8)
        shackle.lineTo(5, 5)
        shackle.arcTo(5, 2, 6, 6, 180, -180)
        shackle.lineTo(11, 8 if kind == "locked" else 5)
        p.drawPath(shackle)
        p.setBrush(QBrush(color))
        p.drawRoundedRect(3, 8, 10, 7, 1.5, 1.5)
    elif kind == "cloth":
        p.setPen(QPen(QColor(60, 60, 90), 1.0))
        p.setBrush(QBrush(QColor(200, 120, 200)))
        cloth = QPainterPath()
        cloth.moveTo(2, 3)
        cloth.lineTo(14, 3)
        cloth.quadTo(12, 9, 14, 14)
        cloth.quadTo(8, 11, 2, 14)
        cloth.quadTo(4, 9, 2, 3)
        p.drawPath(cloth)
    elif kind == "light":
        p.setPen(QPen(QColor(150, 110, 0), 1.0))
        p.setBrush(QBrush(QColor(255, 220, 90)))
        p.drawEllipse(QPointF(8, 7), 4.5, 4.5)
        p.setBrush(QBrush(QColor(120, 120, 120)))
        p.drawRect(6, 12, 4, 3)
    elif kind == "character":
        p.setPen(QPen(QColor(30, 30, 30), 1.2))
        p.setBrush(QBrush(QColor(120, 170, 255)))
        p.drawEllipse(QPointF(8, 5), 3, 3)
        p.drawRoundedRect(4, 9, 8, 6, 2, 2)
    else:
        p.setPen(QPen(QColor(30, 30, 30), 1.2))
        p.setBrush(QBrush(QColor(180, 220, 140)))
        p.drawRect(3, 3, 10, 10)
    p.end()
    return QIcon(pix)


# ----------------------------------------------------------------------- widgets
class DofRow:
    """Slider and spin box for one DOF; edits key through ``panel``."""

    def __init__(self, panel: DofPanel, grid: QGridLayout, row: int, spec: DofSpec) -> None:
        self.panel = panel
        self.spec = spec
        self.label = QLabel(spec.label, panel)
        self.slider = QSlider(Qt.Orientation.Horizontal, panel)
        self.slider.setObjectName(f"dofSlider_{spec.label.replace(' ', '_')}")
        self.steps = spec.steps
        self.slider.setRange(int(math.floor(spec.minimum * self.steps)), int(math.ceil(spec.maximum * self.steps)))
        self.slider.setPageStep(10 * self.steps)
        self.spin = QDoubleSpinBox(panel)
        self.spin.setObjectName(f"dofSpin_{spec.label.replace(' ', '_')}")
        self.spin.setDecimals(spec.decimals)
        self.spin.setRange(*(spec.typed_range or (spec.minimum, spec.maximum)))
        self.spin.setSuffix(spec.suffix)
        self.spin.setKeyboardTracking(False)
        self.spin.setSingleStep(10.0 / self.steps)
        grid.addWidget(self.label, row, 0)
        grid.addWidget(self.slider, row, 1)
        grid.addWidget(self.spin, row, 2)
        self._gesture: Gesture | None = None
        self._aborted = False  # Escape ended the drag: ignore the slider until released
        self.set_value(spec.value)
        self.slider.sliderPressed.connect(self._begin)
        self.slider.sliderReleased.connect(self._end)
        self.slider.valueChanged.connect(self._slider_changed)
        self.spin.valueChanged.connect(self._spin_changed)

    def widgets(self) -> list[QWidget]:
        return [self.label, self.slider, self.spin]

    def set_value(self, value: float) -> None:
        self.spec.value = value
        for w in (self.slider, self.spin):
            w.blockSignals(True)
        self.slider.setValue(int(round(value * self.steps)))
        self.spin.setValue(value)
        for w in (self.slider, self.spin):
            w.blockSignals(False)

    @property
    def dragging(self) -> bool:
        return self._gesture is not None

    def _begin(self) -> None:
        """Slider pressed: one gesture until it is released (one undo step)."""
        self._aborted = False
        self._gesture = self.panel.ctx.begin_gesture(f"Set {self.spec.label}")

    def _end(self) -> None:
        self._aborted = False
        gesture, self._gesture = self._gesture, None
        if gesture is not None:
            gesture.commit()

    def abort(self) -> None:
        """Escape while dragging: put the value back as it was before the drag."""
        gesture, self._gesture = self._gesture, None
        if gesture is not None:
            self._aborted = True
            gesture.abort()
            self.panel.rebuild()

    def _slider_changed(self, v: int) -> None:
        if self._aborted:
            return
        value = v / self.steps
        self.spin.blockSignals(True)
        self.spin.setValue(value)
        self.spin.blockSignals(False)
        self.panel.key(self.spec, value, self._gesture)

    def _spin_changed(self, value: float) -> None:
        self.slider.blockSignals(True)
        self.slider.setValue(int(round(value * self.steps)))
        self.slider.blockSignals(False)
        self.panel.key(self.spec, value, None)


class DofPanel(QWidget):
    """The sliders of the selected joint, plus previous / next joint and reset pose."""

    def __init__(self, ctx: EditorContext, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("dofPanel")
        self.ctx = ctx
        self.rows: list[DofRow] = []
        layout = QVBoxLayout(self)
        layout.setContentsMargins(2, 2, 2, 2)
        self.title = QLabel("No joint selected", self)
        self.title.setObjectName("dofTitle")
        layout.addWidget(self.title)
        self.grid_host = QWidget(self)
        self.grid = QGridLayout(self.grid_host)
        self.grid.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.grid_host)
        buttons = QHBoxLayout()
        self.prev_button = QPushButton("◀ Previous", self)
        self.prev_button.setObjectName("previousJointButton")
        self.next_button = QPushButton("Next ▶", self)
        self.next_button.setObjectName("nextJointButton")
        self.reset_button = QPushButton("Reset Pose (R)", self)
        self.reset_button.setObjectName("resetPoseButton")
        for b in (self.prev_button, self.next_button, self.reset_button):
            buttons.addWidget(b)
        layout.addLayout(buttons)
        layout.addStretch(1)
        self._editing = False
        self._shown: tuple[str, str, tuple[tuple[str, float, float, int], ...]] | None = None

    def rebuild(self) -> None:
        asset, joint = self.ctx.selection
        specs = dof_specs(self.ctx.doc, asset, joint, self.ctx.time) if asset else []
        key = (asset, joint, tuple((s.label, s.minimum, s.maximum, s.steps) for s in specs))
        if key == self._shown and len(self.rows) == len(specs):
            for row, spec in zip(self.rows, specs):
                row.spec = spec
                row.set_value(spec.value)
            return
        for row in self.rows:
            for w in row.widgets():
                self.grid.removeWidget(w)
                w.deleteLater()
        self.rows = [DofRow(self, self.grid, i, s) for i, s in enumerate(specs)]
        self._shown = key
        if not asset:
            self.title.setText("No joint selected")
        else:
            self.title.setText(f"{asset} / {joint}" if joint else f"{asset} (position)")

    def keyPressEvent(self, event: QKeyEvent) -> None:
        if event.key() == Qt.Key.Key_Escape and any(row.dragging for row in self.rows):
            for row in self.rows:
                row.abort()
            event.accept()
            return
        super().keyPressEvent(event)

    def refresh_values(self) -> None:
        if self._editing or any(row.dragging for row in self.rows):
            return  # the row being edited already shows its value
        self.rebuild()

    def key(self, spec: DofSpec, value: float, gesture: Gesture | None) -> None:
        """Key ``value``: a preview of the slider's gesture, or one undo step of its own
        (arrow keys, page steps and typed values)."""
        self._editing = True
        try:
            doc = self.ctx.doc
            if spec.channel and not autokey(doc):
                # Auto-key off: pose without keying, like a drag in the editors.
                command: Command = PosePreview(doc, spec.pose_values(value, self.ctx.time), self.ctx.time,
                                               f"Pose {spec.label}", gesture)
            else:
                command = spec.make(value, self.ctx.time, None)
            if gesture is not None:
                gesture.update(command)
            else:
                self.ctx.push(command)
        finally:
            self._editing = False


class JointTree(QTreeWidget):
    """The outliner: every asset (2D and 3D characters with their joints, cloths, others)
    and the two lights, each with an eye (shown / hidden) and a lock toggle.

    Click the eye or the lock to toggle it; F2 or a double-click renames an asset, Delete
    removes it, and the right-click menu frames it in the view, resets its pose, hides,
    locks, renames or removes it. Every change is one undo step."""

    def __init__(self, ctx: EditorContext, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("jointTree")
        self.ctx = ctx
        self.setHeaderHidden(True)
        self.setColumnCount(3)
        header = self.header()
        header.setStretchLastSection(False)
        header.setSectionResizeMode(NAME_COLUMN, QHeaderView.ResizeMode.Stretch)
        for column in (EYE_COLUMN, LOCK_COLUMN):
            header.setSectionResizeMode(column, QHeaderView.ResizeMode.Fixed)
            header.resizeSection(column, TOGGLE_WIDTH)
        self.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)  # F2 / double-click: below
        self.icons = {k: _icon(k) for k in ("dynamic", "keyed", "key", "character", "skeleton", "cloth", "light",
                                            "shown", "hidden", "locked", "unlocked")}
        self._items: dict[tuple[str, str], QTreeWidgetItem] = {}
        self._syncing = False
        self.currentItemChanged.connect(self._current_changed)
        self.itemChanged.connect(self._item_changed)
        #: A re-parenting drag: the joint item pressed, where, and whether it is moving.
        self._press: tuple[QTreeWidgetItem, QPoint] | None = None
        self.reparenting = False
        self.last_message = ""
        #: The open context menu (tests find its actions here).
        self.menu: QMenu | None = None

    # ------------------------------------------------------------- rows
    @staticmethod
    def row_kind(item: QTreeWidgetItem | None) -> str:
        """``asset``, ``joint`` or ``light`` (``""`` for None)."""
        return "" if item is None else str(item.data(0, KIND_ROLE))

    def light_item(self, name: str) -> QTreeWidgetItem | None:
        return self._items.get((LIGHT_PREFIX + name, ""))

    def toggle_rect(self, item: QTreeWidgetItem, column: int) -> Any:
        """Where the eye (EYE_COLUMN) or lock (LOCK_COLUMN) of a row is drawn (viewport coordinates)."""
        return self.visualRect(self.indexFromItem(item, column))

    # ------------------------------------------------------- mouse and keys
    def _toggle_at(self, event: QMouseEvent) -> bool:
        """A left press on an eye or a lock: toggle it (without selecting the row)."""
        if event.button() != Qt.MouseButton.LeftButton:
            return False
        pos = event.position().toPoint()
        item = self.itemAt(pos)
        column = self.columnAt(pos.x())
        if item is None or column not in (EYE_COLUMN, LOCK_COLUMN) or self.row_kind(item) == "joint":
            return False
        self.toggle(item.data(0, ROLE)[0], HIDDEN if column == EYE_COLUMN else LOCKED)
        event.accept()
        return True

    def mousePressEvent(self, event: QMouseEvent) -> None:
        self._press = None
        self.reparenting = False
        if self._toggle_at(event):
            return
        super().mousePressEvent(event)
        item = self.itemAt(event.position().toPoint())
        if event.button() == Qt.MouseButton.RightButton:
            self._menu_requested(event.position().toPoint())
            event.accept()
            return
        if event.button() == Qt.MouseButton.LeftButton and self.row_kind(item) == "joint":
            assert item is not None
            self._press = (item, event.position().toPoint())

    def mouseMoveEvent(self, event: QMouseEvent) -> None:
        if self._press is not None and event.buttons() & Qt.MouseButton.LeftButton:
            moved = (event.position().toPoint() - self._press[1]).manhattanLength()
            if moved >= QApplication.startDragDistance():
                if not self.reparenting:
                    self.reparenting = True
                    self.viewport().setCursor(Qt.CursorShape.DragMoveCursor)
                event.accept()
                return
        if not self.reparenting:
            super().mouseMoveEvent(event)

    def mouseReleaseEvent(self, event: QMouseEvent) -> None:
        press, dragging = self._press, self.reparenting
        self._press = None
        self.reparenting = False
        if dragging:
            self.viewport().unsetCursor()
        if press is None or not dragging or event.button() != Qt.MouseButton.LeftButton:
            super().mouseReleaseEvent(event)
            return
        event.accept()
        target = self.itemAt(event.position().toPoint())
        if target is None or target is press[0]:
            return
        self.reparent(press[0].data(0, ROLE), target.data(0, ROLE))

    def mouseDoubleClickEvent(self, event: QMouseEvent) -> None:
        if self._toggle_at(event):  # a quick second click on a toggle toggles it back
            return
        item = self.itemAt(event.position().toPoint())
        if event.button() == Qt.MouseButton.LeftButton and self.row_kind(item) == "asset":
            assert item is not None
            self.start_rename(item)
            event.accept()
            return
        super().mouseDoubleClickEvent(event)

    def event(self, event: QEvent) -> bool:
        # F2 and Delete belong to the tree while it has the focus (not to a window shortcut).
        if event.type() == QEvent.Type.ShortcutOverride and isinstance(event, QKeyEvent) \
                and event.key() in (Qt.Key.Key_F2, Qt.Key.Key_Delete) and self.state() != self.State.EditingState:
            event.accept()
            return True
        return super().event(event)

    def keyPressEvent(self, event: QKeyEvent) -> None:
        item = self.currentItem()
        if self.state() != self.State.EditingState and event.modifiers() == Qt.KeyboardModifier.NoModifier:
            if event.key() == Qt.Key.Key_F2 and item is not None:
                self.start_rename(item)
                event.accept()
                return
            if event.key() in (Qt.Key.Key_Delete, Qt.Key.Key_Backspace) and item is not None:
                self.remove(item.data(0, ROLE)[0] if self.row_kind(item) != "joint" else "")
                event.accept()
                return
        super().keyPressEvent(event)

    # ------------------------------------------------------------- edits
    def toggle(self, target: str, name: str) -> None:
        """Flip ``hidden`` or ``locked`` of an asset (or ``light:NAME`` row id): one undo step."""
        target = target.removeprefix(LIGHT_PREFIX)
        self.ctx.push(outliner.set_flag_command(self.ctx.doc, target, name, not outliner.flag(self.ctx.doc,
                                                                                                target, name)))

    def start_rename(self, item: QTreeWidgetItem) -> bool:
        if self.row_kind(item) != "asset":
            return self._say("Only assets can be renamed here.")
        self.setCurrentItem(item, NAME_COLUMN)
        self.editItem(item, NAME_COLUMN)
        return True

    def _item_changed(self, item: QTreeWidgetItem, column: int) -> None:
        if self._syncing or column != NAME_COLUMN or self.row_kind(item) != "asset":
            return
        old = item.data(0, ROLE)[0]
        new = item.text(NAME_COLUMN).strip()
        if new == old:
            return
        # The tree is rebuilt by the rename: leave the editor's signal first.
        QTimer.singleShot(0, lambda: self.rename(old, new))

    def rename(self, old: str, new: str) -> bool:
        """Rename an asset (its channels and the selection follow); a name in use, empty or
        with other characters than letters, digits and - _ . is refused with a message."""
        doc = self.ctx.doc
        problem = outliner.name_problem(doc, old, new)
        if problem is not None:
            item = self._items.get((old, ""))
            if item is not None:
                self._syncing = True
                item.setText(NAME_COLUMN, old)
                self._syncing = False
            return self._say(problem)
        asset, joint = self.ctx.selection
        channels = self.ctx.channel_selection
        self.ctx.push(outliner.rename_command(doc, old, new))
        if asset == old:
            self.ctx.select(new, joint)
        prefix = old + "/"
        if any(c.startswith(prefix) for c in channels):
            self.ctx.select_channels([new + "/" + c[len(prefix):] if c.startswith(prefix) else c for c in channels])
        self._say(f"Renamed {old} to {new}.")
        return True

    def remove(self, asset: str) -> bool:
        """Remove an asset and its channels: one undo step."""
        if asset.startswith(LIGHT_PREFIX):
            return self._say("The lights cannot be removed: hide them instead.")
        if asset not in self.ctx.doc.assets:
            return self._say("Select an asset's row to remove it.")
        self.ctx.push(RemoveAsset(self.ctx.doc, asset))
        return True

    # ------------------------------------------------------- context menu
    def contextMenuEvent(self, event: QContextMenuEvent) -> None:
        # A right press opens the menu (mousePressEvent); here only the Menu key does.
        event.accept()
        if event.reason() != QContextMenuEvent.Reason.Mouse and self.currentItem() is not None:
            self._menu_requested(self.visualItemRect(self.currentItem()).center())

    def _menu_requested(self, pos: QPoint) -> None:
        item = self.itemAt(pos)
        if item is None:
            return
        menu = self.context_menu(item)
        menu.popup(self.viewport().mapToGlobal(pos))

    def context_menu(self, item: QTreeWidgetItem) -> QMenu:
        """The right-click menu of a row (of its asset for a joint's row)."""
        target = item.data(0, ROLE)[0]
        light = self.row_kind(item) == "light"
        name = target.removeprefix(LIGHT_PREFIX)
        doc = self.ctx.doc
        menu = QMenu(self)
        menu.setObjectName("outlinerMenu")
        menu.setAttribute(Qt.WidgetAttribute.WA_DeleteOnClose)

        def add(object_name: str, text: str, slot: Callable[[], object], enabled: bool = True) -> QAction:
            action = menu.addAction(text)
            action.setObjectName(object_name)
            action.setEnabled(enabled)
            action.triggered.connect(lambda _c=False: slot())
            return action

        kind = _asset_kind(doc, target)
        character = kind in (character2d.ASSET_KIND, character3d.ASSET_KIND)
        add("outlinerFrame", "Frame in View", lambda: self.frame_in_view(target), not light)
        add("outlinerResetPose", "Reset Pose", lambda: self._reset_pose(target), character)
        menu.addSeparator()
        hidden, locked = outliner.is_hidden(doc, name), outliner.is_locked(doc, name)
        add("outlinerHide", "Show" if hidden else "Hide", lambda: self.toggle(name, HIDDEN))
        add("outlinerLock", "Unlock" if locked else "Lock", lambda: self.toggle(name, LOCKED))
        menu.addSeparator()
        rename_item = self._items.get((target, ""))
        add("outlinerRename", "Rename… (F2)", lambda: rename_item is not None and self.start_rename(rename_item),
            not light)
        add("outlinerRemove", "Remove (Delete)", lambda: self.remove(target), not light)
        self.menu = menu
        return menu

    def _reset_pose(self, asset: str) -> None:
        cmd = reset_pose_command(self.ctx.doc, asset, self.ctx.time)
        if cmd is not None:
            self.ctx.push(cmd)

    def frame_in_view(self, asset: str) -> bool:
        """Show the editor that draws ``asset`` and fit its view to it: the 2D editor for a
        2D character, the 3D view for the rest."""
        window = self.window()
        doc = self.ctx.doc
        if asset not in doc.assets:
            return False
        if _asset_kind(doc, asset) == character2d.ASSET_KIND:
            editor = getattr(window, "rig_editor", None)
            if editor is None:
                return False
            _show_central(window, editor)
            return bool(editor.view.frame_asset(asset))
        view = getattr(window, "viewport3d", None)
        if view is None:
            return False
        _show_central(window, getattr(window, "viewport_panel", view))
        if self.ctx.selection[0] != asset:
            self.ctx.select(asset, "")
        view.frame_selection()
        return True

    def reparent(self, source: tuple[str, str], target: tuple[str, str]) -> bool:
        """Make ``target`` (asset, joint) the parent of ``source``: one undo step."""
        asset, joint = source
        doc = self.ctx.doc
        if _asset_kind(doc, asset) != character2d.ASSET_KIND:
            return self._say("Only the joints of 2D characters can be re-parented here.")
        if target[0] != asset:
            return self._say("A joint can only hang from a joint of its own character.")
        from qtanimator.document import rigging
        from qtanimator.formats.errors import FormatError

        parent = target[1] or doc.runtime[asset].joints[0].name
        try:
            command = rigging.reparent_command(doc, asset, joint, parent)
        except (rigging.RigError, FormatError) as exc:
            return self._say(str(exc))
        self.ctx.push(command)
        self.ctx.select(asset, joint)
        return True

    def _say(self, text: str) -> bool:
        self.last_message = text
        bar = getattr(self.window(), "statusBar", None)
        if callable(bar):
            bar().showMessage(text, 5000)
        return False

    def rebuild(self) -> None:
        self._syncing = True
        self.clear()
        self._items.clear()
        doc = self.ctx.doc
        for aid, asset in doc.assets.items():
            top = QTreeWidgetItem([aid])
            top.setData(0, ROLE, (aid, ""))
            top.setData(0, KIND_ROLE, "asset")
            top.setFlags(top.flags() | Qt.ItemFlag.ItemIsEditable)
            icon = ("character" if asset.kind == character2d.ASSET_KIND
                    else "skeleton" if asset.kind == character3d.ASSET_KIND
                    else "cloth" if asset.kind == "cloth" else "")
            if icon:
                top.setIcon(0, self.icons[icon])
            top.setToolTip(0, f"{aid} ({asset.kind}): F2 renames, Delete removes, right-click for more")
            self.addTopLevelItem(top)
            self._items[(aid, "")] = top
            self._show_flags(top, aid)
            items: list[QTreeWidgetItem] = []
            for name, parent, _dynamic in joint_names(doc, aid):
                item = QTreeWidgetItem([name])
                item.setData(0, ROLE, (aid, name))
                item.setData(0, KIND_ROLE, "joint")
                (items[parent] if parent is not None else top).addChild(item)
                items.append(item)
                self._items[(aid, name)] = item
            top.setExpanded(True)
            for item in items:
                item.setExpanded(True)
        for name in outliner.LIGHTS:
            row = QTreeWidgetItem([LIGHT_TITLES.get(name, name)])
            row.setData(0, ROLE, (LIGHT_PREFIX + name, ""))
            row.setData(0, KIND_ROLE, "light")
            row.setIcon(0, self.icons["light"])
            row.setToolTip(0, f"{name}: its position, colour and intensity are in the Lights dock")
            self.addTopLevelItem(row)
            self._items[(LIGHT_PREFIX + name, "")] = row
            self._show_flags(row, name)
        self.refresh_icons()
        self._syncing = False
        self.follow_selection()

    def _show_flags(self, item: QTreeWidgetItem, target: str) -> None:
        """The eye and lock of a row, and its name greyed when hidden."""
        doc = self.ctx.doc
        hidden, locked = outliner.is_hidden(doc, target), outliner.is_locked(doc, target)
        item.setIcon(EYE_COLUMN, self.icons["hidden" if hidden else "shown"])
        item.setToolTip(EYE_COLUMN, "hidden: click to show" if hidden else "shown: click to hide")
        item.setIcon(LOCK_COLUMN, self.icons["locked" if locked else "unlocked"])
        item.setToolTip(LOCK_COLUMN, "locked: click to unlock" if locked else "click to lock (no picking in views)")
        item.setForeground(NAME_COLUMN, self.palette().brush(
            QPalette.ColorGroup.Disabled if hidden else QPalette.ColorGroup.Active, QPalette.ColorRole.Text))

    def refresh_flags(self) -> None:
        """Update every row's eye and lock (flags are asset properties and light parameters)."""
        self._syncing = True
        try:
            for (target, joint), item in self._items.items():
                if not joint:
                    self._show_flags(item, target.removeprefix(LIGHT_PREFIX))
        finally:
            self._syncing = False

    def refresh_icons(self, assets: Collection[str] | None = None) -> None:
        """Update the keyed / not keyed icons of every joint (of ``assets`` only if given)."""
        doc = self.ctx.doc
        shown = {k[0] for k in self._items}
        targets = shown if assets is None else shown & set(assets)
        if not targets:
            return
        keyed: set[tuple[str, str]] = set()
        for aid in targets:
            for cid, ch in doc.channels_of(aid):
                if ch.keys:
                    a, j, _dof = split_channel_id(cid)
                    keyed.add((a, j))
        for aid in targets:
            for name, _parent, dynamic in joint_names(doc, aid):
                item = self._items.get((aid, name))
                if item is None:
                    continue
                kind = "dynamic" if dynamic else ("keyed" if (aid, name) in keyed else "key")
                item.setIcon(0, self.icons[kind])
                item.setToolTip(0, {"dynamic": "dynamic joint (pendulum)", "keyed": "keyframed joint (has keys)",
                                    "key": "keyframed joint"}[kind])

    def item_for(self, asset: str, joint: str) -> QTreeWidgetItem | None:
        return self._items.get((asset, joint))

    def follow_selection(self) -> None:
        item = self.item_for(*self.ctx.selection)
        self._syncing = True
        self.setCurrentItem(item)  # type: ignore[arg-type]
        if item is None:
            self.clearSelection()
        else:
            self.scrollToItem(item)
        self._syncing = False

    def _current_changed(self, current: QTreeWidgetItem | None, _previous: QTreeWidgetItem | None) -> None:
        if self._syncing or current is None:
            return
        asset, joint = current.data(0, ROLE)
        if self.row_kind(current) == "light":
            # A light is no asset: show its dock (position, colour, intensity) instead.
            dock = self.window().findChild(QDockWidget, "lightDock")
            if dock is not None:
                dock.show()
                dock.raise_()
            return
        self.ctx.select(asset, joint)

    def step_joint(self, delta: int) -> None:
        """Select the next / previous joint of the selected asset (pre-order, wrapping)."""
        asset, joint = self.ctx.selection
        if not asset:
            return
        names = [""] + [n for n, _p, _d in joint_names(self.ctx.doc, asset)]
        i = names.index(joint) if joint in names else 0
        self.ctx.select(asset, names[(i + delta) % len(names)])


class JointTreePanel(QWidget):
    def __init__(self, ctx: EditorContext, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("jointTreePanel")
        self.ctx = ctx
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        self.tree = JointTree(ctx, self)
        self.dofs = DofPanel(ctx, self)
        layout.addWidget(self.tree, 3)
        layout.addWidget(self.dofs, 1)
        self.dofs.prev_button.clicked.connect(lambda: self.tree.step_joint(-1))
        self.dofs.next_button.clicked.connect(lambda: self.tree.step_joint(1))
        self.dofs.reset_button.clicked.connect(self.reset_pose)
        ctx.selectionChanged.connect(self._selection_changed)
        ctx.documentChanged.connect(self._document_changed)
        ctx.documentReset.connect(self._reset)
        ctx.frameChanged.connect(lambda _f: self.dofs.refresh_values())
        self._reset()

    def _reset(self) -> None:
        self.tree.rebuild()
        self.dofs.rebuild()

    def _selection_changed(self, _asset: str, _joint: str) -> None:
        self.tree.follow_selection()
        self.dofs.rebuild()

    def _document_changed(self, change: DocumentChange) -> None:
        if change.assets:
            self.tree.rebuild()
            self.dofs.rebuild()
            return
        if change.channels:
            self.tree.refresh_icons(change.channel_assets())
        if any(p.endswith((".hidden", ".locked")) for p in change.parameters):
            self.tree.refresh_flags()  # a light's eye or lock
        if change.channels or change.parameters:
            self.dofs.refresh_values()

    def reset_pose(self) -> None:
        asset = self.ctx.selection[0]
        if not asset:
            return
        cmd = reset_pose_command(self.ctx.doc, asset, self.ctx.time)
        if cmd is not None:
            self.ctx.push(cmd)


def _show_central(window: QWidget, widget: QWidget) -> None:
    """Bring the central tab holding ``widget`` to the front."""
    tabs = getattr(window, "central_tabs", None)
    if tabs is None:
        return
    for i in range(tabs.count()):
        page = tabs.widget(i)
        if page is widget or page.isAncestorOf(widget):
            tabs.setCurrentIndex(i)
            return


def install(window: MainWindow) -> None:
    panel = JointTreePanel(window.ctx)
    window.joint_tree = panel  # type: ignore[attr-defined]
    window.add_dock("jointTreeDock", "Outliner", panel, Qt.DockWidgetArea.LeftDockWidgetArea)
    reset = QAction("Reset Pose", window)
    reset.setObjectName("actionResetPose")
    reset.setShortcut(QKeySequence("R"))
    reset.setShortcutContext(Qt.ShortcutContext.WidgetWithChildrenShortcut)
    reset.triggered.connect(lambda _c=False: panel.reset_pose())
    panel.addAction(reset)
    window.reset_pose_action = reset  # type: ignore[attr-defined]
    view = window.findChild(QWidget, "rigEditorView")
    if view is not None:
        view.addAction(reset)

