"""Causal latent-diffusion denoiser (GestureDiffuCLIP §3.2–§4, DiffuseStyleGesture §3).

A transformer over VQ-VAE latent frames (B, N, C). Frame i's token is
``in(x_t,i) + emb(t_i) + audio(window_i)``; each block applies style modulation (AdaIN-like),
local causal attention over at most ``window`` past frames, and a feed-forward layer. The network
predicts x0 (DiffuseStyleGesture eq. 4, "x̂0 = D(x_t, t, c)").

Noise levels are per frame (diffusion forcing, Chen et al. 2024 §3): history frames are clean
(``t = CLEAN_TIMESTEP``) and the current frame is noisy, exactly as during autoregressive inference.

The same ``forward_chunk`` serves the whole-sequence forward (empty cache) and the incremental
step (a cache of the last ``window`` frames' keys/values per layer), so the two agree exactly.
"""

from __future__ import annotations

from dataclasses import dataclass

import torch
import torch.nn.functional as F
from torch import nn

from gesturecast.models.generator.denoiser_config import (
    MODULATION_WIDTHS_PER_LAYER,
    DenoiserConfig,
    audio_frames_needed,
    audio_window_end,
)
from gesturecast.models.networks.attention import AttentionMask, LocalCausalAttention, local_causal_mask
from gesturecast.models.networks.denoiser_conditioning import (
    AudioWindowEncoder,
    StyleEncoder,
    StyleModulation,
    TimestepEmbedding,
)


@dataclass(frozen=True)
class KVCache:
    """Keys/values of the last ``window`` history frames: (L, B, H, W, Dh); valid = last ``length[b]`` slots."""

    keys: torch.Tensor
    values: torch.Tensor
    length: torch.Tensor  # (B,) int64

    @classmethod
    def empty(cls, config: DenoiserConfig, batch: int) -> KVCache:
        shape = (config.num_layers, batch, config.num_heads, config.window, config.head_dim)
        return cls(torch.zeros(shape), torch.zeros(shape), torch.zeros(batch, dtype=torch.int64))

    def append(self, new_keys: torch.Tensor, new_values: torch.Tensor) -> KVCache:
        """Push (L, B, H, M, Dh) new frames, evicting the oldest beyond the window."""
        window = self.keys.shape[3]
        keys = torch.cat([self.keys, new_keys], dim=3)[:, :, :, -window:]  # (L, B, H, W, Dh)
        values = torch.cat([self.values, new_values], dim=3)[:, :, :, -window:]  # (L, B, H, W, Dh)
        return KVCache(keys, values, (self.length + new_keys.shape[3]).clamp(max=window))


def audio_windows(audio: torch.Tensor, num_latents: int, config: DenoiserConfig) -> torch.Tensor:
    """(B, N*d + δa, F) aligned features → (B, N, A, F) per-latent windows (zero-padded before frame 0)."""
    needed = audio_frames_needed(num_latents, config)
    if audio.shape[1] < needed:
        raise ValueError(f"{num_latents} latents need {needed} audio frames, got {audio.shape[1]}")
    padded = F.pad(audio, (0, 0, config.audio_window, 0))  # (B, A + T, F)
    ends = [audio_window_end(i, config) for i in range(num_latents)]
    unfolded = padded.unfold(1, config.audio_window, 1)  # (B, T+1, F, A): index j covers audio[j-A, j)
    return unfolded[:, ends].transpose(2, 3)  # (B, N, A, F)


class DenoiserBlock(nn.Module):
    def __init__(self, config: DenoiserConfig):
        super().__init__()
        width = config.width
        self.attn_mod = StyleModulation(width)
        self.attn = LocalCausalAttention(width, config.num_heads, config.window)
        self.ff_mod = StyleModulation(width)
        self.ff = nn.Sequential(
            nn.Linear(width, config.ff_mult * width), nn.GELU(), nn.Linear(config.ff_mult * width, width)
        )

    def modulation(self, style_code: torch.Tensor) -> torch.Tensor:
        """style_code (B, M, D) → this block's (γ, β) of both modulations (B, M, 4D)."""
        return torch.cat([self.attn_mod.modulation(style_code), self.ff_mod.modulation(style_code)], dim=-1)

    def forward(self, x, modulation: tuple[torch.Tensor, ...], cache_k, cache_v, mask: AttentionMask):
        """x (B, M, D), modulation = (attention scale, shift, feed-forward scale, shift), each (B, M, D)
        → (B, M, D), new keys/values (B, H, M, Dh)."""
        attn_scale, attn_shift, ff_scale, ff_shift = modulation
        attended, keys, values = self.attn(self.attn_mod(x, attn_scale, attn_shift), cache_k, cache_v, mask)
        x = x + attended
        x = x + self.ff(self.ff_mod(x, ff_scale, ff_shift))
        return x, keys, values


