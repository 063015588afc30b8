"""Style classifier: training on a tiny constructed two-style problem, its numpy runtime, and accuracy rules."""

import numpy as np
import pytest

from gesturecast.models.evaluation.convnet import ConvNetConfig
from gesturecast.models.evaluation.data import RealClip
from gesturecast.models.evaluation.style_classifier import (
    DEFAULT_STYLE_CLASSIFIER,
    STYLE_CLASSIFIER_VERSION,
    StyleClassifier,
    classification_report,
)
from gesturecast.models.evaluation.train_networks import EvalTrainConfig, train_style_classifier
from gesturecast.models.evaluation.windows import POSITION_CHANNELS, WindowConfig

FPS = 30.0
FRAMES = 96
WINDOW = WindowConfig(frames=32, stride=16)
TINY_NET = ConvNetConfig(channels=(16, 16), window=WINDOW)
SHARED_POSE = np.linspace(-0.5, 0.5, POSITION_CHANNELS)
CHANNEL_PHASE = np.linspace(0.0, np.pi, POSITION_CHANNELS)
STYLE_FREQUENCY_HZ = {"calm": 0.5, "brisk": 3.0}  # the constructed styles: how fast the joints sway


def swaying_clip(style: str, rng: np.random.Generator) -> RealClip:
    """Joints swaying about one shared pose at the style's frequency, random clip phase and amplitude."""
    t = np.arange(FRAMES) / FPS
    phase = rng.uniform(0, 2 * np.pi) + CHANNEL_PHASE
    amplitude = rng.uniform(0.02, 0.1)
    channels = SHARED_POSE + amplitude * np.sin(2 * np.pi * STYLE_FREQUENCY_HZ[style] * t[:, None] + phase)
    return RealClip(f"{style}", "constructed", style, "train", channels.astype(np.float32))


def test_classifier_learns_a_constructed_problem():
    rng = np.random.default_rng(0)
    labels = tuple(sorted(STYLE_FREQUENCY_HZ))
    train = [swaying_clip(style, rng) for style in labels for _ in range(8)]
    test = [swaying_clip(style, rng) for style in labels for _ in range(4)]
    config = EvalTrainConfig(steps=200, batch_size=16, learning_rate=3e-3)
    net, _ = train_style_classifier(train, labels, TINY_NET, config, progress=False)
    windows = [np.lib.stride_tricks.sliding_window_view(c.channels, WINDOW.frames, axis=0)[:: WINDOW.stride]
               for c in test]  # (N_i, C, frames) each
    predicted = np.argmax(net.forward(np.concatenate(windows).transpose(0, 2, 1)), axis=1)
    truth = np.concatenate([np.full(len(w), labels.index(c.style)) for c, w in zip(test, windows, strict=True)])
    report = classification_report(predicted, truth, labels)
    assert report["balanced_accuracy"] >= 0.9
    assert report["chance"] == 0.5


def test_classification_report_counts():
    report = classification_report(np.array([0, 0, 1, 1]), np.array([0, 1, 1, 1]), ("a", "b"))
    assert report["window_accuracy"] == 0.75
    assert report["per_style_recall"] == {"a": 1.0, "b": pytest.approx(2 / 3)}


def test_committed_classifier_is_stamped_with_held_out_accuracy():
    classifier = StyleClassifier.load()
    assert classifier.version == STYLE_CLASSIFIER_VERSION
    assert DEFAULT_STYLE_CLASSIFIER.stat().st_size < 2 * 1024 * 1024
    assert classifier.net.config.out_dim == len(classifier.labels)
    held_out = classifier.stamp["held_out"]
    assert held_out["split"] == "test" and held_out["windows"] > 0
    assert held_out["balanced_accuracy"] > held_out["chance"]


def test_unknown_style_or_short_clip_scores_nan():
    classifier = StyleClassifier.load()
    still = np.zeros((90, 22, 3))
    assert np.isnan(classifier.accuracy([still], "no-such-style"))
    assert np.isnan(classifier.accuracy([still[:10]], classifier.labels[0]))
