"""Fixed-length motion windows for the frozen evaluation networks (FGD encoder, style classifier).

Both networks see the same input: root-relative canonical joint positions (T, J·3) in metres
(the hips at the origin every frame, so the character's travel and facing do not count, only
its pose and how it moves), cut into windows of ``frames`` frames every ``stride`` frames.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gesturecast.models.evaluation.metrics import root_relative
from gesturecast.models.motion.skeleton import NUM_JOINTS

POSITION_CHANNELS = NUM_JOINTS * 3  # root-relative xyz of every canonical joint


@dataclass(frozen=True)
class WindowConfig:
    frames: int = 64  # 2.1 s at 30 fps: about one gesture phrase
    stride: int = 16


def pose_channels(positions: np.ndarray) -> np.ndarray:
    """World joint positions (T, J, 3) → root-relative channels (T, J·3) float32."""
    return root_relative(positions).reshape(positions.shape[0], -1).astype(np.float32)


def motion_windows(positions: np.ndarray, config: WindowConfig = WindowConfig()) -> np.ndarray:
    """(N, frames, J·3) windows of one clip's positions (T, J, 3); N = 0 when the clip is too short."""
    return channel_windows(pose_channels(positions), config)


def channel_windows(channels: np.ndarray, config: WindowConfig = WindowConfig()) -> np.ndarray:
    """(N, frames, C) windows of one clip's root-relative channels (T, C) (:func:`pose_channels`)."""
    if channels.shape[0] < config.frames:
        return np.zeros((0, config.frames, channels.shape[1]), np.float32)
    starts = range(0, channels.shape[0] - config.frames + 1, config.stride)
    return np.stack([channels[s : s + config.frames] for s in starts])  # (N, frames, C)


def clips_windows(clips: list[np.ndarray], config: WindowConfig = WindowConfig()) -> np.ndarray:
    """Windows of several clips (each (T, J, 3)) stacked into one (N, frames, J·3) array."""
    windows = [motion_windows(clip, config) for clip in clips]
    return np.concatenate(windows) if windows else np.zeros((0, config.frames, POSITION_CHANNELS), np.float32)
