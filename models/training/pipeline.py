"""The `gesturecast train` pipeline: dataset cache → VQ-VAE → latents → denoiser → motion prompt.

Stages (each saved to the checkpoint when done, so ``resume`` skips finished stages):

1. ``data``: motion-feature normalisation statistics (full-body train takes) and audio-feature ones
   (every paired train take), the style vocabulary's wordllama embeddings (prompt "a person gesturing
   in a {label} way");
2. ``vqvae``: one motion VQ-VAE per body part on the train motion that holds that part (mirrored;
   paired takes also speed-augmented), with held-out reconstruction error (feature space, cm,
   degrees; full-body takes) and codebook usage;
3. ``denoiser``: latents of every clip (normalised by ``latent_stats`` of the full-body clips; the
   channels of parts a take lacks zeroed and masked out of the loss), then the causal denoiser with
   diffusion forcing on latent sequences + aligned audio windows (masked for motion-only takes) +
   label style embeddings (dropped 10 % for CFG);
4. ``motion_prompt``: the contrastive motion → style-embedding encoder.

The checkpoint (``checkpoint.pt``) holds plain data only — config dicts, statistics, state dicts —
and is read back with ``torch.load(weights_only=True)``: nothing is unpickled as code.
Everything is deterministic under the preset's seed (torch.manual_seed, numpy Generators).
"""

from __future__ import annotations

import logging
import os
import platform
import subprocess
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import torch

from gesturecast.errors import UserError
from gesturecast.models.audio.stats import FeatureStats
from gesturecast.models.audio.streaming import FeatureConfig
from gesturecast.models.generator.denoiser_config import DenoiserConfig
from gesturecast.models.generator.style_text import PROMPT_TEMPLATE, StyleTextEmbedder, vocabulary_embeddings
from gesturecast.models.motion.body_parts import PART_NAMES, BodyPart, body_parts, holds_every_part
from gesturecast.models.networks.motion_prompt import (
    MotionPromptConfig,
    MotionPromptEncoder,
    PromptTrainConfig,
    train_motion_prompt,
)
from gesturecast.models.networks.part_vqvae import (
    PartVQVAE,
    PartVQVAEConfig,
    load_motion_vq,
    motion_vq_checkpoint,
    part_channel_masks,
)
from gesturecast.models.networks.style_critic import StyleCritic
from gesturecast.models.networks.vqvae import VQVAEConfig
from gesturecast.models.runtime.bundle import Normalizer, StyleTable
from gesturecast.models.training.arrays import TrainingClip, dataset_summary, load_training_clips
from gesturecast.models.training.audio_augment import AudioAugmentConfig, FeatureAugmenter
from gesturecast.models.training.denoiser_objective import DenoiserTrainConfig
from gesturecast.models.training.denoiser_trainer import LatentClip, train_denoiser
from gesturecast.models.training.presets import TrainPreset
from gesturecast.models.training.reconstruction import joint_errors
from gesturecast.models.training.vqvae import VQTrainConfig, reconstruct, train_vqvae

logger = logging.getLogger(__name__)

CHECKPOINT_FORMAT_VERSION = 2  # 2: one VQ-VAE per body part
CHECKPOINT_FILE = "checkpoint.pt"
MOTION_STD_FLOOR = 1e-2  # near-constant rotation channels are not amplified into noise
STAGES = ("data", "vqvae", "motion_prompt", "denoiser")  # each stage seeds itself: the order changes no result
MAX_EVAL_CLIPS = 40  # held-out clips decoded for joint-space errors


@dataclass
class TrainInputs:
    """The loaded clips and the statistics every stage shares."""

    train: list[TrainingClip]
    val: list[TrainingClip]
    feature_config: FeatureConfig

    @property
    def motion_train(self) -> list[TrainingClip]:
        """The train clips without voice copies: every motion once (statistics, VQ-VAE, motion prompt)."""
        return [clip for clip in self.train if not clip.voice_copy]

    @property
    def full_body_train(self) -> list[TrainingClip]:
        """The motion of takes that hold every body part (statistics, the motion prompt)."""
        return [clip for clip in self.motion_train if clip.full_body]


