"""A 3D character's channels as one glTF animation: exact keys where glTF can hold them, samples elsewhere.

:func:`clip_animation` writes one animation (a clip, or the document's channels over its frame
range) for the joint nodes of :mod:`qtanimator.document.gltf_export`. Per joint and per path:

* **rotation** of a joint keyed as a quaternion (``qw qx qy qz``): when the four channels share
  their key times and every span has the same interpolation, the keys are written as they
  are: linear → ``LINEAR`` (slerp, as the document evaluates it), constant → ``STEP``, cubic →
  ``CUBICSPLINE`` with the keys' resolved in / out slopes as in / out tangents (the document's
  Hermite span is glTF's cubic spline). Otherwise the rotation is sampled and a message says so.
* **translation** (``tx ty tz`` added to the offset; the root translation ``/tx …`` on roots)
  and **scale** (``sx sy sz``): exact in the same way when the keyed components share key times
  and interpolation (a component without keys holds its rest value); else sampled, with a
  message (none for the root translation, which course exports always sampled).
* **rotation of an Euler joint** (course ``.skel``, BVH): sampled, as the course exports always
  were: at ``fps`` plus every key time, ``LINEAR``, DOFs clamped to their limits.

Keys must also lie inside the exported range, with constant extrapolation wherever the range
reaches past them (glTF holds the end values), and have no weighted tangents (glTF's cubic
spline has no handle lengths). Samples hold the document's evaluation exactly at the sample
times; between them glTF interpolates linearly (slerp for rotations).

The animation spans the clip: where no sampler reaches its start or end, one gets a key there
holding the value glTF holds anyway, so a re-import finds the clip's length again. Times:
``shift`` is subtracted from every time written (glTF times start at 0 or later).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from qtanimator.core.channel import Channel, Extrapolation, Interpolation
from qtanimator.core.quaternion_channels import quaternions_at
from qtanimator.core.rotation import euler_to_quaternions
from qtanimator.core.skeleton import Joint
from qtanimator.document.character3d_model import (
    JOINT_DOFS,
    QUAT_DOFS,
    ROOT_DOFS,
    SCALE_DOFS,
    TRANSLATE_DOFS,
    Character3D,
)
from qtanimator.document.document import channel_id
from qtanimator.formats.gltf.model import GltfAnimation, GltfAnimationChannel, GltfSampler
from qtanimator.formats.gltf.sampling import sample_times

FloatArray = npt.NDArray[np.float64]

__all__ = ["ClipAnimation", "clip_animation", "exact_sampler", "rest_rotations"]

_INTERPOLATIONS = {Interpolation.LINEAR: "LINEAR", Interpolation.CONSTANT: "STEP", Interpolation.CUBIC: "CUBICSPLINE"}
#: glTF's (x, y, z, w) slots of the qw, qx, qy, qz channels
_QUAT_COLUMNS = (3, 0, 1, 2)


@dataclass
class ClipAnimation:
    """What :func:`clip_animation` wrote: the animation (None when nothing is keyed), every
    time it holds (shifted), and messages for the user."""

    animation: GltfAnimation | None
    times: FloatArray
    messages: list[str] = field(default_factory=list)


def rest_rotations(ch: Character3D) -> FloatArray:
    """(J, 4) rest rotations ``(x, y, z, w)``: the file's quaternions for quaternion joints,
    the Euler DOFs' rotation for the others."""
    sk = ch.skeleton
    out = np.array(ch.rest_quaternions(), dtype=np.float64).reshape(len(sk.joints), 4)
    for j, joint in enumerate(sk.joints):
        if not joint.quaternion:
            out[j] = euler_to_quaternions(joint.pose, joint.rotation_order or sk.rotation_order)[0]
    return out


# ------------------------------------------------------------------------- exact
def exact_sampler(channels: Sequence[Channel | None], fill: npt.ArrayLike, start: float, end: float,
                  all_keyed: bool = False) -> tuple[GltfSampler | None, str]:
    """The channels' keys as one glTF sampler (values (K, n), or (K, 3, n) for cubic), or None
    and the reason glTF cannot hold them as they are. A channel without keys holds its
    ``fill`` value; ``all_keyed`` (quaternions) asks for keys on every channel."""
    keyed = [c for c in channels if c is not None and c.keys]
    if not keyed or (all_keyed and len(keyed) < len(channels)):
        return None, "not every component is keyed"
    times = keyed[0].times
    if any(len(c.keys) != len(times) or not np.array_equal(c.times, times) for c in keyed[1:]):
        return None, "its components are keyed at different times"
    if any(c.is_weighted for c in keyed):
        return None, "weighted tangents"
    kinds = {k.interpolation for c in keyed for k in c.keys[:-1]}
    if len(kinds) > 1:
        return None, "mixed interpolation"
    if times[0] < start or times[-1] > end:
        return None, "keys outside the exported range"
    if ((start < times[0] and any(c.pre is not Extrapolation.CONSTANT for c in keyed))
            or (end > times[-1] and any(c.post is not Extrapolation.CONSTANT for c in keyed))):
        return None, "extrapolation other than constant"
    if np.any(np.diff(times.astype(np.float32)) <= 0):
        return None, "keys closer than a float can tell apart"
    kind = kinds.pop() if kinds else Interpolation.LINEAR
    n = len(times)
    rest = np.asarray(fill, dtype=np.float64).reshape(len(channels))
    values = np.stack([c.values if c is not None and c.keys else np.full(n, float(v))
                       for c, v in zip(channels, rest)], axis=1)
    if kind is not Interpolation.CUBIC:
        return GltfSampler(times.copy(), values, _INTERPOLATIONS[kind]), ""
    zero = np.zeros(n)
    s_in = np.stack([c.slopes()[0] if c is not None and c.keys else zero for c in channels], axis=1)
    s_out = np.stack([c.slopes()[1] if c is not None and c.keys else zero for c in channels], axis=1)
    return GltfSampler(times.copy(), np.stack([s_in, values, s_out], axis=1), "CUBICSPLINE"), ""


