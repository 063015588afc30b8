"""Beat consistency between speech onsets and motion beats (BEAT / EMAGE "BC").

Liu et al. 2022, "BEAT: A Large-Scale Semantic and Emotional Multi-Modal Dataset for
Conversational Gestures Synthesis" (Sec. 5, Beat Consistency Score), adapted from the BeatAlign
score of Li et al. 2021, "AI Choreographer" (AIST++). As in the released BEAT/EMAGE evaluation
code (``alignment``: sigma 0.3 s, minima order 7 at 30 fps, 2 s masked at each end):

- motion beats of upper-body joint j: frames where its speed v_j(t) (central differences) is a
  strict local minimum within ±`minima_order` frames and v_j(t) > `min_relative_speed` · v̄_j,
  with v̄_j the joint's mean speed (EMAGE: the training set's; here the clip's own by default);
- speech onsets A: ``librosa.onset.onset_detect`` on the audio (hop 512), in seconds;
- per joint: BC_j = (1/|A|) Σ_{a∈A} exp(−min_{b∈B_j} (a − b)² / (2σ²)), σ = 0.3 s;
- BC = mean over the upper-body joints. Onsets and beats within `skip_s` of either end are ignored.

Note the direction: the released code averages over speech onsets (each onset looks for its
nearest motion beat); the AIST++ paper averages over kinematic beats. `beat_alignment` computes
either direction from its arguments. A joint without beats scores 0; a window without onsets
gives NaN.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from gesturecast.models.motion.skeleton import CANONICAL, Skeleton

# EMAGE's 13 upper-body joints (SMPL-X spine1-3, neck, collars, head, shoulders, elbows, wrists)
UPPER_BODY_JOINTS = (
    "Spine", "Chest", "UpperChest", "Neck", "Head",
    "LeftShoulder", "LeftUpperArm", "LeftLowerArm", "LeftHand",
    "RightShoulder", "RightUpperArm", "RightLowerArm", "RightHand",
)  # fmt: skip
ONSET_HOP_LENGTH = 512  # librosa's default hop, as in the BEAT/EMAGE evaluation


@dataclass(frozen=True)
class BeatConsistencyConfig:
    sigma_s: float = 0.3  # width of the Gaussian tolerance, seconds
    skip_s: float = 2.0  # ignored at the start and at the end of the clip, seconds
    minima_order: int = 7  # a beat is the lowest speed within this many frames on each side
    min_relative_speed: float = 0.3  # beats need speed above this fraction of the joint's mean speed
    joints: tuple[str, ...] = UPPER_BODY_JOINTS


def speech_onsets(audio: np.ndarray, sample_rate: int) -> np.ndarray:
    """Onset times (seconds) of mono audio with librosa's spectral-flux onset detector."""
    import librosa  # evaluation-only dependency, imported when used

    return librosa.onset.onset_detect(
        y=np.asarray(audio, dtype=np.float32), sr=sample_rate, hop_length=ONSET_HOP_LENGTH, units="time"
    )


def joint_speeds(positions: np.ndarray, fps: float) -> np.ndarray:
    """Speed of every joint (T, J) in units/s: central differences inside, one-sided at the ends."""
    return np.linalg.norm(np.gradient(positions, 1.0 / fps, axis=0), axis=-1)


def motion_beats(speed: np.ndarray, fps: float, config: BeatConsistencyConfig, mean_speed: float) -> np.ndarray:
    """Times (s) of the beats in one joint's speed curve (T,) (see the module docstring)."""
    from scipy.signal import argrelextrema  # here, not at the top: the CLI's help imports this module (2 s)

    minima = argrelextrema(speed, np.less, order=config.minima_order)[0]
    moving = speed[minima] > config.min_relative_speed * mean_speed
    return minima[moving] / fps


def beat_alignment(query_times: np.ndarray, reference_times: np.ndarray, sigma: float) -> float:
    """(1/|Q|) Σ_{q∈Q} exp(−min_{r∈R} (q − r)² / (2σ²)); 0 when R is empty, NaN when Q is empty."""
    if len(query_times) == 0:
        return float("nan")
    if len(reference_times) == 0:
        return 0.0
    nearest = np.abs(np.asarray(query_times)[:, None] - np.asarray(reference_times)[None, :]).min(axis=1)  # (Q,)
    return float(np.mean(np.exp(-(nearest**2) / (2.0 * sigma**2))))


def beat_consistency(
    positions: np.ndarray,
    fps: float,
    onset_times: np.ndarray,
    config: BeatConsistencyConfig | None = None,
    skeleton: Skeleton = CANONICAL,
    reference_mean_speed: Sequence[float] | None = None,
) -> float:
    """BC of joint positions (T, J, 3) against speech onsets (s), in [0, 1] (1: every onset on a beat).

    reference_mean_speed: per upper-body joint mean speed of real data (EMAGE's normalisation);
    by default each joint's mean speed over this clip.
    """
    config = config or BeatConsistencyConfig()
    joints = [skeleton.index(name) for name in config.joints]
    speeds = joint_speeds(positions[:, joints], fps)  # (T, U)
    means = speeds.mean(axis=0) if reference_mean_speed is None else np.asarray(reference_mean_speed)
    duration = positions.shape[0] / fps
    window = (config.skip_s, duration - config.skip_s)

    def inside(times: np.ndarray) -> np.ndarray:
        return times[(times >= window[0]) & (times <= window[1])]

    onsets = inside(np.asarray(onset_times, dtype=np.float64))
    scores = [
        beat_alignment(onsets, inside(motion_beats(speeds[:, u], fps, config, means[u])), config.sigma_s)
        for u in range(len(joints))
    ]
    return float(np.mean(scores))
