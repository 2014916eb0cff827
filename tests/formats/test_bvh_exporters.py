"""BVH as exporters write it (issue 21, item 3), checked against bvhio.

bvhio (an independent reader) puts a joint at its position channels when it has them and at
its OFFSET otherwise: the **absolute** convention, per axis and per joint. qtanimator detects
the convention per file (:func:`qtanimator.formats.bvh.detect_positions`). So:

* a file detected absolute is compared with bvhio on the same file;
* a file detected relative (position added to the OFFSET) is compared with bvhio on the same
  motion rewritten into the absolute convention by the test (each position value plus its
  joint's OFFSET): the documented relative reading.

bvhio computes in float32 (PyGLM), so "equal" is 1e-6 of the skeleton's size.
"""

from __future__ import annotations

import re
from pathlib import Path

import bvhio  # a test dependency: missing is an error, not a skip
import numpy as np
import pytest
from needs import shared_data_dir, shared_data_params, shared_data_path
from samples import BLENDER_BVH

from qtanimator.core.clip import apply_clip
from qtanimator.document.character3d import load_bvh_character
from qtanimator.formats import FormatError
from qtanimator.formats.bvh import detect_positions, load_bvh, parse_bvh

#: The sample BVH files (``tests/needs.py``): every one is compared with bvhio; without the
#: sample data the list is one placeholder that the test skips (fails in CI).
DATA = shared_data_dir() / "bvh"
SAMPLES = shared_data_params(sorted(DATA.glob("*.bvh")), DATA / "*.bvh")


@pytest.fixture
def cmu() -> Path:
    """The CMU walk (relative root positions, feet on the floor)."""
    return shared_data_path("bvh", "cmu_12_01_walk.bvh")


# ------------------------------------------------------------------ writing files
def _split(text: str) -> tuple[str, list[str]]:
    head, motion = text.split("MOTION", 1)
    lines = [ln for ln in motion.splitlines() if ln.strip()]
    return head, lines


def _rewrite(path: Path, out: Path, *, root_offset: tuple[float, float, float] | None = None,
             shift_root: tuple[float, float, float] = (0.0, 0.0, 0.0), positions_everywhere: bool = False,
             absolute_children: bool = True, frames: int | None = None, extra_rows: list[str] = ()) -> Path:
    """Write a variant of a BVH file: a new root OFFSET, root positions shifted, position
    channels on every joint (Blender's exporter: absolute, equal to the OFFSET), fewer frames,
    rows after the declared frames."""
    clip = load_bvh(path)
    text = path.read_text()
    head, _ = _split(text)
    motion = clip.motion[: frames or clip.frame_count].copy()
    root = clip.joints[0]
    for col in root.columns:
        name = root.channels[col - root.first_column]
        if name.endswith("position"):
            motion[:, col] += shift_root["XYZ".index(name[0])]
    if root_offset is not None:
        head = re.sub(r"OFFSET[^\n]*", "OFFSET {!r} {!r} {!r}".format(*root_offset), head, count=1)
    if positions_everywhere:
        # Every joint gets "CHANNELS 6 Xposition Yposition Zposition <its rotations>".
        cols: list[np.ndarray] = []
        pieces = re.split(r"(CHANNELS[^\n]*)", head)
        out_head = []
        for piece in pieces:
            if piece.startswith("CHANNELS"):
                names = piece.split()[2:]
                if any(n.endswith("position") for n in names):
                    out_head.append(piece)
                else:
                    out_head.append(f"CHANNELS {len(names) + 3} Xposition Yposition Zposition {' '.join(names)}")
            else:
                out_head.append(piece)
        head = "".join(out_head)
        for j in clip.joints:
            block = motion[:, list(j.columns)]
            if any(c.endswith("position") for c in j.channels):
                cols.append(block)
            else:
                value = j.offset if absolute_children else np.zeros(3)
                cols.append(np.hstack([np.broadcast_to(value, (len(motion), 3)), block]))
        motion = np.hstack(cols)
    rows = [" ".join(repr(float(v)) for v in row) for row in motion]
    head = re.sub(r"\s+$", "\n", head)
    body = f"MOTION\nFrames: {len(rows)}\nFrame Time: {clip.frame_time!r}\n" + "\n".join([*rows, *extra_rows]) + "\n"
    out.write_text(head + body)
    return out


