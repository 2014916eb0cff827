#!/usr/bin/env python3
"""Seeded, sampled mutation testing for qtanimator (an mutmut equivalent that fits 2 cores).

    python tools/mutation.py --modules qtanimator/core --per-module 12 --seed 17 --jobs 1 \
        --out benchmarks/results/mutation_core.txt

What it does:

1. Copies the repository (without .venv, .git, node_modules, __pycache__) into a private work
   folder, ``/tmp/mutation-work/repo-<i>`` (one per job), so the working tree is never touched.
   ``/tmp/shared`` is made a link to ``/work/shared`` (the tests find the data as ../shared).
2. Parses every module under ``--modules`` with :mod:`ast` and lists its mutation sites
   (:func:`mutation_sites`): arithmetic ``+ - * / // **`` swaps (also in ``+=`` etc.),
   comparison flips ``< <=``, ``> >=``, ``== !=``, ``is / is not``, ``in / not in``,
   ``and/or`` swap, ``not x -> x``, ``-x -> x``, numeric constant ``c -> c + 1``,
   ``True/False`` swap and ``return x -> return None``. Skipped: docstrings and all string
   constants, annotations, ``__all__``, decorators, f-strings and ``%``/``.format``
   formatting, logging / ``warnings.warn`` / ``print`` calls, ``raise`` statements, code under
   ``if TYPE_CHECKING:`` and ``if __name__ == "__main__":``.
3. Samples ``--per-module`` sites per module with a random generator seeded by
   ``(seed, module path)``, so a run is repeatable.
4. Picks the tests of each module (:func:`tests_for_module`, :func:`rank_tests`): test files
   under ``tests/`` that import the module (or a module that imports it), leaving out
   ``tests/ui``/``tests/render`` (Qt, GL); its own ``test_<module>*`` files first, then the
   files that mention more of its names; at most ``--max-test-files`` that pass alone, files
   slower than ``--max-file-seconds`` left out (not ``test_<module>.py`` or
   ``test_<module>_mutants.py``); tests marked ``slow``
   are deselected.
5. Baseline: runs each module's tests unmutated once (they must pass); with ``--select lines``
   under the line tracer of ``tools/mutation_trace.py``: which test ran which of the module's
   lines. The timeout is ``--timeout`` (default: 3 x baseline + 5 s).
6. For each mutant: writes the mutated module into the private copy, runs
   ``pytest -x -q -p no:cacheprovider -m "not slow"`` under ``nice -n 19`` on the module's
   test files (``--select lines``: on the tests that ran the mutated lines, all the files when
   the line runs at import, none -- the mutant survives unrun -- when no test runs it), with
   ``QTANIMATOR_NO_NUMBA=1`` (the numpy kernels
   run, so mutating them means something), ``CI`` unset, ``PYTHONDONTWRITEBYTECODE=1``,
   ``PYTHONPATH`` and cwd in the copy, then restores the file. Outcome: ``killed`` (tests
   fail), ``survived`` (tests pass), ``timeout`` and ``error`` (collection/import error) --
   both of the last count as killed.
7. Writes the report after every mutant (so a run stopped by ``--budget-minutes`` or Ctrl-C
   still leaves one): killed/total per module, the pooled score with a 95 % Wilson interval,
   a site-weighted (stratified) estimate, and every survivor as ``file:line  mutation``.
"""

from __future__ import annotations

import argparse
import ast
import dataclasses
import difflib
import functools
import json
import math
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
WORK = Path("/tmp/mutation-work")
SHARED = Path("/work/shared")
SHARED_LINK = Path("/tmp/shared")
EXCLUDE = {".venv", ".git", "node_modules", "__pycache__", ".hypothesis", ".mypy_cache", ".ruff_cache",
           ".pytest_cache"}
SLOW_TEST_DIRS = ("tests/ui", "tests/render")

# ---------------------------------------------------------------------------------------------
# Mutation sites
# ---------------------------------------------------------------------------------------------

BINOP_SWAP: dict[type[ast.operator], type[ast.operator]] = {
    ast.Add: ast.Sub, ast.Sub: ast.Add, ast.Mult: ast.Div, ast.Div: ast.Mult,
    ast.FloorDiv: ast.Div, ast.Pow: ast.Mult, ast.Mod: ast.FloorDiv,
}
CMPOP_SWAP: dict[type[ast.cmpop], type[ast.cmpop]] = {
    ast.Lt: ast.LtE, ast.LtE: ast.Lt, ast.Gt: ast.GtE, ast.GtE: ast.Gt, ast.Eq: ast.NotEq,
    ast.NotEq: ast.Eq, ast.Is: ast.IsNot, ast.IsNot: ast.Is, ast.In: ast.NotIn, ast.NotIn: ast.In,
}
LOG_METHODS = {"debug", "info", "warning", "warn", "error", "exception", "critical", "log"}
LOG_OBJECTS = {"log", "_log", "logger", "_logger", "LOG", "logging", "warnings"}


