"""Regenerate ``scenes/demo/demo.qtanim`` (run: ``.venv/bin/python scenes/make_demo.py``).

The demo project holds Pip (``scenes/demo/pip.svg``: a waving character carrying a lantern
on a two-link chain, a coupled double pendulum, and wearing a pendulum earring) and the
pendulum clock (``scenes/pendulum_clock.svg``). Saved through ``save_document`` so the file
is exactly what the program writes.
"""

from __future__ import annotations

import math
from pathlib import Path

from qtanimator.core.channel import Key
from qtanimator.document import Document, SetKeys, SetParameter, save_document
from qtanimator.document.character2d import add_characters_command, angle_channel_id, position_channel_ids

HERE = Path(__file__).resolve().parent
FPS = 60.0


def build() -> Document:
    doc = Document()
    doc.parameters.update({"fps": FPS, "frame_start": 0, "frame_end": 240})
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
    return doc


def main() -> None:
    doc = build()
    save_document(doc, HERE / "demo" / "demo.qtanim")
    print(f"wrote {HERE / 'demo' / 'demo.qtanim'}")


if __name__ == "__main__":
    main()
