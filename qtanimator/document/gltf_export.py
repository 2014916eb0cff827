"""A 3D character as a glTF scene: every mesh, every clip, and the rest pose of its file.

The mapping is :mod:`qtanimator.document.gltf_character` run backwards (issue 21), so that
importing an export gives the same character back:

* **Joints** are nodes named after the joints (an unnamed glTF joint keeps ``Node_<i>``), with
  the rest pose as TRS: translation ``offset + translation`` (plus the rest root translation
  on roots), the rest rotation (the file's quaternion for a quaternion joint, the Euler DOFs'
  otherwise) and the scale. The skeleton's placement is a node ``placement`` above the roots
  (TRS; its matrix where a shear leaves no TRS).
* **Meshes.** The parts of one glTF mesh node (same node and mesh) form one mesh with a
  primitive each; every other part is a mesh of its own (a course character's skin is one
  part). A primitive has POSITION, NORMAL and TEXCOORD_0 where the skin has them, every
  influence (as many JOINTS_n / WEIGHTS_n sets as needed; weights divided by their sum, which
  glTF requires), and a material with the part's base colour. A skinned mesh has a node of its
  own at the scene root (glTF ignores that node's transform). A rigid part (each vertex on one
  joint slot with weight 1) is a mesh on its joint's node, its positions moved by the slot's
  inverse bind matrix: that is how the importer reads a mesh below a joint.
* **Skins.** The merged skin's palette maps joint slots to joints, each slot with its inverse
  bind matrix. Meshes share a glTF skin as long as no joint would be in it twice (glTF lists a
  node once per skin); a mesh that binds one joint through two slots gets, for the second, a
  helper node below that joint (the importer reads it as one more joint). Joints in no skin
  and carrying no mesh are added to the first skin: the importer keeps only skin joints, mesh
  nodes and the nodes between them, and folds a still root outside every skin into the placement.
* **Clips**: each clip is an animation with its own name and times
  (:mod:`qtanimator.document.gltf_export_clips`); a character without clips exports the
  document's channels over the frame range, time 0 at the range's start.

Texture coordinates: a character read from glTF holds them as glTF does (origin top left),
others as OpenGL does (origin bottom left, v flipped on export). A part's image (a glTF
baseColorTexture, a course skin's material texture) is embedded in the ``.glb`` as a buffer
view with its mime type, PNG and JPEG as they are and other formats (BMP) converted to PNG,
with a sampler and the material's ``baseColorTexture``; an image that is missing or cannot be
read is left out.
"""

from __future__ import annotations

import io
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.core.rotation import matrices_to_quaternions, polar
from qtanimator.core.skinning import Skin, skin_positions
from qtanimator.document.character3d_model import Character3D, MeshPart, TextureImage, character
from qtanimator.document.clips3d import clip_channels_of, clip_duration
from qtanimator.document.document import Document
from qtanimator.document.gltf_export_clips import clip_animation, rest_rotations
from qtanimator.document.gltf_skeleton_export import CharacterExport
from qtanimator.formats.gltf.model import (
    GltfImage,
    GltfMesh,
    GltfNode,
    GltfPrimitive,
    GltfScene,
    GltfSkin,
)

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

#: How far (relative to the model's size) renormalising the weights may move the rest
#: mesh before the export says so.
WEIGHT_TOLERANCE = 1e-4
PLACEMENT_NAME = "placement"

__all__ = ["PLACEMENT_NAME", "WEIGHT_TOLERANCE", "character_scene"]

_Key = tuple[str, int]  # ("joint", joint), ("helper", slot), ("mesh", unit) or ("placement", 0)


@dataclass
class _Unit:
    """Parts written as one glTF mesh; ``slot`` is the joint slot of a rigid one."""

    name: str
    parts: list[MeshPart]
    slot: int | None = None


@dataclass
class _SkinGroup:
    """One glTF skin: its joints (by key) and the slot each stands for (None: a joint added
    so that the importer keeps it, bound at its rest pose)."""

    keys: list[_Key] = field(default_factory=list)
    slots: list[int | None] = field(default_factory=list)

    def slot_of(self, key: _Key) -> int | None:
        return self.slots[self.keys.index(key)] if key in self.keys else None

    def fits(self, keyed: dict[int, _Key]) -> bool:
        return all(key not in self.keys or self.slot_of(key) == s for s, key in keyed.items())

    def add(self, keyed: dict[int, _Key]) -> None:
        for s, key in keyed.items():
            if key not in self.keys:
                self.keys.append(key)
                self.slots.append(s)


