"""Importing 3D files into the document and exporting 3D characters to glTF.

Every ``*_command`` function reads its files first (a :class:`FormatError` leaves the
document untouched) and returns an :class:`Import`: **one** undoable command plus notes for
the user (companion files that were picked up, approximations). The GUI's openers
(:mod:`qtanimator.ui.import3d`) push the command.

* ``.skel``: the skeleton with the companions of the same stem in its folder: ``.skin`` and
  ``.anim`` (balljoint), ``.obj`` and ``.attach`` (MIT). Without an ``.anim`` of the same stem,
  the folder's only ``.anim`` is used; among several, the one whose name starts with the
  skeleton's stem and is a prefix of every other such name (``wasp.skel`` →
  ``wasp_walk.anim`` next to ``wasp_walk_crlf.anim``).
* ``.skin``: replaces the skin of a character, or brings the ``.skel`` of the same stem;
  with neither, the skin alone in its bind pose on one root joint (a static mesh).
* ``.anim``: replaces a character's channels (:func:`load_anim_command`).
* ``.obj``: an MIT mesh with its ``.skel`` (required) and ``.attach`` of the same stem.
* ``.bvh``: skeleton (a rotation order per joint) and motion as channels with linear keys.
* ``.glb`` / ``.gltf``: the whole character: every mesh, joints that move, turn and scale,
  every animation as a clip (:mod:`qtanimator.document.gltf_character`).

An import that brings a clip longer than the document's frame range also lengthens the range
(in the same undo step), so the whole clip plays. A ``.bvh`` or glTF clip keeps its own timing:
into a document without keys, the project takes the clip's frame rate (a BVH's frame time, a
glTF clip's key spacing when even) and the frame range fits the clip; into one with keys, the
range only grows and a different rate is offered (:attr:`Import.clip_fps`,
:func:`~qtanimator.document.character3d.set_fps_command`).

"""

from __future__ import annotations

import contextlib
import math
import os
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.core.channel import Channel, Extrapolation, Interpolation, Key, Tangent
from qtanimator.core.rotation import euler_from_matrices
from qtanimator.document.channels3d import anim_channel_ids
from qtanimator.document.character3d import (
    ASSET_KIND,
    BVH_POSITIONS,
    CLIP,
    Character3D,
    add_character3d_command,
    character,
    clip_range_command,
    load_anim_command,
    load_bvh_character,
    load_skin_character,
    skin_texture,
)
from qtanimator.document.character3d import (
    bounds as character3d_bounds,
)
from qtanimator.document.commands import AddAsset, Command, Macro, SetParameter
from qtanimator.document.document import Asset, Document
from qtanimator.document.gltf_character import (
    GLTF_ROTATION_ORDER,
    character_from_gltf,
    load_gltf_character_asset,
)
from qtanimator.document.gltf_export import character_scene
from qtanimator.document.gltf_skeleton_export import CharacterExport
from qtanimator.document.placement import CHARACTER_HEIGHT, FAR_FROM_UNIT, GAP, PLACEMENT
from qtanimator.formats.anim import load_anim
from qtanimator.formats.errors import FormatError
from qtanimator.formats.gltf.reader import import_gltf
from qtanimator.formats.gltf.writer import export_glb
from qtanimator.formats.skel import load_skel
from qtanimator.formats.skin import load_skin

FloatArray = npt.NDArray[np.float64]

SUFFIXES = (".skel", ".skin", ".anim", ".obj", ".bvh", ".glb", ".gltf")
GLTF_SUFFIXES = (".glb", ".gltf")


__all__ = [
    "GLTF_ROTATION_ORDER", "GLTF_SUFFIXES", "Import", "SUFFIXES", "anim_import", "bvh_import", "companions",
    "euler_from_matrices", "export_gltf", "gltf_import", "import_file", "load_gltf_character_asset",
    "obj_import", "skel_import", "skin_import", "target_character",
]


