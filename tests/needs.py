"""What a test needs from the machine: skipped on a developer's machine that lacks it, a
failure in CI (``CI=true``; ``.ci/run`` sets it), where everything the project's files
install must be there (issue 17: a missing Xvfb or ``../shared/data`` is not a pass).

The public sample data (issue 30): every test that reads it gets the folder from here, through
the ``shared_data`` fixture of ``tests/conftest.py`` or :func:`shared_data_path` (the fixture
calls it). The folder is ``$QTANIMATOR_SHARED_DATA`` when that is set, else ``../shared/data`` beside the
checkout. Without it those tests skip (a fresh clone passes), and ``tests/conftest.py`` prints
one line at the end of the run saying how many were skipped and why; in CI they fail.
Module-level code (constants, parametrize lists) uses :func:`shared_data_dir`, which never
skips, and :func:`shared_data_params`, which never leaves a parameter list empty.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path
from typing import NoReturn

import pytest

#: The environment variable that gives the sample data's folder.
SHARED_DATA_ENV = "QTANIMATOR_SHARED_DATA"
#: Where the sample data is without the variable: ``../shared/data`` beside the checkout.
DEFAULT_SHARED_DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"
#: Every skip (or CI failure) for missing sample data starts with this; conftest counts them.
SHARED_DATA_MISSING = "sample data not found at "


def in_ci() -> bool:
    return os.environ.get("CI", "").strip().lower() in ("1", "true", "yes")


def missing(reason: str) -> NoReturn:
    """Skip with ``reason``, or fail with it in CI."""
    if in_ci():
        pytest.fail(f"{reason} (in CI this is a failure, not a skip)", pytrace=False)
    pytest.skip(reason)


def shared_data_dir() -> Path:
    """The sample data folder, whether or not it is there (never skips: for module-level code)."""
    given = os.environ.get(SHARED_DATA_ENV, "").strip()
    return (Path(given).expanduser() if given else DEFAULT_SHARED_DATA).resolve()


def shared_data_missing_reason() -> str | None:
    """Why the sample data cannot be read here, or None when its folder is there."""
    folder = shared_data_dir()
    if folder.is_dir():
        return None
    if os.environ.get(SHARED_DATA_ENV, "").strip():
        how = f"{SHARED_DATA_ENV} names a folder that does not exist"
    else:
        how = f"set {SHARED_DATA_ENV} or clone ../shared beside the repository"
    return f"{SHARED_DATA_MISSING}{folder} ({how})"


def shared_data_path(*parts: str | os.PathLike[str]) -> Path:
    """The sample data folder (or ``parts`` inside it) for a test that reads it: skips the
    test when the folder is missing, fails it in CI. A file missing inside a folder that is
    there is not checked here: reading it fails the test, as it should."""
    reason = shared_data_missing_reason()
    if reason is not None:
        missing(reason)
    return shared_data_dir().joinpath(*parts)


def shared_data_params(found: Iterable[object], placeholder: object) -> list[object]:
    """A parametrize list built at import time from the sample folder: ``found`` as it is, or,
    when the folder is missing, the single ``placeholder`` (the test must call
    :func:`shared_data_path` first, which then skips it, or fails it in CI). An empty list would
    be a silent skip even in CI. ``found`` is only read when the folder is there."""
    if shared_data_missing_reason() is not None:
        return [pytest.param(placeholder, id="sample-data-missing")]
    return list(found)
