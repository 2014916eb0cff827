"""Build Robo, a nested mechanical figure, on the matrix stack, and animate it with linear keys.

Run: ``.venv/bin/python scenes/tools/make_robot.py [--out DIR]`` (default ``scenes/robot/``).

This is the lecture notes' exercise (a nested mechanised figure drawn with push / translate /
rotate / pop, moved by piecewise-linear key frames) made into qtanimator files:

* ``robot.svg`` — the figure as an **SVG rig**, so it opens in the 2D editor. The rest pose is
  drawn by walking the part tree with :class:`qtanimator.core.matrix_stack.MatrixStack`:
  for each part ``push(); translate(pivot); rotate_z(-angle)``, transform the part's shapes
  by the top of the stack, recurse into the children, ``pop()``. Each part becomes a joint
  whose pivot circle sits at the stack's origin for that part.
* ``robot.qtanim`` — a project holding the rig and one channel per animated value whose keys
  all use :data:`qtanimator.core.channel.Interpolation.LINEAR` (the lecture's ``eval``:
  ``V = V_i + (V_{i+1} − V_i)·(t − T_i)/(T_{i+1} − T_i)``) and ``cycle`` extrapolation (the
  lecture's ``eval(keys, time % period)``).

Coordinates are SVG user units with y down. The rig's joint angle θ is counter-clockwise on
screen; on a y-down plane that is ``rotate_z(-θ)`` of the stack (whose rotate_z turns +x
toward +y). :func:`stack_pivots` poses the figure with the stack exactly as the lecture's
``animate(time)`` would; ``tests/test_scenes.py`` checks that the program's own 2D rig, fed
the project's channels, puts every joint where the stack does.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from svgwriter import JointSpec, circle, document, num, polygon, polyline  # noqa: E402

from qtanimator.core.matrix_stack import MatrixStack  # noqa: E402

OUT = HERE.parent / "robot"
ROOT_POSITION = (300.0, 360.0)  # the hip, the root joint's pivot, in the rest pose
FPS = 60.0
PERIOD = 2.0  # every cycle of the walk lasts two seconds; the slide lasts two cycles
INK = "#1e2430"
STEEL = "#9aa7b8"
STEEL_DARK = "#6c7a8f"
ACCENT = "#f0a020"


# ---------------------------------------------------------------- the part tree
@dataclass
class Part:
    """A rigid part: pivot relative to the parent's frame, rest angle, local shapes."""

    name: str
    pivot: tuple[float, float]
    rest: float = 0.0  # rig convention: radians, counter-clockwise on screen
    boxes: list[tuple[float, float, float, float, str]] = field(default_factory=list)  # x, y, w, h, fill
    polys: list[tuple[list[tuple[float, float]], str]] = field(default_factory=list)
    dots: list[tuple[float, float, float, str]] = field(default_factory=list)  # x, y, r, fill
    lines: list[tuple[list[tuple[float, float]], str, float]] = field(default_factory=list)
    children: list[Part] = field(default_factory=list)

    def walk(self) -> Iterator[Part]:
        yield self
        for c in self.children:
            yield from c.walk()


def _arm(side: str, sx: float) -> Part:
    s = -1.0 if side == "left" else 1.0
    claw = Part(f"claw_{side}", (0.0, 58.0), 0.0,
                boxes=[(-12, -4, 24, 12, STEEL_DARK)],
                polys=[([(-12, 6), (-4, 6), (-8, 34), (-16, 28)], ACCENT),
                       ([(12, 6), (4, 6), (8, 34), (16, 28)], ACCENT)],
                dots=[(0, 0, 7, INK)])
    fore = Part(f"forearm_{side}", (0.0, 64.0), s * 0.1,
                boxes=[(-10, -4, 20, 64, STEEL)], dots=[(0, 0, 9, STEEL_DARK)], children=[claw])
    return Part(f"arm_{side}", (sx, -132.0), s * 0.12,
                boxes=[(-13, -8, 26, 72, STEEL)], dots=[(0, 0, 14, STEEL_DARK)], children=[fore])


def _leg(side: str, hx: float) -> Part:
    foot_dir = -1.0 if side == "left" else 1.0
    shin = Part(f"shin_{side}", (0.0, 66.0), 0.0,
                boxes=[(-12, -4, 24, 64, STEEL)],
                polys=[([(-18, 60), (18 + 14 * foot_dir, 60), (18 + 14 * foot_dir, 74), (-18, 74)]
                        if foot_dir > 0 else [(-18 - 14, 60), (18, 60), (18, 74), (-18 - 14, 74)], INK)],
                dots=[(0, 0, 10, STEEL_DARK)])
    return Part(f"leg_{side}", (hx, 0.0), 0.0,
                boxes=[(-15, -6, 30, 72, STEEL)], dots=[(0, 0, 13, STEEL_DARK)], children=[shin])