def _absolute_equivalent(path: Path, out: Path) -> Path:
    """The same motion in the absolute convention: each position value plus the OFFSET."""
    clip = load_bvh(path)
    motion = clip.motion.copy()
    for j in clip.joints:
        for col in j.columns:
            name = j.channels[col - j.first_column]
            if name.endswith("position"):
                motion[:, col] += j.offset["XYZ".index(name[0])]
    head, _ = _split(path.read_text())
    rows = [" ".join(repr(float(v)) for v in row) for row in motion]
    out.write_text(head.rstrip() + f"\nMOTION\nFrames: {len(rows)}\nFrame Time: {clip.frame_time!r}\n"
                   + "\n".join(rows) + "\n")
    return out


# -------------------------------------------------------------------- references
def _bvhio_positions(path: Path, frames: list[int]) -> np.ndarray:
    root = bvhio.readAsHierarchy(str(path))
    joints = [j for j, _, _ in root.layout()]
    out = []
    for f in frames:
        root.loadPose(f)
        out.append([list(j.PositionWorld) for j in joints])
    return np.array(out, dtype=np.float64)


def _character_positions(path: Path, frames: list[int], positions: str | None = None) -> np.ndarray:
    """World joint positions through the document's path: load_bvh_character + channels."""
    character, channels = load_bvh_character(path, positions)
    clip = load_bvh(path)
    skeleton = character.skeleton.copy()
    out = []
    for f in frames:
        t = f * clip.frame_time
        apply_clip(skeleton, channels, t)
        for j, chans in character.translations.items():  # joints below the root that move
            for axis, ch in enumerate(chans):
                if ch is not None:
                    skeleton.joints[j].translation[axis] = ch.evaluate(t)
        out.append(skeleton.world_matrices()[:, :3, 3])
    return np.array(out)


def _frames(path: Path, step: int = 7) -> list[int]:
    n = load_bvh(path).frame_count
    return sorted({*range(0, n, step), n - 1})


def _assert_same(ours: np.ndarray, ref: np.ndarray, path: Path) -> None:
    size = load_bvh(path).size()
    err = float(np.abs(ours - ref).max())
    assert err <= 1e-6 * size, f"{path.name}: {err / size:.2e} of the size off bvhio"


# ------------------------------------------------------------------------- tests
@pytest.mark.parametrize("path", SAMPLES, ids=lambda p: p.name)
def test_shared_samples_equal_bvhio(path: Path, tmp_path: Path) -> None:
    shared_data_path()
    frames = _frames(path)
    clip = load_bvh(path)
    ref = _bvhio_positions(path if clip.positions == "absolute" else _absolute_equivalent(path, tmp_path / "a.bvh"),
                           frames)
    _assert_same(_character_positions(path, frames), ref, path)
    W = clip.all_world_matrices()[frames, :, :3, 3]
    _assert_same(W, ref, path)


@pytest.mark.parametrize("name", ["cmu_12_01_walk.bvh", "fairmotion_sinusoidal.bvh", "pybvh_rotation_first_root.bvh"])
def test_six_channels_per_joint_like_blender(name: str, tmp_path: Path) -> None:
    """Blender's exporter: 6 channels on every joint, positions equal to the OFFSET
    (absolute), the root's first position at its OFFSET."""
    src = shared_data_path("bvh", name)
    clip = load_bvh(src)
    first = clip.motion[0, :3] if clip.joints[0].channels[0].endswith("position") else clip.motion[0, 3:6]
    path = _rewrite(src, tmp_path / "blender.bvh", root_offset=tuple(float(v) for v in first),
                    positions_everywhere=True, frames=60)
    assert all(len(j.channels) == 6 for j in load_bvh(path).joints)
    assert load_bvh(path).positions == "absolute"
    frames = _frames(path, 5)
    ref = _bvhio_positions(path, frames)
    _assert_same(_character_positions(path, frames), ref, path)
    character, _ = load_bvh_character(path)
    assert character.positions == "absolute" and "absolute" in character.notes[0]


