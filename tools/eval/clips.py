"""The evaluation sets: held-out paired speech + motion, unseen speech, and the real reference motion.

- held-out: the test segments (final 15 %) of every cached take with speech (ZeroEGGS, BEAT2);
  the model never trained on them, and their real motion is the ground truth;
- unseen speech: recordings the model never saw in any form (no motion);
- reference: real motion of the paired takes' train split (what FGD and liveliness compare with).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.models.audio.files import PACKAGED_SAMPLE, SAMPLE_RATE, load_audio
from gesturecast.models.dataset.augment import audio_samples_for_frames, slice_audio
from gesturecast.models.dataset.cache import is_full_body, load_take, read_index
from gesturecast.models.motion.motion import MOTION_FPS

SHARED_UNSEEN = ("zeggs/037_Flirty_1_x_1_0.wav", "speech/*.wav")


@dataclass(frozen=True)
class EvalClip:
    name: str
    audio: np.ndarray  # (N,) float32 16 kHz mono
    style: str  # the style to request when generating for this clip
    positions: np.ndarray | None = None  # (T, J, 3) real motion, None for speech without motion

    @property
    def seconds(self) -> float:
        return self.audio.shape[0] / SAMPLE_RATE

    def crop(self, seconds: float | None) -> EvalClip:
        """The first ``seconds`` of audio and motion (unchanged when None or already shorter)."""
        if seconds is None or seconds >= self.seconds:
            return self
        frames = int(seconds * MOTION_FPS)
        samples = audio_samples_for_frames(frames, MOTION_FPS, SAMPLE_RATE)
        positions = None if self.positions is None else self.positions[:frames]
        return replace(self, audio=self.audio[:samples], positions=positions)


def _paired_segments(cache_dir: Path, split: str) -> list[tuple[dict, dict]]:
    """Segments of ``split`` of the full-body paired takes (arms-only takes have no motion to compare with)."""
    paired = [record for record in read_index(cache_dir)["takes"] if record["has_audio"] and is_full_body(record)]
    return [(record, segment) for record in paired for segment in record["segments"] if segment["split"] == split]


def held_out_clips(cache_dir: Path) -> list[EvalClip]:
    """The test segments of the paired takes, with their real motion and style."""
    clips = []
    for record, segment in _paired_segments(cache_dir, "test"):
        motion, audio = load_take(cache_dir, record)
        start, stop = segment["start"], segment["stop"]
        clips.append(EvalClip(f"{record['dataset']}/{record['name']}[test]",
                              slice_audio(audio, start, stop, motion.fps, SAMPLE_RATE), record["style"],
                              motion.positions()[start:stop]))
    if not clips:
        raise UserError(f"the dataset cache {cache_dir} has no paired test segments; rebuild it with speech takes")
    return clips


def reference_positions(cache_dir: Path) -> list[np.ndarray]:
    """Real motion (T, J, 3) of the paired takes' train split."""
    clips = []
    for record, segment in _paired_segments(cache_dir, "train"):
        motion, _ = load_take(cache_dir, record)
        clips.append(motion.positions()[segment["start"] : segment["stop"]])
    return clips


def default_unseen_paths(shared: Path) -> list[Path]:
    """The shared unseen recordings when the shared folder exists, else the packaged sample."""
    paths = sorted(p for pattern in SHARED_UNSEEN for p in shared.glob(pattern)) if shared.is_dir() else []
    return paths or [PACKAGED_SAMPLE]


def unseen_clips(paths: list[Path], style: str, max_seconds: float | None) -> list[EvalClip]:
    return [EvalClip(path.name, load_audio(path), style).crop(max_seconds) for path in paths]
