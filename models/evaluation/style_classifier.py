"""The frozen motion style classifier (numpy only): which style a motion window was acted in.

Trained on real labelled motion (Bandai Namco styles, ZeroEGGS and BEAT2 takes, labels mapped to
the canonical vocabulary of :mod:`.styles`), see :mod:`.eval_training`. Applied to generated motion,
the share of windows classified as the requested style is the style accuracy; compare it with the
classifier's accuracy on held-out real motion (in the weights' stamp) and with chance (1 / labels).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gesturecast.models.evaluation.convnet import EvalConvNet, read_stamp
from gesturecast.models.evaluation.fgd_encoder import EVAL_WEIGHTS_DIR
from gesturecast.models.evaluation.windows import clips_windows

STYLE_CLASSIFIER_VERSION = 1
DEFAULT_STYLE_CLASSIFIER = EVAL_WEIGHTS_DIR / f"style_classifier_v{STYLE_CLASSIFIER_VERSION}.npz"


@dataclass(frozen=True)
class StyleClassifier:
    net: EvalConvNet
    labels: tuple[str, ...]
    stamp: dict

    @classmethod
    def load(cls, path: Path | str = DEFAULT_STYLE_CLASSIFIER) -> StyleClassifier:
        stamp = read_stamp(path)
        return cls(EvalConvNet.load(path), tuple(stamp["labels"]), stamp)

    @property
    def version(self) -> int:
        return int(self.stamp["version"])

    def predict_windows(self, windows: np.ndarray) -> np.ndarray:
        """Label indices (N,) of windows (N, frames, J·3)."""
        return np.argmax(self.net.forward(windows), axis=1)

    def predict(self, clips: list[np.ndarray]) -> np.ndarray:
        """Label indices (N,) of every window of clips of positions (T, J, 3)."""
        return self.predict_windows(clips_windows(clips, self.net.config.window))

    def accuracy(self, clips: list[np.ndarray], style: str) -> float:
        """Share of the clips' windows classified as ``style``; NaN without windows or for an unknown style."""
        predicted = self.predict(clips)
        if style not in self.labels or predicted.size == 0:
            return float("nan")
        return float(np.mean(predicted == self.labels.index(style)))


def classification_report(predicted: np.ndarray, truth: np.ndarray, labels: tuple[str, ...]) -> dict:
    """Window accuracy, balanced accuracy (mean per-class recall) and per-class recall of index arrays (N,)."""
    recall = {labels[k]: float(np.mean(predicted[truth == k] == k)) for k in np.unique(truth)}
    return {
        "window_accuracy": float(np.mean(predicted == truth)),
        "balanced_accuracy": float(np.mean(list(recall.values()))),
        "chance": 1.0 / len(labels),
        "per_style_recall": recall,
        "windows": int(truth.size),
    }
