"""Small sample files written by tests in more than one folder (tests/conftest.py puts
this folder on the import path)."""

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
