"""The cloth dock (``clothDock``): every :class:`~qtanimator.core.cloth.ClothParams` field of
the selected cloth asset, edited live through ``set_cloth_param_command`` (a drag on a field
is one undo step), plus the interactive simulation controls of the 3D viewport (live
simulation on / off, pause, reset; W/A/S/D/Q/E and Z/C in the viewport move the pins).

The cloth is simulated on a background thread (the 3D viewport's ``cloth_worker``). When that
takes longer than a second, ``clothProgress`` says how far it is and ``clothCancel`` stops it
(then resumes it); a blow-up's explanation is shown there too."""

from __future__ import annotations

import itertools
import math
from dataclasses import fields
from typing import Any

from PySide6.QtCore import Qt
from PySide6.QtWidgets import (
    QAbstractSpinBox,
    QCheckBox,
    QComboBox,
    QFormLayout,
    QGridLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QScrollArea,
    QVBoxLayout,
    QWidget,
)

from qtanimator.core.cloth_params import ClothParams, Sphere
from qtanimator.document.cloth import ASSET_KIND, add_cloth_command, cloth_params, set_cloth_param_command
from qtanimator.document.document import DocumentChange
from qtanimator.document.parameters import CLOTH, CLOTH_SPHERE_CENTRE, CLOTH_SPHERE_RADIUS, CLOTH_WIND_SPEED, Param
from qtanimator.ui.context import EditorContext
from qtanimator.ui.param_fields import ParamDoubleSpinBox, ParamSpinBox, editor_for, spin_for
from qtanimator.ui.widgets import wrap_long_rows

_gestures = itertools.count(1)

# Every field's range, step, decimals, choices, special minimum text and the reasons shown
# when a typed value beyond a limit is refused come from the parameter schema
# (qtanimator.document.parameters.CLOTH, built from ClothParams' fields). The minimums are
# the ones ClothParams.validate enforces; where the model has no maximum the field's is far
# beyond any useful value (stiffness 1e7 is fine: the implicit integrator takes it). A typed
# value outside a field's range is refused with the reason shown, never clamped.
#: (minimum, maximum, step, decimals) of the float fields: a view of the schema.
FLOAT_RANGES: dict[str, tuple[float, float, float, int]] = {
    k: (float(p.minimum or 0.0), float(p.maximum or 0.0), float(p.step or 0.0), int(p.decimals or 0))
    for k, p in CLOTH.items() if p.kind == "float"}
#: (minimum, maximum) of the int fields: a view of the schema.
INT_RANGES: dict[str, tuple[int, int]] = {k: (int(p.minimum or 0), int(p.maximum or 0))
                                          for k, p in CLOTH.items() if p.kind == "int"}
CHOICES: dict[str, tuple[str, ...]] = {k: p.choices for k, p in CLOTH.items() if p.kind == "choice"}
VECTORS = tuple(k for k, p in CLOTH.items() if p.kind == "vector")
GROUPS = (
    ("Grid", ("rows", "cols", "width", "height", "total_mass", "origin", "orientation")),
    ("Springs", ("structural_stiffness", "structural_damping", "shear_stiffness", "shear_damping",
                 "bend_stiffness", "bend_damping")),
    ("Air and wind", ("drag_coefficient", "air_density", "wind", "turbulence", "turbulence_seed", "gravity")),
    ("Collisions", ("ground_enabled", "ground_height", "ground_restitution", "ground_friction", "spheres",
                    "collision_margin")),
    ("Pins and solver", ("pin_mode", "custom_pins", "integrator", "substeps")),
)


#: The narrowest a field in a row of several (a vector, the sphere) may get, in pixels.
COMPONENT_MIN_WIDTH = 48


def _label(name: str) -> str:
    """The row label of a cloth field: the schema's label with its unit."""
    return CLOTH[name].title