def _shifted_values(sampler: GltfSampler, add: FloatArray) -> GltfSampler:
    """The sampler with ``add`` added to its values (not to cubic tangents)."""
    values = sampler.values.copy()
    if sampler.interpolation == "CUBICSPLINE":
        values[:, 1] += add
    else:
        values += add
    return GltfSampler(sampler.times, values, sampler.interpolation)


def _quaternion_sampler(sampler: GltfSampler) -> GltfSampler:
    """qw, qx, qy, qz columns as glTF's (x, y, z, w); linear and stepped keys normalised (the
    document evaluates those spans from normalised keys)."""
    order = [_QUAT_COLUMNS.index(slot) for slot in range(4)]
    values = sampler.values[..., order]
    if sampler.interpolation != "CUBICSPLINE":
        norms = np.linalg.norm(values, axis=-1, keepdims=True)
        values = values / np.where(norms > 0, norms, 1.0)
    return GltfSampler(sampler.times, values, sampler.interpolation)


# ----------------------------------------------------------------------- tracks
class _Evaluator:
    """One joint's channels in one clip: which paths move, their exact samplers, and their
    values at any times."""

    def __init__(self, ch: Character3D, j: int, channels: Mapping[str, Channel], asset_id: str,
                 rest_q: FloatArray) -> None:
        sk = ch.skeleton
        self.joint: Joint = sk.joints[j]
        self.order = self.joint.rotation_order or sk.rotation_order
        self.rest_q = rest_q
        key = sk.joint_keys()[j]

        def get(joint_key: str, dofs: Sequence[str]) -> list[Channel | None]:
            found = [channels.get(channel_id(asset_id, joint_key, d)) for d in dofs]
            return [c if c is not None and c.keys else None for c in found]

        joint = self.joint
        self.rotation = get(key, QUAT_DOFS if joint.quaternion else JOINT_DOFS)
        self.translation = get(key, TRANSLATE_DOFS) if joint.translates else [None] * 3
        self.root = get("", ROOT_DOFS) if joint.parent is None else [None] * 3
        self.scale = get(key, SCALE_DOFS) if joint.scales else [None] * 3
        root_rest = sk.root_translation if joint.parent is None else np.zeros(3)
        self.rest_t = joint.offset + joint.translation + root_rest
        self.root_rest = np.asarray(root_rest, dtype=np.float64)

    def keyed_channels(self) -> list[Channel]:
        return [c for c in (*self.rotation, *self.translation, *self.root, *self.scale) if c is not None]

    # ---------------------------------------------------------------- exact
    def exact(self, path: str, start: float, end: float) -> tuple[GltfSampler | None, str]:
        """The exact sampler of ``path`` (None and why not)."""
        j = self.joint
        if path == "rotation":
            if not j.quaternion:
                return None, ""  # Euler joints are sampled, silently
            sampler, why = exact_sampler(self.rotation, [0.0] * 4, start, end, all_keyed=True)
            return (None, why) if sampler is None else (_quaternion_sampler(sampler), "")
        if path == "scale":
            return exact_sampler(self.scale, j.scale, start, end)
        own, root = _any(self.translation), _any(self.root)
        if own and root:
            return None, "the joint and the root translation are both keyed"
        chans, fill = (self.translation, j.translation) if own else (self.root, self.root_rest)
        sampler, why = exact_sampler(chans, fill, start, end)
        if sampler is None:
            return None, why if own else ""  # the root translation of course files was always sampled
        return _shifted_values(sampler, self.rest_t - np.asarray(fill, dtype=np.float64)), ""

    # ---------------------------------------------------------------- sampled
    def values(self, path: str, times: FloatArray) -> FloatArray:
        """(T, 4) rotations or (T, 3) translations / scales at ``times``."""
        j = self.joint
        if path == "rotation":
            if j.quaternion:
                return quaternions_at(self.rotation, self.rest_q, times)
            angles = np.tile(j.pose, (len(times), 1))
            for a, c in enumerate(self.rotation):
                if c is not None:
                    angles[:, a] = np.clip(c.evaluate(times), j.dofs[a].min, j.dofs[a].max)
            return euler_to_quaternions(angles, self.order)
        if path == "scale":
            return _components(self.scale, j.scale, times)
        own = _components(self.translation, j.translation, times)
        root = _components(self.root, self.root_rest, times)
        return j.offset + own + root

    def paths(self) -> list[str]:
        return [p for p, chans in (("translation", (*self.translation, *self.root)), ("rotation", self.rotation),
                                   ("scale", self.scale)) if _any(chans)]


