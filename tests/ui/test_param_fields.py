"""Panels built from the parameter schema (issue 17 item 2): the cloth, light and properties
fields take their ranges, steps, decimals, choices and reasons from
``qtanimator.document.parameters``, and keep their object names."""

from __future__ import annotations

import pytest
from PySide6.QtWidgets import QCheckBox, QComboBox, QDoubleSpinBox, QSpinBox, QWidget

from qtanimator.document.parameters import CLOTH, IK, LIGHTS, PENDULUM, Param
from qtanimator.ui import cloth_panel, light_panel
from qtanimator.ui.main_window import MainWindow
from qtanimator.ui.param_fields import VectorField, editor_for, spin_for

#: The cloth fields' object names before the schema (interface for tests and scripts).
CLOTH_NAMES = {
    "cloth_rows", "cloth_cols", "cloth_width", "cloth_height", "cloth_total_mass", "cloth_structural_stiffness",
    "cloth_structural_damping", "cloth_shear_stiffness", "cloth_shear_damping", "cloth_bend_stiffness",
    "cloth_bend_damping", "cloth_drag_coefficient", "cloth_air_density", "cloth_turbulence",
    "cloth_turbulence_seed", "cloth_gravity", "cloth_ground_enabled", "cloth_ground_height",
    "cloth_ground_restitution", "cloth_ground_friction", "cloth_collision_margin", "cloth_pin_mode",
    "cloth_custom_pins", "cloth_integrator", "cloth_substeps", "cloth_sphere_on", "cloth_sphere_x",
    "cloth_sphere_y", "cloth_sphere_z", "cloth_sphere_radius", "cloth_wind_speed",
    *(f"cloth_{v}_{a}" for v in ("wind", "origin", "orientation") for a in "xyz"),
}


def _window(qtbot, *modules):
    w = MainWindow(install_editors=False)
    for m in modules:
        m.install(w)
    qtbot.addWidget(w)
    return w


def test_the_cloth_panels_fields_have_the_schemas_ranges_and_their_old_names(qtbot):
    w = _window(qtbot, cloth_panel)
    names = {c.objectName() for c in w.cloth_panel.findChildren(QWidget) if c.objectName().startswith("cloth_")}
    assert names == CLOTH_NAMES
    for key, p in CLOTH.items():
        if p.kind == "float":
            box = w.findChild(QDoubleSpinBox, f"cloth_{key}")
            assert (box.minimum(), box.maximum()) == (pytest.approx(p.minimum), pytest.approx(p.maximum)), key
            assert box.singleStep() == pytest.approx(p.step) and box.decimals() == p.decimals, key
            assert box.why_max == p.reason
        elif p.kind == "int":
            box = w.findChild(QSpinBox, f"cloth_{key}")
            assert (box.minimum(), box.maximum()) == (p.minimum, p.maximum), key
            assert box.specialValueText() == p.special_minimum and box.why_max == p.reason
        elif p.kind == "choice":
            combo = w.findChild(QComboBox, f"cloth_{key}")
            assert tuple(combo.itemText(i) for i in range(combo.count())) == p.choices
        elif p.kind == "vector":
            for axis in "xyz":
                box = w.findChild(QDoubleSpinBox, f"cloth_{key}_{axis}")
                tol = 10.0 ** -p.decimals  # the field rounds its range to its decimals (±2π)
                assert box.minimum() == pytest.approx(p.minimum, abs=tol)
                assert box.maximum() == pytest.approx(p.maximum, abs=tol)
    # the documented ranges themselves (were cloth_panel's tables)
    assert CLOTH["ground_restitution"].maximum == 1.0 and "gain energy" in CLOTH["ground_restitution"].reason
    assert (CLOTH["rows"].minimum, CLOTH["rows"].maximum) == (2, 1000)
    assert cloth_panel.FLOAT_RANGES["width"] == (0.001, 1e4, 0.1, 3)
    assert cloth_panel.INT_RANGES["substeps"] == (0, 100_000)


def test_the_light_fields_have_the_schemas_ranges(qtbot):
    w = _window(qtbot, light_panel)
    for name in ("light1", "light2"):
        inten = w.findChild(QDoubleSpinBox, f"{name}_intensity")
        p = LIGHTS[f"{name}.intensity"]
        assert (inten.minimum(), inten.maximum()) == (p.minimum, p.maximum)
        pos = LIGHTS[f"{name}.position"]
        for axis in "xyz":
            box = w.findChild(QDoubleSpinBox, f"{name}_position_{axis}")
            assert (box.minimum(), box.maximum(), box.decimals()) == (pos.minimum, pos.maximum, pos.decimals)


def test_the_ik_fields_have_the_schemas_ranges_and_choices(qtbot):
    from qtanimator.ui import properties

    w = _window(qtbot, properties)
    panel = w.properties_panel
    iterations = panel.findChild(QSpinBox, "param_ik_max_iterations")
    p = IK["ik.max_iterations"]
    assert (iterations.minimum(), iterations.maximum()) == (p.minimum, p.maximum)
    solver = panel.findChild(QComboBox, "param_ik_solver")
    assert tuple(solver.itemText(i) for i in range(solver.count())) == IK["ik.solver"].choices
    step = panel.findChild(QDoubleSpinBox, "param_ik_handout_step")
    assert step.decimals() == IK["ik.handout_step"].decimals == 9
    assert isinstance(panel.findChild(QCheckBox, "param_ik_two_bone"), QCheckBox)


def test_editor_for_builds_each_kind(qtbot):
    parent = QWidget()
    qtbot.addWidget(parent)
    assert isinstance(editor_for(IK["ik.solver"], parent, "a"), QComboBox)
    assert isinstance(editor_for(IK["ik.two_bone"], parent, "b"), QCheckBox)
    assert isinstance(editor_for(IK["ik.max_iterations"], parent, "c"), QSpinBox)
    damping = editor_for(PENDULUM["damping"], parent, "d")
    assert isinstance(damping, QDoubleSpinBox) and damping.objectName() == "d"
    vec = editor_for(LIGHTS["light1.position"], parent, "pos")
    assert isinstance(vec, VectorField) and [s.objectName() for s in vec.spins] == ["pos_x", "pos_y", "pos_z"]
    with pytest.raises(ValueError):
        editor_for(CLOTH["spheres"], parent)


def test_a_refusal_below_the_minimum_gives_the_schemas_reason(qtbot):
    box = spin_for(PENDULUM["step"], None, "step")
    qtbot.addWidget(box)
    box.refuse("Simulation step: 0 is below the smallest value, 1e-05.")
    assert "at least 1e-05 s" in box.toolTip()
    p = Param("x", 1.0, "float", "X", minimum=0.0, maximum=2.0, reason="too big")
    other = spin_for(p)
    qtbot.addWidget(other)
    assert other.why_max == "too big" and other.maximum() == 2.0