class ClothPanel(QWidget):
    def __init__(self, ctx: EditorContext, window: Any = None, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("clothPanel")
        self.ctx = ctx
        self.window_ = window
        self.editors: dict[str, Any] = {}
        self._updating = False
        self._gesture: tuple[str, int] | None = None
        # Everything scrolls, the buttons with the form (as in Blender's property editor):
        # the dock can then be short, a tab on a 768-pixel-high screen (issue 30).
        scroll = QScrollArea(self)
        scroll.setWidgetResizable(True)
        content = QWidget(scroll)
        scroll.setWidget(content)
        panel_layout = QVBoxLayout(self)
        panel_layout.setContentsMargins(0, 0, 0, 0)
        panel_layout.addWidget(scroll)
        outer = QVBoxLayout(content)
        top = QHBoxLayout()
        self.asset = QComboBox(self)
        self.asset.setObjectName("clothAsset")
        self.asset.currentIndexChanged.connect(self._on_asset_changed)
        add = QPushButton("Add cloth", self)
        add.setObjectName("clothAdd")
        add.clicked.connect(self.add_cloth)
        top.addWidget(self.asset, 1)
        top.addWidget(add)
        outer.addLayout(top)
        # Two short rows, not one long one: the dock can be narrow (issue 30, a laptop screen).
        sim = QGridLayout()
        self.live = QCheckBox("Interactive", self)
        self.live.setObjectName("clothLive")
        self.live.setToolTip("Simulate in real time in the 3D view: W/A/S/D/Q/E move the pins, Z/C turn them, "
                             "drag the cloth with the mouse")
        self.live.toggled.connect(self._on_live)
        self.pause = QPushButton("Pause", self)
        self.pause.setObjectName("clothPause")
        self.pause.setCheckable(True)
        self.pause.toggled.connect(self._on_pause)
        self.reset = QPushButton("Reset cloth", self)
        self.reset.setObjectName("clothReset")
        self.reset.setToolTip("Put the interactive cloth back in its rest shape (Shift+R in the 3D view)")
        self.reset.clicked.connect(self._on_reset)
        sim.addWidget(self.live, 0, 0, 1, 2)
        sim.addWidget(self.pause, 1, 0)
        sim.addWidget(self.reset, 1, 1)
        outer.addLayout(sim)
        self.message = QLabel(self)
        self.message.setObjectName("clothMessage")
        self.message.setWordWrap(True)
        outer.addWidget(self.message)
        # Why a simulation stopped (a blow-up), naming the parameter to change.
        self.problem = QLabel(self)
        self.problem.setObjectName("clothProblem")
        self.problem.setWordWrap(True)
        self.problem.setStyleSheet("color: #c0392b;")
        self.problem.hide()
        outer.addWidget(self.problem)
        self._last_problem = ""
        # Without numba the solver runs on numpy, several times slower: say so once, here.
        from qtanimator.core import cloth_kernels

        self.speed_note = QLabel(cloth_kernels.SLOW_PATH_NOTE or "", self)
        self.speed_note.setObjectName("clothSpeedNote")
        self.speed_note.setWordWrap(True)
        self.speed_note.setVisible(bool(cloth_kernels.SLOW_PATH_NOTE))
        outer.addWidget(self.speed_note)
        busy = QHBoxLayout()
        self.progress = QLabel(self)
        self.progress.setObjectName("clothProgress")
        self.progress.setWordWrap(True)
        self.cancel = QPushButton("Cancel", self)
        self.cancel.setObjectName("clothCancel")
        self.cancel.setToolTip("Stop simulating the cloth cache (the frames computed so far stay)")
        self.cancel.clicked.connect(self._on_cancel)
        busy.addWidget(self.progress, 1)
        busy.addWidget(self.cancel)
        outer.addLayout(busy)
        self.progress.hide()
        self.cancel.hide()

        body = QWidget(content)
        form_layout = QVBoxLayout(body)
        form_layout.setContentsMargins(0, 0, 0, 0)
        for title, names in GROUPS:
            head = QLabel(f"<b>{title}</b>", body)
            form_layout.addWidget(head)
            form = QFormLayout()
            for name in names:
                form.addRow(_label(name), self._make_editor(name, body))
            form_layout.addLayout(form)
        form_layout.addStretch(1)
        wrap_long_rows(body)
        outer.addWidget(body, 1)
        known = {f.name for f in fields(ClothParams)}
        missing = known - set(self.editors)
        assert not missing, f"cloth fields without an editor: {missing}"
        ctx.documentChanged.connect(self._on_changed)
        ctx.documentReset.connect(self.refresh_assets)
        vp = self._viewport()
        if vp is not None:
            vp.liveClothChanged.connect(self._show_live)
            vp.clothProgressChanged.connect(self.show_progress)
        self.refresh_assets()

    def _show_live(self, on: bool) -> None:
        self.live.blockSignals(True)
        self.live.setChecked(on)
        self.live.blockSignals(False)

    # ------------------------------------------------------------- editors
    def _spin(self, param: Param, name: str, parent: QWidget,
              label: str = "") -> ParamSpinBox | ParamDoubleSpinBox:
        """The spin box of ``param`` (range, step, decimals, reasons from the schema), named
        ``cloth_<name>``."""
        s = spin_for(param, parent, f"cloth_{name}", label or param.label)
        # A typed value is one edit, committed with Enter or on leaving the field (not one
        # command and one re-simulation per keystroke); the arrows still apply at once.
        s.editingFinished.connect(self.end_gesture)
        s.refused.connect(self._refused)
        return s

    def _refused(self, reason: str) -> None:
        """A typed value outside a field's range: say why (the field is red too)."""
        self.message.setText(reason)

    def _make_editor(self, name: str, parent: QWidget) -> QWidget:
        widget = self._editor(name, parent)
        # The fields of a row (a vector, the sphere) may be narrower than their widest value
        # needs, so the rows fit the dock's width with the unit in the label (no sideways
        # scrolling); a single field fills its row anyway.
        for spin in widget.findChildren(QAbstractSpinBox):
            spin.setMinimumWidth(COMPONENT_MIN_WIDTH)
        return widget

    def _editor(self, name: str, parent: QWidget) -> QWidget:
        param = CLOTH[name]
        if param.kind == "float":
            s = self._spin(param, name, parent)
            s.valueChanged.connect(lambda v, n=name: self.edit(n, float(v)))
            self.editors[name] = s
            return s
        if param.kind == "int":
            i = self._spin(param, name, parent)
            i.valueChanged.connect(lambda v, n=name: self.edit(n, int(v)))
            self.editors[name] = i
            return i
        if param.kind == "choice":
            c = editor_for(param, parent, f"cloth_{name}")
            assert isinstance(c, QComboBox)
            c.currentTextChanged.connect(lambda v, n=name: self.edit(n, str(v)))
            self.editors[name] = c
            return c
        if param.kind == "bool":
            b = editor_for(param, parent, f"cloth_{name}")
            assert isinstance(b, QCheckBox)
            b.toggled.connect(lambda v, n=name: self.edit(n, bool(v)))
            self.editors[name] = b
            return b
        if param.kind == "vector":
            w = QWidget(parent)
            row = QHBoxLayout(w)
            row.setContentsMargins(0, 0, 0, 0)
            spins = []
            for axis in "xyz":
                s = self._spin(param, f"{name}_{axis}", w, f"{param.label} {axis}")
                s.valueChanged.connect(lambda _v, n=name: self._vector_edited(n))
                row.addWidget(s)
                spins.append(s)
            self.editors[name] = spins
            if name == "wind":
                speed = self._spin(CLOTH_WIND_SPEED, "wind_speed", w)
                assert isinstance(speed, ParamDoubleSpinBox)
                speed.setPrefix("speed ")
                speed.valueChanged.connect(self._speed_edited)
                row.addWidget(speed)
                self.wind_speed = speed
            return w
        if name == "spheres":
            w = QWidget(parent)
            row = QHBoxLayout(w)
            row.setContentsMargins(0, 0, 0, 0)
            on = QCheckBox("on", w)
            on.setObjectName("cloth_sphere_on")
            spins = [self._spin(CLOTH_SPHERE_CENTRE, f"sphere_{k}", w, f"{CLOTH_SPHERE_CENTRE.label} {k}")
                     for k in ("x", "y", "z")]
            spins.append(self._spin(CLOTH_SPHERE_RADIUS, "sphere_radius", w))
            on.toggled.connect(lambda _v: self._sphere_edited())
            row.addWidget(on)
            for s in spins:
                s.valueChanged.connect(lambda _v: self._sphere_edited())
                row.addWidget(s)
            self.editors[name] = (on, spins)
            return w
        if name == "custom_pins":
            e = QLineEdit(parent)
            e.setObjectName("cloth_custom_pins")
            e.setPlaceholderText("particle indices, e.g. 0 19")
            e.editingFinished.connect(self._pins_edited)
            self.editors[name] = e
            return e
        raise ValueError(name)

    # ------------------------------------------------------------- editing
    def current_asset(self) -> str:
        return str(self.asset.currentData() or "")

    def edit(self, name: str, value: Any) -> bool:
        """Set one parameter of the current cloth through a command. False if refused."""
        asset = self.current_asset()
        if self._updating or not asset:
            return False
        if self._gesture is None or self._gesture[0] != name:
            self._gesture = (name, next(_gestures))
        try:
            cmd = set_cloth_param_command(self.ctx.doc, asset, name, value, gesture=("cloth", asset, self._gesture))
        except ValueError as exc:
            self.message.setText(str(exc))
            self.refresh_fields()
            return False
        self.message.setText("")
        self.ctx.push(cmd)
        return True

    def end_gesture(self) -> None:
        """The next edit is a new undo step (a field lost the focus or Enter was pressed)."""
        self._gesture = None

    def _vector_edited(self, name: str) -> None:
        if self._updating:
            return
        self.edit(name, [float(s.value()) for s in self.editors[name]])
        if name == "wind":
            self._show_speed()

    def _speed_edited(self, speed: float) -> None:
        if self._updating:
            return
        v = [float(s.value()) for s in self.editors["wind"]]
        length = math.sqrt(sum(c * c for c in v))
        direction = [c / length for c in v] if length > 1e-9 else [1.0, 0.0, 0.0]
        self.edit("wind", [round(c * speed, 6) for c in direction])
        self.refresh_fields()

    def _show_speed(self) -> None:
        v = [float(s.value()) for s in self.editors["wind"]]
        # Keep the caller's flag: refresh_fields calls this while it fills the other fields.
        updating, self._updating = self._updating, True
        try:
            self.wind_speed.setValue(math.sqrt(sum(c * c for c in v)))
        finally:
            self._updating = updating

    def _sphere_edited(self) -> None:
        on, spins = self.editors["spheres"]
        spheres = []
        if on.isChecked():
            x, y, z, r = (float(s.value()) for s in spins)
            spheres = [Sphere((x, y, z), r).to_dict()]
        self.edit("spheres", spheres)

    def _pins_edited(self) -> None:
        text = self.editors["custom_pins"].text().replace(",", " ")
        try:
            pins = [int(t) for t in text.split()]
        except ValueError:
            self.message.setText("Custom pins are particle numbers separated by spaces.")
            return
        self.edit("custom_pins", pins)

    def _on_asset_changed(self, _index: int) -> None:
        self.end_gesture()
        self.refresh_fields()

    def add_cloth(self) -> None:
        self.ctx.push(add_cloth_command(self.ctx.doc))

    # ------------------------------------------------------------ refresh
    def _on_changed(self, change: DocumentChange) -> None:
        if change.assets:
            self.refresh_assets()

    def refresh_assets(self) -> None:
        current = self.current_asset()
        ids = [a for a, asset in self.ctx.doc.assets.items() if asset.kind == ASSET_KIND]
        self.asset.blockSignals(True)
        self.asset.clear()
        for a in ids:
            self.asset.addItem(a, a)
        if current in ids:
            self.asset.setCurrentIndex(ids.index(current))
        self.asset.blockSignals(False)
        self.refresh_fields()

    def refresh_fields(self) -> None:
        asset = self.current_asset()
        enabled = bool(asset)
        # No cloth in the project: the fields are disabled and show what a new cloth gets.
        # A cloth whose stored parameters are bad raises here (cloth_params), no defaults.
        params = cloth_params(self.ctx.doc, asset) if asset else ClothParams()
        self._updating = True
        try:
            for name, editor in self.editors.items():
                value = getattr(params, name)
                if name in FLOAT_RANGES or name in INT_RANGES:
                    editor.setValue(value)
                elif name in CHOICES:
                    editor.setCurrentText(str(value))
                elif name == "ground_enabled":
                    editor.setChecked(bool(value))
                elif name in VECTORS:
                    for s, v in zip(editor, value):
                        s.setValue(float(v))
                elif name == "spheres":
                    on, spins = editor
                    on.setChecked(bool(value))
                    if value:
                        s0 = Sphere.from_value(value[0])
                        for s, v in zip(spins, (*s0.centre, s0.radius)):
                            s.setValue(float(v))
                elif name == "custom_pins":
                    editor.setText(" ".join(str(i) for i in value))
            wind = params.wind
            self.wind_speed.setValue(math.sqrt(sum(c * c for c in wind)))
        finally:
            self._updating = False
        for w in self.findChildren(QWidget):
            if w.objectName().startswith("cloth_"):
                w.setEnabled(enabled)

    # ------------------------------------------------- background simulation
    #: Work shorter than this (seconds) shows no progress.
    PROGRESS_AFTER_S = 1.0

    def show_progress(self, progress: list[Any]) -> None:
        """Show how far the cloth cache worker is (a list of ClothProgress)."""
        lines: list[str] = []
        running = cancelled = False
        self.show_problems(progress)
        for p in progress:
            if p.error:
                continue   # shown by show_problems
            elif p.running and p.elapsed >= self.PROGRESS_AFTER_S:
                running = True
                lines.append(f"Simulating {p.asset_id}: {p.done} of {p.wanted} frames "
                             f"({p.fraction:.0%}, {p.elapsed:.0f} s)")
            elif p.cancelled:
                cancelled = True
                lines.append(f"{p.asset_id}: simulation stopped after {p.done} of {p.wanted} frames")
        self.progress.setText("\n".join(lines))
        self.progress.setVisible(bool(lines))
        self.cancel.setText("Cancel" if running else "Resume")
        self.cancel.setVisible(running or cancelled)

    def show_problems(self, progress: list[Any] | None = None) -> str:
        """Show why a cloth stopped (cache or interactive blow-ups) in the dock's
        ``clothProblem`` label and the status bar; the text names the parameter to change."""
        vp = self._viewport()
        if progress is None:
            worker = getattr(vp, "cloth_worker", None)
            progress = worker.progress() if worker is not None else []
        lines = [f"Cloth '{p.asset_id}' stopped: {p.error}" for p in progress if p.error]
        live = getattr(vp, "live", None)
        for aid, text in sorted(getattr(live, "errors", {}).items()):
            lines.append(f"Interactive cloth '{aid}' stopped: {text}")
        text = "\n".join(lines)
        self.problem.setText(text)
        self.problem.setVisible(bool(text))
        if text and text != self._last_problem:
            bar = getattr(self.window_, "statusBar", None)
            if callable(bar):
                # the same words as the timeline's cache bar uses for a simulation that stopped
                bar().showMessage("Simulation stopped: " + lines[0], 15000)
        self._last_problem = text
        return text

    def _on_cancel(self) -> None:
        vp = self._viewport()
        worker = getattr(vp, "cloth_worker", None)
        if worker is None:
            return
        if self.cancel.text() == "Cancel":
            worker.cancel()
        else:
            worker.resume()
            vp.watch_simulations()
        self.show_progress(worker.progress())

    # --------------------------------------------------- live simulation
    def _viewport(self) -> Any:
        return getattr(self.window_, "viewport3d", None)

    def _on_live(self, on: bool) -> None:
        vp = self._viewport()
        if vp is not None:
            vp.set_live_cloth(on)

    def _on_pause(self, paused: bool) -> None:
        vp = self._viewport()
        if vp is not None:
            vp.live.paused = paused

    def _on_reset(self) -> None:
        vp = self._viewport()
        if vp is not None:
            vp.reset_cloth()
        self.show_problems()


def install(window: Any) -> None:
    panel = ClothPanel(window.ctx, window, window)
    window.cloth_panel = panel
    window.add_dock("clothDock", "Cloth", panel, Qt.DockWidgetArea.RightDockWidgetArea)
