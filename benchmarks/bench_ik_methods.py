"""IK methods side by side (issue 18): damped least squares, CCD, FABRIK, the handout's
gradient descent and the analytic two-bone solver, on the same drags.

Run: ``.venv/bin/python benchmarks/bench_ik_methods.py [--rounds N] [--out FILE]`` (prints a
table; ``--out`` also writes it, with the load average), or call ``run()`` for the rows.

A drag is a sequence of mouse-move targets along an arc; each event is solved from the
previous event's solution, as the editors do, with the editor's settings (2D: tolerance
1e-4 scene units, at most 100 iterations, root frozen; 3D: tolerance 1e-5, 100 sweeps or
passes, the DLS solver's own defaults). For each method and chain: time per drag event
(median, min–max over every event of every round; the methods take turns round by round),
final distance to the target per event (mean, max), how many events ended within 1e-3,
and iterations per event (median, max): DLS steps, CCD sweeps, FABRIK passes, handout
gradient steps, 1 for two-bone (3D two-bone: 1 + CCD sweeps when it needs them).

2D chains: ``character.svg``'s right arm (root → shoulder → … → hand: 4 moving joints, two
pendulum flaps held; needs the shared sample data), its upper arm + forearm (two moving
joints: the two-bone case), and planar chains of 10, 50 and 100 links. 3D: the CSE169
wasp's tail (3 joints, as the viewport's IK chain; its two-joint part for two-bone) and
straight ball-joint chains of 10 and 50 links solved over every joint.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

DATA = (REPO / ".." / "shared" / "data").resolve()
CHARACTER = DATA / "cmu-animator" / "scenes" / "character.svg"
WASP = DATA / "cse169" / "wasp_walk" / "wasp.skel"
EVENTS = 40
REACHED = 1e-3
COLUMNS = ["chain", "method", "median ms", "min–max ms", "mean error", "max error", "reached", "iterations"]


def _summary(chain: str, method: str, times: list[float], errors: list[float], iterations: list[int],
             events: int) -> dict[str, Any]:
    t = 1e3 * np.asarray(times)
    e = np.asarray(errors)
    return {"chain": chain, "method": method, "median ms": f"{np.median(t):.3f}",
            "min–max ms": f"{t.min():.3f}–{t.max():.3f}", "mean error": f"{e.mean():.2e}",
            "max error": f"{e.max():.2e}", "reached": f"{int((e[:events] <= REACHED).sum())}/{events}",
            "iterations": f"{int(np.median(iterations))} (max {max(iterations)})"}


# ------------------------------------------------------------------------------ 2D
def _methods_2d(two_bone: bool) -> dict[str, Callable[..., np.ndarray]]:
    from qtanimator.core import ik, ik_methods

    out: dict[str, Callable[..., np.ndarray]] = {
        "dls": ik.solve_ik, "ccd": ik_methods.solve_ccd, "fabrik": ik_methods.solve_fabrik,
        "handout": lambda *a, stats=None, **_k: ik.gradient_descent_step(*a[:6], stats=stats),
    }
    if two_bone:
        out["two-bone"] = lambda *a, stats=None, max_iterations=0, **k: ik_methods.solve_two_bone(*a, stats=stats,
                                                                                                  **k)
    return out


def _targets_2d(ch: Any, joint: int, local_point: np.ndarray, angles0: np.ndarray) -> list[np.ndarray]:
    """An arc of mouse moves from the current end, about the first moving joint's child."""
    chain_idx = ch.ancestors(joint)[::-1]
    pose = ch.pose(angles0, (0, 0))
    tip0 = pose.to_world(joint, local_point)
    centre = pose.pivots[chain_idx[1]] if len(chain_idx) > 2 else pose.pivots[chain_idx[-1]]
    r0 = float(np.hypot(*(tip0 - centre)))
    start = math.atan2(tip0[1] - centre[1], tip0[0] - centre[0])
    return [centre + (r0 * (1 - 0.25 * k / EVENTS)) * np.array([math.cos(start + 0.8 * k / EVENTS),
                                                                   math.sin(start + 0.8 * k / EVENTS)])
            for k in range(1, EVENTS + 1)]


