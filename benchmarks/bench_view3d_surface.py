"""3D view surface: QOpenGLWindow in a window container against a QOpenGLWidget (issue 12).

Run: ``.venv/bin/python benchmarks/bench_view3d_surface.py`` (prints a table), or call ``run()``
for the rows. ``QTANIMATOR_BENCH_QUICK=1`` plays 3 s per run instead of 8.

The real main window (every editor installed) plays the demo project
(``scenes/demo/demo.qtanim``: the 3D arm and the wind-blown flag) in its "3D" tab with the
docks hidden and the window sized so that the GL view is 1280×720, on a private Xvfb with
Mesa llvmpipe (software GL, ``QT_QPA_PLATFORM=xcb``). The same view is measured with its two
GL surfaces (``QTANIMATOR_VIEW3D_SURFACE``):

* ``widget``: a QOpenGLWidget. Qt then composes the whole main window through OpenGL on
  every frame (the widgets' backing store and the GL texture, ``rhiFlush`` / ``QRhi::endFrame``);
* ``window``: a QOpenGLWindow shown in a ``QWidget.createWindowContainer``: the window system
  shows its pixels, the main window is not composed through OpenGL.

Each run is a fresh process (the surface and Qt's composition are per process); the two
kinds take turns (widget, window, widget, …) so that load on a shared machine hits both alike.
Figures: frames painted per second while playing (median of the runs, min–max), the median
interval between painted frames, and the CPU time per painted frame (main thread, and the
whole process: llvmpipe rasterises on its own threads). The cloth cache is filled before
playing (the simulation is not part of this figure).
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from benchmarks.common import print_rows, row, skipped  # noqa: E402

DEMO = REPO / "scenes" / "demo" / "demo.qtanim"
VIEW_SIZE = (1280, 720)
KINDS = ("widget", "window")


def _quick() -> bool:
    return os.environ.get("QTANIMATOR_BENCH_QUICK", "") not in ("", "0")


def _child(kind: str, seconds: float) -> dict[str, Any]:
    """One run in this process: play the demo's 3D tab for ``seconds``."""
    display = os.environ.get("QTANIMATOR_BENCH_DISPLAY")
    if not display:  # run alone: a server of its own (left behind by os._exit below)
        from qtanimator.render.xvfb import start_private_xvfb

        display = start_private_xvfb("2560x1440x24")
    os.environ["DISPLAY"] = display
    os.environ["QT_QPA_PLATFORM"] = "xcb"
    os.environ["QTANIMATOR_VIEW3D_SURFACE"] = kind
    from PySide6.QtCore import QEventLoop, QTimer
    from PySide6.QtTest import QTest
    from PySide6.QtWidgets import QApplication, QDockWidget

    from qtanimator.document.cloth_worker import cloth_worker
    from qtanimator.ui.main_window import MainWindow

    app = QApplication.instance() or QApplication([])

    def spin(s: float) -> None:
        loop = QEventLoop()
        QTimer.singleShot(int(s * 1000), loop.quit)
        loop.exec()

    window = MainWindow()
    window.show()
    QTest.qWaitForWindowExposed(window, 5000)
    if not window.open_path(DEMO):
        raise RuntimeError(f"could not open {DEMO}")
    for dock in window.findChildren(QDockWidget):
        dock.hide()
    window.central_tabs.setCurrentWidget(window.viewport_panel)
    view = window.viewport3d
    assert view.surface_kind == kind
    window.resize(1400, 900)
    spin(0.3)
    for _ in range(3):  # the window manager-less Xvfb takes the size at once; settle the layout
        window.resize(window.width() + VIEW_SIZE[0] - view.width(), window.height() + VIEW_SIZE[1] - view.height())
        app.processEvents()
        spin(0.2)
    cloth_worker(window.doc).wait(60)
    spin(0.5)
    stamps: list[float] = []
    view.frameRendered.connect(lambda _ms: stamps.append(time.perf_counter()))
    play = window.findChild(type(window.action_save), "actionPlay")
    t0, c0, m0 = time.perf_counter(), time.process_time(), time.thread_time()
    play.trigger()
    spin(seconds)
    elapsed, cpu, main = time.perf_counter() - t0, time.process_time() - c0, time.thread_time() - m0
    window.playback.pause()
    frames = len(stamps)
    intervals = [(b - a) * 1000.0 for a, b in zip(stamps, stamps[1:])]
    out = {"kind": kind, "fps": frames / elapsed, "frames": frames,
           "interval_ms": statistics.median(intervals) if intervals else None,
           "cpu_ms": 1000.0 * cpu / max(frames, 1), "main_cpu_ms": 1000.0 * main / max(frames, 1),
           "view": f"{view.width()}x{view.height()}", "window": f"{window.width()}x{window.height()}",
           "gl": view.gl_info, "load": os.getloadavg()[0]}
    window.ctx.undo_stack.setClean()
    return out