def _any(channels: Sequence[Channel | None]) -> bool:
    return any(c is not None for c in channels)


def _components(channels: Sequence[Channel | None], rest: npt.ArrayLike, times: FloatArray) -> FloatArray:
    out = np.tile(np.asarray(rest, dtype=np.float64), (len(times), 1))
    for a, c in enumerate(channels):
        if c is not None:
            out[:, a] = c.evaluate(times)
    return out


def _increasing(times: FloatArray) -> FloatArray:
    """Times that stay strictly increasing once stored as float32."""
    t32 = times.astype(np.float32)
    keep = np.concatenate([[True], np.diff(t32) > 0]) if len(times) else np.zeros(0, dtype=bool)
    result: FloatArray = times[keep]
    return result


# ------------------------------------------------------------------------- clip
def clip_animation(ch: Character3D, node_of: Sequence[int], channels: Mapping[str, Channel], asset_id: str,
                   name: str, start: float, end: float, fps: float, shift: float = 0.0) -> ClipAnimation:
    """One animation named ``name`` of the character's ``channels`` (document channel ids)
    over ``start … end`` seconds, joint j animating node ``node_of[j]``. Times written are
    ``time − shift``. The animation spans ``start … end`` exactly, so that the clip keeps its
    length: where no sampler reaches that far, one holds its end value there with an added
    key; a clip that keys nothing holds its first joint's rest rotation."""
    rest_q = rest_rotations(ch)
    evaluators = [_Evaluator(ch, j, channels, asset_id, rest_q[j]) for j in range(len(ch.skeleton.joints))]
    keyed = [c for e in evaluators for c in e.keyed_channels()]
    grid: FloatArray | None = None
    samplers: list[GltfSampler] = []
    targets: list[GltfAnimationChannel] = []
    sampled: list[str] = []
    for j, ev in enumerate(evaluators):
        for path in ev.paths():
            sampler, why = ev.exact(path, start, end)
            if sampler is None:
                if grid is None:
                    grid = _increasing(sample_times(start, end, fps, keyed))
                if why:
                    sampled.append(f"{ch.skeleton.joints[j].name} {path} ({why})")
                sampler = GltfSampler(grid, ev.values(path, grid), "LINEAR")
            samplers.append(sampler)
            targets.append(GltfAnimationChannel(len(samplers) - 1, node_of[j], path))
    if not samplers and evaluators:
        samplers.append(GltfSampler(np.array([start]), rest_q[:1].copy(), "LINEAR"))
        targets.append(GltfAnimationChannel(0, node_of[0], "rotation"))
    if samplers:
        first = min(range(len(samplers)), key=lambda i: samplers[i].times[0])
        samplers[first] = _held(samplers[first], start, before=True)
        last = max(range(len(samplers)), key=lambda i: samplers[i].times[-1])
        samplers[last] = _held(samplers[last], end, before=False)
    samplers = [GltfSampler(s.times - shift, s.values, s.interpolation) for s in samplers]
    messages = []
    if sampled:
        messages.append(f"{name}: glTF cannot hold the keys of {', '.join(sampled)} as they are: sampled at "
                        f"{fps:g} fps.")
    times = np.unique(np.concatenate([s.times for s in samplers])) if samplers else np.zeros(0)
    animation = GltfAnimation(samplers, targets, name) if samplers else None
    return ClipAnimation(animation, times, messages)


def _held(sampler: GltfSampler, time: float, before: bool) -> GltfSampler:
    """The sampler with a key at ``time`` (before its first key or after its last) holding
    the end value it already holds there; cubic tangents on that span are 0, so it is flat."""
    times, values = sampler.times, sampler.values.copy()
    edge = 0 if before else -1
    if (np.float32(time) >= np.float32(times[0])) if before else (np.float32(time) <= np.float32(times[-1])):
        return sampler
    added = values[edge:edge + 1 if before else None].copy()
    if sampler.interpolation == "CUBICSPLINE":
        added[:, 0] = added[:, 2] = 0.0
        values[edge, 0 if before else 2] = 0.0  # the tangent into the added span (unused until now)
    if before:
        return GltfSampler(np.concatenate([[time], times]), np.concatenate([added, values]), sampler.interpolation)
    return GltfSampler(np.concatenate([times, [time]]), np.concatenate([values, added]), sampler.interpolation)
