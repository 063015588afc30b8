import json
import shutil

import numpy as np
import pytest
import torch

from gesturecast.cli import main
from gesturecast.errors import UserError
from gesturecast.models.audio.speaker_norm import SpeakerNormConfig
from gesturecast.models.audio.stats import FeatureStats
from gesturecast.models.audio.streaming import FeatureConfig
from gesturecast.models.dataset.sources import show_takes
from gesturecast.models.export.bundle import export_bundle
from gesturecast.models.networks.part_vqvae import load_motion_vq
from gesturecast.models.runtime.bundle import ModelBundle, Normalizer, StyleTable
from gesturecast.models.training.arrays import TrainingClip
from gesturecast.models.training.denoiser_trainer import learning_rate_factor
from gesturecast.models.training.pipeline import (
    CHECKPOINT_FILE,
    latent_clip,
    load_checkpoint,
    run_training,
    save_checkpoint,
)
from gesturecast.models.training.presets import get_preset


def finished_work_dir(tiny_model, folder):
    """A copy of the tiny run's checkpoint folder."""
    checkpoint_path = tiny_model[1].parent / "work" / CHECKPOINT_FILE
    folder.mkdir(parents=True)
    shutil.copy(checkpoint_path, folder / CHECKPOINT_FILE)
    return folder


def test_resumed_stages_are_retrained_identically_under_the_seed(tiny_model, tmp_path):
    checkpoint = tiny_model[0]
    work = finished_work_dir(tiny_model, tmp_path / "work")
    partial = load_checkpoint(work / CHECKPOINT_FILE)
    del partial["stages"]["denoiser"], partial["stages"]["motion_prompt"]
    save_checkpoint(partial, work / CHECKPOINT_FILE)
    cache = tiny_model[1].parent / "dataset"
    resumed = run_training(get_preset("tiny"), cache, work, resume=True, progress=False)
    for stage in ("denoiser", "motion_prompt"):
        retrained = resumed["stages"][stage]["state"]
        for key, value in checkpoint["stages"][stage]["state"].items():
            torch.testing.assert_close(retrained[key], value, rtol=0, atol=0)
    assert resumed["stages"]["denoiser"]["metrics"]["final_loss"] == checkpoint["stages"]["denoiser"]["metrics"][
        "final_loss"]


def test_resume_refuses_other_settings_and_export_refuses_unfinished_runs(tiny_model, tmp_path):
    work = finished_work_dir(tiny_model, tmp_path / "work")
    with pytest.raises(UserError, match="other settings"):
        run_training(get_preset("tiny", seed=99), tmp_path / "unused", work, resume=True, progress=False)
    speaker_normalised = FeatureConfig(speaker_norm=SpeakerNormConfig(enabled=True))
    with pytest.raises(UserError, match="other settings"):
        run_training(get_preset("tiny"), tmp_path / "unused", work, resume=True, progress=False,
                     feature_config=speaker_normalised)
    partial = load_checkpoint(work / CHECKPOINT_FILE)
    del partial["stages"]["motion_prompt"]
    with pytest.raises(UserError, match="missing motion_prompt"):
        export_bundle(partial, tmp_path / "bundle")


def test_train_and_export_commands(tiny_model, tmp_path, capsys):
    work = finished_work_dir(tiny_model, tmp_path / "work")
    cache = tiny_model[1].parent / "dataset"
    args = ["train", "--preset", "tiny", "--data", str(cache), "--work-dir", str(work), "--resume", "--no-progress",
            "--out", str(tmp_path / "trained")]
    assert main(args) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["preset"] == "tiny" and summary["parameters"]["vqvae"] > 0
    assert main(["export", str(work), "-o", str(tmp_path / "exported")]) == 0
    exported, trained = ModelBundle.load(tmp_path / "exported"), ModelBundle.load(tmp_path / "trained")
    np.testing.assert_array_equal(exported.latent_stats.mean, trained.latent_stats.mean)
    assert main(["export", str(tmp_path / "nothing"), "-o", str(tmp_path / "x")]) == 2
    assert "no training checkpoint" in capsys.readouterr().err


def test_unknown_preset_is_a_user_error():
    with pytest.raises(UserError, match="known presets: tiny, default"):
        get_preset("huge")


def test_learning_rate_warms_up_then_decays_to_a_tenth():
    factors = [learning_rate_factor(step, 1000) for step in range(1000)]
    assert factors[0] < factors[50] < factors[99] == pytest.approx(1.0)
    assert factors[-1] == pytest.approx(0.1, abs=1e-4) and max(factors) <= 1.0


def test_arms_only_takes_train_the_arms_and_leave_statistics_and_the_other_parts_alone(tiny_model, tmp_path,
                                                                                     shared_data):
    from train_fixtures import build_tiny_cache

    show = tuple(t for t in show_takes(shared_data / "show") if t.name.startswith("unknown_116213"))
    cache = build_tiny_cache(tmp_path, shared_data / "zeggs", show)
    without = run_training(get_preset("tiny"), cache, tmp_path / "without", progress=False)
    assert without["stages"]["data"]["summary"] == tiny_model[0]["stages"]["data"]["summary"]  # left out by default
    checkpoint = run_training(get_preset("tiny", partial_takes=True), cache, tmp_path / "work", progress=False)
    stages, base = checkpoint["stages"], tiny_model[0]["stages"]
    assert stages["data"]["motion_stats"] == base["data"]["motion_stats"]  # statistics of full-body motion only
    parts, base_parts = stages["vqvae"]["metrics"]["parts"], base["vqvae"]["metrics"]["parts"]
    assert parts["arms"]["train_clips"] == base_parts["arms"]["train_clips"] + 2  # the SHOW take and its mirror
    assert parts["torso"]["train_clips"] == base_parts["torso"]["train_clips"]
    assert parts["legs"]["train_clips"] == base_parts["legs"]["train_clips"]
    model = load_motion_vq(stages["vqvae"]["model"])
    channels = model.config.latent_slices()
    latents = np.random.default_rng(0).normal(size=(3, model.config.latent_dim)).astype(np.float32)
    clip = TrainingClip("x", "show", "neutral", "orig", np.zeros((12, 136), np.float32), None, parts=("arms",))
    unit = Normalizer(np.zeros(model.config.latent_dim), np.ones(model.config.latent_dim))
    styles = StyleTable.from_dict(stages["data"]["styles"])
    made = latent_clip(clip, latents, model, unit, FeatureStats.from_dict(stages["data"]["audio_stats"]), styles)
    assert np.array_equal(made.latents[:, channels["arms"]], latents[:, channels["arms"]])
    assert not made.latents[:, channels["legs"]].any() and not made.latents[:, channels["torso"]].any()
    assert made.channel_mask[channels["arms"]].all() and not made.channel_mask[channels["legs"]].any()


def test_speaker_normalisation_is_the_default_presets_and_the_flag_reaches_the_features(tiny_model, tmp_path, capsys):
    assert get_preset("default").speaker_norm and not get_preset("default", speaker_norm=False).speaker_norm
    work = finished_work_dir(tiny_model, tmp_path / "work")  # trained on absolute features
    cache = tiny_model[1].parent / "dataset"
    args = ["train", "--preset", "tiny", "--data", str(cache), "--work-dir", str(work), "--resume", "--no-progress"]
    assert main([*args, "--speaker-norm"]) == 2  # resuming with other features is refused
    assert "speaker_norm" in capsys.readouterr().err
