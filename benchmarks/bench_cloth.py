"""Cloth: milliseconds per 60 Hz frame against warp-lang's own cloth benchmark.

Run: ``.venv/bin/python benchmarks/bench_cloth.py`` (prints a table), or call ``run()`` for the
rows. The peer is the numpy integrator that warp-lang ships in
``warp/examples/benchmarks/benchmark_cloth_numpy.py``, fed with the cloth that
``benchmark_cloth.py`` builds (its ``Cloth`` class is taken from the installed file as it is;
the file itself cannot be imported because it needs USD and runs the benchmark on import).
The ceiling is the same benchmark on warp's compiled CPU backend
(``benchmark_cloth_warp.WpIntegrator(cloth, "cpu")``).

Identical settings on both sides (those of warp's benchmark): grids 32², 64², 128² with a
spacing of 0.1 m, stretch, shear and bend springs with k = 1000 N/m and damping 10 N·s/m,
0.1 kg per particle, the two top corners fixed, gravity, 16 substeps per 1/60 s frame,
60 frames, no drag and no ground (the peer has neither). Each side runs one untimed warm-up
frame, then 60 timed frames, taken in turns (one frame of each simulation per round, so a busy
machine slows all of them alike); the figure is the median, the mean is in the row too. After
the run the two clouds of points are compared, to show both simulate the same thing (warp's
numpy peer works in float32).

Goals (issue 5): ≥ 5× faster than the numpy peer at 64², and a 32×32 cloth in real time
(< 16 ms per frame).
"""

from __future__ import annotations

import ast
import math
import os
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from benchmarks.common import print_rows  # noqa: E402

DIMS = (32, 64, 128)
FRAMES = 60
SUBSTEPS = 16
DT = 1.0 / 60.0
SPACING = 0.1
MASS = 0.1
K = 1000.0
DAMPING = 10.0
REALTIME_MS = 16.0
SPEEDUP_GOAL = 5.0


def _warp_benchmarks_dir() -> Path | None:
    try:
        import warp
    except ImportError:
        return None
    path = Path(warp.__file__).resolve().parent / "examples" / "benchmarks"
    return path if (path / "benchmark_cloth.py").is_file() else None


def _peer_cloth_class(bench_dir: Path) -> Any:
    """warp's ``Cloth`` builder, taken from benchmark_cloth.py without running that script."""
    source = (bench_dir / "benchmark_cloth.py").read_text()
    tree = ast.parse(source)
    cls = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "Cloth")
    namespace: dict[str, Any] = {"np": np}
    exec(compile(ast.Module(body=[cls], type_ignores=[]), str(bench_dir / "benchmark_cloth.py"), "exec"), namespace)
    return namespace["Cloth"]


def _peer_cloth(bench_dir: Path, dim: int) -> Any:
    cloth_cls = _peer_cloth_class(bench_dir)
    return cloth_cls(lower=(0.0, 0.0, 0.0), dx=dim, dy=dim, radius=SPACING, stretch_stiffness=K,
                     bend_stiffness=K, shear_stiffness=K, mass=MASS, fix_corners=True)


def _interleaved(sims: dict[str, Any]) -> dict[str, list[float]]:
    """Time FRAMES frames of every simulation, one frame of each in turn (fair on a busy machine)."""
    for simulate in sims.values():
        simulate()  # warm-up (kernel loading, caches)
    times: dict[str, list[float]] = {name: [] for name in sims}
    for _ in range(FRAMES):
        for name, simulate in sims.items():
            t0 = time.perf_counter()
            simulate()
            times[name].append((time.perf_counter() - t0) * 1000.0)
    return times


def _our_cloth(dim: int, integrator: str = "symplectic", substeps: int = SUBSTEPS, accelerate: bool | None = None,
               **extra: Any) -> Any:
    from qtanimator.core.cloth import Cloth, ClothParams

    width = SPACING * (dim - 1)
    params = ClothParams(
        rows=dim, cols=dim, width=width, height=width, total_mass=MASS * dim * dim,
        structural_stiffness=K, shear_stiffness=K, bend_stiffness=K,
        structural_damping=DAMPING, shear_damping=DAMPING, bend_damping=DAMPING,
        drag_coefficient=0.0, ground_enabled=False, pin_mode="top_corners", gravity=9.8,
        integrator=integrator, substeps=substeps,
        # warp's cloth lies in the xz plane from (0, 0, 0), rows along +z: turn ours to match.
        origin=(width / 2.0, 0.0, 0.0), orientation=(-math.pi / 2.0, 0.0, 0.0),
    ).replace(**extra)
    return Cloth(params, accelerate=accelerate)


