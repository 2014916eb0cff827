"""End-to-end GUI benchmarks of issue 12 ("The application at 60 Hz"): the real main window.

Run: ``.venv/bin/python -m benchmarks gui`` (the runner's table) or
``.venv/bin/python benchmarks/bench_gui.py [--parts ik2,play2d,...]`` (this module's own table).
``QTANIMATOR_BENCH_QUICK=1`` shortens every part (3 s of playback, fewer runs, smaller time
budgets); ``QTANIMATOR_BENCH_GUI_PARTS=ik2,curve`` runs only some parts.

Every figure is measured on the real :class:`qtanimator.ui.main_window.MainWindow` with all
editors installed, the project opened with ``window.open_path`` (File > Open), driven with
real mouse events sent to the editors' viewports and timed from sending the event to the end
of the repaint it causes (the event is sent, then ``processEvents`` delivers what it posted,
then a synchronous ``repaint()`` if the editor has not painted yet; the 2D editor counts its
paints in ``frames_drawn``, the 3D view emits ``frameRendered``).

Parts (each runs in its own Python process with its own time limit, so that a crash, a hang
or an OpenGL problem in one does not take the others down; rows already measured survive):

``ik2``, ``ik200``, ``ik2000``
    Right-drag IK on Pip's lantern hand (``hand_right`` of the demo's ``pip``) at frames 2,
    200 and 2000 (``frame_end`` raised to 2100 with a SetParameter command pushed through
    ``window.ctx.push``): right press on the hand, 30 mouse moves, release. Figure: time per
    move event until the repaint is done. "settle" is the time from the release until the
    editor stops repainting (and the pendulum cache reaches the frame): the simulation
    catching up, if any. Goal ≤ 16 ms per move, flat in the frame number.
``play2d``, ``play3d``
    Playback of the demo (Play action, loop on) in the "2D Rig" and the "3D" tab with the
    window at 1280×720, N seconds (10, or 3 when quick) from a freshly opened project:
    frames painted per second, and what :class:`~qtanimator.ui.playback.Playback` counted
    (frames shown, frames dropped). Goal 60 fps in 2D, ≥ 30 fps in 3D. The 3D part runs on
    the ``xcb`` platform under a private Xvfb (Mesa llvmpipe, software GL).
``curve``
    Curve editor (plot ``curvePlot``) with the CMU walk BVH imported (File > Open) and with a
    synthetic document of 300 channels × 2000 keys: a full redraw (a wheel-zoom event on the
    plot: every curve resampled and drawn again) and a key drag (left press on a key, 30
    moves). Goal ≤ 16 ms per drag move, ≤ 50 ms per full redraw at 300 × 2000. Runs under
    Xvfb: the BVH import shows the 3D tab (the 2D tab is shown again before measuring).
``stall3d``
    Longest event-loop stall (gaps between the ticks of a 1 ms QTimer) while the cloth panel's
    widgets switch the demo flag to the implicit integrator and then its structural stiffness
    to 1e6 (3D tab shown, frame 120), and while the "3D" tab is opened with a mouse click on
    the tab bar (frame 120, freshly opened project). Runs under Xvfb. Goal ≤ 50 ms.
``autosave``
    Longest stall while the recovery manager's own timer autosaves a 600,000-key project
    (300 synthetic channels × 2000 keys) with unsaved changes. Goal ≤ 50 ms.

Each figure is the median of every sample over repeated runs, with min–max (not best-of);
the note gives its ratio to the 16.7 ms frame budget and to a bare repaint of the same editor
(nothing changed) measured in the same process. The table's "peer figure" is that bare
repaint and "ratio" follows the runner's convention (bare ÷ ours for times, so far below 1
means far slower than a bare repaint). The load average (``os.getloadavg``) before and after
each measurement goes into the row (and the note), since the machine may be shared.

A loop that would run for minutes (an IK move that re-simulates 2000 frames, a redraw of
600,000 keys) stops taking samples once its time budget is spent and says so in the note.
The shared data is read from ``../shared/data`` beside the checkout, or from
``QTANIMATOR_SHARED_DATA`` (e.g. for a worktree elsewhere).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from functools import partial
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from benchmarks.common import print_rows, row, skipped  # noqa: E402

#: The shared sample data (``QTANIMATOR_SHARED_DATA`` for a checkout elsewhere, e.g. a worktree).
DATA = Path(os.environ.get("QTANIMATOR_SHARED_DATA") or (REPO / ".." / "shared" / "data")).resolve()
DEMO = REPO / "scenes" / "demo" / "demo.qtanim"
BVH = DATA / "bvh" / "cmu_12_01_walk.bvh"
BUDGET_MS = 1000.0 / 60.0
COLUMNS = ["name", "figure", "unit", "peer figure", "ratio", "goal"]

#: The lantern hand of the demo's Pip, dragged with IK.
IK_ASSET = "pip"
IK_JOINT = "hand_right"
IK_MOVES = 30
PLAY_SIZE = (1280, 720)
CLOTH_ASSET = "flag"
CLOTH_FRAME = 120
SYNTH_CHANNELS = 300
SYNTH_KEYS = 2000
CURVE_MOVES = 30
WHEELS = 20


def quick() -> bool:
    return os.environ.get("QTANIMATOR_BENCH_QUICK", "") not in ("", "0")


# ============================================================== the parent process
#: name -> (platform, hard time limit in seconds (full, quick)).
PARTS: dict[str, tuple[str, tuple[int, int]]] = {
    "ik2": ("offscreen", (240, 120)),
    "ik200": ("offscreen", (300, 150)),
    "ik2000": ("offscreen", (360, 180)),
    "play2d": ("offscreen", (240, 120)),
    "play3d": ("xcb", (240, 120)),
    # xcb: importing a BVH switches to the 3D tab, whose GL view needs a real context.
    "curve": ("xcb", (360, 200)),
    "stall3d": ("xcb", (480, 240)),
    "autosave": ("offscreen", (300, 150)),
}


def selected_parts() -> list[str]:
    chosen = os.environ.get("QTANIMATOR_BENCH_GUI_PARTS", "").strip()
    if not chosen:
        return list(PARTS)
    names = [n.strip() for n in chosen.split(",") if n.strip()]
    unknown = [n for n in names if n not in PARTS]
    if unknown:
        raise ValueError(f"no GUI benchmark part named {', '.join(unknown)} (there are: {', '.join(PARTS)})")
    return names


def _start_xvfb() -> str:
    """A private X server for one part (stopped when this process exits)."""
    from qtanimator.render.xvfb import start_private_xvfb  # imports no Qt

    return start_private_xvfb("1920x1080x24")


def run_part_isolated(name: str) -> list[dict[str, Any]]:
    """Run one part in a fresh Python process with a hard time limit; its rows."""
    platform, limits = PARTS[name]
    limit = limits[1] if quick() else limits[0]
    load_before = os.getloadavg()
    with tempfile.TemporaryDirectory(prefix=f"qtanimator-gui-{name}-") as tmp:
        rows_file = Path(tmp) / "rows.json"
        env = dict(os.environ)
        env["QTANIMATOR_SETTINGS_DIR"] = str(Path(tmp) / "settings")  # no recovery prompts, default layout
        env["QT_QPA_PLATFORM"] = platform
        if platform == "xcb":
            try:
                env["DISPLAY"] = _start_xvfb()
            except OSError as exc:
                return [skipped(f"gui {name}", f"no X server for OpenGL: {exc}")]
        command = [sys.executable, str(Path(__file__).resolve()), "--part", name, "--rows-to", str(rows_file)]
        status: str | None = None
        start = time.perf_counter()
        try:
            proc = subprocess.run(command, cwd=REPO, env=env, stdout=sys.stderr, timeout=limit, check=False)
            if proc.returncode != 0:
                status = f"the part's process ended with status {proc.returncode}"
        except subprocess.TimeoutExpired:
            status = f"the part ran past its {limit} s time limit and was stopped"
        elapsed = time.perf_counter() - start
        try:
            rows: list[dict[str, Any]] = json.loads(rows_file.read_text())
        except (OSError, ValueError):
            rows = []
    if status is not None:
        rows.append({**skipped(f"gui {name}: incomplete", f"{status} after {elapsed:.0f} s"
                               f" ({len(rows)} rows measured before)"),
                     "load_before": _load_text(load_before), "load_after": _load_text(os.getloadavg())})
    print(f"[gui {name}: {elapsed:.1f} s]", file=sys.stderr)
    return rows


def _flatness_row(rows: list[dict[str, Any]]) -> dict[str, Any] | None:
    """IK move time at frame 2000 relative to frame 2 (1 = flat in the frame number)."""
    by_frame = {r.get("ik_frame"): r for r in rows if r.get("ik_frame") is not None and r.get("figure") is not None
                and r.get("kind") == "ik_move"}
    if 2 not in by_frame or 2000 not in by_frame:
        return None
    early, late = float(by_frame[2]["figure"]), float(by_frame[2000]["figure"])
    return row("IK drag: move time at frame 2000 ÷ at frame 2", late / early, "×", goal="≈ 1 (flat)",
               higher_is_better=False, note=f"{late:.4g} ms vs {early:.4g} ms")


def run() -> list[dict[str, Any]]:
    if not DEMO.is_file():
        return [skipped("gui", f"demo project not found at {DEMO}")]
    rows: list[dict[str, Any]] = []
    for name in selected_parts():
        rows.extend(run_part_isolated(name))
    flat = _flatness_row(rows)
    if flat is not None:
        rows.append(flat)
    return rows


# ============================================================== measurement helpers
def _load_text(load: tuple[float, float, float]) -> str:
    return "/".join(f"{v:.2f}" for v in load)


@contextmanager
def load_span(extra: dict[str, Any]) -> Iterator[None]:
    """Put the load average before and after the block into ``extra``."""
    extra["load_before"] = _load_text(os.getloadavg())
    try:
        yield
    finally:
        extra["load_after"] = _load_text(os.getloadavg())


def spread(samples: list[float]) -> tuple[float, float, float]:
    return statistics.median(samples), min(samples), max(samples)


def timed_row(name: str, samples: list[float], bare: list[float] | None, goal_ms: float | None,
              extra: dict[str, Any], unit: str = "ms", per_run: list[float] | None = None,
              runs: int | None = None, bare_of: str = "the same editor") -> dict[str, Any]:
    """A row for a time (lower is better): median, min–max, × budget, × bare repaint."""
    if not samples:
        return {**skipped(name, "nothing was measured", unit), **extra}
    med, lo, hi = spread(samples)
    bare_med = statistics.median(bare) if bare else None
    budget_x = med / BUDGET_MS
    parts = [f"median of {len(samples)}" + (f" over {runs} runs" if runs else ""), f"min–max {lo:.3g}–{hi:.3g} {unit}",
             f"{budget_x:.2f}× the 16.7 ms budget"]
    if bare_med:
        parts.append(f"{med / bare_med:.1f}× a bare repaint of {bare_of} ({bare_med:.3g} ms)")
    if per_run:
        parts.append("per run " + ", ".join(f"{v:.3g}" for v in per_run))
    parts.append(f"load {extra.get('load_before', '?')} → {extra.get('load_after', '?')}")
    return row(name, med, unit, peer=bare_med, goal="-" if goal_ms is None else f"≤ {goal_ms:g} ms",
               higher_is_better=False, note="; ".join(parts), min=round(lo, 3), max=round(hi, 3),
               samples=len(samples), budget_ratio=round(budget_x, 3), bare_of=bare_of,
               bare_ratio=None if not bare_med else round(med / bare_med, 3),
               per_run=None if per_run is None else [round(v, 3) for v in per_run], **extra)


class PartContext:
    """What a part needs: the application, the rows written so far (saved after each one)."""

    def __init__(self, rows_to: Path | None) -> None:
        os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
        from PySide6.QtWidgets import QApplication

        self.app = QApplication.instance() or QApplication([])
        self.rows: list[dict[str, Any]] = []
        self.rows_to = rows_to
        import qtanimator

        self.package = str(Path(qtanimator.__file__).resolve().parent)

    def add(self, r: dict[str, Any]) -> None:
        r.setdefault("qtanimator", self.package)
        r.setdefault("platform", os.environ.get("QT_QPA_PLATFORM", ""))
        self.rows.append(r)
        if self.rows_to is not None:  # what was measured survives a later crash or timeout
            self.rows_to.write_text(json.dumps(self.rows, default=str))
        print(f"  {r['name']}: {r.get('figure')} {r.get('unit', '')} {r.get('note', r.get('skipped', ''))}",
              file=sys.stderr)

    # ---------------------------------------------------------------- the window
    def window(self, size: tuple[int, int] | None = None, project: Path | None = DEMO) -> Any:
        """A shown MainWindow with every editor, the project opened as File > Open does."""
        from PySide6.QtTest import QTest

        from qtanimator.ui.main_window import MainWindow

        window = MainWindow()
        if size is not None:
            window.resize(*size)
        window.show()
        QTest.qWaitForWindowExposed(window, 5000)
        self.app.processEvents()
        if project is not None and not window.open_path(project):
            raise RuntimeError(f"could not open {project}")
        self.app.processEvents()
        return window

    def dispose(self, window: Any) -> None:
        """Close a window without the unsaved-changes question."""
        window.ctx.undo_stack.setClean()
        window.close()
        window.deleteLater()
        self.app.processEvents()

    def spin(self, seconds: float) -> None:
        """Run the event loop for ``seconds`` (timers fire, paints happen)."""
        from PySide6.QtCore import QEventLoop, QTimer

        loop = QEventLoop()
        QTimer.singleShot(max(0, int(seconds * 1000)), loop.quit)
        loop.exec()

    def spin_until(self, done: Callable[[], bool], cap_s: float, poll_ms: int = 10) -> bool:
        """Run the event loop until ``done()`` (checked every ``poll_ms``) or ``cap_s``; True if done."""
        from PySide6.QtCore import QEventLoop, QTimer

        if done():
            return True
        loop = QEventLoop()
        deadline = time.perf_counter() + cap_s
        result = [False]

        def check() -> None:
            if done():
                result[0] = True
                loop.quit()
            elif time.perf_counter() >= deadline:
                loop.quit()

        timer = QTimer()
        timer.setInterval(poll_ms)
        timer.timeout.connect(check)
        timer.start()
        loop.exec()
        timer.stop()
        return result[0]


class PaintCounter:
    """Counts the paints of one editor: ``frames_drawn`` of the 2D view, ``frameRendered`` of
    the 3D view, else the Paint events of the widget (seen by an event filter)."""

    def __init__(self, view: Any) -> None:
        self.view = view
        self._count = 0
        self.last = time.perf_counter()
        self._filter: Any = None
        signal = getattr(view, "frameRendered", None)
        self.mode = "attribute" if hasattr(view, "frames_drawn") else "signal" if signal is not None else "events"
        if self.mode == "signal" and signal is not None:
            signal.connect(self._painted)
        elif self.mode == "events":
            self._filter = _paint_filter(self._painted)
            view.installEventFilter(self._filter)

    @property
    def is_signal(self) -> bool:
        """A view whose repaint() does not paint synchronously (the GL view): ask and wait."""
        return self.mode == "signal"

    def _painted(self, *_args: Any) -> None:
        self._count += 1
        self.last = time.perf_counter()

    @property
    def count(self) -> int:
        if self.mode != "attribute":
            return self._count
        n = int(self.view.frames_drawn)
        if n != self._count:
            self._count = n
            self.last = time.perf_counter()
        return n


def _paint_filter(callback: Callable[[], None]) -> Any:
    """A QObject event filter that calls ``callback`` after each Paint event."""
    from PySide6.QtCore import QEvent, QObject

    class PaintFilter(QObject):
        def eventFilter(self, _watched: QObject, event: QEvent) -> bool:
            if event.type() == QEvent.Type.Paint:
                callback()
            return False

    return PaintFilter()


def _painted_since(counter: PaintCounter, before: int) -> bool:
    return counter.count > before


class Budget:
    """A soft time limit for a measuring loop: it stops taking samples once spent."""

    def __init__(self, seconds: float) -> None:
        self.seconds = seconds
        self.start = time.perf_counter()

    @property
    def spent(self) -> bool:
        return time.perf_counter() - self.start >= self.seconds


class StallMeter:
    """Gaps between the ticks of a 1 ms precise QTimer: the event loop's stalls."""

    def __init__(self) -> None:
        from PySide6.QtCore import Qt, QTimer

        self.timer = QTimer()
        self.timer.setTimerType(Qt.TimerType.PreciseTimer)
        self.timer.setInterval(1)
        self.timer.timeout.connect(self._tick)
        self.ticks: list[float] = []

    def _tick(self) -> None:
        self.ticks.append(time.perf_counter())

    def start(self) -> None:
        self.ticks = [time.perf_counter()]
        self.timer.start()

    def stop(self) -> None:
        self.timer.stop()
        self.ticks.append(time.perf_counter())

    def longest_ms(self) -> float:
        return max((b - a for a, b in zip(self.ticks, self.ticks[1:])), default=0.0) * 1000.0


