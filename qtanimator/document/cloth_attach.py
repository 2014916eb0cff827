"""Cloth on a character (issue 14): pins that follow a joint, capsules around the bones.

A cloth asset may carry the property ``attach = {"asset": <3D character id>, "joint": <joint
name>}`` (not a :class:`~qtanimator.core.cloth.ClothParams` field: the Cloth dock leaves it
alone). Then

* its pinned particles are expressed in the joint's frame at the cloth's rest time (frame
  ``frame_start``): ``local = W_joint(t0)⁻¹ · rest``; before the step into frame ``f`` they are
  set to ``W_joint(t_f) · local`` (:func:`transform_points`), and the step lands them there
  exactly;
* it collides with one capsule per bone of that character (parent joint → child joint). A
  bone's radius is the character property ``capsule_radii[<child joint name>]`` when set
  (:func:`set_capsule_radius_command`), else the median distance to the bone's segment of the
  skin vertices whose strongest weight is the parent joint and which lie nearest to this bone
  among the parent's bones (:func:`default_capsule_radii`), else :data:`FALLBACK_RADIUS`.

:class:`ClothDriver` samples the joint matrices once, on the thread that owns the document, at
every frame from ``frame_start`` to ``frame_end`` (later frames hold the last pose), so the
worker thread that steps the cloth never reads the document. :func:`driver_key` is the cheap
fingerprint of everything the samples depend on (the character's runtime object, its
channels, its properties, the frame grid); a cache whose key differs is rebuilt.
"""

from __future__ import annotations

import math
from collections.abc import Hashable
from dataclasses import dataclass
from typing import Any

import numpy as np

from qtanimator.core.cloth import Cloth, FloatArray
from qtanimator.document.commands import Command, SetAssetProperty
from qtanimator.document.document import Document

#: The cloth asset property naming the character and joint its pins follow.
ATTACH = "attach"
#: The 3D character property holding per-bone capsule radii (metres) by child joint name.
CAPSULE_RADII = "capsule_radii"
#: A bone's radius when the character has no skin vertices near it (metres).
FALLBACK_RADIUS = 0.05


def attachment(properties: dict[str, Any]) -> tuple[str, str] | None:
    """``(character id, joint name)`` of a cloth's ``attach`` property, or None."""
    value = properties.get(ATTACH)
    if not value:
        return None
    if not isinstance(value, dict) or not isinstance(value.get("asset"), str) or not isinstance(
            value.get("joint"), str):
        raise ValueError("attach must be {'asset': <3D character id>, 'joint': <joint name>}")
    return value["asset"], value["joint"]


def bones(skeleton: Any) -> list[tuple[int, int]]:
    """``(parent, child)`` joint indices of every bone, in joint order of the child."""
    return [(j.parent, i) for i, j in enumerate(skeleton.joints) if j.parent is not None]


