"""Curve editor: full redraws and drag frames on real and synthetic documents.

Run: ``.venv/bin/python benchmarks/bench_curve_editor.py`` (prints a table), or call
``run()`` for the rows. Uses the real widget (1400 × 700) on Qt's offscreen platform,
framed on all channels, every channel visible. Documents:

* ``wasp``: the CSE169 wasp walk (72 channels, ``../shared/data/cse169``);
* ``cmu walk``: the CMU walk BVH imported as the app imports it (96 channels × 524
  keys, ``../shared/data/bvh``);
* ``synthetic``: 300 channels × 2000 keys (one key per frame, smooth walk-like curves,
  every third channel with linear spans as a BVH import makes them).

Figures (milliseconds, each the time to a synchronous repaint of the plot):

* full redraw, cold: every path built from the channels and every curve and key drawn
  (what the first show or a document reset costs);
* full redraw: every curve and key drawn again with the paths kept (a resize, a change
  of highlighted channels, the cached layer's pixels dropped);
* pan / zoom frame: one view change (per-column paths are rebuilt when a zoom crosses
  a power-of-two level, extrapolation when a pan leaves its range);
* drag start: mouse press on an unselected key and the first move (the key's channel
  leaves the cached layer, which is drawn again without it);
* drag frame: one mouse move of a key drag (gesture update, one change per frame,
  only the dragged channel's paths rebuilt, the cached layer reused).

Each row gives the median with min–max over repeated runs (not best-of), the median CPU
time of this process (less sensitive to other jobs than the wall clock), the median as a
share of the 16.7 ms frame budget (``ratio`` = budget / median: above 1 fits a 60 Hz
frame) and the load average around the run (other jobs share the machine).
Goals: drag frame ≤ 16 ms; full redraw ≤ 50 ms at 300 × 2000.
"""

from __future__ import annotations

import os
import re
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from benchmarks.common import print_rows, skipped  # noqa: E402

SHARED = (REPO / ".." / "shared" / "data").resolve()
WASP = SHARED / "cse169" / "wasp_walk"
BVH = SHARED / "bvh" / "cmu_12_01_walk.bvh"
FRAME_MS = 1000.0 / 60.0
DRAG_GOAL_MS = 16.0
REDRAW_GOAL_MS = 50.0
MOVES = 40
REDRAWS = 15
DRAG_STARTS = 7


def _wasp_document() -> Any:
    from qtanimator.document import Document, channel_id
    from qtanimator.formats.anim import load_anim

    clip = load_anim(WASP / "wasp_walk.anim")
    joints = re.findall(r"balljoint\s+([^\s{]+)", (WASP / "wasp.skel").read_text())
    ids = [channel_id("wasp", "", d) for d in ("tx", "ty", "tz")]
    ids += [channel_id("wasp", j, d) for j in joints for d in ("rx", "ry", "rz")]
    return Document(channels=dict(zip(ids, clip.channels, strict=False)))


def _bvh_document() -> Any:
    from qtanimator.document import Document
    from qtanimator.document.import3d import bvh_import

    doc = Document()
    imported = bvh_import(doc, BVH)
    with doc.batch():
        imported.command.do(doc)
    return doc


def synthetic_document(channels: int = 300, keys: int = 2000, fps: float = 60.0) -> Any:
    """``channels`` channels of ``keys`` keys (one per frame) shaped like joint rotations
    of a long walk (degrees): a gait cycle of about a second with two harmonics, 2–25°
    amplitude, an offset anywhere in ±120°, capture noise; every third channel has linear
    spans (as a BVH import makes them)."""
    import numpy as np

    from qtanimator.core.channel import Channel, Interpolation, Key, Tangent
    from qtanimator.document import Document, channel_id

    rng = np.random.default_rng(12)
    built: dict[str, Channel] = {}
    t = np.arange(keys) / fps
    for c in range(channels):
        amp = rng.uniform(2, 25) * np.array([1.0, rng.uniform(0, 0.35), rng.uniform(0, 0.12)])
        freq = rng.uniform(0.8, 1.25) * np.array([1.0, 2.0, 3.0])
        phase = rng.uniform(0, 2 * np.pi, 3)
        v = sum(a * np.sin(2 * np.pi * f * t + p) for a, f, p in zip(amp, freq, phase))
        v = v + rng.normal(0, 0.2, keys) + rng.uniform(-120, 120)
        if c % 3 == 2:
            ks = [Key(float(a), float(b), Tangent.LINEAR, Tangent.LINEAR, interpolation=Interpolation.LINEAR)
                  for a, b in zip(t, v)]
        else:
            ks = [Key(float(a), float(b)) for a, b in zip(t, v)]
        built[channel_id("synth", f"joint{c // 3:03d}", "r" + "xyz"[c % 3])] = Channel(ks)
    return Document(channels=built, parameters={"frame_end": keys})


