"""Motion VQ-VAE over normalized motion features (torch): causal conv encoder/decoder + EMA codebook.

(B, T, D) features at 30 fps → encoder (×1/d in time) → latents (B, T/d, C) → EMA vector quantizer
(512 codes) → decoder (×d) → (B, T, D). Everything is causal (left padding only), so the decoder
also runs one latent frame at a time with explicit state (:meth:`VQDecoder.step`), exactly equal to
the offline decoder. The latent diffusion model works on the continuous quantized code vectors
(GestureDiffuCLIP-style), hence :meth:`MotionVQVAE.encode` returns both pre- and post-quantization
latents and :meth:`MotionVQVAE.decode` takes any latents.

References: van den Oord et al. 2017 (VQ-VAE); Razavi et al. 2019 (EMA codebook); Zhang et al. 2023
(T2M-GPT: causal-ish 1-D conv motion VQ-VAE with d = 4, 512 codes, velocity loss).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import torch
from torch import nn
from torch.nn import functional as F

from gesturecast.models.networks.causal_conv import (
    Activation,
    CausalConv1d,
    CausalResBlock,
    NearestUpsample,
    TransposedUpsample,
)
from gesturecast.models.networks.quantizer import EMAQuantizer, QuantizerOutput

STAGE_FACTOR = 2  # each encoder stage halves the frame rate, each decoder stage doubles it
DOWNSAMPLE_KERNEL = 2 * STAGE_FACTOR
VQVAE_FORMAT_VERSION = 2  # 2 added `upsampling` and `acceleration_weight`
UPSAMPLINGS = ("nearest", "transposed")


@dataclass(frozen=True)
class VQVAEConfig:
    """Sizes of the motion VQ-VAE and weights of its losses."""

    feature_dim: int = 136  # D: root 4 + 22 joints × 6D (motion_features.FEATURE_DIM)
    hidden_dim: int = 128
    latent_dim: int = 32  # C: code vector size, the diffusion model's latent size
    downsample: int = 4  # d: motion frames per latent frame, a power of two (30 fps → 7.5 Hz)
    res_blocks_per_stage: int = 2
    dilation_growth: int = 3  # dilation of res block i is growth**i
    kernel_size: int = 3
    codebook_size: int = 512
    ema_decay: float = 0.99
    dead_code_threshold: float = 0.1  # EMA assignments per training step below which a code is re-seeded
    commitment_weight: float = 0.02
    velocity_weight: float = 0.5  # weight of the frame-difference reconstruction loss
    acceleration_weight: float = 1.0  # weight of the second-difference loss (suppresses frame-level jitter)
    upsampling: str = "nearest"  # decoder: "nearest" + causal conv, or "transposed" (format 1)

    def __post_init__(self) -> None:
        if self.downsample < 1 or self.downsample & (self.downsample - 1):
            raise ValueError(f"downsample must be a power of two, got {self.downsample}")
        if self.upsampling not in UPSAMPLINGS:
            raise ValueError(f"upsampling must be one of {UPSAMPLINGS}, got {self.upsampling!r}")

    @property
    def num_stages(self) -> int:
        return int(math.log2(self.downsample))

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass
class VQEncoding:
    pre_quantization: torch.Tensor  # (B, N, C) encoder output
    quantized: torch.Tensor  # (B, N, C) code vectors (straight-through gradient)
    codes: torch.Tensor  # (B, N) int64
    commitment_loss: torch.Tensor  # ()


def _upsampling_layers(config: VQVAEConfig) -> list[nn.Module]:
    """One ×2 decoder stage's upsampling: nearest repeat + causal conv, or the format-1 transposed conv."""
    if config.upsampling == "transposed":
        return [TransposedUpsample(config.hidden_dim, STAGE_FACTOR)]
    return [NearestUpsample(STAGE_FACTOR), CausalConv1d(config.hidden_dim, config.hidden_dim, config.kernel_size)]


def _res_blocks(config: VQVAEConfig) -> list[nn.Module]:
    return [
        CausalResBlock(config.hidden_dim, config.kernel_size, config.dilation_growth**i)
        for i in range(config.res_blocks_per_stage)
    ]


class VQEncoder(nn.Module):
    """(B, T, D) → (B, T/d, C): input conv, then per stage a strided causal conv and res blocks."""

    def __init__(self, config: VQVAEConfig):
        super().__init__()
        layers: list[nn.Module] = [CausalConv1d(config.feature_dim, config.hidden_dim, config.kernel_size)]
        for _ in range(config.num_stages):
            layers.append(CausalConv1d(config.hidden_dim, config.hidden_dim, DOWNSAMPLE_KERNEL, stride=STAGE_FACTOR))
            layers.extend(_res_blocks(config))
        layers += [Activation(), nn.Conv1d(config.hidden_dim, config.latent_dim, 1)]
        self.layers = nn.Sequential(*layers)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.layers(x.transpose(1, 2)).transpose(1, 2)  # (B, T/d, C)