@dataclass
class Import:
    """One undoable command that adds what a file brought, the asset it concerns, and notes
    for the user (files picked up alongside, approximations made)."""

    command: Command
    asset_id: str
    notes: list[str] = field(default_factory=list)
    #: The clip's own frame rate when it differs from the document's and was not adopted
    #: (the document already had keys): the window offers to set the project to it.
    clip_fps: float | None = None


# --------------------------------------------------------------------- companions
def _same_stem(folder: Path, stem: str, suffix: str) -> Path | None:
    exact = folder / f"{stem}{suffix}"
    if exact.is_file():
        return exact
    for p in sorted(folder.iterdir()):
        if p.is_file() and p.stem.lower() == stem.lower() and p.suffix.lower() == suffix:
            return p
    return None


def _folder_anim(folder: Path, stem: str) -> Path | None:
    """The folder's ``.anim`` for a skeleton without one of its own stem (see the module doc)."""
    anims = sorted(p for p in folder.iterdir() if p.is_file() and p.suffix.lower() == ".anim")
    if len(anims) == 1:
        return anims[0]
    named = [p for p in anims if p.stem.lower().startswith(stem.lower())]
    if not named:
        return None
    shortest = min(named, key=lambda p: (len(p.stem), p.name))
    if all(p.stem.lower().startswith(shortest.stem.lower()) for p in named):
        return shortest
    return None


def companions(skel_path: str | os.PathLike[str], dialect: str | None = None) -> dict[str, Path]:
    """The files that belong with a ``.skel``: keys ``skin``, ``anim``, ``obj``, ``attach``.

    ``dialect`` ("balljoint" or "mit", read from the file when None) decides whether a
    ``.skin`` or an ``.obj`` + ``.attach`` pair is looked for.
    """
    p = Path(skel_path)
    folder, stem = p.parent, p.stem
    if dialect is None:
        dialect = load_skel(p).dialect
    found: dict[str, Path] = {}
    kinds = ("obj", "attach") if dialect == "mit" else ("skin",)
    for kind in (*kinds, "anim"):
        c = _same_stem(folder, stem, f".{kind}")
        if c is not None:
            found[kind] = c
    if "anim" not in found and dialect != "mit":
        a = _folder_anim(folder, stem)
        if a is not None:
            found["anim"] = a
    return found


# ------------------------------------------------------------------------ helpers
def target_character(doc: Document, selected: str | None) -> str | None:
    """The selected 3D character, else the only one in the document, else None."""
    if selected and selected in doc.assets and doc.assets[selected].kind == ASSET_KIND:
        return selected
    ids = [a.id for a in doc.assets.values() if a.kind == ASSET_KIND]
    return ids[0] if len(ids) == 1 else None


def _end_frame(doc: Document, end_time: float) -> int | None:
    """The frame the document's range must end at to show ``end_time`` (None: it does)."""
    end_frame = int(math.ceil(doc.time_to_frame(end_time) - 1e-6))
    return end_frame if end_frame > doc.frame_range[1] else None


def _channels_end(channels: Sequence[Channel | None]) -> float:
    return max((float(c.keys[-1].time) for c in channels if c is not None and c.keys), default=0.0)


def _with_range(doc: Document, text: str, add: Command, end_time: float, asset_id: str,
                notes: list[str]) -> Import:
    end_frame = _end_frame(doc, end_time)
    if end_frame is not None:
        notes.append(f"Frame range extended to {doc.frame_range[0]}–{end_frame} to show the whole clip.")
        return Import(Macro(text, [add, SetParameter(doc, "frame_end", end_frame)]), asset_id, notes)
    return Import(add, asset_id, notes)


