"""What the 3D view shows at a time, as plain draw data built from the document.

``scene_items(doc, time)`` turns every 3D asset (characters with skeleton and skin, cloths)
into :mod:`qtanimator.render.gl.renderer` draw items. It reads the document through the
engines' public functions and never touches GL, so the viewport, the headless renderer and
picking share it.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

from qtanimator.core.skeleton import DEFAULT_BOXMAX, DEFAULT_BOXMIN
from qtanimator.core.skinning import vertex_normals
from qtanimator.document import character3d, cloth
from qtanimator.render.gl.meshes import csr_influences
from qtanimator.render.gl.renderer import SKIN_COLOR, CharacterDraw, ClothDraw, PlaneDraw, SceneItem, SkinDraw

CHARACTER_KIND = character3d.ASSET_KIND
CLOTH_KIND = cloth.ASSET_KIND


def scene_items(doc: Any, time: float, selection: tuple[str, str] = ("", ""),
                cloth_override: dict[str, Any] | None = None,
                errors: list[str] | None = None, wait: bool = True) -> list[SceneItem]:
    """Draw items for every 3D asset of ``doc`` at ``time`` seconds.

    ``cloth_override`` maps a cloth asset id to a live simulation (anything with
    ``positions``, ``normals()``, ``triangles``, ``params`` and ``pinned``: a ``Cloth`` or a
    ``LiveClothFrame``) to show instead of the document's cached state (the viewport's
    interactive cloth). With an ``errors`` list, an asset that cannot be evaluated is left
    out and its error appended there (the viewport keeps drawing the rest); without it the
    error propagates. ``wait=False`` never simulates: a cloth whose frame is not cached yet
    (a worker is filling the cache) shows its newest cached frame and is marked ``stale``.
    """
    items: list[SceneItem] = []
    for asset_id, asset in doc.assets.items():
        if asset.properties.get("hidden"):
            continue  # hidden in the outliner (document.outliner)
        try:
            if asset.kind == CHARACTER_KIND:
                item = character_item(doc, asset_id, time, selection)
                if item is not None:
                    items.append(item)
            elif asset.kind == CLOTH_KIND:
                live = (cloth_override or {}).get(asset_id)
                citem = cloth_item(doc, asset_id, time, live, wait)
                if citem is not None:
                    items.append(citem)
        except Exception as exc:
            if errors is None:
                raise
            errors.append(f"{asset_id}: {type(exc).__name__}: {exc}")
    return items


def character_item(doc: Any, asset_id: str, time: float,
                   selection: tuple[str, str] = ("", "")) -> CharacterDraw | None:
    skel = character3d.pose_skeleton(doc, asset_id, time)
    world = np.asarray(skel.world_matrices(), dtype=float)
    selected = None
    if selection[0] == asset_id and selection[1]:
        with contextlib.suppress(KeyError, ValueError):
            selected = joint_index(skel, selection[1])
    has_boxes = draws_boxes(skel)
    item = CharacterDraw(asset_id, world, skel.parents, selected=selected,
                         joint_radius=joint_radius(skel, world))
    if has_boxes:
        item.boxmin = np.array([j.boxmin for j in skel.joints])
        item.boxmax = np.array([j.boxmax for j in skel.joints])
    item.skin = skin_draw(doc, asset_id, world)
    return item


def draws_boxes(skel: Any) -> bool:
    """Balljoint skeletons with boxes draw them; others (MIT, BVH, no boxes) draw spheres and bones."""
    if skel.rotation_order != "zyx" or not skel.joints:
        return False
    return any(not (np.allclose(j.boxmin, DEFAULT_BOXMIN) and np.allclose(j.boxmax, DEFAULT_BOXMAX))
               for j in skel.joints)


def joint_index(skel: Any, key: str) -> int:
    """Index of a joint by its stable key (``name`` or ``name#index``)."""
    keys = skel.joint_keys()
    if key in keys:
        return keys.index(key)
    return int(skel.index_of(key))


def joint_radius(skel: Any, world: np.ndarray) -> float:
    """Sphere radius for drawing joints: a small fraction of the skeleton's size."""
    pos = world[:, :3, 3]
    if len(pos) < 2:
        return 0.05
    extent = float(np.linalg.norm(pos.max(axis=0) - pos.min(axis=0)))
    return max(extent * 0.022, 1e-3)


def skin_draw(doc: Any, asset_id: str, world: np.ndarray) -> SkinDraw | None:
    """The skin of a character as bind data plus this pose's skinning matrices."""
    runtime = doc.runtime.get(asset_id)
    skin = getattr(runtime, "skin", None)
    if skin is None:
        return None
    arrays = gpu_skin_arrays(skin)
    if isinstance(runtime, character3d.Character3D):
        world = runtime.skinning_world(world)
    faceted = bool(getattr(runtime, "faceted", False)) or arrays["faceted"]
    inv = arrays["inverse_bind"]
    n = min(len(world), len(inv))
    matrices = np.tile(np.eye(4), (len(inv), 1, 1))
    matrices[:n] = world[:n] @ inv[:n]
    is_character = isinstance(runtime, character3d.Character3D)
    parts = part_colors(runtime, len(arrays["triangles"])) if is_character else ()
    textures = texture_ranges(runtime, len(arrays["triangles"])) if is_character else ()
    texcoords = gpu_texcoords(skin, runtime) if textures else None
    return SkinDraw(key=skin, positions=arrays["positions"], normals=arrays["normals"],
                    triangles=arrays["triangles"], influence=arrays["influence"], pairs=arrays["pairs"],
                    matrices=matrices, faceted=faceted, parts=parts, texcoords=texcoords,
                    textures=textures if texcoords is not None else ())


def texture_ranges(runtime: character3d.Character3D, triangles: int) -> tuple[tuple[int, int, Color, Any], ...]:
    """(first triangle, count, base colour, image or None) covering the skin when a part (or,
    for a skin without parts, the character) has an image; empty otherwise. A textured part's
    base colour is its material's (white for a course skin's texture); untextured ranges keep
    the colours :func:`part_colors` gives them."""
    if not runtime.parts:
        return ((0, triangles, WHITE, runtime.texture),) if runtime.texture is not None and triangles else ()
    if not any(p.texture is not None for p in runtime.parts):
        return ()
    coloured = part_colors(runtime, triangles) or ((0, triangles, SKIN_COLOR),)
    images = sorted(((p.triangle_start, p.triangle_count, display_color(p.color), p.texture)
                     for p in runtime.parts if p.texture is not None and p.triangle_count > 0),
                    key=lambda r: r[0])
    out: list[tuple[int, int, Color, Any]] = []
    for first, count, colour in coloured:
        at, end = first, first + count
        for t_first, t_count, t_colour, image in images:
            lo, hi = max(at, t_first), min(end, t_first + t_count)
            if hi <= lo:
                continue
            if lo > at:
                out.append((at, lo - at, colour, None))
            out.append((lo, hi - lo, t_colour, image))
            at = hi
        if at < end:
            out.append((at, end - at, colour, None))
    return tuple(out)


def gpu_texcoords(skin: Any, runtime: Any) -> np.ndarray | None:
    """(N, 2) float32 texture coordinates with t = 0 at the image's top row (glTF's v as it
    is; a course skin's v, whose origin is the bottom left, flipped), cached in the skin's extras."""
    extras = getattr(skin, "extras", None)
    cached = extras.get("_gpu_texcoords") if isinstance(extras, dict) else None
    if cached is not None:
        return cached
    uv = getattr(skin, "texcoords", None)
    if uv is None or np.shape(uv)[1] < 2:
        return None
    out = np.asarray(uv, dtype=np.float32)[:, :2].copy()
    if getattr(runtime.skeleton, "dialect", "") != "gltf":
        out[:, 1] = 1.0 - out[:, 1]
    if isinstance(extras, dict):
        extras["_gpu_texcoords"] = out
    return out


Color = tuple[float, float, float, float]
#: the base colour of a course skin's texture (the image as it is)
WHITE: Color = (1.0, 1.0, 1.0, 1.0)


def display_color(linear: Sequence[float]) -> Color:
    """A material's base colour (linear, as glTF stores it) as the colour the view draws with:
    sRGB-encoded, as the view's other colours are (the shaders do no gamma), opaque."""
    c = np.clip(np.asarray(linear[:3], dtype=float), 0.0, 1.0)
    srgb = np.where(c <= 0.0031308, 12.92 * c, 1.055 * c ** (1.0 / 2.4) - 0.055)
    return (float(srgb[0]), float(srgb[1]), float(srgb[2]), 1.0)


def part_colors(runtime: character3d.Character3D, triangles: int) -> tuple[tuple[int, int, Color], ...]:
    """(first triangle, triangle count, colour) ranges covering the skin's ``triangles``
    when its mesh parts differ in colour: each part in its material's colour (triangles no
    part holds in SKIN_COLOR). Empty when the parts share one colour (or there are none, as
    for course characters): the skin is drawn in SKIN_COLOR, as before."""
    parts = sorted((p for p in runtime.parts if p.triangle_count > 0), key=lambda p: p.triangle_start)
    if len({tuple(p.color[:3]) for p in parts}) < 2:
        return ()
    out: list[tuple[int, int, Color]] = []
    at = 0
    for part in parts:
        first = max(part.triangle_start, at)
        end = min(part.triangle_start + part.triangle_count, triangles)
        if first > at:
            out.append((at, first - at, SKIN_COLOR))
        if end > first:
            out.append((first, end - first, display_color(part.color)))
            at = end
    if at < triangles:
        out.append((at, triangles - at, SKIN_COLOR))
    return tuple(out)


def gpu_skin_arrays(skin: Any) -> dict[str, Any]:
    """Bind positions, normals, triangles, sparse influences and inverse bind matrices of a
    :class:`qtanimator.core.skinning.Skin`, computed once per skin and kept in its extras."""
    extras = getattr(skin, "extras", None)
    cached = extras.get("_gpu_arrays") if isinstance(extras, dict) else None
    if cached is not None:
        return cached
    positions = np.asarray(skin.positions, dtype=float)
    normals = skin.normals
    normals = None if normals is None or len(normals) != len(positions) else np.asarray(normals, dtype=float)
    indptr, joints, weights = skin.binding.csr()
    influence, pairs = csr_influences(indptr, joints, weights)
    faceted = normals is None
    out = {"positions": positions, "normals": normals, "triangles": np.asarray(skin.triangles, dtype=np.int64),
           "influence": influence, "pairs": pairs,
           "inverse_bind": np.asarray(skin.inverse_bind_matrices, dtype=float), "faceted": faceted}
    if isinstance(extras, dict):
        extras["_gpu_arrays"] = out
    return out


def cloth_item(doc: Any, asset_id: str, time: float, live: Any = None, wait: bool = True) -> ClothDraw | None:
    """A cloth asset: the live simulation ``live`` when given, else the document's cached
    simulation at the frame of ``time`` (with ``wait=False`` the newest cached frame up to
    it, never simulating: the item is ``stale`` when that is an earlier frame)."""
    stale = False
    if live is not None:
        positions = np.asarray(live.positions, dtype=float)
        normals = np.asarray(live.normals(), dtype=float)
        triangles, params, pinned = live.triangles, live.params, live.pinned
    else:
        cache = cloth.cloth_cache(doc, asset_id)
        frame = doc.time_to_frame(time)
        if wait:
            positions = np.asarray(cache.positions(frame), dtype=float)
        else:
            cached, exact = cache.latest(frame)
            positions, stale = np.asarray(cached, dtype=float), not exact
        triangles, params, pinned = cache.triangles, cache.params, cache.cloth.pinned
        normals = vertex_normals(positions, np.asarray(triangles, dtype=np.int64))
    item = ClothDraw(asset_id, positions, normals, np.asarray(triangles, dtype=np.int64), stale=stale)
    for s in getattr(params, "spheres", None) or []:
        item.spheres.append((np.asarray(s[0], dtype=float), float(s[1])))
    if pinned is not None:
        idx = np.asarray(pinned)
        if idx.dtype == bool:
            idx = np.nonzero(idx)[0]
        if idx.size:
            item.pinned = positions[idx.astype(np.int64)]
    return item


def scene_bounds(items: Iterable[SceneItem]) -> tuple[np.ndarray, np.ndarray] | None:
    """Axis-aligned bounds of everything drawn (None for an empty scene)."""
    pts: list[np.ndarray] = []
    for item in items:
        if isinstance(item, CharacterDraw):
            pts.append(item.world[:, :3, 3])
            if item.skin is not None:
                pts.append(skinned_positions(item.skin, 500))
        elif isinstance(item, ClothDraw):
            pts.append(item.positions)
        elif isinstance(item, PlaneDraw):
            s = item.size / 2
            pts.append(np.array([[-s, item.height, -s], [s, item.height, s]]))
    if not pts:
        return None
    allp = np.concatenate(pts)
    return allp.min(axis=0), allp.max(axis=0)


def skinned_positions(skin: SkinDraw, max_vertices: int | None = None) -> np.ndarray:
    """CPU linear blend skinning of (a subsample of) a skin's vertices, for bounds and tests."""
    step = 1 if max_vertices is None else max(1, len(skin.positions) // max_vertices)
    idx = np.arange(0, len(skin.positions), step)
    out = np.zeros((len(idx), 3))
    first = skin.influence[idx, 0].astype(np.int64)
    count = skin.influence[idx, 1].astype(np.int64)
    h = np.c_[skin.positions[idx], np.ones(len(idx))]
    for k in range(int(count.max()) if len(count) else 0):
        has = count > k
        jw = skin.pairs[first[has] + k]
        m = skin.matrices[jw[:, 0].astype(np.int64)]
        out[has] += jw[:, 1:2] * np.einsum("nab,nb->na", m, h[has])[:, :3]
    return out