def _frame_ready(doc: Any, asset: str, frame: int) -> bool | None:
    """Whether the simulation cache of ``asset`` reaches ``frame`` (None: cannot tell)."""
    try:
        start = int(doc.frame_range[0])
        if asset in doc.assets and doc.assets[asset].kind == "cloth":
            cached = getattr(doc.runtime.get(asset), "cached_frames", None)
        else:
            from qtanimator.document import character2d as c2d

            cached = c2d.simulation(doc).cached_frames(asset)
        if callable(cached):
            cached = cached()
        return None if cached is None else int(cached) > frame - start
    except Exception:  # an API that changed: settle on repaints alone
        return None


def settle(ctx: PartContext, counter: PaintCounter, since: float, ready: Callable[[], bool | None],
           cap_s: float, quiet_s: float = 0.3) -> tuple[float, bool]:
    """Run the event loop until the editor has not painted for ``quiet_s`` and ``ready()`` is
    not False; (seconds from ``since`` to its last paint, whether it settled within ``cap_s``)."""
    counter.count  # noqa: B018 - note a paint that already happened

    def done() -> bool:
        counter.count  # noqa: B018
        return time.perf_counter() - counter.last >= quiet_s and ready() is not False

    ok = ctx.spin_until(done, cap_s)
    return max(counter.last - since, 0.0), ok


