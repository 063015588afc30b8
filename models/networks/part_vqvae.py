"""One motion VQ-VAE per body part, latents stacked into one vector (GestureDiffuCLIP §6.3) (torch).

Each part (:mod:`gesturecast.models.motion.body_parts`) has its own causal :class:`MotionVQVAE` over its
own feature columns. The latent of one latent frame is the parts' code vectors side by side,
``z = [z_arms | z_torso | z_legs]`` (B, N, ΣC_o), so the latent denoiser is trained on the stack exactly
as on a single VQ-VAE's latent, and a part's style can be steered by masking its latent channels at
sampling time (:func:`part_channel_masks`). Decoding splits the stack, decodes every part with its own
streaming decoder and puts the columns back in canonical order, offline or one latent at a time.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import torch
from torch import nn

from gesturecast.models.motion.body_parts import BodyPart, body_parts
from gesturecast.models.networks.vqvae import (
    MotionVQVAE,
    VQDecoder,
    VQEncoding,
    VQVAEConfig,
    vqvae_checkpoint,
    vqvae_from_checkpoint,
)


@dataclass(frozen=True)
class PartVQVAEConfig:
    """The parts (names, in latent order) and each part's VQ-VAE config (its feature_dim = its column count)."""

    parts: tuple[str, ...]
    part_configs: tuple[VQVAEConfig, ...]

    def __post_init__(self) -> None:
        for part, config in zip(body_parts(self.parts), self.part_configs, strict=True):
            if config.feature_dim != part.feature_dim:
                raise ValueError(f"part {part.name} has {part.feature_dim} feature columns, its VQ-VAE "
                                 f"{config.feature_dim}")
        if len({config.downsample for config in self.part_configs}) != 1:
            raise ValueError("every part's VQ-VAE needs the same downsampling d")

    @property
    def downsample(self) -> int:
        return self.part_configs[0].downsample

    @property
    def latent_dim(self) -> int:
        return sum(config.latent_dim for config in self.part_configs)

    @property
    def feature_dim(self) -> int:
        return sum(config.feature_dim for config in self.part_configs)

    def latent_slices(self) -> dict[str, slice]:
        """Each part's channels of the stacked latent."""
        ends = np.cumsum([config.latent_dim for config in self.part_configs])
        return {name: slice(int(end - config.latent_dim), int(end))
                for name, config, end in zip(self.parts, self.part_configs, ends, strict=True)}

    def to_dict(self) -> dict[str, Any]:
        return {"parts": list(self.parts), "part_configs": [config.to_dict() for config in self.part_configs]}

    @classmethod
    def from_dict(cls, values: dict[str, Any]) -> PartVQVAEConfig:
        return cls(tuple(values["parts"]), tuple(VQVAEConfig(**config) for config in values["part_configs"]))


def part_channel_masks(slices: dict[str, slice], latent_dim: int) -> dict[str, np.ndarray]:
    """M_o of E = Σ_o E_o · M_o: a (C,) 0/1 mask of each part's latent channels."""
    masks = {}
    for name, channels in slices.items():
        mask = np.zeros(latent_dim, np.float32)
        mask[channels] = 1.0
        masks[name] = mask
    return masks


def _canonical_order(parts: tuple[BodyPart, ...]) -> torch.Tensor:
    """Index that turns the parts' columns laid side by side back into canonical feature order."""
    side_by_side = np.concatenate([part.columns for part in parts])
    return torch.as_tensor(np.argsort(side_by_side), dtype=torch.long)