def case_2d(name: str, ch: Any, joint: int, local_point: np.ndarray, angles0: np.ndarray, rounds: int,
            two_bone: bool = False) -> list[dict[str, Any]]:
    from qtanimator.core.ik import IKStats, ik_error

    methods = _methods_2d(two_bone)
    targets = _targets_2d(ch, joint, local_point, angles0)
    record: dict[str, tuple[list[float], list[float], list[int]]] = {m: ([], [], []) for m in methods}
    for _round in range(rounds):
        for method, solve in methods.items():
            angles = angles0.copy()
            times, errors, its = record[method]
            for q in targets:
                stats = IKStats()
                t = time.perf_counter()
                angles = solve(ch, angles, (0, 0), joint, local_point, q, tolerance=1e-4, max_iterations=100,
                               stats=stats)
                times.append(time.perf_counter() - t)
                errors.append(ik_error(ch, angles, (0, 0), joint, local_point, q))
                its.append(stats.iterations)
    return [_summary(name, m, *record[m], events=len(targets) * rounds) for m in methods]


def rows_2d(rounds: int) -> list[dict[str, Any]]:
    from qtanimator.core.ik import planar_chain

    rows: list[dict[str, Any]] = []
    if CHARACTER.is_file():
        from qtanimator.formats.svg_rig import load_characters

        [ch] = load_characters(CHARACTER)
        a0 = np.zeros(len(ch.joints))
        a0[[4, 5]] = 0.3
        hand = 6  # root → 3 (shoulder) → 4 → 5 → 6 (hand)
        rows += case_2d("2D character.svg arm (4 joints)", ch, hand, ch.joints[hand].pivot + np.array([-30.0, 0.0]),
                        a0, rounds)
        forearm = 4  # root → 3 → 4: two moving joints; the point grabbed is the wrist pivot
        rows += case_2d("2D character.svg upper arm + forearm (2 joints)", ch, forearm, ch.joints[5].pivot.copy(),
                        a0, rounds, two_bone=True)
    else:
        rows.append({"chain": "2D character.svg", "method": f"skipped: no sample data at {CHARACTER}"})
    for n in (10, 50, 100):
        ch = planar_chain(n, 10.0)
        a0 = np.full(n, 0.05)
        a0[0] = 0.0
        rows += case_2d(f"2D planar {n}-link chain", ch, n - 1, np.array([n * 10.0, 0.0]), a0, rounds)
    return rows


# ------------------------------------------------------------------------------ 3D
def _straight_skeleton(links: int) -> Any:
    from qtanimator.core.skeleton import Joint, Skeleton

    joints = [Joint("root", None, (0, 0, 0))]
    for i in range(1, links + 1):
        joints.append(Joint(f"j{i}", i - 1, (1.0 if i > 1 else 0.0, 0.0, 0.0)))
    return Skeleton(joints)


