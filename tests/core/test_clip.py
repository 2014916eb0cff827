import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from qtanimator.core.channel import Channel, Key
from qtanimator.core.clip import (
    ROOT,
    AnimationClip,
    ClipPlayer,
    apply_clip,
    channel_count,
    channel_index,
    channel_target,
)
from qtanimator.core.skeleton import Dof, Joint, Skeleton
from qtanimator.core.skinning import skin_positions
from qtanimator.formats.anim import load_anim
from qtanimator.formats.skel import load_skel
from qtanimator.formats.skin import load_skin


def test_channel_mapping():
    assert [channel_target(i) for i in range(6)] == [(ROOT, "x"), (ROOT, "y"), (ROOT, "z"),
                                                     (0, "x"), (0, "y"), (0, "z")]
    assert channel_target(71) == (22, "z")
    assert channel_count(23) == 72
    for i in range(80):
        assert channel_index(*channel_target(i)) == i


def test_apply_clip_sets_root_and_clamped_dofs():
    skel = Skeleton([Joint("r"), Joint("k", 0, [0, -1, 0], (Dof(0, -2, 0), Dof(), Dof()))])
    chans = [Channel([Key(0, 1), Key(1, 3)]), None, None,  # root x; y, z missing
             Channel([Key(0, 0.5)]), None, None,
             Channel([Key(0, 0), Key(1, -5)])]
    apply_clip(skel, chans, 0.5)
    assert skel.root_translation[0] == pytest.approx(2.0)
    assert skel.get_dof(0, "x") == 0.5
    assert skel.get_dof(1, "x") == -2.0  # −2.5 clamped to the limit


class TestPlayer:
    def test_loop(self):
        p = ClipPlayer(1.0, 3.0, "loop")
        assert [p.clip_time(e) for e in (0.0, 1.5, 2.0, 2.5, 4.0, -0.5)] == [1.0, 2.5, 1.0, 1.5, 1.0, 2.5]

    def test_once_stops_at_the_end(self):
        p = ClipPlayer(0.0, 2.0, "once")
        assert p.advance(1.5) == 1.5
        assert not p.finished
        assert p.advance(1.5) == 2.0
        assert p.finished

    def test_ping_pong(self):
        p = ClipPlayer(0.0, 2.0, "ping-pong")
        assert [p.clip_time(e) for e in (0.5, 2.0, 2.5, 3.5, 4.0, 4.5)] == [0.5, 2.0, 1.5, 0.5, 0.0, 0.5]

    def test_continue_and_speed(self):
        p = ClipPlayer(0.0, 2.0, "continue", speed=2.0)
        assert p.advance(1.5) == 3.0
        p = ClipPlayer(0.0, 2.0, "loop", speed=-1.0)
        assert p.advance(0.5) == 1.5
        p.seek(0.25)
        assert p.time == 0.25

    def test_bad_range(self):
        with pytest.raises(ValueError):
            ClipPlayer(2.0, 1.0)

    @settings(max_examples=50, deadline=None)
    @given(st.floats(-100, 100), st.sampled_from(["loop", "once", "ping-pong"]))
    def test_time_stays_in_range(self, elapsed, mode):
        p = ClipPlayer(-1.0, 3.0, mode)
        assert -1.0 <= p.clip_time(elapsed) <= 3.0


@pytest.fixture(scope="module")
def wasp(shared_data):
    d = shared_data / "cse169/wasp_walk"
    return load_skel(d / "wasp.skel"), load_skin(d / "wasp.skin"), load_anim(d / "wasp_walk.anim")


def test_wasp_walk_feet_stay_on_the_ground(wasp):
    skel, skin, clip = wasp
    lows = []
    for t in np.linspace(0.0, 4.0, 81):
        apply_clip(skel, clip, float(t))
        lows.append(skin_positions(skin, skel.world_matrices())[:, 1].min())
    lows = np.array(lows)
    assert lows.min() >= -0.0365 - 1e-4
    assert lows.max() <= -0.0171 + 1e-4
    # it walks towards −z at 0.45 units/s
    apply_clip(skel, clip, 0.0)
    z0 = skel.root_translation[2]
    apply_clip(skel, clip, 4.0)
    assert skel.root_translation[2] - z0 == pytest.approx(-1.8, abs=1e-9)


def test_planted_foot_does_not_slide(wasp):
    skel, skin, clip = wasp
    track = []
    for t in np.linspace(0.0, 0.5, 11):
        apply_clip(skel, clip, float(t))
        track.append(skin_positions(skin, skel.world_matrices()))
    track = np.array(track)
    # some vertex near (1.09, 0, 0.63) barely moves over the first half second
    start = track[0]
    near = np.linalg.norm(start - [1.09, 0.0, 0.63], axis=1).argmin()
    assert np.linalg.norm(start[near] - [1.09, 0.0, 0.63]) < 0.1
    assert np.ptp(track[:, near], axis=0).max() < 0.05


@settings(max_examples=20, deadline=None)
@given(t=st.floats(-3.0, 7.0))
def test_pose_equals_evaluating_channels(wasp, t):
    skel, _, clip = wasp
    s = skel.copy()
    apply_clip(s, clip, t)
    direct = clip.evaluate(t)
    assert np.array_equal(s.root_translation, direct[:3])
    lo, hi = s.dof_limits()
    assert np.array_equal(s.dof_values().reshape(-1), np.clip(direct[3:], lo.reshape(-1), hi.reshape(-1)))


def test_clip_evaluate_shapes():
    clip = AnimationClip([Channel([Key(0, 0), Key(1, 1)]), Channel([Key(0, 2)])], 0.0, 1.0)
    assert clip.evaluate(0.5).shape == (2,)
    assert clip.evaluate([0.0, 0.5, 1.0]).shape == (2, 3)
    assert clip.duration == 1.0
