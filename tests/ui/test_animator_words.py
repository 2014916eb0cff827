"""Words for animators (issue 16, item 6): the Properties dock speaks the animator's language
(course names in tool tips), and the curve editor opens on something readable."""

from __future__ import annotations

import math
from pathlib import Path

from PySide6.QtWidgets import QFormLayout, QGroupBox, QLabel, QWidget

DEMO = Path(__file__).resolve().parents[2] / "scenes" / "demo" / "demo.qtanim"


def form_rows(group: QGroupBox) -> dict[str, QWidget]:
    form = group.layout()
    assert isinstance(form, QFormLayout)
    rows = {}
    for r in range(form.rowCount()):
        label = form.itemAt(r, QFormLayout.ItemRole.LabelRole)
        field = form.itemAt(r, QFormLayout.ItemRole.FieldRole)
        if label is not None and field is not None and isinstance(label.widget(), QLabel):
            rows[label.widget().text()] = field.widget()
    return rows


def test_ik_and_pendulum_settings_use_the_animators_words(make_window):
    window = make_window(editors=("rig_editor", "timeline", "properties"))
    assert window.open_path(DEMO)
    window.ctx.select("pip", "")
    ik = form_rows(window.findChild(QGroupBox, "ikProperties"))
    assert "Smoothness" in ik and "damped least squares" in ik["Smoothness"].toolTip()
    assert not any("DLS" in text or "Handout step" in text for text in ik)
    assert "course handout" in ik["Solver"].toolTip()
    pendulums = form_rows(window.findChild(QGroupBox, "pendulumProperties"))
    assert "Damping" in pendulums and "e^(−a·τ)" in pendulums["Damping"].toolTip()
    assert "Follow the body" in pendulums


def test_the_curve_editor_opens_normalised_and_frames_the_selected_joint(make_window, qtbot):
    window = make_window(editors=("rig_editor", "timeline", "curve_editor"))
    assert window.open_path(DEMO)
    view = window.curve_editor.view
    # Pip's x position spans hundreds of units and the joints' angles tens of degrees (shown
    # in degrees): comparable, so the editor opens in raw values.
    assert not view.normalised
    view.set_normalised(False)  # in raw values, framing all would span the positions' hundreds
    view.frame_all()
    window.ctx.select("pip", "forearm_left")
    (x0, x1), (y0, y1) = view.vb.viewRange()
    cid = "pip/forearm_left/angle"
    off, scale = view.display_transform(cid)
    values = (window.doc.channels[cid].values - off) * scale
    times = window.doc.channels[cid].times * window.doc.fps
    assert y0 <= values.min() and values.max() <= y1
    assert x0 <= times.min() and times.max() <= x1
    # Framed on the joint: its curve fills a good part of the view, not a sliver of it.
    assert (values.max() - values.min()) > 0.3 * (y1 - y0)
    assert y1 - y0 < 20.0 * 180.0 / math.pi   # degrees
