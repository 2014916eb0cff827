"""A glTF scene as one 3D character: every mesh, every animation, joints that move, turn and scale.

The mapping (issue 21; docs/formats.md lists what is read):

* **Skeleton.** Every node that is a joint of a skin or carries a mesh, and every node
  above those, becomes a joint, in depth-first order (several roots are allowed). A joint's
  rest pose is its node's: translation (``offset`` 0, ``translation`` the node's), rotation
  (Euler DOFs equal to the node's quaternion) and scale. Its rotation is keyed as a
  quaternion (:attr:`~qtanimator.core.skeleton.Joint.quaternion`); it gets translation and
  scale channels where an animation moves or scales it. A node given as a ``matrix`` is
  split into translation, rotation and scale (a shear, which TRS cannot hold, is noted).
  A joint's name is its node's, or ``Node_<index>`` (Blender's name) when it has none.
* **Placement.** Nodes above the skeleton that no animation moves and that hold only the
  skeleton (CesiumMan's Z-up to Y-up node) are not joints: their product is the
  skeleton's :attr:`~qtanimator.core.skeleton.Skeleton.placement`.
* **Meshes.** Every primitive of every mesh node is a :class:`MeshPart` of one merged
  :class:`~qtanimator.core.skinning.Skin`. A skinned primitive keeps its skin's inverse
  bind matrices through the character's palette (each glTF skin has its own slots); a mesh
  without a skin rides rigidly on its node's joint. Parts keep their material's base colour.
* **Textures.** A material's ``baseColorTexture`` becomes the part's
  :class:`~qtanimator.document.character3d.TextureImage` (embedded bytes, or the ``uri``'s
  file inside the file's folder); the render layer decodes it. Its base colour is the factor
  (white without one).
* **Clips.** Every animation is a :class:`ClipSource` named as in the file (``Animation
  <i>`` when unnamed) with its keys as they are: translation and scale keys become linear,
  stepped or cubic (fixed-slope Hermite, exactly glTF's CUBICSPLINE) keys; rotation keys
  become four quaternion channels (``qw qx qy qz``) that
  :mod:`qtanimator.core.quaternion_channels` evaluates with slerp, steps or the cubic
  spline, as the specification says. Morph target weights are not read.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from urllib.parse import unquote

import numpy as np
import numpy.typing as npt

from qtanimator.core.channel import Channel, Extrapolation, Interpolation, Key
from qtanimator.core.rotation import euler_from_matrices, matrices_to_quaternions, polar, quaternion_to_matrix
from qtanimator.core.skeleton import DEFAULT_BOXMAX, DEFAULT_BOXMIN, Joint, Skeleton
from qtanimator.core.skinning import Skin, SkinBinding, vertex_normals
from qtanimator.document.character3d_model import (
    QUAT_DOFS,
    SCALE_DOFS,
    TRANSLATE_DOFS,
    Character3D,
    ClipSource,
    MeshPart,
    TextureImage,
)
from qtanimator.document.document import Asset
from qtanimator.formats.errors import FormatError
from qtanimator.formats.gltf.model import GltfAnimation, GltfSampler, GltfScene
from qtanimator.formats.gltf.reader import import_gltf

FloatArray = npt.NDArray[np.float64]

#: Euler order the DOF sliders show glTF rotations in (R = Rz·Ry·Rx).
GLTF_ROTATION_ORDER = "zyx"
DEFAULT_COLOR = (0.8, 0.8, 0.8, 1.0)

__all__ = ["GLTF_ROTATION_ORDER", "GltfMapping", "character_from_gltf", "node_name"]


@dataclass
class GltfMapping:
    """The character and how it relates to the file: ``nodes[j]`` is joint j's node."""

    character: Character3D
    nodes: list[int]
    notes: list[str]


def node_name(scene: GltfScene, index: int) -> str:
    """A node's name, or ``Node_<index>`` (as Blender names it) when it has none."""
    name = scene.nodes[index].name
    return name if name else f"Node_{index}"


def _animated(scene: GltfScene) -> dict[int, set[str]]:
    """Node → the paths (translation, rotation, scale) any animation drives."""
    out: dict[int, set[str]] = {}
    for anim in scene.animations:
        for ch in anim.channels:
            if ch.path in ("translation", "rotation", "scale"):
                out.setdefault(ch.node, set()).add(ch.path)
    return out


def _needed_nodes(scene: GltfScene) -> set[int]:
    """Joints, mesh nodes and every node above them."""
    seeds: set[int] = set()
    for skin in scene.skins:
        seeds.update(skin.joints)
    for i, node in enumerate(scene.nodes):
        if node.mesh is not None and not _skinned_node(scene, i):
            seeds.add(i)
    needed: set[int] = set()
    for i in seeds:
        k: int | None = i
        while k is not None and k not in needed:
            needed.add(k)
            k = scene.nodes[k].parent
    return needed


