"""Spring and bouncing joints in the GUI (issue 18 item 4): the joint's "Driven by" choice in
Properties (keys / pendulum / spring, one undo step), the Springs group with its presets and
values, the pendulums' Bounce (restitution), the rig menu's Spring Joint; and a character
with a bouncing pendulum and a spring playing, drawn inside its limits."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QComboBox, QDoubleSpinBox, QGroupBox, QLabel

from qtanimator.core.channel import Key
from qtanimator.document import SetKeys
from qtanimator.document import character2d as c2d

RIG = """<svg xmlns="http://www.w3.org/2000/svg" width="400" height="400">
<g>
  <g><rect x="150" y="50" width="100" height="100" fill="#888"/><circle cx="200" cy="100" r="4" fill="#000"/></g>
  <g><rect x="195" y="150" width="10" height="100" fill="#c33"/><circle cx="200" cy="150" r="4" fill="#FFFFFF"/></g>
  <g><rect x="250" y="95" width="100" height="10" fill="#3c3"/><circle cx="250" cy="100" r="4" fill="#000"/></g>
</g>
</svg>
"""


@pytest.fixture
def rig(make_window, qtbot, tmp_path: Path):
    (tmp_path / "rig.svg").write_text(RIG)
    window = make_window(active=False)
    assert window.open_path(tmp_path / "rig.svg")
    window.ctx.undo_stack.clear()
    return window, window.properties_panel, next(iter(window.doc.assets))


def test_driven_by_makes_a_spring_joint_in_one_undo_step(qtbot, rig) -> None:
    window, panel, aid = rig
    doc = window.doc
    window.ctx.select(aid, "joint2")
    assert panel.findChild(QLabel, "jointType").text() == "keyframed"
    assert panel.findChild(QGroupBox, "springProperties") is None
    mode = panel.findChild(QComboBox, "jointMode")
    mode.setCurrentIndex(mode.findData("spring"))
    qtbot.waitUntil(lambda: c2d.character(doc, aid).joints[2].is_spring)
    assert window.ctx.undo_stack.count() == 1
    qtbot.waitUntil(lambda: panel.findChild(QGroupBox, "springProperties") is not None)
    assert panel.findChild(QLabel, "jointType").text() == "spring"
    preset = panel.findChild(QComboBox, "springPreset")
    assert preset.currentText() == "soft"
    preset.setCurrentText("stiff")
    assert c2d.spring_params(doc, aid).stiffness == 1000.0
    mix = panel.findChild(QDoubleSpinBox, f"param_{aid}_spring_mix")
    mix.setValue(0.5)
    assert c2d.spring_params(doc, aid).mix == 0.5
    assert preset.currentText() == "custom"
    typed(qtbot, mix, "2")  # refused (mix is 0 … 1), not clamped to 1
    assert c2d.spring_params(doc, aid).mix == 0.5
    assert mix.maximum() == 1.0
    for _ in range(3):
        window.ctx.undo_stack.undo()
    assert not c2d.character(doc, aid).joints[2].is_spring
    assert "rig" not in doc.assets[aid].properties


def typed(qtbot, box: QDoubleSpinBox, text: str) -> None:
    """Type ``text`` into a field as a user does (select all, type, Enter)."""
    qtbot.mouseClick(box, Qt.MouseButton.LeftButton)
    qtbot.keyClick(box, Qt.Key.Key_A, Qt.KeyboardModifier.ControlModifier)
    qtbot.keyClicks(box, text)
    qtbot.keyClick(box, Qt.Key.Key_Return)


def test_the_root_cannot_become_a_pendulum(qtbot, rig) -> None:
    window, panel, aid = rig
    window.ctx.select(aid, "root")
    mode = panel.findChild(QComboBox, "jointMode")
    mode.setCurrentIndex(mode.findData("dynamic"))
    qtbot.waitUntil(lambda: panel.findChild(QComboBox, "jointMode") is not mode)  # rebuilt: back to "Keys"
    assert panel.findChild(QComboBox, "jointMode").currentData() == "keyframed"
    assert not c2d.character(window.doc, aid).joints[0].is_dynamic
    assert window.ctx.undo_stack.count() == 0
    assert "root" in window.statusBar().currentMessage()


def test_bounce_is_a_pendulum_parameter(qtbot, rig) -> None:
    window, panel, aid = rig
    window.ctx.select(aid, "")
    box = panel.findChild(QDoubleSpinBox, f"param_{aid}_pendulum_restitution")
    assert box.value() == pytest.approx(0.5)
    box.setValue(0.9)
    assert c2d.pendulum_params(window.doc, aid).restitution == 0.9
    typed(qtbot, box, "1.5")  # refused (a bounce above 1 would gain energy), not clamped to 1
    assert c2d.pendulum_params(window.doc, aid).restitution == 0.9


def test_a_bouncing_and_springing_character_plays_inside_its_limits(qtbot, rig, tmp_path: Path) -> None:
    window, panel, aid = rig
    doc = window.doc
    from qtanimator.document.rigging import set_joint_mode_command

    window.ctx.push(set_joint_mode_command(doc, aid, "joint2", "spring"))
    window.ctx.push(c2d.set_joint_limits_command(doc, aid, "joint1", -0.15, 0.5))
    root = c2d.angle_channel_id(aid, "root")
    window.ctx.push(SetKeys(doc, {c2d.angle_channel_id(aid, "joint1"): Key(0.0, 0.45),
                                  c2d.angle_channel_id(aid, "joint2"): Key(0.0, 0.0)}))
    window.ctx.push(SetKeys(doc, {root: Key(0.0, 0.0)}))
    window.ctx.push(SetKeys(doc, {root: Key(0.5, 0.6)}))
    window.ctx.push(SetKeys(doc, {c2d.angle_channel_id(aid, "joint2"): Key(0.5, 0.8)}))
    window.ctx.select(aid, "joint1")
    play = window.findChild(type(window.action_save), "actionPlay")
    play.trigger()
    qtbot.wait(1200)
    play.trigger()
    assert window.ctx.frame > 0
    frames = range(0, 90)
    for f in frames:
        local = c2d.joint_angles(doc, aid, f / doc.fps)[1]
        assert -0.15 - 1e-9 <= local <= 0.5 + 1e-9
    angle = panel.findChild(QLabel, "jointAngle").text()
    assert angle.endswith("°") and -0.15 - 1e-6 <= math.radians(float(angle[:-1])) <= 0.5 + 1e-6