def place_new_character(doc: Document, add: AddAsset, time: float = 0.0) -> list[str]:
    """Give a 3D character about to be added an authored placement (issue 14): scaled
    uniformly to the height of the 3D characters already there (their median), or to
    :data:`~qtanimator.document.placement.CHARACTER_HEIGHT` when there are none (so a file
    in centimetres and one in metres look the same size), standing on the floor (y = 0)
    and, when the document has 3D characters already, beside them along +x with its box
    clear of theirs. The scale lives in the asset's ``placement`` (the file's numbers stay as they
    are). A character alone in the document keeps its file's place and size unless its size
    is more than :data:`~qtanimator.document.placement.FAR_FROM_UNIT` times off (a file in
    centimetres or millimetres): a lone import stays exactly as the file has it.
    Returns notes for the user."""
    scratch = Document()
    add.do(scratch)
    aid = add.asset.id
    try:
        lo, hi = character3d_bounds(scratch, aid, time)
    except (ValueError, KeyError, np.linalg.LinAlgError):
        return []
    others = [a for a, asset in doc.assets.items() if asset.kind == ASSET_KIND and a in doc.runtime]
    height = float(hi[1] - lo[1])
    extent = float(np.max(hi - lo))
    size = height if height > 1e-6 * max(extent, 1e-12) else extent
    if not math.isfinite(size) or size <= 0.0:
        return []
    boxes = []
    for other in others:
        with contextlib.suppress(ValueError, KeyError, np.linalg.LinAlgError):
            boxes.append(character3d_bounds(doc, other, time))
    heights = [float(b[1][1] - b[0][1]) for b in boxes]
    heights = [h for h in heights if math.isfinite(h) and h > 0.0]
    # the common size: that of the characters already there (a lone first one may keep its
    # file's size), else the standard height
    common = float(np.median(heights)) if heights else CHARACTER_HEIGHT
    scale = common / size
    if not boxes and 1.0 / FAR_FROM_UNIT <= scale <= FAR_FROM_UNIT:
        return []  # alone and not wildly off in size: left where (and as big as) its file puts it
    lo_s, hi_s = lo * scale, hi * scale
    translate = np.array([-(lo_s[0] + hi_s[0]) / 2.0, -lo_s[1], -(lo_s[2] + hi_s[2]) / 2.0])
    if boxes:
        right = max(float(b[1][0]) for b in boxes)
        translate[0] = right + GAP * common - lo_s[0]
        translate[2] = float(np.mean([(b[0][2] + b[1][2]) / 2.0 for b in boxes])) - (lo_s[2] + hi_s[2]) / 2.0
    add.asset.properties[PLACEMENT] = {"translate": [float(v) for v in translate], "rotate": [0.0, 0.0, 0.0],
                                       "scale": float(scale)}
    return [f"Placed at x = {translate[0]:.3g}, scaled ×{scale:.3g} to {common:.3g} units tall "
            "(Properties ▸ Placement)."]


def _linear_channel(times: Sequence[float], values: Sequence[float]) -> Channel:
    keys = [Key(float(t), float(v), Tangent.LINEAR, Tangent.LINEAR, interpolation=Interpolation.LINEAR)
            for t, v in zip(times, values)]
    return Channel(keys, Extrapolation.CONSTANT, Extrapolation.CONSTANT)


# -------------------------------------------------------------------- .skel / .obj
def skel_import(doc: Document, path: str | os.PathLike[str]) -> Import:
    """A ``.skel`` with its companions (see :func:`companions`)."""
    p = Path(path)
    skeleton = load_skel(p)
    found = companions(p, skeleton.dialect)
    notes = [f"Also loaded {', '.join(found[k].name for k in sorted(found))}."] if found else []
    try:
        cmd = add_character3d_command(doc, p, found.get("skin"), found.get("anim"), found.get("obj"),
                                      found.get("attach"))
    except FormatError:
        anim = found.get("anim")
        if anim is None or _same_stem(p.parent, p.stem, ".anim") is not None:
            raise
        # An animation guessed from the folder that does not fit is left out, not an error.
        cmd = add_character3d_command(doc, p, found.get("skin"), None, found.get("obj"), found.get("attach"))
        notes = [f"{anim.name} does not fit {p.name} and was not loaded."]
    assert isinstance(cmd, AddAsset)
    notes += place_new_character(doc, cmd)
    clip = cmd.runtime.clip
    return _with_range(doc, cmd.text, cmd, clip.end if clip is not None else 0.0, cmd.asset.id, notes)


