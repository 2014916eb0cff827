"""BVH import: the three shared sample files, conventions checked against scipy, bad input."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from qtanimator.core.channel import Channel, Interpolation
from qtanimator.formats import FormatError
from qtanimator.formats.bvh import load_bvh, parse_bvh, summarize
from qtanimator.formats.info import summarize as info_summarize

SMALL = """HIERARCHY
ROOT Hips
{
\tOFFSET 1 2 3
\tCHANNELS 6 Zrotation Xrotation Yrotation Xposition Yposition Zposition
\tJOINT Spine
\t{
\t\tOFFSET 0 10 0
\t\tCHANNELS 3 Zrotation Xrotation Yrotation
\t\tEnd Site
\t\t{
\t\t\tOFFSET 0 4 0
\t\t}
\t}
\tJOINT Leaf
\t{
\t\tOFFSET 2 -8 0
\t\tCHANNELS 3 Xrotation Yrotation Zrotation
\t}
}
MOTION
Frames: 2
Frame Time: .5
5 -3 0 10 50 -20 1 2 3 4 5 6
15 -13 10 20 60 -30 11 12 13 14 15 16
"""


def _bvh(shared_data: Path, name: str) -> Path:
    return shared_data / "bvh" / name


def _local(offset: np.ndarray, order: str, angles_deg: list[float], position: np.ndarray) -> np.ndarray:
    """Independent reference: T(offset + position) · intrinsic rotation in the listed order."""
    m = np.eye(4)
    m[:3, :3] = Rotation.from_euler(order.upper(), angles_deg, degrees=True).as_matrix()
    m[:3, 3] = offset + position
    return m


# ----------------------------------------------------------------- sample files
@pytest.mark.parametrize(("name", "joints", "end_sites", "frames", "frame_time", "channels"), [
    ("cmu_12_01_walk.bvh", 31, 7, 524, 0.0083333, 96),
    ("pybvh_rotation_first_root.bvh", 4, 2, 4, 0.04, 15),
    ("fairmotion_sinusoidal.bvh", 4, 0, 120, 0.016666666666666666, 15),
])
def test_sample_files_load(shared_data: Path, name: str, joints: int, end_sites: int, frames: int,
                           frame_time: float, channels: int) -> None:
    clip = load_bvh(_bvh(shared_data, name))
    assert len(clip.joints) == joints
    assert sum(j.end_site is not None for j in clip.joints) == end_sites
    assert clip.frame_count == frames
    assert clip.frame_time == frame_time
    assert clip.channel_count == channels
    assert clip.motion.shape == (frames, channels)
    assert len(clip.channels) == channels
    for ch in clip.channels.values():
        assert len(ch.keys) == frames
        assert all(k.interpolation is Interpolation.LINEAR for k in ch.keys[:-1])
    assert clip.all_world_matrices().shape == (frames, joints, 4, 4)


def test_cmu_walk_names_orders_and_zero_offsets(shared_data: Path) -> None:
    clip = load_bvh(_bvh(shared_data, "cmu_12_01_walk.bvh"))
    assert clip.joint_names[:6] == ["Hips", "LHipJoint", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase"]
    assert clip.joint_names[-1] == "RThumb"
    assert clip.joints[0].channels == ("Xposition", "Yposition", "Zposition", "Zrotation", "Yrotation", "Xrotation")
    assert all(j.rotation_order == "zyx" for j in clip.joints)
    zero = {j.name for j in clip.joints if not np.any(j.offset)}
    assert zero == {"Hips", "LHipJoint", "RHipJoint", "LowerBack", "Neck", "LeftShoulder", "RightShoulder",
                    "LeftFingerBase", "RightFingerBase", "LThumb", "RThumb"}
    # Units are not metres: the hips stand about 16 units high.
    assert 10 < clip.world_matrices(frame=100)[0, 1, 3] < 25


def test_cmu_world_matrices_match_independent_reference(shared_data: Path) -> None:
    clip = load_bvh(_bvh(shared_data, "cmu_12_01_walk.bvh"))
    for frame in (0, 1, 257, 523):
        row = clip.motion[frame]
        ref: list[np.ndarray] = []
        for j in clip.joints:
            vals = dict(zip(j.channels, row[j.first_column:j.first_column + len(j.channels)]))
            pos = np.array([vals.get(a + "position", 0.0) for a in "XYZ"])
            angles = [vals[a.upper() + "rotation"] for a in j.rotation_order]
            local = _local(j.offset, j.rotation_order, angles, pos)
            ref.append(local if j.parent is None else ref[j.parent] @ local)
        np.testing.assert_allclose(clip.world_matrices(frame=frame), np.array(ref), atol=1e-9)
        np.testing.assert_allclose(clip.all_world_matrices()[frame], np.array(ref), atol=1e-9)


def test_rotation_first_root_by_hand(shared_data: Path) -> None:
    clip = load_bvh(_bvh(shared_data, "pybvh_rotation_first_root.bvh"))
    hips, spine, head, leg = clip.joints
    assert hips.channels[:3] == ("Zrotation", "Xrotation", "Yrotation")
    assert (hips.rotation_order, spine.rotation_order, head.rotation_order, leg.rotation_order) == \
        ("zxy", "zxy", "zyx", "xyz")
    assert [j.parent for j in clip.joints] == [None, 0, 1, 0]
    np.testing.assert_array_equal(head.end_site, [0, 4, 0])
    w = clip.world_matrices(frame=0)
    # Frame 0: Hips Z=5 X=-3 Y=0, position (10, 50, -20); Spine 1 2 3 (Z X Y); Head 4 5 6 (Z Y X).
    m_hips = _local(np.zeros(3), "ZXY", [5, -3, 0], np.array([10.0, 50, -20]))
    m_spine = m_hips @ _local(np.array([0.0, 10, 0]), "ZXY", [1, 2, 3], np.zeros(3))
    m_head = m_spine @ _local(np.array([0.0, 8, 0]), "ZYX", [4, 5, 6], np.zeros(3))
    m_leg = m_hips @ _local(np.array([2.0, -8, 0]), "XYZ", [7, 8, 9], np.zeros(3))
    np.testing.assert_allclose(w, np.array([m_hips, m_spine, m_head, m_leg]), atol=1e-12)
    # The rotation order matters: the head's ZYX differs from ZXY.
    wrong = m_spine @ _local(np.array([0.0, 8, 0]), "ZXY", [4, 5, 6], np.zeros(3))
    assert not np.allclose(wrong[:3, :3], w[2, :3, :3], atol=1e-6)
    tip = clip.end_site_positions(w)[2]
    np.testing.assert_allclose(tip, (m_head @ [0, 4, 0, 1])[:3], atol=1e-12)


def test_sinusoidal_leaf_without_end_site(shared_data: Path) -> None:
    clip = load_bvh(_bvh(shared_data, "fairmotion_sinusoidal.bvh"))
    leaf = clip.joints[3]
    assert leaf.name == "child3" and leaf.end_site is None and len(leaf.channels) == 3
    moving = np.flatnonzero(np.ptp(clip.motion, axis=0) > 0)
    assert moving.tolist() == [9]
    assert clip.motion[:, 9].min() == -90.0 and clip.motion[:, 9].max() == -45.0
    roots = clip.all_world_matrices()[:, 0, :3, 3]
    np.testing.assert_allclose(roots, np.broadcast_to([-3.0, 6.0, 5.0], roots.shape))
    # child2 rotates about x by -90°: child3 (offset (0, 3, 0)) swings from +y onto -z.
    w = clip.world_matrices(frame=0)
    np.testing.assert_allclose(w[3, :3, 3] - w[2, :3, 3], [0.0, 0.0, -3.0], atol=1e-12)


def test_channels_are_linear_in_seconds_and_radians(shared_data: Path) -> None:
    clip = load_bvh(_bvh(shared_data, "cmu_12_01_walk.bvh"))
    name = "LeftUpLeg/Xrotation"
    ch = clip.channels[name]
    col = clip.channel_names.index(name)
    assert isinstance(ch, Channel)
    t = clip.frame_time * 10.25
    expected = np.radians(clip.motion[10, col] * 0.75 + clip.motion[11, col] * 0.25)
    assert ch.evaluate(t) == pytest.approx(expected, abs=1e-12)
    assert ch.evaluate(clip.frame_time * 523) == pytest.approx(np.radians(clip.motion[523, col]))
    assert clip.channels["Hips/Yposition"].evaluate(0.0) == clip.motion[0, 1]
    # Constant extrapolation outside the clip.
    assert ch.evaluate(-1.0) == pytest.approx(np.radians(clip.motion[0, col]))
    assert ch.evaluate(100.0) == pytest.approx(np.radians(clip.motion[-1, col]))


def test_world_matrices_at_time_follow_the_channels(shared_data: Path) -> None:
    clip = load_bvh(_bvh(shared_data, "cmu_12_01_walk.bvh"))
    np.testing.assert_allclose(clip.world_matrices(7 * clip.frame_time), clip.world_matrices(frame=7), atol=1e-9)
    t = 3.3 * clip.frame_time
    values = np.array([clip.channels[n].evaluate(t) for n in clip.channel_names])
    np.testing.assert_allclose(clip.values_at(t), values, atol=1e-12)
    w = clip.world_matrices(t)
    np.testing.assert_allclose(w[:, :3, :3] @ np.swapaxes(w[:, :3, :3], 1, 2),
                               np.broadcast_to(np.eye(3), (31, 3, 3)), atol=1e-12)


def test_inline_small_file_and_summary(tmp_path: Path) -> None:
    clip = parse_bvh(SMALL)
    assert clip.frame_time == 0.5 and clip.frame_count == 2
    assert clip.channel_names[-3:] == ["Leaf/Xrotation", "Leaf/Yrotation", "Leaf/Zrotation"]
    w = clip.world_matrices(frame=1)
    ref = _local(np.array([1.0, 2, 3]), "ZXY", [15, -13, 10], np.array([20.0, 60, -30]))
    np.testing.assert_allclose(w[0], ref, atol=1e-12)
    np.testing.assert_allclose(clip.rest_world_matrices()[2, :3, 3], [3.0, -6.0, 3.0])
    path = tmp_path / "small.bvh"
    path.write_text(SMALL)
    info = info_summarize(path)
    assert info == summarize(path)
    assert info["frames"] == 2 and info["joints"] == 3 and info["channels"] == 12


@pytest.mark.parametrize("newline", ["\r\n", "\r", "\n"])
def test_line_endings_and_whitespace(newline: str) -> None:
    text = SMALL.replace("\n", newline).replace("CHANNELS 3", "CHANNELS  3").replace("\t", "\t\t")
    text = text.replace("Frame Time: .5", "Frame Time: .5   ")
    clip = parse_bvh(text.rstrip())
    np.testing.assert_array_equal(clip.motion, parse_bvh(SMALL).motion)


# ------------------------------------------------------------------ bad input
@pytest.mark.parametrize(("edit", "line", "words"), [
    (("HIERARCHY", "HIERARCHIE"), 1, "HIERARCHY"),
    (("CHANNELS 3 Xrotation Yrotation Zrotation", "CHANNELS 3 Xrotation Yrotation Wrotation"), 18, "Wrotation"),
    (("CHANNELS 3 Zrotation", "CHANNELS 7 Zrotation"), 9, "0 to 6"),
    (("OFFSET 0 10 0", "OFFSET 0 ten 0"), 8, "ten"),
    (("Frame Time: .5", "Frame Time: 0"), 23, "positive"),
    (("Frames: 2", "Frames: 3"), 25, "ends early"),
    # Rows after the declared frames are ignored with a warning (issue 21):
    # tests/formats/test_bvh_exporters.py.
    (("15 -13 10", "15 x 10"), 25, "'x'"),
    (("Frames: 2", "Frames: 2.5"), 22, "whole number"),
    (("Frames: 2", "Frames: 999999999999"), 25, "ends early"),
    (("Frames: 2", "Frames: " + "9" * 20), 22, "too large"),
    (("Frames: 2", "Frames: " + "9" * 5000), 22, "too large"),  # int() refuses > 4300 digits
    (("CHANNELS 3 Zrotation", "CHANNELS " + "9" * 5000 + " Zrotation"), 9, "too large"),
    (("OFFSET 0 4 0", "OFFSET 0 4"), 13, "number"),
    (("1 2 3 4 5 6\n", "1 2 3 4 5 1e999\n"), 24, "too large"),
    (("Zrotation Xrotation Yrotation\n", "Zrotation Zrotation Yrotation\n"), 9, "twice"),
])
def test_malformed_input_reports_line(edit: tuple[str, str], line: int, words: str) -> None:
    text = SMALL.replace(edit[0], edit[1], 1)
    assert text != SMALL
    with pytest.raises(FormatError) as info:
        parse_bvh(text, "bad.bvh")
    assert info.value.line == line
    assert words in str(info.value)
    assert str(info.value).startswith("bad.bvh, line")


def test_unclosed_and_empty_files(tmp_path: Path) -> None:
    with pytest.raises(FormatError, match="not closed"):
        parse_bvh(SMALL[:SMALL.index("MOTION")].rstrip().rstrip("}"))
    with pytest.raises(FormatError, match="empty"):
        parse_bvh("")
    with pytest.raises(FormatError, match="cannot read"):
        load_bvh(tmp_path / "missing.bvh")
    deep = "HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\n" + "JOINT j\n{\nOFFSET 0 0 0\n" * 5000 + "}\n" * 5001
    clip = parse_bvh(deep + "MOTION\nFrames: 0\nFrame Time: 1\n")
    assert len(clip.joints) == 5001 and clip.frame_count == 0


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
def test_fuzzed_bvh_raises_only_format_error(data: st.DataObject) -> None:
    text = SMALL
    for _ in range(data.draw(st.integers(1, 4))):
        i = data.draw(st.integers(0, len(text)))
        j = data.draw(st.integers(i, min(len(text), i + 12)))
        insert = data.draw(st.sampled_from(["", "{", "}", "-", "1e400", " ", "\n", "JOINT x", "End Site",
                                            "CHANNELS 9", "nan", "Frames:", "\r", "0"]))
        text = text[:i] + insert + text[j:]
    try:
        clip = parse_bvh(text)
    except FormatError:
        return
    assert clip.motion.shape == (clip.frame_count, clip.channel_count)
    assert np.isfinite(clip.all_world_matrices()).all()


@settings(max_examples=100, deadline=None)
@given(st.binary(max_size=300))
def test_random_bytes_raise_only_format_error(tmp_path_factory: pytest.TempPathFactory, blob: bytes) -> None:
    path = tmp_path_factory.mktemp("fuzz") / "f.bvh"
    path.write_bytes(b"HIERARCHY\nROOT a\n{" + blob)
    try:
        load_bvh(path)
    except FormatError:
        pass


@pytest.mark.parametrize("name", ["cmu_12_01_walk.bvh", "pybvh_rotation_first_root.bvh", "fairmotion_sinusoidal.bvh"])
def test_to_skeleton_and_clip_channels_pose_like_the_clip(shared_data: Path, name: str) -> None:
    from qtanimator.core.clip import apply_clip

    clip = load_bvh(_bvh(shared_data, name))
    skeleton, channels, moving = clip.to_skeleton()
    assert moving == {}
    assert skeleton.names == clip.joint_names
    assert [j.rotation_order[:len(b.rotation_order)] for j, b in zip(skeleton.joints, clip.joints)] == \
        [b.rotation_order for b in clip.joints]
    assert len(channels) == 3 + 3 * len(clip.joints)
    for t in np.linspace(-0.1, clip.duration + 0.1, 9):
        apply_clip(skeleton, channels, float(t))
        np.testing.assert_allclose(skeleton.world_matrices(), clip.world_matrices(float(t)), atol=1e-9)


def test_to_skeleton_gives_a_joint_that_moves_translation_channels() -> None:
    from qtanimator.core.clip import apply_clip

    text = SMALL.replace("CHANNELS 3 Xrotation Yrotation Zrotation", "CHANNELS 3 Xposition Yrotation Zrotation")
    clip = parse_bvh(text)
    for convention in ("relative", "absolute"):
        skeleton, channels, moving = clip.to_skeleton(convention)
        assert moving and all(skeleton.joints[j].translates for j in moving)
        for t in np.linspace(0.0, clip.duration, 5):
            apply_clip(skeleton, channels, float(t))
            for j, chans in moving.items():
                for axis, ch in enumerate(chans):
                    if ch is not None:
                        skeleton.joints[j].translation[axis] = ch.evaluate(float(t))
            np.testing.assert_allclose(skeleton.world_matrices(), clip.world_matrices(float(t), positions=convention),
                                       atol=1e-9)
