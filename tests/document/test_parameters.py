"""The typed parameter schema (issue 17 item 2): each group's defaults are the documented
values and the core dataclasses', validation accepts the limits and refuses what lies beyond
them naming the setting, and SetParameter refuses what the schema refuses."""

from __future__ import annotations

import math
from dataclasses import fields

import pytest

from qtanimator.core.cloth import ClothParams
from qtanimator.core.pendulum import PendulumParams
from qtanimator.core.spring_joint import SpringParams
from qtanimator.document import Document
from qtanimator.document.commands import SetParameter, UndoStack
from qtanimator.document.document import PROJECT_DEFAULTS
from qtanimator.document.ik_settings import IK_DEFAULTS, IK_SOLVERS
from qtanimator.document.parameters import (
    CLOTH,
    GROUPS,
    IK,
    LIGHTS,
    PENDULUM,
    PROJECT,
    RENDER,
    SPRING,
    Param,
    defaults,
    param_for,
    parameter_problems,
    validate_parameter,
)
from qtanimator.render.gl.lights import DEFAULTS as LIGHT_DEFAULTS


# ------------------------------------------------------------------ defaults
def test_project_defaults_are_the_documented_ones_and_the_document_has_them():
    assert defaults(PROJECT) == {"fps": 60.0, "frame_start": 0, "frame_end": 240}
    assert PROJECT_DEFAULTS == defaults(PROJECT)
    assert Document().parameters == {"fps": 60.0, "frame_start": 0, "frame_end": 240}


def test_ik_defaults_are_the_documented_ones():
    assert IK_DEFAULTS == {
        "ik.solver": "dls", "ik.two_bone": True, "ik.bend_direction": "keep", "ik.freeze_root": True,
        "ik.max_iterations": 100, "ik.damping": 1e-3, "ik.handout_step": 1e-6, "ik.handout_iterations": 10,
        "ik.gradient_arrow_scale": 0.1,
    }
    assert IK_DEFAULTS == defaults(IK)
    assert IK_SOLVERS == ("dls", "ccd", "fabrik", "handout")
    assert IK["ik.bend_direction"].choices == ("keep", "positive", "negative")


def test_light_defaults_are_each_lights_own():
    assert LIGHT_DEFAULTS == {
        "light1.position": [4.0, 6.0, 5.0], "light1.color": [1.0, 0.95, 0.85], "light1.intensity": 0.8,
        "light2.position": [-5.0, 3.0, -3.0], "light2.color": [0.55, 0.65, 1.0], "light2.intensity": 0.5,
        "lights.ambient": [0.16, 0.16, 0.18],
    }
    assert LIGHT_DEFAULTS == defaults(LIGHTS)


def test_pendulum_and_spring_keys_and_defaults_are_the_dataclasses():
    assert list(PENDULUM) == [f.name for f in fields(PendulumParams)]
    assert defaults(PENDULUM) == PendulumParams().to_dict()
    # the documented values (docs/user-guide.md, core/pendulum.py)
    assert defaults(PENDULUM)["g"] == 3000.0 and defaults(PENDULUM)["restitution"] == 0.5
    assert defaults(PENDULUM)["integrator"] == "symplectic_euler" and defaults(PENDULUM)["step"] == 1 / 600
    assert list(SPRING) == [f.name for f in fields(SpringParams)]
    assert defaults(SPRING) == {"stiffness": 120.0, "damping": 8.0, "mix": 1.0, "inertia": 0.5}


def test_cloth_keys_and_defaults_are_the_dataclass():
    assert list(CLOTH) == [f.name for f in fields(ClothParams)]
    values = {k: list(v) if isinstance(v, tuple) else v for k, v in defaults(CLOTH).items()}
    assert values == ClothParams().to_dict()
    assert CLOTH["rows"].default == 20 and CLOTH["integrator"].default == "implicit"
    assert CLOTH["substeps"].special_minimum == "auto" and CLOTH["substeps"].minimum == 0


def test_render_defaults_are_what_the_export_offers():
    assert defaults(RENDER) == {"render.view": "2d", "render.format": "png", "render.width": 960,
                                "render.height": 640, "render.fps": 60.0, "render.first": 0, "render.last": 240,
                                "render.background": [0.6, 0.6, 0.95]}


def test_every_default_is_valid_and_within_its_range():
    for group in GROUPS.values():
        for key, p in group.items():
            p.validate(list(p.default) if isinstance(p.default, tuple) else p.default)
            assert p.kind != "choice" or p.default in p.choices, key


def test_every_preset_is_valid():
    from qtanimator.core.pendulum import PRESETS
    from qtanimator.core.spring_joint import SPRING_PRESETS

    for preset in PRESETS.values():
        for k, v in preset.to_dict().items():
            validate_parameter(f"hero.pendulum.{k}", v)
    for spring in SPRING_PRESETS.values():
        for k, v in spring.to_dict().items():
            validate_parameter(f"hero.spring.{k}", v)


# ---------------------------------------------------------------- param_for
def test_param_for_resolves_document_paths():
    assert param_for("fps") is PROJECT["fps"]
    assert param_for("ik.solver") is IK["ik.solver"]
    assert param_for("light2.intensity") is LIGHTS["light2.intensity"]
    assert param_for("hero.pendulum.damping") is PENDULUM["damping"]
    assert param_for("my.hero.spring.mix") is SPRING["mix"]
    assert param_for("hero.pendulum.preset").choices == ("physical", "handout", "handout_3a")
    assert param_for("hero.spring.preset").default == "soft"
    for unknown in ("cloth.wind", "hero.pendulum.nothing", "pip.limits.head", ".pendulum.g", "animation.key_all"):
        assert param_for(unknown) is None


