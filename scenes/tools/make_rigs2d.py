"""Write the hand-designed 2D rig scenes (run: ``.venv/bin/python scenes/tools/make_rigs2d.py``).

Files (in ``scenes/``, or in ``--out DIR``):

* ``telescope_chain.svg`` — a base and six nested telescope tubes, each the child of the one
  below: a long keyframed chain for trying inverse kinematics (right-drag the tip).
* ``flappy.svg`` — Flappy, a full character (torso, head, two-link arms and legs) with four
  pendulum joints: two floppy ears and a two-link ponytail, drawn off their rest angle so
  they swing from the first frame.
* ``pencil.svg`` — a pencil whose pivot is its graphite tip, so moving the character moves
  the tip: made for path animation.
* ``flappy_hop.qtanim`` — Flappy hops, waves and shakes her head in a one-second loop; the
  ears and the ponytail are not keyed: they swing by physics.
* ``pencil_path.qtanim`` — a project in which the pencil writes a loop: its position
  channels (``pencil//x``, ``pencil//y``) follow the path with smooth keys, and the root
  angle leans with the stroke.

Every rig follows the rules in ``svgwriter.py``. The output is deterministic (no dates, at
most three decimals), and ``tests/test_scenes.py`` checks that running this script again
reproduces the committed files byte for byte.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from svgwriter import (  # noqa: E402
    JointSpec,
    circle,
    document,
    ellipse,
    path,
    polygon,
    polyline,
    rect,
    rotate_points,
)

SCENES = HERE.parent
INK = "#2b2b2b"


# ------------------------------------------------------------------ telescope
def telescope() -> tuple[JointSpec, float, float]:
    cx = 180.0
    base = JointSpec("base", (cx, 560.0), [
        rect(80, 596, 200, 22, "#3d3d46", INK, 2, rx=6),
        polygon([(130, 598), (150, 548), (210, 548), (230, 598)], "#5a5a66", INK, 2),
        circle(cx, 560, 20, "#8a8a99", INK, 2),
    ])
    widths = [58.0, 50.0, 42.0, 35.0, 29.0, 24.0]
    heights = [104.0, 92.0, 80.0, 70.0, 60.0, 52.0]
    colours = ["#b5651d", "#c07a2c", "#c98f3c", "#d2a44f", "#d8b866", "#dfcb80"]
    parent = base
    y = 560.0  # pivot of the next tube
    for k, (w, h, col) in enumerate(zip(widths, heights, colours), start=1):
        top = y - h
        shapes = [
            rect(cx - w / 2, top, w, h + 10, col, INK, 2, rx=4),
            rect(cx - w / 2 + 5, top + 6, w * 0.18, h - 4, "#fff3d6", opacity=0.35),
            rect(cx - w / 2 - 3, top, w + 6, 12, "#6b4a1f", INK, 1.5, rx=3),
        ]
        if k == len(widths):
            shapes += [ellipse(cx, top - 4, w / 2 + 6, 9, "#2f5f8f", INK, 2),
                       ellipse(cx, top - 6, w / 2 - 2, 5, "#9fd3ff")]
        tube = JointSpec(f"tube{k}", (cx, y), shapes)
        parent.children.append(tube)
        parent = tube
        y = top + 12.0
    return base, 360.0, 640.0


# ------------------------------------------------------------------ pencil
PENCIL_TIP = (150.0, 470.0)
PENCIL_TILT = math.radians(55.0)  # the body leans up and to the right of the tip


def pencil() -> tuple[JointSpec, float, float]:
    tx, ty = PENCIL_TIP
    half = 15.0

    def along(points: list[tuple[float, float]]) -> list[tuple[float, float]]:
        # Designed lying along +x from the tip at the origin, then lifted to the writing angle.
        return rotate_points([(tx + x, ty + y) for x, y in points], PENCIL_TILT, PENCIL_TIP)

    shapes = [
        polygon(along([(0, 0), (16, -4.5), (16, 4.5)]), "#333333", INK, 1),                     # graphite
        polygon(along([(16, -4.5), (56, -half), (56, half), (16, 4.5)]), "#e8c49a", INK, 1.5),   # wood
        polygon(along([(56, -half), (286, -half), (286, -5), (56, -5)]), "#f7d154", INK, 1.5),
        polygon(along([(56, -5), (286, -5), (286, 5), (56, 5)]), "#f2c230", INK, 1.5),
        polygon(along([(56, 5), (286, 5), (286, half), (56, half)]), "#d9a61a", INK, 1.5),
        polygon(along([(286, -half - 1), (318, -half - 1), (318, half + 1), (286, half + 1)]),
                "#b8bcc4", INK, 1.5),                                                          # ferrule
        polyline(along([(296, -half - 1), (296, half + 1)]), "#7d828c", 2),
        polyline(along([(308, -half - 1), (308, half + 1)]), "#7d828c", 2),
        path("M {} {} L {} {} Q {} {} {} {} L {} {} Z".format(*(
            f"{v:.3f}".rstrip("0").rstrip(".") for v in _flat(along(
                [(318, -half), (338, -half), (352, 0), (338, half), (318, half)])))),
            "#f28da0", INK, 1.5),                                                              # eraser
    ]
    return JointSpec("pencil", PENCIL_TIP, shapes), 600.0, 560.0


def _flat(points: list[tuple[float, float]]) -> list[float]:
    return [v for p in points for v in p]


# ------------------------------------------------------------------ flappy
SKIN = "#f5c9a3"
COAT = "#3d7bd9"
COAT_DARK = "#2b5ca8"
HAIR = "#8a4b1f"


def _limb(x0: float, y0: float, x1: float, y1: float, r0: float, r1: float) -> list[tuple[float, float]]:
    """A tapered limb outline from (x0, y0) to (x1, y1) with round-ish ends (a polygon)."""
    dx, dy = x1 - x0, y1 - y0
    n = math.hypot(dx, dy)
    ux, uy = dx / n, dy / n
    px, py = -uy, ux
    out: list[tuple[float, float]] = []
    for i in range(7):  # half circle around the far end
        a = math.pi * i / 6
        c, s = math.cos(a), math.sin(a)
        out.append((x1 + r1 * (px * c + ux * s), y1 + r1 * (py * c + uy * s)))
    for i in range(7):  # half circle around the near end
        a = math.pi + math.pi * i / 6
        c, s = math.cos(a), math.sin(a)
        out.append((x0 + r0 * (px * c + ux * s), y0 + r0 * (py * c + uy * s)))
    return out


def _ear(px: float, py: float, side: float) -> list[str]:
    # A long floppy ear hanging 25 degrees outward from the pivot, drawn as a curved path.
    tip = rotate_points([(px, py + 118)], side * math.radians(25), (px, py))[0]
    mid_out = rotate_points([(px + side * 22, py + 60)], side * math.radians(25), (px, py))[0]
    mid_in = rotate_points([(px - side * 16, py + 64)], side * math.radians(25), (px, py))[0]
    d = (f"M {px - side * 10:.3f} {py - 6:.3f} "
         f"Q {mid_out[0]:.3f} {mid_out[1] - 30:.3f} {mid_out[0]:.3f} {mid_out[1]:.3f} "
         f"Q {tip[0] + side * 12:.3f} {tip[1]:.3f} {tip[0]:.3f} {tip[1]:.3f} "
         f"Q {mid_in[0]:.3f} {mid_in[1] + 20:.3f} {mid_in[0]:.3f} {mid_in[1]:.3f} "
         f"Q {px - side * 14:.3f} {py + 20:.3f} {px - side * 10:.3f} {py - 6:.3f} Z")
    inner = rotate_points([(px + side * 2, py + 20), (px + side * 10, py + 62), (px, py + 100),
                           (px - side * 6, py + 60)], side * math.radians(25), (px, py))
    return [path(d.replace(".000", ""), HAIR, INK, 2), polygon(inner, "#c27a48")]


def flappy() -> tuple[JointSpec, float, float]:
    cx = 210.0
    torso = JointSpec("torso", (cx, 392.0), [
        path(f"M {cx - 58} 270 Q {cx} 250 {cx + 58} 270 L {cx + 66} 400 Q {cx} 420 {cx - 66} 400 Z",
             COAT, INK, 2.5),
        polygon([(cx - 6, 268), (cx + 6, 268), (cx + 4, 404), (cx - 4, 404)], COAT_DARK),
        circle(cx, 300, 5, "#ffd84d", INK, 1), circle(cx, 330, 5, "#ffd84d", INK, 1),
        circle(cx, 360, 5, "#ffd84d", INK, 1),
        rect(cx - 66, 384, 132, 16, "#5a3a1a", INK, 2, rx=4),
    ])
    head = JointSpec("head", (cx, 262.0), [
        rect(cx - 14, 238, 28, 30, SKIN, INK, 2),
        circle(cx, 190, 64, SKIN, INK, 2.5),
        path(f"M {cx - 64} 186 Q {cx - 60} 118 {cx} 122 Q {cx + 60} 118 {cx + 64} 186 "
             f"Q {cx + 30} 150 {cx} 156 Q {cx - 30} 150 {cx - 64} 186 Z", HAIR, INK, 2),
        ellipse(cx - 22, 192, 9, 12, "#ffffff", INK, 1.5), ellipse(cx + 22, 192, 9, 12, "#ffffff", INK, 1.5),
        circle(cx - 20, 195, 5, INK), circle(cx + 20, 195, 5, INK),
        ellipse(cx, 212, 8, 6, "#e0785a", INK, 1.5),
        path(f"M {cx - 22} 228 Q {cx} 246 {cx + 22} 228", "none", INK, 2.5),
        circle(cx - 40, 220, 9, "#f59a9a", opacity=0.6), circle(cx + 40, 220, 9, "#f59a9a", opacity=0.6),
    ])
    ear_l = JointSpec("ear_left", (cx - 56.0, 158.0), _ear(cx - 56.0, 158.0, -1.0), dynamic=True)
    ear_r = JointSpec("ear_right", (cx + 56.0, 158.0), _ear(cx + 56.0, 158.0, 1.0), dynamic=True)
    # The ponytail: two pendulum links, the first tied at the back of the head.
    tail1 = JointSpec("ponytail", (cx + 50.0, 136.0), [
        polygon(_limb(cx + 50, 136, cx + 96, 176, 11, 13), HAIR, INK, 2),
        circle(cx + 50, 136, 9, "#e84a5f", INK, 1.5),
    ], dynamic=True)
    tail2 = JointSpec("ponytail_tip", (cx + 96.0, 176.0), [
        polygon(_limb(cx + 96, 176, cx + 126, 236, 13, 6), HAIR, INK, 2),
    ], dynamic=True)
    tail1.children.append(tail2)
    head.children += [ear_l, ear_r, tail1]

    def arm(side: float) -> JointSpec:
        sx, ex, hx = cx + side * 58, cx + side * 82, cx + side * 92
        upper = JointSpec(f"upper_arm_{'left' if side < 0 else 'right'}", (sx, 282.0), [
            polygon(_limb(sx, 282, ex, 340, 15, 12), COAT, INK, 2)])
        fore = JointSpec(f"forearm_{'left' if side < 0 else 'right'}", (ex, 340.0), [
            polygon(_limb(ex, 340, hx, 396, 12, 10), COAT, INK, 2),
            circle(hx + side * 2, 404, 14, SKIN, INK, 2)])
        upper.children.append(fore)
        return upper

    def leg(side: float) -> JointSpec:
        hx, kx, fx = cx + side * 30, cx + side * 34, cx + side * 36
        thigh = JointSpec(f"thigh_{'left' if side < 0 else 'right'}", (hx, 400.0), [
            polygon(_limb(hx, 400, kx, 470, 20, 16), "#404a5c", INK, 2)])
        shin = JointSpec(f"shin_{'left' if side < 0 else 'right'}", (kx, 470.0), [
            polygon(_limb(kx, 470, fx, 536, 16, 13), "#404a5c", INK, 2),
            path(f"M {fx - 18} 530 Q {fx + side * 30} 520 {fx + side * 46} 546 L {fx - side * 16} 552 Z"
                 , "#c0392b", INK, 2)])
        thigh.children.append(shin)
        return thigh

    torso.children += [leg(-1.0), leg(1.0), head, arm(-1.0), arm(1.0)]
    return torso, 420.0, 600.0


# ------------------------------------------------------------------ projects
def pencil_project(out: Path) -> None:
    """The pencil writing a loop: smooth position keys along the path, the body leaning."""
    from qtanimator.core.channel import Channel, Extrapolation, Key
    from qtanimator.document import Document, SetChannels, save_document
    from qtanimator.document.character2d import add_characters_command, angle_channel_id, position_channel_ids

    doc = Document(parameters={"fps": 60.0, "frame_start": 0, "frame_end": 240})
    add_characters_command(doc, out / "pencil.svg").do(doc)
    # A loop-the-loop signature: offsets from the rest position of the tip, every 0.4 s.
    path_xy = [(0, 0), (60, -40), (120, 10), (90, 60), (40, 20), (110, -30), (190, -10), (230, 40),
               (180, 70), (150, 20), (240, -20), (320, 0)]
    lean = [0.0, 0.12, 0.05, -0.1, -0.05, 0.1, 0.12, 0.0, -0.12, -0.04, 0.1, 0.0]
    cx, cy = position_channel_ids("pencil")
    xs = Channel([Key(0.4 * i, float(x)) for i, (x, _) in enumerate(path_xy)], Extrapolation.CONSTANT,
                 Extrapolation.CONSTANT)
    ys = Channel([Key(0.4 * i, float(y)) for i, (_, y) in enumerate(path_xy)])
    ang = Channel([Key(0.4 * i, a) for i, a in enumerate(lean)])
    SetChannels("Pencil path", {cx: (None, xs), cy: (None, ys),
                                angle_channel_id("pencil", "pencil"): (None, ang)}).do(doc)
    save_document(doc, out / "pencil_path.qtanim")


def flappy_project(out: Path) -> None:
    """Flappy hops and shakes her head; the ears and the ponytail follow by physics."""
    from qtanimator.core.channel import Channel, Extrapolation, Key
    from qtanimator.document import Document, SetChannels, SetParameter, save_document
    from qtanimator.document.character2d import add_characters_command, angle_channel_id, position_channel_ids

    doc = Document(parameters={"fps": 60.0, "frame_start": 0, "frame_end": 240})
    add_characters_command(doc, out / "flappy.svg").do(doc)
    cycle = Extrapolation.CYCLE
    tracks = {
        position_channel_ids("flappy")[1]: [(0, 0.0), (0.25, -35.0), (0.5, 0.0), (1.0, 0.0)],
        angle_channel_id("flappy", "head"): [(0, 0.0), (0.3, 0.25), (0.6, -0.25), (1.0, 0.0)],
        angle_channel_id("flappy", "upper_arm_left"): [(0, 0.0), (0.25, -1.6), (0.5, -0.3), (1.0, 0.0)],
        angle_channel_id("flappy", "forearm_left"): [(0, 0.0), (0.25, -0.6), (1.0, 0.0)],
        angle_channel_id("flappy", "upper_arm_right"): [(0, 0.0), (0.25, 1.6), (0.5, 0.3), (1.0, 0.0)],
        angle_channel_id("flappy", "forearm_right"): [(0, 0.0), (0.25, 0.6), (1.0, 0.0)],
        angle_channel_id("flappy", "thigh_left"): [(0, 0.0), (0.25, -0.3), (0.5, 0.0), (1.0, 0.0)],
        angle_channel_id("flappy", "thigh_right"): [(0, 0.0), (0.25, 0.3), (0.5, 0.0), (1.0, 0.0)],
    }
    changes = {cid: (None, Channel([Key(float(t), v) for t, v in keys], cycle, cycle)) for cid, keys in tracks.items()}
    SetChannels("Flappy hops", changes).do(doc)
    SetParameter(doc, "flappy.pendulum.damping", 2.0).do(doc)  # hair and ears settle between hops
    save_document(doc, out / "flappy_hop.qtanim")


def write(out: Path) -> list[Path]:
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for name, build, note in (
        ("telescope_chain.svg", telescope,
         "A telescope-style chain for qtanimator (CC0): a base and six nested tubes, each the child of "
         "the one below. Right-drag the tip to try inverse kinematics. Generated by scenes/tools/make_rigs2d.py."),
        ("flappy.svg", flappy,
         "Flappy, a full character for qtanimator (CC0). White pivot circles make the ears and the two "
         "ponytail links pendulums. Generated by scenes/tools/make_rigs2d.py."),
        ("pencil.svg", pencil,
         "A pencil for path animation in qtanimator (CC0): its pivot is the graphite tip, so moving the "
         "character moves the tip. Generated by scenes/tools/make_rigs2d.py."),
    ):
        root, w, h = build()
        p = out / name
        p.write_text(document(root, w, h, note), encoding="utf-8", newline="\n")
        written.append(p)
    pencil_project(out)
    flappy_project(out)
    written += [out / "pencil_path.qtanim", out / "flappy_hop.qtanim"]
    return written


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=SCENES, help="output folder (default: scenes/)")
    ns = ap.parse_args(argv)
    for p in write(ns.out):
        print(f"wrote {p}")


if __name__ == "__main__":
    main()