@dataclasses.dataclass(frozen=True)
class Mutant:
    """One mutation: the source span it replaces and the replacement text."""

    path: str            # repository-relative path of the module
    line: int
    operator: str        # short name of the mutation operator
    start: int           # byte offsets into the module's UTF-8 source
    end: int
    replacement: str
    before: str          # the original text of the span (one line, shortened)
    after: str           # the mutated text (one line, shortened)

    def describe(self) -> str:
        return f"{self.path}:{self.line}  [{self.operator}]  {self.before}  ->  {self.after}"


def _short(text: str, limit: int = 90) -> str:
    text = " ".join(text.split())
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _is_main_guard(test: ast.expr) -> bool:
    return (isinstance(test, ast.Compare) and isinstance(test.left, ast.Name)
            and test.left.id == "__name__")


def _is_logging_call(node: ast.Call) -> bool:
    func = node.func
    if isinstance(func, ast.Name):
        return func.id in {"print"}
    if isinstance(func, ast.Attribute):
        if func.attr == "format" and isinstance(func.value, ast.Constant) and isinstance(func.value.value, str):
            return True
        if func.attr in LOG_METHODS:
            base = func.value
            name = base.id if isinstance(base, ast.Name) else base.attr if isinstance(base, ast.Attribute) else ""
            return name in LOG_OBJECTS or "log" in name.lower()
    return False


def _is_str(node: ast.expr) -> bool:
    return isinstance(node, ast.JoinedStr) or (isinstance(node, ast.Constant) and isinstance(node.value, str))


class _SiteFinder(ast.NodeVisitor):
    """Walks a module and yields (node, operator name, mutated node or text) for each site."""

    def __init__(self) -> None:
        self.sites: list[tuple[ast.AST, str, ast.AST | str]] = []
        self._returns: list[ast.expr | None] = []
        self._in_dunder_str = False

    # --- what is skipped ---------------------------------------------------------------------
    def visit_FunctionDef(self, node: ast.FunctionDef | ast.AsyncFunctionDef) -> None:
        # Decorators, annotations and the docstring are skipped; defaults and the body are not.
        # An ``@overload`` stub is never run (it is a type annotation): skipped whole.
        if any((isinstance(d, ast.Name) and d.id == "overload")
               or (isinstance(d, ast.Attribute) and d.attr == "overload") for d in node.decorator_list):
            return
        for default in [*node.args.defaults, *(d for d in node.args.kw_defaults if d is not None)]:
            self.visit(default)
        self._returns.append(node.returns)
        outer, self._in_dunder_str = self._in_dunder_str, node.name in ("__repr__", "__str__", "__format__")
        for stmt in node.body:
            self.visit(stmt)
        self._in_dunder_str = outer
        self._returns.pop()

    visit_AsyncFunctionDef = visit_FunctionDef  # type: ignore[assignment]

    def visit_Lambda(self, node: ast.Lambda) -> None:
        self._returns.append(None)
        self.generic_visit(node)
        self._returns.pop()

    def visit_ClassDef(self, node: ast.ClassDef) -> None:
        for stmt in node.body:
            self.visit(stmt)

    def visit_arg(self, node: ast.arg) -> None:  # annotation only
        return

    def visit_AnnAssign(self, node: ast.AnnAssign) -> None:
        if node.value is not None:
            self.visit(node.value)

    def visit_Assign(self, node: ast.Assign) -> None:
        if any(isinstance(t, ast.Name) and t.id == "__all__" for t in node.targets):
            return
        for target in node.targets:
            self.visit(target)
        self.visit(node.value)

    def visit_If(self, node: ast.If) -> None:
        if _is_type_checking(node.test) or _is_main_guard(node.test):
            for stmt in node.orelse:
                self.visit(stmt)
            return
        self.generic_visit(node)

    def visit_Raise(self, node: ast.Raise) -> None:
        return

    def visit_JoinedStr(self, node: ast.JoinedStr) -> None:
        return

    def visit_Call(self, node: ast.Call) -> None:
        if _is_logging_call(node):
            return
        self.visit(node.func)
        for arg in node.args:
            self.visit(arg)
        for kw in node.keywords:
            if kw.arg == "stacklevel":
                continue
            self.visit(kw.value)

    def visit_Expr(self, node: ast.Expr) -> None:
        if isinstance(node.value, ast.Constant):  # docstrings and bare constants
            return
        self.visit(node.value)

    # --- the sites ----------------------------------------------------------------------------
    def visit_BinOp(self, node: ast.BinOp) -> None:
        new_op = BINOP_SWAP.get(type(node.op))
        string_op = isinstance(node.op, (ast.Add, ast.Mod)) and (_is_str(node.left) or _is_str(node.right))
        if new_op is not None and not string_op:
            self.sites.append((node, "arith", ast.BinOp(left=node.left, op=new_op(), right=node.right)))
        if string_op and isinstance(node.op, ast.Mod):
            return  # "%" formatting: skip the arguments too
        self.generic_visit(node)

    def visit_AugAssign(self, node: ast.AugAssign) -> None:
        new_op = BINOP_SWAP.get(type(node.op))
        if new_op is not None and not _is_str(node.value):
            self.sites.append((node, "arith", ast.AugAssign(target=node.target, op=new_op(), value=node.value)))
        self.visit(node.value)

    def visit_Compare(self, node: ast.Compare) -> None:
        for i, op in enumerate(node.ops):
            new_op = CMPOP_SWAP.get(type(op))
            if new_op is not None:
                ops = list(node.ops)
                ops[i] = new_op()
                self.sites.append((node, "compare", ast.Compare(left=node.left, ops=ops, comparators=node.comparators)))
        self.generic_visit(node)

    def visit_BoolOp(self, node: ast.BoolOp) -> None:
        new_op: ast.boolop = ast.Or() if isinstance(node.op, ast.And) else ast.And()
        self.sites.append((node, "boolop", ast.BoolOp(op=new_op, values=node.values)))
        self.generic_visit(node)

    def visit_UnaryOp(self, node: ast.UnaryOp) -> None:
        if isinstance(node.op, ast.Not):
            self.sites.append((node, "not", node.operand))
        elif isinstance(node.op, ast.USub):
            self.sites.append((node, "neg", node.operand))
            if isinstance(node.operand, ast.Constant):
                return  # -1 -> 1 is the site; "-(1 + 1)" would only duplicate the constant one
        self.generic_visit(node)

    def visit_Constant(self, node: ast.Constant) -> None:
        value = node.value
        if isinstance(value, bool):
            self.sites.append((node, "bool", ast.Constant(value=not value)))
        elif isinstance(value, (int, float)) and not isinstance(value, bool):
            self.sites.append((node, "number", ast.Constant(value=value + 1)))

    def visit_Return(self, node: ast.Return) -> None:
        value = node.value
        returns = self._returns[-1] if self._returns else None
        returns_none = isinstance(returns, ast.Constant) and returns.value is None
        sensible = (value is not None and not (isinstance(value, ast.Constant) and value.value is None)
                    and not _is_str(value) and not returns_none and not self._in_dunder_str)
        if sensible:
            self.sites.append((node, "return", ast.Return(value=ast.Constant(value=None))))
        if value is not None:
            self.visit(value)