def _run_child(kind: str, seconds: float, display: str) -> dict[str, Any]:
    env = {**os.environ, "QTANIMATOR_VIEW3D_SURFACE": kind, "QTANIMATOR_BENCH_DISPLAY": display}
    proc = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--child", kind, str(seconds)],
                          capture_output=True, text=True, env=env, cwd=REPO, timeout=240, check=False)
    for line in reversed(proc.stdout.splitlines()):
        if line.startswith("{"):
            return json.loads(line)  # type: ignore[no-any-return]
    raise RuntimeError(f"{kind} run failed: {proc.stderr.strip().splitlines()[-1:] or proc.returncode}")


def run() -> list[dict[str, Any]]:
    import shutil

    if shutil.which("Xvfb") is None:
        return [skipped("3D view surface: QOpenGLWindow vs QOpenGLWidget", "Xvfb is not installed")]
    from qtanimator.render.xvfb import start_private_xvfb

    display = start_private_xvfb("2560x1440x24")  # one server for every run, stopped when this process exits
    seconds = 3.0 if _quick() else 8.0
    rounds = 2 if _quick() else 3
    results: dict[str, list[dict[str, Any]]] = {k: [] for k in KINDS}
    for _ in range(rounds):
        for kind in KINDS:
            results[kind].append(_run_child(kind, seconds, display))
    rows = []
    fps = {k: statistics.median(r["fps"] for r in v) for k, v in results.items()}
    for kind in KINDS:
        runs = results[kind]
        f = [r["fps"] for r in runs]
        loads = ", ".join(f"{r['load']:.2f}" for r in runs)
        note = (f"median of {len(runs)} runs of {seconds:g} s, min–max {min(f):.3g}–{max(f):.3g} fps; "
                f"frame interval {statistics.median(r['interval_ms'] for r in runs):.3g} ms; CPU per frame "
                f"{statistics.median(r['cpu_ms'] for r in runs):.3g} ms (process), "
                f"{statistics.median(r['main_cpu_ms'] for r in runs):.3g} ms (UI thread); view {runs[0]['view']} in "
                f"a {runs[0]['window']} window; load {loads}")
        label = "QOpenGLWindow in a window container" if kind == "window" else "QOpenGLWidget"
        rows.append(row(f"3D tab playing the demo, view 1280x720, {label}: frames painted per second", fps[kind],
                        "fps", peer=fps["widget"] if kind == "window" else None,
                        goal="≥ 30 fps (software GL)", note=note, per_run=[round(v, 2) for v in f],
                        interval_ms=[round(r["interval_ms"] or 0, 2) for r in runs],
                        cpu_ms=[round(r["cpu_ms"], 2) for r in runs],
                        main_cpu_ms=[round(r["main_cpu_ms"], 2) for r in runs], gl=runs[0]["gl"]))
    return rows


def main(argv: list[str]) -> int:
    if len(argv) >= 2 and argv[0] == "--child":
        result = _child(argv[1], float(argv[2]) if len(argv) > 2 else 8.0)
        sys.stdout.write(json.dumps(result) + "\n")
        sys.stdout.flush()
        os._exit(0)  # leave without tearing Qt and GL down
    return print_rows(run(), ["name", "figure", "unit", "peer figure", "ratio", "goal"])


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
