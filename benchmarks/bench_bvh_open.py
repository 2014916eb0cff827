"""BVH file-open time per sample (issue 21, item 4): our reader plus load_bvh_character
(the skeleton and channels a project gets) against bvhio's load of the same file
(``readAsHierarchy``: parse plus its joint hierarchy). Median [min-max] over interleaved runs.

    .venv/bin/python -m benchmarks.bench_bvh_open [--repeats N] [--out PATH]
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from collections.abc import Callable
from datetime import date
from pathlib import Path

from qtanimator.document.character3d import load_bvh_character
from qtanimator.formats.bvh import load_bvh

DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "bvh"


def _times(fns: dict[str, Callable[[], object]], repeats: int) -> dict[str, list[float]]:
    for fn in fns.values():
        fn()
    out: dict[str, list[float]] = {name: [] for name in fns}
    for _ in range(repeats):
        for name, fn in fns.items():  # taking turns: a burst of load hits both alike
            start = time.perf_counter()
            fn()
            out[name].append(time.perf_counter() - start)
    return out


def _fmt(ts: list[float]) -> str:
    ms = [t * 1e3 for t in ts]
    return f"{statistics.median(ms):.2f} [{min(ms):.2f}-{max(ms):.2f}] ms"


def run(repeats: int) -> list[str]:
    import bvhio

    lines = [f"# benchmarks/bench_bvh_open.py, {date.today()}, {os.cpu_count()}-core machine, "
             f"bvhio {bvhio.__version__ if hasattr(bvhio, '__version__') else '1.5.4'}, {repeats} runs each; "
             f"load average before {os.getloadavg()[0]:.2f}",
             "file | size | frames x channels | qtanimator open (load_bvh + load_bvh_character) | "
             "bvhio.readAsHierarchy | ratio bvhio/ours"]
    for path in sorted(DATA.glob("*.bvh")):
        p = str(path)
        times = _times({"ours": lambda p=p: load_bvh_character(p),  # type: ignore[misc]
                        "bvhio": lambda p=p: bvhio.readAsHierarchy(p)}, repeats)  # type: ignore[misc]
        clip = load_bvh(p)
        ratio = statistics.median(times["bvhio"]) / statistics.median(times["ours"])
        lines.append(f"{path.name} | {path.stat().st_size:,} B | {clip.frame_count} x {clip.channel_count} | "
                     f"{_fmt(times['ours'])} | {_fmt(times['bvhio'])} | {ratio:.2f}")
    lines.append(f"# load average after {os.getloadavg()[0]:.2f}")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--out", type=Path, default=None)
    args = parser.parse_args()
    lines = run(args.repeats)
    text = "\n".join(lines) + "\n"
    print(text, end="")
    if args.out is not None:
        args.out.write_text(text)


if __name__ == "__main__":
    main()
