"""Motion-prompt encoder: a canonical-motion clip (T, D) → a unit style vector in the text space.

GestureDiffuCLIP §4.1 lets a motion clip serve as the style prompt by mapping it into CLIP's
space. Here a small (non-causal) 1D conv net with temporal mean pooling is trained contrastively
(CLIP, Radford et al. 2021, Fig. 3: logits = exp(τ)·m·tᵀ, cross-entropy) against the frozen
text embeddings of the style labels (:mod:`gesturecast.models.generator.style_text`). The text side is a
fixed vocabulary, so the loss is the motion→text InfoNCE term over all label prompts; the
text→motion term is ill-posed when a batch holds several clips of one label.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import torch
import torch.nn.functional as F
from torch import nn

from gesturecast.models.motion.motion_features import FEATURE_DIM

logger = logging.getLogger(__name__)

CLIP_INITIAL_TEMPERATURE = 0.07  # Radford et al. 2021 §2.5: τ initialised to 0.07
CLIP_MAX_LOGIT_SCALE = 100.0  # Radford et al. 2021 §2.5: logit scale clipped at 100
STD_FLOOR = 1e-4  # keeps constant feature channels from blowing up under normalisation
LOG_EVERY = 50


@dataclass(frozen=True)
class MotionPromptConfig:
    feature_dim: int = FEATURE_DIM  # D: canonical motion features per frame
    width: int = 128
    embed_dim: int = 256  # S: must equal the text embedding size
    kernel: int = 5
    num_layers: int = 3  # conv layers; all but the first halve the time axis


class MotionPromptEncoder(nn.Module):
    def __init__(self, config: MotionPromptConfig):
        super().__init__()
        self.config = config
        self.register_buffer("feature_mean", torch.zeros(config.feature_dim))
        self.register_buffer("feature_std", torch.ones(config.feature_dim))
        pad = config.kernel // 2
        layers: list[nn.Module] = [nn.Conv1d(config.feature_dim, config.width, config.kernel, padding=pad), nn.GELU()]
        for _ in range(config.num_layers - 1):
            layers += [nn.Conv1d(config.width, config.width, config.kernel, stride=2, padding=pad), nn.GELU()]
        self.convs = nn.Sequential(*layers)
        self.project = nn.Linear(config.width, config.embed_dim)
        self.logit_scale = nn.Parameter(torch.tensor(math.log(1.0 / CLIP_INITIAL_TEMPERATURE)))

    def set_normalization(self, mean: np.ndarray, std: np.ndarray) -> None:
        self.feature_mean.copy_(torch.as_tensor(mean, dtype=torch.float32))
        self.feature_std.copy_(torch.as_tensor(np.maximum(std, STD_FLOOR), dtype=torch.float32))

    def forward(self, features: torch.Tensor) -> torch.Tensor:
        """features (B, T, D) → (B, S) unit-norm embeddings."""
        normalized = (features - self.feature_mean) / self.feature_std  # (B, T, D)
        hidden = self.convs(normalized.transpose(1, 2))  # (B, W, T')
        return F.normalize(self.project(hidden.mean(dim=2)), dim=-1)  # (B, S)


@dataclass(frozen=True)
class PromptTrainConfig:
    clip_frames: int = 120  # 4 s at 30 fps
    batch_size: int = 32
    steps: int = 1000
    learning_rate: float = 1e-3
    seed: int = 0


def info_nce_loss(motion: torch.Tensor, texts: torch.Tensor, targets: torch.Tensor, logit_scale: torch.Tensor):
    """motion (B, S), texts (L, S) unit vectors, targets (B,) label indices → CLIP cross-entropy."""
    logits = logit_scale.clamp(max=math.log(CLIP_MAX_LOGIT_SCALE)).exp() * motion @ texts.T  # (B, L)
    return F.cross_entropy(logits, targets)


def sample_clip_batch(clips: Sequence[np.ndarray], labels: np.ndarray, config: PromptTrainConfig, rng):
    """Random fixed-length crops: → (B, T, D) float32 tensor and (B,) int64 labels."""
    chosen = rng.integers(0, len(clips), config.batch_size)
    crops = []
    for index in chosen:
        clip = clips[index]
        start = rng.integers(0, len(clip) - config.clip_frames + 1)
        crops.append(clip[start : start + config.clip_frames])
    return torch.as_tensor(np.stack(crops), dtype=torch.float32), torch.as_tensor(labels[chosen], dtype=torch.int64)


def train_motion_prompt(
    encoder: MotionPromptEncoder,
    clips: Sequence[np.ndarray],
    labels: Sequence[int],
    label_embeddings: np.ndarray,
    config: PromptTrainConfig = PromptTrainConfig(),  # noqa: B008 (frozen dataclass)
) -> list[float]:
    """Train on (T_i, D) clips (each at least ``clip_frames`` long) with label indices into the (L, S)
    text table; sets the encoder's feature normalisation from the clips. Returns the loss per step."""
    too_short = [len(clip) for clip in clips if len(clip) < config.clip_frames]
    if too_short:
        raise ValueError(f"{len(too_short)} clips are shorter than {config.clip_frames} frames")
    stacked = np.concatenate(clips)  # (ΣT, D)
    encoder.set_normalization(stacked.mean(axis=0), stacked.std(axis=0))
    torch.manual_seed(config.seed)
    rng = np.random.default_rng(config.seed)
    texts = torch.as_tensor(label_embeddings, dtype=torch.float32)  # (L, S)
    label_array = np.asarray(labels, dtype=np.int64)
    optimizer = torch.optim.AdamW(encoder.parameters(), lr=config.learning_rate)
    encoder.train()
    losses = []
    for step in range(config.steps):
        features, targets = sample_clip_batch(clips, label_array, config, rng)
        loss = info_nce_loss(encoder(features), texts, targets, encoder.logit_scale)
        optimizer.zero_grad()
        loss.backward()
        optimizer.step()
        losses.append(loss.item())
        if step % LOG_EVERY == 0:
            logger.info("motion prompt step %d loss %.4f", step, losses[-1])
    encoder.eval()
    return losses
