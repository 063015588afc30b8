"""Training for any voice: waveform voice copies of the paired clips, the prosody front end in the bundle,
and a VQ-VAE reused from another run (`train --vq-from`)."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from gesturecast.errors import UserError
from gesturecast.models.audio.streaming import FeatureConfig
from gesturecast.models.export.bundle import export_bundle
from gesturecast.models.runtime.bundle import ModelBundle
from gesturecast.models.training.arrays import load_training_clips
from gesturecast.models.training.pipeline import run_training
from gesturecast.models.training.presets import get_preset

pytest.importorskip("librosa")
PROSODY = FeatureConfig(kind="prosody")


def test_voice_copies_repeat_the_motion_with_new_audio(tiny_model):
    cache = tiny_model[1].parent / "dataset"
    plain = load_training_clips(cache, "train", PROSODY, progress=False)
    copied = load_training_clips(cache, "train", PROSODY, progress=False, voice_copies=2, seed=1)
    paired = [clip for clip in plain if clip.audio is not None]
    assert len(copied) == len(plain) + 2 * len(paired)
    copies = [clip for clip in copied if "+voice" in clip.variant]
    original = next(clip for clip in paired if clip.variant == copies[0].variant.split("+")[0])
    np.testing.assert_array_equal(copies[0].motion, original.motion)
    assert copies[0].audio.shape == original.audio.shape
    assert not np.allclose(copies[0].audio, original.audio)
    assert all("+voice" not in clip.variant for clip in load_training_clips(cache, "val", PROSODY, progress=False,
                                                                              voice_copies=2))


def test_prosody_run_reuses_the_vqvae_and_exports_its_front_end(tiny_model, tmp_path):
    checkpoint, bundle_dir = tiny_model
    cache = bundle_dir.parent / "dataset"
    preset = get_preset("tiny", front_end="prosody", voice_copies=1)
    trained = run_training(preset, cache, tmp_path / "work", progress=False, feature_config=PROSODY,
                           vq_from=bundle_dir.parent / "work")
    reused = trained["stages"]["vqvae"]["model"]["parts"]
    for original, copy in zip(checkpoint["stages"]["vqvae"]["model"]["parts"], reused, strict=True):
        for key, value in original["state"].items():
            torch.testing.assert_close(copy["state"][key], value, rtol=0, atol=0)
    bundle = ModelBundle.load(export_bundle(trained, tmp_path / "bundle"))
    assert bundle.feature_config == PROSODY
    assert ModelBundle.load(bundle_dir).feature_config.kind == "mel"


def test_vq_from_a_folder_without_a_vqvae_is_a_user_error(tiny_model, tmp_path):
    cache = tiny_model[1].parent / "dataset"
    with pytest.raises(UserError, match="no training checkpoint"):
        run_training(get_preset("tiny"), cache, tmp_path / "work", progress=False, vq_from=tmp_path / "missing")