def _skinned_node(scene: GltfScene, index: int) -> bool:
    """A mesh node whose primitives are all skinned (its own transform is ignored)."""
    node = scene.nodes[index]
    if node.mesh is None or node.skin is None:
        return False
    return all(p.joints is not None and p.weights is not None for p in scene.meshes[node.mesh].primitives)


def _split_placement(scene: GltfScene, needed: set[int], animated: dict[int, set[str]],
                     joint_nodes: set[int]) -> tuple[FloatArray | None, list[int]]:
    """Fold the still wrapper nodes at the top into a placement matrix; return it and the
    skeleton's root nodes."""
    roots = [i for i in range(len(scene.nodes)) if i in needed and scene.nodes[i].parent not in needed]
    placement: FloatArray | None = None
    while len(roots) == 1:
        r = roots[0]
        node = scene.nodes[r]
        kids = [c for c in node.children if c in needed]
        if r in joint_nodes or r in animated or node.mesh is not None or not kids:
            break
        m = node.local_matrix()
        placement = m if placement is None else placement @ m
        roots = kids
    return placement, roots


def _trs(scene: GltfScene, index: int) -> tuple[FloatArray, FloatArray, FloatArray, bool]:
    """Translation, rotation matrix and scale of a node; False when a matrix had a shear."""
    node = scene.nodes[index]
    if node.matrix is None:
        return (np.asarray(node.translation, dtype=np.float64).copy(), quaternion_to_matrix(node.rotation),
                np.asarray(node.scale, dtype=np.float64).copy(), True)
    m = np.asarray(node.matrix, dtype=np.float64)
    r, stretch = polar(m[:3, :3])
    scale = np.diag(stretch).copy()
    exact = bool(np.allclose(stretch, np.diag(scale), atol=1e-9 * max(1.0, float(np.abs(scale).max()))))
    return m[:3, 3].copy(), r, scale, exact


def _material_color(scene: GltfScene, material: int | None) -> tuple[float, float, float, float]:
    if material is None or not 0 <= material < len(scene.materials):
        return DEFAULT_COLOR
    pbr = scene.materials[material].get("pbrMetallicRoughness")
    factor = pbr.get("baseColorFactor") if isinstance(pbr, dict) else None
    if (isinstance(factor, list) and len(factor) == 4
            and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in factor)):
        c = [min(max(float(x), 0.0), 1.0) for x in factor]
        return (c[0], c[1], c[2], c[3])
    if _base_color_texture(scene, material) is not None:
        return (1.0, 1.0, 1.0, 1.0)  # the specification's default factor: the texture as it is
    return DEFAULT_COLOR


def _base_color_texture(scene: GltfScene, material: int | None) -> int | None:
    """The image index of a material's ``baseColorTexture`` (None without one)."""
    if material is None or not 0 <= material < len(scene.materials):
        return None
    pbr = scene.materials[material].get("pbrMetallicRoughness")
    info = pbr.get("baseColorTexture") if isinstance(pbr, dict) else None
    index = info.get("index") if isinstance(info, dict) else None
    if not isinstance(index, int) or isinstance(index, bool) or not 0 <= index < len(scene.textures):
        return None
    source = scene.textures[index].get("source")
    if not isinstance(source, int) or isinstance(source, bool) or not 0 <= source < len(scene.images):
        return None
    return source


def _image_texture(scene: GltfScene, image: int, folder: Path | None) -> TextureImage:
    """An image of the file: its embedded bytes, or its ``uri`` as a file inside the file's
    folder (a path that leaves the folder, or a URL, stays unread: the checkerboard)."""
    im = scene.images[image]
    name = im.name or f"Image_{image}"
    if im.data is not None:
        return TextureImage(data=im.data, mime_type=im.mime_type, name=name)
    path: str | None = None
    if im.uri and folder is not None and "://" not in im.uri:
        candidate = (folder / unquote(im.uri)).resolve()
        if candidate.is_relative_to(folder.resolve()):
            path = str(candidate)
    return TextureImage(path=path, mime_type=im.mime_type, name=name)


def _keys(sampler: GltfSampler, column: int, start: int = 0) -> list[Key]:
    """One component's keys from a sampler (glTF interpolation kept exactly)."""
    times = sampler.times
    if sampler.interpolation == "CUBICSPLINE":
        vals = sampler.values  # (K, 3, n): in-tangent, value, out-tangent
        return Key.series(times, vals[:, 1, column], Interpolation.CUBIC, vals[:, 0, column], vals[:, 2, column])
    interp = Interpolation.CONSTANT if sampler.interpolation == "STEP" else Interpolation.LINEAR
    return Key.series(times, sampler.values[:, column], interp)


