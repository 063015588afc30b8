"""Does the motion follow the speech? Correlation of upper-body joint speed with speech energy.

For one clip (positions (T, J, 3) at ``fps``, mono audio at ``sample_rate``):

- speech energy e(t): RMS of motion frame t's own audio samples, in dB, floored at ``floor_db``
  (digital silence of synthetic voices would otherwise dominate the statistics);
- motion activity v(t): mean speed over the upper-body joints (the beat-consistency set) of the
  root-relative joint positions (walking does not count as gesturing);
- both smoothed with a centred moving average of ``smooth_s`` (syllable-scale detail is what
  beat consistency measures; this measures the slower "moves while talking, rests in pauses");
- Pearson correlation r(ℓ) between e(t) and v(t + ℓ) over the overlap, for every lag
  |ℓ| ≤ ``max_lag_s`` (ℓ > 0: the motion follows the speech). Reported: the best r and its lag,
  and r(0). The first and last ``skip_s`` are ignored (stream start-up).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gesturecast.models.audio.dsp import frame_boundary, segment_rms_db
from gesturecast.models.evaluation.beat_consistency import UPPER_BODY_JOINTS, joint_speeds
from gesturecast.models.evaluation.metrics import root_relative
from gesturecast.models.motion.skeleton import CANONICAL, Skeleton


@dataclass(frozen=True)
class FollowingConfig:
    max_lag_s: float = 0.5
    smooth_s: float = 0.5
    floor_db: float = -60.0
    skip_s: float = 0.5


@dataclass(frozen=True)
class Following:
    best_correlation: float
    best_lag_s: float  # > 0: motion after speech
    zero_lag_correlation: float

    def to_dict(self) -> dict:
        return {"r_best": round(self.best_correlation, 4), "lag_s": round(self.best_lag_s, 3),
                "r_lag0": round(self.zero_lag_correlation, 4)}


def frame_energy_db(audio: np.ndarray, sample_rate: int, fps: float, num_frames: int, floor_db: float) -> np.ndarray:
    """(N,) audio → (num_frames,) RMS dB per motion frame (frames past the audio's end are at the floor)."""
    fps = int(round(fps))
    available = min(num_frames, len(audio) * fps // sample_rate)
    bounds = frame_boundary(np.arange(available + 1), sample_rate, fps)  # (T' + 1,)
    energy = np.full(num_frames, floor_db)
    energy[:available] = np.maximum(segment_rms_db(np.asarray(audio), bounds), floor_db)
    return energy


def upper_body_speed(positions: np.ndarray, fps: float, skeleton: Skeleton = CANONICAL,
                     joints: tuple[str, ...] = UPPER_BODY_JOINTS) -> np.ndarray:
    """(T, J, 3) → (T,) mean speed of the upper-body joints (or of ``joints``) relative to the root (Hips)."""
    relative = root_relative(positions)  # (T, J, 3)
    joints = [skeleton.index(name) for name in joints]
    return joint_speeds(relative[:, joints], fps).mean(axis=1)


def moving_average(values: np.ndarray, width: int) -> np.ndarray:
    """Centred moving average of odd ``width`` (edges: mean of the available values)."""
    if width <= 1:
        return values
    kernel = np.ones(width)
    return np.convolve(values, kernel, mode="same") / np.convolve(np.ones_like(values), kernel, mode="same")


def _pearson(a: np.ndarray, b: np.ndarray) -> float:
    a, b = a - a.mean(), b - b.mean()
    scale = np.sqrt((a**2).sum() * (b**2).sum())
    return float((a * b).sum() / scale) if scale > 0 else float("nan")


def lagged_correlations(energy: np.ndarray, speed: np.ndarray, max_lag: int,
                        kept: np.ndarray | None = None) -> dict[int, float]:
    """{ℓ: corr(energy[t], speed[t + ℓ])} for |ℓ| ≤ max_lag (frames), over the pairs whose frames t and t + ℓ are
    both ``kept`` ((T,) bool; default all)."""
    kept = np.ones(len(energy), bool) if kept is None else kept
    result = {}
    for lag in range(-max_lag, max_lag + 1):
        first, last = max(-lag, 0), len(energy) - max(lag, 0)  # t ∈ [first, last)
        pairs = kept[first:last] & kept[first + lag : last + lag]  # (T − |ℓ|,)
        result[lag] = _pearson(energy[first:last][pairs], speed[first + lag : last + lag][pairs])
    return result


def speech_following(positions: np.ndarray, audio: np.ndarray, sample_rate: int, fps: float,
                     config: FollowingConfig | None = None, kept: np.ndarray | None = None) -> Following:
    """The clip's energy–speed correlation (see the module docstring); ``kept`` (T,) bool limits it to those frames,
    with the speed and energy still computed on the whole clip (no jumps where kept spans meet)."""
    config = config or FollowingConfig()
    energy = frame_energy_db(audio, sample_rate, fps, len(positions), config.floor_db)  # (T,)
    speed = upper_body_speed(positions, fps)  # (T,)
    width = int(round(config.smooth_s * fps)) | 1
    skip = int(round(config.skip_s * fps))
    energy = moving_average(energy, width)[skip : len(energy) - skip]
    speed = moving_average(speed, width)[skip : len(speed) - skip]
    kept = None if kept is None else np.asarray(kept, bool)[skip : len(kept) - skip]
    correlations = lagged_correlations(energy, speed, int(round(config.max_lag_s * fps)), kept)
    finite = {lag: r for lag, r in correlations.items() if np.isfinite(r)}
    if not finite:
        return Following(float("nan"), 0.0, float("nan"))
    best = max(finite, key=finite.get)
    return Following(finite[best], best / fps, correlations[0])