def _line_offsets(source: bytes) -> list[int]:
    offsets = [0]
    for line in source.splitlines(keepends=True):
        offsets.append(offsets[-1] + len(line))
    return offsets


def mutation_sites(source: str, path: str = "<module>") -> list[Mutant]:
    """Every mutant of ``source``, in source order (``path`` names the module in the result)."""
    tree = ast.parse(source)
    finder = _SiteFinder()
    finder.visit(tree)
    data = source.encode("utf-8")
    offsets = _line_offsets(data)
    mutants: list[Mutant] = []
    seen: set[tuple[int, int, str]] = set()
    for node, operator, new in finder.sites:
        assert node.end_lineno is not None and node.end_col_offset is not None
        start = offsets[node.lineno - 1] + node.col_offset  # type: ignore[attr-defined]
        end = offsets[node.end_lineno - 1] + node.end_col_offset
        original = data[start:end].decode("utf-8")
        if isinstance(new, ast.AST):
            text = ast.unparse(new)
            if isinstance(node, ast.expr):
                text = f"({text})"
        else:
            text = new
        key = (start, end, text)
        if key in seen:
            continue
        seen.add(key)
        mutants.append(Mutant(path=path, line=node.lineno, operator=operator,  # type: ignore[attr-defined]
                              start=start, end=end, replacement=text,
                              before=_short(original), after=_short(text)))
    mutants.sort(key=lambda m: (m.start, m.end, m.replacement))
    return mutants


def apply_mutant(source: str, mutant: Mutant) -> str:
    """``source`` with ``mutant`` applied; the result always parses."""
    data = source.encode("utf-8")
    mutated = (data[: mutant.start] + mutant.replacement.encode("utf-8") + data[mutant.end:]).decode("utf-8")
    ast.parse(mutated)
    return mutated


def is_valid(source: str, mutant: Mutant) -> bool:
    try:
        apply_mutant(source, mutant)
    except SyntaxError:
        return False
    return True


def sample_sites(mutants: list[Mutant], n: int, seed: int, path: str, source: str | None = None) -> list[Mutant]:
    """``n`` mutants chosen at random, repeatably for (seed, path); all of them when n >= len.

    With ``source``, a mutant whose result does not parse is passed over for the next one.
    """
    order = list(mutants)
    random.Random(f"{seed}:{path}").shuffle(order)
    chosen: list[Mutant] = []
    for m in order:
        if len(chosen) >= n:
            break
        if source is None or is_valid(source, m):
            chosen.append(m)
    return sorted(chosen, key=lambda m: (m.start, m.end))


# ---------------------------------------------------------------------------------------------
# Which tests exercise a module
# ---------------------------------------------------------------------------------------------

def module_name(path: str) -> str:
    return path[:-3].replace("/", ".").removesuffix(".__init__")