class VQDecoder(nn.Module):
    """(B, N, C) → (B, N·d, D), offline or one latent frame at a time with explicit state."""

    def __init__(self, config: VQVAEConfig):
        super().__init__()
        layers: list[nn.Module] = [CausalConv1d(config.latent_dim, config.hidden_dim, config.kernel_size)]
        for _ in range(config.num_stages):
            layers.extend(_res_blocks(config))
            layers.extend(_upsampling_layers(config))
        layers += [Activation(), CausalConv1d(config.hidden_dim, config.feature_dim, config.kernel_size)]
        self.layers = nn.ModuleList(layers)
        self.frames_per_latent = config.downsample

    def forward(self, latents: torch.Tensor) -> torch.Tensor:
        x = latents.transpose(1, 2)  # (B, C, N)
        for layer in self.layers:
            x = layer(x)
        return x.transpose(1, 2)  # (B, N·d, D)

    def state_shapes(self) -> list[tuple[int, int]]:
        """(channels, context frames) of each state tensor, in step order."""
        return [(layer.in_channels, layer.context) for layer in self.layers if layer.context]

    def initial_state(self, batch: int = 1, device: torch.device | None = None) -> list[torch.Tensor]:
        """Zero state: the streaming equivalent of the offline left zero padding."""
        return [torch.zeros(batch, channels, context, device=device) for channels, context in self.state_shapes()]

    def step(self, latent: torch.Tensor, state: list[torch.Tensor]) -> tuple[torch.Tensor, list[torch.Tensor]]:
        """One latent frame (B, C) + state → d pose-feature frames (B, d, D) + new state."""
        x = latent.unsqueeze(-1)  # (B, C, 1)
        states = iter(state)
        new_state = []
        for layer in self.layers:
            if layer.context:
                x, layer_state = layer.step(x, next(states))
                new_state.append(layer_state)
            else:
                x = layer(x)
        return x.transpose(1, 2), new_state  # (B, d, D)


class MotionVQVAE(nn.Module):
    def __init__(self, config: VQVAEConfig):
        super().__init__()
        self.config = config
        self.encoder = VQEncoder(config)
        self.quantizer = EMAQuantizer(
            config.codebook_size, config.latent_dim, config.ema_decay, config.dead_code_threshold
        )
        self.decoder = VQDecoder(config)

    def encode(self, x: torch.Tensor) -> VQEncoding:
        """x (B, T, D) with T a multiple of d → latents before and after quantization, (B, T/d, C)."""
        if x.shape[1] % self.config.downsample:
            raise ValueError(f"sequence length {x.shape[1]} is not a multiple of {self.config.downsample}")
        pre = self.encoder(x)  # (B, N, C)
        out: QuantizerOutput = self.quantizer(pre)
        return VQEncoding(pre, out.quantized, out.codes, out.commitment_loss)

    def quantized_latents(self, x: torch.Tensor) -> torch.Tensor:
        """x (B, T, D) → the nearest code vectors (B, T/d, C), no statistics updated (the encoder export)."""
        return self.quantizer.lookup(self.quantizer.nearest_codes(self.encoder(x)))

    def decode(self, latents: torch.Tensor) -> torch.Tensor:
        """Latents (B, N, C), quantized or not → features (B, N·d, D)."""
        return self.decoder(latents)

    def decode_codes(self, codes: torch.Tensor) -> torch.Tensor:
        """Code indices (B, N) → features (B, N·d, D)."""
        return self.decoder(self.quantizer.lookup(codes))

    def forward(self, x: torch.Tensor) -> tuple[torch.Tensor, VQEncoding]:
        encoding = self.encode(x)
        return self.decode(encoding.quantized), encoding  # (B, T, D)

    def loss(self, x: torch.Tensor) -> tuple[torch.Tensor, dict[str, float]]:
        """Smooth-L1 reconstruction of features, first and second frame differences + β·commitment (VQ-VAE eq. 3)."""
        reconstruction, encoding = self(x)  # (B, T, D)
        feature_loss = F.smooth_l1_loss(reconstruction, x)
        velocity_loss = F.smooth_l1_loss(reconstruction.diff(dim=1), x.diff(dim=1))
        acceleration_loss = F.smooth_l1_loss(reconstruction.diff(n=2, dim=1), x.diff(n=2, dim=1))
        total = (
            feature_loss
            + self.config.velocity_weight * velocity_loss
            + self.config.acceleration_weight * acceleration_loss
            + self.config.commitment_weight * encoding.commitment_loss
        )
        parts = {
            "reconstruction": feature_loss.item(),
            "velocity": velocity_loss.item(),
            "acceleration": acceleration_loss.item(),
            "commitment": encoding.commitment_loss.item(),
        }
        return total, parts


def vqvae_checkpoint(model: MotionVQVAE) -> dict[str, Any]:
    """Plain data (config dict + tensors) that :func:`vqvae_from_checkpoint` rebuilds; no pickled modules."""
    return {"format_version": VQVAE_FORMAT_VERSION, "config": model.config.to_dict(), "state": model.state_dict()}


FORMAT_1_CONFIG = {"upsampling": "transposed", "acceleration_weight": 0.0}  # what format 1 implied


def vqvae_from_checkpoint(checkpoint: dict[str, Any]) -> MotionVQVAE:
    version = checkpoint.get("format_version")
    if version not in (1, VQVAE_FORMAT_VERSION):
        raise ValueError(f"unsupported VQ-VAE checkpoint format {version!r}")
    config = {**FORMAT_1_CONFIG, **checkpoint["config"]} if version == 1 else checkpoint["config"]
    model = MotionVQVAE(VQVAEConfig(**config))
    model.load_state_dict(checkpoint["state"])
    return model.eval()
