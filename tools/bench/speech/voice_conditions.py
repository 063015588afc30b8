"""The conditions of ``gesturecast bench voices``: which audio the model hears, and what it is scored against.

- For the held-out test segment of every paired take (seen speakers, unseen sentences) — the cached
  takes' test segments and the final 15 % of the two ``zeggs_upper`` takes (the split rule of the cache;
  that data is not trained on) — the original and nine transformed versions (:data:`TRANSFORMS`, waveform DSP of
  :mod:`gesturecast.models.dataset.voice_transforms`). The motion generated for a transformed version
  is scored against the **original** audio's loudness and onsets: the transforms keep words, timing
  and prosody, so the motion should follow the same envelope.
- Unseen voices (:mod:`gesturecast.tools.bench.speech.voice_set`): voice groups written down before any
  choice was made, in a held-out split (scored, never chosen on) and a dev split (may be chosen on).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.models.dataset import voice_transforms as vt
from gesturecast.models.dataset.cache import DEFAULT_SPLIT, INDEX_FILE, load_take, read_index
from gesturecast.models.generator.styles import canonical_style
from gesturecast.tools.bench.speech.voice_set import voice_audio
from gesturecast.tools.eval.clips import EvalClip, held_out_clips

SR = SAMPLE_RATE
FORMANT_FACTOR = 1.15  # ±15 % vocal-tract length: about the adult female / male difference
NOISE_SEED = 11  # noise and reverb draws are fixed: every model hears the same transformed audio
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


@dataclass(frozen=True)
class VoiceCase:
    condition: str  # "original", a TRANSFORMS key, or an unseen-voice group
    file: str  # the source recording (the same for an original and its transforms)
    heard: np.ndarray  # (N,) what the model hears, 16 kHz
    reference: np.ndarray  # (N,) the clean speech its motion is scored against
    positions: np.ndarray | None = None  # (T, J, 3) real motion (originals of paired takes only)
    voice: str = ""  # the voice heard, where it differs from the file (unseen voices)


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
        cases.append(VoiceCase(ORIGINAL, clip.name, clip.audio, clip.audio, clip.positions))
        cases += [VoiceCase(name, clip.name, transform(clip.audio), clip.audio)
                  for name, transform in transforms.items()]
    return cases


def recorded_motion(cache: Path) -> dict[str, np.ndarray]:
    """Real motion (T, J, 3) of the cache's takes that came with a recording, by the recording's path under the
    shared folder (``show/NAME.wav``); empty without a cache. SHOW takes hold reliable arms only (docs/dataset.md)."""
    if not (cache / INDEX_FILE).is_file():
        return {}
    takes = [record for record in read_index(cache)["takes"] if record["dataset"] == "show"]
    return {f"show/{record['name']}.wav": load_take(cache, record)[0].positions() for record in takes}


def voice_set_cases(split: str, shared: Path, cache: Path) -> list[VoiceCase]:
    """The unseen voices of one split of :mod:`voice_set`: the condition is the voice group, the file the source
    recording (a re-recorded channel variant shares its source's, so it is never its own chance reference).
    A whole single recording whose motion the cache holds carries it as the real motion."""
    motion = recorded_motion(cache)
    cases = []
    for item in voice_audio(split, shared):
        voice = item.voice
        source = voice.channel.of if voice.channel is not None else voice.name
        whole = voice.channel is None and not voice.spans_s and len(voice.files) == 1
        cases.append(VoiceCase(voice.group, source, item.heard, item.reference,
                               motion.get(voice.files[0]) if whole else None, voice=voice.name))
    return cases