@functools.cache
def _imports_of(path: Path) -> frozenset[str]:
    """Dotted names a file imports (``from a.b import c`` gives a.b and a.b.c)."""
    try:
        tree = ast.parse(path.read_text(encoding="utf-8"))
    except (SyntaxError, UnicodeDecodeError):
        return frozenset()
    names: set[str] = set()
    package = ""
    if path.is_relative_to(REPO):
        package = module_name(str(path.relative_to(REPO)))
        if path.name != "__init__.py":
            package = package.rsplit(".", 1)[0]
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                parts = parts[: len(parts) - (node.level - 1)] if node.level > 1 else parts
                base = ".".join([*parts, base]) if base else ".".join(parts)
            names.add(base)
            names.update(f"{base}.{a.name}" for a in node.names)
    return frozenset(names)


def tests_for_module(path: str, test_files: Iterable[Path], package_files: Iterable[Path]) -> list[str]:
    """Test files that import ``path``'s module or a module that imports it."""
    target = module_name(path)
    tests = {t: _imports_of(t) for t in test_files}
    wanted = {target}
    parent = target.rsplit(".", 1)[0]
    if parent.count(".") >= 2:  # a module of a subpackage (qtanimator.formats.gltf.reader): its package too
        wanted.add(parent)
    # Also the tests of the modules that import it: a module split out of another (cloth_params
    # out of cloth) is mostly tested through the module that re-exports it.
    importers = {module_name(str(p.relative_to(REPO))) for p in package_files if target in _imports_of(p)}
    return sorted(str(t.relative_to(REPO)) for t, names in tests.items() if names & (wanted | importers))


def defined_names(path: Path) -> frozenset[str]:
    """The names ``path`` defines at module level and in its classes (functions, classes,
    constants, methods), private ones included."""
    try:
        tree = ast.parse(path.read_text(encoding="utf-8"))
    except (SyntaxError, UnicodeDecodeError, OSError):
        return frozenset()
    names: set[str] = set()
    bodies = [tree.body]
    while bodies:
        for node in bodies.pop():
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                names.add(node.name)
                if isinstance(node, ast.ClassDef):
                    bodies.append(node.body)
            elif isinstance(node, (ast.Assign, ast.AnnAssign)):
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                names.update(t.id for t in targets if isinstance(t, ast.Name))
    return frozenset(n for n in names if len(n.strip("_")) > 2 and not (n.startswith("__") and n.endswith("__")))


def reference_weight(names: Iterable[str], tests: list[str]) -> dict[str, float]:
    """How much of ``names`` each test file mentions, each name weighted by 1 / (the number of
    ``tests`` that mention it): a file that calls the rare function a mutant sits in ranks above
    one that only mentions the module's common types."""
    words = {t: frozenset(_WORD.findall((REPO / t).read_text(encoding="utf-8", errors="replace"))) for t in tests}
    weight = dict.fromkeys(tests, 0.0)
    for name in names:
        holders = [t for t in tests if name in words[t]]
        for t in holders:
            weight[t] += 1.0 / len(holders)
    return weight


_WORD = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def own_tier(path: str, test: str) -> int:
    """0: ``test`` is named after the module (test_<module>*.py); 1: after the first word of
    its name; 2: after its package; 3: none of these."""
    p = Path(path)
    stem = p.parent.name if p.name == "__init__.py" else p.stem.lstrip("_")
    name = Path(test).stem
    return 0 if stem in name else 1 if stem.split("_")[0] in name else 2 if p.parent.name in name else 3


def is_own(path: str, test: str) -> bool:
    """``test`` is the module's own file: ``test_<module>.py`` or ``test_<module>_mutants.py``."""
    p = Path(path)
    stem = p.parent.name if p.name == "__init__.py" else p.stem.lstrip("_")
    return Path(test).stem in (f"test_{stem}", f"test_{stem}_mutants")


def rank_tests(path: str, tests: list[str]) -> list[str]:
    """``tests`` in the order to try them for ``path``: files named after the module (or its
    package, for ``pkg/__init__.py`` and the modules of a subpackage) first; then, within each
    of those tiers, the files that mention more of the module's own names (weighted by how few
    files mention each, :func:`reference_weight`), then those of the same area (tests/core for
    qtanimator/core), smaller files first."""
    p = Path(path)
    area = p.parts[1] if len(p.parts) > 2 else ""
    weight = reference_weight(defined_names(REPO / path), tests)

    def key(t: str) -> tuple[int, float, int, int]:
        return (min(own_tier(path, t), 2), -round(weight[t], 3), 0 if area in Path(t).parts else 1,
                (REPO / t).stat().st_size)

    return sorted(tests, key=key)


# ---------------------------------------------------------------------------------------------
# Running
# ---------------------------------------------------------------------------------------------

def make_copy(dest: Path) -> None:
    """A copy of the repository at ``dest`` without the excluded folders."""
    if dest.exists():
        shutil.rmtree(dest)
    shutil.copytree(REPO, dest, symlinks=True, ignore=lambda _d, names: [n for n in names if n in EXCLUDE])
    # The tests find the sample data as ../shared beside the repository: without it every test
    # that needs the data skips and its mutants look like survivors.
    beside = dest.parent / "shared"
    if SHARED.exists() and not (beside.is_symlink() or beside.exists()):
        beside.symlink_to(SHARED)