def obj_import(doc: Document, path: str | os.PathLike[str]) -> Import:
    """An MIT ``.obj`` mesh: needs the ``.skel`` of the same stem; uses its ``.attach``."""
    p = Path(path)
    skel = _same_stem(p.parent, p.stem, ".skel")
    if skel is None:
        raise FormatError(f"an .obj mesh is imported with its skeleton: {p.stem}.skel was not found next "
                          "to it.", p)
    attach = _same_stem(p.parent, p.stem, ".attach")
    notes = [f"Loaded with {skel.name}" + (f" and {attach.name}." if attach else
                                           f"; no {p.stem}.attach, so the mesh rides on the root joint.")]
    cmd = add_character3d_command(doc, skel, obj_path=p, attach_path=attach)
    assert isinstance(cmd, AddAsset)
    return Import(cmd, cmd.asset.id, notes)


def skin_import(doc: Document, path: str | os.PathLike[str], selected: str | None = None) -> Import:
    """A ``.skin``: on the selected 3D character, else with the ``.skel`` of the same stem,
    else on the document's only 3D character."""
    p = Path(path)
    skel = _same_stem(p.parent, p.stem, ".skel")
    target = selected if selected and selected in doc.assets and doc.assets[selected].kind == ASSET_KIND else None
    if target is None and skel is not None:
        anim = _same_stem(p.parent, p.stem, ".anim")
        cmd = add_character3d_command(doc, skel, p, anim)
        assert isinstance(cmd, AddAsset)
        notes = [f"Loaded with {skel.name}" + (f" and {anim.name}." if anim else ".")]
        clip = cmd.runtime.clip
        return _with_range(doc, cmd.text, cmd, clip.end if clip is not None else 0.0, cmd.asset.id, notes)
    if target is None:
        # The only 3D character is dressed when it is a .skel one; anything else (a glTF,
        # a BVH) cannot wear a .skin, so the skin opens alone.
        only = target_character(doc, None)
        if only is not None and Path(doc.assets[only].source or "").suffix.lower() == ".skel":
            target = only
    if target is None:
        # Nothing to dress: the skin alone, as stored (its bind pose) on one still root joint.
        runtime = load_skin_character(p)
        aid = doc.unique_asset_id(_asset_base(p))
        add = AddAsset(Asset(aid, ASSET_KIND, str(p.resolve()), {}), runtime, text=f"Add 3D character {aid}")
        return Import(add, aid, [f"No {p.stem}.skel next to {p.name} and no 3D character to dress: the skin is "
                                 "shown in its bind pose on one root joint."])
    asset = doc.assets[target]
    if not asset.source or Path(asset.source).suffix.lower() != ".skel":
        raise FormatError(f"a .skin file can only dress a character loaded from a .skel file; "
                          f"{target!r} comes from {Path(asset.source or '?').name}.", p)
    old = character(doc, target)
    skin = load_skin(p, num_joints=len(old.skeleton.joints))
    runtime = Character3D(old.skeleton, skin, None, old.clip, False, texture=skin_texture(skin, p))
    props = dict(asset.properties)
    for name in ("obj_file", "attach_file"):
        props.pop(name, None)
    props["skin_file"] = str(p.resolve())
    new_asset = Asset(asset.id, asset.kind, asset.source, props)
    return Import(AddAsset(new_asset, runtime, text=f"Load skin {p.name}"), target, [])


