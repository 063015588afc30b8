"""Held-out denoising error of a trained causal denoiser (training checkpoint), with and without audio.

On the test segments of the paired takes (never trained on): every window of ``num_latents``
latent frames (stride ``stride``) is noised exactly as in training with clean-history prefixes
(the autoregressive inference configuration: ``clean_history_prob = 1``) and the label style
always present; the error is the x0 Huber loss of :func:`denoiser_training.training_loss` averaged
over ``draws`` fixed noise draws. The same draws are scored with the audio condition masked, so
``audio_gain = error_without_audio − error_with_audio`` says how much the speech helps predict the
held-out motion (> 0: the model uses the audio). A stricter control scores the same draws with
the audio of another moment of the same take (each take's windows rolled by half their count, so
speaker and room stay the same): ``match_gain = error_mismatched_audio − error_with_audio`` > 0
means the model uses *this* speech, not just the presence or the voice of the speaker.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch

from gesturecast.models.audio.stats import FeatureStats
from gesturecast.models.audio.streaming import FeatureConfig
from gesturecast.models.generator.denoiser_config import DenoiserConfig, sequence_audio
from gesturecast.models.generator.diffusion import get_schedule
from gesturecast.models.networks.denoiser_network import CausalDenoiser
from gesturecast.models.networks.part_vqvae import load_motion_vq
from gesturecast.models.runtime.bundle import Normalizer, StyleTable
from gesturecast.models.training.arrays import load_training_clips
from gesturecast.models.training.denoiser_objective import DenoiserTrainConfig, training_loss
from gesturecast.models.training.pipeline import encode_latents

AUTOREGRESSIVE = DenoiserTrainConfig(style_drop_prob=0.0, clean_history_prob=1.0)


@dataclass(frozen=True)
class HeldOutConfig:
    num_latents: int = 16
    stride: int = 4
    draws: int = 32
    seed: int = 0
    split: str = "test"


def held_out_windows(checkpoint: dict, cache_dir: Path, config: HeldOutConfig) -> tuple[torch.Tensor, ...]:
    """latents (B, N, C), audio (B, N*d + δa, F), style (B, S), take index (B,) of every held-out paired window."""
    stages = checkpoint["stages"]
    feature_config = FeatureConfig.from_dict(checkpoint["feature_config"])
    den_config = DenoiserConfig.from_dict(stages["denoiser"]["config"])
    vq = load_motion_vq(stages["vqvae"]["model"])
    motion_stats = Normalizer.from_dict(stages["data"]["motion_stats"])
    latent_stats = Normalizer.from_dict(stages["denoiser"]["latent_stats"])
    audio_stats = FeatureStats.from_dict(stages["data"]["audio_stats"])
    styles = StyleTable.from_dict(stages["data"]["styles"])
    clips = load_training_clips(cache_dir, config.split, feature_config, progress=False)
    clips = [clip for clip in clips if clip.audio is not None]
    latents, audio, style, take = [], [], [], []
    for index, clip in enumerate(clips):
        clip_latents = latent_stats.normalize(encode_latents(vq, motion_stats.normalize(clip.motion)))  # (L, C)
        clip_audio = audio_stats.apply(clip.audio)  # (T, F)
        for start in range(0, len(clip_latents) - config.num_latents + 1, config.stride):
            latents.append(clip_latents[start : start + config.num_latents])
            audio.append(sequence_audio(clip_audio, start, config.num_latents, den_config))  # (N*d + δa, F)
            style.append(styles.embedding(clip.style))
            take.append(index)
    if not latents:
        raise ValueError(f"no held-out paired window of {config.num_latents} latents in {cache_dir}")
    tensors = tuple(torch.as_tensor(np.stack(values), dtype=torch.float32) for values in (latents, audio, style))
    return (*tensors, torch.as_tensor(take))


def same_take_mismatch(audio: torch.Tensor, take: torch.Tensor) -> torch.Tensor:
    """audio (B, A, F) with each take's windows rolled by half their count (another moment, same speaker)."""
    mismatched = audio.clone()
    for index in torch.unique(take):
        rows = torch.nonzero(take == index).flatten()  # (n,)
        mismatched[rows] = audio[torch.roll(rows, len(rows) // 2)]
    return mismatched


def held_out_denoising_error(checkpoint: dict, cache_dir: Path, config: HeldOutConfig | None = None) -> dict:
    """Errors with / without / with mismatched audio, the two gains and the window count (held-out paired)."""
    config = config or HeldOutConfig()
    den = checkpoint["stages"]["denoiser"]
    model = CausalDenoiser(DenoiserConfig.from_dict(den["config"]))
    model.load_state_dict(den["state"])
    model.eval()
    latents, audio, style, take = held_out_windows(checkpoint, cache_dir, config)
    schedule = get_schedule()
    mismatched = same_take_mismatch(audio, take)  # (B, A, F)
    conditions = {"with_audio": (audio, 1.0), "without_audio": (audio, 0.0), "mismatched_audio": (mismatched, 1.0)}
    errors: dict[str, list[float]] = {key: [] for key in conditions}
    with torch.no_grad():
        for draw in range(config.draws):
            for key, (windows, mask) in conditions.items():
                generator = torch.Generator().manual_seed(config.seed + draw)  # the same noise for every condition
                present = torch.full((len(latents),), mask)  # (B,)
                errors[key].append(training_loss(model, latents, windows, present, style, schedule, generator,
                                                 AUTOREGRESSIVE).item())
    result = {key: float(np.mean(values)) for key, values in errors.items()}
    return {**result, "audio_gain": result["without_audio"] - result["with_audio"],
            "match_gain": result["mismatched_audio"] - result["with_audio"], "windows": len(latents)}
