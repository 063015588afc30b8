"""Vector quantizer with EMA codebook updates and dead-code reset (torch).

- Nearest-neighbour quantization, straight-through gradients and the commitment loss
  ‖z − sg[e]‖² — van den Oord et al. 2017 (VQ-VAE), eq. 3.
- Codebook learned by exponential moving averages of assignment counts and sums instead of a
  codebook loss — Razavi et al. 2019 (VQ-VAE-2), appendix A / van den Oord 2017 appendix A.1, with
  Laplace smoothing of the counts.
- Codes whose EMA count falls below a threshold are re-seeded with random encoder outputs of the
  current batch (Dhariwal et al. 2020, Jukebox, §2.2 "random restarts"; Williams et al. 2020).
- On the first training batch the codebook is seeded from that batch's encoder outputs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch
from torch import nn
from torch.nn import functional as F

LAPLACE_EPSILON = 1e-5
RESEEDED_COUNT = 1.0  # EMA count given to a re-seeded code: "as if used once"


@dataclass
class QuantizerOutput:
    quantized: torch.Tensor  # (..., C) code vectors, straight-through gradient to the input
    codes: torch.Tensor  # (...) int64 code indices
    commitment_loss: torch.Tensor  # () mean ‖z − sg[e]‖²


class EMAQuantizer(nn.Module):
    """Codebook of ``num_codes`` vectors of size ``dim``; quantizes the last axis of its input."""

    def __init__(self, num_codes: int, dim: int, decay: float, dead_code_threshold: float):
        super().__init__()
        self.decay = decay
        self.dead_code_threshold = dead_code_threshold
        codebook = torch.randn(num_codes, dim)
        self.register_buffer("codebook", codebook)  # (K, C)
        self.register_buffer("ema_count", torch.full((num_codes,), RESEEDED_COUNT))  # (K,)
        self.register_buffer("ema_sum", codebook.clone())  # (K, C)
        self.register_buffer("initialized", torch.tensor(False))

    @property
    def num_codes(self) -> int:
        return self.codebook.shape[0]

    def nearest_codes(self, z: torch.Tensor) -> torch.Tensor:
        """Index of the nearest code (Euclidean) for each vector: (..., C) -> (...)."""
        flat = z.reshape(-1, z.shape[-1])  # (N, C)
        distances = (
            flat.pow(2).sum(1, keepdim=True) - 2.0 * flat @ self.codebook.T + self.codebook.pow(2).sum(1)
        )  # (N, K)
        return distances.argmin(dim=1).reshape(z.shape[:-1])

    def lookup(self, codes: torch.Tensor) -> torch.Tensor:
        """Code vectors for indices: (...) -> (..., C)."""
        return F.embedding(codes, self.codebook)

    def forward(self, z: torch.Tensor) -> QuantizerOutput:
        """Quantize z (..., C); in training mode also update the codebook (after quantizing)."""
        if self.training and not bool(self.initialized):
            self._seed_codebook(z.detach().reshape(-1, z.shape[-1]))
        codes = self.nearest_codes(z.detach())  # (...)
        quantized = self.lookup(codes)  # (..., C)
        commitment = F.mse_loss(z, quantized.detach())
        if self.training:
            self._ema_update(z.detach().reshape(-1, z.shape[-1]), codes.reshape(-1))
        return QuantizerOutput(quantized=z + (quantized - z).detach(), codes=codes, commitment_loss=commitment)

    @torch.no_grad()
    def _random_vectors(self, flat: torch.Tensor, count: int) -> torch.Tensor:
        index = torch.randint(0, flat.shape[0], (count,), device=flat.device)
        return flat[index]  # (count, C)

    @torch.no_grad()
    def _seed_codebook(self, flat: torch.Tensor) -> None:
        self.codebook.copy_(self._random_vectors(flat, self.num_codes))
        self.ema_sum.copy_(self.codebook * RESEEDED_COUNT)
        self.ema_count.fill_(RESEEDED_COUNT)
        self.initialized.fill_(True)

    @torch.no_grad()
    def _ema_update(self, flat: torch.Tensor, codes: torch.Tensor) -> None:
        one_hot = F.one_hot(codes, self.num_codes).type(flat.dtype)  # (N, K)
        self.ema_count.mul_(self.decay).add_(one_hot.sum(0), alpha=1.0 - self.decay)
        self.ema_sum.mul_(self.decay).add_(one_hot.T @ flat, alpha=1.0 - self.decay)
        total = self.ema_count.sum()
        smoothed = (self.ema_count + LAPLACE_EPSILON) / (total + self.num_codes * LAPLACE_EPSILON) * total  # (K,)
        self.codebook.copy_(self.ema_sum / smoothed.unsqueeze(1))
        self._reset_dead_codes(flat)

    @torch.no_grad()
    def _reset_dead_codes(self, flat: torch.Tensor) -> None:
        dead = self.ema_count < self.dead_code_threshold  # (K,)
        count = int(dead.sum())
        if count == 0:
            return
        fresh = self._random_vectors(flat, count)  # (count, C)
        self.codebook[dead] = fresh
        self.ema_sum[dead] = fresh * RESEEDED_COUNT
        self.ema_count[dead] = RESEEDED_COUNT


def codebook_usage(codes: np.ndarray, num_codes: int) -> dict[str, float]:
    """Perplexity exp(−Σ p log p) of the code histogram and the fraction of codes used at least once."""
    counts = np.bincount(np.asarray(codes).ravel(), minlength=num_codes).astype(np.float64)
    probabilities = counts / max(counts.sum(), 1.0)
    nonzero = probabilities[probabilities > 0]
    return {
        "perplexity": float(np.exp(-(nonzero * np.log(nonzero)).sum())),
        "used_fraction": float((counts > 0).mean()),
    }