def bare_repaints(ctx: PartContext, view: Any, n: int = 20) -> list[float]:
    """Milliseconds of repainting the editor with nothing changed (n times)."""
    target = view.viewport() if hasattr(view, "viewport") else view
    own = hasattr(view, "frames_drawn") or hasattr(view, "frameRendered")
    counter = PaintCounter(view if own else target)
    out = []
    for _ in range(n):
        before = counter.count
        t0 = time.perf_counter()
        _force_paint(ctx, counter, target, before)
        out.append((time.perf_counter() - t0) * 1000.0)
    return out


def _force_paint(ctx: PartContext, counter: PaintCounter, target: Any, before: int, cap_s: float = 5.0) -> None:
    """Make sure the editor painted after ``before``: posted events, then a synchronous
    repaint; a GL view (whose repaint() is not synchronous) is asked and waited for."""
    from PySide6.QtCore import QEventLoop

    ctx.app.processEvents(QEventLoop.ProcessEventsFlag.AllEvents)
    if counter.count > before:
        return
    if counter.is_signal:  # the 3D view: update() and wait for frameRendered
        target.update()
        deadline = time.perf_counter() + cap_s
        while counter.count <= before and time.perf_counter() < deadline:
            ctx.app.processEvents(QEventLoop.ProcessEventsFlag.AllEvents)
        return
    target.repaint()