def _segment_distances(points: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    ab = b - a
    ab2 = float(ab @ ab)
    t = np.zeros(len(points)) if ab2 <= 0 else np.clip((points - a) @ ab / ab2, 0.0, 1.0)
    return np.asarray(np.linalg.norm(points - (a + t[:, None] * ab), axis=1), dtype=np.float64)


def default_capsule_radii(character: Any) -> dict[str, float]:
    """The skin's radius of every bone, by child joint name (see the module docstring)."""
    sk = character.skeleton
    pairs = bones(sk)
    out = {sk.joints[c].name: FALLBACK_RADIUS for _, c in pairs}
    skin = getattr(character, "skin", None)
    if skin is None or not pairs:
        return out
    world = sk.bind_world_matrices()
    heads = world[:, :3, 3]
    binding = skin.binding
    # The strongest weight of every vertex, as a skeleton joint.
    best_w = np.full(binding.num_vertices, -1.0)
    best_j = np.full(binding.num_vertices, -1, dtype=np.int64)
    palette = getattr(character, "palette", None)
    for v, j, w in zip(binding.vertex, binding.joint, binding.weight):
        if w > best_w[v]:
            best_w[v], best_j[v] = w, j if palette is None else int(palette[j])
    positions = np.asarray(skin.positions, dtype=np.float64)
    for parent in sorted({p for p, _ in pairs}):
        mine = [c for p, c in pairs if p == parent]
        pts = positions[best_j == parent]
        if not len(pts):
            continue
        dists = np.stack([_segment_distances(pts, heads[parent], heads[c]) for c in mine], axis=1)
        nearest = np.argmin(dists, axis=1)
        for k, c in enumerate(mine):
            d = dists[nearest == k, k]
            if len(d) and float(np.median(d)) > 1e-4:
                out[sk.joints[c].name] = float(np.median(d))
    return out


def capsule_radii(doc: Document, character_id: str) -> dict[str, float]:
    """Every bone's radius: the character's ``capsule_radii`` over the skin's defaults."""
    from qtanimator.document.character3d import character

    radii = default_capsule_radii(character(doc, character_id))
    for name, value in (doc.assets[character_id].properties.get(CAPSULE_RADII) or {}).items():
        if name in radii:
            radii[name] = float(value)
    return radii


def set_capsule_radius_command(doc: Document, character_id: str, joint: str, radius: float | None,
                               gesture: Hashable | None = None) -> Command:
    """Set (or, with None, go back to the skin's default for) the radius of the bone ending at
    ``joint`` (metres, > 0)."""
    from qtanimator.document.character3d import character

    names = {j.name for j in character(doc, character_id).skeleton.joints}
    if joint not in names:
        raise ValueError(f"{character_id!r} has no joint {joint!r}")
    current = dict(doc.assets[character_id].properties.get(CAPSULE_RADII) or {})
    if radius is None:
        current.pop(joint, None)
    else:
        if not (math.isfinite(radius) and radius > 0):
            raise ValueError("a capsule radius must be a positive number of metres")
        current[joint] = float(radius)
    return SetAssetProperty(doc, character_id, CAPSULE_RADII, current or None,
                            text=f"Set capsule radius of {joint}", gesture=gesture)


def transform_points(world: FloatArray, local: FloatArray) -> FloatArray:
    """``W · p`` for points ``local`` (N, 3) and a 4×4 ``world``: ``local @ R.T + t``."""
    return np.asarray(local @ world[:3, :3].T + world[:3, 3], dtype=np.float64)


def driver_key(doc: Document, cloth_properties: dict[str, Any]) -> Hashable | None:
    """A fingerprint of everything an attached cloth's driver reads (None: not attached)."""
    att = attachment(cloth_properties)
    if att is None:
        return None
    cid, joint = att
    asset = doc.assets.get(cid)
    runtime = doc.runtime.get(cid)
    prefix = cid + "/"
    channels = tuple((k, id(c)) for k, c in doc.channels.items() if k.startswith(prefix))
    props = repr(sorted(asset.properties.items())) if asset is not None else None
    return (cid, joint, id(runtime), channels, props, doc.fps, doc.frame_range)


@dataclass(frozen=True)
class ClothDriver:
    """The joint matrices and capsules an attached cloth follows, one sample per frame."""

    character: str
    joint: str
    joint_world: FloatArray      # (F, 4, 4) the joint's world matrix per frame from frame_start
    capsule_a: FloatArray        # (F, K, 3) each bone's parent joint per frame
    capsule_b: FloatArray        # (F, K, 3) each bone's child joint per frame
    radii: FloatArray            # (K,)
    bone_names: tuple[str, ...]  # child joint of each capsule
    key: Hashable = None

    def sample(self, k: int) -> int:
        return min(max(k, 0), len(self.joint_world) - 1)

    def pin_locals(self, cloth: Cloth) -> FloatArray:
        """The pinned particles' rest places in the joint's frame at the rest time."""
        inv = np.linalg.inv(self.joint_world[0])
        return transform_points(inv, cloth.rest_positions[cloth.pinned_indices])

    def apply(self, cloth: Cloth, local: FloatArray, k: int) -> None:
        """Prepare ``cloth`` for the step that ends at frame ``k`` (counted from frame_start)."""
        cloth.set_pin_targets(transform_points(self.joint_world[self.sample(k)], local))
        if len(self.radii):
            s0, s1 = self.sample(k - 1), self.sample(k)
            cloth.set_capsules(self.capsule_a[s1], self.capsule_b[s1], self.radii,
                               self.capsule_a[s0], self.capsule_b[s0])

    def place(self, cloth: Cloth, local: FloatArray) -> None:
        """Put the pins and capsules where they are at the rest frame (frame 0)."""
        targets = transform_points(self.joint_world[0], local)
        cloth.set_pin_targets(targets)
        cloth.positions[cloth.pinned_indices] = targets
        if len(self.radii):
            cloth.set_capsules(self.capsule_a[0], self.capsule_b[0], self.radii)


def build_driver(doc: Document, cloth_properties: dict[str, Any]) -> ClothDriver | None:
    """Sample the joint and the capsules of an attached cloth (None: not attached).

    Raises ValueError naming a missing character or joint."""
    from qtanimator.document.character3d import character, world_matrices

    att = attachment(cloth_properties)
    if att is None:
        return None
    cid, joint = att
    if cid not in doc.assets:
        raise ValueError(f"the cloth is attached to {cid!r}, which is not in the document")
    try:
        ch = character(doc, cid)
    except KeyError as exc:
        raise ValueError(f"the cloth is attached to {cid!r}, which is not a loaded 3D character") from exc
    names = [j.name for j in ch.skeleton.joints]
    if joint not in names:
        raise ValueError(f"the cloth is attached to joint {joint!r}, which {cid!r} does not have")
    ji = names.index(joint)
    start, end = doc.frame_range
    fps = doc.fps
    pairs = bones(ch.skeleton)
    radii_by_name = capsule_radii(doc, cid)
    frames = max(1, end - start + 1)
    worlds = np.stack([world_matrices(doc, cid, (start + f) / fps) for f in range(frames)])
    heads = worlds[:, :, :3, 3]
    pi = np.array([p for p, _ in pairs], dtype=np.int64)
    ci = np.array([c for _, c in pairs], dtype=np.int64)
    radii = np.array([radii_by_name[names[c]] for c in ci], dtype=np.float64)
    return ClothDriver(cid, joint, np.ascontiguousarray(worlds[:, ji]), np.ascontiguousarray(heads[:, pi]),
                       np.ascontiguousarray(heads[:, ci]), radii, tuple(names[c] for c in ci),
                       driver_key(doc, cloth_properties))
