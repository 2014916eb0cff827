"""2D drawing of a frame, old path (flattened geometry) against new (issue 23: each joint's own
SVG drawn by QtSvg, replayed from a cached QPicture), on the demo's characters and owl.svg.

Run: ``.venv/bin/python benchmarks/bench_svg_paint.py``. One figure = ``draw_character`` for
every character of the scene, posed at the frame's time, into a 960×640 ARGB32 image fitted
to the content (as the headless render and the rig editor's still frames draw). 120 frames
of playback are drawn per run (caches warm: the first frame of each path is drawn before);
a run's figure is the mean frame time; the row gives the median over RUNS runs with the
min–max in ``spread``. Both paths take turns within one run so that load from other jobs
hits them alike. Goal (issue 23): the new path at least as fast as the old (ratio ≥ 1).
"""

from __future__ import annotations

import os
import statistics
import sys
import time
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from benchmarks.common import print_rows, row, skipped  # noqa: E402

DEMO = REPO / "scenes" / "demo" / "demo.qtanim"
OWL = (REPO / ".." / "shared" / "data" / "cmu-animator" / "scenes" / "owl.svg").resolve()
SIZE = (960, 640)
FRAMES = 120
RUNS = 7


def _scene(name: str) -> Any:
    from qtanimator.document import Document
    from qtanimator.document.character2d import add_characters_command
    from qtanimator.document.io import open_document

    if name == "demo":
        return open_document(DEMO)
    doc = Document()
    add_characters_command(doc, OWL).do(doc)
    return doc


def _measure(doc: Any) -> dict[str, list[float]]:
    from PySide6.QtGui import QColor, QImage, QPainter

    from qtanimator.document.character2d import character, character_assets, evaluate_pose
    from qtanimator.render.painter2d import animation_bounds, draw_character, fit_transform

    fps = doc.fps
    times = [k / fps for k in range(FRAMES)]
    ids = character_assets(doc)
    poses = [{aid: evaluate_pose(doc, aid, t) for aid in ids} for t in times]  # simulation outside the timing
    chars = {aid: character(doc, aid) for aid in ids}
    view = fit_transform(animation_bounds(doc, times[::10]), SIZE)
    image = QImage(SIZE[0], SIZE[1], QImage.Format.Format_ARGB32_Premultiplied)

    def frame(posed: dict[str, Any], mode: str) -> float:
        image.fill(QColor("white"))
        start = time.perf_counter()
        p = QPainter(image)
        p.setRenderHint(QPainter.RenderHint.Antialiasing, True)
        p.setWorldTransform(view)
        for aid, pose in posed.items():
            draw_character(p, chars[aid], pose, mode=mode)
        p.end()
        return time.perf_counter() - start

    for mode in ("geometry", "svg"):
        frame(poses[0], mode)  # build the paths / pictures once
    runs: dict[str, list[float]] = {"geometry": [], "svg": []}
    for _ in range(RUNS):
        sums = {"geometry": 0.0, "svg": 0.0}
        for posed in poses:
            for mode in sums:
                sums[mode] += frame(posed, mode)
        for mode, total in sums.items():
            runs[mode].append(1000.0 * total / FRAMES)
    return runs


