"""glTF file-open time per sample (issue 21, item 4): what File ▸ Open costs (read the file,
build the whole character, every clip, apply the import to a document) against pygltflib's
load of the same file (parsing only: it decodes no accessor). Median [min-max] over
interleaved runs. Besides ../shared/data/gltf, a generated character (tests/gltf_gen.big_clip:
59 meshes on one skin, 60 joints, one 35 s clip keyed on every joint at 30 fps) is timed, and
posing it at one frame (what playback pays per frame) is reported beside.

    .venv/bin/python -m benchmarks.bench_gltf_open [--repeats N] [--out PATH]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
from datetime import date
from pathlib import Path

from benchmarks.common import interleaved_times, median_range_ms
from qtanimator.document import Document, UndoStack
from qtanimator.document.character3d import skinned_mesh
from qtanimator.document.import3d import import_file

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data" / "gltf"


def _open(path: str) -> tuple[Document, str]:
    doc = Document()
    imp = import_file(doc, path)
    UndoStack(doc).push(imp.command)
    return doc, imp.asset_id


def run(repeats: int) -> list[str]:
    import pygltflib

    sys.path.insert(0, str(ROOT / "tests"))
    from gltf_gen import big_clip

    tmp = Path(tempfile.mkdtemp(prefix="bench_gltf_"))
    files = [*sorted(DATA.glob("*.gl*")), big_clip(tmp)]
    lines = [f"# benchmarks/bench_gltf_open.py, {date.today()}, {os.cpu_count()}-core machine, "
             f"pygltflib {pygltflib.__version__ if hasattr(pygltflib, '__version__') else '?'}, "
             f"{repeats} runs each; load average before {os.getloadavg()[0]:.2f}",
             "file | size | meshes / joints / clips (keys) | qtanimator open (read + character + document) | "
             "pygltflib.GLTF2.load | ratio ours/pygltflib | pose + skin one frame"]
    for path in files:
        p = str(path)
        times = interleaved_times({"ours": lambda p=p: _open(p),  # type: ignore[misc]
                        "pygltflib": lambda p=p: pygltflib.GLTF2.load(p)}, repeats)  # type: ignore[misc]
        doc, aid = _open(p)
        ch = doc.runtime[aid]
        keys = sum(len(c.keys) for c in doc.channels.values())
        mid = 0.5 * (ch.clips[0].start + ch.clips[0].end) if ch.clips else 0.0
        frame = interleaved_times({"pose": lambda d=doc, a=aid, t=mid: skinned_mesh(d, a, t)}, repeats)["pose"]  # type: ignore[misc]
        ratio = statistics.median(times["ours"]) / statistics.median(times["pygltflib"])
        lines.append(f"{path.name} | {path.stat().st_size:,} B | {len(ch.parts)} / {len(ch.skeleton.joints)} / "
                     f"{len(ch.clips)} ({keys:,}) | {median_range_ms(times['ours'])} | "
                     f"{median_range_ms(times['pygltflib'])} | "
                     f"{ratio:.2f} | {median_range_ms(frame)}")
    lines.append(f"# load average after {os.getloadavg()[0]:.2f}")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=11)
    parser.add_argument("--out", type=Path, default=None)
    args = parser.parse_args()
    lines = run(args.repeats)
    text = "\n".join(lines) + "\n"
    print(text, end="")
    if args.out is not None:
        args.out.write_text(text)


if __name__ == "__main__":
    main()
