"""Weighted tangents in formats that cannot hold them (issue 13, item 4): ``.anim`` gets
added keys, glTF is sampled, and both say so."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from qtanimator.core.channel import Channel, Key
from qtanimator.core.clip import AnimationClip
from qtanimator.document.gltf_skeleton_export import GltfExportWarning, build_character_scene
from qtanimator.formats.anim import AnimExportWarning, format_anim, load_anim, parse_anim, save_anim
from qtanimator.formats.skel import load_skel
from qtanimator.formats.skin import load_skin

ARM = Path(__file__).resolve().parents[2] / "scenes" / "arm3d"


def weighted() -> Channel:
    return Channel([Key.make(0.0, 0.2, "smooth", 1.5, out_weight=0.8), Key(1.0, 0.5, in_weight=0.05, out_weight=0.1),
                    Key(2.0, 0.2, in_weight=0.6)], "cycle", "cycle")


# ------------------------------------------------------------------------ .anim
def test_anim_writes_weighted_channels_as_added_keys_and_warns(tmp_path):
    plain = Channel([Key(0.0, 1.0), Key(1.0, 2.0)], "constant", "linear")
    clip = AnimationClip([plain, weighted()], 0.0, 2.0)
    with pytest.warns(AnimExportWarning, match=r"channel 1 has weighted tangents.*added keys") as caught:
        save_anim(clip, tmp_path / "w.anim")
    assert len(caught) == 1
    back = load_anim(tmp_path / "w.anim")
    assert back.channels[0] == plain
    written = back.channels[1]
    assert len(written.keys) > 3 and not written.is_weighted
    assert (written.pre, written.post) == ("cycle", "cycle")
    t = np.linspace(-2.0, 4.0, 3001)
    assert np.max(np.abs(written.evaluate(t) - weighted().evaluate(t))) <= 1e-6
    # What was written is what unweighted() gives; saving it again changes nothing.
    assert written == weighted().unweighted()[0]
    with warnings.catch_warnings():
        warnings.simplefilter("error", AnimExportWarning)
        assert parse_anim(format_anim(back)) == back


def test_anim_without_weights_writes_as_before():
    clip = AnimationClip([Channel([Key.make(0.0, 1.0, "flat", 0.25), Key(1.0, 2.0, "clamped", "linear")],
                                  "bounce", "cycle_offset")], 0.0, 1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", AnimExportWarning)
        text = format_anim(clip)
    assert text == ("animation {\n\trange 0 1\n\tnumchannels 1\n\tchannel 0 {\n\t\textrapolate bounce cycle_offset\n"
                    "\t\tkeys 2 {\n\t\t\t0 1 flat 0.25\n\t\t\t1 2 clamped linear\n\t\t}\n\t}\n}\n")


# ------------------------------------------------------------------------ glTF
def _arm_scene(channels: list[Channel | None]) -> tuple[object, list[str]]:
    skeleton = load_skel(ARM / "arm.skel")
    skin = load_skin(ARM / "arm.skin")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", GltfExportWarning)
        result = build_character_scene(skeleton, skin, channels, 0.0, 2.0, 30, name="arm")
    return result, [str(w.message) for w in caught if issubclass(w.category, GltfExportWarning)]


def test_gltf_samples_weighted_channels_and_names_them():
    clip = load_anim(ARM / "arm_wave.anim")
    chans: list[Channel | None] = list(clip.channels)
    plain_result, plain_messages = _arm_scene(chans)
    assert plain_messages == []
    # The root's x translation, so the sampler holds the channel's values themselves.
    chans[0] = weighted()
    result, messages = _arm_scene(chans)
    assert messages == ["arm: channel 0 (root translation x) has weighted tangents, which glTF cannot hold: "
                        "sampled at 30 fps (LINEAR)."]
    sampler = next(result.scene.animations[0].samplers[c.sampler] for c in result.scene.animations[0].channels
                   if c.path == "translation")
    offset = load_skel(ARM / "arm.skel").joints[0].offset[0]
    np.testing.assert_allclose(np.asarray(sampler.values)[:, 0] - offset, weighted().evaluate(result.times),
                               rtol=0, atol=1e-12)
    # Other channels are written as before.
    rot = [s for s, c in zip(result.scene.animations[0].samplers, result.scene.animations[0].channels)
           if c.path == "rotation"]
    rot0 = [s for s, c in zip(plain_result.scene.animations[0].samplers, plain_result.scene.animations[0].channels)
            if c.path == "rotation"]
    assert all(np.array_equal(a.values, b.values) for a, b in zip(rot, rot0))
