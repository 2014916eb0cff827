"""The Khronos glTF validator for tests: ``validate(path)`` gives the file's errors and warnings.

The validator is the npm package ``gltf-validator`` pinned in ``tools/gltf-validator/package.json``
(``./dev.sh test`` installs it there with npm), run by node through
``tools/gltf-validator/validate.mjs``. Where node or the package is missing, a test that
validates is skipped with the reason, except in CI (``CI=true``), where it fails: every export
must be validated there.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

from needs import missing

TOOL = Path(__file__).resolve().parents[1] / "tools" / "gltf-validator"
SCRIPT = TOOL / "validate.mjs"
PACKAGE = TOOL / "node_modules" / "gltf-validator"

__all__ = ["Issue", "Report", "issues", "validate"]


@dataclass(frozen=True)
class Issue:
    code: str
    message: str
    severity: int  # 0 error, 1 warning, 2 info, 3 hint
    pointer: str | None

    def __str__(self) -> str:
        return f"{self.code} at {self.pointer or '/'}: {self.message}"


@dataclass(frozen=True)
class Report:
    """What the validator said about one file."""

    file: str
    errors: list[Issue]
    warnings: list[Issue]
    infos: list[Issue]
    version: str


def _missing() -> str | None:
    """Why the validator cannot run here, or None."""
    node = shutil.which("node")
    if node is None:
        return "node is not installed (apt-get install nodejs npm)"
    if not PACKAGE.is_dir():
        return f"the gltf-validator npm package is not installed (npm ci --prefix {TOOL})"
    return None


def _unavailable(reason: str) -> None:
    missing(f"Khronos glTF validator unavailable: {reason}; every glTF export must be validated")


def validate(path: str | os.PathLike[str]) -> Report:
    """Run the Khronos validator on a ``.glb`` / ``.gltf``; skip (fail in CI) without it."""
    reason = _missing()
    if reason is not None:
        _unavailable(reason)
    node = shutil.which("node")
    assert node is not None
    done = subprocess.run([node, str(SCRIPT), os.fspath(path)], capture_output=True, text=True, timeout=120,
                          check=False)
    if done.returncode != 0:
        raise RuntimeError(f"the glTF validator failed on {path}: {done.stderr.strip() or done.stdout.strip()}")
    report = json.loads(done.stdout)
    (found,) = report["files"]
    by_severity: dict[int, list[Issue]] = {0: [], 1: [], 2: [], 3: []}
    for m in found["messages"]:
        by_severity.setdefault(m["severity"], []).append(Issue(m["code"], m["message"], m["severity"], m["pointer"]))
    return Report(found["file"], by_severity[0], by_severity[1], by_severity[2], report["validator"])


def issues(path: str | os.PathLike[str]) -> tuple[list[Issue], list[Issue]]:
    """``(errors, warnings)`` the Khronos validator reports for a file."""
    report = validate(path)
    return report.errors, report.warnings
