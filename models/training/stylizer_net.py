"""A small learned stylizer, to measure against the fitted one: a causal residual network on content-paired takes.

Input: the styled joints' rotation vectors of a neutral take (T, S·3) and a style's one-hot code; output: the
rotation vectors of the same action in that style, as a residual added to the input. Three causal temporal
convolutions (kernel :data:`KERNEL`, left padding only: no look-ahead, like the stylizer it would replace). The
styled take of an action is not aligned in time with its neutral take, so each pair is first brought to the neutral
take's length by linear resampling (the style's own timing becomes part of what is learned, spread evenly).
Trained with Adam on the mean squared error, full pairs as a batch padded at the end (masked). torch; training only.
"""

from __future__ import annotations

import numpy as np
import torch
from torch import nn

KERNEL = 9
HIDDEN = 64


class CausalStylizer(nn.Module):
    def __init__(self, channels: int, styles: int) -> None:
        super().__init__()
        self.styles = styles
        self.layers = nn.ModuleList([nn.Conv1d(channels + styles, HIDDEN, KERNEL), nn.Conv1d(HIDDEN, HIDDEN, KERNEL),
                                     nn.Conv1d(HIDDEN, channels, 1)])
        nn.init.zeros_(self.layers[-1].weight)  # starts as the identity (no change)
        nn.init.zeros_(self.layers[-1].bias)

    def forward(self, v: torch.Tensor, style: torch.Tensor) -> torch.Tensor:
        """v (B, T, C) rotation vectors, style (B,) indices → styled (B, T, C)."""
        code = nn.functional.one_hot(style, self.styles).float()[:, :, None].expand(-1, -1, v.shape[1])  # (B, L, T)
        x = torch.cat([v.transpose(1, 2), code], dim=1)  # (B, C + L, T)
        for layer in self.layers[:-1]:
            x = nn.functional.gelu(layer(nn.functional.pad(x, (KERNEL - 1, 0))))  # causal: (B, H, T)
        return v + self.layers[-1](x).transpose(1, 2)  # (B, T, C)


def resample(frames: np.ndarray, length: int) -> np.ndarray:
    """(T, C) → (length, C) by linear interpolation over the same span."""
    source = np.linspace(0.0, 1.0, len(frames))
    target = np.linspace(0.0, 1.0, length)
    return np.stack([np.interp(target, source, frames[:, c]) for c in range(frames.shape[1])], axis=1)


def _batch(pairs: list[tuple[np.ndarray, np.ndarray, int]]) -> tuple[torch.Tensor, ...]:
    """Pairs (neutral (T_i, C), styled (T_i, C), style) → padded (B, T, C) inputs, targets, mask (B, T), styles."""
    longest = max(len(n) for n, _, _ in pairs)
    channels = pairs[0][0].shape[1]
    inputs, targets = np.zeros((len(pairs), longest, channels)), np.zeros((len(pairs), longest, channels))
    mask = np.zeros((len(pairs), longest))
    for b, (neutral, styled, _) in enumerate(pairs):
        inputs[b, : len(neutral)], targets[b, : len(neutral)], mask[b, : len(neutral)] = neutral, styled, 1.0
    styles = torch.tensor([style for _, _, style in pairs])
    return torch.tensor(inputs).float(), torch.tensor(targets).float(), torch.tensor(mask).float(), styles


def train_stylizer(pairs: list[tuple[np.ndarray, np.ndarray, int]], styles: int, seed: int, steps: int = 1500,
                   rate: float = 2e-3) -> CausalStylizer:
    """A network trained on (neutral, styled resampled to its length, style index) pairs."""
    torch.manual_seed(seed)
    model = CausalStylizer(pairs[0][0].shape[1], styles)
    inputs, targets, mask, style = _batch(pairs)
    optimizer = torch.optim.Adam(model.parameters(), lr=rate)
    for _ in range(steps):
        error = ((model(inputs, style) - targets) ** 2).sum(dim=-1)  # (B, T)
        loss = (error * mask).sum() / mask.sum()
        optimizer.zero_grad()
        loss.backward()
        optimizer.step()
    return model.eval()


def stylize(model: CausalStylizer, neutral: np.ndarray, style: int) -> np.ndarray:
    """(T, C) rotation vectors of a neutral take → (T, C) in the style."""
    with torch.no_grad():
        out = model(torch.tensor(neutral[None]).float(), torch.tensor([style]))  # (1, T, C)
    return out[0].numpy().astype(np.float64)