class CausalDenoiser(nn.Module):
    def __init__(self, config: DenoiserConfig):
        super().__init__()
        self.config = config
        self.input = nn.Linear(config.latent_dim, config.width)
        self.timestep = TimestepEmbedding(config.width)
        self.audio = AudioWindowEncoder(config)
        self.style = StyleEncoder(config)
        self.blocks = nn.ModuleList(DenoiserBlock(config) for _ in range(config.num_layers))
        self.final_norm = nn.LayerNorm(config.width)
        self.output = nn.Linear(config.width, config.latent_dim)

    def condition(self, windows, audio_present, style, style_present, lookahead=None):
        """Everything a frame's denoising needs besides x_t and t, computed once per frame (not per sampler step).

        windows (B, M, A, F), audio_present (B, M), style (B, M, S), style_present (B, M), lookahead δ (B, M)
        (look-ahead truncation models only) → (B, M, condition_dim) = [audio token | per layer: attention
        scale 1 + γ, shift β, feed-forward scale, shift], each D wide.
        """
        style_code = self.style(style, style_present)  # (B, M, D)
        audio_token = self.audio(windows, audio_present, lookahead)  # (B, M, D)
        parts = [audio_token] + [block.modulation(style_code) for block in self.blocks]
        return torch.cat(parts, dim=-1)  # (B, M, D + L·4D)

    def split_condition(self, condition: torch.Tensor) -> tuple[torch.Tensor, list[tuple[torch.Tensor, ...]]]:
        """(B, M, condition_dim) → audio token (B, M, D) and per layer 4 × (B, M, D) (one static split)."""
        width = self.config.width
        parts = condition.split(width, dim=-1)  # (1 + 4L) × (B, M, D)
        per_layer = MODULATION_WIDTHS_PER_LAYER
        return parts[0], [parts[1 + per_layer * i : 1 + per_layer * (i + 1)] for i in range(len(self.blocks))]

    def forward_conditioned(self, x_t, t, condition, cache_k, cache_v, cache_len):
        """Denoise M new frames after a cache of Wc frames, given their :meth:`condition`.

        x_t (B, M, C), t (B, M) int64, condition (B, M, condition_dim), cache_k/v (L, B, H, Wc, Dh),
        cache_len (B,) int64 → x0 (B, M, C), new keys/values (L, B, H, M, Dh).
        """
        audio_token, modulations = self.split_condition(condition)  # (B, M, D), L × 4 × (B, M, D)
        h = self.input(x_t) + self.timestep(t) + audio_token  # (B, M, D)
        mask = local_causal_mask(x_t.shape[1], cache_k.shape[3], cache_len, self.config.window)
        new_keys, new_values = [], []
        for layer, (block, modulation) in enumerate(zip(self.blocks, modulations, strict=True)):
            h, keys, values = block(h, modulation, cache_k[layer], cache_v[layer], mask)
            new_keys.append(keys)
            new_values.append(values)
        x0 = self.output(self.final_norm(h))  # (B, M, C)
        return x0, torch.stack(new_keys), torch.stack(new_values)

    def forward_chunk(self, x_t, t, windows, audio_present, style, style_present, cache_k, cache_v, cache_len,
                      lookahead=None):
        """:meth:`forward_conditioned` on the raw per-frame inputs (B, M, ...) (see :meth:`condition`)."""
        condition = self.condition(windows, audio_present, style, style_present, lookahead)  # (B, M, condition_dim)
        return self.forward_conditioned(x_t, t, condition, cache_k, cache_v, cache_len)

    def forward(self, x_t, t, audio, audio_present, style, style_present, lookahead=None):
        """Whole-sequence forward: x_t (B, N, C), t (B, N), audio (B, N*d+δa, F), audio_present (B, N),
        style (B, S), style_present (B,), lookahead δ (B,) (truncation models; default δa) → x0 (B, N, C)."""
        batch, num_latents, _ = x_t.shape
        cfg = self.config
        empty = x_t.new_zeros(cfg.num_layers, batch, cfg.num_heads, 0, cfg.head_dim)  # (L, B, H, 0, Dh)
        no_history = torch.zeros(batch, dtype=torch.int64, device=x_t.device)
        windows = audio_windows(audio, num_latents, cfg)  # (B, N, A, F)
        style = style[:, None].expand(-1, num_latents, -1)  # (B, N, S)
        style_present = style_present[:, None].expand(-1, num_latents)  # (B, N)
        if lookahead is None:
            lookahead = torch.full((batch,), cfg.audio_lookahead, device=x_t.device)
        per_frame = lookahead[:, None].expand(-1, num_latents)  # (B, N)
        x0, _, _ = self.forward_chunk(x_t, t, windows, audio_present, style, style_present, empty, empty, no_history,
                                      per_frame)
        return x0

    def step(self, x_t, t, audio_window, style, cache: KVCache, audio_present=None, style_present=None,
             lookahead=None):
        """One incremental call: x_t (B, C), t (B,), audio_window (B, A, F), style (B, S), lookahead δ (B,)
        (truncation models; default δa) → x0 (B, C), the cache with this frame appended.

        Keep the returned cache only for a clean frame (``t = CLEAN_TIMESTEP``, x_t = the chosen x0):
        that is how a generated latent becomes history. Noisy calls reuse the old cache.
        """
        batch = x_t.shape[0]
        audio_present = torch.ones(batch) if audio_present is None else audio_present
        style_present = torch.ones(batch) if style_present is None else style_present
        lookahead = torch.full((batch,), self.config.audio_lookahead) if lookahead is None else lookahead
        frame_inputs = (x_t, t, audio_window, audio_present, style, style_present)
        as_chunk = (value[:, None] for value in frame_inputs)  # one new frame: M = 1
        x0, keys, values = self.forward_chunk(*as_chunk, cache.keys, cache.values, cache.length, lookahead[:, None])
        return x0[:, 0], cache.append(keys, values)
