"""Channel evaluation: samples per second against scipy's CubicHermiteSpline.

Run: ``python -m benchmarks channel`` or ``python benchmarks/bench_channel.py``.

Both sides get identical keys and slopes (10, 100 and 1000 keys at random, uneven times,
random values and fixed slopes) and 1 M sample times. scipy's ``CubicHermiteSpline`` is
evaluated inside the key range (it has no cycle semantics: outside it would just continue
the end cubics). Ours is timed twice: on the same times inside the keys, and on times
spread over the keys *and* one key range before and after them with ``cycle`` extrapolation
on both sides, so every sample outside the keys pays for the period wrap. The figure is the
best of several repeats, ours and scipy taking turns in the same run. Values are checked
to agree (the same cubic) before timing.

Goal (issue 2): at least half of scipy's throughput with our full extrapolation semantics.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import numpy as np

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from benchmarks.common import interleaved_best, row, skipped  # noqa: E402

SAMPLES = 1_000_000
KEY_COUNTS = (10, 100, 1000)
REPEATS = 7
GOAL = 0.5


def _case(n: int, rng: np.random.Generator) -> tuple[Any, Any, np.ndarray, np.ndarray]:
    from scipy.interpolate import CubicHermiteSpline

    from qtanimator.core.channel import Channel, Key

    times = np.cumsum(rng.uniform(0.05, 1.0, n))
    values = rng.normal(size=n)
    slopes = rng.normal(size=n)
    ours = Channel([Key.make(t, v, s, s) for t, v, s in zip(times, values, slopes)], "cycle", "cycle")
    peer = CubicHermiteSpline(times, values, slopes)
    span = times[-1] - times[0]
    inside = rng.uniform(times[0], times[-1], SAMPLES)
    spread = rng.uniform(times[0] - span, times[-1] + span, SAMPLES)
    np.testing.assert_allclose(ours.evaluate(inside), peer(inside), rtol=1e-9, atol=1e-9)
    return ours, peer, inside, spread


def run() -> list[dict[str, Any]]:
    try:
        import scipy.interpolate  # noqa: F401
    except ModuleNotFoundError:
        return [skipped("channel evaluation vs scipy CubicHermiteSpline", "scipy is not installed",
                        "M samples/s", f"≥ {GOAL}× scipy")]
    rng = np.random.default_rng(169)
    rows = []
    for n in KEY_COUNTS:
        ours, peer, inside, spread = _case(n, rng)
        best = interleaved_best({
            "scipy": lambda p=peer, t=inside: p(t),
            "ours inside": lambda c=ours, t=inside: c.evaluate(t),
            "ours cycle": lambda c=ours, t=spread: c.evaluate(t),
        }, repeats=REPEATS)
        rate = {k: SAMPLES / v / 1e6 for k, v in best.items()}
        rows.append(row(f"channel evaluate, {n} keys, 1 M times, 2/3 outside (cycle)", rate["ours cycle"],
                        "M samples/s", rate["scipy"], f"≥ {GOAL}× scipy", digits=1,
                        note="met" if rate["ours cycle"] >= GOAL * rate["scipy"] else "below goal"))
        rows.append(row(f"channel evaluate, {n} keys, 1 M times inside the keys", rate["ours inside"],
                        "M samples/s", rate["scipy"], f"≥ {GOAL}× scipy", digits=1))
    return rows


if __name__ == "__main__":
    from benchmarks.__main__ import format_table

    print(format_table(run()))