def anim_import(doc: Document, path: str | os.PathLike[str], selected: str | None = None) -> Import:
    """An ``.anim`` on the selected (or only) 3D character."""
    p = Path(path)
    target = target_character(doc, selected)
    if target is None:
        have = sum(1 for a in doc.assets.values() if a.kind == ASSET_KIND)
        why = "there is no 3D character to animate" if have == 0 else f"there are {have} 3D characters"
        raise FormatError(f"an .anim file animates the selected 3D character, and {why}: open or select "
                          "a skeleton first.", p)
    clip = load_anim(p)
    cmd = load_anim_command(doc, target, p, clip)
    return _with_range(doc, cmd.text, cmd, clip.end, target, [f"Applied to {target}."])


# ---------------------------------------------------------------------------- BVH
def bvh_import(doc: Document, path: str | os.PathLike[str]) -> Import:
    """A ``.bvh`` file as a 3D character with its motion in the document's channels."""
    p = Path(path)
    runtime, chans = load_bvh_character(p)
    aid = doc.unique_asset_id(_asset_base(p))
    ids = anim_channel_ids(aid, runtime.skeleton.joint_keys())
    channels = {cid: ch for cid, ch in zip(ids, chans) if ch is not None}
    channels.update(runtime.translation_channels(aid))
    # The root-position convention detected (or chosen later in Properties) is saved with
    # the asset; the notes say which one was used and what was ignored.
    asset = Asset(aid, ASSET_KIND, str(p.resolve()), {BVH_POSITIONS: runtime.positions})
    add = AddAsset(asset, runtime, channels, text=f"Add 3D character {aid}")
    n = max((len(c.keys) for c in channels.values()), default=0)
    notes = [f"{len(runtime.skeleton.joints)} joints, {n} frames.", *runtime.notes]
    notes += place_new_character(doc, add)
    return _timed(doc, add, 0.0, _channels_end(list(channels.values())), _key_rate(channels.values()), aid, notes)


def _key_rate(channels: Iterable[Channel | None]) -> float | None:
    """The frame rate of keys evenly spaced in time (a BVH's frames, a glTF clip sampled at a
    fixed rate), whole when within 0.2 % of a whole number; None when the keys are not evenly
    spaced, fewer than two, or under 10 per second (key poses rather than frames)."""
    # straight from the keys: compiling every channel of a long clip here costs more than reading it
    times = [np.fromiter((k.time for k in c.keys), float, len(c.keys))
             for c in channels if c is not None and len(c.keys) >= 2]
    if not times:
        return None
    t = np.unique(np.round(np.concatenate(times), 6))
    if len(t) < 2:
        return None
    steps = np.diff(t)
    dt = float(np.median(steps))
    if dt <= 0 or float(np.max(np.abs(steps - dt))) > max(1e-5, 1e-3 * dt):
        return None
    rate = 1.0 / dt
    whole = float(round(rate))
    rate = whole if abs(rate - whole) <= 2e-3 * rate else round(rate, 3)
    return rate if 10.0 <= rate <= 1000.0 else None  # sparser keys are poses, not a frame rate


def _timed(doc: Document, add: Command, start: float, end: float, rate: float | None, asset_id: str,
           notes: list[str]) -> Import:
    """An import of a clip spanning ``start … end`` s whose keys are ``rate`` per second (None:
    uneven): into a document without keys the project takes the clip's rate and its frame
    range fits the clip; otherwise the range only grows to show it and a different rate is
    offered (:attr:`Import.clip_fps`), not imposed."""
    differs = rate is not None and abs(rate - doc.fps) > 1e-6
    keep = _animated_elsewhere(doc) or end <= start
    if rate is not None:  # a file's rounded frame time (0.0166667) must not add a frame
        counted = rate if differs and not keep else doc.fps
        if abs(end * counted - round(end * counted)) < 1e-3:
            end = round(end * counted) / counted
    if keep:
        offer = None
        if differs and end > start:
            assert rate is not None
            offer = rate
            notes.append(f"The clip runs at {rate:g} fps, the project at {doc.fps:g} fps, so playback shows it "
                         f"only at the project's frames; set the project to {rate:g} fps to see every frame.")
        imp = _with_range(doc, add.text, add, end, asset_id, notes)
        imp.clip_fps = offer
        return imp
    commands = [add]
    fps = doc.fps
    if differs:
        assert rate is not None
        commands.append(SetParameter(doc, "fps", int(rate) if rate.is_integer() else rate))
        notes.append(f"Project frame rate set to the clip's {rate:g} fps (it was {doc.fps:g}).")
        fps = rate
    rng = clip_range_command(doc, start, end, fps)
    if rng is not None:
        commands.append(rng)
        notes.append(f"Frame range set to the clip ({end - start:.3g} s).")
    return Import(commands[0] if len(commands) == 1 else Macro(add.text, commands), asset_id, notes)