#: ``--numba python``: numba on but its JIT disabled, so the kernels' own Python source runs (the
#: only way to mutate qtanimator/core/cloth_kernels.py meaningfully: with QTANIMATOR_NO_NUMBA=1
#: the numpy paths elsewhere run instead and the kernels are never called).
NUMBA_MODE = "off"


def _env(copy: Path) -> dict[str, str]:
    env = dict(os.environ)
    env.pop("CI", None)
    env.update(QTANIMATOR_TEST_NO_XVFB="1", PYTHONDONTWRITEBYTECODE="1",
               PYTHONPATH=str(copy), PYTHONHASHSEED="0", HYPOTHESIS_PROFILE="default")
    if NUMBA_MODE == "python":
        env.pop("QTANIMATOR_NO_NUMBA", None)
        env["NUMBA_DISABLE_JIT"] = "1"
    else:
        env["QTANIMATOR_NO_NUMBA"] = "1"
    return env


def run_tests(copy: Path, tests: list[str], timeout: float,
              trace: tuple[Path, Path] | None = None) -> tuple[str, float, str]:
    """Run ``tests`` (files or node ids) in ``copy``: (outcome, seconds, output tail); outcome
    passed/failed/timeout/error, or ``notfound`` when pytest could not find a node id or
    collected nothing. ``trace`` = (module file, JSON out): record which tests run which of
    the module's lines (tools/mutation_trace.py)."""
    cmd = ["nice", "-n", "19", sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider",
           "-m", "not slow", "-o", "timeout=0", *tests]
    env = _env(copy)
    if trace is not None:
        cmd[cmd.index("-x")] = "-p"
        cmd.insert(cmd.index("-p") + 1, "mutation_trace")
        env.update(PYTHONPATH=f"{copy}{os.pathsep}{copy / 'tools'}", MUTATION_TRACE_FILE=str(trace[0]),
                   MUTATION_TRACE_OUT=str(trace[1]))
    start = time.monotonic()
    proc = subprocess.Popen(cmd, cwd=copy, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            start_new_session=True, text=True)
    try:
        out, _ = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, _ = proc.communicate()
        return "timeout", time.monotonic() - start, out[-2000:]
    seconds = time.monotonic() - start
    if proc.returncode == 0:
        return "passed", seconds, out[-2000:]
    if proc.returncode in (4, 5):  # usage error (a node id not found) / nothing collected
        return "notfound", seconds, out[-2000:]
    if proc.returncode == 2 or "error during collection" in out or "errors during collection" in out:
        return "error", seconds, out[-2000:]
    return "failed", seconds, out[-2000:]


@dataclasses.dataclass
class ModulePlan:
    path: str
    sites: int
    mutants: list[Mutant]
    tests: list[str]
    source: str = ""
    baseline_s: float = 0.0
    timeout_s: float = 0.0
    skipped: str = ""
    #: ``--select lines``: the test node ids in the order they ran, the lines each ran, and
    #: the lines run outside any test (import, collection).
    order: list[str] = dataclasses.field(default_factory=list)
    lines: dict[str, frozenset[int]] = dataclasses.field(default_factory=dict)
    outside: frozenset[int] = frozenset()

    def tests_for(self, mutant: Mutant) -> list[str] | None:
        """The tests to run for ``mutant``: the node ids that ran one of its lines ([] when
        none did), or None for the whole files (no line map, or a line run at import)."""
        if not self.order:
            return None
        first = mutant.line
        last = first + self.source.encode("utf-8")[mutant.start:mutant.end].count(b"\n")
        span = set(range(first, last + 1))
        if span & self.outside:
            return None
        return [t for t in self.order if span & self.lines.get(t, frozenset())]


@dataclasses.dataclass
class Result:
    mutant: Mutant
    outcome: str   # killed / survived / timeout / error
    seconds: float
    tests: int = -1  # node ids run (--select lines); -1: the whole files


def wilson(k: int, n: int, z: float = 1.96) -> tuple[float, float]:
    """95 % Wilson score interval for k successes out of n."""
    if n == 0:
        return (0.0, 1.0)
    p = k / n
    denom = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denom
    return (max(0.0, centre - half), min(1.0, centre + half))