# ============================================================== parts
def part_ik(ctx: PartContext, frame: int) -> None:
    """Right-drag IK on Pip's lantern hand at ``frame``."""
    import numpy as np
    from PySide6.QtCore import QPoint, QPointF, Qt
    from PySide6.QtTest import QTest

    from qtanimator.document import character2d as c2d
    from qtanimator.document.commands import SetParameter
    from qtanimator.ui.rig_interaction import pick

    runs = 2 if quick() else 3
    budget_s = 30.0 if quick() else 90.0  # moves stop (the drag is released) once spent
    window = ctx.window()
    doc = window.doc
    if frame > doc.frame_range[1]:
        window.ctx.push(SetParameter(doc, "frame_end", max(2100, frame + 100)))
    window.central_tabs.setCurrentWidget(window.rig_editor)
    view = window.rig_editor.view
    vp = view.viewport()
    counter = PaintCounter(view)
    character = doc.runtime[IK_ASSET]
    joint = int(character.joint_index(IK_JOINT))

    def warm() -> float:
        """Show ``frame`` and wait until the editor has settled; seconds."""
        t0 = time.perf_counter()
        window.ctx.set_frame(float(frame))
        _force_paint(ctx, counter, vp, counter.count)
        settle(ctx, counter, t0, lambda: _frame_ready(doc, IK_ASSET, frame), cap_s=120.0)
        return time.perf_counter() - t0

    warm_s = warm()
    extra: dict[str, Any] = {"ik_frame": frame, "viewport": f"{vp.width()}x{vp.height()}",
                             "first_show_s": round(warm_s, 3)}
    with load_span(extra):
        bare = bare_repaints(ctx, view)

    def hand_point() -> QPoint:
        pose = c2d.evaluate_pose(doc, IK_ASSET, window.ctx.time)
        pts = np.asarray(character.joints[joint].shapes[0].points, dtype=float)
        centre = pts.mean(axis=0)
        for local in [centre] + [centre + f * (p - centre) for f in (0.3, 0.6) for p in pts]:
            p = view.from_scene(pose.to_world(joint, local))
            pos = QPoint(int(round(p.x())), int(round(p.y())))
            if pick(doc, window.ctx.time, view.to_scene(QPointF(pos))) == (IK_ASSET, joint):
                return pos
        raise RuntimeError(f"{IK_JOINT} of {IK_ASSET} is not under any point of its shape")

    moves: list[float] = []
    per_run: list[float] = []
    settles: list[float] = []
    releases: list[float] = []
    unsettled = 0
    incomplete = ""
    spent = 0.0
    done_runs = 0
    move_extra: dict[str, Any] = dict(extra)
    with load_span(move_extra):
        for run_index in range(runs):
            if spent >= budget_s:
                break
            start = hand_point()
            QTest.mousePress(vp, Qt.MouseButton.RightButton, Qt.KeyboardModifier.NoModifier, start)
            ctx.app.processEvents()
            run_moves: list[float] = []
            pos = start
            for k in range(1, IK_MOVES + 1):
                # Up and out in a gentle arc, 2 px per move: a slow, steady drag.
                pos = start + QPoint(2 * k, -int(round(12 * math.sin(k / IK_MOVES * math.pi))))
                before = counter.count
                t0 = time.perf_counter()
                QTest.mouseMove(vp, pos)
                _force_paint(ctx, counter, vp, before)
                dt = time.perf_counter() - t0
                run_moves.append(dt * 1000.0)
                spent += dt
                if spent >= budget_s and k < IK_MOVES:
                    incomplete = (f"time budget of {budget_s:g} s spent: run {run_index + 1} released after "
                                  f"{k} of {IK_MOVES} moves")
                    break
            t_release = time.perf_counter()
            QTest.mouseRelease(vp, Qt.MouseButton.RightButton, Qt.KeyboardModifier.NoModifier, pos)
            _force_paint(ctx, counter, vp, counter.count)
            releases.append((time.perf_counter() - t_release) * 1000.0)
            settled_s, ok = settle(ctx, counter, t_release, lambda: _frame_ready(doc, IK_ASSET, frame),
                                   cap_s=60.0)
            settles.append(settled_s * 1000.0)
            unsettled += not ok
            moves.extend(run_moves)
            per_run.append(statistics.median(run_moves))
            done_runs += 1
            if window.ctx.undo_stack.undoText() and run_index + 1 < runs and spent < budget_s:
                window.ctx.undo_stack.undo()  # the next run starts from the same pose
                warm()
    if incomplete:
        move_extra["incomplete"] = incomplete
    r = timed_row(f"IK right-drag on {IK_ASSET}/{IK_JOINT}, frame {frame}: mouse move → repainted",
                  moves, bare, 16.0, move_extra, per_run=per_run, runs=done_runs, bare_of="the 2D view")
    r["kind"] = "ik_move"
    if incomplete:
        r["note"] += f"; {incomplete}"
    ctx.add(r)
    settle_extra = {"ik_frame": frame, "release_to_repaint_ms": [round(v, 2) for v in releases],
                    "load_before": move_extra.get("load_before"), "load_after": move_extra.get("load_after")}
    s = timed_row(f"IK drag, frame {frame}: settle after release (until the last repaint)", settles, bare,
                  None, settle_extra, runs=done_runs, bare_of="the 2D view")
    if unsettled:
        s["note"] += f"; {unsettled} run(s) still busy after 60 s"
    ctx.add(s)
    ctx.dispose(window)


