"""Generate "Walker", a simple skinned biped with a walk, in the CSE 169 formats (issue 14).

Run: ``.venv/bin/python scenes/tools/make_walker.py [--out DIR]`` (default ``scenes/walker/``).

Writes:

* ``walker.skel`` — 14 balljoints: ``hips`` (root) → ``chest`` → ``neck`` → ``head`` →
  ``head_top``; ``shoulder_l/r`` → ``elbow_l/r`` → ``wrist_l/r`` on the chest; ``hip_l/r`` →
  ``knee_l/r`` → ``ankle_l/r`` on the hips. Built facing +z, y up, 1.75 m tall, bind pose
  all zero;
* ``walker.skin`` — one closed tube per body part around its bone, each vertex bound with
  weight 1 to the bone's parent joint (so the skin's default capsule radii are the tubes'
  radii);
* ``walker_walk.anim`` — a one-second walk cycle (two steps) facing +x: the hips turn to +x
  (``ry`` = 90°), start at x = −0.6, z = 1.2, advance 0.8 m a cycle (``cycle_offset``) and bob, the legs swing and bend,
  the arms swing against them, the chest counter-sways.

The demo (``scenes/make_demo.py``) puts a cape on Walker, pinned to its chest.
"""

from __future__ import annotations

import argparse
import importlib.util
import math
import sys
from pathlib import Path
from types import ModuleType

import numpy as np

from qtanimator.core.channel import Channel, Extrapolation, Key
from qtanimator.core.clip import AnimationClip
from qtanimator.core.skeleton import Dof, Joint, Skeleton
from qtanimator.core.skinning import Skin, SkinBinding, vertex_normals
from qtanimator.formats.anim import format_anim

HERE = Path(__file__).resolve().parent
OUT = HERE.parent / "walker"
#: (name, parent, offset from the parent, tube radius of the bone ending here or None)
JOINTS: list[tuple[str, str | None, tuple[float, float, float], float | None]] = [
    ("hips", None, (0.0, 0.98, 0.0), None),
    ("chest", "hips", (0.0, 0.42, 0.0), 0.15),
    ("neck", "chest", (0.0, 0.13, 0.0), 0.12),
    ("head", "neck", (0.0, 0.08, 0.0), 0.05),
    ("head_top", "head", (0.0, 0.2, 0.0), 0.1),
    ("shoulder_l", "chest", (0.19, 0.06, 0.0), None),
    ("elbow_l", "shoulder_l", (0.0, -0.28, 0.0), 0.05),
    ("wrist_l", "elbow_l", (0.0, -0.26, 0.0), 0.04),
    ("shoulder_r", "chest", (-0.19, 0.06, 0.0), None),
    ("elbow_r", "shoulder_r", (0.0, -0.28, 0.0), 0.05),
    ("wrist_r", "elbow_r", (0.0, -0.26, 0.0), 0.04),
    ("hip_l", "hips", (0.1, -0.04, 0.0), None),
    ("knee_l", "hip_l", (0.0, -0.44, 0.0), 0.07),
    ("ankle_l", "knee_l", (0.0, -0.44, 0.0), 0.055),
    ("hip_r", "hips", (-0.1, -0.04, 0.0), None),
    ("knee_r", "hip_r", (0.0, -0.44, 0.0), 0.07),
    ("ankle_r", "knee_r", (0.0, -0.44, 0.0), 0.055),
]
SEGMENTS, RINGS = 12, 6
STRIDE = 0.8  # metres a cycle (two steps)
CYCLE = 1.0   # seconds
START_X, LANE_Z = -0.6, 1.2  # where the hips start (x) and the line it walks along (z)


