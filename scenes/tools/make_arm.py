"""Generate a skinned 3D arm in the CSE 169 formats.

Run: ``.venv/bin/python scenes/tools/make_arm.py [--out DIR]`` (default ``scenes/arm3d/``).

Writes:

* ``arm.skel`` — two balljoints, ``shoulder`` (root) and ``elbow`` (offset 1 along x), with
  boxes, an elbow that only bends one way (``rotzlimit 0 2.6``) and a bind ``pose``;
* ``arm.skin`` — a round-ended tube built straight along +x in the all-zero pose, then bent
  into the bind pose, with smooth two-joint weights across the elbow (a smoothstep over
  ±0.25 around it; vertices away from the elbow have a single weight of 1). Its ``bindings``
  are the joints' **bind world matrices B** (not inverses), written as four lines a, b, c,
  d: the **columns** of B (the x, y, z axes and the position of the joint at bind time);
* ``arm_wave.anim`` — a two-second waving loop: 9 channels (root x, y, z, then x, y, z
  rotation of the shoulder and of the elbow), smooth keys, ``cycle`` extrapolation;
* ``arm3d.qtanim`` — a project holding the character with its skin and animation.

The bind pose is the pose the ``.skel`` file gives (``pose`` lines, root translation 0), so a
freshly loaded arm shows the mesh exactly as stored; it is deliberately not the zero pose
(the shoulder is lifted and turned, the elbow bent) so that the bind matrices have
rotations and a reader that took a, b, c, d as rows would visibly tear the mesh.
``tests/test_scenes.py`` skins the bind pose with :mod:`qtanimator.core.skinning` and checks
that it reproduces the stored positions and normals.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

from qtanimator.core.channel import Channel, Extrapolation, Key
from qtanimator.core.clip import AnimationClip
from qtanimator.core.skeleton import Dof, Joint, Skeleton
from qtanimator.core.skinning import Skin, SkinBinding, skin_positions, vertex_normals
from qtanimator.formats.anim import format_anim

HERE = Path(__file__).resolve().parent
OUT = HERE.parent / "arm3d"

UPPER = 1.0  # shoulder → elbow
LENGTH = 1.9  # shoulder → fingertip end of the tube
R_SHOULDER, R_WRIST = 0.17, 0.11
SEGMENTS = 20  # around the tube
RINGS = 40  # along the straight part
CAP_RINGS = 5  # per rounded end
BLEND = 0.25  # half-width of the elbow's weight blend
ROOT_OFFSET = (0.0, 1.4, 0.0)
BIND_POSE = {"shoulder": (0.2, 0.35, 0.3), "elbow": (0.0, 0.0, 0.45)}
ELBOW_LIMIT = (0.0, 2.6)


def skeleton() -> Skeleton:
    sh = BIND_POSE["shoulder"]
    el = BIND_POSE["elbow"]
    shoulder = Joint("shoulder", None, np.array(ROOT_OFFSET), (Dof(sh[0]), Dof(sh[1]), Dof(sh[2])),
                     np.array([-0.2, -0.2, -0.2]), np.array([UPPER, 0.2, 0.2]))
    elbow = Joint("elbow", 0, np.array([UPPER, 0.0, 0.0]),
                  (Dof(el[0], -0.6, 0.6), Dof(el[1], -0.3, 0.3), Dof(el[2], *ELBOW_LIMIT)),
                  np.array([0.0, -0.15, -0.15]), np.array([LENGTH - UPPER, 0.15, 0.15]))
    return Skeleton([shoulder, elbow], rotation_order="zyx", name="arm", dialect="balljoint")


def _f(v: float) -> str:
    text = f"{float(v):.6f}"
    return "0.000000" if text == "-0.000000" else text


def format_skel(sk: Skeleton) -> str:
    lines: list[str] = []

    def joint(i: int, depth: int) -> None:
        j = sk.joints[i]
        pad = "\t" * depth
        lines.append(f"{pad}balljoint {j.name} {{")
        lines.append(f"{pad}\toffset {' '.join(_f(v) for v in j.offset)}")
        lines.append(f"{pad}\tboxmin {' '.join(_f(v) for v in j.boxmin)}")
        lines.append(f"{pad}\tboxmax {' '.join(_f(v) for v in j.boxmax)}")
        for axis, dof in zip("xyz", j.dofs):
            if dof.min > -1e5 or dof.max < 1e5:
                lines.append(f"{pad}\trot{axis}limit {_f(dof.min)} {_f(dof.max)}")
        lines.append(f"{pad}\tpose {' '.join(_f(d.value) for d in j.dofs)}")
        for c in sk.children(i):
            joint(c, depth + 1)
        lines.append(f"{pad}}}")

    joint(0, 0)
    return "\n".join(lines) + "\n"


def _profile() -> tuple[np.ndarray, np.ndarray]:
    """(x, radius) of every ring from shoulder pole to wrist pole, in the zero pose."""
    xs, rs = [], []
    for i in range(CAP_RINGS, 0, -1):  # rounded shoulder end
        a = 0.5 * math.pi * i / (CAP_RINGS + 1)
        xs.append(-R_SHOULDER * math.sin(a))
        rs.append(R_SHOULDER * math.cos(a))
    for i in range(RINGS + 1):
        x = LENGTH * i / RINGS
        xs.append(x)
        rs.append(R_SHOULDER + (R_WRIST - R_SHOULDER) * x / LENGTH)
    for i in range(1, CAP_RINGS + 1):  # rounded wrist end
        a = 0.5 * math.pi * i / (CAP_RINGS + 1)
        xs.append(LENGTH + R_WRIST * math.sin(a))
        rs.append(R_WRIST * math.cos(a))
    return np.array(xs), np.array(rs)


def tube() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Zero-pose positions (V, 3), triangles (T, 3) wound counter-clockwise seen from outside,
    and the elbow weight of each vertex."""
    xs, rs = _profile()
    angles = 2 * math.pi * np.arange(SEGMENTS) / SEGMENTS
    ring = np.stack([np.zeros(SEGMENTS), np.cos(angles), np.sin(angles)], axis=1)
    pos = [np.array([[-R_SHOULDER, 0.0, 0.0]])]  # shoulder pole
    for x, r in zip(xs, rs):
        pos.append(np.array([x, 0.0, 0.0]) + r * ring)
    pos.append(np.array([[LENGTH + R_WRIST, 0.0, 0.0]]))  # wrist pole
    positions = np.concatenate(pos)
    n_rings = len(xs)
    tris: list[tuple[int, int, int]] = []

    def v(ring_index: int, k: int) -> int:
        return 1 + ring_index * SEGMENTS + k % SEGMENTS

    for k in range(SEGMENTS):  # fan around the shoulder pole (facing −x)
        tris.append((0, v(0, k + 1), v(0, k)))
    for r in range(n_rings - 1):
        for k in range(SEGMENTS):
            a, b, c, d = v(r, k), v(r, k + 1), v(r + 1, k), v(r + 1, k + 1)
            tris.append((a, b, d))
            tris.append((a, d, c))
    last = len(positions) - 1
    for k in range(SEGMENTS):  # fan around the wrist pole (facing +x)
        tris.append((last, v(n_rings - 1, k), v(n_rings - 1, k + 1)))
    s = np.clip((positions[:, 0] - (UPPER - BLEND)) / (2 * BLEND), 0.0, 1.0)
    elbow_weight = np.round(s * s * (3 - 2 * s), 6)  # so that 1 − w is exact in the file too
    return positions, np.array(tris, dtype=np.int64), elbow_weight


