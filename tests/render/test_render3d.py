"""Headless 3D rendering through an offscreen context (real Mesa GL under the private Xvfb)."""

from __future__ import annotations

import numpy as np
import pytest

from qtanimator.document.commands import SetParameter, UndoStack
from qtanimator.document.document import Document
from qtanimator.render.gl.camera import OrbitCamera
from qtanimator.render.gl.renderer import PlaneDraw, ViewOptions

pytestmark = pytest.mark.gl

SIZE = (160, 120)


def _render(doc, items, camera, options=None, times=(0.0,)):
    from qtanimator.render.render3d import render_frames_3d

    return list(render_frames_3d(doc, times, SIZE, camera=camera, options=options, extra_items=items))


def _two_light_doc() -> Document:
    doc = Document()
    stack = UndoStack(doc)
    for path, value in {
        "light1.position": [-2.0, 0.6, 0.0], "light1.color": [1.0, 0.0, 0.0], "light1.intensity": 1.0,
        "light2.position": [2.0, 0.6, 0.0], "light2.color": [0.0, 0.0, 1.0], "light2.intensity": 1.0,
        "lights.ambient": [0.0, 0.0, 0.0],
    }.items():
        stack.push(SetParameter(doc, path, value))
    return doc


TOP = OrbitCamera(azimuth=0.0, inclination=89.0, distance=4.5)
PLAIN = ViewOptions(show_grid=False, show_lights=False, background=(0, 0, 0, 1))