def _window_playback(path: Path, mode: str, seconds: float = 3.0) -> tuple[float, float, int]:
    """Play ``path`` in the real main window's 2D tab (1280×720) for ``seconds``, drawing
    with ``mode`` ("svg" or "geometry"): (painted frames per second, main-thread CPU ms per
    painted frame, frames the playback dropped). The rig editor draws playing frames from
    per-joint sprites built by ``draw_character``, still frames as vectors."""
    from functools import partial

    from PySide6.QtCore import QEvent, QEventLoop, QObject, QTimer
    from PySide6.QtTest import QTest

    from qtanimator.render import painter2d
    from qtanimator.ui.main_window import MainWindow

    original = painter2d.draw_character
    painter2d.draw_character = partial(original, mode=mode)  # type: ignore[assignment]
    try:
        window = MainWindow()
        window.resize(1280, 720)
        window.show()
        QTest.qWaitForWindowExposed(window, 5000)
        if not window.open_path(path):
            raise RuntimeError(f"cannot open {path}")
        window.central_tabs.setCurrentWidget(window.rig_editor)
        viewport = window.rig_editor.view.viewport()

        class Count(QObject):
            n = 0

            def eventFilter(self, _o: QObject, e: QEvent) -> bool:
                if e.type() == QEvent.Type.Paint:
                    self.n += 1
                return False

        counter = Count()
        viewport.installEventFilter(counter)

        def spin(s: float) -> None:
            loop = QEventLoop()
            QTimer.singleShot(int(s * 1000), loop.quit)
            loop.exec()

        spin(1.0)  # the pendulum caches settle
        window.playback.play()
        spin(0.5)  # sprites built
        n0, c0, t0 = counter.n, time.thread_time(), time.perf_counter()
        dropped0 = window.playback.dropped_frames
        spin(seconds)
        painted = counter.n - n0
        cpu = time.thread_time() - c0
        elapsed = time.perf_counter() - t0
        dropped = window.playback.dropped_frames - dropped0
        window.playback.pause()
        window.ctx.undo_stack.setClean()
        window.close()
        window.deleteLater()
        spin(0.1)
        return painted / elapsed, 1000.0 * cpu / max(painted, 1), dropped
    finally:
        painter2d.draw_character = original  # type: ignore[assignment]


def run() -> list[dict[str, Any]]:
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    from PySide6.QtWidgets import QApplication

    _app = QApplication.instance() or QApplication([])
    rows: list[dict[str, Any]] = []
    for name, path in (("demo", DEMO), ("owl.svg", OWL)):
        if not path.is_file():
            rows.append(skipped(f"2D frame draw {name}: SVG path", f"{path} not found", "ms"))
            continue
        runs = _measure(_scene(name))
        old, new = statistics.median(runs["geometry"]), statistics.median(runs["svg"])
        spread = {m: f"{min(v):.2f}-{max(v):.2f}" for m, v in runs.items()}
        rows.append(row(f"2D frame draw {name}: SVG path (peer: geometry path)", new, "ms", peer=old,
                        goal="ratio >= 1", higher_is_better=False, digits=2,
                        spread=f"new {spread['svg']}, old {spread['geometry']} ms over {RUNS} runs"))
    # The same scenes playing in the real window (the user's path), both drawing paths.
    for name, path in (("demo", DEMO), ("owl.svg", OWL)):
        if not path.is_file():
            continue
        got: dict[str, list[tuple[float, float, int]]] = {"svg": [], "geometry": []}
        for _ in range(3):
            for mode in ("geometry", "svg"):
                got[mode].append(_window_playback(path, mode))
        med = {m: statistics.median(v[1] for v in vals) for m, vals in got.items()}
        fps = {m: statistics.median(v[0] for v in vals) for m, vals in got.items()}
        note = ", ".join(f"{m}: {fps[m]:.1f} fps, CPU {min(v[1] for v in got[m]):.2f}-{max(v[1] for v in got[m]):.2f} "
                         f"ms/frame, dropped {[v[2] for v in got[m]]}" for m in ("svg", "geometry"))
        rows.append(row(f"2D playback in the window, {name}: UI-thread CPU per painted frame, SVG path "
                        "(peer: geometry path)", med["svg"], "ms", peer=med["geometry"], goal="ratio >= 1",
                        higher_is_better=False, digits=2, spread=note + f"; load {os.getloadavg()[0]:.2f}"))
    return rows


if __name__ == "__main__":
    rows = run()
    sys.exit(print_rows(rows, ["name", "figure", "unit", "peer figure", "ratio", "goal", "spread"]))
