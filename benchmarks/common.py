"""Helpers shared by the benchmark modules: timing, row building and standalone printing.

A row is a plain dict; see ``benchmarks/__main__.py`` for the keys the runner prints.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable
from typing import Any


def best_time(fn: Callable[[], object], repeats: int = 5, warmup: int = 1) -> float:
    """Seconds of the fastest of ``repeats`` calls of ``fn`` (after ``warmup`` untimed calls).

    The best of several repeats is the least disturbed by other jobs on a shared machine.
    """
    for _ in range(warmup):
        fn()
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - start)
    return best


def interleaved_best(fns: dict[str, Callable[[], object]], repeats: int = 5) -> dict[str, float]:
    """Best time of each function, the functions taking turns, so that a burst of load on
    the machine hits every contender alike (fair ratios measured in one run)."""
    for fn in fns.values():
        fn()
    best = {name: float("inf") for name in fns}
    for _ in range(repeats):
        for name, fn in fns.items():
            start = time.perf_counter()
            fn()
            best[name] = min(best[name], time.perf_counter() - start)
    return best


def row(name: str, figure: float | None, unit: str, peer: float | None = None, goal: str = "-",
        higher_is_better: bool = True, digits: int = 3, **extra: Any) -> dict[str, Any]:
    """A result row. ``ratio`` is ours / peer when higher is better, else peer / ours, so
    that a ratio above 1 always means "we are faster"."""
    ratio = None
    if figure is not None and peer:
        ratio = figure / peer if higher_is_better else peer / figure
    return {"name": name, "figure": None if figure is None else round(figure, digits), "unit": unit,
            "peer figure": None if peer is None else round(peer, digits),
            "ratio": None if ratio is None else round(ratio, 3), "goal": goal, **extra}


def skipped(name: str, why: str, unit: str = "", goal: str = "-") -> dict[str, Any]:
    """The row of a benchmark that could not run (a peer not installed, no sample data)."""
    return {"name": name, "figure": None, "unit": unit, "peer figure": None, "ratio": None,
            "goal": goal, "skipped": why}


def print_rows(rows: list[dict[str, Any]], columns: list[str]) -> int:
    """Print ``rows`` as a plain table of ``columns`` (a module run alone, without the
    runner); keys outside the columns follow each line so nothing measured is hidden."""
    print(" | ".join(columns))
    for r in rows:
        extras = {k: v for k, v in r.items() if k not in columns and k != "peer"}
        print(" | ".join(str(r.get(c, "")) for c in columns) + (f"  {extras}" if extras else ""))
    return 0


def interleaved_times(fns: dict[str, Callable[[], object]], repeats: int) -> dict[str, list[float]]:
    """Every run's seconds of each function, after one warm-up call each; the functions take
    turns, so a burst of load hits them alike."""
    for fn in fns.values():
        fn()
    out: dict[str, list[float]] = {name: [] for name in fns}
    for _ in range(repeats):
        for name, fn in fns.items():
            start = time.perf_counter()
            fn()
            out[name].append(time.perf_counter() - start)
    return out


def median_range_ms(ts: list[float]) -> str:
    """``median [min-max] ms`` of run times given in seconds."""
    ms = [t * 1e3 for t in ts]
    return f"{statistics.median(ms):.2f} [{min(ms):.2f}-{max(ms):.2f}] ms"
