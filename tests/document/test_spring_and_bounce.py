"""Spring joints and bouncing pendulums in the document (issue 18 item 4): the joint mode is
part of the rig (undoable, saved), springs run in the pendulum cache and its worker, a spring
at rest follows its keys exactly, a step in its keys gives the closed-form response at every
frame, mix 0 is the keys, and a pendulum with limits stays inside them while it bounces."""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from qtanimator.core.channel import Interpolation, Key
from qtanimator.document import Document, SetKeys, SetParameter, UndoStack, open_document, save_document
from qtanimator.document.character2d import (
    add_characters_command,
    angle_channel_id,
    character,
    joint_angles,
    keyframed_angles,
    set_joint_limits_command,
    set_spring_preset,
    simulation,
    simulation_ready,
    spring_params,
)
from qtanimator.document.rigging import RigError, joint_mode, set_joint_mode_command
from qtanimator.document.simulation import shutdown_all

RIG = """<svg xmlns="http://www.w3.org/2000/svg" width="400" height="400">
<g>
  <g><rect x="150" y="50" width="100" height="100" fill="#888"/><circle cx="200" cy="100" r="4" fill="#000"/></g>
  <g><rect x="195" y="150" width="10" height="100" fill="#c33"/><circle cx="200" cy="150" r="4" fill="#FFFFFF"/></g>
  <g><rect x="250" y="95" width="100" height="10" fill="#3c3"/><circle cx="250" cy="100" r="4" fill="#000"/></g>
</g>
</svg>
"""


@pytest.fixture(autouse=True)
def no_threads_left() -> Iterator[None]:
    yield
    shutdown_all()


def make(tmp_path: Path) -> tuple[Document, UndoStack, str]:
    """root (keyframed), joint1 (a pendulum hanging below), joint2 (a bar to the right) as a spring."""
    (tmp_path / "rig.svg").write_text(RIG)
    doc = Document()
    stack = UndoStack(doc)
    stack.push(add_characters_command(doc, tmp_path / "rig.svg"))
    aid = next(iter(doc.assets))
    stack.push(set_joint_mode_command(doc, aid, "joint2", "spring"))
    return doc, stack, aid


def key(doc: Document, stack: UndoStack, cid: str, t: float, v: float, stepped: bool = False) -> None:
    k = Key(t, v, interpolation=Interpolation.CONSTANT) if stepped else Key(t, v)
    stack.push(SetKeys(doc, {cid: k}))


def test_the_joint_mode_is_an_undoable_rig_edit_that_is_saved(tmp_path: Path) -> None:
    doc, stack, aid = make(tmp_path)
    ch = character(doc, aid)
    assert [j.is_spring for j in ch.joints] == [False, False, True]
    assert joint_mode(doc, aid, "joint2") == "spring" and joint_mode(doc, aid, "joint1") == "dynamic"
    assert ch.simulated.tolist() == [False, True, True]
    stack.push(set_spring_preset(doc, aid, "stiff"))
    assert spring_params(doc, aid).stiffness == 1000.0
    save_document(doc, tmp_path / "p.qtanim")
    again = open_document(tmp_path / "p.qtanim")
    assert [j.is_spring for j in character(again, aid).joints] == [False, False, True]
    assert spring_params(again, aid) == spring_params(doc, aid)
    stack.undo()
    stack.undo()
    assert "rig" not in doc.assets[aid].properties
    assert not character(doc, aid).spring.any()
    stack.redo()
    stack.push(set_joint_mode_command(doc, aid, "joint2", "dynamic"))
    assert joint_mode(doc, aid, "joint2") == "dynamic"
    stack.push(set_joint_mode_command(doc, aid, "joint2", "keyframed"))
    assert joint_mode(doc, aid, "joint2") == "keyframed"
    with pytest.raises(RigError):
        set_joint_mode_command(doc, aid, "root", "dynamic")
    with pytest.raises(RigError):
        set_joint_mode_command(doc, aid, "joint2", "wobbly")


def test_a_spring_at_rest_follows_its_keys_exactly(tmp_path: Path) -> None:
    doc, stack, aid = make(tmp_path)
    cid = angle_channel_id(aid, "joint2")
    key(doc, stack, cid, 0.0, 0.3)
    key(doc, stack, cid, 2.0, 0.3)
    key(doc, stack, angle_channel_id(aid, "root"), 0.0, 0.2)
    for f in range(0, 150):
        t = f / doc.fps
        assert joint_angles(doc, aid, t)[2] == keyframed_angles(doc, aid, t)[2] == 0.3


