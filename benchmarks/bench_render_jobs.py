"""``qtanimator render --jobs N``: wall time of a headless render in 1 and in N processes: the
2D view of the demo and of the pendulum clock, and the demo's 3D view (skinned walker, cape and
flag cloth baked in the parent, each worker drawing through Mesa on the parent's private Xvfb).

Each run is a fresh ``python -m qtanimator render`` (interpreter and Qt start-up, the
pendulum bake in the parent, the workers' spawn and the PNG writing included), the
contenders taking turns; the median of ``--repeats`` runs. Writes
``benchmarks/results/issue15_render_jobs.txt`` with ``--write``.

    python benchmarks/bench_render_jobs.py [--frames 240] [--size 960x640] [--repeats 3]
        [--scenes "demo,clock,demo 3D view"] [--write]
"""

from __future__ import annotations

import argparse
import datetime
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEMO = ROOT / "scenes" / "demo" / "demo.qtanim"
SCENES: dict[str, tuple[Path, tuple[str, ...]]] = {
    "demo": (DEMO, ()),
    "clock": (ROOT / "scenes" / "pendulum_clock.svg", ()),
    "demo 3D view": (DEMO, ("--view", "3d")),
}


def _run(scene: Path, extra: tuple[str, ...], frames: int, size: str, jobs: int) -> float:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env["QT_QPA_PLATFORM"] = "offscreen"  # headless: the 3D view starts its private Xvfb
    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        subprocess.run([sys.executable, "-m", "qtanimator", "render", str(scene), "-o", str(Path(tmp) / "f"),
                        "--frames", f"0:{frames - 1}", "--size", size, "--jobs", str(jobs), "--quiet", *extra],
                       check=True, env=env, cwd=ROOT)
        return time.perf_counter() - start


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--frames", type=int, default=240)
    ap.add_argument("--size", default="960x640")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 2)
    ap.add_argument("--scenes", default=",".join(SCENES), help="comma-separated rows to run")
    ap.add_argument("--write", action="store_true")
    ns = ap.parse_args()
    rows = []
    for name in ns.scenes.split(","):
        scene, extra = SCENES[name]
        times: dict[int, list[float]] = {1: [], ns.jobs: []}
        loads = []
        for _ in range(ns.repeats):
            for jobs in times:
                loads.append(os.getloadavg()[0])
                times[jobs].append(_run(scene, extra, ns.frames, ns.size, jobs))
        one, many = statistics.median(times[1]), statistics.median(times[ns.jobs])
        spread = ", ".join(f"--jobs {j}: " + "/".join(f"{t:.2f}" for t in ts) for j, ts in times.items())
        rows.append(f"render {name} {ns.frames} frames {ns.size} to PNG, --jobs {ns.jobs} (peer: --jobs 1) | "
                    f"{many:.2f} | s | {one:.2f} | {one / many:.2f} | ratio > 1 | {spread} s; "
                    f"load {min(loads):.2f}-{max(loads):.2f}")
    head = (f"# benchmarks/bench_render_jobs.py, {datetime.date.today()}, {os.cpu_count()}-core machine, "
            f"median of {ns.repeats} fresh processes each\nname | figure | unit | peer figure | ratio | goal | spread")
    text = head + "\n" + "\n".join(rows) + "\n"
    print(text, end="")
    if ns.write:
        (ROOT / "benchmarks" / "results" / "issue15_render_jobs.txt").write_text(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
