"""The conditions of ``gesturecast bench voices``: which audio the model hears, and what it is scored against.

- For the held-out test segment of every paired take (seen speakers, unseen sentences) — the cached
  takes' test segments and the final 15 % of the two ``zeggs_upper`` takes (the split rule of the cache;
  that data is not trained on) — the original and nine transformed versions (:data:`TRANSFORMS`, waveform DSP of
  :mod:`gesturecast.models.dataset.voice_transforms`). The motion generated for a transformed version
  is scored against the **original** audio's loudness and onsets: the transforms keep words, timing
  and prosody, so the motion should follow the same envelope.
- Unseen voices: the clips of the held-out SHOW speakers (``SHOW_HELD_OUT_SPEAKERS``), the ZeroEGGS
  Flirty recording, the synthetic espeak voices one by one and all joined with 1.5 s pauses.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.models.dataset import voice_transforms as vt
from gesturecast.models.dataset.cache import DEFAULT_SPLIT
from gesturecast.models.dataset.sources import SHOW_HELD_OUT_SPEAKERS, show_speaker
from gesturecast.models.generator.styles import canonical_style
from gesturecast.tools.eval.clips import EvalClip, held_out_clips

SR = SAMPLE_RATE
FORMANT_FACTOR = 1.15  # ±15 % vocal-tract length: about the adult female / male difference
NOISE_SEED = 11  # noise and reverb draws are fixed: every model hears the same transformed audio
JOIN_GAP_S = 1.5
FLIRTY = "zeggs/037_Flirty_1_x_1_0.wav"
ESPEAK = "speech/*.wav"
SHOW = "show/*.wav"
ZEGGS_UPPER = "zeggs_upper/*.wav"
ZEGGS_UPPER_STYLE = "Neutral"  # both takes (zeggs_upper/README.md)

Transform = Callable[[np.ndarray], np.ndarray]
TRANSFORMS: dict[str, Transform] = {
    "pitch -4 st": lambda a: vt.pitch_shift(a, SR, -4.0),
    "pitch +4 st": lambda a: vt.pitch_shift(a, SR, 4.0),
    "pitch +8 st": lambda a: vt.pitch_shift(a, SR, 8.0),
    f"formant x{FORMANT_FACTOR:g}": lambda a: vt.formant_shift(a, FORMANT_FACTOR),
    f"formant x{1 / FORMANT_FACTOR:.2f}": lambda a: vt.formant_shift(a, 1.0 / FORMANT_FACTOR),
    "gain -20 dB": lambda a: vt.apply_gain(a, -20.0),
    "noise 20 dB SNR": lambda a: vt.add_white_noise(a, 20.0, np.random.default_rng(NOISE_SEED)),
    "telephone 300-3400 Hz": lambda a: vt.telephone_band(a, SR),
    "reverb small room": lambda a: vt.reverb(a, SR, np.random.default_rng(NOISE_SEED)),
}
ORIGINAL = "original"
UNSEEN_STYLE = "speech"


@dataclass(frozen=True)
class VoiceCase:
    condition: str  # "original", a TRANSFORMS key, or an unseen-voice group
    file: str  # the source recording (the same for an original and its transforms)
    heard: np.ndarray  # (N,) what the model hears, 16 kHz
    reference: np.ndarray  # (N,) the clean speech its motion is scored against
    style: str
    positions: np.ndarray | None = None  # (T, J, 3) real motion (originals of paired takes only)


def upper_body_held_out(shared: Path) -> list[EvalClip]:
    """The final ``paired_test_fraction`` of every zeggs_upper take's speech (no motion: scored on audio only)."""
    clips = []
    for path in sorted(shared.glob(ZEGGS_UPPER)):
        audio = load_audio(path)
        start = int(round(len(audio) * (1.0 - DEFAULT_SPLIT.paired_test_fraction)))
        clips.append(EvalClip(f"zeggs_upper/{path.stem}[test]", audio[start:], canonical_style(ZEGGS_UPPER_STYLE)))
    return clips


def transformed_cases(cache: Path, shared: Path, transforms: dict[str, Transform]) -> list[VoiceCase]:
    """Original + every transform of every held-out paired segment."""
    cases = []
    for clip in [*held_out_clips(cache), *upper_body_held_out(shared)]:
        cases.append(VoiceCase(ORIGINAL, clip.name, clip.audio, clip.audio, clip.style, clip.positions))
        cases += [VoiceCase(name, clip.name, transform(clip.audio), clip.audio, clip.style)
                  for name, transform in transforms.items()]
    return cases


def _joined(audios: list[np.ndarray], gap_s: float) -> np.ndarray:
    gap = np.zeros(int(round(gap_s * SR)), np.float32)
    return np.concatenate([part for audio in audios for part in (audio, gap)])


def unseen_cases(shared: Path) -> list[VoiceCase]:
    """Held-out SHOW speakers, Flirty, espeak single files and joined (whatever of them ``shared`` holds)."""
    cases = []
    for path in sorted(shared.glob(SHOW)):
        if show_speaker(path.stem) in SHOW_HELD_OUT_SPEAKERS:
            audio = load_audio(path)
            cases.append(VoiceCase("show held-out speakers", path.name, audio, audio, UNSEEN_STYLE))
    for path in sorted(shared.glob(FLIRTY)):
        audio = load_audio(path)
        cases.append(VoiceCase("flirty", path.name, audio, audio, UNSEEN_STYLE))
    espeak = [load_audio(path) for path in sorted(shared.glob(ESPEAK))]
    cases += [VoiceCase("espeak single", path.name, audio, audio, UNSEEN_STYLE)
              for path, audio in zip(sorted(shared.glob(ESPEAK)), espeak, strict=True)]
    if espeak:
        joined = _joined(espeak, JOIN_GAP_S)
        cases.append(VoiceCase("espeak joined", "espeak_joined", joined, joined, UNSEEN_STYLE))
    return cases