def save_checkpoint(checkpoint: dict, path: Path) -> None:
    """Atomic write (temporary file renamed into place)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    staging = path.with_suffix(".tmp")
    torch.save(checkpoint, staging)
    os.replace(staging, path)


def load_checkpoint(path: Path) -> dict:
    """A training checkpoint (plain data only); other format versions raise UserError."""
    if not Path(path).is_file():
        raise UserError(f"no training checkpoint at {path}")
    checkpoint = torch.load(path, map_location="cpu", weights_only=True)
    if checkpoint.get("format_version") != CHECKPOINT_FORMAT_VERSION:
        raise UserError(f"{path} has checkpoint format {checkpoint.get('format_version')!r}, "
                        f"expected {CHECKPOINT_FORMAT_VERSION}; retrain")
    return checkpoint


def git_commit() -> str:
    try:
        result = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True, check=True,
                                cwd=Path(__file__).resolve().parent)
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return result.stdout.strip()


def hardware_summary() -> dict:
    return {"machine": platform.machine(), "processor": platform.processor() or platform.machine(),
            "cpu_count": os.cpu_count(), "torch_threads": torch.get_num_threads(), "device": "cpu"}


def data_stage(inputs: TrainInputs) -> dict:
    motion_stats = Normalizer.fit([clip.motion for clip in inputs.full_body_train], MOTION_STD_FLOOR)
    paired = [clip.audio for clip in inputs.motion_train if clip.audio is not None]  # the speakers' own voices
    if not paired:
        raise UserError("the training split holds no take with speech audio; the model needs paired data")
    audio_stats = FeatureStats.fit(paired, inputs.feature_config)
    labels, embeddings = vocabulary_embeddings(StyleTextEmbedder())
    trained = tuple(sorted({clip.style for clip in inputs.train}))
    table = StyleTable(labels, embeddings, trained, PROMPT_TEMPLATE)
    return {"motion_stats": motion_stats.to_dict(), "audio_stats": audio_stats.to_dict(),
            "styles": table.to_dict(), "summary": dataset_summary(inputs.motion_train, inputs.feature_config.fps)}


def part_vq_config(preset: TrainPreset) -> PartVQVAEConfig:
    """One VQ-VAE config per body part, sized by the preset (same d, codebook size and depth for all)."""
    vq = preset.vq
    configs = tuple(
        VQVAEConfig(feature_dim=part.feature_dim, hidden_dim=hidden, latent_dim=latent, downsample=vq.downsample,
                    res_blocks_per_stage=vq.res_blocks_per_stage, codebook_size=vq.codebook_size)
        for part, hidden, latent in zip(body_parts(), vq.hidden_dims, vq.latent_dims, strict=True)
    )
    return PartVQVAEConfig(PART_NAMES, configs)


def vq_joint_errors(model: PartVQVAE, clips: list[np.ndarray], motion_stats: Normalizer,
                    joints: tuple[str, ...] | None = None) -> dict[str, float]:
    """Mean held-out joint errors (cm, degrees) over up to MAX_EVAL_CLIPS clips (of ``joints`` when given)."""
    errors = []
    for clip in clips[:MAX_EVAL_CLIPS]:
        reconstruction, _ = reconstruct(model, clip)  # (T', D)
        errors.append(joint_errors(motion_stats.denormalize(clip[: len(reconstruction)]),
                                   motion_stats.denormalize(reconstruction), joints))
    return {key: float(np.mean([e[key] for e in errors])) for key in errors[0]} if errors else {}


def normalized_motion(clips: list[TrainingClip], motion_stats: Normalizer) -> list[tuple[tuple[str, ...], np.ndarray]]:
    """(parts the take holds, normalised features (T, D)) of every clip."""
    return [(clip.parts, motion_stats.normalize(clip.motion)) for clip in clips]


def part_columns(motions: list[tuple[tuple[str, ...], np.ndarray]], part: BodyPart) -> list[np.ndarray]:
    """The feature columns of ``part`` of every normalised clip whose take holds that part."""
    return [motion[:, list(part.columns)] for parts, motion in motions if part.name in parts]


def vqvae_stage(inputs: TrainInputs, preset: TrainPreset, motion_stats: Normalizer, progress: bool) -> dict:
    """One VQ-VAE per body part on that part's feature columns of the takes that hold it; held-out errors for
    the whole body (full-body takes) and per part."""
    train_motion = normalized_motion(inputs.motion_train, motion_stats)
    val_motion = normalized_motion([clip for clip in inputs.val if clip.num_frames >= preset.vq.downsample],
                                   motion_stats)
    config = part_vq_config(preset)
    train_config = VQTrainConfig(window=preset.vq.window, batch_size=preset.vq.batch_size)
    models, part_metrics = [], {}
    for part, part_config in zip(body_parts(config.parts), config.part_configs, strict=True):
        train = part_columns(train_motion, part)
        part_model, metrics = train_vqvae(train, part_config, preset.vq.steps, preset.seed, progress,
                                          part_columns(val_motion, part) or None, train_config)
        models.append(part_model)
        part_metrics[part.name] = {**metrics, "train_clips": len(train)}
    model = PartVQVAE(config, models)
    val = [motion for parts, motion in val_motion if holds_every_part(parts)]
    metrics = {
        "parts": part_metrics,
        "parameters": sum(m["parameters"] for m in part_metrics.values()),
        "final_losses": {name: m["final_losses"] for name, m in part_metrics.items()},
        "val": {name: m["val"] for name, m in part_metrics.items() if "val" in m},
        "val_joint_errors": vq_joint_errors(model, val, motion_stats),
        "val_part_joint_errors": {part.name: vq_joint_errors(model, val, motion_stats, part.joints)
                                  for part in model.parts},
    }
    return {"model": motion_vq_checkpoint(model), "metrics": metrics}


def encode_latents(model: PartVQVAE, motion: np.ndarray) -> np.ndarray:
    """(T, D) normalised features → (T // d, C) quantized latents (the parts' stacked)."""
    d = model.config.downsample
    usable = len(motion) - len(motion) % d
    with torch.no_grad():
        encoding = model.encode(torch.as_tensor(motion[None, :usable], dtype=torch.float32))
    return encoding.quantized[0].numpy()


def channel_mask(model: PartVQVAE, parts: tuple[str, ...]) -> np.ndarray:
    """(C,) 1 on the stacked latent's channels of ``parts``, 0 on the others."""
    masks = part_channel_masks(model.config.latent_slices(), model.config.latent_dim)
    return np.clip(np.sum([masks[name] for name in parts], axis=0), 0.0, 1.0).astype(np.float32)


def latent_clip(clip: TrainingClip, latents: np.ndarray, model: PartVQVAE, latent_stats: Normalizer,
                audio_stats: FeatureStats, styles: StyleTable) -> LatentClip:
    """A denoiser clip; a take lacking parts gets their channels zeroed (placeholders, never targets) and masked."""
    audio = None if clip.audio is None else audio_stats.apply(clip.audio)
    normalized = latent_stats.normalize(latents)  # (N, C)
    if clip.full_body:
        return LatentClip(normalized, audio, styles.embedding(clip.style))
    mask = channel_mask(model, clip.parts)  # (C,)
    return LatentClip((normalized * mask).astype(np.float32), audio, styles.embedding(clip.style), mask)


def latent_clips(inputs: TrainInputs, model: PartVQVAE, stats: dict, styles: StyleTable) -> tuple[list, Normalizer]:
    motion_stats = Normalizer.from_dict(stats["motion_stats"])
    audio_stats = FeatureStats.from_dict(stats["audio_stats"])
    encoded = [encode_latents(model, motion_stats.normalize(clip.motion)) for clip in inputs.train]
    encoded_clips = [(clip, latents) for clip, latents in zip(inputs.train, encoded, strict=True) if len(latents)]
    latent_stats = Normalizer.fit([latents for clip, latents in encoded_clips if clip.full_body])
    clips = [latent_clip(clip, latents, model, latent_stats, audio_stats, styles) for clip, latents in encoded_clips]
    return clips, latent_stats


def denoiser_config(preset: TrainPreset, latent_dim: int, audio_dim: int, style_dim: int) -> DenoiserConfig:
    den = preset.denoiser
    return DenoiserConfig(latent_dim=latent_dim, audio_dim=audio_dim, style_dim=style_dim, width=den.width,
                          num_layers=den.num_layers, num_heads=den.num_heads, window=den.window,
                          frames_per_latent=preset.vq.downsample, audio_lookahead=preset.audio_lookahead,
                          audio_window=den.audio_window, lookahead_truncation=preset.lookahead_truncation)


def denoiser_stage(inputs: TrainInputs, preset: TrainPreset, checkpoint: dict, progress: bool) -> dict:
    stages = checkpoint["stages"]
    model = load_motion_vq(stages["vqvae"]["model"])
    styles = StyleTable.from_dict(stages["data"]["styles"])
    clips, latent_stats = latent_clips(inputs, model, stages["data"], styles)
    config = denoiser_config(preset, model.config.latent_dim, inputs.feature_config.num_features,
                             styles.embeddings.shape[1])
    den = preset.denoiser
    augmenter = None
    if preset.audio_augmentation:
        audio_stats = FeatureStats.from_dict(stages["data"]["audio_stats"])
        augmenter = FeatureAugmenter(AudioAugmentConfig(), audio_stats, inputs.feature_config)
    objective = DenoiserTrainConfig(style_loss_weight=preset.style_loss_weight, style_swap_prob=preset.style_swap_prob,
                                    style_swap_weight=preset.style_swap_weight,
                                    swap_channels=swap_channels(model, preset.style_swap_parts))
    styled = objective.style_loss_weight or objective.style_swap_prob
    critic = style_critic(model, stages, latent_stats) if styled else None
    denoiser, metrics = train_denoiser(clips, config, den.steps, den.batch_size, den.sequence_latents,
                                       den.learning_rate, den.paired_fraction, preset.seed, progress, augmenter,
                                       critic, objective, styles.embeddings)
    return {"config": config.to_dict(), "state": denoiser.state_dict(), "latent_stats": latent_stats.to_dict(),
            "metrics": metrics}


def swap_channels(model: PartVQVAE, parts: tuple[str, ...]) -> tuple[float, ...]:
    """(C,) 1 on the latent channels of the parts a style swap restyles; () for all of them."""
    return tuple(float(value) for value in channel_mask(model, parts)) if parts else ()


def style_critic(model: PartVQVAE, stages: dict, latent_stats: Normalizer) -> StyleCritic:
    """The style loss's frozen critic: this run's VQ-VAE decoder and motion-prompt encoder."""
    prompt = stages["motion_prompt"]
    encoder = MotionPromptEncoder(MotionPromptConfig(**prompt["config"]))
    encoder.load_state_dict(prompt["state"])
    motion_stats = Normalizer.from_dict(stages["data"]["motion_stats"])
    return StyleCritic(model, encoder, (latent_stats.mean, latent_stats.std), (motion_stats.mean, motion_stats.std))


def prompt_stage(inputs: TrainInputs, preset: TrainPreset, checkpoint: dict) -> dict:
    styles = StyleTable.from_dict(checkpoint["stages"]["data"]["styles"])
    usable = [clip for clip in inputs.full_body_train if clip.num_frames >= preset.prompt.clip_frames]
    config = MotionPromptConfig(feature_dim=usable[0].motion.shape[1], width=preset.prompt.width,
                                embed_dim=styles.embeddings.shape[1])
    train_config = PromptTrainConfig(clip_frames=preset.prompt.clip_frames, batch_size=preset.prompt.batch_size,
                                     steps=preset.prompt.steps, seed=preset.seed)
    torch.manual_seed(preset.seed)
    encoder = MotionPromptEncoder(config)
    started = time.perf_counter()
    losses = train_motion_prompt(encoder, [clip.motion for clip in usable],
                                 [styles.labels.index(clip.style) for clip in usable], styles.embeddings, train_config)
    metrics = {"final_loss": float(np.mean(losses[-20:])), "train_seconds": time.perf_counter() - started,
               "parameters": sum(p.numel() for p in encoder.parameters())}
    return {"config": asdict(config), "state": encoder.state_dict(), "metrics": metrics}


def new_checkpoint(preset: TrainPreset, feature_config: FeatureConfig) -> dict:
    return {"format_version": CHECKPOINT_FORMAT_VERSION, "preset": preset.to_dict(),
            "feature_config": feature_config.to_dict(), "stages": {}, "stage_seconds": {}}


def same_training_settings(stored: dict, wanted: dict) -> bool:
    """Equal presets up to settings that do not change the result (thread count)."""
    return {**stored, "threads": None} == {**wanted, "threads": None}


def open_checkpoint(path: Path, preset: TrainPreset, feature_config: FeatureConfig, resume: bool) -> dict:
    if not resume or not path.is_file():
        return new_checkpoint(preset, feature_config)
    checkpoint = load_checkpoint(path)
    same_features = FeatureConfig.from_dict(checkpoint["feature_config"]) == feature_config
    if not (same_features and same_training_settings(checkpoint["preset"], preset.to_dict())):
        raise UserError(f"{path} was trained with other settings; drop --resume or use another --work-dir")
    logger.info("resuming: stages done %s", list(checkpoint["stages"]))
    return checkpoint


def reuse_vqvae(checkpoint: dict, vq_from: Path) -> None:
    """Take the finished VQ-VAE stage of another run trained on the same motion (same motion statistics)."""
    other = load_checkpoint(vq_from / CHECKPOINT_FILE)
    if "vqvae" not in other["stages"]:
        raise UserError(f"{vq_from} has no finished VQ-VAE stage to reuse")
    if other["stages"]["data"]["motion_stats"] != checkpoint["stages"]["data"]["motion_stats"]:
        raise UserError(f"{vq_from} was trained on other motion (its motion statistics differ)")
    checkpoint["stages"]["vqvae"] = other["stages"]["vqvae"]
    checkpoint["stage_seconds"]["vqvae"] = 0.0
    checkpoint["vq_from"] = str(vq_from)
    logger.info("VQ-VAE reused from %s", vq_from)


def run_training(preset: TrainPreset, cache_dir: Path, work_dir: Path, resume: bool = False,
                 progress: bool = True, feature_config: FeatureConfig | None = None,
                 vq_from: Path | None = None) -> dict:
    """Run every unfinished stage, saving ``work_dir/checkpoint.pt`` after each; returns the checkpoint.

    ``feature_config``: the audio features the model listens to (default ``FeatureConfig()``); it is stored in
    the checkpoint and the bundle, so the live runtime computes the same features. ``vq_from``: a work folder
    whose VQ-VAE stage is reused instead of training one (the representation study trains it once)."""
    torch.set_num_threads(preset.threads)
    feature_config = feature_config or FeatureConfig()
    path = work_dir / CHECKPOINT_FILE
    checkpoint = open_checkpoint(path, preset, feature_config, resume)
    started = time.perf_counter()
    kwargs = {"mirror_motion_only": preset.mirror_motion_only, "paired_speeds": preset.paired_speeds,
              "progress": progress, "partial_takes": preset.partial_takes,
              "paired_style": preset.paired_style}
    inputs = TrainInputs(load_training_clips(cache_dir, "train", feature_config, **kwargs,
                                             voice_copies=preset.voice_copies, seed=preset.seed,
                                             respoken_copies=preset.respoken_copies),
                         load_training_clips(cache_dir, "val", feature_config, **kwargs), feature_config)
    checkpoint["stage_seconds"]["load"] = time.perf_counter() - started
    stage_functions = {
        "data": lambda: data_stage(inputs),
        "vqvae": lambda: vqvae_stage(inputs, preset, Normalizer.from_dict(checkpoint["stages"]["data"]["motion_stats"]),
                                     progress),
        "denoiser": lambda: denoiser_stage(inputs, preset, checkpoint, progress),
        "motion_prompt": lambda: prompt_stage(inputs, preset, checkpoint),
    }
    for stage in STAGES:
        if stage in checkpoint["stages"]:
            continue
        stage_started = time.perf_counter()
        checkpoint["stages"][stage] = stage_functions[stage]()
        checkpoint["stage_seconds"][stage] = time.perf_counter() - stage_started
        if stage == "data" and vq_from is not None:
            reuse_vqvae(checkpoint, vq_from)
        save_checkpoint(checkpoint, path)
        logger.info("stage %s done in %.1f s", stage, checkpoint["stage_seconds"][stage])
    checkpoint["summary"] = {"git_commit": git_commit(), "hardware": hardware_summary(),
                             "total_seconds": sum(checkpoint["stage_seconds"].values())}
    save_checkpoint(checkpoint, path)
    return checkpoint