def _asset_base(p: Path) -> str:
    base = p.stem.replace("/", "_") or "character"
    return base


# --------------------------------------------------------------------------- glTF
def _animated_elsewhere(doc: Document) -> bool:
    """Whether the document has keys on any channel (its range is someone's choice)."""
    return any(c.keys for c in doc.channels.values())


def gltf_import(doc: Document, path: str | os.PathLike[str]) -> Import:
    """A ``.glb`` / ``.gltf``: the whole character (every mesh, every animation as a clip;
    see :mod:`qtanimator.document.gltf_character`), the first clip active. The frame range
    fits that clip, or grows to show it when the document already has keys."""
    p = Path(path)
    scene = import_gltf(p)
    mapping = character_from_gltf(scene, p)
    ch = mapping.character
    aid = doc.unique_asset_id(_asset_base(p))
    props: dict[str, Any] = {}
    channels: dict[str, Channel] = {}
    if ch.clips:
        first = ch.clips[0]
        props[CLIP] = first.name
        channels = {f"{aid}/{rel}": c for rel, c in first.channels.items()}
    asset = Asset(aid, ASSET_KIND, str(p.resolve()), props)
    add = AddAsset(asset, ch, channels, text=f"Add 3D character {aid}")
    nv = ch.skin.num_vertices if ch.skin is not None else 0
    notes = [f"{len(ch.parts)} meshes ({nv} vertices), {len(ch.skeleton.joints)} joints."]
    if ch.clips:
        listed = ", ".join(f"{c.name} ({c.end - c.start:.3g} s)" for c in ch.clips)
        notes.append(f"{len(ch.clips)} clips: {listed}; pick one in Properties or in the Clip list under the "
                     "3D view.")
    notes += mapping.notes
    notes += place_new_character(doc, add, ch.clips[0].start if ch.clips else 0.0)
    if not ch.clips:
        return Import(add, aid, notes)
    first = ch.clips[0]
    return _timed(doc, add, first.start, first.end, _key_rate(first.channels.values()), aid, notes)


# --------------------------------------------------------------------------- any
def import_file(doc: Document, path: str | os.PathLike[str], selected: str | None = None) -> Import:
    """Import any 3D file by its suffix (FormatError for an unknown one)."""
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix == ".skel":
        return skel_import(doc, p)
    if suffix == ".skin":
        return skin_import(doc, p, selected)
    if suffix == ".anim":
        return anim_import(doc, p, selected)
    if suffix == ".obj":
        return obj_import(doc, p)
    if suffix == ".bvh":
        return bvh_import(doc, p)
    if suffix in GLTF_SUFFIXES:
        return gltf_import(doc, p)
    raise FormatError("not a 3D file qtanimator can import.", p)


# ------------------------------------------------------------------------- export
def export_gltf(doc: Document, asset_id: str, path: str | os.PathLike[str]) -> tuple[CharacterExport, list[str]]:
    """Write a 3D character to ``.glb``: every mesh, every clip (a character without clips: its
    channels over the document's frame range at its fps) and the rest pose of its file (see
    :mod:`qtanimator.document.gltf_export`). Returns the export and messages for the user
    (keys that had to be sampled, weights renormalised).

    Raises ValueError when the character has no skin or mesh; OSError when writing fails.
    """
    result, messages = character_scene(doc, asset_id)
    export_glb(path, result.scene)
    return result, messages