def robot() -> Part:
    head = Part("head", (0.0, -150.0), 0.0,
                boxes=[(-9, -22, 18, 24, STEEL_DARK), (-46, -98, 92, 78, STEEL), (-30, -76, 60, 26, INK)],
                dots=[(-15, -63, 7, ACCENT), (15, -63, 7, ACCENT), (0, -122, 7, "#e04040")],
                lines=[([(0, -98), (0, -116)], INK, 3), ([(-18, -34), (18, -34)], INK, 3)])
    body = Part("body", ROOT_POSITION, 0.0,
                boxes=[(-62, -152, 124, 140, STEEL), (-38, -126, 76, 60, STEEL_DARK), (-42, -14, 84, 18, INK)],
                dots=[(-20, -96, 8, "#40c070"), (0, -96, 8, ACCENT), (20, -96, 8, "#e04040")],
                lines=[([(-30, -56), (30, -56)], INK, 3), ([(-30, -44), (30, -44)], INK, 3)],
                children=[_leg("left", -28.0), _leg("right", 28.0), head,
                          _arm("left", -76.0), _arm("right", 76.0)])
    return body


# ---------------------------------------------------------------- the stack walk
def _walk(stack: MatrixStack, part: Part, angles: dict[str, float], visit) -> None:  # type: ignore[no-untyped-def]
    stack.push()
    stack.translate(part.pivot[0], part.pivot[1], 0.0)
    stack.rotate_z(-(part.rest + angles.get(part.name, 0.0)))
    visit(part, stack)
    for child in part.children:
        _walk(stack, child, angles, visit)
    stack.pop()


def _xy(stack: MatrixStack, points: list[tuple[float, float]]) -> list[tuple[float, float]]:
    p = np.array([[x, y, 0.0] for x, y in points], dtype=np.float64)
    return [(float(x), float(y)) for x, y, _ in stack.transform_points(p)]


def stack_pivots(angles: dict[str, float] | None = None,
                 translation: tuple[float, float] = (0.0, 0.0)) -> dict[str, tuple[float, float]]:
    """World pivot of every part with the given joint angles, computed on the matrix stack."""
    out: dict[str, tuple[float, float]] = {}
    stack = MatrixStack(16)
    stack.translate(translation[0], translation[1], 0.0)

    def visit(part: Part, st: MatrixStack) -> None:
        out[part.name] = _xy(st, [(0.0, 0.0)])[0]

    _walk(stack, robot(), angles or {}, visit)
    return out


def rig() -> JointSpec:
    """The rest pose as rig joints (shapes in world coordinates, from the stack)."""
    specs: dict[str, JointSpec] = {}
    parents: dict[str, str] = {}
    for p in robot().walk():
        for c in p.children:
            parents[c.name] = p.name

    def visit(part: Part, st: MatrixStack) -> None:
        shapes = []
        for x, y, w, h, fill in part.boxes:
            shapes.append(polygon(_xy(st, [(x, y), (x + w, y), (x + w, y + h), (x, y + h)]), fill, INK, 2))
        for pts, fill in part.polys:
            shapes.append(polygon(_xy(st, pts), fill, INK, 1.5))
        for pts, colour, width in part.lines:
            shapes.append(polyline(_xy(st, pts), colour, width))
        for x, y, r, fill in part.dots:
            (cx, cy), = _xy(st, [(x, y)])
            shapes.append(circle(cx, cy, r, fill, INK, 1.5))
        spec = JointSpec(part.name, _xy(st, [(0.0, 0.0)])[0], shapes)
        specs[part.name] = spec
        if part.name in parents:
            specs[parents[part.name]].children.append(spec)

    _walk(MatrixStack(16), robot(), {}, visit)
    return specs["body"]