def _stats(name: str, timed: tuple[list[float], list[float]], goal: float | None,
           load: tuple[float, float]) -> dict[str, Any]:
    wall, cpu = timed
    med = statistics.median(wall)
    return {"name": name, "figure": round(med, 2), "unit": "ms (median)", "peer figure": None,
            "ratio": round(FRAME_MS / med, 2) if med > 0 else None,
            "goal": f"≤ {goal:g} ms" if goal is not None else "-",
            "min": round(min(wall), 2), "max": round(max(wall), 2), "runs": len(wall),
            "cpu median": round(statistics.median(cpu), 2),
            "of frame budget": f"{med / FRAME_MS:.2f}×", "load": f"{load[0]:.2f} → {load[1]:.2f}"}


def _timed(fn: Callable[[], None], repeats: int) -> tuple[list[float], list[float]]:
    """Wall-clock and CPU milliseconds of each of ``repeats`` calls."""
    wall, cpu = [], []
    for _ in range(repeats):
        c0 = time.process_time()
        t0 = time.perf_counter()
        fn()
        wall.append((time.perf_counter() - t0) * 1000.0)
        cpu.append((time.process_time() - c0) * 1000.0)
    return wall, cpu


def measure(doc: Any, label: str, redraw_goal: float | None) -> list[dict[str, Any]]:
    """Every figure of the module docstring for one document."""
    from PySide6.QtWidgets import QApplication

    app = QApplication.instance() or QApplication([])
    from qtanimator.ui.context import EditorContext
    from qtanimator.ui.curve_editor import CurveEditor

    load0 = os.getloadavg()[0]
    editor = CurveEditor(EditorContext(doc))
    editor.resize(1400, 700)
    editor.show()
    app.processEvents()
    editor.view.frame_all()
    app.processEvents()
    view, vp = editor.view, editor.plot.viewport()
    n = len(view.visible)
    keys = sum(len(doc.channels[c].keys) for c in view.visible)
    what = f"{label}, {n} channels / {keys} keys"
    vp.repaint()

    def cold() -> None:
        view.clear_drawings()  # what a reset does: nothing of the drawing is kept
        vp.repaint()

    def warm() -> None:
        view.refresh_all()
        vp.repaint()

    (x0, x1), _ = view.vb.viewRange()
    width = x1 - x0
    step = [0]

    def pan() -> None:
        step[0] += 1
        shift = 0.02 * width * (1 if step[0] % 2 else -1)
        (a, b), _ = view.vb.viewRange()
        view.vb.setXRange(a + shift, b + shift, padding=0)
        vp.repaint()

    def zoom() -> None:
        step[0] += 1
        (a, b), _ = view.vb.viewRange()
        mid, half = 0.5 * (a + b), 0.5 * (b - a)
        f = 1.3 if step[0] % 4 < 2 else 1 / 1.3
        view.vb.setXRange(mid - half * f, mid + half * f, padding=0)
        vp.repaint()

    cold_ms = _timed(cold, REDRAWS)
    warm_ms = _timed(warm, REDRAWS)
    pan_ms = _timed(pan, REDRAWS)
    zoom_ms = _timed(zoom, REDRAWS * 2)
    view.vb.setXRange(x0, x1, padding=0)
    app.processEvents()
    start_ms, move_ms = _drags(editor, app)
    load1 = os.getloadavg()[0]
    load = (load0, load1)
    rows = [
        _stats(f"curve editor ({what}): full redraw, cold (all paths built)", cold_ms, redraw_goal, load),
        _stats(f"curve editor ({what}): full redraw (paths kept)", warm_ms, redraw_goal, load),
        _stats(f"curve editor ({what}): pan frame", pan_ms, None, load),
        _stats(f"curve editor ({what}): zoom frame", zoom_ms, None, load),
        _stats(f"curve editor ({what}): drag start (press + first move)", start_ms, redraw_goal, load),
        _stats(f"curve editor ({what}): drag frame (one key)", move_ms, DRAG_GOAL_MS, load),
    ]
    editor.close()
    editor.deleteLater()
    app.processEvents()
    return rows


