"""Causal local (windowed) self-attention with an explicit key/value cache.

Each query frame attends to itself and at most ``window`` past frames (the "cross-local attention"
of DiffuseStyleGesture §3.2, made causal as in GestureDiffuCLIP's autoregressive denoiser), so the
cache holds ``window`` frames and the cost per new frame is constant on an arbitrarily long stream.
Positions enter only as a learned per-head bias on the distance ``0..window`` (relative position,
Shaw et al. 2018), so cached keys never need re-encoding.

Scaled dot-product attention, Vaswani et al. 2017 eq. (1): softmax(QKᵀ/√d + bias) V.
"""

from __future__ import annotations

import math

import torch
from torch import nn

AttentionMask = tuple[torch.Tensor, torch.Tensor]  # distance (M, K) int64, valid (B, 1, M, K) bool


def local_causal_mask(num_new: int, cache_size: int, cache_len: torch.Tensor, window: int) -> AttentionMask:
    """Distances and validity of every (query, key) pair.

    Keys are ``cache_size`` cached slots followed by the ``num_new`` new frames; cached slot ``s`` sits
    ``cache_size - s`` frames before the first new frame; only the last ``cache_len[b]`` slots are valid.
    Returns ``distance`` (M, K) int64 clamped to ``[0, window]`` and ``valid`` (B, 1, M, K) bool.
    """
    device = cache_len.device
    query_pos = torch.arange(num_new, device=device)  # (M,)
    key_pos = torch.arange(cache_size + num_new, device=device) - cache_size  # (K,)
    distance = query_pos[:, None] - key_pos[None, :]  # (M, K)
    in_window = (distance >= 0) & (distance <= window)  # (M, K)
    slot = torch.arange(cache_size + num_new, device=device)  # (K,)
    key_filled = slot[None, :] >= (cache_size - cache_len[:, None])  # (B, K)
    valid = in_window[None, None] & key_filled[:, None, None, :]  # (B, 1, M, K)
    return distance.clamp(0, window), valid


class LocalCausalAttention(nn.Module):
    def __init__(self, width: int, num_heads: int, window: int):
        super().__init__()
        self.num_heads = num_heads
        self.head_dim = width // num_heads
        self.qkv = nn.Linear(width, 3 * width)
        self.out = nn.Linear(width, width)
        self.distance_bias = nn.Parameter(torch.zeros(num_heads, window + 1))  # (H, W+1)

    def forward(
        self, x: torch.Tensor, cache_k: torch.Tensor, cache_v: torch.Tensor, mask: AttentionMask
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """x (B, M, D); cache_k/v (B, H, Wc, Dh); mask from :func:`local_causal_mask` (computed once for all
        layers) → out (B, M, D), new k, v (B, H, M, Dh)."""
        batch, num_new, width = x.shape
        q, k, v = self.qkv(x).split(width, dim=-1)  # 3 × (B, M, D)
        q, k, v = (z.reshape(batch, num_new, self.num_heads, self.head_dim).transpose(1, 2) for z in (q, k, v))
        keys = torch.cat([cache_k, k], dim=2)  # (B, H, Wc+M, Dh)
        values = torch.cat([cache_v, v], dim=2)  # (B, H, Wc+M, Dh)
        distance, valid = mask
        scores = q @ keys.transpose(-1, -2) / math.sqrt(self.head_dim)  # (B, H, M, Wc+M)
        scores = scores + self.distance_bias[:, distance]  # (B, H, M, Wc+M)
        scores = scores.masked_fill(~valid, float("-inf"))
        attended = scores.softmax(dim=-1) @ values  # (B, H, M, Dh)
        attended = attended.transpose(1, 2).reshape(batch, num_new, width)  # (B, M, D)
        return self.out(attended), k, v
