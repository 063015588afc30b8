"""Per-column feature normalisation, fitted at training time and stored with the model.

``FeatureStats.fit`` accumulates float64 sums over any number of takes (no concatenation);
``apply`` maps features to zero mean / unit variance; ``to_dict`` / ``from_dict`` round-trip
through plain lists for a checkpoint. The speaking flag column is left as 0/1 (mean 0, std 1).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from gesturecast.models.audio.streaming import FeatureConfig

MIN_STD = 1e-3  # constant columns (e.g. digital silence) are not blown up
UNNORMALISED_COLUMNS = ("speaking",)


@dataclass(frozen=True)
class FeatureStats:
    mean: np.ndarray  # (F,) float32
    std: np.ndarray  # (F,) float32

    @classmethod
    def fit(cls, takes: Iterable[np.ndarray], config: FeatureConfig | None = None) -> FeatureStats:
        """Takes: (T_i, F) feature arrays → statistics over all their frames."""
        config = config or FeatureConfig()
        count = 0
        total = np.zeros(config.num_features)
        total_sq = np.zeros(config.num_features)
        for features in takes:
            values = features.astype(np.float64)  # (T, F)
            count += values.shape[0]
            total += values.sum(axis=0)
            total_sq += (values**2).sum(axis=0)
        if count == 0:
            raise ValueError("cannot fit feature statistics on zero frames")
        mean = total / count
        std = np.sqrt(np.maximum(total_sq / count - mean**2, 0.0))
        std = np.maximum(std, MIN_STD)
        for name in UNNORMALISED_COLUMNS:
            mean[config.layout[name]] = 0.0
            std[config.layout[name]] = 1.0
        return cls(mean.astype(np.float32), std.astype(np.float32))

    def apply(self, features: np.ndarray) -> np.ndarray:
        """(T, F) → (T, F) float32 normalised."""
        return ((features - self.mean) / self.std).astype(np.float32)

    def invert(self, normalised: np.ndarray) -> np.ndarray:
        return (normalised * self.std + self.mean).astype(np.float32)

    def to_dict(self) -> dict[str, list[float]]:
        return {"mean": self.mean.tolist(), "std": self.std.tolist()}

    @classmethod
    def from_dict(cls, values: dict[str, list[float]]) -> FeatureStats:
        return cls(np.asarray(values["mean"], np.float32), np.asarray(values["std"], np.float32))
