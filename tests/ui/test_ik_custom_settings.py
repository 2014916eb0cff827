"""A right-drag IK keys the same channels whatever the IK settings (issue 17 item 5).

With key-all on (``animation.key_all``) an IK drag sets the universal keyframe: every
keyframed joint and the position of every 2D character of the demo, listed here by hand. A
drag with any IK setting changed from its default (another solver, the two-bone solver off,
a bend side, a free root, other iteration counts or steps) must key exactly that set too,
and with key-all off only the joints the solve moved, each with one key at the drag's
frame. Driven by real mouse events on the 2D editor of the demo project.
"""

from __future__ import annotations

import pytest
from PySide6.QtCore import QEvent, QPoint, Qt
from rig_helpers import hand_point, open_demo, send_mouse

from qtanimator.document import character2d as c2d
from qtanimator.document.commands import SetParameter
from qtanimator.document.ik_settings import IK_DEFAULTS

FRAME = 37.0  # no channel of the demo has a key here

#: Every keyframed joint and the position of every 2D character of the demo (by hand).
UNIVERSAL = {
    "pip/torso/angle", "pip/head/angle", "pip/leg_left/angle", "pip/leg_right/angle",
    "pip/upper_arm_left/angle", "pip/forearm_left/angle", "pip/hand_left/angle",
    "pip/upper_arm_right/angle", "pip/forearm_right/angle", "pip/hand_right/angle", "pip//x", "pip//y",
    "pendulum_clock/clock/angle", "pendulum_clock/hour_hand/angle", "pendulum_clock/minute_hand/angle",
    "pendulum_clock//x", "pendulum_clock//y",
    "robot/body/angle", "robot/leg_left/angle", "robot/shin_left/angle", "robot/leg_right/angle",
    "robot/shin_right/angle", "robot/head/angle", "robot/arm_left/angle", "robot/forearm_left/angle",
    "robot/claw_left/angle", "robot/arm_right/angle", "robot/forearm_right/angle", "robot/claw_right/angle",
    "robot//x", "robot//y",
}
#: Pip's right arm chain (what a drag on the right hand may move with the root frozen).
RIGHT_ARM = {"pip/upper_arm_right/angle", "pip/forearm_right/angle", "pip/hand_right/angle"}

#: One non-default value for every IK setting (each alone is a "custom settings" drag).
CUSTOM: list[dict[str, object]] = [
    {"ik.solver": "ccd"},
    {"ik.solver": "fabrik"},
    {"ik.solver": "handout", "ik.handout_step": 5e-5, "ik.handout_iterations": 30},
    {"ik.two_bone": False},
    {"ik.bend_direction": "positive"},
    {"ik.freeze_root": False},
    {"ik.max_iterations": 37},
    {"ik.damping": 0.05},
    {"ik.handout_step": 2e-6},
    {"ik.handout_iterations": 11},
    {"ik.gradient_arrow_scale": 0.3},
    {"ik.solver": "ccd", "ik.two_bone": False, "ik.max_iterations": 20},
]


def test_custom_list_covers_every_setting() -> None:
    named = set().union(*CUSTOM)
    assert named == set(IK_DEFAULTS)
    for custom in CUSTOM:
        assert all(IK_DEFAULTS[k] != v for k, v in custom.items())


@pytest.fixture
def demo(make_window, qtbot):  # type: ignore[no-untyped-def]
    window, view = open_demo(make_window, qtbot, focus=True)
    window.ctx.set_frame(FRAME)
    return window, view


def channels(doc) -> dict:  # type: ignore[no-untyped-def]
    return {cid: ch.to_dict() for cid, ch in doc.channels.items()}


def changed(before: dict, doc) -> set[str]:  # type: ignore[no-untyped-def]
    now = channels(doc)
    return {cid for cid in set(now) | set(before) if now.get(cid) != before.get(cid)}


def right_drag(view, start: QPoint, offset: QPoint, steps: int = 4) -> None:  # type: ignore[no-untyped-def]
    button = Qt.MouseButton.RightButton
    send_mouse(view, QEvent.Type.MouseButtonPress, start, button, button)
    for i in range(1, steps + 1):
        p = start + QPoint(offset.x() * i // steps, offset.y() * i // steps)
        send_mouse(view, QEvent.Type.MouseMove, p, Qt.MouseButton.NoButton, button)
    send_mouse(view, QEvent.Type.MouseButtonRelease, start + offset, button, Qt.MouseButton.NoButton)


def set_parameters(window, values: dict[str, object]) -> None:  # type: ignore[no-untyped-def]
    for name, value in values.items():
        window.ctx.push(SetParameter(window.doc, name, value))


def keyed_by_drag(window, view, settings: dict[str, object], key_all: bool) -> set[str]:  # type: ignore[no-untyped-def]
    doc, ctx = window.doc, window.ctx
    set_parameters(window, {c2d.KEY_ALL_PARAMETER: key_all, **settings})
    for name, value in settings.items():
        assert c2d.ik_setting(doc, name) == value
    before = channels(doc)
    steps_before = ctx.undo_stack.count()
    right_drag(view, hand_point(window, view), QPoint(-30, 25))
    assert ctx.undo_stack.count() == steps_before + 1  # one undo step
    keyed = changed(before, doc)
    for cid in keyed:  # every change is a key at the drag's frame
        times = [k.time * doc.fps for k in doc.channels[cid].keys]
        assert any(abs(t - FRAME) < 1e-9 for t in times), cid
    return keyed


@pytest.mark.parametrize("settings", CUSTOM, ids=lambda s: ",".join(f"{k[3:]}={v}" for k, v in s.items()))
def test_key_all_ik_drag_keys_the_universal_keyframe_with_custom_settings(demo, settings) -> None:  # type: ignore[no-untyped-def]
    window, view = demo
    assert keyed_by_drag(window, view, settings, key_all=True) == UNIVERSAL


def test_key_all_ik_drag_with_default_settings_keys_the_same(demo) -> None:  # type: ignore[no-untyped-def]
    window, view = demo
    assert all(window.doc.parameter(k, v) == v for k, v in IK_DEFAULTS.items())
    assert keyed_by_drag(window, view, {}, key_all=True) == UNIVERSAL


@pytest.mark.parametrize("settings", [{}, {"ik.solver": "ccd"}, {"ik.two_bone": False, "ik.max_iterations": 37}],
                         ids=["defaults", "ccd", "no_two_bone"])
def test_without_key_all_an_ik_drag_keys_only_the_arm_it_moved(demo, settings) -> None:  # type: ignore[no-untyped-def]
    window, view = demo
    keyed = keyed_by_drag(window, view, settings, key_all=False)
    assert keyed and keyed <= RIGHT_ARM