def test_relative_positions_on_every_joint(cmu: Path, tmp_path: Path) -> None:
    """Position channels of 0 on every joint, root relative: the documented relative reading."""
    path = _rewrite(cmu, tmp_path / "rel6.bvh", root_offset=(0.0, 16.0, 0.0), shift_root=(0.0, -16.0, 0.0),
                    positions_everywhere=True, absolute_children=False, frames=40)
    assert load_bvh(path).positions == "relative"
    frames = _frames(path, 5)
    ref = _bvhio_positions(_absolute_equivalent(path, tmp_path / "abs6.bvh"), frames)
    _assert_same(_character_positions(path, frames), ref, path)


def test_a_joint_that_really_moves_gets_translation_channels(cmu: Path, tmp_path: Path) -> None:
    path = _rewrite(cmu, tmp_path / "moving.bvh", positions_everywhere=True, frames=10)
    text = path.read_text().splitlines()
    head_end = text.index("MOTION")
    clip = load_bvh(path)
    col = clip.joints[3].first_column  # LeftLeg's Xposition
    row = text[head_end + 4].split()
    row[col] = repr(float(row[col]) + 2.0)
    text[head_end + 4] = " ".join(row)
    path.write_text("\n".join(text) + "\n")
    character, _ = load_bvh_character(path, "absolute")
    assert list(character.translations) == [3]  # LeftLeg moves: translation channels
    frames = _frames(path, 1)
    # bvhio reads positions as absolute (they replace the OFFSET), whatever the file looks like
    _assert_same(_character_positions(path, frames, "absolute"), _bvhio_positions(path, frames), path)


@pytest.mark.parametrize("extra", [["0 " * 96], ["0 " * 96, "1 2 3"], ["KEYS 1 2", "Hips 3 4"]])
def test_rows_after_the_declared_frames_are_ignored_with_a_warning(cmu: Path, extra: list[str], tmp_path: Path) -> None:
    path = _rewrite(cmu, tmp_path / "extra.bvh", frames=30, extra_rows=extra)
    clip = load_bvh(path)
    assert clip.frame_count == 30
    n = len(extra)
    assert clip.warnings == [f"{n} row{'s' if n > 1 else ''} after the declared 30 frames "
                             f"{'were' if n > 1 else 'was'} ignored."]
    np.testing.assert_array_equal(clip.motion, load_bvh(cmu).motion[:30])
    frames = _frames(path, 3)
    _assert_same(_character_positions(path, frames), _bvhio_positions(path, frames), path)
    character, _ = load_bvh_character(path)
    assert clip.warnings[0] in character.notes


def _height_and_floor(path: Path, positions: str | None = None) -> tuple[float, np.ndarray]:
    """The rest pose's height and, per frame, the lowest toe tip (End Sites of the feet)."""
    clip = load_bvh(path)
    rest = clip.rest_world_matrices()
    tips = clip.end_site_positions(rest)
    height = float(max(p[1] for p in tips.values()) - min(p[1] for p in tips.values()))
    character, channels = load_bvh_character(path, positions)
    skeleton = character.skeleton.copy()
    toes = [i for i, j in enumerate(clip.joints) if "Toe" in j.name]
    lowest = []
    for f in range(0, clip.frame_count, 4):
        apply_clip(skeleton, channels, f * clip.frame_time)
        w = skeleton.world_matrices()
        lowest.append(min((w[i, :3, :3] @ clip.joints[i].end_site + w[i, :3, 3])[1] for i in toes))
    return height, np.array(lowest)


