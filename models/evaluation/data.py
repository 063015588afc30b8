"""Real motion for training and checking the frozen evaluation networks, read from the dataset cache.

Every cached full-body take (all datasets; arms-only takes such as SHOW are left out) is turned into
root-relative joint positions per split segment (:mod:`.dataset`'s split rule: paired takes by time,
motion-only takes whole by a hash of the name), with its canonical style label. No augmentation:
the networks learn the data as recorded.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gesturecast.models.dataset.cache import is_full_body, load_take, read_index
from gesturecast.models.evaluation.windows import WindowConfig, pose_channels


@dataclass(frozen=True)
class RealClip:
    name: str
    dataset: str
    style: str
    split: str
    channels: np.ndarray  # (T, J*3) root-relative positions, float32


def real_clips(cache_dir: Path, splits: tuple[str, ...], min_frames: int = WindowConfig().frames) -> list[RealClip]:
    """Every take segment of ``splits`` with at least ``min_frames`` frames, as :class:`RealClip`."""
    clips = []
    for record in filter(is_full_body, read_index(cache_dir)["takes"]):
        segments = [s for s in record["segments"] if s["split"] in splits and s["stop"] - s["start"] >= min_frames]
        if not segments:
            continue
        motion, _ = load_take(cache_dir, record)
        channels = pose_channels(motion.positions())  # (T, J*3)
        clips += [RealClip(record["name"], record["dataset"], record["style"], s["split"],
                           channels[s["start"] : s["stop"]]) for s in segments]
    return clips


def training_summary(clips: list[RealClip]) -> dict:
    """What a network was trained on: datasets, takes, minutes, per-style minutes (for the JSON stamp)."""
    frames_per_minute = 30.0 * 60.0
    styles: dict[str, float] = {}
    for clip in clips:
        styles[clip.style] = styles.get(clip.style, 0.0) + clip.channels.shape[0] / frames_per_minute
    return {
        "datasets": sorted({clip.dataset for clip in clips}),
        "segments": len(clips),
        "minutes": round(sum(c.channels.shape[0] for c in clips) / frames_per_minute, 2),
        "style_minutes": {k: round(v, 2) for k, v in sorted(styles.items())},
    }


def sample_windows(clips: list[RealClip], count: int, frames: int, rng: np.random.Generator) -> np.ndarray:
    """``count`` random windows (count, frames, C), clips drawn in proportion to their usable length."""
    usable = np.array([c.channels.shape[0] - frames + 1 for c in clips], np.float64)
    chosen = rng.choice(len(clips), size=count, p=usable / usable.sum())
    starts = rng.integers(0, usable[chosen].astype(np.int64))
    return np.stack([clips[c].channels[s : s + frames] for c, s in zip(chosen, starts, strict=True)])