def report(plans: list[ModulePlan], results: list[Result], args: argparse.Namespace, status: str,
           started: float) -> str:
    by_module: dict[str, list[Result]] = {}
    for r in results:
        by_module.setdefault(r.mutant.path, []).append(r)
    lines = [
        "Mutation testing (sampled) -- tools/mutation.py",
        f"date: {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}   status: {status}   "
        f"wall: {(time.monotonic() - started) / 60:.1f} min",
        f"command: python tools/mutation.py {' '.join(args.argv)}",
        f"modules: {', '.join(args.modules)}   "
        + (f"rerun of the survivors of {args.rerun}   " if args.rerun else
           f"per-module: {args.per_module}   seed: {args.seed}   ")
        + f"jobs: {args.jobs}   numba: {args.numba}   select: {args.select}   tree: {args.tree}",
        "killed = the module's tests fail; timeout and import/collection error also count as killed.",
        "",
        f"{'module':44} {'sites':>5} {'run':>4} {'killed':>6} {'surv':>4} {'tmo':>3} {'err':>3} {'score':>6}"
        f" {'base_s':>6}  tests",
    ]
    total_k = total_n = 0
    strata: list[tuple[int, int, int]] = []  # (sites, killed, run)
    for plan in plans:
        rs = by_module.get(plan.path, [])
        k = sum(r.outcome != "survived" for r in rs)
        s = sum(r.outcome == "survived" for r in rs)
        t = sum(r.outcome == "timeout" for r in rs)
        e = sum(r.outcome == "error" for r in rs)
        score = f"{100 * k / len(rs):5.1f}%" if rs else "    -"
        tests = plan.skipped or " ".join(Path(x).name for x in plan.tests)
        lines.append(f"{plan.path:44} {plan.sites:5} {len(rs):4} {k:6} {s:4} {t:3} {e:3} {score:>6}"
                     f" {plan.baseline_s:6.1f}  {tests}")
        total_k += k
        total_n += len(rs)
        if rs:
            strata.append((plan.sites, k, len(rs)))
    lines.append("")
    lo, hi = wilson(total_k, total_n)
    if total_n:
        lines.append(f"pooled score: {total_k}/{total_n} killed = {100 * total_k / total_n:.1f}% "
                     f"(95% Wilson interval {100 * lo:.1f}-{100 * hi:.1f}%)")
        weight = sum(w for w, _, _ in strata)
        est = sum(w * k / n for w, k, n in strata) / weight
        var = sum((w / weight) ** 2 * (k / n) * (1 - k / n) / n * ((w - n) / max(w - 1, 1))
                  for w, k, n in strata)
        half = 1.96 * math.sqrt(var)
        lines.append(f"site-weighted estimate (each module weighted by its number of sites, "
                     f"{weight} sites in all): {100 * est:.1f}% (+/- {100 * half:.1f}, normal approx.)")
        outcomes = {o: sum(r.outcome == o for r in results) for o in ("killed", "timeout", "error", "survived")}
        lines.append("outcomes: " + ", ".join(f"{o} {c}" for o, c in outcomes.items()))
        ops: dict[str, list[int]] = {}
        for r in results:
            ops.setdefault(r.mutant.operator, [0, 0])
            ops[r.mutant.operator][0] += r.outcome != "survived"
            ops[r.mutant.operator][1] += 1
        lines.append("by operator: " + ", ".join(f"{o} {k}/{n}" for o, (k, n) in sorted(ops.items())))
        secs = [r.seconds for r in results]
        lines.append(f"seconds per mutant: mean {sum(secs) / len(secs):.1f}, max {max(secs):.1f}")
    lines += ["", "Survivors (the tests still pass with this change):"]
    for r in sorted(results, key=lambda r: (r.mutant.path, r.mutant.start)):
        if r.outcome == "survived":
            lines.append("  " + r.mutant.describe() + ("   (no test runs this line)" if r.tests == 0 else ""))
    if getattr(args, "gone", None):
        lines += ["", "Survivors of the earlier run whose code is gone (not run, not counted):"]
        lines += [f"  {g}" for g in args.gone]
    lines += ["", "Timeouts and import errors (counted as killed):"]
    for r in sorted(results, key=lambda r: (r.mutant.path, r.mutant.start)):
        if r.outcome in ("timeout", "error"):
            lines.append(f"  {r.outcome:7} " + r.mutant.describe())
    return "\n".join(lines) + "\n"


def line_map(commit: str, path: str, source: str) -> dict[int, int]:
    """Old line number -> line number in ``source`` for the lines of ``path`` at ``commit``
    that are unchanged (git's copy of the file; every line maps to itself without one)."""
    old = subprocess.run(["git", "-C", str(REPO), "show", f"{commit}:{path}"], capture_output=True, text=True)
    new_lines = source.splitlines()
    if not commit or old.returncode != 0:
        return {i: i for i in range(1, len(new_lines) + 1)}
    matcher = difflib.SequenceMatcher(None, old.stdout.splitlines(), new_lines, autojunk=False)
    mapping: dict[int, int] = {}
    for a, b, size in matcher.get_matching_blocks():
        for k in range(size):
            mapping[a + k + 1] = b + k + 1
    return mapping