def _channel(keys: list[Key]) -> Channel:
    return Channel(keys, Extrapolation.CONSTANT, Extrapolation.CONSTANT)


def _clip(scene: GltfScene, ai: int, anim: GltfAnimation, joint_of: dict[int, int], keys: list[str],
          name: str) -> ClipSource:
    channels: dict[str, Channel] = {}
    for ch in anim.channels:
        j = joint_of.get(ch.node)
        if j is None or ch.path not in ("translation", "rotation", "scale"):
            continue
        sampler = anim.samplers[ch.sampler]
        if ch.path == "rotation":
            for column, dof in zip((3, 0, 1, 2), QUAT_DOFS):
                channels[f"{keys[j]}/{dof}"] = _channel(_keys(sampler, column))
        else:
            dofs = TRANSLATE_DOFS if ch.path == "translation" else SCALE_DOFS
            for column, dof in enumerate(dofs):
                channels[f"{keys[j]}/{dof}"] = _channel(_keys(sampler, column))
    return ClipSource(name, anim.start, anim.end, channels, ai)


def _clip_names(scene: GltfScene) -> list[str]:
    names: list[str] = []
    for i, anim in enumerate(scene.animations):
        base = anim.name or f"Animation {i}"
        name, n = base, 2
        while name in names:
            name, n = f"{base} ({n})", n + 1
        names.append(name)
    return names


def character_from_gltf(scene: GltfScene, path: str | os.PathLike[str] | None = None) -> GltfMapping:
    """The whole character of a glTF scene (see the module doc). Never raises for a scene
    :func:`~qtanimator.formats.gltf.import_gltf` accepted."""
    notes: list[str] = []
    animated = _animated(scene)
    needed = _needed_nodes(scene)
    joint_nodes = {j for skin in scene.skins for j in skin.joints}
    placement, roots = _split_placement(scene, needed, animated, joint_nodes)

    order: list[int] = []
    parents: list[int | None] = []
    stack: list[tuple[int, int | None]] = [(r, None) for r in reversed(roots)]
    while stack:
        n, p = stack.pop()
        order.append(n)
        parents.append(p)
        idx = len(order) - 1
        stack.extend((c, idx) for c in reversed(scene.nodes[n].children) if c in needed)
    joint_of = {n: j for j, n in enumerate(order)}

    joints: list[Joint] = []
    sheared: list[str] = []
    rest_r = np.zeros((len(order), 3, 3))
    for j, n in enumerate(order):
        t, r, s, exact = _trs(scene, n)
        if not exact:
            sheared.append(node_name(scene, n))
        rest_r[j] = r
        paths = animated.get(n, set())
        joints.append(Joint(node_name(scene, n), parents[j], np.zeros(3), boxmin=np.array(DEFAULT_BOXMIN),
                            boxmax=np.array(DEFAULT_BOXMAX), rotation_order=GLTF_ROTATION_ORDER,
                            translation=t, scale=s, quaternion=True,
                            translates="translation" in paths, scales="scale" in paths))
    skeleton = Skeleton(joints, rotation_order=GLTF_ROTATION_ORDER, name=Path(path).stem if path else "",
                        dialect="gltf")
    skeleton.placement = placement
    if order:
        angles = euler_from_matrices(rest_r, GLTF_ROTATION_ORDER)
        for j, joint in enumerate(skeleton.joints):
            for a in range(3):
                joint.dofs[a].value = float(angles[j, a])
    if sheared:
        notes.append(f"{len(sheared)} node matrices have a shear, which a joint cannot hold: "
                     f"{', '.join(sheared[:5])}.")

    where = path if path is not None else scene.path
    skin, parts, palette = _merged_skin(scene, joint_of, notes, Path(where).parent if where else None)
    keys = skeleton.joint_keys()
    clips = [_clip(scene, i, a, joint_of, keys, name)
             for i, (a, name) in enumerate(zip(scene.animations, _clip_names(scene)))]
    if any(ch.path == "weights" for a in scene.animations for ch in a.channels):
        notes.append("The file animates morph target weights; morph targets are not read.")
    ch = Character3D(skeleton, skin, None, None, False, parts=parts, clips=clips, palette=palette, notes=notes)
    # The rest quaternions are the file's own (Euler angles would give the same rotation
    # with possibly the other sign, which matters for cubic spans only through the keys).
    rest_q = np.tile(np.array([0.0, 0.0, 0.0, 1.0]), (len(order), 1))
    for j, n in enumerate(order):
        node = scene.nodes[n]
        rest_q[j] = (np.asarray(node.rotation, dtype=np.float64) if node.matrix is None
                     else matrices_to_quaternions(rest_r[j]))
    ch._rest_quaternions = rest_q
    return GltfMapping(ch, order, notes)