def _peer_numpy(bench_dir: Path, dim: int) -> tuple[Any, Any]:
    """warp's numpy integrator on warp's cloth: (simulate one frame, the cloth)."""
    if str(bench_dir) not in sys.path:
        sys.path.insert(0, str(bench_dir))
    import benchmark_cloth_numpy

    cloth = _peer_cloth(bench_dir, dim)
    integrator = benchmark_cloth_numpy.NpIntegrator(cloth)
    return (lambda: integrator.simulate(DT, SUBSTEPS)), cloth


def _peer_warp_cpu(bench_dir: Path, dim: int) -> tuple[Any, str]:
    """warp's compiled CPU integrator: (simulate one frame or None, a note)."""
    try:
        import warp as wp

        wp.config.quiet = True  # warp < 1.10; later versions print by log level
        if hasattr(wp, "LOG_WARNING"):
            wp.config.log_level = wp.LOG_WARNING
        if str(bench_dir) not in sys.path:
            sys.path.insert(0, str(bench_dir))
        import benchmark_cloth_warp

        cloth = _peer_cloth(bench_dir, dim)
        t0 = time.perf_counter()
        integrator = benchmark_cloth_warp.WpIntegrator(cloth, "cpu")
        integrator.simulate(DT, SUBSTEPS)  # compiles the kernels (warp clears its kernel cache on import)
        compile_ms = (time.perf_counter() - t0) * 1000.0
        return (lambda: integrator.simulate(DT, SUBSTEPS)), f"first frame incl. kernel compile {compile_ms:.0f} ms"
    except Exception as exc:  # noqa: BLE001 - any failure of the compiled backend is reported, not fatal
        return None, f"unavailable: {type(exc).__name__}: {exc}".splitlines()[0][:200]


def _row(name: str, ours: float | None, peer: float | None, goal: str, peer_name: str,
         met: bool | None = None, **extra: Any) -> dict[str, Any]:
    row: dict[str, Any] = {
        "name": name, "figure": None if ours is None else round(ours, 3), "unit": "ms/frame",
        "peer figure": None if peer is None else round(peer, 3),
        # the runner's convention: a ratio above 1 means we are faster (peer ms / our ms)
        "ratio": None if ours is None or peer is None else round(peer / ours, 4),
        "speedup": None if ours is None or peer is None else round(peer / ours, 2),
        "goal": goal, "peer": peer_name,
    }
    if met is not None:
        row["met"] = met
    row.update(extra)
    return row


def _cold_compile_s() -> float | None:
    """Seconds a fresh process takes to compile the numba kernels with an empty cache."""
    import subprocess
    import tempfile

    code = "from qtanimator.core import cloth_kernels as k; print(k.warm_up())"
    with tempfile.TemporaryDirectory(prefix="qtanimator-numba-") as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache}
        proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                              cwd=REPO, check=False)
    try:
        return float(proc.stdout.strip().splitlines()[-1])
    except (ValueError, IndexError):
        return None