def part_play(ctx: PartContext, tab: str) -> None:
    """Playback of the demo in the 2D or the 3D tab, window 1280×720."""
    seconds = 3.0 if quick() else 10.0
    runs = 2 if quick() else 3
    fps_goal = 60.0 if tab == "2d" else 30.0
    window = ctx.window(PLAY_SIZE)
    label = "2D Rig" if tab == "2d" else "3D"
    view = window.rig_editor.view if tab == "2d" else window.viewport3d
    panel = window.rig_editor if tab == "2d" else window.viewport_panel
    counter = PaintCounter(view)
    play_action = window.findChild(type(window.action_save), "actionPlay")
    fps_runs: list[float] = []
    frame_ms: list[float] = []
    cpu_ms: list[float] = []
    shown: list[int] = []
    dropped: list[int] = []
    playback_fps: list[float] = []
    extra: dict[str, Any] = {}
    with load_span(extra):
        for _ in range(runs):
            # A freshly opened project each run: empty simulation caches, frame 0.
            if not window.open_path(DEMO):
                raise RuntimeError(f"could not open {DEMO}")
            window.central_tabs.setCurrentWidget(panel)
            ctx.spin(0.3)
            _force_paint(ctx, counter, view.viewport() if tab == "2d" else view, counter.count)
            ctx.spin(0.2)
            painted0 = counter.count
            t0 = time.perf_counter()
            c0 = time.process_time()
            play_action.trigger()
            ctx.spin(seconds)
            elapsed = time.perf_counter() - t0
            cpu = time.process_time() - c0
            painted = counter.count - painted0
            playback = window.playback
            shown.append(int(playback.shown_frames))
            dropped.append(int(playback.dropped_frames))
            playback_fps.append(float(playback.measured_fps()))
            playback.pause()
            ctx.spin(0.1)
            fps_runs.append(painted / elapsed)
            frame_ms.append(1000.0 * elapsed / max(painted, 1))
            cpu_ms.append(1000.0 * cpu / max(painted, 1))
        bare = bare_repaints(ctx, view)
    size = f"{view.width()}x{view.height()}"
    med, lo, hi = spread(fps_runs)
    bare_med = statistics.median(bare)
    cpu_med = statistics.median(cpu_ms)
    note = (f"median of {runs} runs of {seconds:g} s; min–max {lo:.3g}–{hi:.3g} fps; "
            f"CPU per painted frame {cpu_med:.3g} ms (all threads) = {cpu_med / BUDGET_MS:.2f}× the 16.7 ms "
            f"budget, {cpu_med / bare_med:.1f}× a bare repaint ({bare_med:.3g} ms); "
            f"Playback per run: shown {shown}, dropped {dropped}; "
            f"load {extra['load_before']} → {extra['load_after']}")
    ctx.add(row(f"playback of the demo, {label} tab, window 1280x720 (view {size}): frames painted per second",
                med, "fps", peer=1000.0 / bare_med, goal=f"≥ {fps_goal:g} fps", note=note, min=round(lo, 2),
                max=round(hi, 2), per_run=[round(v, 2) for v in fps_runs], shown=shown, dropped=dropped,
                playback_measured_fps=[round(v, 2) for v in playback_fps],
                frame_ms=[round(v, 2) for v in frame_ms], cpu_ms_per_frame=[round(v, 2) for v in cpu_ms],
                bare_ms=round(bare_med, 3), **extra))
    drop_share = [d / max(d + s, 1) * 100.0 for d, s in zip(dropped, shown)]
    ctx.add(row(f"playback, {label} tab: frames dropped by Playback (of shown + dropped)",
                statistics.median(drop_share), "%", goal="0 %", higher_is_better=False,
                note=f"per run {', '.join(f'{v:.0f}' for v in drop_share)} %; shown {shown}, dropped {dropped}",
                per_run=[round(v, 2) for v in drop_share], **extra))
    if tab == "3d":
        gl = getattr(view, "gl_info", "")
        ctx.rows[-2]["gl"] = gl
    window.playback.pause()
    ctx.dispose(window)


def _synthetic_document() -> Any:
    """A document of 300 channels × 2000 keys (one key a frame at 60 fps), smooth curves."""
    import numpy as np

    from qtanimator.core.channel import Channel, Key
    from qtanimator.document.document import Document, channel_id

    doc = Document()
    fps = 60.0
    times = np.arange(SYNTH_KEYS) / fps
    for c in range(SYNTH_CHANNELS):
        values = np.sin(times * (0.5 + 0.01 * c) + c) * (1.0 + c % 7) + 0.2 * np.sin(times * 7.3 + 2 * c)
        channel = Channel([Key(float(t), float(v)) for t, v in zip(times, values)])
        cid = channel_id(f"synth{c // 30:02d}", f"joint{c % 30:02d}", ("rx", "ry", "rz")[c % 3])
        doc.apply_channel(cid, channel)
    doc.apply_parameter("frame_end", SYNTH_KEYS - 1)
    return doc


