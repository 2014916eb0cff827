"""2D IK: time per drag-event solve, against ikpy on the same chains at equal accuracy.

Run: ``.venv/bin/python benchmarks/bench_ik.py`` (prints a table), or call ``run()`` for the
rows. A "drag" is a sequence of mouse-move targets along an arc; each event is solved
starting from the previous event's solution (as the rig editor does).

* ours: ``qtanimator.core.ik.solve_ik`` (damped least squares, adaptive damping, root frozen);
* peer: ikpy ``Chain.inverse_kinematics`` (scipy optimiser over ikpy's 4×4 forward
  kinematics) on the same planar chain, root joint inactive, same start, same targets.

Equal accuracy: each event is first solved by ikpy; ours is then asked for the same or a
smaller error (tolerance = ikpy's error, floored at 1e-9 and capped at 1e-3), and both
errors are reported. Chains: ``character.svg``'s right arm (shoulder → hand, 4 moving
joints; needs the shared sample data) and planar chains of 10 and 50 links.
Goals (issue 3): 30× faster than ikpy, and under 1 ms per drag event up to 50 links.
"""

from __future__ import annotations

import math
import os
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from benchmarks.common import print_rows  # noqa: E402

SAMPLES = (REPO / ".." / "shared" / "data" / "cmu-animator" / "scenes").resolve()
GOAL_RATIO = 30.0
GOAL_MS = 1.0
EVENTS = 40


def _ikpy_chain(pivots: np.ndarray, tip: np.ndarray) -> Any:
    """An ikpy chain with the same geometry (y flipped: ikpy's y points up)."""
    from ikpy.chain import Chain
    from ikpy.link import OriginLink, URDFLink

    links: list[Any] = [OriginLink()]
    points = np.vstack([pivots, tip[None, :]])
    prev = np.zeros(2)
    for i, p in enumerate(points[:-1]):
        d = p - prev
        links.append(URDFLink(name=f"j{i}", origin_translation=np.array([d[0], -d[1], 0.0]),
                              origin_orientation=np.zeros(3), rotation=np.array([0.0, 0.0, 1.0])))
        prev = p
    d = points[-1] - prev
    links.append(URDFLink(name="tip", origin_translation=np.array([d[0], -d[1], 0.0]),
                          origin_orientation=np.zeros(3), rotation=None, joint_type="fixed"))
    mask = [False, False] + [True] * (len(points) - 2) + [False]
    return Chain(links, active_links_mask=mask)


def _case(name: str, ch: Any, joint: int, local_point: np.ndarray, angles0: np.ndarray) -> dict[str, Any]:
    from qtanimator.core.ik import ik_error, solve_ik

    chain_idx = ch.ancestors(joint)[::-1]
    pose = ch.pose(angles0, (0, 0))
    tip0 = pose.to_world(joint, local_point)
    pivots = ch.rest_pivots[chain_idx]
    peer = _ikpy_chain(pivots - pivots[0], local_point - pivots[0])
    reach = float(np.sum(np.hypot(*np.diff(np.vstack([pivots, local_point]), axis=0).T)))
    # an arc of mouse moves from the current tip, inside the reachable disc
    centre = pose.pivots[chain_idx[1]] if len(chain_idx) > 1 else pose.pivots[0]
    r0 = np.hypot(*(tip0 - centre))
    start = math.atan2(tip0[1] - centre[1], tip0[0] - centre[0])
    targets = [centre + (r0 * (1 - 0.25 * k / EVENTS)) * np.array([math.cos(start + 0.8 * k / EVENTS),
                                                                      math.sin(start + 0.8 * k / EVENTS)])
               for k in range(1, EVENTS + 1)]
    ours_a = angles0.copy()
    peer_q = np.zeros(len(peer.links))
    peer_q[2:-1] = -angles0[chain_idx][1:]  # ikpy turns the other way with y up
    peer_q[1] = 0.0
    t_ours, t_peer, e_ours, e_peer = [], [], [], []
    for q in targets:
        q3 = np.array([q[0] - pivots[0][0], -(q[1] - pivots[0][1]), 0.0])
        t = time.perf_counter()
        peer_q = peer.inverse_kinematics(q3, initial_position=peer_q)
        t_peer.append(time.perf_counter() - t)
        fk = peer.forward_kinematics(peer_q)[:3, 3]
        ep = float(np.hypot(fk[0] - q3[0], fk[1] - q3[1]))
        e_peer.append(ep)
        tol = min(max(ep, 1e-9), 1e-3)
        t = time.perf_counter()
        ours_a = solve_ik(ch, ours_a, (0, 0), joint, local_point, q, tolerance=tol, max_iterations=200)
        t_ours.append(time.perf_counter() - t)
        e_ours.append(ik_error(ch, ours_a, (0, 0), joint, local_point, q))
    ours_ms = 1e3 * float(np.mean(t_ours))
    peer_ms = 1e3 * float(np.mean(t_peer))
    ratio = peer_ms / ours_ms
    return {"name": f"IK drag event: {name} ({len(chain_idx) - 1} moving joints, reach {reach:.0f})",
            "figure": round(ours_ms, 4), "unit": "ms per drag event", "peer figure": round(peer_ms, 3),
            "peer": "ikpy Chain.inverse_kinematics", "ratio": round(ratio, 1),
            "goal": f"≥ {GOAL_RATIO:g}× faster than ikpy and < {GOAL_MS:g} ms",
            "met": bool(ratio >= GOAL_RATIO and ours_ms < GOAL_MS),
            "mean_error_ours": float(np.mean(e_ours)), "mean_error_peer": float(np.mean(e_peer)),
            "max_error_ours": float(np.max(e_ours)), "load_average": round(os.getloadavg()[0], 2)}


def run() -> list[dict[str, Any]]:
    from qtanimator.core.ik import planar_chain

    rows: list[dict[str, Any]] = []
    try:
        import ikpy  # noqa: F401
    except ImportError:
        return [{"name": "IK drag event", "figure": None, "unit": "ms", "peer figure": None, "ratio": None,
                 "goal": f"≥ {GOAL_RATIO:g}× faster than ikpy", "skipped": "ikpy is not installed"}]
    if (SAMPLES / "character.svg").is_file():
        from qtanimator.formats.svg_rig import load_characters

        [ch] = load_characters(SAMPLES / "character.svg")
        hand = 6  # right hand: root → 3 (shoulder) → 4 → 5 → 6
        lp = ch.joints[hand].pivot + np.array([-30.0, 0.0])
        a0 = np.zeros(len(ch.joints))
        a0[[4, 5]] = 0.3
        rows.append(_case("character.svg arm", ch, hand, lp, a0))
    else:
        rows.append({"name": "IK drag event: character.svg arm", "figure": None, "unit": "ms",
                     "peer figure": None, "ratio": None, "goal": "", "skipped": f"no sample data at {SAMPLES}"})
    for n in (10, 50):
        ch = planar_chain(n, 10.0)
        a0 = np.full(n, 0.05)
        a0[0] = 0.0
        rows.append(_case(f"planar {n}-link chain", ch, n - 1, np.array([n * 10.0, 0.0]), a0))
    return rows


def main() -> int:
    return print_rows(run(), ["name", "figure", "unit", "peer figure", "ratio", "goal", "met"])


if __name__ == "__main__":
    sys.exit(main())
