"""The frozen critic of GestureDiffuCLIP's style loss: denoised latents → the style embedding of their motion.

GestureDiffuCLIP §4.3, Eq. 16: the denoised motion is encoded by the frozen motion encoder and compared with the
style prompt's embedding. Here the latents (normalised, as the denoiser predicts them) are denormalised, decoded
by the frozen part VQ-VAE decoder into canonical motion features, and embedded by the frozen motion-prompt
encoder, whose space is the text space of the style labels (:mod:`gesturecast.models.networks.motion_prompt`).
Only the denoiser learns from it: every parameter here is frozen, the gradient flows through to the latents.
"""

from __future__ import annotations

import numpy as np
import torch
from torch import nn

from gesturecast.models.networks.motion_prompt import MotionPromptEncoder
from gesturecast.models.networks.part_vqvae import PartVQVAE


def _buffer(values: np.ndarray) -> torch.Tensor:
    return torch.as_tensor(np.asarray(values, np.float32))


class StyleCritic(nn.Module):
    """Normalised latents (B, N, C) → unit style embeddings (B, S) of the motion they decode to."""

    def __init__(self, vq: PartVQVAE, encoder: MotionPromptEncoder, latent_stats: tuple[np.ndarray, np.ndarray],
                 motion_stats: tuple[np.ndarray, np.ndarray]) -> None:
        super().__init__()
        self.vq = vq.eval()
        self.encoder = encoder.eval()
        for parameter in self.parameters():
            parameter.requires_grad_(False)
        self.register_buffer("latent_mean", _buffer(latent_stats[0]))
        self.register_buffer("latent_std", _buffer(latent_stats[1]))
        self.register_buffer("motion_mean", _buffer(motion_stats[0]))
        self.register_buffer("motion_std", _buffer(motion_stats[1]))

    def forward(self, latents: torch.Tensor) -> torch.Tensor:
        raw = latents * self.latent_std + self.latent_mean  # (B, N, C) the VQ-VAE's latent units
        motion = self.vq.decode(raw) * self.motion_std + self.motion_mean  # (B, N·d, D) canonical features
        return self.encoder(motion)  # (B, S)
