"""Regenerate ``scenes/demo/demo.qtanim`` (run: ``.venv/bin/python scenes/make_demo.py``).

The demo project combines the bundled scenes:

* 2D (the rig editor): Pip (``scenes/demo/pip.svg``: a waving character carrying a lantern
  on a two-link chain, a coupled double pendulum, and wearing a pendulum earring), the
  pendulum clock (``scenes/pendulum_clock.svg``) and Robo (``scenes/robot/robot.svg``) with
  the linear-key walk of ``scenes/robot/robot.qtanim``, moved to the right of the clock;
* 3D (the viewport): the skinned arm of ``scenes/arm3d`` with its ``arm_wave.anim`` loop, and
  a small flag (a mass-spring cloth pinned along its left edge) in a gusty wind, to the
  arm's left so it never hides it; and Walker (``scenes/walker``, made by
  ``scenes/tools/make_walker.py``) walking across the front in a cape pinned to its chest
  (a cloth whose ``attach`` names the ``chest`` joint; it collides with capsules around the bones).

Saved through ``save_document`` so the file is exactly what the program writes; the asset
sources are stored relative to ``scenes/demo/``.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

from qtanimator.core.channel import Key
from qtanimator.core.cloth import ClothParams, pins_from_cells
from qtanimator.document import Document, SetChannels, SetKeys, SetParameter, open_document, save_document
from qtanimator.document.character2d import add_characters_command, angle_channel_id, position_channel_ids
from qtanimator.document.character3d import add_character3d_command
from qtanimator.document.cloth import add_cloth_command
from qtanimator.document.cloth_attach import ATTACH
from qtanimator.document.commands import SetAssetProperty

HERE = Path(__file__).resolve().parent
FPS = 60.0
ROBOT_SHIFT = 1130.0  # Robo's rest hip is at x = 300 in robot.svg; walk it right of the clock
FLAG_ROWS, FLAG_COLS = 16, 24
FLAG_WIDTH = 1.5
#: The saved 3D camera: from the front, a little above, the flag on the left, the arm right,
#: Walker and its cape in front.
VIEW3D_CAMERA = {"azimuth": 15.0, "inclination": 12.0, "distance": 6.8,
                 "target": [-0.2, 1.5, 0.4], "fov_y": 45.0}
CAPE_ROWS, CAPE_COLS = 14, 10
CAPE_WIDTH, CAPE_HEIGHT = 0.46, 0.85


def flag_params() -> ClothParams:
    """A light 1.5 m × 1.0 m flag (16 × 24 particles) whose pinned left edge stands at
    x = −2.9, left of the arm, flying towards +x in a steady breeze with mild gusts."""
    return ClothParams(
        integrator="symplectic",
        rows=FLAG_ROWS, cols=FLAG_COLS, width=FLAG_WIDTH, height=1.0, total_mass=0.35,
        structural_stiffness=150.0, structural_damping=0.15,
        shear_stiffness=60.0, shear_damping=0.08,
        bend_stiffness=4.0, bend_damping=0.02,
        drag_coefficient=1.0, air_density=1.225,
        wind=(8.5, 0.0, 0.6), turbulence=0.12, turbulence_seed=11,
        ground_enabled=True, ground_height=0.0,
        pin_mode="custom", custom_pins=pins_from_cells(FLAG_COLS, [(r, 0) for r in range(FLAG_ROWS)]),
        substeps=32, origin=(-2.9 + FLAG_WIDTH / 2, 2.7, -0.3), orientation=(0.0, 0.0, 0.0),
    )


def cape_params() -> ClothParams:
    """A 0.46 m × 0.85 m cape (14 × 10 particles, 0.3 kg) whose top edge is pinned across
    Walker's back, 0.19 m behind its chest joint at frame 0 (Walker faces +x from x = −0.6,
    z = 1.2); implicit integrator, automatic steps."""
    return ClothParams(
        rows=CAPE_ROWS, cols=CAPE_COLS, width=CAPE_WIDTH, height=CAPE_HEIGHT, total_mass=0.3,
        structural_stiffness=300.0, shear_stiffness=120.0, bend_stiffness=6.0,
        structural_damping=0.2, shear_damping=0.1, bend_damping=0.02,
        ground_enabled=True, ground_height=0.0, collision_margin=0.01,
        pin_mode="top_edge", origin=(-0.6 - 0.19, 1.5, 1.2), orientation=(0.0, math.pi / 2, 0.0),
    )


def add_robot(doc: Document) -> None:
    """Robo and the channels of ``scenes/robot/robot.qtanim`` (its x keys shifted right)."""
    add_characters_command(doc, HERE / "robot" / "robot.svg").do(doc)
    walk = open_document(HERE / "robot" / "robot.qtanim")
    changes = {}
    for cid, channel in walk.channels.items():
        if cid == position_channel_ids("robot")[0]:
            channel = channel.with_keys([replace(k, value=k.value + ROBOT_SHIFT) for k in channel.keys])
        changes[cid] = (None, channel)
    SetChannels("Robot walk (linear keys)", changes).do(doc)


def build() -> Document:
    doc = Document(parameters={"fps": FPS, "frame_start": 0, "frame_end": 240})
    add_characters_command(doc, HERE / "demo" / "pip.svg").do(doc)
    add_characters_command(doc, HERE / "pendulum_clock.svg").do(doc)

    tracks: dict[str, list[tuple[float, float]]] = {
        angle_channel_id("pip", "upper_arm_right"): [(0, 0.0), (1, 0.6), (2, -0.3), (3, 0.5), (4, 0.0)],
        angle_channel_id("pip", "forearm_right"): [(0, 0.0), (1, 0.7), (2, 0.2), (3, 0.9), (4, 0.0)],
        angle_channel_id("pip", "upper_arm_left"): [(0, 0.0), (1.5, -0.8), (3, -0.2), (4, 0.0)],
        angle_channel_id("pip", "forearm_left"): [(0, 0.0), (1.5, -0.9), (3, -0.3), (4, 0.0)],
        angle_channel_id("pip", "head"): [(0, 0.0), (1, 0.15), (2.5, -0.15), (4, 0.0)],
        angle_channel_id("pip", "leg_left"): [(0, 0.0), (1, -0.25), (2, 0.2), (3, -0.25), (4, 0.0)],
        angle_channel_id("pip", "leg_right"): [(0, 0.0), (1, 0.2), (2, -0.25), (3, 0.2), (4, 0.0)],
        position_channel_ids("pip")[0]: [(0, 0.0), (2, 140.0), (4, 0.0)],
        position_channel_ids("pip")[1]: [(0, 0.0), (0.5, -25.0), (1, 0.0), (2.5, -25.0), (3, 0.0)],
        position_channel_ids("pendulum_clock")[0]: [(0, 700.0)],
        position_channel_ids("pendulum_clock")[1]: [(0, -60.0)],
        angle_channel_id("pendulum_clock", "minute_hand"): [(0, 0.0), (4, -2 * math.pi)],
        angle_channel_id("pendulum_clock", "hour_hand"): [(0, 0.0), (4, -2 * math.pi / 12)],
    }
    for cid, values in tracks.items():
        for t, v in values:
            SetKeys(doc, {cid: Key(float(t), float(v))}).do(doc)
    SetParameter(doc, "pip.pendulum.damping", 0.4).do(doc)
    add_robot(doc)

    arm = HERE / "arm3d"
    add_character3d_command(doc, arm / "arm.skel", arm / "arm.skin", arm / "arm_wave.anim", asset_id="arm").do(doc)
    add_cloth_command(doc, flag_params(), asset_id="flag").do(doc)
    walker = HERE / "walker"
    add_character3d_command(doc, walker / "walker.skel", walker / "walker.skin", walker / "walker_walk.anim",
                            asset_id="walker").do(doc)
    add_cloth_command(doc, cape_params(), asset_id="cape").do(doc)
    SetAssetProperty(doc, "cape", ATTACH, {"asset": "walker", "joint": "chest"}, text="Attach the cape").do(doc)
    # The 3D view opens on the flag and the arm (view state, as the program saves it).
    doc.set_view_state("view3d.camera", dict(VIEW3D_CAMERA))
    return doc


def main() -> None:
    doc = build()
    save_document(doc, HERE / "demo" / "demo.qtanim")
    print(f"wrote {HERE / 'demo' / 'demo.qtanim'}")


if __name__ == "__main__":
    main()
