"""A tiny, deterministic SVG writer for the scene generators in this folder.

It writes rig SVGs by the qtanimator rig rules (``docs`` and ``notes/cmu-animator.md`` §2):

* the first top-level element of the ``<svg>`` is the character: one group of joints;
* in a group of joints the first is the parent and the rest are its children: a joint with
  children is ``<g id=NAME> <g> own shapes… pivot </g> child… </g>``, a leaf joint is
  ``<g id=NAME> shapes… pivot </g>``;
* a joint's last element is a ``<circle>`` whose centre is the pivot; a white (``#ffffff``)
  fill makes the joint dynamic (a pendulum), anything else keyframed.

A leaf joint must never start with a ``<g>`` (that would make it a parent), so shapes are
always plain elements here. Numbers are written with at most three decimals, so running a
generator twice gives byte-identical files.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

Point = tuple[float, float]


def num(v: float) -> str:
    """A number with at most three decimals, no trailing zeros, never ``-0``."""
    text = f"{float(v):.3f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def pts(points: Iterable[Point]) -> str:
    return " ".join(f"{num(x)},{num(y)}" for x, y in points)


def style(fill: str, stroke: str | None = None, width: float | None = None, opacity: float | None = None) -> str:
    out = f'fill="{fill}"'
    if stroke is not None:
        out += f' stroke="{stroke}" stroke-width="{num(1.0 if width is None else width)}"'
        out += ' stroke-linejoin="round"'
    if opacity is not None:
        out += f' opacity="{num(opacity)}"'
    return out


def rect(x: float, y: float, w: float, h: float, fill: str, stroke: str | None = None,
         width: float | None = None, rx: float = 0.0, opacity: float | None = None) -> str:
    r = f' rx="{num(rx)}"' if rx > 0 else ""
    return (f'<rect x="{num(x)}" y="{num(y)}" width="{num(w)}" height="{num(h)}"{r} '
            f'{style(fill, stroke, width, opacity)}/>')


def circle(cx: float, cy: float, r: float, fill: str, stroke: str | None = None, width: float | None = None,
           opacity: float | None = None) -> str:
    return f'<circle cx="{num(cx)}" cy="{num(cy)}" r="{num(r)}" {style(fill, stroke, width, opacity)}/>'


def ellipse(cx: float, cy: float, rx: float, ry: float, fill: str, stroke: str | None = None,
            width: float | None = None, opacity: float | None = None) -> str:
    return (f'<ellipse cx="{num(cx)}" cy="{num(cy)}" rx="{num(rx)}" ry="{num(ry)}" '
            f'{style(fill, stroke, width, opacity)}/>')


def polygon(points: Iterable[Point], fill: str, stroke: str | None = None, width: float | None = None,
            opacity: float | None = None) -> str:
    return f'<polygon points="{pts(points)}" {style(fill, stroke, width, opacity)}/>'


def polyline(points: Iterable[Point], stroke: str, width: float = 1.0) -> str:
    return f'<polyline points="{pts(points)}" {style("none", stroke, width)} stroke-linecap="round"/>'


def path(d: str, fill: str, stroke: str | None = None, width: float | None = None,
         opacity: float | None = None) -> str:
    return f'<path d="{d}" {style(fill, stroke, width, opacity)}/>'


def pivot(x: float, y: float, dynamic: bool = False) -> str:
    """The centre circle that ends every joint: white = pendulum, black = keyframed."""
    return circle(x, y, 4.0, "#ffffff" if dynamic else "#000000")


@dataclass
class JointSpec:
    """One joint: its shapes (SVG element strings), its pivot and its children."""

    name: str
    pivot: Point
    shapes: list[str]
    dynamic: bool = False
    children: list[JointSpec] = field(default_factory=list)

    def lines(self, indent: int) -> list[str]:
        pad = "  " * indent
        own = [*self.shapes, pivot(*self.pivot, dynamic=self.dynamic)]
        if not self.children:
            return [f'{pad}<g id="{self.name}">', *(f"{pad}  {s}" for s in own), f"{pad}</g>"]
        out = [f'{pad}<g id="{self.name}">', f"{pad}  <g>", *(f"{pad}    {s}" for s in own), f"{pad}  </g>"]
        for child in self.children:
            out.extend(child.lines(indent + 1))
        out.append(f"{pad}</g>")
        return out

    def walk(self) -> Iterable[JointSpec]:
        """Joints in pre-order (the order the loader numbers them)."""
        yield self
        for c in self.children:
            yield from c.walk()


def document(root: JointSpec, width: float, height: float, comment: str) -> str:
    """A whole SVG file holding one character."""
    head = ['<?xml version="1.0" encoding="UTF-8"?>', f"<!-- {comment.strip()} -->",
            f'<svg xmlns="http://www.w3.org/2000/svg" width="{num(width)}" height="{num(height)}" '
            f'viewBox="0 0 {num(width)} {num(height)}">']
    return "\n".join([*head, *root.lines(1), "</svg>"]) + "\n"


def rotate_points(points: Sequence[Point], angle: float, about: Point) -> list[Point]:
    """Rotate points by ``angle`` radians counter-clockwise on a y-down screen (the rig's R(θ))."""
    c, s = math.cos(angle), math.sin(angle)
    ax, ay = about
    return [(ax + (x - ax) * c + (y - ay) * s, ay - (x - ax) * s + (y - ay) * c) for x, y in points]