def case_3d(name: str, skel: Any, end: int, dofs: list[tuple[int, int]], rounds: int,
            two_bone: bool = False) -> list[dict[str, Any]]:
    from qtanimator.core import ik3d, ik3d_methods

    methods: dict[str, Callable[..., Any]] = {
        "dls": lambda s, e, q, d: ik3d.solve_ik(s, e, q, dofs=d),
        "ccd": lambda s, e, q, d: ik3d_methods.solve_ccd(s, e, q, dofs=d, iterations=100),
        "fabrik": lambda s, e, q, d: ik3d_methods.solve_fabrik(s, e, q, dofs=d, iterations=100),
    }
    if two_bone:
        methods["two-bone"] = lambda s, e, q, d: ik3d_methods.solve_two_bone(s, e, q, dofs=d, iterations=100)
    world = skel.world_matrices()
    top = world[min((j for j, _a in dofs), key=lambda j: skel.depths[j]), :3, 3]   # the chain's highest pivot
    tip0 = world[end, :3, 3]
    r = tip0 - top
    r0 = float(np.linalg.norm(r))
    u = r / r0
    v = np.cross(u, [0.0, 0.0, 1.0] if abs(u[2]) < 0.9 else [1.0, 0.0, 0.0])
    v /= np.linalg.norm(v)
    targets = [top + r0 * (1 - 0.25 * k / EVENTS) * (math.cos(0.8 * k / EVENTS) * u + math.sin(0.8 * k / EVENTS) * v)
               for k in range(1, EVENTS + 1)]
    start = skel.dof_values()
    record: dict[str, tuple[list[float], list[float], list[int]]] = {m: ([], [], []) for m in methods}
    for _round in range(rounds):
        for method, solve in methods.items():
            s = skel.copy()
            s.set_dof_values(start)
            times, errors, its = record[method]
            for q in targets:
                t = time.perf_counter()
                result = solve(s, end, q, dofs)
                times.append(time.perf_counter() - t)
                for (j, a), x in result.values.items():
                    s.joints[j].dofs[a].value = x
                errors.append(float(np.linalg.norm(s.world_matrices()[end, :3, 3] - q)))
                its.append(result.iterations)
    return [_summary(name, m, *record[m], events=len(targets) * rounds) for m in methods]


def rows_3d(rounds: int) -> list[dict[str, Any]]:
    from qtanimator.core.ik3d import chain_dofs

    rows: list[dict[str, Any]] = []
    if WASP.is_file():
        from qtanimator.formats.skel import load_skel

        wasp = load_skel(WASP)
        tail = wasp.index_of("tail_04")
        rows += case_3d("3D wasp tail (3 joints)", wasp, tail, chain_dofs(wasp, tail, 3), rounds)
        tail2 = wasp.index_of("tail_02")
        rows += case_3d("3D wasp tail_01 + abdomen (2 joints)", wasp, tail2, chain_dofs(wasp, tail2, 3), rounds,
                        two_bone=True)
    else:
        rows.append({"chain": "3D wasp", "method": f"skipped: no sample data at {WASP}"})
    for n in (10, 50):
        skel = _straight_skeleton(n)
        # a slight bend so that no solve starts on the straight-chain singularity
        skel.set_dof_values(np.tile([0.0, 0.0, 0.05], (n + 1, 1)))
        rows += case_3d(f"3D straight {n}-link chain", skel, n, chain_dofs(skel, n, n), rounds)
    return rows


def run(rounds: int = 3) -> list[dict[str, Any]]:
    return rows_2d(rounds) + rows_3d(rounds)


def table(rows: list[dict[str, Any]]) -> str:
    widths = {c: max(len(c), *(len(str(r.get(c, ""))) for r in rows)) for c in COLUMNS}
    lines = ["  ".join(c.ljust(widths[c]) for c in COLUMNS), "  ".join("-" * widths[c] for c in COLUMNS)]
    last = None
    for r in rows:
        if last is not None and r["chain"] != last:
            lines.append("")
        last = r["chain"]
        lines.append("  ".join(str(r.get(c, "")).ljust(widths[c]) for c in COLUMNS))
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--out", type=Path)
    args = parser.parse_args(argv)
    load0 = os.getloadavg()
    started = time.time()
    rows = run(args.rounds)
    load1 = os.getloadavg()
    text = (f"IK methods side by side: {EVENTS} drag events × {args.rounds} rounds per method and chain "
            f"({time.time() - started:.0f} s)\n"
            f"load average (1, 5, 15 min) before {load0[0]:.2f} {load0[1]:.2f} {load0[2]:.2f}, "
            f"after {load1[0]:.2f} {load1[1]:.2f} {load1[2]:.2f}; {os.cpu_count()} CPUs; "
            f"python {sys.version.split()[0]}, numpy {np.__version__}\n"
            f"reached: events ending within {REACHED:g} of the target\n\n" + table(rows) + "\n")
    print(text)
    if args.out is not None:
        args.out.write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
