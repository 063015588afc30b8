"""Train the motion VQ-VAE on a list of normalized motion-feature clips (T, D) — dataset-agnostic.

The caller (the training pipeline) loads, mirrors and normalizes the clips; this module samples
random windows, optimizes :meth:`MotionVQVAE.loss` with AdamW, and reports held-out reconstruction
error in feature space plus codebook usage. Joint-space errors (cm, degrees) need the feature
decoding of ``motion_features`` and are computed by the caller from :func:`reconstruct`.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass

import numpy as np
import torch
from tqdm import tqdm

from gesturecast.models.networks.quantizer import codebook_usage
from gesturecast.models.networks.vqvae import MotionVQVAE, VQVAEConfig

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class VQTrainConfig:
    window: int = 64  # motion frames per training window (a multiple of the downsampling)
    batch_size: int = 32
    learning_rate: float = 2e-4
    weight_decay: float = 0.0
    warmup_steps: int = 100  # linear learning-rate warm-up
    grad_clip_norm: float = 1.0
    log_every: int = 50  # steps per entry of the loss history


class WindowSampler:
    """Random fixed-length windows, clips chosen in proportion to how many windows they hold."""

    def __init__(self, clips: list[np.ndarray], window: int, rng: np.random.Generator):
        self.clips = [np.asarray(c, dtype=np.float32) for c in clips if len(c) >= window]
        if not self.clips:
            raise ValueError(f"no clip is at least {window} frames long")
        starts = np.array([len(c) - window + 1 for c in self.clips], dtype=np.float64)
        self.clip_probabilities = starts / starts.sum()
        self.window = window
        self.rng = rng

    def sample(self, batch_size: int) -> np.ndarray:
        """(B, window, D) float32."""
        chosen = self.rng.choice(len(self.clips), size=batch_size, p=self.clip_probabilities)
        windows = []
        for index in chosen:
            clip = self.clips[index]
            start = int(self.rng.integers(0, len(clip) - self.window + 1))
            windows.append(clip[start : start + self.window])
        return np.stack(windows)


def _warmup_factor(step: int, warmup_steps: int) -> float:
    return min(1.0, (step + 1) / max(warmup_steps, 1))


def reconstruct(model: MotionVQVAE, clip: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Reconstruction (T', D) and codes (T'/d,) of one clip cropped to a multiple of d frames."""
    usable = len(clip) - len(clip) % model.config.downsample
    x = torch.as_tensor(np.asarray(clip[:usable], dtype=np.float32)).unsqueeze(0)  # (1, T', D)
    model.eval()
    with torch.no_grad():
        reconstruction, encoding = model(x)
    return reconstruction[0].numpy(), encoding.codes[0].numpy()


def evaluate_reconstruction(model: MotionVQVAE, clips: list[np.ndarray]) -> dict[str, float]:
    """Feature-space mean absolute and RMS error over whole clips, and codebook usage."""
    abs_sum, sq_sum, count, all_codes = 0.0, 0.0, 0, []
    for clip in clips:
        reconstruction, codes = reconstruct(model, clip)
        error = reconstruction - np.asarray(clip[: len(reconstruction)], dtype=np.float32)  # (T', D)
        abs_sum += float(np.abs(error).sum())
        sq_sum += float(np.square(error).sum())
        count += error.size
        all_codes.append(codes)
    if count == 0:
        raise ValueError("no clip is long enough to evaluate")
    usage = codebook_usage(np.concatenate(all_codes), model.config.codebook_size)
    return {"feature_mae": abs_sum / count, "feature_rmse": float(np.sqrt(sq_sum / count)), **usage}


def train_vqvae(
    clips: list[np.ndarray],
    config: VQVAEConfig,
    steps: int,
    seed: int,
    progress: bool = True,
    val_clips: list[np.ndarray] | None = None,
    train_config: VQTrainConfig | None = None,
) -> tuple[MotionVQVAE, dict]:
    """Train a VQ-VAE from scratch, deterministically under ``seed``; returns (model in eval mode, metrics).

    metrics: ``loss_history`` (mean total loss per ``log_every`` steps), ``final_losses`` (last step's
    parts), ``train_seconds``, ``parameters``, and ``val`` (:func:`evaluate_reconstruction`) when
    ``val_clips`` are given, else ``train_usage`` (codebook usage over the training clips).
    """
    train_config = train_config or VQTrainConfig()
    if train_config.window % config.downsample:
        raise ValueError(f"window {train_config.window} is not a multiple of downsample {config.downsample}")
    torch.manual_seed(seed)
    model = MotionVQVAE(config).train()
    sampler = WindowSampler(clips, train_config.window, np.random.default_rng(seed))
    optimizer = torch.optim.AdamW(
        model.parameters(), lr=train_config.learning_rate, weight_decay=train_config.weight_decay
    )
    scheduler = torch.optim.lr_scheduler.LambdaLR(optimizer, lambda s: _warmup_factor(s, train_config.warmup_steps))
    history, window_losses, parts = [], [], {}
    started = time.perf_counter()
    for step in tqdm(range(steps), desc="vq-vae", disable=not progress):
        batch = torch.from_numpy(sampler.sample(train_config.batch_size))  # (B, W, D)
        loss, parts = model.loss(batch)
        optimizer.zero_grad(set_to_none=True)
        loss.backward()
        torch.nn.utils.clip_grad_norm_(model.parameters(), train_config.grad_clip_norm)
        optimizer.step()
        scheduler.step()
        window_losses.append(loss.item())
        if len(window_losses) == train_config.log_every or step == steps - 1:
            history.append(float(np.mean(window_losses)))
            logger.info("vq-vae step %d: loss %.5f %s", step + 1, history[-1], parts)
            window_losses = []
    model.eval()
    metrics = {
        "loss_history": history,
        "final_losses": parts,
        "train_seconds": time.perf_counter() - started,
        "parameters": sum(p.numel() for p in model.parameters()),
    }
    if val_clips:
        metrics["val"] = evaluate_reconstruction(model, val_clips)
    else:
        metrics["train_usage"] = evaluate_reconstruction(model, clips)
    return model, metrics