def _merged_skin(scene: GltfScene, joint_of: dict[int, int], notes: list[str],
                 folder: Path | None = None) -> tuple[Skin | None, list[MeshPart], npt.NDArray[np.intp] | None]:
    """Every primitive of every mesh node in one skin, with its palette."""
    palette: list[int] = []
    ibms: list[FloatArray] = []
    skin_base: dict[int, int] = {}
    rigid_slot: dict[int, int] = {}
    positions: list[FloatArray] = []
    triangles: list[npt.NDArray[np.int64]] = []
    normals: list[FloatArray] = []
    texcoords: list[FloatArray | None] = []
    b_vertex: list[npt.NDArray[np.intp]] = []
    b_slot: list[npt.NDArray[np.intp]] = []
    b_weight: list[FloatArray] = []
    parts: list[MeshPart] = []
    images: dict[int, TextureImage] = {}  # one per image, shared by the parts that use it
    nv = nt = 0
    for n, node in enumerate(scene.nodes):
        if node.mesh is None:
            continue
        mesh = scene.meshes[node.mesh]
        for pi, prim in enumerate(mesh.primitives):
            count = prim.num_vertices
            skinned = (node.skin is not None and prim.joints is not None and prim.weights is not None)
            if skinned:
                assert node.skin is not None and prim.joints is not None and prim.weights is not None
                gs = scene.skins[node.skin]
                if node.skin not in skin_base:
                    skin_base[node.skin] = len(palette)
                    palette.extend(joint_of[j] for j in gs.joints)
                    ibms.extend(gs.inverse_bind_matrices[: len(gs.joints)])
                base = skin_base[node.skin]
                w = np.asarray(prim.weights, dtype=np.float64)
                jj = np.asarray(prim.joints, dtype=np.intp)
                keep = w.reshape(-1) != 0.0
                v = np.repeat(np.arange(count), jj.shape[1])[keep]
                b_vertex.append(v + nv)
                b_slot.append(jj.reshape(-1)[keep] + base)
                b_weight.append(w.reshape(-1)[keep])
            else:
                joint = joint_of.get(n)
                if joint is None:
                    continue  # a skinned node's unskinned primitive with no joint to ride on
                if n not in rigid_slot:
                    rigid_slot[n] = len(palette)
                    palette.append(joint)
                    ibms.append(np.eye(4))
                b_vertex.append(np.arange(count, dtype=np.intp) + nv)
                b_slot.append(np.full(count, rigid_slot[n], dtype=np.intp))
                b_weight.append(np.ones(count))
            p = np.asarray(prim.positions, dtype=np.float64)
            tri = np.asarray(prim.triangles, dtype=np.int64)
            positions.append(p)
            triangles.append(tri + nv)
            normals.append(np.asarray(prim.normals, dtype=np.float64) if prim.normals is not None
                           else vertex_normals(p, tri))
            texcoords.append(None if prim.texcoords is None else np.asarray(prim.texcoords, dtype=np.float64))
            name = mesh.name or f"Mesh_{node.mesh}"
            image = _base_color_texture(scene, prim.material)
            texture = None
            if image is not None:
                texture = images.get(image) or images.setdefault(image, _image_texture(scene, image, folder))
            parts.append(MeshPart(name if len(mesh.primitives) == 1 else f"{name}.{pi}", nv, count, nt, len(tri),
                                  skinned, n, node.mesh, pi, _material_color(scene, prim.material), texture))
            nv += count
            nt += len(tri)
    if not parts:
        notes.append("The file has no mesh: only its skeleton was imported.")
        return None, [], None
    uv: FloatArray | None = None
    if any(t is not None for t in texcoords):
        uv = np.concatenate([t[:, :2] if t is not None else np.zeros((len(p), 2))
                             for t, p in zip(texcoords, positions)])
    binding = SkinBinding(np.concatenate(b_vertex), np.concatenate(b_slot), np.concatenate(b_weight), nv,
                          len(palette))
    skin = Skin(np.concatenate(positions), np.concatenate(triangles), binding, np.array(ibms),
                normals=np.concatenate(normals), texcoords=uv)
    return skin, parts, np.array(palette, dtype=np.intp)


def clip_summary(ch: Character3D) -> list[dict[str, Any]]:
    """Name, start and end of each clip (for notes and the info command)."""
    return [{"name": c.name, "start": c.start, "end": c.end} for c in ch.clips]


def load_gltf_character_asset(asset: Asset) -> Character3D:
    """The runtime of a character whose source is a ``.glb`` / ``.gltf`` (a project being opened)."""
    if not asset.source:
        raise FormatError(f"3D character {asset.id!r} has no source file.")
    return character_from_gltf(import_gltf(asset.source), asset.source).character
