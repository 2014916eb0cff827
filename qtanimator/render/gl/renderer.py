"""Draws a 3D scene (characters, cloths, grid, light gizmos) into the bound framebuffer.

The scene is described by plain data (:class:`CharacterDraw`, :class:`ClothDraw`, built from
the document by :mod:`qtanimator.render.scene3d`); this module owns the GL programs and the
GPU buffers and caches them per asset. It is shared by the viewport widget and the headless
renderer, so both draw the same pixels.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from OpenGL import GL

from qtanimator.render.gl.camera import OrbitCamera
from qtanimator.render.gl.lights import Light
from qtanimator.render.gl.meshes import (
    Mesh,
    SkinnedMesh,
    box_geometry,
    cylinder_geometry,
    grid_geometry,
    plane_geometry,
    sphere_geometry,
)
from qtanimator.render.gl.program import Program
from qtanimator.render.gl.scene_items import (  # the scene's data, re-exported
    AXIS_COLORS,
    BACKGROUND,
    BONE_COLOR,
    CLOTH_COLOR,
    FLOOR_HEIGHT,
    SELECTED_COLOR,
    SHADOW_COLOR,
    SKIN_COLOR,
    WEIGHTS_ALL,
    WEIGHTS_OFF,
    WIRE_COLOR,
    CharacterDraw,
    ClothDraw,
    PlaneDraw,
    SceneItem,
    SkinDraw,
    ViewOptions,
    axes_matrices,
    bone_matrices,
    box_matrices,
    grid_scale_for,
    key_light,
    shadow_matrix,
)
from qtanimator.render.gl.textures import TextureCache


class SceneRenderer:
    """GL programs and per-asset GPU buffers. Create, use and release with a current context."""

    def __init__(self) -> None:
        self.program: Program | None = None
        self._cube: Mesh | None = None
        self._sphere: Mesh | None = None
        self._cylinder: Mesh | None = None
        self._plane: Mesh | None = None
        self._grid: Mesh | None = None
        self._skins: dict[str, tuple[Any, SkinnedMesh]] = {}
        self._cloths: dict[str, tuple[int, int, Mesh]] = {}
        self._feedback: Program | None = None
        self.textures = TextureCache()
        self.stats: dict[str, int] = {}

    def initialize(self) -> None:
        self.program = Program("mesh.vert", "mesh.frag")
        self._cube = Mesh(*box_geometry())
        self._sphere = Mesh(*sphere_geometry())
        self._cylinder = Mesh(*cylinder_geometry())
        self._plane = Mesh(*plane_geometry(1.0, 8))
        gp, gc, gi = grid_geometry(5.0, 0.5)
        self._grid = Mesh(gp, None, gi, colors=gc, mode=GL.GL_LINES)

    @property
    def initialized(self) -> bool:
        return self.program is not None

    def release(self) -> None:
        for mesh in (self._cube, self._sphere, self._cylinder, self._plane, self._grid):
            if mesh is not None:
                mesh.delete()
        for _key, skin in self._skins.values():
            skin.delete()
        for _n, _t, cloth in self._cloths.values():
            cloth.delete()
        self._skins.clear()
        self._cloths.clear()
        self.textures.release()
        for prog in (self.program, self._feedback):
            if prog is not None:
                prog.delete()
        self.program = None
        self._feedback = None

    # ---------------------------------------------------------------- frame
    def render(self, items: Sequence[SceneItem], camera: OrbitCamera, width: int, height: int,
               lights: Sequence[Light], ambient: np.ndarray, options: ViewOptions | None = None) -> None:
        """Clear and draw everything into the framebuffer bound now, at (width, height) pixels."""
        if self.program is None:
            self.initialize()
        assert self.program is not None
        opts = options or ViewOptions()
        GL.glViewport(0, 0, width, height)
        GL.glClearColor(*opts.background)
        GL.glClear(GL.GL_COLOR_BUFFER_BIT | GL.GL_DEPTH_BUFFER_BIT)
        GL.glEnable(GL.GL_DEPTH_TEST)
        GL.glDisable(GL.GL_CULL_FACE)
        GL.glEnable(GL.GL_MULTISAMPLE)
        GL.glPolygonMode(GL.GL_FRONT_AND_BACK, GL.GL_FILL)
        prog = self.program
        prog.use()
        prog.set("u_view", camera.view())
        prog.set("u_proj", camera.projection(width / max(height, 1)))
        prog.set("u_eye", camera.eye())
        prog.set("u_model", np.eye(4))
        prog.set("u_ambient", np.asarray(ambient, dtype=float))
        pos = np.array([lights[i].position if i < len(lights) else np.zeros(3) for i in range(2)])
        rad = np.array([lights[i].radiance if i < len(lights) else np.zeros(3) for i in range(2)])
        prog.set("u_light_pos", pos)
        prog.set("u_light_color", rad)
        prog.set("u_specular", np.array([0.35, 0.35, 0.35]))
        prog.set("u_shininess", 32.0)
        prog.set("u_joint_tex", 0)
        prog.set("u_influence_tex", 1)
        prog.set("u_texture", 2)
        self._reset_state()
        self.stats = {"draw_calls": 0, "triangles": 0}

        if opts.show_grid:
            self._draw_grid(opts.grid_scale)
        if opts.show_axes:
            self._draw_world_axes(opts.grid_scale)
        live_skins, live_cloths = set(), set()
        xray: list[CharacterDraw] = []
        for item in items:
            if isinstance(item, PlaneDraw):
                self._draw_plane(item)
            elif isinstance(item, CharacterDraw):
                if item.skin is not None:
                    live_skins.add(item.asset_id)
                    if opts.show_skin:
                        self._draw_skin(item, opts)
                if opts.show_skeleton or item.skin is None or not opts.show_skin:
                    # over a visible skin the skeleton is drawn thin (spheres and bones)
                    # and in front of it (x-ray), so joints stay visible and pickable
                    if item.skin is not None and opts.show_skin:
                        xray.append(item)
                    else:
                        self._draw_skeleton(item)
            elif isinstance(item, ClothDraw):
                live_cloths.add(item.asset_id)
                self._draw_cloth(item, opts)
        if opts.show_shadow:
            self._draw_shadows(items, lights, opts)
        characters = [i for i in items if isinstance(i, CharacterDraw)] if opts.show_axes else []
        if xray or characters:
            # the skeleton over a skin and the joint axes are drawn in front of everything
            GL.glClear(GL.GL_DEPTH_BUFFER_BIT)
            for item in xray:
                self._draw_skeleton(item, thin=True)
            for item in characters:
                self._draw_joint_axes(item)
        if opts.show_lights:
            self._draw_light_gizmos(lights, opts.light_gizmo_size)
        self._forget(live_skins, live_cloths)
        self.textures.sweep()
        GL.glUseProgram(0)

    # -------------------------------------------------------------- helpers
    def _reset_state(self) -> None:
        p = self.program
        assert p is not None
        p.set("u_instanced", 0)
        p.set("u_use_vertex_color", 0)
        p.set("u_skinning", 0)
        p.set("u_weight_mode", WEIGHTS_OFF)
        p.set("u_lit", 1)
        p.set("u_faceted", 0)
        p.set("u_two_sided", 0)
        p.set("u_textured", 0)
        p.set("u_model", np.eye(4))

    def _count(self, mesh: Mesh, instances: int = 1) -> None:
        self.stats["draw_calls"] += 1
        if mesh.mode == GL.GL_TRIANGLES:
            self.stats["triangles"] += mesh.index_count // 3 * instances

    def _draw_grid(self, scale: float) -> None:
        p = self.program
        assert p is not None and self._grid is not None
        p.set("u_model", np.diag([scale, scale, scale, 1.0]))
        p.set("u_lit", 0)
        p.set("u_use_vertex_color", 1)
        self._grid.draw()
        self._count(self._grid)
        self._reset_state()

    def _draw_world_axes(self, scale: float) -> None:
        """The MIT viewer's coordinate axes: x, y, z from the origin, two grid cells long."""
        assert self._cylinder is not None
        p = self.program
        assert p is not None
        models, colors = axes_matrices(np.eye(4)[None], scale, 0.012 * scale)
        p.set("u_lit", 0)
        self._instanced(self._cylinder, models, colors)
        p.set("u_lit", 1)

    def _draw_joint_axes(self, item: CharacterDraw) -> None:
        """Small x / y / z axes at every joint, in the joint's frame."""
        assert self._cylinder is not None
        p = self.program
        assert p is not None
        r = item.joint_radius
        models, colors = axes_matrices(item.world, 4.0 * r, 0.22 * r)
        p.set("u_lit", 0)
        self._instanced(self._cylinder, models, colors)
        p.set("u_lit", 1)

    def _draw_shadows(self, items: Sequence[SceneItem], lights: Sequence[Light], opts: ViewOptions) -> None:
        """Every character and cloth once more, flattened onto the floor from the key light:
        the skin skinned on the GPU as usual with the projection as its model matrix (no CPU
        work per vertex), or the skeleton where no skin is drawn. The stencil buffer lets each
        floor pixel darken once however many surfaces project onto it."""
        light = key_light(lights)
        if light is None or float(light.position[1]) <= FLOOR_HEIGHT + 1e-6:
            return   # a light on or below the floor casts nothing onto it
        p = self.program
        assert p is not None
        top = float(light.position[1])
        casters: list[CharacterDraw | ClothDraw] = []
        for item in items:
            if isinstance(item, CharacterDraw) and len(item.world):
                if float(np.max(item.world[:, 1, 3])) < top:
                    casters.append(item)
            elif isinstance(item, ClothDraw) and len(item.positions):
                if float(np.max(item.positions[:, 1])) < top:
                    casters.append(item)
        if not casters:
            return
        GL.glEnable(GL.GL_BLEND)
        # "over" for alpha too: an opaque floor stays opaque (read-backs un-premultiply), and
        # over a transparent background the shadow is half-transparent black
        GL.glBlendFuncSeparate(GL.GL_SRC_ALPHA, GL.GL_ONE_MINUS_SRC_ALPHA, GL.GL_ONE, GL.GL_ONE_MINUS_SRC_ALPHA)
        GL.glDepthMask(GL.GL_FALSE)
        GL.glDepthFunc(GL.GL_LEQUAL)
        GL.glEnable(GL.GL_POLYGON_OFFSET_FILL)
        GL.glPolygonOffset(-1.0, -1.0)
        GL.glClearStencil(0)
        GL.glClear(GL.GL_STENCIL_BUFFER_BIT)
        GL.glEnable(GL.GL_STENCIL_TEST)
        GL.glStencilFunc(GL.GL_EQUAL, 0, 0xFF)
        GL.glStencilOp(GL.GL_KEEP, GL.GL_KEEP, GL.GL_INCR)
        color = np.asarray(SHADOW_COLOR, dtype=float)
        model = shadow_matrix(light.position)
        try:
            for item in casters:
                p.set("u_lit", 0)
                p.set("u_model", model)
                p.set("u_color", color)
                if isinstance(item, ClothDraw):
                    cached = self._cloths.get(item.asset_id)
                    if cached is not None:
                        cached[2].draw()
                        self._count(cached[2])
                elif item.skin is not None and opts.show_skin:
                    mesh = self.skinned_mesh(item.skin, item.asset_id)
                    mesh.bind_textures()   # this frame's joint matrices: uploaded for the skin
                    p.set("u_skinning", 1)
                    mesh.draw()
                    self._count(mesh)
                else:
                    self._draw_skeleton_shadow(item, model, color)
                self._reset_state()
        finally:
            GL.glDisable(GL.GL_STENCIL_TEST)
            GL.glDisable(GL.GL_POLYGON_OFFSET_FILL)
            GL.glDepthFunc(GL.GL_LESS)
            GL.glDepthMask(GL.GL_TRUE)
            GL.glDisable(GL.GL_BLEND)

    def _draw_skeleton_shadow(self, item: CharacterDraw, model: np.ndarray, color: np.ndarray) -> None:
        """The skeleton's boxes (or spheres and bones) as they are drawn, flattened by ``model``."""
        assert self._cube is not None and self._sphere is not None and self._cylinder is not None
        n = len(item.world)
        if item.boxmin is not None and item.boxmax is not None:
            self._instanced(self._cube, box_matrices(item.world, item.boxmin, item.boxmax), np.tile(color, (n, 1)))
            return
        r = item.joint_radius
        spheres = np.tile(np.eye(4), (n, 1, 1))
        spheres[:, :3, :3] *= r
        spheres[:, :3, 3] = item.world[:, :3, 3]
        self._instanced(self._sphere, spheres, np.tile(color, (n, 1)))
        bones = bone_matrices(item.world, item.parents, r * 0.8)
        self._instanced(self._cylinder, bones, np.tile(color, (len(bones), 1)))

    def _draw_plane(self, item: PlaneDraw) -> None:
        p = self.program
        assert p is not None and self._plane is not None
        m = np.diag([item.size, 1.0, item.size, 1.0])
        m[1, 3] = item.height
        p.set("u_model", m)
        p.set("u_color", np.asarray(item.color, dtype=float))
        p.set("u_two_sided", 1)
        self._plane.draw()
        self._count(self._plane)
        self._reset_state()

    def _instanced(self, mesh: Mesh, models: np.ndarray, colors: np.ndarray) -> None:
        if len(models) == 0:
            return
        p = self.program
        assert p is not None
        mesh.set_instances(models, colors)
        p.set("u_instanced", 1)
        mesh.draw(instanced=True)
        self._count(mesh, len(models))
        p.set("u_instanced", 0)

    def _draw_skeleton(self, item: CharacterDraw, thin: bool = False) -> None:
        assert self._cube is not None and self._sphere is not None and self._cylinder is not None
        n = len(item.world)
        colors = np.tile(BONE_COLOR, (n, 1))
        if item.selected is not None and 0 <= item.selected < n:
            colors[item.selected] = SELECTED_COLOR
        if item.boxmin is not None and item.boxmax is not None and not thin:
            self._instanced(self._cube, box_matrices(item.world, item.boxmin, item.boxmax), colors)
            return
        r = item.joint_radius
        spheres = np.tile(np.eye(4), (n, 1, 1))
        spheres[:, :3, :3] *= r
        spheres[:, :3, 3] = item.world[:, :3, 3]
        self._instanced(self._sphere, spheres, colors)
        bones = bone_matrices(item.world, item.parents, r * 0.8)
        child_colors = np.array([colors[j] for j, p in enumerate(item.parents) if p >= 0
                                 and np.linalg.norm(item.world[j, :3, 3] - item.world[p, :3, 3]) >= 1e-9])
        self._instanced(self._cylinder, bones, child_colors.reshape(-1, 4))

    def skinned_mesh(self, skin: SkinDraw, asset_id: str) -> SkinnedMesh:
        """The GPU mesh for ``skin``, built on first use and when its bind data changes."""
        cached = self._skins.get(asset_id)
        if cached is not None and cached[0] is skin.key:
            return cached[1]
        if cached is not None:
            cached[1].delete()
        mesh = SkinnedMesh(skin.positions, skin.normals, skin.triangles, skin.influence, skin.pairs,
                           len(skin.matrices), skin.texcoords)
        self._skins[asset_id] = (skin.key, mesh)
        return mesh

    def _draw_skin(self, item: CharacterDraw, opts: ViewOptions) -> None:
        p = self.program
        assert p is not None and item.skin is not None
        skin = item.skin
        mesh = self.skinned_mesh(skin, item.asset_id)
        mesh.set_joint_matrices(skin.matrices)
        mesh.bind_textures()
        faceted = skin.faceted if opts.faceted is None else opts.faceted
        p.set("u_skinning", 1)
        p.set("u_color", np.asarray(SKIN_COLOR))
        p.set("u_faceted", 1 if faceted or skin.normals is None else 0)
        mode = opts.weight_mode
        if mode >= 0 and opts.weight_asset is not None and opts.weight_asset != item.asset_id:
            mode = WEIGHTS_OFF
        p.set("u_weight_mode", mode)
        if skin.textures and skin.texcoords is not None and mode == WEIGHTS_OFF:
            self._draw_textured(mesh, opts.wireframe, skin.textures)
        else:
            self._draw_surface(mesh, opts.wireframe, skin.parts)

    def _draw_textured(self, mesh: Mesh, wireframe: bool,
                       ranges: Sequence[tuple[int, int, tuple[float, float, float, float], Any]]) -> None:
        """Draw each range in its base colour, times its image where it has one (texture unit 2)."""
        p = self.program
        assert p is not None
        if wireframe:
            GL.glEnable(GL.GL_POLYGON_OFFSET_FILL)
            GL.glPolygonOffset(1.0, 1.0)
        for first, count, color, image in ranges:
            p.set("u_color", np.asarray(color, dtype=float))
            p.set("u_textured", 0 if image is None else 1)
            if image is not None:
                GL.glActiveTexture(GL.GL_TEXTURE2)
                GL.glBindTexture(GL.GL_TEXTURE_2D, self.textures.get(image))
                GL.glActiveTexture(GL.GL_TEXTURE0)
            mesh.draw_range(3 * first, 3 * count)
            self.stats["draw_calls"] += 1
            self.stats["triangles"] += count
        p.set("u_textured", 0)
        if wireframe:
            GL.glDisable(GL.GL_POLYGON_OFFSET_FILL)
            self._wire(mesh)
        self._reset_state()

    def skin_on_gpu(self, skin: SkinDraw, key: str = "_capture") -> tuple[np.ndarray, np.ndarray]:
        """Run the skinning vertex shader on every vertex and read back world positions and
        normals with transform feedback: (N, 3), (N, 3). For checking GPU against CPU skinning."""
        if self.program is None:
            self.initialize()
        if self._feedback is None:
            self._feedback = Program("mesh.vert", "mesh.frag", feedback=["v_world", "v_normal"])
        prog = self._feedback
        mesh = self.skinned_mesh(skin, key)
        mesh.set_joint_matrices(skin.matrices)
        n = mesh.vertex_count
        out = int(GL.glGenBuffers(1))
        GL.glBindBuffer(GL.GL_TRANSFORM_FEEDBACK_BUFFER, out)
        GL.glBufferData(GL.GL_TRANSFORM_FEEDBACK_BUFFER, n * 24, None, GL.GL_STATIC_READ)
        prog.use()
        for name, value in (("u_model", np.eye(4)), ("u_view", np.eye(4)), ("u_proj", np.eye(4)),
                            ("u_instanced", 0), ("u_use_vertex_color", 0), ("u_skinning", 1),
                            ("u_weight_mode", WEIGHTS_OFF), ("u_joint_tex", 0), ("u_influence_tex", 1),
                            ("u_texture", 2), ("u_textured", 0)):
            prog.set(name, value)
        mesh.bind_textures()
        GL.glEnable(GL.GL_RASTERIZER_DISCARD)
        GL.glBindBufferBase(GL.GL_TRANSFORM_FEEDBACK_BUFFER, 0, out)
        GL.glBindVertexArray(mesh.vao)
        GL.glBeginTransformFeedback(GL.GL_POINTS)
        GL.glDrawArrays(GL.GL_POINTS, 0, n)
        GL.glEndTransformFeedback()
        GL.glBindVertexArray(0)
        GL.glDisable(GL.GL_RASTERIZER_DISCARD)
        GL.glFinish()
        GL.glBindBuffer(GL.GL_TRANSFORM_FEEDBACK_BUFFER, out)
        data = GL.glGetBufferSubData(GL.GL_TRANSFORM_FEEDBACK_BUFFER, 0, n * 24)
        arr = np.frombuffer(bytes(data), dtype=np.float32).reshape(n, 6).astype(np.float64)
        GL.glBindBufferBase(GL.GL_TRANSFORM_FEEDBACK_BUFFER, 0, 0)
        GL.glDeleteBuffers(1, [out])
        GL.glUseProgram(0)
        return arr[:, :3], arr[:, 3:]

    def _draw_surface(self, mesh: Mesh, wireframe: bool,
                      parts: Sequence[tuple[int, int, tuple[float, float, float, float]]] = ()) -> None:
        """Draw a triangle mesh in the colour set, or each of its ``parts`` (first triangle,
        triangle count, colour) in its own colour; a wireframe over it on request."""
        if wireframe:
            # Push the fill back so the wire drawn over it is not lost to z-fighting.
            GL.glEnable(GL.GL_POLYGON_OFFSET_FILL)
            GL.glPolygonOffset(1.0, 1.0)
        if parts:
            p = self.program
            assert p is not None
            for first, count, color in parts:
                p.set("u_color", np.asarray(color, dtype=float))
                mesh.draw_range(3 * first, 3 * count)
                self.stats["draw_calls"] += 1
                self.stats["triangles"] += count
        else:
            mesh.draw()
            self._count(mesh)
        if wireframe:
            GL.glDisable(GL.GL_POLYGON_OFFSET_FILL)
            self._wire(mesh)
        self._reset_state()

    def _wire(self, mesh: Mesh) -> None:
        p = self.program
        assert p is not None
        p.set("u_lit", 0)
        p.set("u_weight_mode", WEIGHTS_OFF)
        p.set("u_color", np.asarray(WIRE_COLOR))
        GL.glEnable(GL.GL_BLEND)
        GL.glBlendFunc(GL.GL_SRC_ALPHA, GL.GL_ONE_MINUS_SRC_ALPHA)
        GL.glDepthMask(GL.GL_FALSE)
        GL.glPolygonMode(GL.GL_FRONT_AND_BACK, GL.GL_LINE)
        mesh.draw()
        GL.glPolygonMode(GL.GL_FRONT_AND_BACK, GL.GL_FILL)
        GL.glDepthMask(GL.GL_TRUE)
        GL.glDisable(GL.GL_BLEND)
        p.set("u_lit", 1)

    def _draw_cloth(self, item: ClothDraw, opts: ViewOptions) -> None:
        p = self.program
        assert p is not None and self._sphere is not None
        n, t = len(item.positions), len(item.triangles)
        cached = self._cloths.get(item.asset_id)
        if cached is None or cached[0] != n or cached[1] != t:
            if cached is not None:
                cached[2].delete()
            mesh = Mesh(item.positions, item.normals, item.triangles, dynamic=True)
            self._cloths[item.asset_id] = (n, t, mesh)
        else:
            mesh = cached[2]
            mesh.update(item.positions, item.normals)
        p.set("u_color", np.asarray(item.color, dtype=float))
        p.set("u_two_sided", 1)
        self._draw_surface(mesh, opts.wireframe)
        if item.spheres:
            models = []
            for centre, radius in item.spheres:
                m = np.diag([radius, radius, radius, 1.0])
                m[:3, 3] = centre
                models.append(m)
            self._instanced(self._sphere, np.array(models),
                            np.tile((0.55, 0.6, 0.55, 1.0), (len(models), 1)))
        if item.pinned is not None and len(item.pinned):
            k = len(item.pinned)
            pins = np.tile(np.eye(4), (k, 1, 1))
            pins[:, :3, :3] *= 0.02
            pins[:, :3, 3] = item.pinned
            p.set("u_lit", 0)
            self._instanced(self._sphere, pins, np.tile((1.0, 0.85, 0.2, 1.0), (k, 1)))
            p.set("u_lit", 1)

    def _draw_light_gizmos(self, lights: Sequence[Light], size: float) -> None:
        assert self._sphere is not None
        p = self.program
        assert p is not None
        models, colors = [], []
        for light in lights:
            m = np.diag([size, size, size, 1.0])
            m[:3, 3] = light.position
            models.append(m)
            colors.append((*light.color, 1.0))
        p.set("u_lit", 0)
        self._instanced(self._sphere, np.array(models).reshape(-1, 4, 4), np.array(colors).reshape(-1, 4))
        p.set("u_lit", 1)

    def _forget(self, live_skins: set[str], live_cloths: set[str]) -> None:
        for key in [k for k in self._skins if k not in live_skins]:
            self._skins.pop(key)[1].delete()
        for key in [k for k in self._cloths if k not in live_cloths]:
            self._cloths.pop(key)[2].delete()


__all__ = [
    "SceneRenderer", "AXIS_COLORS", "BACKGROUND", "BONE_COLOR", "CLOTH_COLOR", "CharacterDraw", "ClothDraw",
    "FLOOR_HEIGHT", "PlaneDraw", "SELECTED_COLOR", "SHADOW_COLOR", "SKIN_COLOR", "SceneItem", "SkinDraw",
    "ViewOptions", "WEIGHTS_ALL", "WEIGHTS_OFF", "WIRE_COLOR", "axes_matrices", "bone_matrices",
    "box_matrices", "grid_scale_for", "key_light", "shadow_matrix",
]