def binding(elbow_weight: np.ndarray) -> SkinBinding:
    verts, joints, weights = [], [], []
    for i, w in enumerate(elbow_weight):
        for j, wj in ((0, 1.0 - w), (1, w)):
            if wj > 0:
                verts.append(i)
                joints.append(j)
                weights.append(wj)
    return SkinBinding(np.array(verts), np.array(joints), np.array(weights), len(elbow_weight), 2)


def build() -> tuple[Skeleton, Skin]:
    sk = skeleton()
    local, tris, w = tube()
    zero_pose = local + np.array(ROOT_OFFSET)  # the straight tube where the zero-pose arm is
    bind_world = sk.world_matrices()  # the .skel's pose, root translation 0
    zero_world = sk.world_matrices(np.zeros((2, 3)), np.zeros(3))
    # Bend the straight tube into the bind pose with its own weights: a skin bound at the zero
    # pose, posed by the bind-pose matrices.
    straight = Skin.from_bind_matrices(zero_pose, tris, binding(w), zero_world)
    positions = skin_positions(straight, bind_world)
    skin = Skin.from_bind_matrices(positions, tris, binding(w), bind_world,
                                   normals=vertex_normals(positions, tris))
    return sk, skin


def format_skin(skin: Skin) -> str:
    assert skin.normals is not None and skin.bind_matrices is not None
    out = [f"positions {skin.num_vertices} {{"]
    out += [f"\t{_f(x)} {_f(y)} {_f(z)}" for x, y, z in skin.positions]
    out += ["}", f"normals {skin.num_vertices} {{"]
    out += [f"\t{_f(x)} {_f(y)} {_f(z)}" for x, y, z in skin.normals]
    out += ["}", f"skinweights {skin.num_vertices} {{"]
    starts, joints, weights = skin.binding.csr()
    for i in range(skin.num_vertices):
        pairs = [f"{int(joints[k])} {_f(weights[k])}" for k in range(starts[i], starts[i + 1])]
        out.append(f"\t{len(pairs)} {' '.join(pairs)}")
    out += ["}", f"triangles {len(skin.triangles)} {{"]
    out += [f"\t{a} {b} {c}" for a, b, c in skin.triangles]
    out += ["}", f"bindings {len(skin.bind_matrices)} {{"]
    for m in skin.bind_matrices:
        out.append("\tmatrix {")
        for col in range(4):  # a, b, c, d are the COLUMNS of the bind world matrix
            out.append(f"\t\t{_f(m[0, col])} {_f(m[1, col])} {_f(m[2, col])}")
        out.append("\t}")
    out.append("}")
    return "\n".join(out) + "\n"


