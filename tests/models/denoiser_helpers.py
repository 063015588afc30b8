"""Tiny denoiser config and random-weight model shared by the denoiser tests."""

from dataclasses import replace

import torch

from gesturecast.models.generator.denoiser_config import DenoiserConfig
from gesturecast.models.networks.denoiser_network import CausalDenoiser

TINY = DenoiserConfig(
    latent_dim=6, audio_dim=5, style_dim=8, width=16, num_layers=2, num_heads=2, window=3, audio_window=8
)
TRUNCATING = replace(TINY, audio_lookahead=4, lookahead_truncation=True)  # serves look-ahead 0..4 of its 8-frame window
WEIGHT_JITTER = 0.1  # perturbs every weight so zero-initialised style modulation is exercised too


def random_model(config: DenoiserConfig = TINY, seed: int = 0) -> CausalDenoiser:
    torch.manual_seed(seed)
    model = CausalDenoiser(config).eval()
    with torch.no_grad():
        for param in model.parameters():
            param.add_(WEIGHT_JITTER * torch.randn_like(param))
    return model