def character_scene(doc: Document, asset_id: str) -> tuple[CharacterExport, list[str]]:
    """The glTF scene of a 3D character (see the module doc) and messages for the user.

    Raises ValueError when the character has no skin or mesh."""
    ch = character(doc, asset_id)
    skin = ch.skin
    if skin is None:
        raise ValueError(f"3D character {asset_id!r} has no skin or mesh to export.")
    palette = np.arange(skin.num_joints) if ch.palette is None else np.asarray(ch.palette)
    units = _units(ch, asset_id, palette)
    groups, unit_skins = _skin_groups(ch, units, palette)
    order = _node_order(ch, units, groups, palette)
    index = {key: i for i, key in enumerate(order)}
    nodes = [GltfNode() for _ in order]
    _joint_nodes(ch, nodes, index)
    for key in order:
        if key[0] == "helper":
            parent = index[("joint", int(palette[key[1]]))]
            nodes[index[key]].name = f"{nodes[parent].name}.slot{key[1]}"
            nodes[index[key]].parent = parent
            nodes[parent].children.append(index[key])
    scene = GltfScene(nodes=nodes, generator="qtanimator")
    world = ch.skeleton.world_matrices()
    for g in groups:
        ibm = [skin.inverse_bind_matrices[s] if s is not None else np.linalg.inv(world[k[1]])
               for k, s in zip(g.keys, g.slots)]
        scene.skins.append(GltfSkin([index[k] for k in g.keys], np.array(ibm, dtype=np.float64)))
    _meshes(ch, units, unit_skins, scene, index, palette)
    scene.roots = [i for i, n in enumerate(nodes) if n.parent is None]

    messages: list[str] = []
    joint_nodes = [index[("joint", j)] for j in range(len(ch.skeleton.joints))]
    times = _animations(doc, asset_id, ch, joint_nodes, scene, messages)
    error = _renormalisation_error(ch)
    if error > WEIGHT_TOLERANCE:
        messages.append(f"{asset_id}: some vertices' weights do not sum to 1, which glTF requires; dividing them by "
                        f"their sum moves the mesh by up to {error:.2e} of its size.")
    mesh_node = index[order[0]] if units else -1
    return CharacterExport(scene, times, np.zeros(0, dtype=np.int64), error, joint_nodes, mesh_node), messages


def _node_order(ch: Character3D, units: list[_Unit], groups: list[_SkinGroup],
                palette: npt.NDArray[Any]) -> list[_Key]:
    """Mesh-bearing nodes first, in part order (the importer orders parts by node), then the
    other joints, the helpers and the placement. (Children follow the skeleton's order.)"""
    order: list[_Key] = [("mesh", u) if unit.slot is None else ("joint", int(palette[unit.slot]))
                         for u, unit in enumerate(units)]
    placed = set(order)
    order += [("joint", j) for j in range(len(ch.skeleton.joints)) if ("joint", j) not in placed]
    order += list(dict.fromkeys(key for g in groups for key in g.keys if key[0] == "helper"))
    if ch.skeleton.placement is not None:
        order.append(("placement", 0))
    return order


# ----------------------------------------------------------------------- meshes
def _units(ch: Character3D, asset_id: str, palette: npt.NDArray[Any]) -> list[_Unit]:
    skin = ch.skin
    assert skin is not None
    parts = list(ch.parts) or [MeshPart(asset_id, 0, skin.num_vertices, 0, len(skin.triangles),
                                        color=(1.0, 1.0, 1.0, 1.0) if ch.texture is not None else (0.8, 0.8, 0.8, 1.0),
                                        texture=ch.texture)]
    units: list[_Unit] = []
    by_source: dict[tuple[int | None, int | None, int | None], _Unit] = {}
    rigid_joints: set[int] = set()
    for part in parts:
        slot = None if part.skinned else _rigid_slot(skin, part)
        if slot is not None and int(palette[slot]) in rigid_joints and (part.node, part.mesh, slot) not in by_source:
            slot = None  # a joint node holds one mesh: a second rigid mesh on it is written skinned
        source = (part.node, part.mesh, slot)
        if part.node is not None and source in by_source:
            by_source[source].parts.append(part)
            continue
        unit = _Unit(part.name, [part], slot)
        units.append(unit)
        if part.node is not None:
            by_source[source] = unit
        if slot is not None:
            rigid_joints.add(int(palette[slot]))
    for unit in units:
        first = unit.parts[0]
        suffix = f".{first.primitive}"
        if len(unit.parts) > 1 and first.name.endswith(suffix):
            unit.name = first.name[: -len(suffix)]
    return units