def _drags(editor: Any, app: Any) -> tuple[tuple[list[float], list[float]], tuple[list[float], list[float]]]:
    """DRAG_STARTS drags of the middle key of channels spread over the view, MOVES real
    mouse moves in the first one; each drag is undone. Wall and CPU times of the drag
    starts (press and first move, without the pause between them) and of the moves."""
    from PySide6.QtCore import QEvent, QPointF, Qt
    from PySide6.QtGui import QMouseEvent

    view = editor.view
    ctx = editor.ctx
    vp = editor.plot.viewport()

    def send(kind: QEvent.Type, pos: QPointF, buttons: Qt.MouseButton) -> None:
        ev = QMouseEvent(kind, pos, vp.mapToGlobal(pos), Qt.MouseButton.LeftButton, buttons,
                         Qt.KeyboardModifier.NoModifier)
        app.sendEvent(vp, ev)

    starts: tuple[list[float], list[float]] = ([], [])
    moves: tuple[list[float], list[float]] = ([], [])

    def timed(into: tuple[list[float], list[float]], fn: Callable[[], None], add: bool = False) -> None:
        c0 = time.process_time()
        t0 = time.perf_counter()
        fn()
        wall, cpu = (time.perf_counter() - t0) * 1000.0, (time.process_time() - c0) * 1000.0
        if add:
            into[0][-1] += wall
            into[1][-1] += cpu
        else:
            into[0].append(wall)
            into[1].append(cpu)

    def step(kind: QEvent.Type, pos: QPointF, buttons: Qt.MouseButton) -> Callable[[], None]:
        def fn() -> None:
            send(kind, pos, buttons)
            ctx.flush_changes()  # the context emits at most once per frame during a gesture
            vp.repaint()
        return fn
    cids = view.visible[:: max(1, len(view.visible) // DRAG_STARTS)][:DRAG_STARTS]
    for d, cid in enumerate(cids):
        index = len(ctx.doc.channels[cid].keys) // 2
        view.clear_selection()
        vp.repaint()
        start = QPointF(editor.plot.mapFromScene(view.handle_positions(cid, index)[0]))
        timed(starts, step(QEvent.Type.MouseButtonPress, start, Qt.MouseButton.LeftButton))
        time.sleep(0.012)  # pyqtgraph drops mouse moves closer than 10 ms apart
        pos = QPointF(start.x() + 4, start.y() - 3)  # the drag starts with this move
        timed(starts, step(QEvent.Type.MouseMove, pos, Qt.MouseButton.LeftButton), add=True)
        for k in range(1, (MOVES if d == 0 else 4) + 1):
            time.sleep(0.012)
            pos = QPointF(start.x() + 4 + 3 * k, start.y() - 3 - 2 * k)
            timed(moves, step(QEvent.Type.MouseMove, pos, Qt.MouseButton.LeftButton))
        send(QEvent.Type.MouseButtonRelease, pos, Qt.MouseButton.NoButton)
        app.processEvents()
        ctx.undo_stack.undo()
        app.processEvents()
    return starts, moves


def run() -> list[dict[str, Any]]:
    rows: list[dict[str, Any]] = []
    if (WASP / "wasp_walk.anim").is_file():
        rows += measure(_wasp_document(), "wasp walk", None)
    else:
        rows.append(skipped("curve editor (wasp walk)", f"shared data not found at {WASP}", "ms"))
    if BVH.is_file():
        rows += measure(_bvh_document(), "CMU walk BVH", None)
    else:
        rows.append(skipped("curve editor (CMU walk BVH)", f"shared data not found at {BVH}", "ms"))
    rows += measure(synthetic_document(), "synthetic", REDRAW_GOAL_MS)
    return rows


def main() -> int:
    return print_rows(run(), ["name", "figure", "unit", "min", "max", "cpu median", "of frame budget", "goal",
                              "load"])


if __name__ == "__main__":
    sys.exit(main())
