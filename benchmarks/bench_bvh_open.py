"""BVH file-open time per sample (issue 21, item 4): our reader plus load_bvh_character
(the skeleton and channels a project gets) against bvhio's load of the same file
(``readAsHierarchy``: parse plus its joint hierarchy). Median [min-max] over interleaved runs.

    .venv/bin/python -m benchmarks.bench_bvh_open [--repeats N] [--out PATH]
"""

from __future__ import annotations

import argparse
import os
import statistics
from datetime import date
from pathlib import Path

from benchmarks.common import interleaved_times, median_range_ms
from qtanimator.document.character3d import load_bvh_character
from qtanimator.formats.bvh import load_bvh

DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "bvh"


def run(repeats: int) -> list[str]:
    import bvhio

    lines = [f"# benchmarks/bench_bvh_open.py, {date.today()}, {os.cpu_count()}-core machine, "
             f"bvhio {bvhio.__version__ if hasattr(bvhio, '__version__') else '1.5.4'}, {repeats} runs each; "
             f"load average before {os.getloadavg()[0]:.2f}",
             "file | size | frames x channels | qtanimator open (load_bvh + load_bvh_character) | "
             "bvhio.readAsHierarchy | ratio bvhio/ours"]
    for path in sorted(DATA.glob("*.bvh")):
        p = str(path)
        times = interleaved_times({"ours": lambda p=p: load_bvh_character(p),  # type: ignore[misc]
                        "bvhio": lambda p=p: bvhio.readAsHierarchy(p)}, repeats)  # type: ignore[misc]
        clip = load_bvh(p)
        ratio = statistics.median(times["bvhio"]) / statistics.median(times["ours"])
        lines.append(f"{path.name} | {path.stat().st_size:,} B | {clip.frame_count} x {clip.channel_count} | "
                     f"{median_range_ms(times['ours'])} | {median_range_ms(times['bvhio'])} | {ratio:.2f}")
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