def _make_arm() -> ModuleType:
    spec = importlib.util.spec_from_file_location("_make_arm_for_walker", HERE / "make_arm.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def skeleton() -> Skeleton:
    names = [j[0] for j in JOINTS]
    joints = []
    for name, parent, offset, _ in JOINTS:
        joints.append(Joint(name, None if parent is None else names.index(parent), np.array(offset),
                            (Dof(0.0), Dof(0.0), Dof(0.0)), np.array([-0.05, -0.05, -0.05]),
                            np.array([0.05, 0.05, 0.05])))
    return Skeleton(joints, rotation_order="zyx", name="walker", dialect="balljoint")


def _tube(a: np.ndarray, b: np.ndarray, r: float, base: int) -> tuple[np.ndarray, list[tuple[int, int, int]]]:
    """A closed tube of radius r around the segment a→b (rings, plus a pole at each end
    r beyond it), triangles wound counter-clockwise seen from outside."""
    axis = b - a
    length = float(np.linalg.norm(axis))
    u = axis / length
    helper = np.array([1.0, 0.0, 0.0]) if abs(u[0]) < 0.9 else np.array([0.0, 0.0, 1.0])
    e1 = np.cross(u, helper)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(u, e1)
    ang = 2 * math.pi * np.arange(SEGMENTS) / SEGMENTS
    ring = np.cos(ang)[:, None] * e1 + np.sin(ang)[:, None] * e2
    pos = [a - u * r * 0.7]
    for i in range(RINGS + 1):
        pos.extend(a + axis * (i / RINGS) + r * ring)
    pos.append(b + u * r * 0.7)
    tris: list[tuple[int, int, int]] = []

    def v(ri: int, k: int) -> int:
        return base + 1 + ri * SEGMENTS + k % SEGMENTS

    for k in range(SEGMENTS):
        tris.append((base, v(0, k + 1), v(0, k)))
    for ri in range(RINGS):
        for k in range(SEGMENTS):
            p, q, s, t = v(ri, k), v(ri, k + 1), v(ri + 1, k), v(ri + 1, k + 1)
            tris.append((p, s, t))
            tris.append((p, t, q))
    last = base + 1 + (RINGS + 1) * SEGMENTS
    for k in range(SEGMENTS):
        tris.append((last, v(RINGS, k), v(RINGS, k + 1)))
    return np.array(pos), tris


def build() -> tuple[Skeleton, Skin]:
    sk = skeleton()
    world = sk.world_matrices()
    heads = world[:, :3, 3]
    positions: list[np.ndarray] = []
    tris: list[tuple[int, int, int]] = []
    verts: list[int] = []
    joints: list[int] = []
    count = 0
    for i, (_, _, _, radius) in enumerate(JOINTS):
        parent = sk.joints[i].parent
        if radius is None or parent is None:
            continue
        pos, t = _tube(heads[parent], heads[i], radius, count)
        positions.append(pos)
        tris.extend(t)
        verts.extend(range(count, count + len(pos)))
        joints.extend([parent] * len(pos))
        count += len(pos)
    allpos = np.concatenate(positions)
    triangles = np.array(tris, dtype=np.int64)
    binding = SkinBinding(np.array(verts), np.array(joints), np.ones(len(verts)), count, len(sk.joints))
    skin = Skin.from_bind_matrices(allpos, triangles, binding, world, normals=vertex_normals(allpos, triangles))
    return sk, skin


def walk_clip() -> AnimationClip:
    """One cycle of walking towards +x (see the module docstring)."""
    names = [j[0] for j in JOINTS]

    def const(v: float) -> Channel:
        return Channel([Key.make(0.0, v, "flat", "flat")])

    def loop(*keys: tuple[float, float]) -> Channel:
        return Channel([Key.make(t * CYCLE, v, "smooth", "smooth") for t, v in keys], Extrapolation.CYCLE,
                       Extrapolation.CYCLE)

    swing = 0.45
    channels: dict[int, Channel] = {
        0: Channel([Key.make(0.0, START_X, "linear", "linear"), Key.make(CYCLE, START_X + STRIDE, "linear", "linear")],
                   Extrapolation.CYCLE_OFFSET, Extrapolation.CYCLE_OFFSET),
        1: loop((0.0, 0.0), (0.25, 0.03), (0.5, 0.0), (0.75, 0.03), (1.0, 0.0)),
        2: const(LANE_Z),
    }

    def dof(joint: str, axis: int) -> int:
        return 3 + 3 * names.index(joint) + axis

    channels[dof("hips", 1)] = const(math.pi / 2)
    channels[dof("chest", 1)] = loop((0.0, 0.12), (0.5, -0.12), (1.0, 0.12))
    channels[dof("chest", 0)] = const(0.08)
    for side, phase in (("l", 0.0), ("r", 0.5)):
        def key(t: float, v: float, ph: float = phase) -> tuple[float, float]:
            return ((t + ph) % 1.0, v)

        def cyc(*kv: tuple[float, float]) -> Channel:
            pts = sorted(key(t, v) for t, v in kv)
            pts = [(0.0, _wrap(pts, 0.0))] + [p for p in pts if 0.0 < p[0] < 1.0] + [(1.0, _wrap(pts, 0.0))]
            return loop(*pts)

        channels[dof(f"hip_{side}", 0)] = cyc((0.0, -swing), (0.5, swing))
        channels[dof(f"knee_{side}", 0)] = cyc((0.0, 0.1), (0.25, 0.05), (0.5, 0.15), (0.75, 0.75))
        channels[dof(f"shoulder_{side}", 0)] = cyc((0.0, 0.35), (0.5, -0.35))
        channels[dof(f"elbow_{side}", 0)] = cyc((0.0, -0.35), (0.5, -0.15))
    total = 3 + 3 * len(names)
    return AnimationClip([channels.get(i, const(0.0)) for i in range(total)], 0.0, CYCLE)


def _wrap(points: list[tuple[float, float]], t: float) -> float:
    """The value a cyclic, piecewise linear key list has at t (for the keys at 0 and 1)."""
    ts = [p[0] for p in points] + [points[0][0] + 1.0]
    vs = [p[1] for p in points] + [points[0][1]]
    tt = t if t >= ts[0] else t + 1.0
    return float(np.interp(tt, ts, vs))


def write(out: Path) -> list[Path]:
    arm = _make_arm()
    out.mkdir(parents=True, exist_ok=True)
    sk, skin = build()
    files = {"walker.skel": arm.format_skel(sk), "walker.skin": arm.format_skin(skin),
             "walker_walk.anim": format_anim(walk_clip())}
    paths = []
    for name, text in files.items():
        p = out / name
        p.write_text(text, encoding="utf-8", newline="\n")
        paths.append(p)
    return paths


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description="Generate Walker, a skinned biped with a walk cycle.")
    ap.add_argument("--out", type=Path, default=OUT, help="output folder (default: scenes/walker/)")
    ns = ap.parse_args(argv)
    for p in write(ns.out):
        print(f"wrote {p}")


if __name__ == "__main__":
    sys.exit(main())
