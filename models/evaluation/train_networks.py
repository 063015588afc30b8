"""Training the frozen evaluation networks (torch; run once, then the weights are committed).

- FGD encoder (Yoon et al. 2020, "Speech Gesture Generation from the Trimodal Context of Text,
  Audio, and Speaker Identity", Sec. 5.1: an autoencoder of motion sequences whose encoder features
  feed the Fréchet distance): :class:`EvalConvNet` encoder + transposed-convolution decoder,
  reconstruction MSE on normalised windows; only the encoder is kept.
- Style classifier: the same network with a class-logit head, cross-entropy on class-balanced
  batches (every style equally often, whatever its minutes), accuracy on the test split.

Both are exported as numpy weights (:meth:`EvalConvNet.save`) with a JSON stamp beside them.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, replace
from itertools import pairwise

import numpy as np
import torch
from torch import nn
from tqdm import tqdm

from gesturecast.models.evaluation.convnet import ConvNetConfig, EvalConvNet
from gesturecast.models.evaluation.data import RealClip, sample_windows

LOGGER = logging.getLogger(__name__)
STD_FLOOR = 1e-3  # metres: channels that hardly move are not blown up by normalisation
STATS_SAMPLE_WINDOWS = 4096


@dataclass(frozen=True)
class EvalTrainConfig:
    steps: int = 3000
    batch_size: int = 64
    learning_rate: float = 1e-3
    weight_decay: float = 1e-4
    seed: int = 0
    threads: int = 1  # 2 threads on a shared 2-core machine ran 20x slower (measured)


class TorchConvNet(nn.Module):
    """The torch twin of :class:`EvalConvNet` (same layers, same parameter names)."""

    def __init__(self, config: ConvNetConfig):
        super().__init__()
        self.config = config
        widths = (config.in_channels, *config.channels)
        self.convs = nn.ModuleList(
            nn.Conv1d(a, b, config.kernel, config.stride, config.padding) for a, b in pairwise(widths)
        )
        self.head = nn.Linear(widths[-1], config.out_dim)
        self.act = nn.LeakyReLU(config.negative_slope)

    def trunk(self, x: torch.Tensor) -> torch.Tensor:
        h = x.transpose(1, 2)  # (N, C, T)
        for conv in self.convs:
            h = self.act(conv(h))  # (N, C_i, T / 2^(i+1))
        return h

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.head(self.trunk(x).mean(dim=2))  # (N, out_dim)

    def export(self, mean: np.ndarray, std: np.ndarray) -> EvalConvNet:
        weights = {"input_mean": mean.astype(np.float32), "input_std": std.astype(np.float32)}
        for i, conv in enumerate(self.convs):
            weights[f"conv{i}.weight"] = conv.weight.detach().numpy().copy()
            weights[f"conv{i}.bias"] = conv.bias.detach().numpy().copy()
        weights["head.weight"] = self.head.weight.detach().numpy().copy()
        weights["head.bias"] = self.head.bias.detach().numpy().copy()
        return EvalConvNet(self.config, weights)


class MotionAutoencoder(nn.Module):
    """Encoder (TorchConvNet → feature vector) and a mirrored transposed-convolution decoder."""

    def __init__(self, config: ConvNetConfig):
        super().__init__()
        self.encoder = TorchConvNet(config)
        self.latent_frames = config.window.frames // config.stride ** len(config.channels)
        self.expand = nn.Linear(config.out_dim, config.channels[-1] * self.latent_frames)
        widths = (*reversed(config.channels), config.in_channels)
        self.deconvs = nn.ModuleList(
            nn.ConvTranspose1d(a, b, config.kernel, config.stride, config.padding) for a, b in pairwise(widths)
        )
        self.act = nn.LeakyReLU(config.negative_slope)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        z = self.encoder(x)  # (N, out_dim)
        h = self.expand(z).view(x.shape[0], -1, self.latent_frames)  # (N, C_last, T / 8)
        for i, deconv in enumerate(self.deconvs):
            h = deconv(h)
            h = self.act(h) if i < len(self.deconvs) - 1 else h  # (N, C, 2T')
        return h.transpose(1, 2)  # (N, T, C)


def channel_statistics(clips: list[RealClip], frames: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Per-channel mean and std (C,) of the input, from a sample of windows."""
    sample = sample_windows(clips, STATS_SAMPLE_WINDOWS, frames, rng).reshape(-1, clips[0].channels.shape[1])
    return sample.mean(axis=0), np.maximum(sample.std(axis=0), STD_FLOOR)


def _optimise(module: nn.Module, loss_of_step, config: EvalTrainConfig, desc: str, progress: bool) -> float:
    """Adam over ``config.steps`` steps; ``loss_of_step(step)`` returns the batch loss. Returns the last loss."""
    optimiser = torch.optim.AdamW(module.parameters(), lr=config.learning_rate, weight_decay=config.weight_decay)
    loss_value = float("nan")
    for step in tqdm(range(config.steps), desc=desc, disable=not progress):
        loss = loss_of_step(step)
        optimiser.zero_grad()
        loss.backward()
        optimiser.step()
        loss_value = loss.item()
    return loss_value


def _seeded_setup(
    clips: list[RealClip], net_config: ConvNetConfig, config: EvalTrainConfig
) -> tuple[np.random.Generator, int, np.ndarray, np.ndarray]:
    """Seed torch and numpy, set the thread count; (rng, window frames, channel mean, channel std)."""
    torch.manual_seed(config.seed)
    torch.set_num_threads(config.threads)
    rng = np.random.default_rng(config.seed)
    frames = net_config.window.frames
    mean, std = channel_statistics(clips, frames, rng)
    return rng, frames, mean, std


def train_fgd_encoder(
    clips: list[RealClip], net_config: ConvNetConfig, config: EvalTrainConfig, progress: bool = True
) -> tuple[EvalConvNet, float]:
    """Train the autoencoder on windows of ``clips``; the frozen encoder and the final reconstruction MSE."""
    rng, frames, mean, std = _seeded_setup(clips, net_config, config)
    model = MotionAutoencoder(net_config)

    def loss_of_step(_: int) -> torch.Tensor:
        batch = torch.from_numpy((sample_windows(clips, config.batch_size, frames, rng) - mean) / std).float()
        return nn.functional.mse_loss(model(batch), batch)  # (B, T, C) vs (B, T, C)

    final_loss = _optimise(model, loss_of_step, config, "fgd encoder", progress)
    return model.encoder.export(mean, std), final_loss


def train_style_classifier(
    clips: list[RealClip], labels: tuple[str, ...], net_config: ConvNetConfig, config: EvalTrainConfig,
    progress: bool = True,
) -> tuple[EvalConvNet, float]:
    """Train the classifier on class-balanced windows of ``clips`` (their ``style`` in ``labels``)."""
    rng, frames, mean, std = _seeded_setup(clips, net_config, config)
    by_style = [[c for c in clips if c.style == label] for label in labels]
    model = TorchConvNet(replace(net_config, out_dim=len(labels)))
    per_class = max(config.batch_size // len(labels), 1)
    targets = torch.arange(len(labels)).repeat_interleave(per_class)  # (B,)

    def loss_of_step(_: int) -> torch.Tensor:
        windows = np.concatenate([sample_windows(group, per_class, frames, rng) for group in by_style])
        logits = model(torch.from_numpy((windows - mean) / std).float())  # (B, L)
        return nn.functional.cross_entropy(logits, targets)

    final_loss = _optimise(model, loss_of_step, config, "style classifier", progress)
    return model.export(mean, std), final_loss
