"""Benchmark runner: ``python -m benchmarks [NAME ...]`` prints one table of every result.

Convention for benchmark modules (``benchmarks/bench_<name>.py``)
----------------------------------------------------------------
* The module exposes ``run() -> list[dict]``; each dict is one row of the table:

  ``name``         what was measured (str)
  ``figure``       our figure (number, or None when skipped)
  ``unit``         its unit, e.g. "M samples/s" or "ms/frame"
  ``peer figure``  the peer's figure in the same unit, measured in the same run (or None)
  ``ratio``        ours relative to the peer, > 1 meaning we are better (or None)
  ``goal``         the goal as text, e.g. "≥ 0.5× scipy" or "< 16 ms"
  ``skipped``      optional: why the row has no figure (e.g. "ikpy is not installed")
  ``note``         optional: anything else worth a word

  Other keys are allowed and ignored by the table. ``benchmarks/common.py`` has ``row()``,
  ``skipped()`` and timing helpers.
* A peer that is an optional package (scipy, ikpy, warp-lang) must be imported inside
  ``run()`` and, when missing, give a row with ``skipped`` instead of raising.
* Importing the module must be cheap and have no side effects; it runs only in ``run()``.
* Modules may also be run alone (``python benchmarks/bench_x.py``) with their own printing.

``NAME`` selects modules by the part after ``bench_`` (``channel``, ``startup``, …); with no
name every module runs. A module that fails prints one row with the error and the runner
goes on; the exit status is 1 if any module failed. ``--json`` prints the rows as JSON.

When more than one module runs, each runs in a fresh Python process: a module's
process-wide state (a QApplication on the ``offscreen`` platform, which can make no OpenGL
context; numba or warp caches; imported peers) must not change another module's figures.
Whatever a module prints on stdout goes to stderr, so the table stays clean.
"""

from __future__ import annotations

import argparse
import importlib
import json
import subprocess
import sys
import tempfile
import time
import traceback
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
if str(HERE.parent) not in sys.path:
    sys.path.insert(0, str(HERE.parent))

COLUMNS = ("name", "figure", "unit", "peer figure", "ratio", "goal")


def discover() -> list[str]:
    """Names of the benchmark modules, in alphabetical order."""
    return sorted(p.stem[len("bench_"):] for p in HERE.glob("bench_*.py"))


def run_module(name: str) -> tuple[list[dict[str, Any]], bool]:
    """Rows of one module, and whether it ran without an exception."""
    try:
        module = importlib.import_module(f"benchmarks.bench_{name}")
        rows = list(module.run())
        for r in rows:
            r.setdefault("module", name)
        return rows, True
    except ModuleNotFoundError as exc:  # a peer imported at module level
        return [{"name": f"{name}: not run", "module": name, "skipped": f"{exc.name} is not installed"}], True
    except Exception as exc:  # keep going: one broken benchmark must not hide the others
        traceback.print_exc(file=sys.stderr)
        return [{"name": f"{name}: failed", "module": name, "skipped": f"{type(exc).__name__}: {exc}"}], False


def run_module_isolated(name: str) -> tuple[list[dict[str, Any]], bool]:
    """:func:`run_module` in a fresh Python process (rows come back through a file)."""
    with tempfile.TemporaryDirectory(prefix="qtanimator-bench-") as tmp:
        rows_file = Path(tmp) / "rows.json"
        proc = subprocess.run([sys.executable, "-m", "benchmarks", name, "--rows-to", str(rows_file)],
                              cwd=HERE.parent, stdout=sys.stderr, check=False)
        try:
            rows = json.loads(rows_file.read_text())
        except (OSError, ValueError):
            return [{"name": f"{name}: failed", "module": name,
                     "skipped": f"the benchmark process ended with status {proc.returncode} and no rows"}], False
        return rows, proc.returncode == 0


def _cell(value: Any) -> str:
    if value is None:
        return "-"
    if isinstance(value, float):
        return f"{value:.4g}" if abs(value) < 1e5 else f"{value:.3e}"
    return str(value)


def format_table(rows: list[dict[str, Any]]) -> str:
    cells = [[_cell(r.get(c)) for c in COLUMNS] for r in rows]
    for r, line in zip(rows, cells):
        if r.get("skipped"):
            line[1:] = ["skipped: " + str(r["skipped"]), "", "", "", ""]
    # A skipped row's long reason must not widen the figure column.
    widths = [max([len(c)] + [len(line[i]) for line, r in zip(cells, rows) if not (i and r.get("skipped"))])
              for i, c in enumerate(COLUMNS)]
    out = ["  ".join(c.ljust(w) if i == 0 else c.rjust(w) if i != 5 else c for i, (c, w) in
                     enumerate(zip(COLUMNS, widths))).rstrip()]
    out.append("  ".join("-" * w for w in widths))
    for r, line in zip(rows, cells):
        if r.get("skipped"):
            out.append(f"{line[0].ljust(widths[0])}  {line[1]}")
            continue
        text = "  ".join(v.ljust(w) if i == 0 else v.rjust(w) if i != 5 else v
                         for i, (v, w) in enumerate(zip(line, widths))).rstrip()
        if r.get("note"):
            text += f"  ({r['note']})"
        out.append(text)
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks", description=__doc__.split("\n")[0])
    parser.add_argument("names", nargs="*", help=f"modules to run (default: all of {', '.join(discover())})")
    parser.add_argument("--json", action="store_true", help="print the rows as JSON instead of a table")
    parser.add_argument("--rows-to", help=argparse.SUPPRESS)  # used by the runner's child processes
    ns = parser.parse_args(argv)
    available = discover()
    unknown = [n for n in ns.names if n not in available]
    if unknown:
        print(f"python -m benchmarks: no benchmark named {', '.join(unknown)} "
              f"(there are: {', '.join(available)})", file=sys.stderr)
        return 2
    rows: list[dict[str, Any]] = []
    ok = True
    names = ns.names or available
    for name in names:
        start = time.perf_counter()
        module_rows, fine = run_module_isolated(name) if len(names) > 1 else run_module(name)
        ok &= fine
        rows.extend(module_rows)
        if not ns.rows_to:  # a child process: the parent prints the time
            print(f"[{name}: {time.perf_counter() - start:.1f} s]", file=sys.stderr)
    if ns.rows_to:
        Path(ns.rows_to).write_text(json.dumps(rows, default=str))
        return 0 if ok else 1
    if ns.json:
        print(json.dumps(rows, indent=2, default=str))
    else:
        print(format_table(rows))
    return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
