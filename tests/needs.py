"""What a test needs from the machine: skipped on a developer's machine that lacks it, a
failure in CI (``CI=true``; ``.ci/run`` sets it), where everything the project's files
install must be there (issue 17: a missing Xvfb or ``../shared/data`` is not a pass)."""

from __future__ import annotations

import os
from typing import NoReturn

import pytest


def in_ci() -> bool:
    return os.environ.get("CI", "").strip().lower() in ("1", "true", "yes")


def missing(reason: str) -> NoReturn:
    """Skip with ``reason``, or fail with it in CI."""
    if in_ci():
        pytest.fail(f"{reason} (in CI this is a failure, not a skip)", pytrace=False)
    pytest.skip(reason)