def _curve_case(ctx: PartContext, window: Any, label: str, goals: tuple[float, float]) -> None:
    """Full redraw (wheel zoom) and a key drag in the curve editor of ``window``."""
    from PySide6.QtCore import QEvent, QPoint, QPointF, Qt
    from PySide6.QtGui import QMouseEvent, QWheelEvent
    from PySide6.QtWidgets import QDockWidget, QWidget

    dock = window.findChild(QDockWidget, "curveEditorDock")
    dock.show()
    dock.raise_()
    editor = window.curve_editor
    view = editor.view
    plot = window.findChild(QWidget, "curvePlot")
    vp = plot.viewport()
    counter = PaintCounter(vp)
    t0 = time.perf_counter()
    view.frame_all()
    _force_paint(ctx, counter, vp, counter.count)
    first_s = time.perf_counter() - t0
    doc = window.doc
    visible = list(view.visible)
    keys = sum(len(doc.channels[c].keys) for c in visible)
    runs = 2 if quick() else 3
    budget_s = 20.0 if quick() else 60.0
    drag_budget_s = 40.0 if quick() else 90.0  # a first move may rebuild every curve's drawing
    extra: dict[str, Any] = {"plot": f"{vp.width()}x{vp.height()}", "visible_channels": len(visible),
                             "visible_keys": keys, "frame_all_s": round(first_s, 3)}
    if not visible:
        ctx.add({**skipped(f"curve editor, {label}", "no channel is visible in the curve editor"), **extra})
        return
    with load_span(extra):
        bare = bare_repaints(ctx, plot)

    def after_event(before: int) -> None:
        """Deliver what the event posted; repaint synchronously if nothing was painted."""
        _force_paint(ctx, counter, vp, before)

    # Full redraw: a wheel notch on the plot (zoom in, then out): every curve resampled.
    centre = QPointF(vp.width() / 2.0, vp.height() / 2.0)
    redraw: list[float] = []
    redraw_runs: list[float] = []
    r_extra = dict(extra)
    budget = Budget(budget_s)
    with load_span(r_extra):
        for _ in range(runs):
            this: list[float] = []
            for k in range(WHEELS):
                delta = 120 if k % 2 == 0 else -120
                ev = QWheelEvent(centre, QPointF(vp.mapToGlobal(centre.toPoint())), QPoint(0, 0), QPoint(0, delta),
                                 Qt.MouseButton.NoButton, Qt.KeyboardModifier.NoModifier, Qt.ScrollPhase.NoScrollPhase,
                                 False)
                before = counter.count
                t0 = time.perf_counter()
                ctx.app.sendEvent(vp, ev)
                after_event(before)
                this.append((time.perf_counter() - t0) * 1000.0)
                if budget.spent:
                    break
            redraw.extend(this)
            redraw_runs.append(statistics.median(this))
            if budget.spent:
                r_extra["incomplete"] = f"time budget of {budget_s:g} s spent after {len(redraw)} redraws"
                break
    r = timed_row(f"curve editor, {label}: full redraw (wheel zoom on the plot → repainted)", redraw, bare,
                  goals[1], r_extra, per_run=redraw_runs, runs=len(redraw_runs), bare_of="the plot")
    if "incomplete" in r_extra:
        r["note"] += f"; {r_extra['incomplete']}"
    ctx.add(r)

    # Key drag: the middle key of the channel with the most keys, 30 moves.
    view.frame_all()
    _force_paint(ctx, counter, vp, counter.count)
    cid = max(visible, key=lambda c: len(doc.channels[c].keys))
    index = len(doc.channels[cid].keys) // 2

    def send(kind: QEvent.Type, pos: QPointF, button: Qt.MouseButton, buttons: Qt.MouseButton) -> None:
        ev = QMouseEvent(kind, pos, QPointF(vp.mapToGlobal(pos.toPoint())), button, buttons,
                         Qt.KeyboardModifier.NoModifier)
        ctx.app.sendEvent(vp, ev)

    drag: list[float] = []
    drag_runs: list[float] = []
    releases: list[float] = []
    presses: list[float] = []
    d_extra = dict(extra)
    d_extra["dragged"] = f"{cid} key {index}"
    left = Qt.MouseButton.LeftButton
    budget = Budget(drag_budget_s)
    with load_span(d_extra):
        for _ in range(runs):
            start = QPointF(plot.mapFromScene(view.handle_positions(cid, index)[0]))
            before = counter.count
            t0 = time.perf_counter()
            send(QEvent.Type.MouseButtonPress, start, left, left)
            after_event(before)
            presses.append((time.perf_counter() - t0) * 1000.0)
            this = []
            pos = start
            for k in range(1, CURVE_MOVES + 1):
                time.sleep(0.012)  # pyqtgraph drops mouse moves closer than 10 ms apart
                pos = QPointF(start.x() + 2 * k, start.y() - 1.5 * k)
                before = counter.count
                t0 = time.perf_counter()
                send(QEvent.Type.MouseMove, pos, Qt.MouseButton.NoButton, left)
                after_event(before)
                this.append((time.perf_counter() - t0) * 1000.0)
                if budget.spent:
                    break
            before = counter.count
            t0 = time.perf_counter()
            send(QEvent.Type.MouseButtonRelease, pos, left, Qt.MouseButton.NoButton)
            after_event(before)
            releases.append((time.perf_counter() - t0) * 1000.0)
            pushed = window.ctx.undo_stack.undoText()
            window.ctx.undo_stack.undo()
            _force_paint(ctx, counter, vp, counter.count)
            # The first move starts the gesture (selection, live layer); it is kept.
            drag.extend(this)
            drag_runs.append(statistics.median(this))
            d_extra["undo_text"] = pushed
            if budget.spent:
                d_extra["incomplete"] = f"time budget of {drag_budget_s:g} s spent after {len(drag)} moves"
                break
    d_extra["first_move_ms"] = round(drag[0], 2) if drag else None
    d_extra["release_ms"] = [round(v, 2) for v in releases]
    d_extra["press_ms"] = [round(v, 2) for v in presses]
    later = [v for k, v in enumerate(drag) if k not in _first_moves(drag_runs, drag)]
    r = timed_row(f"curve editor, {label}: key drag (mouse move → repainted)", drag, bare, goals[0], d_extra,
                  per_run=drag_runs, runs=len(drag_runs), bare_of="the plot")
    if drag:
        r["note"] += (f"; press → repainted {', '.join(f'{v:.3g}' for v in presses)} ms; first move of each run "
                      + ", ".join(f"{drag[k]:.3g}" for k in sorted(_first_moves(drag_runs, drag))) + " ms"
                      + (f"; later moves median {statistics.median(later):.3g} ms" if later else ""))
    if "incomplete" in d_extra:
        r["note"] += f"; {d_extra['incomplete']}"
    if not d_extra.get("undo_text"):
        r["note"] += "; the drag pushed no command (no key under the press?)"
    ctx.add(r)


def _first_moves(per_run: list[float], samples: list[float]) -> set[int]:
    """Indices in ``samples`` of each run's first move (runs of CURVE_MOVES, the last maybe shorter)."""
    return {k * CURVE_MOVES for k in range(len(per_run)) if k * CURVE_MOVES < len(samples)}