def _rigid_slot(skin: Skin, part: MeshPart) -> int | None:
    """The slot every vertex of the part rides on with weight 1, else None."""
    idx, w = skin.binding.padded(np.float64)
    sub_i, sub_w = idx[part.start:part.start + part.count], w[part.start:part.start + part.count]
    if part.count == 0 or np.any(sub_w[:, 1:] != 0) or np.any(np.abs(sub_w[:, 0] - 1.0) > 1e-12):
        return None
    slots = np.unique(sub_i[:, 0])
    return int(slots[0]) if len(slots) == 1 else None


def _part_influences(skin: Skin, part: MeshPart) -> tuple[npt.NDArray[Any], FloatArray]:
    """(V, K) slots and weights of a part's vertices, strongest first, K the most any has."""
    idx, w = skin.binding.padded(np.float64)
    sl = slice(part.start, part.start + part.count)
    order = np.argsort(-w[sl], axis=1, kind="stable")
    slots = np.take_along_axis(idx[sl], order, axis=1)
    weights = np.take_along_axis(w[sl], order, axis=1)
    k = max(1, int((weights != 0).sum(axis=1).max())) if part.count else 1
    return slots[:, :k], weights[:, :k]


def _skin_groups(ch: Character3D, units: list[_Unit],
                 palette: npt.NDArray[Any]) -> tuple[list[_SkinGroup], dict[int, tuple[int, dict[int, int]]]]:
    """The glTF skins, and per skinned unit its skin and slot → joint index in that skin."""
    skin = ch.skin
    assert skin is not None
    groups: list[_SkinGroup] = []
    keyed_units: dict[int, dict[int, _Key]] = {}
    for u, unit in enumerate(units):
        if unit.slot is not None:
            continue
        found = [slots[weights != 0] for slots, weights in (_part_influences(skin, p) for p in unit.parts)]
        used = [int(s) for s in np.unique(np.concatenate(found))] or [0]
        keyed: dict[int, _Key] = {}
        taken: set[int] = set()
        for s in used:
            j = int(palette[s])
            keyed[s] = ("helper", s) if j in taken else ("joint", j)
            taken.add(j)
        keyed_units[u] = keyed
    placed: dict[int, int] = {}
    for u, keyed in keyed_units.items():
        g = next((i for i, grp in enumerate(groups) if grp.fits(keyed)), None)
        if g is None:
            groups.append(_SkinGroup())
            g = len(groups) - 1
        groups[g].add(keyed)
        placed[u] = g
    _add_missing_joints(ch, units, palette, groups)
    luts = {u: (g, {s: groups[g].keys.index(key) for s, key in keyed_units[u].items()}) for u, g in placed.items()}
    return groups, luts


def _add_missing_joints(ch: Character3D, units: list[_Unit], palette: npt.NDArray[Any],
                        groups: list[_SkinGroup]) -> None:
    """Put the joints that are in no skin and carry no mesh into the first skin (a new one if
    there is none): the importer keeps only skin joints, mesh nodes and the nodes between them,
    and would fold an unused root into the placement."""
    present = {k[1] for g in groups for k in g.keys if k[0] == "joint"}
    present |= {int(palette[u.slot]) for u in units if u.slot is not None}
    missing = [j for j in range(len(ch.skeleton.joints)) if j not in present]
    if missing and not groups:
        groups.append(_SkinGroup())
    for j in missing:
        groups[0].keys.append(("joint", j))
        groups[0].slots.append(None)


def _meshes(ch: Character3D, units: list[_Unit], unit_skins: dict[int, tuple[int, dict[int, int]]],
            scene: GltfScene, index: dict[_Key, int], palette: npt.NDArray[Any]) -> None:
    """One mesh per unit (a primitive per part) on its node, and a material per colour."""
    skin = ch.skin
    assert skin is not None
    colours: dict[tuple[Any, ...], int] = {}
    images: dict[int, int | None] = {}
    gltf_uv = ch.skeleton.dialect == "gltf"
    for u, unit in enumerate(units):
        prims = []
        for part in unit.parts:
            image = part.texture if skin.texcoords is not None else None
            texture = None if image is None else _texture(scene, image, images)
            material = colours.setdefault((*part.color, texture), len(colours))
            if material == len(scene.materials):
                scene.materials.append(_material(part, texture))
            if unit.slot is None:
                prims.append(_skinned_primitive(skin, part, unit_skins[u][1], material, gltf_uv))
            else:
                prims.append(_rigid_primitive(skin, part, unit.slot, material, gltf_uv))
        scene.meshes.append(GltfMesh(prims, unit.name))
        if unit.slot is None:
            node = scene.nodes[index[("mesh", u)]]
            node.name, node.skin = unit.name, unit_skins[u][0]
        else:
            node = scene.nodes[index[("joint", int(palette[unit.slot]))]]
        node.mesh = u


