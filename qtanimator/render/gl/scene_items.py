"""What a 3D scene is made of, as plain data the renderer draws (:class:`CharacterDraw`,
:class:`ClothDraw`, :class:`PlaneDraw`, built from the document by
:mod:`qtanimator.render.scene3d`), how it is shown (:class:`ViewOptions`, the colours), and
the per-instance matrices of its bones, axes, boxes and floor shadow. No GL here:
:mod:`qtanimator.render.gl.renderer` draws it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from qtanimator.render.gl.lights import Light

SKIN_COLOR = (0.78, 0.74, 0.68, 1.0)

BONE_COLOR = (0.62, 0.66, 0.74, 1.0)

SELECTED_COLOR = (1.0, 0.62, 0.1, 1.0)

CLOTH_COLOR = (0.75, 0.2, 0.22, 1.0)

WIRE_COLOR = (0.05, 0.05, 0.08, 0.35)   # blended over the shaded surface

BACKGROUND = (0.17, 0.18, 0.2, 1.0)

#: The floor shadow: black at this opacity, blended once per pixel over the floor.
SHADOW_COLOR = (0.0, 0.0, 0.0, 0.5)

#: The plane shadows fall on (the grid's plane).
FLOOR_HEIGHT = 0.0

#: Colours of the x, y and z axes (the MIT viewer's red, green, blue).
AXIS_COLORS = ((0.92, 0.22, 0.2, 1.0), (0.3, 0.85, 0.3, 1.0), (0.25, 0.45, 1.0, 1.0))

#: weight_mode values (the shader's u_weight_mode): no pseudo-colour, or every joint's colour.
WEIGHTS_OFF, WEIGHTS_ALL = -2, -1


@dataclass
class ViewOptions:
    """What the viewport shows and how."""

    show_skin: bool = True
    show_skeleton: bool = True
    show_grid: bool = True
    show_lights: bool = True
    wireframe: bool = False
    #: None: the asset's default (MIT meshes faceted, skins with normals smooth).
    faceted: bool | None = None
    #: WEIGHTS_OFF, WEIGHTS_ALL, or a joint index for that joint's weight as a heat map.
    weight_mode: int = WEIGHTS_OFF
    #: with a joint index as weight_mode: the asset it belongs to (others show no weights)
    weight_asset: str | None = None
    background: tuple[float, float, float, float] = BACKGROUND
    #: radius of the spheres that show where the lights are
    light_gizmo_size: float = 0.08
    #: the ground grid spans ±5·scale with lines every 0.5·scale (see :func:`grid_scale_for`)
    grid_scale: float = 1.0
    #: world axes at the origin and small x / y / z axes at every joint (the MIT viewer's ``a``)
    show_axes: bool = False
    #: a planar shadow of the characters and cloths on the floor (y = 0) from the key light
    show_shadow: bool = False

def grid_scale_for(bmin: np.ndarray, bmax: np.ndarray) -> float:
    """A power of ten that suits the ground grid to a scene of these bounds."""
    extent = float(np.max(np.asarray(bmax) - np.asarray(bmin)))
    if not np.isfinite(extent) or extent <= 0:
        return 1.0
    return float(10.0 ** np.round(np.log10(extent / 4.0)))

@dataclass
class SkinDraw:
    """A skin to draw skinned on the GPU: bind-pose data and this frame's joint matrices."""

    key: Any                      # identity of the bind data (rebuilds GPU buffers on change)
    positions: np.ndarray         # (N, 3) bind positions
    normals: np.ndarray | None    # (N, 3) or None (faceted only)
    triangles: np.ndarray         # (T, 3)
    influence: np.ndarray         # (N, 2) first entry and count in ``pairs``
    pairs: np.ndarray             # (M, 2) joint index, weight
    matrices: np.ndarray          # (J, 4, 4) W_j · B_j⁻¹
    faceted: bool = False
    #: (first triangle, triangle count, RGBA colour) of each part drawn in its own colour
    #: (a character's meshes with their materials); empty: the whole skin in SKIN_COLOR.
    parts: tuple[tuple[int, int, tuple[float, float, float, float]], ...] = ()
    #: (N, 2) texture coordinates, t = 0 at the image's top row (None: no textures drawn)
    texcoords: np.ndarray | None = None
    #: (first triangle, triangle count, RGBA base colour, image or None) covering the skin
    #: when some part has an image (a TextureImage, decoded here): drawn instead of ``parts``.
    textures: tuple[tuple[int, int, tuple[float, float, float, float], Any], ...] = ()