@pytest.mark.parametrize("convention", ["as-is", "absolute", "relative"])
def test_walking_feet_stay_on_the_floor_in_both_conventions(cmu: Path, convention: str, tmp_path: Path) -> None:
    clip = load_bvh(cmu)
    hip = float(clip.motion[0, 1])
    if convention == "as-is":
        path = cmu
    elif convention == "absolute":  # OFFSET = the hip's rest height, positions as captured
        path = _rewrite(cmu, tmp_path / "abs.bvh", root_offset=(0.0, hip, 0.0))
    else:  # OFFSET = the hip's rest height, positions near zero
        path = _rewrite(cmu, tmp_path / "rel.bvh", root_offset=(0.0, hip, 0.0), shift_root=(0.0, -hip, 0.0))
    expected = {"as-is": "relative", "absolute": "absolute", "relative": "relative"}[convention]
    assert detect_positions(load_bvh(path)) == expected
    height, lowest = _height_and_floor(path)
    assert abs(lowest.min()) <= 0.05 * height
    assert abs(float(np.median(lowest))) <= 0.05 * height
    # The other convention floats (or sinks) by the hip's height: detection matters.
    if convention != "as-is":
        other = "relative" if expected == "absolute" else "absolute"
        _, wrong = _height_and_floor(path, other)
        assert abs(float(np.median(wrong))) > 0.5 * height


# ---------------------------------------------------------------- still broken
TINY = BLENDER_BVH


def test_tiny_blender_style_file() -> None:
    clip = parse_bvh(TINY)
    assert clip.positions == "absolute" and clip.warnings == []
    np.testing.assert_allclose(clip.world_matrices(frame=1)[1, :3, 3], [1.0, 5.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(clip.world_matrices(frame=1, positions="relative")[0, :3, 3], [1.0, 20.0, 0.0])


@pytest.mark.parametrize(("edit", "line", "words"), [
    (("1 10 0 0 0 0 0 -5 0 20 0 0\n", "1 10 0 0 0 0 0 -5 0 20 0\n"), 20, "ends early"),
    (("1 10 0 0 0 0 0 -5 0 20 0 0\n", "1 10 0 0 0 0 0 -5 0 20 0 x\n"), 20, "'x'"),
    (("1 10 0 0 0 0 0 -5 0 20 0 0\n", "1 10 0 0 0 0 0 -5 0 20 0\n0 0 0 0 0 0 0 0 0 0 0 0\n"), 20,
     "frame 2 has 11 numbers"),
    (("0 10 0 0 0 0 0 -5 0 10 0 0\n", "0 10 0 0 0 0 0 -5 0 10 0 zero\n"), 19, "'zero'"),
])
def test_broken_files_still_raise(edit: tuple[str, str], line: int, words: str) -> None:
    with pytest.raises(FormatError) as info:
        parse_bvh(TINY.replace(*edit), "bad.bvh")
    assert info.value.line == line
    assert words in str(info.value)


def test_the_import_message_names_the_convention_and_the_asset_keeps_it(shared_data) -> None:  # type: ignore[no-untyped-def]
    """File ▸ Open of a BVH: the import notes say which position convention was used, and
    the asset records it (so the project reopens the same way)."""
    from qtanimator.document import Document
    from qtanimator.document.character3d import BVH_POSITIONS
    from qtanimator.document.import3d import bvh_import

    doc = Document()
    imp = bvh_import(doc, shared_data / "bvh" / "cmu_12_01_walk.bvh")
    imp.command.do(doc)
    assert any(n.startswith("BVH positions: ") and "relative" in n for n in imp.notes)
    assert doc.assets[imp.asset_id].properties[BVH_POSITIONS] == "relative"