def run(dims: tuple[int, ...] = DIMS) -> list[dict[str, Any]]:
    from qtanimator.core import cloth_kernels

    bench_dir = _warp_benchmarks_dir()
    rows: list[dict[str, Any]] = []
    cold_s = cloth_kernels.warm_up()
    kernels = "numba kernels" if cloth_kernels.HAVE_NUMBA else "numpy (numba not installed)"
    if cloth_kernels.HAVE_NUMBA:
        compile_s = _cold_compile_s()
        rows.append({"name": "cloth numba kernels: compile with an empty cache (cold start) vs load from the cache",
                     "figure": None if compile_s is None else round(compile_s, 3), "unit": "s",
                     "peer figure": round(cold_s, 3), "ratio": None, "goal": "report (issue 5)",
                     "peer": "this process, kernels loaded from the on-disk cache"})
    peer_name = "warp examples/benchmarks/benchmark_cloth_numpy.py"
    for dim in dims:
        load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
        ours_cloth = _our_cloth(dim)
        numpy_cloth = _our_cloth(dim, accelerate=False)
        sims: dict[str, Any] = {"ours": lambda c=ours_cloth: c.step(DT), "numpy": lambda c=numpy_cloth: c.step(DT)}
        note = "warp-lang not installed"
        peer_cloth = None
        if bench_dir is not None:
            sims["peer"], peer_cloth = _peer_numpy(bench_dir, dim)
            warp_sim, note = _peer_warp_cpu(bench_dir, dim)
            if warp_sim is not None:
                sims["warp"] = warp_sim
        times = _interleaved(sims)
        fig = {name: float(np.median(t)) for name, t in times.items()}
        mean = {name: round(float(np.mean(t)), 3) for name, t in times.items()}
        ours, ours_np, peer = fig["ours"], fig["numpy"], fig.get("peer")
        goal, met, met_np = "", None, None
        if dim == 64:
            goal = f"≥ {SPEEDUP_GOAL:g}× faster than the numpy peer"
            if peer is not None:
                met, met_np = peer / ours >= SPEEDUP_GOAL, peer / ours_np >= SPEEDUP_GOAL
        elif dim == 32:
            goal, met, met_np = f"< {REALTIME_MS:g} ms (real time at 60 Hz)", ours < REALTIME_MS, ours_np < REALTIME_MS
        extra: dict[str, Any] = {"mean_ms": mean["ours"], "load_average": round(load, 2),
                                 "kernel_load_s": round(cold_s, 3)}
        if peer_cloth is not None:
            diff = float(np.abs(ours_cloth.positions - np.asarray(peer_cloth.positions, dtype=np.float64)).max())
            extra["max_position_difference_m"] = round(diff, 6)
            extra["peer_mean_ms"] = mean["peer"]
        rows.append(_row(f"cloth {dim}² symplectic, 16 substeps (ours, {kernels}) vs warp's numpy peer", ours, peer,
                         goal, peer_name, met, **extra))
        rows.append(_row(f"cloth {dim}² symplectic, 16 substeps (ours, plain numpy) vs warp's numpy peer", ours_np,
                         peer, goal, peer_name, met_np, mean_ms=mean["numpy"]))
        rows.append(_row(f"cloth {dim}² (ours, {kernels}) vs warp's compiled CPU backend (ceiling)", ours,
                         fig.get("warp"), "ceiling, no goal",
                         "warp examples/benchmarks/benchmark_cloth_warp.py on device 'cpu' (its kernel uses g = 9.81)",
                         note=note))
    # Extras with no peer: the large-step implicit integrator and the full feature set.
    extras: dict[str, Any] = {}
    for dim in (32, 64):
        if dim in dims:
            implicit = _our_cloth(dim, integrator="implicit", substeps=1)
            extras[f"implicit {dim}"] = lambda c=implicit: c.step(DT)
    if 32 in dims:
        full = _our_cloth(32, drag_coefficient=1.0, wind=(0.0, 0.0, 3.0), turbulence=1.0, ground_enabled=True,
                          ground_height=-2.0)
        extras["full 32"] = lambda c=full: c.step(DT)
    times = _interleaved(extras)
    for dim in (32, 64):
        if f"implicit {dim}" in times:
            rows.append(_row(f"cloth {dim}² implicit (Baraff–Witkin + CG), 1 step of 1/60 s per frame",
                             float(np.median(times[f"implicit {dim}"])), None, "stable at dt = 1/60 (no peer)", "none"))
    if "full 32" in times:
        t = float(np.median(times["full 32"]))
        rows.append(_row("cloth 32² symplectic, 16 substeps, with drag, wind, turbulence and ground", t, None,
                         f"< {REALTIME_MS:g} ms", "none", t < REALTIME_MS))
    return rows


def main() -> int:
    return print_rows(run(), ["name", "figure", "unit", "peer figure", "ratio", "speedup", "goal", "met"])


if __name__ == "__main__":
    sys.exit(main())