@dataclass
class CharacterDraw:
    asset_id: str
    world: np.ndarray                    # (J, 4, 4)
    parents: Sequence[int]
    boxmin: np.ndarray | None = None     # (J, 3): boxes when given, else spheres and bones
    boxmax: np.ndarray | None = None
    skin: SkinDraw | None = None
    selected: int | None = None
    joint_radius: float = 0.025

@dataclass
class ClothDraw:
    asset_id: str
    positions: np.ndarray                # (N, 3)
    normals: np.ndarray                  # (N, 3)
    triangles: np.ndarray                # (T, 3)
    color: tuple[float, float, float, float] = CLOTH_COLOR
    spheres: list[tuple[np.ndarray, float]] = field(default_factory=list)
    pinned: np.ndarray | None = None     # (P, 3) pinned particle positions
    stale: bool = False                  # an earlier frame stands in (the cache is still filling)

@dataclass
class PlaneDraw:
    """A lit square in y = ``height`` (tests and the empty scene)."""

    size: float = 2.0
    height: float = 0.0
    color: tuple[float, float, float, float] = (0.8, 0.8, 0.8, 1.0)

SceneItem = CharacterDraw | ClothDraw | PlaneDraw

def bone_matrices(world: np.ndarray, parents: Sequence[int], radius: float) -> np.ndarray:
    """Model matrices mapping the unit cylinder (z from 0 to 1) onto each parent→child bone."""
    out = []
    for j, p in enumerate(parents):
        if p < 0:
            continue
        a, b = world[p, :3, 3], world[j, :3, 3]
        d = b - a
        length = float(np.linalg.norm(d))
        if length < 1e-9:
            continue
        z = d / length
        helper = np.array([0.0, 0.0, 1.0]) if abs(z[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
        x = np.cross(helper, z)
        x /= np.linalg.norm(x)
        y = np.cross(z, x)
        m = np.eye(4)
        m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = x * radius, y * radius, z * length, a
        out.append(m)
    return np.array(out).reshape(-1, 4, 4)

def axes_matrices(frames: np.ndarray, length: float, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Model matrices mapping the unit cylinder onto the x, y and z axes of each frame (K, 4, 4)
    from its origin, ``length`` long (a frame's scale is ignored), and their colours:
    (3K, 4, 4), (3K, 4)."""
    frames = np.asarray(frames, dtype=float).reshape(-1, 4, 4)
    k = len(frames)
    out = np.zeros((k, 3, 4, 4))
    out[:, :, 3, 3] = 1.0
    for axis in range(3):
        z = frames[:, :3, axis]
        norm = np.linalg.norm(z, axis=1, keepdims=True)
        z = np.where(norm > 1e-12, z / np.maximum(norm, 1e-12), np.eye(3)[axis])
        helper = np.where(np.abs(z[:, 2:3]) < 0.9, [[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]])
        x = np.cross(helper, z)
        x /= np.linalg.norm(x, axis=1, keepdims=True)
        y = np.cross(z, x)
        m = out[:, axis]
        m[:, :3, 0], m[:, :3, 1], m[:, :3, 2] = x * radius, y * radius, z * length
        m[:, :3, 3] = frames[:, :3, 3]
    colors = np.tile(np.asarray(AXIS_COLORS), (k, 1))
    return out.reshape(-1, 4, 4), colors

def shadow_matrix(light: np.ndarray, floor: float = FLOOR_HEIGHT) -> np.ndarray:
    """The planar projection from a point light onto the plane y = ``floor`` (the OpenGL Red
    Book's shadow matrix): ``M = (P·L) I − L Pᵀ`` with the plane P = (0, 1, 0, −floor) and the
    light L = (x, y, z, 1). A point p lands where the ray from the light through p meets the
    floor (homogeneous: divide by w = L_y − p_y, so points above the light have none)."""
    plane = np.array([0.0, 1.0, 0.0, -float(floor)])
    lh = np.append(np.asarray(light, dtype=float).reshape(3), 1.0)
    return float(plane @ lh) * np.eye(4) - np.outer(lh, plane)

def key_light(lights: Sequence[Light]) -> Light | None:
    """The light that casts the floor shadow: the brightest (light 1 on a tie), if any."""
    best: Light | None = None
    for light in lights:
        if best is None or float(np.sum(light.radiance)) > float(np.sum(best.radiance)) + 1e-12:
            best = light
    return best

def box_matrices(world: np.ndarray, boxmin: np.ndarray, boxmax: np.ndarray) -> np.ndarray:
    """Model matrices mapping the unit cube onto each joint's box in its own frame."""
    s = np.zeros((len(world), 4, 4))
    size = boxmax - boxmin
    s[:, 0, 0], s[:, 1, 1], s[:, 2, 2], s[:, 3, 3] = size[:, 0], size[:, 1], size[:, 2], 1.0
    s[:, :3, 3] = boxmin
    return world @ s
