"""Clip helpers (core/clip.py): pose_values with and without a skeleton, the loop
mapping's half-open range [start, end), the player's "finished" and speed, clip equality."""

from __future__ import annotations

import numpy as np
import pytest

from qtanimator.core.channel import Channel, Key
from qtanimator.core.clip import AnimationClip, ClipPlayer, pose_values
from qtanimator.core.skeleton import Dof, Joint, Skeleton


def _const(v: float) -> Channel:
    return Channel([Key(0.0, v, "linear", "linear")])


def test_pose_values_without_a_skeleton_fill_zeros():
    # two joints: 3 root channels + 6 DOF channels; only root y and joint 1's z are keyed
    chans = [None, _const(2.0), None, None, None, None, None, None, _const(-0.5)]
    root, dofs = pose_values(chans, 2, 0.3)
    np.testing.assert_array_equal(root, [0.0, 2.0, 0.0])
    np.testing.assert_array_equal(dofs, [[0.0, 0.0, 0.0], [0.0, 0.0, -0.5]])
    # short clips: no channel at all
    root, dofs = pose_values([], 3, 0.0)
    assert root.shape == (3,) and dofs.shape == (3, 3)
    assert not root.any() and not dofs.any()


def test_pose_values_keep_the_skeletons_values_where_no_channel():
    def dofs():
        return (Dof(0.0, -10.0, 10.0), Dof(0.0, -10.0, 10.0), Dof(0.0, -10.0, 10.0))
    sk = Skeleton([Joint("root", None, (0, 0, 0), dofs()), Joint("a", 0, (0, 1, 0), dofs())])
    sk.root_translation = np.array([1.0, 2.0, 3.0])
    sk.set_dof_values(np.array([[0.1, 0.2, 0.3], [0.4, 0.5, 0.6]]))
    chans = [_const(7.0), None, None, None, _const(-0.25)]
    root, vals = pose_values(chans, 2, 0.0, sk)
    np.testing.assert_array_equal(root, [7.0, 2.0, 3.0])
    np.testing.assert_array_equal(vals, [[0.1, -0.25, 0.3], [0.4, 0.5, 0.6]])
    # the skeleton itself is not changed
    np.testing.assert_array_equal(sk.root_translation, [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(sk.dof_values(), [[0.1, 0.2, 0.3], [0.4, 0.5, 0.6]])


@pytest.mark.parametrize("elapsed, expected", [
    (0.0, 2.0), (0.25, 2.25), (1.0, 2.0), (3.0, 2.0), (-0.25, 2.75), (-1.0, 2.0),
    # 1 - 1e-20 rounds to 1.0, the end of the loop, which is the start of the next one
    (-1e-20, 2.0),
])
def test_loop_maps_into_start_inclusive_end_exclusive(elapsed, expected):
    assert ClipPlayer(2.0, 3.0, "loop").clip_time(elapsed) == expected


def test_once_with_speed_zero_is_never_finished():
    """A paused "once" player moves towards no end, so it is not finished even at the end."""
    p = ClipPlayer(0.0, 2.0, "once", speed=0.0)
    p.seek(2.0)
    assert p.elapsed == 2.0
    assert not p.finished
    assert p.advance(1.0) == 2.0
    assert not p.finished


def test_once_backwards_is_finished_only_at_the_start():
    """Playing "once" at negative speed finishes when the playhead reaches the start (0 s of
    elapsed time), not before."""
    p = ClipPlayer(1.0, 3.0, "once", speed=-1.0)
    p.seek(2.0)
    assert p.advance(0.5) == 1.5  # elapsed 1.0 - 0.5 = 0.5
    assert p.elapsed == 0.5
    assert not p.finished
    assert p.advance(0.75) == 1.0  # clamped at elapsed 0
    assert p.finished
    # a fresh backwards player already stands at the start it moves towards
    assert ClipPlayer.for_clip(AnimationClip(start=1.0, end=3.0), "once", -1.0).finished


def test_advance_scales_by_speed_and_accumulates():
    """advance(dt) adds dt·speed: 0.5·1.5 then 0.25·1.5 from start 1 -> clip times 1.75, 2.125."""
    p = ClipPlayer(1.0, 5.0, "continue", speed=1.5)
    assert p.advance(0.5) == pytest.approx(1.75)
    assert p.advance(0.25) == pytest.approx(2.125)
    p.reset()
    assert p.time == 1.0


def test_default_clip_is_empty_and_compares_only_with_clips():
    """A clip made without arguments spans [0, 0]; comparing with a non-clip is plainly False."""
    clip = AnimationClip()
    assert (clip.start, clip.end, clip.duration) == (0.0, 0.0, 0.0)
    assert clip.evaluate(1.0).shape == (0,)
    assert (clip == 5) is False
    assert (clip != "clip") is True
    assert clip == AnimationClip([], 0.0, 0.0)
    assert AnimationClip([Channel([Key(0.0, 1.0)])], 0.0, 1.0) != AnimationClip([], 0.0, 1.0)


def test_player_for_a_clip_takes_its_range_loops_and_plays_at_speed_one():
    p = ClipPlayer.for_clip(AnimationClip(start=1.0, end=3.0))
    assert (p.start, p.end, p.duration, p.mode.value, p.speed) == (1.0, 3.0, 2.0, "loop", 1.0)
    assert p.advance(2.5) == 1.5  # 2.5 s into a 2 s loop from 1
