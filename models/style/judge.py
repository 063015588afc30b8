"""The style judge: which style a motion window shows, read from what any speech gesture shares with any action.

It judges a *set* of clips of the same content (one action, or one speech) in at least :data:`MIN_STYLES` styles,
and reads how each clip differs from the others: every window's features (``descriptors.window_features``: upper
body, posture, tempo; no legs, no root travel; speeds, tempo, sharpness and spreads as logarithms, so that a style
that doubles a speed moves it as far in a slow action as in a quick one) less the content's reference, the mean over
the set's clips of each clip's mean features, and divided by the content's own spread, the deviation of all the set's
windows, per feature (no labels used). A bow and a speech gesture differ far more than two
styles of either, and a run's styles differ more than a bow's; centred and scaled on its content, a style is what is
left. A multinomial logistic regression on these features, standardised with the training windows' mean and
deviation, labels each window. It is trained by
``gesturecast style-fit`` so that it must generalise across content: its accuracy is measured with whole actions
held out (leave-one-content-out over the Bandai dataset-1 actions), and the shipped judge is then fitted on all of
them. numpy only.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gesturecast.models.style.descriptors import JUDGE_FEATURES, window_features
from gesturecast.models.style.fitted_file import read_fitted, write_fitted

JUDGE_FORMAT = "gesturecast-style-judge-2"
JUDGED_STYLES = ("neutral", "happy", "angry", "sad", "old", "tired", "proud")
MIN_STYLES = 3  # a content's reference and spread need this many styles of it
LOGGED = np.array([JUDGE_FEATURES.index(name) for name in ("wrist_speed", "wrist_speed_sd", "tempo", "wrist_height_sd",
                                                           "head_pitch_sd", "head_speed", "sharpness")])
LOG_FLOOR = 1e-4  # below any real speed, tempo or spread


@dataclass(frozen=True)
class StyleJudge:
    """labels (L,), feature mean / scale (F,), weights (F, L), bias (L,)."""

    labels: tuple[str, ...]
    mean: np.ndarray
    scale: np.ndarray
    weights: np.ndarray
    bias: np.ndarray

    def probabilities(self, features: np.ndarray) -> np.ndarray:
        """(W, L) style probabilities of window features (W, F)."""
        logits = ((features - self.mean) / self.scale) @ self.weights + self.bias  # (W, L)
        logits -= logits.max(axis=1, keepdims=True)
        odds = np.exp(logits)
        return odds / odds.sum(axis=1, keepdims=True)

    def predict(self, features: np.ndarray) -> list[str]:
        return [self.labels[i] for i in np.argmax(self.probabilities(features), axis=1)]

    def judge_set(self, clips: list[tuple[np.ndarray, np.ndarray]], fps: float) -> list[list[str]]:
        """The style of every window of each clip (rotations (T, J, 4), hips (T, 3)) of one content's set."""
        return [self.predict(features) for features in centred([window_features(r, root, fps) for r, root in clips])]

    def save(self, path: Path, meta: dict) -> None:
        data = {"format": JUDGE_FORMAT, "features": list(JUDGE_FEATURES), "labels": list(self.labels), **meta,
                "mean": self.mean.tolist(), "scale": self.scale.tolist(), "weights": self.weights.tolist(),
                "bias": self.bias.tolist()}
        write_fitted(path, data)

    @staticmethod
    def load(path: Path) -> StyleJudge:
        data = read_fitted(path, "style judge", JUDGE_FORMAT, "features", JUDGE_FEATURES)
        return StyleJudge(tuple(data["labels"]), *(np.asarray(data[key]) for key in ("mean", "scale", "weights",
                                                                                     "bias")))


def logged_features(features: np.ndarray) -> np.ndarray:
    """A copy of window features (W, F) with the :data:`LOGGED` ones as logarithms."""
    out = features.copy()
    out[:, LOGGED] = np.log(np.maximum(out[:, LOGGED], LOG_FLOOR))
    return out


def centred(clips: list[np.ndarray]) -> list[np.ndarray]:
    """Window features (W_i, F) of one content's clips (at least :data:`MIN_STYLES`, one per style) as the judge
    reads them: logged where :data:`LOGGED`, less the content reference, over the content's spread (module
    docstring)."""
    if len(clips) < MIN_STYLES:
        raise ValueError(f"the style judge reads a set of at least {MIN_STYLES} clips of one content, got {len(clips)}")
    logged = [logged_features(features) for features in clips]
    reference = np.mean([features.mean(axis=0) for features in logged], axis=0)  # (F,)
    spread = np.concatenate(logged).std(axis=0) + 1e-6  # (F,) the deviation of all the set's windows
    return [(features - reference) / spread for features in logged]


def train_judge(features: np.ndarray, labels: np.ndarray, names: tuple[str, ...], l2: float = 1e-2,
                steps: int = 600, rate: float = 0.5) -> StyleJudge:
    """A judge fitted to windows (W, F) with label indices (W,) into ``names``: full-batch gradient descent on the
    class-balanced cross-entropy plus ``l2``·|weights|²."""
    mean, scale = features.mean(axis=0), features.std(axis=0) + 1e-6
    x = (features - mean) / scale  # (W, F)
    onehot = np.eye(len(names))[labels]  # (W, L)
    counts = np.maximum(onehot.sum(axis=0), 1.0)  # (L,)
    balance = (onehot / counts).sum(axis=1) * len(x) / len(names)  # (W,) each class weighs the same
    weights, bias = np.zeros((x.shape[1], len(names))), np.zeros(len(names))
    for _ in range(steps):
        logits = x @ weights + bias
        logits -= logits.max(axis=1, keepdims=True)
        p = np.exp(logits)
        p /= p.sum(axis=1, keepdims=True)
        error = (p - onehot) * balance[:, None] / len(x)  # (W, L)
        weights -= rate * (x.T @ error + 2.0 * l2 * weights)
        bias -= rate * error.sum(axis=0)
    return StyleJudge(names, mean, scale, weights, bias)