def test_a_step_in_the_keys_gives_the_closed_form_response(tmp_path: Path) -> None:
    doc, stack, aid = make(tmp_path)
    cid = angle_channel_id(aid, "joint2")
    key(doc, stack, cid, 0.0, 0.0, stepped=True)
    key(doc, stack, cid, 0.5, 0.7, stepped=True)
    p = spring_params(doc, aid)
    k, c = p.stiffness, p.damping
    sigma, wd = c / 2.0, math.sqrt(k - (c / 2.0) ** 2)
    for f in range(0, 200):
        t = f / doc.fps
        got = joint_angles(doc, aid, t)[2]
        if t < 0.5 - 1e-9:
            assert got == 0.0
            continue
        s = t - 0.5
        exact = 0.7 * (1.0 - math.exp(-sigma * s) * (math.cos(wd * s) + sigma / wd * math.sin(wd * s)))
        assert got == pytest.approx(exact, abs=1e-6)


def test_mix_zero_shows_the_keys_and_half_blends(tmp_path: Path) -> None:
    doc, stack, aid = make(tmp_path)
    cid = angle_channel_id(aid, "joint2")
    key(doc, stack, cid, 0.0, 0.0)
    key(doc, stack, cid, 0.4, 1.0)
    key(doc, stack, cid, 0.8, -0.5)
    times = [f / doc.fps for f in range(0, 90)]
    sprung = [joint_angles(doc, aid, t)[2] for t in times]
    keyed = [keyframed_angles(doc, aid, t)[2] for t in times]
    assert max(abs(a - b) for a, b in zip(sprung, keyed)) > 0.05  # it lags and overshoots
    stack.push(SetParameter(doc, f"{aid}.spring.mix", 0.0))
    assert [joint_angles(doc, aid, t)[2] for t in times] == keyed
    stack.push(SetParameter(doc, f"{aid}.spring.mix", 0.5))
    half = [joint_angles(doc, aid, t)[2] for t in times]
    np.testing.assert_allclose(half, 0.5 * np.array(keyed) + 0.5 * np.array(sprung), atol=1e-12)


def test_springs_run_on_the_worker_and_edits_invalidate(tmp_path: Path) -> None:
    doc, stack, aid = make(tmp_path)
    cid = angle_channel_id(aid, "joint2")
    key(doc, stack, cid, 0.0, 0.0)
    key(doc, stack, cid, 0.3, 1.0)
    exact = [joint_angles(doc, aid, f / doc.fps)[2] for f in range(40)]
    simulation(doc).invalidate(aid)
    assert not simulation_ready(doc, 39 / doc.fps)
    joint_angles(doc, aid, 39 / doc.fps, block=False)  # a view asks: the worker fills
    assert simulation(doc).wait_idle(60.0)
    assert simulation_ready(doc, 39 / doc.fps)
    assert [joint_angles(doc, aid, f / doc.fps, block=False)[2] for f in range(40)] == exact
    stack.push(set_spring_preset(doc, aid, "stiff"))
    stiff = [joint_angles(doc, aid, f / doc.fps)[2] for f in range(40)]
    assert stiff != exact


def test_a_bouncing_pendulum_stays_inside_its_limits_under_a_turning_parent(tmp_path: Path) -> None:
    doc, stack, aid = make(tmp_path)
    stack.push(set_joint_limits_command(doc, aid, "joint1", -0.1, 0.4))
    key(doc, stack, angle_channel_id(aid, "joint1"), 0.0, 0.35)  # released at rest at 0.35
    root = angle_channel_id(aid, "root")
    key(doc, stack, root, 0.0, 0.0)
    key(doc, stack, root, 1.0, 0.8)
    key(doc, stack, root, 2.0, -0.4)
    lows = 0
    for f in range(0, 180):
        # The simulated world angle itself (not a display clamp) less the parent's, keyed.
        world = simulation(doc).state(aid, f)[0][1]
        local = world - keyframed_angles(doc, aid, f / doc.fps)[0]
        assert -0.1 - 1e-12 <= local <= 0.4 + 1e-12
        assert joint_angles(doc, aid, f / doc.fps)[1] == pytest.approx(local, abs=1e-12)
        lows += local < -0.0999
    assert lows >= 1  # it reached the lower limit


def test_restitution_changes_the_bounce(tmp_path: Path) -> None:
    doc, stack, aid = make(tmp_path)
    stack.push(set_joint_limits_command(doc, aid, "joint1", -0.1, 0.4))
    key(doc, stack, angle_channel_id(aid, "joint1"), 0.0, 0.35)
    swing = [joint_angles(doc, aid, f / doc.fps)[1] for f in range(120)]
    stack.push(SetParameter(doc, f"{aid}.pendulum.restitution", 1.0))
    elastic = [joint_angles(doc, aid, f / doc.fps)[1] for f in range(120)]
    assert max(elastic[40:]) > max(swing[40:]) + 0.01  # a perfect bounce swings back higher
