"""Where the user looks when a simulation blows up: the Properties of the pendulum, the
timeline's cache bar and the status bar."""

from __future__ import annotations

from pathlib import Path

from PySide6.QtWidgets import QLabel

from qtanimator.document.commands import SetParameter

CLOCK = Path(__file__).resolve().parents[2] / "scenes" / "pendulum_clock.svg"


def test_a_pendulum_blow_up_is_shown_in_properties_cache_bar_and_status_bar(make_window, qtbot):
    window = make_window(editors=("rig_editor", "timeline", "properties"))
    assert window.open_path(CLOCK)
    asset = next(iter(window.doc.assets))
    window.ctx.select(asset, "")
    bar = window.timeline_dock.widget().timeline.cache_bar
    label = window.findChild(QLabel, "pendulumProblem")
    assert label is not None and not label.isVisible()
    window.ctx.push(SetParameter(window.doc, f"{asset}.pendulum.damping", -200.0, validate=False))
    window.ctx.set_frame(150.0)  # the editor asks for frame 150: the worker runs into the blow-up
    qtbot.waitUntil(lambda: bool(bar.failures()), timeout=20000)
    frame, message = bar.failures()[0]
    assert 0 < frame < 150 and "damping" in message
    assert bar.simulated() == (0, frame - 1)
    assert "Stopped at frame" in bar.toolTip()
    assert window.statusBar().currentMessage() == "Simulation stopped: " + message
    label = window.findChild(QLabel, "pendulumProblem")
    qtbot.waitUntil(label.isVisible, timeout=5000)
    assert message in label.text()
    # Undo: the report goes away everywhere.
    window.ctx.undo_stack.undo()
    qtbot.waitUntil(lambda: not bar.failures(), timeout=20000)
    assert window.statusBar().currentMessage() == ""


def test_a_cloth_blow_up_is_marked_on_the_cache_bar_and_in_the_status_bar(make_window, qtbot):
    from qtanimator.core.cloth import ClothParams
    from qtanimator.document.cloth import add_cloth_command

    window = make_window(full=True)
    params = ClothParams(rows=8, cols=8, structural_stiffness=1.0e4, substeps=1, integrator="symplectic")
    window.ctx.push(add_cloth_command(window.doc, params))
    window.central_tabs.setCurrentWidget(window.viewport3d.parentWidget() or window.viewport3d)
    window.ctx.set_frame(60.0)  # the 3D view asks for the cloth's frames: the worker blows up
    bar = window.timeline_dock.widget().timeline.cache_bar
    from qtanimator.document.cloth import cloth_problem
    (aid,) = [a for a, asset in window.doc.assets.items() if asset.kind == "cloth"]
    qtbot.waitUntil(lambda: cloth_problem(window.doc, aid) is not None, timeout=30000)
    qtbot.waitUntil(lambda: any("cloth" in m for _f, m in bar.failures()), timeout=30000)
    frame, message = next((f, m) for f, m in bar.failures() if "cloth" in m)
    assert 0 < frame < 60 and "substeps" in message
    assert window.statusBar().currentMessage().startswith("Simulation stopped: ")