class PartDecoder(nn.Module):
    """The parts' decoders as one: stacked latent (B, N, C) → canonical features (B, N·d, D), offline or per step.

    The streaming state is the parts' states one after another (same interface as :class:`VQDecoder`)."""

    def __init__(self, config: PartVQVAEConfig, decoders: list[VQDecoder]):
        super().__init__()
        self.decoders = nn.ModuleList(decoders)
        self.slices = list(config.latent_slices().values())
        self.state_counts = [len(decoder.state_shapes()) for decoder in decoders]
        self.register_buffer("order", _canonical_order(body_parts(config.parts)), persistent=False)
        self.frames_per_latent = config.downsample

    def forward(self, latents: torch.Tensor) -> torch.Tensor:
        parts = [decoder(latents[..., channels]) for decoder, channels in zip(self.decoders, self.slices, strict=True)]
        return torch.cat(parts, dim=-1)[..., self.order]  # (B, N·d, D)

    def state_shapes(self) -> list[tuple[int, int]]:
        return [shape for decoder in self.decoders for shape in decoder.state_shapes()]

    def initial_state(self, batch: int = 1, device: torch.device | None = None) -> list[torch.Tensor]:
        return [state for decoder in self.decoders for state in decoder.initial_state(batch, device)]

    def step(self, latent: torch.Tensor, state: list[torch.Tensor]) -> tuple[torch.Tensor, list[torch.Tensor]]:
        """One stacked latent (B, C) + the parts' states → d frames (B, d, D) + new states."""
        frames, new_state, start = [], [], 0
        for decoder, channels, count in zip(self.decoders, self.slices, self.state_counts, strict=True):
            part_frames, part_state = decoder.step(latent[..., channels], state[start:start + count])
            frames.append(part_frames)  # (B, d, D_o)
            new_state.extend(part_state)
            start += count
        return torch.cat(frames, dim=-1)[..., self.order], new_state  # (B, d, D)


class PartVQVAE(nn.Module):
    """Per-part motion VQ-VAEs behind the interface of one :class:`MotionVQVAE` (encode, decode, decoder)."""

    def __init__(self, config: PartVQVAEConfig, models: list[MotionVQVAE] | None = None):
        super().__init__()
        self.config = config
        self.parts = body_parts(config.parts)
        self.models = nn.ModuleList(models or [MotionVQVAE(part_config) for part_config in config.part_configs])

    @property
    def decoder(self) -> PartDecoder:
        return PartDecoder(self.config, [model.decoder for model in self.models])

    def part_features(self, x: torch.Tensor, index: int) -> torch.Tensor:
        """The columns of part ``index`` of canonical features (B, T, D) → (B, T, D_o)."""
        return x[..., list(self.parts[index].columns)]

    def encode(self, x: torch.Tensor) -> VQEncoding:
        """x (B, T, D) → stacked latents (B, T/d, C); codes (B, T/d, P), one code per part."""
        encodings = [model.encode(self.part_features(x, i)) for i, model in enumerate(self.models)]
        return VQEncoding(torch.cat([e.pre_quantization for e in encodings], dim=-1),
                          torch.cat([e.quantized for e in encodings], dim=-1),
                          torch.stack([e.codes for e in encodings], dim=-1),
                          torch.stack([e.commitment_loss for e in encodings]).mean())

    def quantized_latents(self, x: torch.Tensor) -> torch.Tensor:
        """x (B, T, D) → the nearest code vectors of every part, stacked (B, T/d, C) (the encoder export)."""
        return torch.cat([model.quantized_latents(self.part_features(x, i)) for i, model in enumerate(self.models)],
                         dim=-1)

    def decode(self, latents: torch.Tensor) -> torch.Tensor:
        """Stacked latents (B, N, C) → canonical features (B, N·d, D)."""
        return self.decoder(latents)

    def forward(self, x: torch.Tensor) -> tuple[torch.Tensor, VQEncoding]:
        encoding = self.encode(x)
        return self.decode(encoding.quantized), encoding  # (B, T, D)


PART_VQVAE_FORMAT_VERSION = 3  # after the single VQ-VAE's formats 1 and 2


def motion_vq_checkpoint(model: MotionVQVAE | PartVQVAE) -> dict[str, Any]:
    """Plain data for either kind of VQ-VAE (a part model: its config and each part's checkpoint)."""
    if isinstance(model, MotionVQVAE):
        return vqvae_checkpoint(model)
    return {"format_version": PART_VQVAE_FORMAT_VERSION, "config": model.config.to_dict(),
            "parts": [vqvae_checkpoint(part_model) for part_model in model.models]}


def load_motion_vq(checkpoint: dict[str, Any]) -> MotionVQVAE | PartVQVAE:
    """Rebuild the VQ-VAE a training checkpoint holds: one whole-body model or one per part (eval mode)."""
    if checkpoint.get("format_version") != PART_VQVAE_FORMAT_VERSION:
        return vqvae_from_checkpoint(checkpoint)
    models = [vqvae_from_checkpoint(part) for part in checkpoint["parts"]]
    return PartVQVAE(PartVQVAEConfig.from_dict(checkpoint["config"]), models).eval()
