"""CPU linear blend skinning: vertices per second, next to the memory-copy bound.

Run: ``.venv/bin/python benchmarks/bench_skinning.py`` (prints a table), or call ``run()``
for the rows. Cases:

* MIT 6.837 Model1 (13,336 vertices, 17 weighted joints, up to 13 influences), float64
  (exact) and float32;
* a synthetic mesh of 100,000 vertices, 4 influences each, 50 joints, float32.

Each figure is the best of several repetitions of ``skin_positions`` (joint skinning
matrices, blend, transform) with a new random pose every call. The peer figure is
``numpy.copyto`` of the same bytes a skinning call must touch (positions in, joint
indices, weights, positions out) measured in the same run: the memory-bandwidth bound,
so the ratio says how far from "as fast as copying the data" skinning is.
Goal: 25 M vertices/s or more at 100k on a 2-core machine.
"""

from __future__ import annotations

import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

REPO = Path(__file__).resolve().parents[1]
MIT = (REPO / ".." / "shared" / "data" / "mit6837").resolve()
GOAL = 25e6
REPEATS = 25


def _best(fn: Callable[[], object], repeats: int = REPEATS) -> tuple[float, float]:
    fn()
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times), statistics.median(times)


def _copy_bound(num_vertices: int, num_influences: int, itemsize: int) -> float:
    """Seconds to copy what one skinning call reads and writes."""
    nbytes = num_vertices * (3 * itemsize + num_influences * (8 + itemsize) + 3 * itemsize)
    src = np.ones(nbytes // 8, dtype=np.float64)
    dst = np.empty_like(src)
    best, _ = _best(lambda: np.copyto(dst, src))
    return best


def _row(name: str, vertices: int, seconds: float, median: float, copy_s: float, goal: str) -> dict[str, Any]:
    rate = vertices / seconds
    peer = vertices / copy_s
    return {"name": name, "figure": round(rate / 1e6, 2), "unit": "M vertices/s",
            "peer figure": round(peer / 1e6, 1), "ratio": round(rate / peer, 3), "goal": goal,
            "median figure": round(vertices / median / 1e6, 2)}


def _synthetic(rng: np.random.Generator, nv: int = 100_000, k: int = 4, nj: int = 50) -> tuple[Any, Any]:
    from qtanimator.core.skeleton import Joint, Skeleton
    from qtanimator.core.skinning import SkinBinding, bind_to_skeleton

    parents = [None] + [int(rng.integers(0, i)) for i in range(1, nj)]
    skel = Skeleton([Joint(f"j{i}", p, rng.normal(scale=0.3, size=3)) for i, p in enumerate(parents)])
    joints = np.stack([rng.choice(nj, size=k, replace=False) for _ in range(256)])[rng.integers(0, 256, nv)]
    w = rng.random((nv, k))
    w /= w.sum(axis=1, keepdims=True)
    binding = SkinBinding.from_padded(joints, w, nj)
    skin = bind_to_skeleton(rng.normal(size=(nv, 3)), np.zeros((0, 3), dtype=np.int64), binding,
                            skel.bind_world_matrices())
    return skel, skin


def _posed(skel: Any, rng: np.random.Generator, count: int = 8) -> list[np.ndarray]:
    out = []
    for _ in range(count):
        s = skel.copy()
        s.set_dof_values(rng.uniform(-0.5, 0.5, size=(len(s.joints), 3)))
        out.append(s.world_matrices())
    return out


def run() -> list[dict[str, Any]]:
    from qtanimator.core.skinning import skin_positions

    rng = np.random.default_rng(1)
    rows: list[dict[str, Any]] = []
    goal = f">= {GOAL / 1e6:g} M vertices/s"

    skel, skin = _synthetic(rng)
    poses = _posed(skel, rng)
    it = iter(range(10**9))
    best, med = _best(lambda: skin_positions(skin, poses[next(it) % len(poses)], np.float32))
    rows.append(_row("skinning 100k vertices, 4 influences, 50 joints, float32", skin.num_vertices, best, med,
                     _copy_bound(skin.num_vertices, 4, 4), goal))
    best, med = _best(lambda: skin_positions(skin, poses[next(it) % len(poses)], np.float64), 10)
    rows.append(_row("skinning 100k vertices, 4 influences, 50 joints, float64", skin.num_vertices, best, med,
                     _copy_bound(skin.num_vertices, 4, 8), "(exact path)"))

    if (MIT / "Model1.skel").is_file():
        from qtanimator.core.skinning import SkinBinding, bind_to_skeleton
        from qtanimator.formats.attach import load_attach
        from qtanimator.formats.obj import load_obj
        from qtanimator.formats.skel import load_skel

        mskel = load_skel(MIT / "Model1.skel")
        mesh = load_obj(MIT / "Model1.obj")
        weights = load_attach(MIT / "Model1.attach", mesh.num_vertices, len(mskel.joints))
        mskin = bind_to_skeleton(mesh.positions, mesh.triangles, SkinBinding.from_dense(weights),
                                 mskel.bind_world_matrices())
        mposes = _posed(mskel, rng)
        nnz = len(mskin.binding)
        for dtype, label in ((np.float64, "float64"), (np.float32, "float32")):
            best, med = _best(lambda d=dtype: skin_positions(mskin, mposes[next(it) % len(mposes)], d))
            itemsize = np.dtype(dtype).itemsize
            rows.append(_row(f"skinning MIT Model1 (13,336 vertices, ≤ 13 influences), {label}",
                             mskin.num_vertices, best, med,
                             _copy_bound(mskin.num_vertices, max(1, round(nnz / mskin.num_vertices)), itemsize),
                             "-"))
    else:
        rows.append({"name": "skinning MIT Model1", "figure": None, "unit": "M vertices/s", "peer figure": None,
                     "ratio": None, "goal": "-", "skipped": f"shared data not found at {MIT}"})
    return rows


def main() -> int:
    rows = run()
    print(f"{'benchmark':<66} {'figure':>9} {'median':>9} {'copy peer':>10} {'ratio':>7}  unit / goal")
    for r in rows:
        if r.get("figure") is None:
            print(f"{r['name']:<66} skipped: {r.get('skipped')}")
            continue
        print(f"{r['name']:<66} {r['figure']:>9} {r['median figure']:>9} {r['peer figure']:>10} {r['ratio']:>7}  "
              f"{r['unit']} / {r['goal']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