# ---------------------------------------------------------------- validate
@pytest.mark.parametrize("path, lo, hi", [
    ("hero.pendulum.restitution", 0.0, 1.0),
    ("hero.pendulum.damping", 0.0, 1e6),
    ("hero.spring.mix", 0.0, 1.0),
    ("light1.intensity", 0.0, 1000.0),
    ("ik.max_iterations", 1, 10_000),
    ("fps", 0.01, 10000.0),
])
def test_validate_accepts_the_limits_and_refuses_beyond_them_naming_the_setting(path, lo, hi):
    p = param_for(path)
    assert p is not None
    assert p.validate(lo, path) == lo and p.validate(hi, path) == hi
    step = 1 if p.kind == "int" else 1e-6 * max(abs(hi), 1.0)
    for bad in (lo - step, hi + step):
        with pytest.raises(ValueError) as info:
            p.validate(bad, path)
        message = str(info.value)
        assert path in message and p.label in message and "from" in message


def test_validate_checks_kinds():
    with pytest.raises(ValueError, match="one of dls, ccd, fabrik, handout"):
        validate_parameter("ik.solver", "newton")
    with pytest.raises(ValueError, match="true or false"):
        validate_parameter("ik.two_bone", 1)
    with pytest.raises(ValueError, match="whole number"):
        validate_parameter("frame_end", 240.5)
    with pytest.raises(ValueError):
        validate_parameter("fps", True)
    with pytest.raises(ValueError):
        validate_parameter("fps", math.nan)
    with pytest.raises(ValueError, match="3 colour components"):
        validate_parameter("light1.color", [1.0, 0.5])
    with pytest.raises(ValueError):
        validate_parameter("lights.ambient", [0.1, 0.2, 1.5])
    assert validate_parameter("fps", 24) == 24 and isinstance(validate_parameter("fps", 24), int)
    assert validate_parameter("light1.position", [-1e5, 0.0, 3.0]) == [-1e5, 0.0, 3.0]
    assert validate_parameter("fps", None) is None               # unset: always allowed
    assert validate_parameter("cloth.wind", {"speed": 1}) == {"speed": 1}   # unknown: anything


def test_reasons_are_shown():
    with pytest.raises(ValueError, match="gain energy"):
        validate_parameter("hero.pendulum.restitution", 1.5)
    with pytest.raises(ValueError, match="at least 1e-05 s"):
        validate_parameter("hero.pendulum.step", 0.0)
    with pytest.raises(ValueError, match="adds energy"):
        validate_parameter("hero.spring.damping", -1.0)


def test_a_param_refuses_an_unknown_kind_or_a_default_outside_its_choices():
    with pytest.raises(ValueError):
        Param("x", 1, "complex", "X")
    with pytest.raises(ValueError):
        Param("x", "c", "choice", "X", choices=("a", "b"))


# -------------------------------------------------------------- SetParameter
def test_set_parameter_refuses_an_out_of_range_value_and_the_document_is_unchanged():
    doc = Document()
    stack = UndoStack(doc)
    seen = []
    doc.subscribe(seen.append)
    before = doc.state()
    for path, value in (("fps", 0.0), ("fps", [30]), ("frame_end", 1.5), ("ik.max_iterations", 0),
                        ("light1.intensity", -1.0), ("hero.pendulum.restitution", 2.0), ("hero.spring.mix", -0.1),
                        ("hero.pendulum.preset", "nope")):
        with pytest.raises(ValueError, match=path.replace(".", r"\.")):
            stack.push(SetParameter(doc, path, value))
    assert doc.state() == before and not seen and not stack.undo()


def test_set_parameter_takes_valid_values_unset_and_unknown_paths():
    doc = Document()
    stack = UndoStack(doc)
    stack.push(SetParameter(doc, "fps", 24))
    stack.push(SetParameter(doc, "light1.intensity", 1.5))   # above 1 is fine
    stack.push(SetParameter(doc, "hero.pendulum.restitution", 1.0))
    stack.push(SetParameter(doc, "light1.intensity", None))  # unset
    stack.push(SetParameter(doc, "cloth.wind", {"speed": 2.0}))
    assert doc.parameters["fps"] == 24 and "light1.intensity" not in doc.parameters
    assert doc.parameters["hero.pendulum.restitution"] == 1.0
    stack.push(SetParameter(doc, "hero.pendulum.damping", -5.0, validate=False))  # a test's escape hatch
    assert doc.parameters["hero.pendulum.damping"] == -5.0


def test_a_stored_value_out_of_range_still_loads_and_is_reported(tmp_path):
    """Opening a project never refuses a setting the schema would (a hand-written file, an
    older version): it loads as stored; parameter_problems names it."""
    from qtanimator.document import open_document, save_document

    doc = Document()
    stack = UndoStack(doc)
    stack.push(SetParameter(doc, "ik.max_iterations", 50_000, validate=False))
    stack.push(SetParameter(doc, "light1.intensity", -2.0, validate=False))
    path = tmp_path / "old.qtanim"
    save_document(doc, path)
    loaded = open_document(path)
    assert loaded.parameters["ik.max_iterations"] == 50_000 and loaded.parameters["light1.intensity"] == -2.0
    problems = parameter_problems(loaded.parameters)
    assert set(problems) == {"ik.max_iterations", "light1.intensity"}
    assert "from 1 to 10000" in problems["ik.max_iterations"]
