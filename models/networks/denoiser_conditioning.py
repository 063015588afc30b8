"""Per-frame conditioning encoders of the causal denoiser: diffusion step, audio window, style.

- Diffusion step: sinusoidal embedding (Vaswani et al. 2017 §3.5; Ho et al. 2020 App. B) of ``t + 1``,
  so that ``t = CLEAN_TIMESTEP = -1`` (clean history, diffusion forcing) has its own exact code.
- Audio: a small 1D conv over the (A, F) window of features ending δa frames past the latent. A model
  with ``lookahead_truncation`` is told its look-ahead δ ≤ δa per frame: the window's last δa − δ frames
  are zeroed and a visibility channel (1 = heard, 0 = masked) joins the features (docs/latency.md).
- Style: AdaIN-like modulation ``x * (1 + γ) + β`` (GestureDiffuCLIP §4 eq. 6; ZeroEGGS), γ and β
  predicted from the style embedding and zero-initialised so every layer starts as identity.
  A learned null style replaces the embedding where ``style_present = 0`` (classifier-free guidance,
  Ho & Salimans 2022).
"""

from __future__ import annotations

import math

import torch
from torch import nn

from gesturecast.models.generator.denoiser_config import DenoiserConfig

MAX_PERIOD = 10000.0  # sinusoidal embedding base (Vaswani et al. 2017)
AUDIO_CONV_KERNEL = 3
AUDIO_CONV_STRIDE = 2


def sinusoidal_embedding(steps: torch.Tensor, dim: int) -> torch.Tensor:
    """steps (...,) float → (..., dim): [cos(s·ω_k), sin(s·ω_k)], ω_k = MAX_PERIOD^(-k/(dim/2))."""
    half = dim // 2
    freqs = torch.exp(-math.log(MAX_PERIOD) * torch.arange(half, dtype=torch.float32, device=steps.device) / half)
    angles = steps.float()[..., None] * freqs  # (..., dim/2)
    return torch.cat([torch.cos(angles), torch.sin(angles)], dim=-1)  # (..., dim)


class TimestepEmbedding(nn.Module):
    def __init__(self, width: int):
        super().__init__()
        self.width = width
        self.mlp = nn.Sequential(nn.Linear(width, width), nn.SiLU(), nn.Linear(width, width))

    def forward(self, t: torch.Tensor) -> torch.Tensor:
        """t (B, M) int, CLEAN_TIMESTEP = -1 for clean frames → (B, M, D)."""
        return self.mlp(sinusoidal_embedding(t + 1, self.width))


class AudioWindowEncoder(nn.Module):
    """(B, M, A, F) audio windows → (B, M, D) tokens; absent audio becomes a learned null token."""

    def __init__(self, config: DenoiserConfig):
        super().__init__()
        width = config.width
        self.config = config
        channels = config.audio_dim + int(config.lookahead_truncation)  # + the visibility channel
        self.convs = nn.Sequential(
            nn.Conv1d(channels, width, AUDIO_CONV_KERNEL, padding=AUDIO_CONV_KERNEL // 2),
            nn.GELU(),
            nn.Conv1d(width, width, AUDIO_CONV_KERNEL, stride=AUDIO_CONV_STRIDE, padding=AUDIO_CONV_KERNEL // 2),
            nn.GELU(),
        )
        reduced = (config.audio_window - 1) // AUDIO_CONV_STRIDE + 1
        self.project = nn.Linear(width * reduced, width)
        self.null_audio = nn.Parameter(torch.zeros(width))

    def visible(self, windows: torch.Tensor, lookahead: torch.Tensor) -> torch.Tensor:
        """windows (B, M, A, F), lookahead δ (B, M) → (B, M, A, F + 1): frames past δ zeroed, visibility appended."""
        length = windows.shape[2]
        heard = length - self.config.audio_lookahead + lookahead.to(windows.dtype)  # (B, M): visible frames
        positions = torch.arange(length, dtype=windows.dtype, device=windows.device)  # (A,)
        mask = (positions < heard[..., None]).to(windows.dtype)[..., None]  # (B, M, A, 1)
        return torch.cat([windows * mask, mask], dim=-1)  # (B, M, A, F + 1)

    def forward(self, windows: torch.Tensor, audio_present: torch.Tensor,
                lookahead: torch.Tensor | None = None) -> torch.Tensor:
        """windows (B, M, A, F), audio_present (B, M) in {0, 1}, lookahead δ (B, M) (truncation models only)
        → (B, M, D)."""
        if self.config.lookahead_truncation:
            if lookahead is None:
                raise ValueError("a look-ahead truncation model needs the look-ahead δ of every frame")
            windows = self.visible(windows, lookahead)  # (B, M, A, F + 1)
        batch, num_new, length, channels = windows.shape
        flat = windows.reshape(batch * num_new, length, channels).transpose(1, 2)  # (B*M, F, A)
        encoded = self.convs(flat).flatten(1)  # (B*M, D*A')
        tokens = self.project(encoded).reshape(batch, num_new, -1)  # (B, M, D)
        present = audio_present[..., None].to(tokens.dtype)  # (B, M, 1)
        return tokens * present + self.null_audio * (1 - present)


class StyleEncoder(nn.Module):
    """(B, M, S) per-frame style embedding (or the learned null style) → (B, M, D) style code."""

    def __init__(self, config: DenoiserConfig):
        super().__init__()
        self.null_style = nn.Parameter(torch.zeros(config.style_dim))
        self.mlp = nn.Sequential(nn.Linear(config.style_dim, config.width), nn.SiLU())

    def forward(self, style: torch.Tensor, style_present: torch.Tensor) -> torch.Tensor:
        present = style_present[..., None].to(style.dtype)  # (B, M, 1)
        return self.mlp(style * present + self.null_style * (1 - present))  # (B, M, D)


class StyleModulation(nn.Module):
    """AdaIN-like ``norm(x) * (1 + γ) + β`` with (γ, β) = Linear(style code), zero-initialised.

    Split in two so the scale ``1 + γ`` and the shift ``β`` can be computed once per latent frame
    (:meth:`modulation`, part of the denoiser's condition) and applied at every sampler step (:meth:`forward`).
    """

    def __init__(self, width: int):
        super().__init__()
        self.width = width
        self.norm = nn.LayerNorm(width, elementwise_affine=False)
        self.to_gamma_beta = nn.Linear(width, 2 * width)
        nn.init.zeros_(self.to_gamma_beta.weight)
        nn.init.zeros_(self.to_gamma_beta.bias)

    def modulation(self, style_code: torch.Tensor) -> torch.Tensor:
        """style_code (B, M, D) → [scale 1 + γ | shift β] (B, M, 2D)."""
        gamma, beta = self.to_gamma_beta(style_code).split(self.width, dim=-1)  # 2 × (B, M, D): static split
        return torch.cat([1 + gamma, beta], dim=-1)

    def forward(self, x: torch.Tensor, scale: torch.Tensor, shift: torch.Tensor) -> torch.Tensor:
        """x, scale, shift (B, M, D) → (B, M, D)."""
        return self.norm(x) * scale + shift