def part_curve(ctx: PartContext) -> None:
    """Curve editor with the CMU walk BVH, then with 300 channels × 2000 keys."""
    if BVH.is_file():
        window = ctx.window(project=None)
        t0 = time.perf_counter()
        if not window.open_path(BVH):
            raise RuntimeError(f"could not import {BVH}")
        import_s = time.perf_counter() - t0
        window.central_tabs.setCurrentWidget(window.rig_editor)  # the 3D view is not measured here
        ctx.spin(0.2)
        _curve_case(ctx, window, f"CMU walk BVH ({len(window.doc.channels)} channels, import "
                    f"{import_s:.2f} s)", (16.0, 50.0))
        ctx.dispose(window)
    else:
        ctx.add(skipped("curve editor, CMU walk BVH", f"not found at {BVH}"))
    t0 = time.perf_counter()
    doc = _synthetic_document()
    build_s = time.perf_counter() - t0
    window = ctx.window(project=None)
    t0 = time.perf_counter()
    window.ctx.replace_document(doc)  # what File > Open does with a loaded document
    ctx.app.processEvents()
    open_s = time.perf_counter() - t0
    print(f"  synthetic document built in {build_s:.2f} s, taken over in {open_s:.2f} s", file=sys.stderr)
    _curve_case(ctx, window, f"{SYNTH_CHANNELS} channels × {SYNTH_KEYS} keys", (16.0, 50.0))
    ctx.dispose(window)


def _stall_row(ctx: PartContext, name: str, stalls: list[float], bare: list[float], extra: dict[str, Any],
               idle: float, settle_s: list[float], incomplete: int, bare_of: str) -> None:
    r = timed_row(name, stalls, bare, 50.0, {**extra, "idle_longest_gap_ms": round(idle, 3),
                                             "settle_s": [round(v, 3) for v in settle_s]},
                  per_run=None, runs=len(stalls), bare_of=bare_of)
    r["note"] += f"; idle loop's longest gap {idle:.3g} ms; busy for {', '.join(f'{v:.2g}' for v in settle_s)} s"
    if incomplete:
        r["note"] += f"; {incomplete} run(s) still busy at the cap"
    ctx.add(r)


def _longest_after(meter: StallMeter, t0: float) -> float:
    """The meter's longest gap among those that began at or after ``t0`` (ms)."""
    ticks = meter.ticks
    return max((b - a for a, b in zip(ticks, ticks[1:]) if a >= t0), default=0.0) * 1000.0


def _idle_gap(ctx: PartContext, seconds: float = 1.0) -> float:
    meter = StallMeter()
    meter.start()
    ctx.spin(seconds)
    meter.stop()
    return meter.longest_ms()


def part_stall3d(ctx: PartContext) -> None:
    """Stalls while the cloth panel switches the flag to implicit / stiffness 1e6, and while
    the 3D tab is opened."""
    from PySide6.QtCore import Qt, QTimer
    from PySide6.QtTest import QTest
    from PySide6.QtWidgets import QComboBox, QDockWidget, QDoubleSpinBox

    runs = 1 if quick() else 3
    cap_s = 60.0 if quick() else 120.0
    budget_s = 150.0 if quick() else 300.0
    spent_start = time.perf_counter()
    idle = _idle_gap(ctx)

    # --- the cloth integrator and stiffness, through the panel's widgets
    results: dict[str, tuple[list[float], list[float], int]] = {"integrator": ([], [], 0), "stiffness": ([], [], 0)}
    bare: list[float] = []
    extra: dict[str, Any] = {"frame": CLOTH_FRAME}
    with load_span(extra):
        for _ in range(runs):
            if time.perf_counter() - spent_start > budget_s / 2 and results["stiffness"][0]:
                break
            window = ctx.window()
            window.central_tabs.setCurrentWidget(window.viewport_panel)
            view = window.viewport3d
            counter = PaintCounter(view)
            window.ctx.set_frame(float(CLOTH_FRAME))
            _force_paint(ctx, counter, view, counter.count)
            cloth_ready = partial(_frame_ready, window.doc, CLOTH_ASSET, CLOTH_FRAME)
            settle(ctx, counter, time.perf_counter(), cloth_ready, cap_s=cap_s)
            if not bare:
                bare = bare_repaints(ctx, view)
            dock = window.findChild(QDockWidget, "clothDock")
            dock.show()
            dock.raise_()
            panel = window.cloth_panel
            ctx.spin(0.2)
            combo = panel.findChild(QComboBox, "cloth_integrator")
            spin = panel.findChild(QDoubleSpinBox, "cloth_structural_stiffness")
            if combo is None or spin is None:
                raise RuntimeError("the cloth panel has no cloth_integrator / cloth_structural_stiffness field")

            def set_integrator(c: Any = combo) -> None:
                c.setCurrentIndex(c.findText("implicit"))

            def set_stiffness(s: Any = spin) -> None:
                s.setFocus()
                s.lineEdit().selectAll()
                QTest.keyClicks(s, "1000000")
                QTest.keyClick(s, Qt.Key.Key_Return)

            for key, action in (("integrator", set_integrator), ("stiffness", set_stiffness)):
                meter = StallMeter()
                meter.start()
                t0 = time.perf_counter() + 0.05
                QTimer.singleShot(50, action)
                ctx.spin(0.1)
                settled_s, ok = settle(ctx, counter, t0, cloth_ready, cap_s=cap_s, quiet_s=0.5)
                meter.stop()
                stalls, settles, bad = results[key]
                stalls.append(meter.longest_ms())
                settles.append(settled_s)
                results[key] = (stalls, settles, bad + (not ok))
            extra["values_after"] = f"{combo.currentText()}, {spin.value():g}"
            ctx.dispose(window)
    _stall_row(ctx, f"stall: cloth panel integrator → implicit (3D tab, frame {CLOTH_FRAME})",
               results["integrator"][0], bare, extra, idle, results["integrator"][1], results["integrator"][2],
               "the 3D view")
    _stall_row(ctx, f"stall: cloth panel structural stiffness → 1e6, implicit (3D tab, frame {CLOTH_FRAME})",
               results["stiffness"][0], bare, extra, idle, results["stiffness"][1], results["stiffness"][2],
               "the 3D view")

    # --- opening the 3D tab with a click on the tab bar
    tab_stalls: list[float] = []
    tab_settles: list[float] = []
    prepare_stalls: list[float] = []
    bad = 0
    t_extra: dict[str, Any] = {"frame": CLOTH_FRAME}
    with load_span(t_extra):
        for _ in range(runs):
            if time.perf_counter() - spent_start > budget_s and tab_stalls:
                break
            prep = StallMeter()
            prep.start()
            window = ctx.window()
            prepare_from = time.perf_counter()
            window.central_tabs.setCurrentWidget(window.rig_editor)
            window.ctx.set_frame(float(CLOTH_FRAME))
            view = window.viewport3d
            if getattr(view, "_prepare_state", "") in ("", "done"):
                t_extra["prepared_before_measuring"] = t_extra.get("prepared_before_measuring", 0) + 1
            # The hidden view prepares its GL shortly after the window shows (prepare_gl):
            # where that cost went, measured as a stall of its own.
            ctx.spin_until(lambda v=view: getattr(v, "_prepare_state", "done") in ("", "done"), 10.0)
            ctx.spin(0.3)
            prep.stop()
            prepare_stalls.append(_longest_after(prep, prepare_from))
            counter = PaintCounter(view)
            bar = window.central_tabs.tabBar()
            index = window.central_tabs.indexOf(window.viewport_panel)
            where = bar.tabRect(index).center()
            meter = StallMeter()
            meter.start()
            t0 = time.perf_counter() + 0.05
            QTimer.singleShot(50, partial(QTest.mouseClick, bar, Qt.MouseButton.LeftButton,
                                          Qt.KeyboardModifier.NoModifier, where))
            ctx.spin(0.1)
            ctx.spin_until(partial(_painted_since, counter, 0), cap_s)
            settled_s, ok = settle(ctx, counter, t0, partial(_frame_ready, window.doc, CLOTH_ASSET, CLOTH_FRAME),
                                   cap_s=cap_s, quiet_s=0.5)
            meter.stop()
            ok = ok and window.central_tabs.currentWidget() is window.viewport_panel
            tab_stalls.append(meter.longest_ms())
            tab_settles.append(settled_s)
            bad += not ok
            if not bare:
                bare = bare_repaints(ctx, view)
            ctx.dispose(window)
    _stall_row(ctx, f"stall: opening the 3D tab (click on the tab bar, frame {CLOTH_FRAME}, fresh project)",
               tab_stalls, bare, t_extra, idle, tab_settles, bad, "the 3D view")
    _stall_row(ctx, "stall: the hidden 3D view preparing its GL after the window shows (open, then wait)",
               prepare_stalls, bare, dict(t_extra), idle, [], 0, "the 3D view")


