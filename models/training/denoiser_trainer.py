"""Train the causal latent denoiser on VQ-VAE latent sequences with aligned audio and style labels.

Batches mix paired clips (speech audio present) and motion-only clips (audio condition masked,
``audio_mask = 0``) in a fixed proportion, so the motion prior and the styles come from the large
motion-only set and the link to speech from the paired takes. The objective is D2's diffusion
forcing loss (:func:`gesturecast.models.training.denoiser_objective.training_loss`): per-frame noise levels,
clean-history prefixes, x0 prediction with a Huber loss, style dropped 10 % of the time for CFG. A clip of a
take that lacks body parts (SHOW: arms only) has those parts' latent channels zeroed and masked out of the loss.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import torch
from tqdm import tqdm

from gesturecast.models.generator.denoiser_config import DenoiserConfig, audio_frames_needed, sequence_audio
from gesturecast.models.generator.diffusion import get_schedule
from gesturecast.models.networks.denoiser_network import CausalDenoiser
from gesturecast.models.networks.style_critic import StyleCritic
from gesturecast.models.training.denoiser_objective import DenoiserTrainConfig, training_loss

logger = logging.getLogger(__name__)

WARMUP_STEPS = 200
WARMUP_FRACTION = 0.1  # short runs warm up over at most a tenth of their steps
GRAD_CLIP_NORM = 1.0
LOG_EVERY = 100


@dataclass
class LatentClip:
    latents: np.ndarray  # (N, C) normalised latents
    audio: np.ndarray | None  # (N*d, F) normalised audio features aligned with motion frame 0
    style: np.ndarray  # (S,) label embedding
    channel_mask: np.ndarray | None = None  # (C,) 1 on the latent channels of parts the take holds; None = all


AudioAugmenter = Callable[[np.ndarray, np.random.Generator], np.ndarray]  # (T, F) normalised → (T, F)


class LatentBatchSampler:
    """Random (latents, audio, audio_mask, style) windows of ``num_latents`` frames."""

    def __init__(self, clips: list[LatentClip], config: DenoiserConfig, num_latents: int, paired_fraction: float,
                 rng: np.random.Generator, augmenter: AudioAugmenter | None = None):
        usable = [clip for clip in clips if len(clip.latents) >= num_latents]
        if not usable:
            raise ValueError(f"no latent clip holds {num_latents} frames")
        self.paired = [clip for clip in usable if clip.audio is not None]
        self.motion_only = [clip for clip in usable if clip.audio is None]
        self.paired_fraction = paired_fraction if self.paired and self.motion_only else float(bool(self.paired))
        self.config = config
        self.num_latents = num_latents
        self.rng = rng
        self.augmenter = augmenter

    def _pick(self) -> LatentClip:
        pool = self.paired if self.rng.random() < self.paired_fraction else self.motion_only
        weights = np.array([len(clip.latents) - self.num_latents + 1 for clip in pool], np.float64)
        return pool[int(self.rng.choice(len(pool), p=weights / weights.sum()))]

    def _window(self, clip: LatentClip) -> tuple[np.ndarray, np.ndarray, float]:
        start = int(self.rng.integers(0, len(clip.latents) - self.num_latents + 1))
        latents = clip.latents[start : start + self.num_latents]  # (N, C)
        if clip.audio is None:
            silent = np.zeros((audio_frames_needed(self.num_latents, self.config), self.config.audio_dim), np.float32)
            return latents, silent, 0.0
        augment = None if self.augmenter is None else (lambda available: self.augmenter(available, self.rng))
        return latents, sequence_audio(clip.audio, start, self.num_latents, self.config, augment), 1.0

    def sample(self, batch_size: int) -> tuple[torch.Tensor, ...]:
        """latents (B, N, C), audio (B, N*d + δa, F), audio_mask (B,), style (B, S), latent_mask (B, C)."""
        picked = [self._pick() for _ in range(batch_size)]
        windows = [self._window(clip) for clip in picked]
        latents = torch.as_tensor(np.stack([w[0] for w in windows]), dtype=torch.float32)
        audio = torch.as_tensor(np.stack([w[1] for w in windows]), dtype=torch.float32)
        mask = torch.as_tensor([w[2] for w in windows], dtype=torch.float32)
        style = torch.as_tensor(np.stack([clip.style for clip in picked]), dtype=torch.float32)
        channels = latents.shape[-1]
        latent_mask = torch.as_tensor(np.stack([np.ones(channels, np.float32) if clip.channel_mask is None
                                                else clip.channel_mask for clip in picked]), dtype=torch.float32)
        return latents, audio, mask, style, latent_mask


def learning_rate_factor(step: int, total: int) -> float:
    """Linear warm-up, then cosine decay to 10 % (Loshchilov & Hutter 2017)."""
    warmup = max(1, min(WARMUP_STEPS, int(total * WARMUP_FRACTION)))
    if step < warmup:
        return (step + 1) / warmup
    progress = (step - warmup) / max(total - warmup, 1)
    return 0.1 + 0.9 * 0.5 * (1.0 + np.cos(np.pi * min(progress, 1.0)))


def train_denoiser(
    clips: list[LatentClip],
    config: DenoiserConfig,
    steps: int,
    batch_size: int,
    num_latents: int,
    learning_rate: float,
    paired_fraction: float,
    seed: int,
    progress: bool = True,
    augmenter: AudioAugmenter | None = None,
    critic: StyleCritic | None = None,
    objective: DenoiserTrainConfig = DenoiserTrainConfig(),  # noqa: B008 (frozen dataclass)
    style_pool: np.ndarray | None = None,
) -> tuple[CausalDenoiser, dict]:
    """Train from scratch, deterministically under ``seed``; returns (model in eval mode, metrics).

    ``augmenter`` (optional) changes every paired audio window (voice / channel augmentation); with a ``critic``,
    ``objective`` may add GestureDiffuCLIP's style loss and style swaps on speech drawn from ``style_pool`` (P, S)
    (:mod:`denoiser_objective`)."""
    torch.manual_seed(seed)
    generator = torch.Generator().manual_seed(seed)
    model = CausalDenoiser(config).train()
    sampler = LatentBatchSampler(clips, config, num_latents, paired_fraction, np.random.default_rng(seed),
                                 augmenter)
    schedule = get_schedule()
    pool = None if style_pool is None else torch.as_tensor(style_pool, dtype=torch.float32)  # (P, S)
    optimizer = torch.optim.AdamW(model.parameters(), lr=learning_rate, weight_decay=0.0)
    scheduler = torch.optim.lr_scheduler.LambdaLR(optimizer, lambda s: learning_rate_factor(s, steps))
    history, recent = [], []
    started = time.perf_counter()
    for step in tqdm(range(steps), desc="denoiser", disable=not progress):
        latents, audio, mask, style, latent_mask = sampler.sample(batch_size)
        loss = training_loss(model, latents, audio, mask, style, schedule, generator, objective,
                             latent_mask=latent_mask, critic=critic, style_pool=pool)
        optimizer.zero_grad(set_to_none=True)
        loss.backward()
        torch.nn.utils.clip_grad_norm_(model.parameters(), GRAD_CLIP_NORM)
        optimizer.step()
        scheduler.step()
        recent.append(loss.item())
        if len(recent) == LOG_EVERY or step == steps - 1:
            history.append(float(np.mean(recent)))
            logger.info("denoiser step %d: loss %.5f", step + 1, history[-1])
            recent = []
    model.eval()
    metrics = {
        "loss_history": history,
        "final_loss": history[-1] if history else None,
        "train_seconds": time.perf_counter() - started,
        "parameters": sum(p.numel() for p in model.parameters()),
    }
    return model, metrics
