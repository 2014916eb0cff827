"""Clip helpers (core/clip.py): pose_values with and without a skeleton, and the loop
mapping's half-open range [start, end)."""

from __future__ import annotations

import numpy as np
import pytest

from qtanimator.core.channel import Channel, Key
from qtanimator.core.clip import ClipPlayer, pose_values
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
