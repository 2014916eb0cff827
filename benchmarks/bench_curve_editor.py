"""Curve editor: redraw time after dragging one key with all 72 wasp-walk channels visible.

Run: ``.venv/bin/python benchmarks/bench_curve_editor.py`` (prints a table), or call
``run()`` for the rows. Uses the real widget on Qt's offscreen platform: a real mouse
press on a key, then real mouse moves; each figure is the time from sending one move to
the end of a synchronous repaint of the plot (command, document event, resampling of the
edited channel, repaint). The peer figure is the same drag where every move also
resamples every channel and redraws every curve (no sample cache, no cached layer), i.e.
what the redraw costs without the per-channel caching.
Goal: under 16 ms (one frame at 60 Hz).
"""

from __future__ import annotations

import os
import re
import statistics
import sys
import time
from pathlib import Path
from typing import Any

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from benchmarks.common import print_rows  # noqa: E402

WASP = (REPO / ".." / "shared" / "data" / "cse169" / "wasp_walk").resolve()
GOAL_MS = 16.0
MOVES = 40


def _wasp_document() -> Any:
    from qtanimator.document import Document, channel_id
    from qtanimator.formats.anim import load_anim

    clip = load_anim(WASP / "wasp_walk.anim")
    joints = re.findall(r"balljoint\s+([^\s{]+)", (WASP / "wasp.skel").read_text())
    ids = [channel_id("wasp", "", d) for d in ("tx", "ty", "tz")]
    ids += [channel_id("wasp", j, d) for j in joints for d in ("rx", "ry", "rz")]
    doc = Document()
    for cid, ch in zip(ids, clip.channels):
        doc.channels[cid] = ch
    return doc


def run() -> list[dict[str, Any]]:
    if not (WASP / "wasp_walk.anim").is_file():
        return [{"name": "curve editor: redraw after dragging one key (72 wasp channels)",
                 "figure": None, "unit": "ms", "peer figure": None, "ratio": None,
                 "goal": f"< {GOAL_MS:g} ms", "skipped": f"shared data not found at {WASP}"}]
    from PySide6.QtWidgets import QApplication

    app = QApplication.instance() or QApplication([])
    from qtanimator.ui.context import EditorContext
    from qtanimator.ui.curve_editor import CurveEditor

    doc = _wasp_document()
    editor = CurveEditor(EditorContext(doc))
    editor.resize(1400, 700)
    editor.show()
    app.processEvents()
    editor.view.frame_all()
    app.processEvents()
    visible = len(editor.view.visible)
    # The key to drag: the middle key of the channel with the most keys.
    cid = max(editor.view.visible, key=lambda c: len(doc.channels[c].keys))
    index = len(doc.channels[cid].keys) // 2
    warm, warm_cpu = _drag(editor, app, cid, index, cold=False)
    cold, cold_cpu = _drag(editor, app, cid, index, cold=True)
    ours = statistics.median(warm)
    peer = statistics.median(cold)
    rows = [
        {"name": f"curve editor: redraw after dragging one key ({visible} wasp channels visible)",
         "figure": round(ours, 3), "unit": "ms", "peer figure": round(peer, 3),
         "ratio": round(peer / ours, 3), "goal": f"< {GOAL_MS:g} ms",
         "peer": "same drag, every channel resampled and redrawn"},
        {"name": "curve editor: 90th percentile of the drag's redraws", "figure": round(_p90(warm), 3),
         "unit": "ms", "peer figure": round(_p90(cold), 3), "ratio": round(_p90(cold) / _p90(warm), 3),
         "goal": f"< {GOAL_MS:g} ms"},
        {"name": "curve editor: CPU time per redraw after dragging one key (less sensitive to a busy machine)",
         "figure": round(statistics.median(warm_cpu), 3), "unit": "ms CPU",
         "peer figure": round(statistics.median(cold_cpu), 3),
         "ratio": round(statistics.median(cold_cpu) / statistics.median(warm_cpu), 3), "goal": f"< {GOAL_MS:g} ms"},
    ]
    editor.close()
    editor.deleteLater()
    app.processEvents()
    return rows


def _p90(values: list[float]) -> float:
    return float(statistics.quantiles(values, n=10)[-1])


def _drag(editor: Any, app: Any, cid: str, index: int, cold: bool) -> tuple[list[float], list[float]]:
    """Press on a key, send MOVES real mouse moves, time each move + synchronous repaint."""
    from PySide6.QtCore import QEvent, QPointF, Qt
    from PySide6.QtGui import QMouseEvent

    view = editor.view
    plot = editor.plot
    vp = plot.viewport()
    start = QPointF(plot.mapFromScene(view.handle_positions(cid, index)[0]))

    def send(kind: QEvent.Type, pos: QPointF, buttons: Qt.MouseButton) -> None:
        ev = QMouseEvent(kind, pos, vp.mapToGlobal(pos), Qt.MouseButton.LeftButton, buttons,
                         Qt.KeyboardModifier.NoModifier)
        app.sendEvent(vp, ev)

    send(QEvent.Type.MouseButtonPress, start, Qt.MouseButton.LeftButton)
    times = []
    cpu = []
    for k in range(1, MOVES + 1):
        time.sleep(0.012)  # pyqtgraph drops mouse moves closer than 10 ms apart
        pos = QPointF(start.x() + 3 * k, start.y() - 2 * k)
        t0 = time.perf_counter()
        c0 = time.process_time()
        send(QEvent.Type.MouseMove, pos, Qt.MouseButton.LeftButton)
        if cold:  # the peer: resample every channel and redraw every curve
            view.cache.clear()
            view.refresh_all()
        vp.repaint()
        times.append((time.perf_counter() - t0) * 1000.0)
        cpu.append((time.process_time() - c0) * 1000.0)
    send(QEvent.Type.MouseButtonRelease, pos, Qt.MouseButton.NoButton)
    app.processEvents()
    editor.ctx.undo_stack.undo()
    app.processEvents()
    # The first move starts the drag (selection, gesture set-up, one rebuild of the cached layer).
    return times[1:], cpu[1:]


def main() -> int:
    return print_rows(run(), ["name", "figure", "unit", "peer figure", "ratio", "goal"])


if __name__ == "__main__":
    sys.exit(main())
