"""Long-run memory: the real main window plays the demo project for minutes; does RSS grow?

Run: ``.venv/bin/python -m benchmarks memory`` (``QTANIMATOR_BENCH_MEMORY_S`` sets the
duration in seconds, default 180). The 2D tab is shown and played frame after frame through
the window's own playback path (``ctx.set_frame`` and a repaint, the frame range looping);
every ``SAMPLE_S`` seconds the process's resident set size is read from
``/proc/self/statm``. The figure is the slope of a least-squares line through the samples
after the first quarter (caches fill during the first loop), in MB per minute; a leak shows
as a steady positive slope. Goal (issue 19): a slope of about zero.
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

from benchmarks.common import print_rows, row  # noqa: E402

SAMPLE_S = 2.0
DEMO = REPO / "scenes" / "demo" / "demo.qtanim"


def rss_mb() -> float:
    with open("/proc/self/statm") as fh:
        pages = int(fh.read().split()[1])
    return pages * os.sysconf("SC_PAGE_SIZE") / 2**20


def run() -> list[dict[str, Any]]:
    duration = float(os.environ.get("QTANIMATOR_BENCH_MEMORY_S", "180"))
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    import numpy as np
    from PySide6.QtWidgets import QApplication

    app = QApplication.instance() or QApplication([])
    from qtanimator.ui.main_window import MainWindow

    window = MainWindow()
    window.resize(1280, 720)
    window.show()
    if not window.open_path(DEMO):
        raise RuntimeError(f"could not open {DEMO}")
    window.central_tabs.setCurrentWidget(window.rig_editor)
    view = window.rig_editor.view
    first, last = window.doc.frame_range
    load_before = os.getloadavg()[0]
    samples: list[tuple[float, float]] = []
    start = time.perf_counter()
    next_sample = start
    frame = first
    frames = 0
    while True:
        now = time.perf_counter()
        if now >= next_sample:
            samples.append((now - start, rss_mb()))
            next_sample += SAMPLE_S
        if now - start >= duration:
            break
        window.ctx.set_frame(float(frame))
        view.viewport().repaint()
        app.processEvents()
        frame = first if frame >= last else frame + 1
        frames += 1
    window.close()
    t = np.array([s[0] for s in samples])
    m = np.array([s[1] for s in samples])
    keep = t >= duration / 4
    slope = float(np.polyfit(t[keep], m[keep], 1)[0]) * 60.0 if keep.sum() >= 3 else float("nan")
    extra = {"load before": round(load_before, 2), "load after": round(os.getloadavg()[0], 2),
             "frames played": frames, "duration s": round(duration, 1)}
    return [
        row("RSS slope over a long playback of the demo (2D tab)", slope, "MB/min", goal="≈ 0", higher_is_better=False,
            **extra),
        row("RSS at the start / end of the measured part", float(m[keep][0]) if keep.any() else None, "MB",
            note=f"end {float(m[-1]):.1f} MB, peak {float(m.max()):.1f} MB", **extra),
    ]


if __name__ == "__main__":
    sys.exit(print_rows(run(), ["name", "figure", "unit", "goal", "load before", "load after", "frames played"]))
