"""3D viewport: software-GL frame time and the CPU cost per frame of GPU skinning.

Run: ``.venv/bin/python benchmarks/bench_viewport.py`` (prints a table), or call ``run()`` for
the rows. Needs an OpenGL 3.3 context: on a machine without a display the offscreen renderer
starts a private Xvfb (Mesa llvmpipe: "software GL", every pixel and vertex on the CPU).

Rows
----
* Frame time of the wasp (skinned on the GPU, walking) plus a 32×32 cloth (falling, cached
  simulation) at 1280×720 with 4× multisampling, Mesa llvmpipe: scene build + draw +
  ``glFinish``, no read-back. Peer: the same frame with the wasp skinned on the CPU
  (``core.skinning``: positions and normals) and uploaded as a dynamic mesh every frame.
* CPU cost per frame of the MIT models with GPU skinning: what the program does per frame on
  the CPU (evaluate the channels, pose the skeleton, W·B⁻¹ for 18 joints, upload 18 matrices)
  - the vertex work belongs to the GPU. Peer: skinning the 13,336 vertices on the CPU
  (positions + normals, ``core.skinning``), which GPU skinning replaces. Goal < 2 ms.

Software GL runs the vertex shader on the CPU too, so the draw itself is timed separately
(``draw + finish``) and is not part of the CPU-cost figure.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from benchmarks.common import print_rows  # noqa: E402

DATA = (REPO / ".." / "shared" / "data").resolve()
SIZE = (1280, 720)
FRAMES = 30
CPU_GOAL_MS = 2.0


def _row(name: str, ours: float | None, peer: float | None, goal: str, peer_name: str,
         met: bool | None = None, unit: str = "ms/frame", **extra: Any) -> dict[str, Any]:
    row: dict[str, Any] = {
        "name": name, "figure": None if ours is None else round(ours, 3), "unit": unit,
        "peer figure": None if peer is None else round(peer, 3),
        # the runner's convention for times: peer / ours, so that above 1 means we are faster
        "ratio": None if ours is None or peer is None or ours == 0 else round(peer / ours, 4),
        "goal": goal, "peer": peer_name,
    }
    if met is not None:
        row["met"] = met
    row.update(extra)
    return row


def _wasp_and_cloth_doc() -> Any:
    from qtanimator.core.cloth import ClothParams
    from qtanimator.document.character3d import add_character3d_command
    from qtanimator.document.cloth import add_cloth_command
    from qtanimator.document.commands import UndoStack
    from qtanimator.document.document import Document

    d = DATA / "cse169"
    doc = Document()
    stack = UndoStack(doc)
    stack.push(add_character3d_command(doc, d / "skeleton" / "wasp.skel", d / "skin" / "wasp.skin",
                                       d / "wasp_walk" / "wasp_walk.anim", asset_id="wasp"))
    stack.push(add_cloth_command(doc, ClothParams(rows=32, cols=32, origin=(1.5, 2.0, 0.0))))
    return doc


def _frame_times(doc: Any, cpu_skinning: bool) -> tuple[list[float], str]:
    from OpenGL import GL

    from qtanimator.core.skinning import skin_normals, skin_positions
    from qtanimator.document.character3d import character, world_matrices
    from qtanimator.render.gl.lights import ambient_of, lights_of
    from qtanimator.render.gl.renderer import CharacterDraw, ClothDraw, SceneRenderer, ViewOptions
    from qtanimator.render.render3d import OffscreenGL, default_camera
    from qtanimator.render.scene3d import scene_items

    gl = OffscreenGL(SIZE)
    renderer = SceneRenderer()
    info = f"{GL.glGetString(GL.GL_RENDERER).decode()}"
    options = ViewOptions(show_skeleton=False)
    camera = None
    # the cloth cache simulates each frame once; fill it first so only drawing is timed
    for f in range(FRAMES + 1):
        scene_items(doc, f / 60.0)
    times = []
    try:
        for f in range(-1, FRAMES):
            t = max(f, 0) / 60.0
            start = time.perf_counter()
            items = scene_items(doc, t)
            if cpu_skinning:
                skin = character(doc, "wasp").skin
                w = world_matrices(doc, "wasp", t)
                pos, nrm = skin_positions(skin, w), skin_normals(skin, w)
                for i, item in enumerate(items):
                    if isinstance(item, CharacterDraw) and item.skin is not None:
                        items[i] = ClothDraw("wasp-cpu", pos, nrm, skin.triangles, color=(0.78, 0.74, 0.68, 1.0))
            if camera is None:
                camera = default_camera(items, doc)
            gl.bind()
            renderer.render(items, camera, SIZE[0], SIZE[1], lights_of(doc), ambient_of(doc), options)
            GL.glFinish()
            if f >= 0:
                times.append((time.perf_counter() - start) * 1000.0)
    finally:
        renderer.release()
        gl.close()
    return times, info


def _mit_cpu_cost(model: str) -> tuple[float, float, float, int]:
    """(ours: CPU ms per frame with GPU skinning, peer: CPU skinning ms, draw+finish ms, max influences)."""
    from OpenGL import GL

    from qtanimator.core.channel import Key
    from qtanimator.core.skinning import skin_normals, skin_positions
    from qtanimator.document.character3d import add_character3d_command, character, dof_channel_id, pose_skeleton
    from qtanimator.document.commands import InsertKey, UndoStack
    from qtanimator.document.document import Document
    from qtanimator.render.gl.lights import ambient_of, lights_of
    from qtanimator.render.gl.renderer import SceneRenderer, ViewOptions
    from qtanimator.render.render3d import OffscreenGL, default_camera
    from qtanimator.render.scene3d import scene_items

    d = DATA / "mit6837"
    doc = Document()
    stack = UndoStack(doc)
    stack.push(add_character3d_command(doc, d / f"{model}.skel", obj_path=d / f"{model}.obj",
                                       attach_path=d / f"{model}.attach", asset_id="mit"))
    # animate every joint so that each frame really poses the character
    for j in range(18):
        for a, axis in enumerate("xyz"):
            cid = dof_channel_id(doc, "mit", j, axis)
            stack.push(InsertKey(doc, cid, Key.make(0.0, 0.0, "smooth")))
            stack.push(InsertKey(doc, cid, Key.make(1.0, 0.3 * np.sin(j + a), "smooth")))
    skin = character(doc, "mit").skin
    gl = OffscreenGL((320, 240))
    renderer = SceneRenderer()
    opts = ViewOptions(show_skeleton=False)
    ours, draws = [], []
    camera = None
    try:
        for f in range(-1, FRAMES):
            t = max(f, 0) / FRAMES
            start = time.perf_counter()
            items = scene_items(doc, t)           # pose, W·B⁻¹
            mesh = renderer.skinned_mesh(items[0].skin, "mit") if renderer.initialized else None
            if mesh is not None:
                mesh.set_joint_matrices(items[0].skin.matrices)   # the per-frame upload
            cpu = time.perf_counter() - start
            if camera is None:
                camera = default_camera(items, doc)
            s2 = time.perf_counter()
            gl.bind()
            renderer.render(items, camera, 320, 240, lights_of(doc), ambient_of(doc), opts)
            GL.glFinish()
            if f >= 0:
                ours.append(cpu * 1000.0)
                draws.append((time.perf_counter() - s2) * 1000.0)
    finally:
        renderer.release()
        gl.close()
    peer = []
    for f in range(FRAMES):
        w = pose_skeleton(doc, "mit", f / FRAMES).world_matrices()
        start = time.perf_counter()
        skin_positions(skin, w)
        skin_normals(skin, w, normals=skin.normals)
        peer.append((time.perf_counter() - start) * 1000.0)
    return float(np.median(ours)), float(np.median(peer)), float(np.median(draws)), skin.binding.max_influences


def run() -> list[dict[str, Any]]:
    rows: list[dict[str, Any]] = []
    if not DATA.is_dir():
        return [_row("3D viewport", None, None, "", "", skipped=f"sample data not found at {DATA}")]
    from qtanimator.render.render3d import ensure_gui_application

    ensure_gui_application()
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    doc = _wasp_and_cloth_doc()
    gpu, info = _frame_times(doc, cpu_skinning=False)
    cpu, _ = _frame_times(doc, cpu_skinning=True)
    rows.append(_row("software-GL frame, wasp (GPU skinning) + 32×32 cloth, 1280×720, 4× MSAA",
                     float(np.median(gpu)), float(np.median(cpu)), "report (software GL)",
                     "same frame, wasp skinned on the CPU and uploaded", renderer=info,
                     p90=round(float(np.percentile(gpu, 90)), 2), load_average=round(load, 2)))
    for model in ("Model1", "Model2", "Model3", "Model4"):
        ours, peer, draw, k = _mit_cpu_cost(model)
        rows.append(_row(f"CPU cost per frame, MIT {model} (13,336 vertices, ≤ {k} influences), GPU skinning",
                         ours, peer, f"< {CPU_GOAL_MS:g} ms", "CPU skinning of positions + normals (core.skinning)",
                         ours < CPU_GOAL_MS, software_gl_draw_ms=round(draw, 2)))
    return rows


def main() -> int:
    return print_rows(run(), ["name", "figure", "unit", "peer figure", "ratio", "goal", "met"])


if __name__ == "__main__":
    raise SystemExit(main())
