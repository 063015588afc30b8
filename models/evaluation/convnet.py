"""The frozen evaluation network, in numpy: a 1D convolution stack over a motion window, mean-pooled
over time, then a linear head. The FGD encoder (head = feature vector) and the style classifier
(head = class logits) are two weight sets of this one architecture; they are trained with torch
(:mod:`.eval_training`) and stored as ``.npz`` so that evaluating needs no torch.

Layer i: ``h = leaky_relu(conv1d(h, W_i, stride, padding) + b_i)``; then ``y = mean_t(h) · Hᵀ + c``.
The input is normalised first with the mean / std saved beside the weights.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from gesturecast.models.evaluation.windows import POSITION_CHANNELS, WindowConfig

CONFIG_KEY = "config_json"
STAT_KEYS = ("input_mean", "input_std")


@dataclass(frozen=True)
class ConvNetConfig:
    in_channels: int = POSITION_CHANNELS
    channels: tuple[int, ...] = (64, 128, 128)
    kernel: int = 4
    stride: int = 2
    out_dim: int = 32
    negative_slope: float = 0.2
    window: WindowConfig = WindowConfig()

    @property
    def padding(self) -> int:
        return (self.kernel - self.stride) // 2

    def to_json(self) -> str:
        return json.dumps(asdict(self))

    @classmethod
    def from_json(cls, text: str) -> ConvNetConfig:
        values = json.loads(text)
        values["channels"] = tuple(values["channels"])
        values["window"] = WindowConfig(**values["window"])
        return cls(**values)


def conv1d(x: np.ndarray, weight: np.ndarray, bias: np.ndarray, stride: int, padding: int) -> np.ndarray:
    """Cross-correlation as torch.nn.Conv1d: x (N, T, Cin), weight (Cout, Cin, k) → (N, T', Cout)."""
    padded = np.pad(x, ((0, 0), (padding, padding), (0, 0)))  # (N, T + 2p, Cin)
    patches = sliding_window_view(padded, weight.shape[2], axis=1)[:, ::stride]  # (N, T', Cin, k)
    return np.einsum("ntck,ock->nto", patches, weight, optimize=True) + bias  # (N, T', Cout)


@dataclass(frozen=True)
class EvalConvNet:
    config: ConvNetConfig
    weights: dict[str, np.ndarray]

    @classmethod
    def load(cls, path: Path | str) -> EvalConvNet:
        with np.load(path) as data:
            arrays = {key: data[key] for key in data.files}
        config = ConvNetConfig.from_json(str(arrays.pop(CONFIG_KEY)))
        return cls(config, arrays)

    def save(self, path: Path | str) -> Path:
        np.savez(path, **{CONFIG_KEY: np.str_(self.config.to_json())}, **self.weights)
        return Path(path)

    def forward(self, windows: np.ndarray) -> np.ndarray:
        """Windows (N, frames, C) → outputs (N, out_dim) float64."""
        h = (windows.astype(np.float64) - self.weights["input_mean"]) / self.weights["input_std"]  # (N, T, C)
        for i in range(len(self.config.channels)):
            h = conv1d(h, self.weights[f"conv{i}.weight"], self.weights[f"conv{i}.bias"],
                       self.config.stride, self.config.padding)  # (N, T / 2^(i+1), C_i)
            h = np.where(h > 0.0, h, self.config.negative_slope * h)
        pooled = h.mean(axis=1)  # (N, C_last)
        return pooled @ self.weights["head.weight"].T + self.weights["head.bias"]  # (N, out_dim)


def stamp_path(weights_path: Path | str) -> Path:
    """The JSON stamp beside a weights file (version, training data, steps, measured scores)."""
    return Path(weights_path).with_suffix(".json")


def write_stamp(weights_path: Path | str, stamp: dict) -> Path:
    path = stamp_path(weights_path)
    path.write_text(json.dumps(stamp, indent=1) + "\n", encoding="utf-8")
    return path


def read_stamp(weights_path: Path | str) -> dict:
    path = stamp_path(weights_path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: the stamp of {weights_path} is missing")
    return json.loads(path.read_text(encoding="utf-8"))
