"""Playback in the 2D rig editor: frame time of evaluate + simulate + draw on owl.svg.

Run: ``.venv/bin/python benchmarks/bench_playback.py`` (prints a table), or call ``run()``
for the rows. owl.svg is the largest reference scene (95 joints, 86 of them pendulums).

What one played frame costs, measured as the editor does it: the frame changes, the view
evaluates every character's pose (keyframes, and the pendulums, simulated one frame
further from the cache because playback moves forward), and repaints its 960×640 viewport
(while playing it draws each joint from a sprite cached at the current zoom; a still frame
is drawn as vectors with the shared QPainter renderer — both are reported). The owl gets
a keyframed sway of its root (three position keys) so that the pendulums are driven.
240 frames are played from an empty simulation cache; the figure is the mean frame time,
with the worst frame and the split between evaluate + simulate and draw as extra rows.
``QTANIMATOR_BENCH_CPU=1`` times this process's CPU instead of the wall clock (for a
machine shared with other jobs).

The peer is the same frames drawn by the headless export path (``render_frame`` into a
960×640 image, cache already warm): the cost of drawing the owl without a widget.
Goal (issue 6): 60 frames per second or better, i.e. a frame in at most 16.7 ms.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from benchmarks.common import print_rows  # noqa: E402

OWL = (REPO / ".." / "shared" / "data" / "cmu-animator" / "scenes" / "owl.svg").resolve()
FRAMES = 240
SIZE = (960, 640)
GOAL_FPS = 60.0
#: Wall clock by default; QTANIMATOR_BENCH_CPU=1 measures this process's CPU time instead
#: (useful on a machine shared with other jobs).
CLOCK = time.process_time if os.environ.get("QTANIMATOR_BENCH_CPU") else time.perf_counter


def _skipped(reason: str) -> list[dict[str, Any]]:
    return [{"name": "playback owl.svg: evaluate + simulate + draw", "figure": None, "unit": "fps",
             "peer figure": None, "ratio": None, "goal": f">= {GOAL_FPS:g} fps", "skipped": reason}]


def run() -> list[dict[str, Any]]:
    if not OWL.is_file():
        return _skipped(f"owl.svg not found at {OWL}")
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    from PySide6.QtWidgets import QApplication

    app = QApplication.instance() or QApplication([])
    from qtanimator.core.channel import Key
    from qtanimator.document import character2d as c2d
    from qtanimator.document.commands import SetKeys
    from qtanimator.render.painter2d import render_frame
    from qtanimator.ui.context import EditorContext
    from qtanimator.ui.rig_editor import RigEditorView

    ctx = EditorContext()
    doc = ctx.doc
    ctx.push(c2d.add_characters_command(doc, OWL))
    asset = next(iter(doc.assets))
    character = doc.runtime[asset]
    fps = doc.fps
    ctx.push(SetKeys(doc, {f"{asset}//x": Key(0.0, 0.0), f"{asset}//y": Key(0.0, 0.0)}))
    ctx.push(SetKeys(doc, {f"{asset}//x": Key(1.0, 80.0), f"{asset}//y": Key(1.0, -30.0)}))
    ctx.push(SetKeys(doc, {f"{asset}//x": Key(2.0, -60.0), f"{asset}//y": Key(2.0, 10.0)}))
    view = RigEditorView(ctx)
    view.resize(*SIZE)
    view.show()
    app.processEvents()
    view.fit_view()
    view.viewport().repaint()  # build the renderer's paths once

    evaluate_ms: list[float] = []
    draw_ms: list[float] = []
    total_ms: list[float] = []
    sim = c2d.simulation(doc)
    sim.invalidate()
    ctx.playingChanged.emit(True)  # what Playback announces: the editor draws joint sprites
    for frame in range(1, FRAMES + 1):
        t0 = CLOCK()
        ctx.set_frame(float(frame))
        # The simulation worker fills the cache in the app; here the frame is stepped on this
        # thread so that "evaluate + simulate" is the cost of one frame of both.
        sim.state(asset, frame)
        view.poses()  # evaluate keyframes, read the pendulums from the cache
        t1 = CLOCK()
        view.viewport().repaint()
        t2 = CLOCK()
        evaluate_ms.append((t1 - t0) * 1e3)
        draw_ms.append((t2 - t1) * 1e3)
        total_ms.append((t2 - t0) * 1e3)
    assert sim.cached_frames(asset) >= FRAMES
    ctx.playingChanged.emit(False)
    vector_ms: list[float] = []
    for frame in range(1, FRAMES + 1, 4):  # still frames: vectors, cache warm
        ctx.set_frame(float(frame))
        view.poses()
        t1 = CLOCK()
        view.viewport().repaint()
        vector_ms.append((CLOCK() - t1) * 1e3)

    peer_ms: list[float] = []
    for frame in range(1, FRAMES + 1, 4):
        t0 = CLOCK()
        render_frame(doc, frame / fps, SIZE, "white")
        peer_ms.append((CLOCK() - t0) * 1e3)
    view.close()

    mean = sum(total_ms) / len(total_ms)
    peer = sum(peer_ms) / len(peer_ms)
    ours_fps = 1000.0 / mean
    peer_fps = 1000.0 / peer
    joints = f"{len(character.joints)} joints, {int(character.dynamic.sum())} dynamic"
    return [
        {"name": f"playback owl.svg ({joints}): evaluate + simulate + draw, mean of {FRAMES} frames",
         "figure": round(ours_fps, 1), "unit": "fps", "peer figure": round(peer_fps, 1),
         "ratio": round(ours_fps / peer_fps, 3), "goal": f">= {GOAL_FPS:g} fps",
         "peer": "render_frame (export renderer, 960x640 image, warm cache)"},
        {"name": "playback owl.svg: mean frame time", "figure": round(mean, 2), "unit": "ms",
         "peer figure": round(peer, 2), "ratio": round(peer / mean, 3), "goal": f"<= {1000 / GOAL_FPS:.1f} ms"},
        {"name": "playback owl.svg: worst frame", "figure": round(max(total_ms), 2), "unit": "ms",
         "peer figure": round(max(peer_ms), 2), "ratio": round(max(peer_ms) / max(total_ms), 3), "goal": ""},
        {"name": "playback owl.svg: evaluate + simulate per frame", "figure": round(sum(evaluate_ms) / FRAMES, 2),
         "unit": "ms", "peer figure": None, "ratio": None, "goal": ""},
        {"name": "playback owl.svg: draw per frame (960x640 viewport, joint sprites)",
         "figure": round(sum(draw_ms) / FRAMES, 2), "unit": "ms",
         "peer figure": round(sum(vector_ms) / len(vector_ms), 2),
         "ratio": round((sum(vector_ms) / len(vector_ms)) / (sum(draw_ms) / FRAMES), 3), "goal": "",
         "peer": "the same view drawing vectors (a still frame)"},
    ]


def main() -> int:
    return print_rows(run(), ["name", "figure", "unit", "peer figure", "ratio", "goal"])


if __name__ == "__main__":
    sys.exit(main())
