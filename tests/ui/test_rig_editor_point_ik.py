"""2D IK where you click: a right-drag on a limb pulls the point under the cursor, not the
joint's pivot (real mouse events on the demo's Pip)."""

from __future__ import annotations

import math

import numpy as np
from PySide6.QtCore import QPoint, QPointF, Qt
from rig_helpers import open_demo

from qtanimator.document import character2d as c2d
from qtanimator.ui.rig_interaction import pick


def test_right_drag_on_a_forearm_point_away_from_its_pivot_brings_that_point_to_the_cursor(make_window, qtbot):
    window, view = open_demo(make_window, qtbot)
    doc, t = window.doc, window.ctx.time
    ch = doc.runtime["pip"]
    joint = ch.joint_index("forearm_right")
    pose0 = c2d.evaluate_pose(doc, "pip", t, block=False)
    pivot = pose0.pivots[joint]
    # the point of the forearm's shape farthest from its pivot that picks the forearm
    pts = ch.joints[joint].shapes[0].points
    centre = pts.mean(axis=0)
    best = None
    for f in (0.9, 0.8, 0.7, 0.6, 0.5):
        for p in pts:
            world = pose0.to_world(joint, centre + f * (p - centre))
            xy = view.from_scene(world)
            pixel = QPoint(int(round(xy.x())), int(round(xy.y())))
            scene = view.to_scene(QPointF(pixel))
            if pick(doc, t, scene) == ("pip", joint):
                d = float(np.hypot(*(scene - pivot)))
                if best is None or d > best[0]:
                    best = (d, pixel, scene)
    assert best is not None and best[0] > 20.0     # well away from the pivot
    _d, start, press = best
    local = pose0.to_local(joint, press)
    # a reachable target: the press point turned 25° about the upper arm's pivot and drawn
    # in a little (the arm is straight: the press point is about as far as it reaches)
    shoulder = pose0.pivots[ch.joints[joint].parent]
    a = math.radians(25)
    rot = np.array([[math.cos(a), math.sin(a)], [-math.sin(a), math.cos(a)]])
    target = shoulder + 0.85 * rot @ (press - shoulder)
    vp = view.viewport()
    steps = window.ctx.undo_stack.count()
    qtbot.mousePress(vp, Qt.MouseButton.RightButton, pos=start)
    moves = []
    for f in (0.25, 0.5, 0.75, 1.0):
        xy = view.from_scene(press + f * (target - press))
        moves.append(QPoint(int(round(xy.x())), int(round(xy.y()))))
        qtbot.mouseMove(vp, moves[-1])
    qtbot.mouseRelease(vp, Qt.MouseButton.RightButton, pos=moves[-1])
    cursor = view.to_scene(QPointF(moves[-1]))
    pose1 = c2d.evaluate_pose(doc, "pip", t, block=False)
    assert np.hypot(*(pose1.to_world(joint, local) - cursor)) < 0.5        # the clicked point
    assert np.hypot(*(pose1.pivots[joint] - cursor)) > 10.0                # not the pivot
    assert window.ctx.undo_stack.count() == steps + 1