# ---------------------------------------------------------------- linear keys
#: The lecture's key arrays, {channel id: [(time, value), ...]}; one period each, cycled.
#: Channel ids are the document's: ``robot//x`` is the character's translation, ``robot/J/angle``
#: joint J's angle (the asset id is the SVG's stem, ``robot``).
#: Angles in radians (rig convention), positions in SVG units from the rest pose.
KEYS: dict[str, list[tuple[float, float]]] = {
    "robot//x": [(0.0, -140.0), (2.0, 140.0), (4.0, -140.0)],                  # slide left and right
    "robot//y": [(0.0, 0.0), (0.5, -14.0), (1.0, 0.0), (1.5, -14.0), (2.0, 0.0)],  # bob on each step
    "robot/body/angle": [(0.0, 0.05), (1.0, -0.05), (2.0, 0.05)],
    "robot/head/angle": [(0.0, -0.15), (0.5, 0.0), (1.0, 0.15), (1.5, 0.0), (2.0, -0.15)],
    "robot/leg_left/angle": [(0.0, 0.0), (0.5, -0.35), (1.0, 0.0), (2.0, 0.0)],   # side steps
    "robot/shin_left/angle": [(0.0, 0.0), (0.5, 0.35), (1.0, 0.0), (2.0, 0.0)],
    "robot/leg_right/angle": [(0.0, 0.0), (1.0, 0.0), (1.5, 0.35), (2.0, 0.0)],
    "robot/shin_right/angle": [(0.0, 0.0), (1.0, 0.0), (1.5, -0.35), (2.0, 0.0)],
    "robot/arm_left/angle": [(0.0, -0.3), (1.0, -1.3), (2.0, -0.3)],            # arms pump in turn
    "robot/forearm_left/angle": [(0.0, -0.2), (1.0, -1.1), (2.0, -0.2)],
    "robot/claw_left/angle": [(0.0, 0.0), (0.5, 0.4), (1.0, 0.0), (1.5, -0.4), (2.0, 0.0)],
    "robot/arm_right/angle": [(0.0, 1.3), (1.0, 0.3), (2.0, 1.3)],
    "robot/forearm_right/angle": [(0.0, 1.1), (1.0, 0.2), (2.0, 1.1)],
    "robot/claw_right/angle": [(0.0, 0.0), (0.5, -0.4), (1.0, 0.0), (1.5, 0.4), (2.0, 0.0)],
}


def eval_keys(keys: list[tuple[float, float]], time: float) -> float:
    """The lecture's ``eval(keyData, time % period)``: piecewise linear, clamped at the ends."""
    t0, tn = keys[0][0], keys[-1][0]
    t = t0 + (time - t0) % (tn - t0)
    if t <= t0:
        return keys[0][1]
    for (ta, va), (tb, vb) in zip(keys, keys[1:]):
        if t <= tb:
            return va + (vb - va) * (t - ta) / (tb - ta)
    return keys[-1][1]


def pose_at(time: float) -> tuple[dict[str, float], tuple[float, float]]:
    """Joint angles and translation at ``time`` from :data:`KEYS` (the lecture's animate)."""
    angles = {cid.split("/")[1]: eval_keys(k, time) for cid, k in KEYS.items() if cid.endswith("/angle")}
    return angles, (eval_keys(KEYS["robot//x"], time), eval_keys(KEYS["robot//y"], time))


def build_project(svg: Path):  # type: ignore[no-untyped-def]
    from qtanimator.core.channel import Channel, Extrapolation, Interpolation, Key, Tangent
    from qtanimator.document import Document, SetChannels
    from qtanimator.document.character2d import add_characters_command

    doc = Document(parameters={"fps": FPS, "frame_start": 0, "frame_end": int(2 * PERIOD * FPS)})
    add_characters_command(doc, svg).do(doc)
    changes = {}
    for cid, keys in KEYS.items():
        channel = Channel([Key(t, v, Tangent.LINEAR, Tangent.LINEAR, interpolation=Interpolation.LINEAR)
                           for t, v in keys], Extrapolation.CYCLE, Extrapolation.CYCLE)
        changes[cid] = (None, channel)
    SetChannels("Robot walk (linear keys)", changes).do(doc)
    return doc


def write(out: Path) -> list[Path]:
    from qtanimator.document import save_document

    out.mkdir(parents=True, exist_ok=True)
    svg = out / "robot.svg"
    note = ("Robo, a nested mechanical figure for qtanimator (CC0), built on the matrix stack by "
            "scenes/tools/make_robot.py (push, translate, rotate_z, pop per part). Animated with "
            "linear keys in robot.qtanim.")
    svg.write_text(document(rig(), 600.0, 560.0, note), encoding="utf-8", newline="\n")
    project = out / "robot.qtanim"
    save_document(build_project(svg), project)
    return [svg, project]


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description="Build the matrix-stack robot (SVG rig + linear-key project).")
    ap.add_argument("--out", type=Path, default=OUT, help="output folder (default: scenes/robot/)")
    ns = ap.parse_args(argv)
    for p in write(ns.out):
        print(f"wrote {p}")
    print("rest pivots:", {k: (num(x), num(y)) for k, (x, y) in stack_pivots().items()})


if __name__ == "__main__":
    main()