def part_autosave(ctx: PartContext) -> None:
    """Stalls while the recovery manager autosaves 300 channels × 2000 keys."""
    from qtanimator.document.commands import SetParameter

    runs = 2 if quick() else 3
    idle = _idle_gap(ctx)
    doc = _synthetic_document()
    window = ctx.window(project=None)
    window.ctx.replace_document(doc)
    ctx.app.processEvents()
    bare = bare_repaints(ctx, window)  # the whole window: curve editor with 300 curves, timeline, docks
    manager = window.recovery
    keys = sum(len(c.keys) for c in window.doc.channels.values())
    stalls: list[float] = []
    durations: list[float] = []
    sizes: list[int] = []
    extra: dict[str, Any] = {"keys": keys}
    fired: list[float] = []

    def note_fired() -> None:
        fired.append(time.perf_counter())
        manager.timer.setInterval(60_000)  # once is enough

    manager.timer.timeout.connect(note_fired)
    with load_span(extra):
        for k in range(runs):
            window.ctx.push(SetParameter(window.doc, "bench.edit", k))  # unsaved changes since the last one
            ctx.app.processEvents()
            path = Path(manager.project_path)
            before = path.stat().st_mtime_ns if path.is_file() else None
            fired.clear()
            meter = StallMeter()
            meter.start()
            t0 = time.perf_counter()
            manager.timer.start(50)  # the manager's own timer, due in 50 ms instead of a minute

            def written(p: Path = path, b: int | None = before) -> bool:
                return bool(fired) and p.is_file() and p.stat().st_mtime_ns != b

            ok = ctx.spin_until(written, 60.0, poll_ms=5)
            t_done = time.perf_counter()
            ctx.spin(0.2)
            meter.stop()
            stalls.append(meter.longest_ms())
            durations.append(max(t_done - t0 - 0.05, 0.0))  # from when the timer was due
            sizes.append(path.stat().st_size if path.is_file() else 0)
            if not ok:
                extra["incomplete"] = "the recovery file was not written within 60 s"
    extra["file_mb"] = round(max(sizes) / 1e6, 1)
    _stall_row(ctx, f"stall: autosave of a {keys:,}-key project (recovery timer)", stalls, bare,
               extra, idle, durations, 0, "the whole window")
    ctx.dispose(window)


def run_part(name: str, rows_to: Path | None) -> list[dict[str, Any]]:
    """Run one part in this process (the child's side)."""
    ctx = PartContext(rows_to)
    try:
        if name.startswith("ik"):
            part_ik(ctx, int(name[2:]))
        elif name == "play2d":
            part_play(ctx, "2d")
        elif name == "play3d":
            part_play(ctx, "3d")
        elif name == "curve":
            part_curve(ctx)
        elif name == "stall3d":
            part_stall3d(ctx)
        elif name == "autosave":
            part_autosave(ctx)
        else:
            raise ValueError(name)
    except Exception as exc:  # the rows so far, plus what went wrong
        import traceback

        traceback.print_exc(file=sys.stderr)
        ctx.add(skipped(f"gui {name}: failed", f"{type(exc).__name__}: {exc}"))
    return ctx.rows


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0] if __doc__ else None)
    parser.add_argument("--part", help="run one part in this process (used by run())")
    parser.add_argument("--parts", help="comma-separated parts to run, each in its own process")
    parser.add_argument("--rows-to", help=argparse.SUPPRESS)
    ns = parser.parse_args(argv)
    if ns.part:
        if ns.part not in PARTS:
            parser.error(f"no part {ns.part!r} (there are: {', '.join(PARTS)})")
        rows = run_part(ns.part, Path(ns.rows_to) if ns.rows_to else None)
        sys.stdout.flush()
        sys.stderr.flush()
        if not ns.rows_to:
            print_rows(rows, COLUMNS)
        # Leave without tearing Qt down (windows, GL contexts): the rows are written.
        os._exit(0)
    if ns.parts:
        os.environ["QTANIMATOR_BENCH_GUI_PARTS"] = ns.parts
    return print_rows(run(), COLUMNS)


if __name__ == "__main__":
    sys.exit(main())
