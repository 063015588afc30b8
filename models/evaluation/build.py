"""Train, freeze and stamp the evaluation networks from the dataset cache (`gesturecast eval-train`).

Writes ``fgd_encoder_v{N}.npz`` and ``style_classifier_v{N}.npz`` with a JSON stamp each (version,
training data, steps, final loss, and for the classifier its labels and held-out accuracy). The
train split of every dataset trains; the test split (held-out takes and take tails) is only
measured. The versions are the constants in :mod:`.fgd_encoder` / :mod:`.style_classifier`:
bump one to replace its file on purpose.
"""

from __future__ import annotations

import datetime
import logging
from dataclasses import asdict
from pathlib import Path

import numpy as np

from gesturecast.models.evaluation.convnet import ConvNetConfig, EvalConvNet, write_stamp
from gesturecast.models.evaluation.data import RealClip, real_clips, training_summary
from gesturecast.models.evaluation.fgd_encoder import FGD_ENCODER_VERSION
from gesturecast.models.evaluation.frechet import frechet_distance
from gesturecast.models.evaluation.style_classifier import STYLE_CLASSIFIER_VERSION, classification_report
from gesturecast.models.evaluation.train_networks import EvalTrainConfig, train_fgd_encoder, train_style_classifier
from gesturecast.models.evaluation.windows import channel_windows

LOGGER = logging.getLogger(__name__)


def _windows_of(clips: list[RealClip], net: EvalConvNet) -> list[np.ndarray]:
    """Per clip, its evaluation windows (N_i, frames, C) (clips stored as channels, not positions)."""
    return [channel_windows(c.channels, net.config.window) for c in clips]


def _stamp(
    version: int, train: list[RealClip], config: EvalTrainConfig, net_config: ConvNetConfig, loss: float
) -> dict:
    return {
        "version": version,
        "created": datetime.date.today().isoformat(),
        "training_data": training_summary(train),
        "train_config": asdict(config),
        "network": asdict(net_config),
        "final_training_loss": loss,
    }


def build_fgd_encoder(train: list[RealClip], test: list[RealClip], out_dir: Path, config: EvalTrainConfig,
                      progress: bool = True) -> Path:
    net_config = ConvNetConfig()
    net, loss = train_fgd_encoder(train, net_config, config, progress)
    path = net.save(out_dir / f"fgd_encoder_v{FGD_ENCODER_VERSION}.npz")
    train_features = net.forward(np.concatenate(_windows_of(train, net)))  # (N, D)
    test_features = net.forward(np.concatenate(_windows_of(test, net)))  # (M, D)
    stamp = _stamp(FGD_ENCODER_VERSION, train, config, net_config, loss)
    stamp["fgd_train_vs_test_real"] = frechet_distance(train_features, test_features)
    write_stamp(path, stamp)
    return path


def build_style_classifier(train: list[RealClip], test: list[RealClip], out_dir: Path, config: EvalTrainConfig,
                           progress: bool = True) -> Path:
    labels = tuple(sorted({clip.style for clip in train}))
    net_config = ConvNetConfig()
    net, loss = train_style_classifier(train, labels, net_config, config, progress)
    path = net.save(out_dir / f"style_classifier_v{STYLE_CLASSIFIER_VERSION}.npz")
    known = [clip for clip in test if clip.style in labels]
    windows = _windows_of(known, net)
    truth = np.concatenate([np.full(len(w), labels.index(c.style)) for c, w in zip(known, windows, strict=True)])
    predicted = np.argmax(net.forward(np.concatenate(windows)), axis=1)  # (N,)
    stamp = _stamp(STYLE_CLASSIFIER_VERSION, train, config, net_config, loss)
    stamp["labels"] = list(labels)
    stamp["held_out"] = {"split": "test", **training_summary(known), **classification_report(predicted, truth, labels)}
    write_stamp(path, stamp)
    return path


def build_eval_models(cache_dir: Path, out_dir: Path, config: EvalTrainConfig, progress: bool = True) -> list[Path]:
    """Train both networks on the cache's train split, measure on its test split, write weights + stamps."""
    out_dir.mkdir(parents=True, exist_ok=True)
    train = real_clips(cache_dir, ("train",))
    test = real_clips(cache_dir, ("test",))
    LOGGER.info("eval networks: %d train and %d test segments", len(train), len(test))
    return [build_fgd_encoder(train, test, out_dir, config, progress),
            build_style_classifier(train, test, out_dir, config, progress)]
