"""Hypothesis profiles of the test suite (loaded by ``tests/conftest.py`` before any test
module is imported, so every ``settings(...)`` a test builds inherits from the profile).

* ``ci`` (loaded when ``CI=true``, as ``.ci/run`` sets it): ``derandomize=True`` — a fixed
  seed per test, so a CI run is reproducible and a failure shows up again on the next run —
  no example database (nothing written into the checkout) and the failing example's blob
  printed.
* ``dev`` (otherwise): Hypothesis' defaults (random seeds, the local ``.hypothesis``
  database that replays earlier failures).

``HYPOTHESIS_PROFILE=ci`` (or ``dev``) picks a profile by hand.

A test's own ``@settings(max_examples=N)`` overrides the profile's count, so the property
tests that guard the most used code (channel evaluation, the command state machine) take
their count from :func:`thorough` instead: :data:`THOROUGH_EXAMPLES` for the active profile
(at least 200 in CI). Other tests keep their own modest counts (the suite must stay within
a few minutes on CI's 2 cores).
"""

from __future__ import annotations

import os
from typing import Any

from hypothesis import settings

CI = os.environ.get("CI", "").strip().lower() in ("1", "true", "yes")
#: The active profile's name.
PROFILE = os.environ.get("HYPOTHESIS_PROFILE") or ("ci" if CI else "dev")

settings.register_profile("dev")
settings.register_profile("ci", derandomize=True, database=None, print_blob=True)

#: ``max_examples`` of the thorough property tests, by profile.
THOROUGH_EXAMPLES = {"dev": 60, "ci": 200}


def load() -> None:
    """Make the active profile the default (call before test modules build settings)."""
    settings.load_profile(PROFILE)


def thorough(**kwargs: Any) -> settings:
    """Settings for a thorough property test: the profile's :data:`THOROUGH_EXAMPLES`
    (other settings from the active profile, or ``kwargs``)."""
    kwargs.setdefault("max_examples", THOROUGH_EXAMPLES.get(PROFILE, THOROUGH_EXAMPLES["dev"]))
    return settings(**kwargs)
