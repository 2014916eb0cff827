"""Issue 30: the sample data helper of ``tests/needs.py`` and ``tests/conftest.py``.

A tiny test file is run by pytest in a subprocess, with this suite's conftest as a plugin and
``QTANIMATOR_SHARED_DATA`` naming a folder: when the folder is missing its tests skip outside CI
(exit 0) and fail in CI (``CI=true``), and the run ends with one line that says how many and
why; when the folder is there they read from it.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

TESTS = Path(__file__).resolve().parent
REPO = TESTS.parent

TINY = '''
import pytest
from needs import shared_data_dir, shared_data_params, shared_data_path


def test_fixture(shared_data):
    assert (shared_data / "x.txt").read_text() == "x"


def test_path():
    assert shared_data_path("x.txt").read_text() == "x"


@pytest.mark.parametrize("path", shared_data_params(sorted(shared_data_dir().glob("*.txt")), None))
def test_params(path):
    shared_data_path()
    assert path.read_text() == "x"


def test_without_sample_data():
    pass
'''


def _run(tmp_path: Path, data: Path, *, ci: bool) -> subprocess.CompletedProcess[str]:
    (tmp_path / "test_tiny.py").write_text(TINY)
    (tmp_path / "pytest.ini").write_text("[pytest]\n")
    env = {k: v for k, v in os.environ.items() if k not in ("CI", "PYTEST_ADDOPTS", "PYTEST_PLUGINS")}
    env.update(QTANIMATOR_SHARED_DATA=str(data), QTANIMATOR_TEST_NO_XVFB="1",
               PYTHONPATH=os.pathsep.join([str(TESTS), str(REPO)]))
    if ci:
        env["CI"] = "true"
    return subprocess.run([sys.executable, "-m", "pytest", "-p", "conftest", "-p", "no:cacheprovider",
                           "-c", str(tmp_path / "pytest.ini"), "--rootdir", str(tmp_path), "-q",
                           str(tmp_path / "test_tiny.py")],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=240, check=False)


def _last_lines(out: str) -> list[str]:
    return [line for line in out.splitlines() if line.strip()][-2:]


@pytest.mark.parametrize("ci", [False, True], ids=["developer", "ci"])
def test_missing_sample_data_skips_outside_ci_and_fails_in_ci(tmp_path: Path, ci: bool) -> None:
    data = tmp_path / "no-such-data"
    done = _run(tmp_path, data, ci=ci)
    out = done.stdout + done.stderr
    reason = f"sample data not found at {data.resolve()} (QTANIMATOR_SHARED_DATA names a folder that does not exist)"
    if ci:
        assert done.returncode == 1, out
        line, counts = _last_lines(done.stdout)
        assert line == f"qtanimator: 3 tests failed: {reason}", out
        assert "1 passed" in counts and "skipped" not in counts, out
    else:
        assert done.returncode == 0, out
        line, counts = _last_lines(done.stdout)
        assert line == f"qtanimator: 3 tests skipped: {reason}", out
        assert "1 passed, 3 skipped" in counts, out
    assert out.count("qtanimator:") == 1, out


def test_the_variable_names_the_sample_data(tmp_path: Path) -> None:
    data = tmp_path / "data"
    data.mkdir()
    (data / "x.txt").write_text("x")
    done = _run(tmp_path, data, ci=True)
    out = done.stdout + done.stderr
    assert done.returncode == 0, out
    assert "4 passed" in _last_lines(done.stdout)[-1] and "qtanimator:" not in out, out
