"""Small sample files written by tests in more than one folder (tests/conftest.py puts
this folder on the import path)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

#: Blender-style BVH: 6 channels per joint, the root's first position equal to its OFFSET
#: (absolute positions), two frames.
BLENDER_BVH = """HIERARCHY
ROOT Hips
{
  OFFSET 0 10 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Leg
  {
    OFFSET 0 -5 0
    CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 -5 0
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.1
0 10 0 0 0 0 0 -5 0 10 0 0
1 10 0 0 0 0 0 -5 0 20 0 0
"""


#: A plain drawing: the first element is a <path>, the first layer is empty, then three
#: layers (body 40x80 at (50, 50), arm 60x10 at (90, 60), hat 20x10 at (60, 30)).
PLAIN_DRAWING = """<svg xmlns="http://www.w3.org/2000/svg"
 xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" width="200" height="200">
<path d="M10 10 L30 10 L30 30 Z" fill="red"/>
<g inkscape:groupmode="layer" inkscape:label="Empty" id="layer0"/>
<g inkscape:groupmode="layer" inkscape:label="Body" id="layer1">
<rect x="50" y="50" width="40" height="80" fill="blue"/></g>
<g inkscape:groupmode="layer" inkscape:label="Arm"><rect x="90" y="60" width="60" height="10" fill="green"/></g>
<g inkscape:groupmode="layer" inkscape:label="Hat" id="layer3">
<rect x="60" y="30" width="20" height="10" fill="black"/></g>
</svg>
"""


def write_bvh(path: Path, frames: int, frame_time: str = "0.00833333") -> Path:
    """A two-joint BVH whose root moves and turns every frame."""
    rows = []
    for k in range(frames):
        rows.append(f"{k * 0.5:g} {10 + np.sin(k / 3):.6f} {-k * 0.25:g} {k * 1.5:g} {k * -0.75:g} {k * 2.0:g} "
                    f"{k * 3.0:g} 0 {k * -1.0:g}")
    path.write_text(
        "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n"
        "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
        "  JOINT Chest\n  {\n    OFFSET 0 5 0\n    CHANNELS 3 Zrotation Xrotation Yrotation\n"
        "    End Site\n    {\n      OFFSET 0 4 0\n    }\n  }\n}\n"
        f"MOTION\nFrames: {frames}\nFrame Time: {frame_time}\n" + "\n".join(rows) + "\n")
    return path