def test_renders_a_non_empty_image(qapp):
    img = _render(Document(), [PlaneDraw(3.0)], OrbitCamera(azimuth=0, inclination=40, distance=4))[0]
    assert img.shape == (SIZE[1], SIZE[0], 4) and img.dtype == np.uint8
    # the lit plane covers the lower middle of the picture, the background the top corners
    centre = img[SIZE[1] * 2 // 3, SIZE[0] // 2, :3].astype(int)
    corner = img[2, 2, :3].astype(int)
    assert centre.sum() > corner.sum() + 150
    assert len(np.unique(img.reshape(-1, 4), axis=0)) > 20  # shading, grid, not a flat fill


def test_two_coloured_lights_tint_the_plane_left_red_right_blue(qapp):
    doc = _two_light_doc()
    img = _render(doc, [PlaneDraw(8.0)], TOP, PLAIN)[0].astype(float)
    w = SIZE[0]
    assert (img[..., :3].sum(axis=2) > 0).all()  # the plane fills the view
    left, right = img[:, : w // 3, :3], img[:, 2 * w // 3:, :3]
    assert left[..., 0].mean() > 2 * left[..., 2].mean() + 5
    assert right[..., 2].mean() > 2 * right[..., 0].mean() + 5
    # specular highlights and falloff: the red is brightest under the red light
    assert left[..., 0].mean() > right[..., 0].mean() + 10


def test_light_intensity_and_colour_parameters_change_the_picture(qapp):
    doc = _two_light_doc()
    stack = UndoStack(doc)
    stack.push(SetParameter(doc, "light1.intensity", 0.0))
    stack.push(SetParameter(doc, "light2.color", [0.0, 1.0, 0.0]))
    img = _render(doc, [PlaneDraw(8.0)], TOP, PLAIN)[0].astype(float)
    assert img[..., 0].max() < 8          # the red light is off
    assert img[..., 1].mean() > 10 and img[..., 2].max() < 8   # the second light is green now
    stack.undo()
    stack.undo()
    img = _render(doc, [PlaneDraw(3.0)], TOP, PLAIN)[0].astype(float)
    assert img[..., 0].mean() > 10 and img[..., 2].mean() > 10


def test_ambient_only_lights_the_plane_evenly(qapp):
    doc = _two_light_doc()
    stack = UndoStack(doc)
    for name in ("light1", "light2"):
        stack.push(SetParameter(doc, f"{name}.intensity", 0.0))
    stack.push(SetParameter(doc, "lights.ambient", [0.5, 0.5, 0.5]))
    img = _render(doc, [PlaneDraw(3.0, color=(1, 1, 1, 1))], TOP, PLAIN)[0].astype(float)
    inner = img[SIZE[1] // 4: 3 * SIZE[1] // 4, SIZE[0] // 4: 3 * SIZE[0] // 4, :3]
    assert abs(inner.mean() - 127.5) < 4 and inner.std() < 2


# ----------------------------------------------------------------- characters
def _wasp_doc(shared_data, with_anim=True):
    from qtanimator.document.character3d import add_character3d_command

    d = shared_data / "cse169"
    doc = Document()
    UndoStack(doc).push(add_character3d_command(
        doc, d / "skeleton" / "wasp.skel", d / "skin" / "wasp.skin",
        d / "wasp_walk" / "wasp_walk.anim" if with_anim else None, asset_id="wasp"))
    return doc


def _mit_doc(shared_data, model="Model1"):
    from qtanimator.document.character3d import add_character3d_command

    d = shared_data / "mit6837"
    doc = Document()
    UndoStack(doc).push(add_character3d_command(doc, d / f"{model}.skel", obj_path=d / f"{model}.obj",
                                                attach_path=d / f"{model}.attach", asset_id="mit"))
    return doc


@pytest.mark.parametrize("which", ["wasp", "mit"])
def test_gpu_skinning_matches_cpu_skinning(qapp, shared_data, which):
    from qtanimator.core.skinning import skin_normals, skin_positions
    from qtanimator.document.character3d import character, pose_skeleton
    from qtanimator.render.gl.renderer import SceneRenderer
    from qtanimator.render.render3d import OffscreenGL
    from qtanimator.render.scene3d import skin_draw

    doc = _wasp_doc(shared_data) if which == "wasp" else _mit_doc(shared_data)
    asset = "wasp" if which == "wasp" else "mit"
    skel = pose_skeleton(doc, asset, 0.7)
    if which == "mit":   # bend a few joints so that many influences matter
        for j, (x, y, z) in {4: (0.3, -0.5, 0.7), 14: (0.0, 0.0, 1.2), 2: (0.2, 0.4, -0.3)}.items():
            skel.set_dof(j, "x", x)
            skel.set_dof(j, "y", y)
            skel.set_dof(j, "z", z)
    world = skel.world_matrices()
    skin = character(doc, asset).skin
    if which == "mit":
        assert skin.binding.max_influences > 4   # up to 13: a 4-influence layout would be wrong
    draw = skin_draw(doc, asset, world)
    gl = OffscreenGL((16, 16))
    renderer = SceneRenderer()
    try:
        gpu_pos, gpu_nrm = renderer.skin_on_gpu(draw)
    finally:
        renderer.release()
        gl.close()
    cpu_pos = skin_positions(skin, world)
    scale = float(np.abs(cpu_pos).max())
    assert np.abs(gpu_pos - cpu_pos).max() < 2e-6 * max(scale, 1.0) * 10
    moved = np.linalg.norm(cpu_pos - skin.positions, axis=1).max()
    assert moved > 0.05   # the pose really deforms the mesh
    if skin.normals is not None:
        cpu_nrm = skin_normals(skin, world)
        gpu_unit = gpu_nrm / np.linalg.norm(gpu_nrm, axis=1, keepdims=True)
        assert np.abs(gpu_unit - cpu_nrm).max() < 1e-4


def _changed_fraction(a, b):
    return float(np.mean(np.any(np.abs(a.astype(int) - b.astype(int)) > 8, axis=2)))


def test_headless_render_of_the_wasp_walking_changes_frame_to_frame(qapp, shared_data):
    from qtanimator.render.render3d import render_frames_3d

    doc = _wasp_doc(shared_data)
    frames = list(render_frames_3d(doc, [0.0, 0.25, 0.5], SIZE))
    assert len(frames) == 3
    for a, b in zip(frames, frames[1:]):
        assert _changed_fraction(a, b) > 0.005
    # the wasp is in the picture: a good share of pixels differ from an empty scene
    empty = next(render_frames_3d(Document(), [0.0], SIZE, camera=None))
    assert _changed_fraction(frames[0], empty) > 0.05


def test_headless_render_of_a_falling_cloth_changes_frame_to_frame(qapp):
    from qtanimator.core.cloth import ClothParams
    from qtanimator.document.cloth import add_cloth_command
    from qtanimator.render.render3d import render_frames_3d

    doc = Document()
    UndoStack(doc).push(add_cloth_command(doc, ClothParams(rows=12, cols=12, pin_mode="none",
                                                           origin=(0.0, 1.5, 0.0),
                                                           orientation=(-1.5707963, 0.0, 0.0))))
    cam = OrbitCamera(azimuth=0.0, inclination=15.0, distance=3.5, target=np.array([0.0, 0.8, 0.0]))
    frames = list(render_frames_3d(doc, [0.0, 10 / 60, 20 / 60], SIZE, camera=cam, options=PLAIN))
    red = [np.argwhere((f[..., 0].astype(int) - f[..., 2]) > 40) for f in frames]
    assert all(len(r) > 30 for r in red)
    rows = [r[:, 0].mean() for r in red]
    assert rows[0] < rows[1] < rows[2]   # the cloth falls: it moves down the picture


# ------------------------------------------------------------- mesh part colours
def _two_part_doc(colors):
    """A character of two flat squares side by side in y = 0, facing up (left: part 0,
    right: part 1), lit by a white ambient light only, so each part shows its colour."""
    from qtanimator.core.skeleton import Joint, Skeleton
    from qtanimator.core.skinning import Skin, SkinBinding
    from qtanimator.document.character3d import ASSET_KIND, Character3D, MeshPart
    from qtanimator.document.commands import AddAsset
    from qtanimator.document.document import Asset

    square = np.array([[0, 0, -1], [1, 0, -1], [1, 0, 1], [0, 0, 1]], dtype=float)
    positions = np.concatenate([square - [1.05, 0, 0], square + [0.05, 0, 0]])
    triangles = np.array([[0, 2, 1], [0, 3, 2], [4, 6, 5], [4, 7, 6]])
    n = len(positions)
    skin = Skin(positions, triangles, SkinBinding(np.arange(n), np.zeros(n), np.ones(n), n, 1), np.eye(4)[None],
                normals=np.tile([0.0, 1.0, 0.0], (n, 1)))
    parts = [MeshPart("left", 0, 4, 0, 2, color=colors[0]), MeshPart("right", 4, 4, 2, 2, color=colors[1])]
    runtime = Character3D(Skeleton([Joint("root")]), skin, parts=parts)
    doc = _two_light_doc()
    stack = UndoStack(doc)
    for name in ("light1", "light2"):
        stack.push(SetParameter(doc, f"{name}.intensity", 0.0))
    stack.push(SetParameter(doc, "lights.ambient", [1.0, 1.0, 1.0]))
    stack.push(AddAsset(Asset("squares", ASSET_KIND, "", {}), runtime, {}))
    return doc


SKIN_ONLY = ViewOptions(show_grid=False, show_lights=False, show_skeleton=False, background=(0, 0, 0, 1))


@pytest.mark.parametrize("wireframe", [False, True])
def test_mesh_parts_are_drawn_each_in_its_material_colour(qapp, wireframe):
    from dataclasses import replace

    from qtanimator.render.scene3d import display_color

    doc = _two_part_doc([(1.0, 0.0, 0.0, 1.0), (0.0, 0.0, 1.0, 1.0)])
    img = _render(doc, [], TOP, replace(SKIN_ONLY, wireframe=wireframe))[0].astype(int)
    h, w = SIZE[1], SIZE[0]
    left = img[h // 2 - 10: h // 2 + 10, w // 2 - 30: w // 2 - 10, :3].reshape(-1, 3)
    right = img[h // 2 - 10: h // 2 + 10, w // 2 + 10: w // 2 + 30, :3].reshape(-1, 3)
    red = (left[:, 0] > 200) & (left[:, 1] < 40) & (left[:, 2] < 40)
    blue = (right[:, 2] > 200) & (right[:, 0] < 40) & (right[:, 1] < 40)
    assert red.mean() > 0.8 and blue.mean() > 0.8
    # the colours are the materials' (linear) base colours encoded for the screen
    assert display_color((0.5, 0.2, 0.0, 0.3)) == pytest.approx((0.7354, 0.4845, 0.0, 1.0), abs=1e-4)


def test_mesh_parts_of_one_colour_draw_the_skin_colour_as_before(qapp):
    from qtanimator.render.gl.renderer import SKIN_COLOR
    from qtanimator.render.scene3d import part_colors

    doc = _two_part_doc([(0.1, 0.9, 0.1, 1.0), (0.1, 0.9, 0.1, 1.0)])
    assert part_colors(doc.runtime["squares"], 4) == ()
    img = _render(doc, [], TOP, SKIN_ONLY)[0].astype(int)
    h, w = SIZE[1], SIZE[0]
    for x in (w // 2 - 20, w // 2 + 20):
        assert np.abs(img[h // 2, x, :3] - np.round(np.array(SKIN_COLOR[:3]) * 255)).max() <= 2


def test_part_colours_cover_every_triangle():
    from qtanimator.core.skeleton import Joint, Skeleton
    from qtanimator.document.character3d import Character3D, MeshPart
    from qtanimator.render.gl.renderer import SKIN_COLOR
    from qtanimator.render.scene3d import display_color, part_colors

    red, blue = (1.0, 0.0, 0.0, 1.0), (0.0, 0.0, 1.0, 1.0)
    ch = Character3D(Skeleton([Joint("root")]), parts=[MeshPart("b", 0, 0, 5, 3, color=blue),
                                                       MeshPart("a", 0, 0, 1, 2, color=red)])
    assert part_colors(ch, 10) == ((0, 1, SKIN_COLOR), (1, 2, display_color(red)), (3, 2, SKIN_COLOR),
                                   (5, 3, display_color(blue)), (8, 2, SKIN_COLOR))


def test_the_floor_shadow_darkens_each_floor_pixel_once(qapp):
    """A closed skin covers its shadow twice (front and back): the stencil lets every floor
    pixel darken once, so the shadow has one even tone; headless (multisampled) too."""
    from qtanimator.document.character3d import add_character3d_command
    from qtanimator.paths import scenes_dir
    from qtanimator.render.gl.renderer import SHADOW_COLOR
    from qtanimator.render.render3d import render_frames_3d

    doc = Document()
    arm = scenes_dir() / "arm3d"
    UndoStack(doc).push(add_character3d_command(doc, arm / "arm.skel", arm / "arm.skin", asset_id="arm"))
    bg = (0.5, 0.5, 0.5, 1.0)
    camera = OrbitCamera(azimuth=30.0, inclination=60.0, distance=7.0, target=np.array([0.0, 0.5, 0.0]))
    off, on = (next(render_frames_3d(doc, [0.0], (240, 180), camera=camera,
                                     options=ViewOptions(show_grid=False, show_lights=False, show_skeleton=False,
                                                         background=bg, show_shadow=shadow)))
               for shadow in (False, True))
    background = (np.abs(off[..., :3].astype(int) - 128) <= 1).all(axis=2)
    level = on[..., :3].astype(int)[background]
    shaded = level.max(axis=1) < 120
    assert shaded.sum() > 200
    once = round(128 * (1 - SHADOW_COLOR[3]))
    # every shadow pixel is at the single-darkening tone or lighter (anti-aliased edges), none darker
    assert level[shaded].min() >= once - 2
    assert np.mean(np.abs(level[shaded] - once).max(axis=1) <= 2) > 0.8