def _texcoords(skin: Skin, part: MeshPart, gltf_uv: bool) -> FloatArray | None:
    if skin.texcoords is None or np.shape(skin.texcoords)[1] < 2:
        return None
    uv = np.asarray(skin.texcoords, dtype=np.float64)[part.start:part.start + part.count, :2].copy()
    if not gltf_uv:
        uv[:, 1] = 1.0 - uv[:, 1]
    return uv


def _geometry(skin: Skin, part: MeshPart) -> tuple[FloatArray, IntArray, FloatArray | None]:
    sl = slice(part.start, part.start + part.count)
    tri = np.asarray(skin.triangles[part.triangle_start:part.triangle_start + part.triangle_count],
                     dtype=np.int64) - part.start
    if tri.size and (tri.min() < 0 or tri.max() >= part.count):
        raise ValueError(f"mesh part {part.name!r} has triangles on vertices of another part")
    normals = None if skin.normals is None else np.asarray(skin.normals, dtype=np.float64)[sl]
    return np.asarray(skin.positions, dtype=np.float64)[sl], tri, normals


def _skinned_primitive(skin: Skin, part: MeshPart, lut: dict[int, int], material: int,
                       gltf_uv: bool) -> GltfPrimitive:
    positions, tri, normals = _geometry(skin, part)
    slots, weights = _part_influences(skin, part)
    sums = weights.sum(axis=1, keepdims=True)
    weights = np.where(sums > 0, weights / np.where(sums > 0, sums, 1.0), weights)
    table = np.zeros(max(lut) + 1, dtype=np.int64)
    for s, local in lut.items():
        table[s] = local
    joints = np.where(weights != 0, table[np.clip(slots, 0, len(table) - 1)], 0)
    return GltfPrimitive(positions, tri, normals, _texcoords(skin, part, gltf_uv), joints, weights, material)


def _rigid_primitive(skin: Skin, part: MeshPart, slot: int, material: int, gltf_uv: bool) -> GltfPrimitive:
    positions, tri, normals = _geometry(skin, part)
    ibm = np.asarray(skin.inverse_bind_matrices[slot], dtype=np.float64)
    if not np.array_equal(ibm, np.eye(4)):
        positions = positions @ ibm[:3, :3].T + ibm[:3, 3]
        if normals is not None:
            normals = normals @ np.linalg.inv(ibm[:3, :3])
    return GltfPrimitive(positions, tri, normals, _texcoords(skin, part, gltf_uv), material=material)


def _material(part: MeshPart, texture: int | None = None) -> dict[str, Any]:
    colour = [float(c) for c in part.color]
    m: dict[str, Any] = {"name": part.name, "pbrMetallicRoughness": {
        "baseColorFactor": colour, "metallicFactor": 0.0, "roughnessFactor": 1.0}}
    if texture is not None:
        m["pbrMetallicRoughness"]["baseColorTexture"] = {"index": texture}
    if colour[3] < 1.0:
        m["alphaMode"] = "BLEND"
    return m


def _image_bytes(image: TextureImage) -> tuple[bytes, str] | None:
    """The image as glTF may embed it: PNG and JPEG as they are, another format Pillow reads
    (a course skin's BMP) converted to PNG; None when it is missing or unreadable."""
    data = image.read()
    if not data:
        return None
    if data.startswith(b"\x89PNG\r\n\x1a\n"):
        return data, "image/png"
    if data.startswith(b"\xff\xd8\xff"):
        return data, "image/jpeg"
    try:
        from PIL import Image

        with Image.open(io.BytesIO(data)) as im:
            out = io.BytesIO()
            im.convert("RGBA" if "A" in im.getbands() else "RGB").save(out, format="PNG")
    except Exception:  # noqa: BLE001 - any undecodable image is left out, not an error
        return None
    return out.getvalue(), "image/png"


