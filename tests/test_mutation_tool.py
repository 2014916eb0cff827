"""tools/mutation.py: the mutation sites it finds on a tiny module (not a mutation run)."""

from __future__ import annotations

import ast
import importlib.util
import sys
import textwrap
from pathlib import Path

import pytest

TOOL = Path(__file__).resolve().parents[1] / "tools" / "mutation.py"


@pytest.fixture(scope="module")
def mutation():  # type: ignore[no-untyped-def]
    spec = importlib.util.spec_from_file_location("qtanimator_mutation_tool", TOOL)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    yield module
    sys.modules.pop(spec.name, None)


def _mutants(mutation, tmp_path: Path, code: str) -> list[tuple[str, str]]:  # type: ignore[no-untyped-def]
    source = textwrap.dedent(code)
    path = tmp_path / "tiny.py"
    path.write_text(source, encoding="utf-8")
    found = mutation.mutation_sites(path.read_text(encoding="utf-8"), "tiny.py")
    for m in found:  # every mutant applies and parses
        ast.parse(mutation.apply_mutant(source, m))
    return [(m.before, m.after) for m in found]


def test_arithmetic_swap(mutation, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    assert _mutants(mutation, tmp_path, "def f(a, b):\n    x = a + b\n") == [("a + b", "(a - b)")]
    source = "def f(a, b):\n    x = a + b\n"
    (m,) = mutation.mutation_sites(source, "tiny.py")
    assert mutation.apply_mutant(source, m) == "def f(a, b):\n    x = (a - b)\n"


def test_precedence_is_kept(mutation, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    got = _mutants(mutation, tmp_path, "def f(a, b, c):\n    y = (a + b) * c\n")
    assert got == [("(a + b) * c", "((a + b) / c)"), ("a + b", "(a - b)")]


def test_docstrings_strings_annotations_and_all_yield_nothing(mutation, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    code = '''
        """Module docstring 1 + 2."""
        from typing import TYPE_CHECKING
        __all__ = ["f"]
        if TYPE_CHECKING:
            X = 1 + 2
        def f(a: int = 0) -> "list[int]":
            """Docstring with a < b."""
            s = "a" + "b"
            t = f"{a + 1}"
            u = "%d" % (a - 1)
            log.debug("x %s", a + 1)
            raise ValueError(a + 1)
    '''
    assert _mutants(mutation, tmp_path, code) == [("0", "(1)")]  # the default value only


def test_each_operator(mutation, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    code = """
        def f(a, b):
            if a < b and not a:
                return -a
            return a == b, True
    """
    assert set(_mutants(mutation, tmp_path, code)) == {
        ("a < b", "(a <= b)"),
        ("a < b and not a", "(a < b or not a)"),
        ("not a", "(a)"),
        ("-a", "(a)"),
        ("return -a", "return None"),
        ("a == b", "(a != b)"),
        ("True", "(False)"),
        ("return a == b, True", "return None"),
    }


def test_numbers_and_augmented_assignment(mutation, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    code = """
        def f(x) -> None:
            x += 2.5
            return
    """
    assert set(_mutants(mutation, tmp_path, code)) == {("x += 2.5", "x -= 2.5"), ("2.5", "(3.5)")}


def test_sampling_is_repeatable(mutation) -> None:  # type: ignore[no-untyped-def]
    source = "def f(a):\n" + "".join(f"    a = a + {i}\n" for i in range(30))
    sites = mutation.mutation_sites(source, "m.py")
    first = mutation.sample_sites(sites, 5, 17, "m.py", source)
    assert first == mutation.sample_sites(sites, 5, 17, "m.py", source)
    assert len(first) == 5 and first != mutation.sample_sites(sites, 5, 18, "m.py", source)
    assert mutation.sample_sites(sites, 1000, 17, "m.py") == sites


def test_wilson_interval(mutation) -> None:  # type: ignore[no-untyped-def]
    lo, hi = mutation.wilson(90, 100)
    assert 0.82 < lo < 0.84 and 0.94 < hi < 0.95


def test_overload_stubs_are_not_mutated(mutation) -> None:  # type: ignore[no-untyped-def]
    src = (
        "from typing import overload\n"
        "class C:\n"
        "    @overload\n"
        "    def f(self, x: int = 0) -> int: ...\n"
        "    @overload\n"
        "    def f(self, x: str = '') -> str: ...\n"
        "    def f(self, x=1):\n"
        "        return x\n"
    )
    sites = mutation.mutation_sites(src)
    # Only the real body's default (1 -> 2) and its return are sites; the stubs' defaults are not.
    assert sorted(m.line for m in sites) == [7, 8]


def test_rank_puts_the_file_that_calls_a_rare_name_first(mutation, tmp_path: Path, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    monkeypatch.setattr(mutation, "REPO", tmp_path)
    (tmp_path / "pkg").mkdir()
    (tmp_path / "tests").mkdir()
    (tmp_path / "pkg" / "things.py").write_text("class Common: ...\ndef rare_rule(): ...\n")
    (tmp_path / "tests" / "test_a.py").write_text("from pkg.things import Common\nCommon()\n" + "#" * 10)
    (tmp_path / "tests" / "test_b.py").write_text("from pkg.things import Common, rare_rule\n" + "#" * 500)
    (tmp_path / "tests" / "test_c.py").write_text("from pkg.things import Common\n")
    order = mutation.rank_tests("pkg/things.py", ["tests/test_a.py", "tests/test_b.py", "tests/test_c.py"])
    # test_b is the largest file but the only one naming rare_rule; then smallest first.
    assert order == ["tests/test_b.py", "tests/test_c.py", "tests/test_a.py"]


def test_line_trace_maps_each_test_to_the_lines_it_runs(tmp_path: Path) -> None:
    """tools/mutation_trace.py: a pytest run over two tests of a tiny module records, per
    test, the module's lines it ran, and apart the lines run at import."""
    import json
    import os
    import subprocess

    (tmp_path / "tiny.py").write_text(textwrap.dedent("""\
        LIMIT = 3

        def small(x):
            return x + 1

        def big(x):
            if x > LIMIT:
                return x * 2
            return x
        """), encoding="utf-8")
    (tmp_path / "test_tiny.py").write_text(textwrap.dedent("""\
        import tiny

        def test_small():
            assert tiny.small(1) == 2

        def test_big():
            assert tiny.big(5) == 10
        """), encoding="utf-8")
    (tmp_path / "pytest.ini").write_text("[pytest]\n", encoding="utf-8")
    out = tmp_path / "trace.json"
    env = dict(os.environ, PYTHONPATH=f"{tmp_path}{os.pathsep}{TOOL.parent}",
               MUTATION_TRACE_FILE=str(tmp_path / "tiny.py"), MUTATION_TRACE_OUT=str(out))
    proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p", "mutation_trace",
                           "test_tiny.py"], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    data = json.loads(out.read_text(encoding="utf-8"))
    assert data["order"] == ["test_tiny.py::test_small", "test_tiny.py::test_big"]
    assert set(data["lines"]["test_tiny.py::test_small"]) == {3, 4}
    assert set(data["lines"]["test_tiny.py::test_big"]) == {6, 7, 8}  # not 9: x > LIMIT
    assert {1, 3, 6} <= set(data["lines"][""])  # import: the constant and the two defs


def test_a_mutant_runs_only_the_tests_that_ran_its_lines(mutation) -> None:  # type: ignore[no-untyped-def]
    source = "LIMIT = 3\n\ndef big(x):\n    if x > LIMIT:\n        return (x\n                * 2)\n    return x\n"
    (mult, *_) = [m for m in mutation.mutation_sites(source, "tiny.py") if m.operator == "arith"]
    number = [m for m in mutation.mutation_sites(source, "tiny.py") if m.before == "3"][0]
    plan = mutation.ModulePlan(path="tiny.py", sites=0, mutants=[], tests=["t.py"], source=source,
                               order=["t.py::a", "t.py::b"],
                               lines={"t.py::a": frozenset({3, 4, 7}), "t.py::b": frozenset({3, 4, 6})},
                               outside=frozenset({1, 3}))
    assert plan.tests_for(mult) == ["t.py::b"]  # the product spans lines 5-6; b ran line 6
    assert plan.tests_for(number) is None  # LIMIT = 3 runs at import: the whole files
    plan.lines = {"t.py::a": frozenset({3, 4, 7}), "t.py::b": frozenset({3, 4, 7})}
    assert plan.tests_for(mult) == []  # nobody runs it: it survives unrun


def test_rerun_lists_only_the_survivors_of_a_report(mutation, tmp_path: Path, monkeypatch, capsys) -> None:  # type: ignore[no-untyped-def]
    import json

    monkeypatch.setattr(mutation, "REPO", tmp_path)
    (tmp_path / "pkg").mkdir()
    (tmp_path / "tests").mkdir()
    (tmp_path / "qtanimator").mkdir()
    source = "def f(a, b):\n    return a + b * 2\n"
    (tmp_path / "pkg" / "m.py").write_text(source, encoding="utf-8")
    sites = mutation.mutation_sites(source, "pkg/m.py")
    plus, times = [m for m in sites if m.before == "a + b * 2"][0], [m for m in sites if m.before == "b * 2"][0]
    report = [dict(vars(plus), outcome="survived", seconds=1.0), dict(vars(times), outcome="killed", seconds=1.0)]
    (tmp_path / "r.json").write_text(json.dumps(report), encoding="utf-8")
    mutation.main(["--modules", "pkg/m.py", "--rerun", str(tmp_path / "r.json"), "--list"])
    listed = [line.strip() for line in capsys.readouterr().out.splitlines() if line.startswith("  ")]
    assert listed == [plus.describe()]
