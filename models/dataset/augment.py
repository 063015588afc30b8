"""Frame-aligned audio for motion clips, and augmentation of a (motion, audio) pair together.

Alignment: motion frame k covers audio ``[k / fps, (k + 1) / fps)``, i.e. samples
``[round(k * sr / fps), round((k + 1) * sr / fps))``; a clip of T frames owns
``round(T * sr / fps)`` samples.

Speed augmentation plays motion and audio ``factor`` times faster: motion by slerp resampling
(:func:`speed_perturb`), audio by band-limited resampling (soxr) from ``sr * factor`` to ``sr``.
This is plain resampling, so the voice's pitch moves with the speed (10 % faster = 10 % higher),
accepted for augmentation as in speech recognition practice (Ko et al. 2015, "Audio
augmentation for speech recognition").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import soxr

from gesturecast.models.motion.motion import SkeletonMotion
from gesturecast.models.motion.motion_features import mirror_motion, speed_perturb


@dataclass(frozen=True)
class AugmentConfig:
    """Which variants :func:`augmented_variants` yields besides the original."""

    mirror: bool = True
    speeds: tuple[float, ...] = (0.9, 1.1)


def audio_samples_for_frames(num_frames: int, fps: float, sample_rate: int) -> int:
    """Number of audio samples owned by ``num_frames`` motion frames."""
    return int(round(num_frames * sample_rate / fps))


def fit_audio(audio: np.ndarray, num_frames: int, fps: float, sample_rate: int) -> np.ndarray:
    """Trim or zero-pad audio to exactly the samples of ``num_frames`` frames. (N,) -> (N',)."""
    length = audio_samples_for_frames(num_frames, fps, sample_rate)
    fitted = np.zeros(length, dtype=np.float32)
    fitted[: min(length, audio.shape[0])] = audio[:length]
    return fitted


def slice_audio(audio: np.ndarray, start: int, stop: int, fps: float, sample_rate: int) -> np.ndarray:
    """The samples owned by motion frames ``[start, stop)``."""
    first = audio_samples_for_frames(start, fps, sample_rate)
    return audio[first : audio_samples_for_frames(stop, fps, sample_rate)]


def speed_perturb_pair(
    motion: SkeletonMotion, audio: np.ndarray | None, factor: float, sample_rate: int
) -> tuple[SkeletonMotion, np.ndarray | None]:
    """SkeletonMotion and its audio both ``factor`` times faster; lengths stay frame-aligned."""
    faster = speed_perturb(motion, factor)
    if audio is None:
        return faster, None
    resampled = soxr.resample(audio, sample_rate * factor, sample_rate)  # (N / factor,)
    return faster, fit_audio(resampled.astype(np.float32), faster.num_frames, faster.fps, sample_rate)


def augmented_variants(
    motion: SkeletonMotion, audio: np.ndarray | None, config: AugmentConfig, sample_rate: int
) -> list[tuple[str, SkeletonMotion, np.ndarray | None]]:
    """(tag, motion, audio) for the original and every configured variant (mirroring keeps audio)."""
    bases = [("", motion)]
    if config.mirror:
        bases.append(("mirror", mirror_motion(motion)))
    variants: list[tuple[str, SkeletonMotion, np.ndarray | None]] = []
    for tag, base in bases:
        variants.append((tag, base, audio))
        for factor in config.speeds:
            faster, faster_audio = speed_perturb_pair(base, audio, factor, sample_rate)
            variants.append(("+".join(filter(None, [tag, f"speed{factor:g}"])), faster, faster_audio))
    return variants