def _texture(scene: GltfScene, image: TextureImage, done: dict[int, int | None]) -> int | None:
    """The index of a texture (image and sampler) for ``image``, written once per image;
    None when the image cannot be embedded (the part keeps its colour only)."""
    key = id(image)
    if key not in done:
        embedded = _image_bytes(image)
        if embedded is None:
            done[key] = None
        else:
            scene.images.append(GltfImage(embedded[0], embedded[1], None, image.name))
            wrap = 33071 if image.wrap == "clamp" else 10497  # CLAMP_TO_EDGE, REPEAT
            scene.samplers.append({"magFilter": 9729, "minFilter": 9987, "wrapS": wrap, "wrapT": wrap})
            scene.textures.append({"sampler": len(scene.samplers) - 1, "source": len(scene.images) - 1})
            done[key] = len(scene.textures) - 1
    return done[key]


def _renormalisation_error(ch: Character3D) -> float:
    """How far dividing the weights by their sums moves the rest mesh, relative to its size."""
    skin = ch.skin
    assert skin is not None
    sums = skin.binding.weight_sums()
    if not np.any(np.abs(sums[sums > 0] - 1.0) > 1e-9):
        return 0.0
    world = ch.skinning_world(ch.skeleton.world_matrices())
    full = skin_positions(skin, world)
    fixed = skin_positions(Skin(skin.positions, skin.triangles, skin.binding.renormalized(),
                                skin.inverse_bind_matrices), world)
    size = float(np.linalg.norm(np.ptp(full, axis=0))) or 1.0
    return float(np.abs(full - fixed).max()) / size


# ----------------------------------------------------------------------- joints
def _joint_nodes(ch: Character3D, nodes: list[GltfNode], index: dict[_Key, int]) -> None:
    """Name, rest TRS and hierarchy of the joint nodes and the placement node."""
    sk = ch.skeleton
    rest_q = rest_rotations(ch)
    placement = index.get(("placement", 0))
    for j, joint in enumerate(sk.joints):
        node = nodes[index[("joint", j)]]
        node.name = joint.name
        node.translation = joint.offset + joint.translation + (sk.root_translation if joint.parent is None else 0.0)
        node.rotation = rest_q[j].copy()
        node.scale = joint.scale.copy()
        parent = placement if joint.parent is None else index[("joint", joint.parent)]
        if parent is not None:
            node.parent = parent
            nodes[parent].children.append(index[("joint", j)])
    if placement is not None and sk.placement is not None:
        _place(nodes[placement], sk.placement)


def _place(node: GltfNode, m: FloatArray) -> None:
    node.name = PLACEMENT_NAME
    r, stretch = polar(m[:3, :3])
    scale = np.diag(stretch).copy()
    if np.allclose(stretch, np.diag(scale), atol=1e-9 * max(1.0, float(np.abs(scale).max()))):
        node.translation = m[:3, 3].copy()
        node.rotation = matrices_to_quaternions(r)
        node.scale = scale
    else:
        node.matrix = np.asarray(m, dtype=np.float64).copy()


# ------------------------------------------------------------------- animations
def _animations(doc: Document, asset_id: str, ch: Character3D, node_of: list[int], scene: GltfScene,
                messages: list[str]) -> FloatArray:
    """Add the clips (or the document's channels) as animations; the first one's times."""
    first_times: FloatArray | None = None
    if ch.clips:
        for clip in ch.clips:
            start, end = clip_duration(doc, asset_id, clip.name)
            shift = min(start, 0.0)
            if shift < 0:
                messages.append(f"{clip.name}: keys before time 0, which glTF cannot hold: the clip starts at 0.")
            chans = clip_channels_of(doc, asset_id, clip.name)
            result = clip_animation(ch, node_of, chans, asset_id, clip.name, start, end, doc.fps, shift)
            messages += result.messages
            if result.animation is not None:
                scene.animations.append(result.animation)
                first_times = result.times if first_times is None else first_times
    else:
        chans = dict(doc.channels_of(asset_id))
        if any(c.keys for c in chans.values()):
            first, last = doc.frame_range
            start, end = doc.frame_to_time(first), doc.frame_to_time(last)
            result = clip_animation(ch, node_of, chans, asset_id, asset_id, start, max(start, end), doc.fps, start)
            messages += result.messages
            if result.animation is not None:
                scene.animations.append(result.animation)
                first_times = result.times
    return np.zeros(0) if first_times is None else first_times