def module_files(roots: list[str]) -> list[str]:
    files: list[str] = []
    for root in roots:
        p = REPO / root
        if p.is_file():
            files.append(str(p.relative_to(REPO)))
        else:
            files += sorted(str(f.relative_to(REPO)) for f in p.rglob("*.py") if "__pycache__" not in f.parts)
    return files


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--modules", nargs="+", default=["qtanimator/core"], help="package folders or files")
    parser.add_argument("--per-module", type=int, default=10, help="mutants sampled per module")
    parser.add_argument("--seed", type=int, default=17)
    parser.add_argument("--jobs", type=int, default=1)
    parser.add_argument("--timeout", type=float, default=None, help="seconds per mutant (default 3x baseline + 5)")
    parser.add_argument("--max-file-seconds", type=float, default=20.0,
                        help="leave out test files slower than this in the baseline")
    parser.add_argument("--max-test-files", type=int, default=10, help="at most this many test files per module")
    parser.add_argument("--budget-minutes", type=float, default=None, help="stop starting mutants after this")
    parser.add_argument("--out", default=None, help="report file (default: print)")
    parser.add_argument("--work", default=str(WORK), help="folder for the private copies of the repository")
    parser.add_argument("--numba", choices=["off", "python"], default="off",
                        help="off: QTANIMATOR_NO_NUMBA=1 (numpy); python: NUMBA_DISABLE_JIT=1 (kernels in Python)")
    parser.add_argument("--list", action="store_true", help="only list the sampled mutants")
    parser.add_argument("--rerun", default=None, metavar="REPORT.json",
                        help="instead of sampling, run again the survivors of an earlier run's JSON report "
                             "(same modules, sources unchanged since; e.g. after writing tests for them)")
    parser.add_argument("--select", choices=["lines", "files"], default="files",
                        help="files: the module's whole test files for every mutant; lines: only the tests "
                             "that ran the mutated lines in a traced baseline (the trace makes the baseline "
                             "of numpy-heavy tests, such as the cloth's, several times slower)")
    args = parser.parse_args(argv)
    args.argv = sys.argv[1:] if argv is None else argv
    global NUMBA_MODE
    NUMBA_MODE = args.numba
    started = time.monotonic()
    head = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    dirty = subprocess.run(["git", "-C", str(REPO), "status", "--porcelain", "--", *args.modules],
                           capture_output=True, text=True)
    args.tree = f"HEAD {head.stdout.strip() or '?'}" + (" + uncommitted changes" if dirty.stdout.strip() else "")

    files = module_files(args.modules)
    rerun: dict[str, list[dict[str, object]]] = {}
    rerun_tree = ""
    args.gone = []
    if args.rerun:
        for entry in json.loads(Path(args.rerun).read_text(encoding="utf-8")):
            if entry["outcome"] == "survived":
                rerun.setdefault(entry["path"], []).append(entry)
        files = [f for f in files if f in rerun]
        txt = Path(args.rerun).with_suffix(".txt")  # its header names the tree it ran on
        header = txt.read_text(encoding="utf-8") if txt.exists() else ""
        tree = next((ln.split("tree: HEAD ")[1].split()[0] for ln in header.splitlines() if "tree: HEAD " in ln), "")
        rerun_tree = tree
    test_files = [t for t in sorted((REPO / "tests").rglob("test_*.py"))
                  if not str(t.relative_to(REPO)).startswith(SLOW_TEST_DIRS)]
    package_files = sorted(p for p in (REPO / "qtanimator").rglob("*.py") if "__pycache__" not in p.parts)
    plans: list[ModulePlan] = []
    for path in files:
        source = (REPO / path).read_text(encoding="utf-8")
        sites = mutation_sites(source, path)
        if args.rerun:
            chosen = []
            moved = line_map(rerun_tree, path, source)
            for entry in rerun.get(path, []):
                # The same change of the same text on the line the old one became (the source may
                # have moved since that run); a survivor whose line is gone is reported, not run.
                line = moved.get(int(str(entry["line"])))
                same = [m for m in sites if (m.line, m.operator, m.before, m.replacement) ==
                        (line, entry["operator"], entry["before"], entry["replacement"]) and m not in chosen]
                if same:
                    chosen.append(same[0])
                else:
                    args.gone.append(f"{path}:{entry['line']}  [{entry['operator']}]  {entry['before']}  ->  "
                                     f"{entry['after']}")
            chosen.sort(key=lambda m: (m.start, m.end))
        else:
            chosen = sample_sites(sites, args.per_module, args.seed, path, source)
        plans.append(ModulePlan(path=path, sites=len(sites), source=source, mutants=chosen,
                                tests=tests_for_module(path, test_files, package_files)))
    if args.list:
        for plan in plans:
            print(f"# {plan.path}: {plan.sites} sites, tests: {' '.join(plan.tests)}")
            for m in plan.mutants:
                print("  " + m.describe())
        for g in args.gone:
            print(f"# gone: {g}")
        return 0

    if SHARED.exists() and not (SHARED_LINK.is_symlink() or SHARED_LINK.exists()):
        SHARED_LINK.symlink_to(SHARED)
    work_dir = Path(args.work)
    work_dir.mkdir(parents=True, exist_ok=True)
    copies = [work_dir / f"repo-{i}" for i in range(max(1, args.jobs))]
    for copy in copies:
        make_copy(copy)
        for plan in plans:  # the sources the sites were computed from, even if the tree moved on
            (copy / plan.path).write_text(plan.source, encoding="utf-8")
    print(f"copied the repository to {', '.join(map(str, copies))}", flush=True)

    # Baseline: each candidate test file alone (cached), then the module's chosen set.
    file_times: dict[str, tuple[str, float]] = {}
    for plan in plans:
        if not plan.mutants:
            plan.skipped = "(no mutation sites)"
            continue
        # The module's own test files first (test_<module>*.py), then the same area, smaller
        # files first; baseline them one by one (cached) until --max-test-files fast, passing
        # ones are found.
        candidates = rank_tests(plan.path, plan.tests)
        usable: list[str] = []
        for t in candidates:
            if len(usable) >= args.max_test_files:
                break
            if t not in file_times:
                limit = 600 if is_own(plan.path, t) else args.max_file_seconds + 10
                outcome, secs, _ = run_tests(copies[0], [t], timeout=limit)
                file_times[t] = (outcome, secs)
                print(f"baseline {t}: {outcome} {secs:.1f}s", flush=True)
            own = is_own(plan.path, t)  # test_<module>.py / test_<module>_mutants.py: kept however slow
            if file_times[t][0] == "passed" and (own or file_times[t][1] <= args.max_file_seconds):
                usable.append(t)
        plan.tests = usable
        if not plan.tests:
            plan.skipped = "(no fast passing tests import it)"
            plan.mutants = []
            continue
        # The baseline (with --select lines, traced: which tests run which of the module's lines).
        trace_out = work_dir / f"trace-{plan.path.replace('/', '.')}.json"
        trace_out.unlink(missing_ok=True)
        trace = (copies[0] / plan.path, trace_out) if args.select == "lines" else None
        outcome, secs, out = run_tests(copies[0], plan.tests, timeout=600, trace=trace)
        if outcome != "passed":
            plan.skipped = f"(baseline {outcome})"
            plan.mutants = []
            print(f"baseline of {plan.path} {outcome}:\n{out}", flush=True)
            continue
        if trace is not None:
            data = json.loads(trace_out.read_text(encoding="utf-8"))
            plan.lines = {k: frozenset(v) for k, v in data["lines"].items() if k}
            plan.outside = frozenset(data["lines"].get("", []))
            plan.order = list(dict.fromkeys(data["order"]))
        plan.baseline_s = secs
        plan.timeout_s = args.timeout if args.timeout else 3 * secs + 5
        print(f"baseline {plan.path}: {secs:.1f}s with {len(plan.tests)} files, "
              f"{len(plan.mutants)} mutants of {plan.sites}", flush=True)

    # Mutants in a seeded random order across modules, so a run stopped early is still a sample.
    work = [(plan, m) for plan in plans for m in plan.mutants]
    random.Random(args.seed).shuffle(work)
    results: list[Result] = []
    free = list(copies)
    status = "running"

    def write() -> None:
        text = report(plans, results, args, status, started)
        if args.out:
            Path(args.out).parent.mkdir(parents=True, exist_ok=True)
            Path(args.out).write_text(text, encoding="utf-8")

    def one(copy: Path, plan: ModulePlan, mutant: Mutant) -> Result:
        selected = plan.tests_for(mutant)
        if selected == []:  # no test runs its lines: it survives without a run
            return Result(mutant, "survived", 0.0, tests=0)
        tests = plan.tests if selected is None else selected
        target = copy / mutant.path
        original = plan.source
        target.write_text(apply_mutant(original, mutant), encoding="utf-8")
        try:
            outcome, secs, _ = run_tests(copy, tests, plan.timeout_s)
            if outcome == "notfound" and selected is not None:  # a node id pytest cannot take back
                tests, selected = plan.tests, None
                outcome, secs, _ = run_tests(copy, tests, plan.timeout_s)
            if outcome == "timeout":  # once more with twice the time: the machine may just be busy
                outcome, secs, _ = run_tests(copy, tests, 2 * plan.timeout_s)
        finally:
            target.write_text(original, encoding="utf-8")
        verdict = {"passed": "survived", "failed": "killed", "notfound": "error"}.get(outcome, outcome)
        return Result(mutant, verdict, secs, tests=-1 if selected is None else len(selected))

    pending: dict[Future[Result], Path] = {}
    with ThreadPoolExecutor(max_workers=len(copies)) as pool:
        queue: Iterator[tuple[ModulePlan, Mutant]] = iter(work)
        try:
            while True:
                over = args.budget_minutes is not None and time.monotonic() - started > args.budget_minutes * 60
                while free and not over:
                    item = next(queue, None)
                    if item is None:
                        break
                    copy = free.pop()
                    pending[pool.submit(one, copy, *item)] = copy
                if not pending:
                    break
                done, _ = wait(pending, return_when=FIRST_COMPLETED)
                for fut in done:
                    free.append(pending.pop(fut))
                    r = fut.result()
                    results.append(r)
                    ran = "files" if r.tests < 0 else f"{r.tests} tests"
                    print(f"[{len(results)}/{len(work)}] {r.outcome:8} {r.seconds:5.1f}s {ran:>9} "
                          f"{r.mutant.describe()}", flush=True)
                write()
        except KeyboardInterrupt:
            status = "interrupted"
            for fut in pending:
                fut.cancel()
    if status == "running":
        done_all = len(results) == len(work)
        status = "complete" if done_all else f"stopped by the budget after {len(results)} of {len(work)}"
    write()
    print(report(plans, results, args, status, started))
    if args.out:
        (Path(args.out).with_suffix(".json")).write_text(json.dumps(
            [dict(dataclasses.asdict(r.mutant), outcome=r.outcome, seconds=round(r.seconds, 2)) for r in results],
            indent=1), encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