def wave_clip() -> AnimationClip:
    """Two seconds of waving; starts and ends in the bind pose."""
    sx, sy, sz = BIND_POSE["shoulder"]
    ez = BIND_POSE["elbow"][2]

    def const(v: float) -> Channel:
        return Channel([Key.make(0.0, v, "flat", "flat")])

    def loop(*keys: tuple[float, float]) -> Channel:
        return Channel([Key.make(t, v, "smooth", "smooth") for t, v in keys], Extrapolation.CYCLE,
                       Extrapolation.CYCLE)

    channels = [
        const(0.0), const(0.0), const(0.0),                                       # root position
        loop((0.0, sx), (1.0, sx + 0.3), (2.0, sx)),                              # shoulder twist
        loop((0.0, sy), (1.0, sy - 0.25), (2.0, sy)),                             # shoulder swing
        loop((0.0, sz), (0.5, 1.1), (1.0, 1.25), (1.5, 1.1), (2.0, sz)),         # shoulder lift
        const(0.0), const(0.0),                                                    # elbow x, y
        loop((0.0, ez), (0.5, 1.7), (0.75, 0.9), (1.0, 1.7), (1.25, 0.9), (1.5, 1.7), (2.0, ez)),  # wave
    ]
    return AnimationClip(channels, 0.0, 2.0)


def write(out: Path) -> list[Path]:
    from qtanimator.document import Document, save_document
    from qtanimator.document.character3d import add_character3d_command

    out.mkdir(parents=True, exist_ok=True)
    sk, skin = build()
    files = {"arm.skel": format_skel(sk), "arm.skin": format_skin(skin), "arm_wave.anim": format_anim(wave_clip())}
    paths = []
    for name, text in files.items():
        p = out / name
        p.write_text(text, encoding="utf-8", newline="\n")
        paths.append(p)
    doc = Document(parameters={"fps": 60.0, "frame_start": 0, "frame_end": 240})
    add_character3d_command(doc, out / "arm.skel", out / "arm.skin", out / "arm_wave.anim", asset_id="arm").do(doc)
    save_document(doc, out / "arm3d.qtanim")
    paths.append(out / "arm3d.qtanim")
    return paths


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description="Generate the skinned 3D arm (.skel, .skin, .anim, project).")
    ap.add_argument("--out", type=Path, default=OUT, help="output folder (default: scenes/arm3d/)")
    ns = ap.parse_args(argv)
    for p in write(ns.out):
        print(f"wrote {p}")


if __name__ == "__main__":
    sys.exit(main())
