"""The labelled vowel set of ``gesturecast bench lipsync``: espeak-ng speaks it at run time into ``.cache``.

Each item is one utterance of a single vowel class in one espeak-ng voice: a sustained vowel ("aaa") or a
word whose vowels are all that vowel ("casa", "piso", …), in Spanish spelling, which the Spanish, Italian,
Portuguese and German voices read with five pure vowels. Frame labels (30 fps, the lip sync's frames):

- the vowel, on the *nucleus*: frames within ``NUCLEUS_DB`` of the utterance's loudest frame (vowels are the
  loud part of a syllable; consonant frames and onsets/offsets are left unlabelled);
- silence, on the padding around the utterance, from ``SILENCE_GUARD_FRAMES`` after the last audible frame
  (and as many before the first): the mouth is given that long to close;
- everything else unlabelled (-1).
"""

from __future__ import annotations

import subprocess
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gesturecast.frames import VISEME_VOWELS
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.models.audio.streaming import FeatureConfig, extract_features
from gesturecast.programs import espeak

SET_DIR = Path(".cache/lipsync_set")
# male and female variants, five languages' rules (voice+variant as espeak-ng names them)
VOICES = ("es", "es+f2", "es+m3", "it+f4", "de+m5", "pt+f1", "es+Annie", "it+Alex")
WORDS = {"a": ("aaa", "casa", "papa"), "i": ("iii", "piso", "mimi"), "u": ("uuu", "tutu", "lulu"),
         "e": ("eee", "bebe", "pepe"), "o": ("ooo", "todo", "coco")}
SPEED_WPM = 110  # slower than espeak's 175: longer vowels
PADDING_S = 0.5  # silence around each utterance
NUCLEUS_DB = 8.0
SILENT_DB = -90.0  # frame RMS of digital silence (the padding)
SILENCE_GUARD_FRAMES = 3
SILENCE = len(VISEME_VOWELS)  # class index of "closed"
UNLABELLED = -1


@dataclass(frozen=True)
class Utterance:
    voice: str
    vowel: str
    word: str
    audio: np.ndarray  # (N,) 16 kHz, padded with silence
    labels: np.ndarray  # (T,) class per frame: 0-4 vowel, 5 silence, -1 unlabelled


def synthesize(voice: str, word: str, out_dir: Path = SET_DIR) -> Path:
    """One utterance as a WAV (kept in ``out_dir``; espeak-ng is deterministic, so a cached file is reused)."""
    path = out_dir / f"{voice}_{word}.wav"
    if not path.is_file():
        out_dir.mkdir(parents=True, exist_ok=True)
        subprocess.run([espeak(), "-v", voice, "-s", str(SPEED_WPM), "-w", str(path), word], check=True,
                       capture_output=True)
    return path


def frame_labels(audio: np.ndarray, vowel: str) -> np.ndarray:
    """(N,) padded utterance → (T,) labels (module docstring)."""
    config = FeatureConfig()
    energy = extract_features(audio, config)[:, config.layout["energy"]][:, 0]  # (T,) dBFS
    labels = np.full(len(energy), UNLABELLED)
    labels[energy >= energy.max() - NUCLEUS_DB] = VISEME_VOWELS.index(vowel)
    audible = np.flatnonzero(energy > SILENT_DB)
    frames = np.arange(len(energy))
    far = (frames < audible[0] - SILENCE_GUARD_FRAMES) | (frames > audible[-1] + SILENCE_GUARD_FRAMES)
    labels[far] = SILENCE
    return labels


def vowel_set(voices: tuple[str, ...] = VOICES, words_per_vowel: int = len(WORDS["a"]),
              out_dir: Path = SET_DIR) -> list[Utterance]:
    """Every (voice, vowel, word) utterance with its frame labels."""
    padding = np.zeros(int(PADDING_S * SAMPLE_RATE), np.float32)
    items = []
    for voice in voices:
        for vowel, words in WORDS.items():
            for word in words[:words_per_vowel]:
                audio = np.concatenate([padding, load_audio(synthesize(voice, word, out_dir)), padding])
                items.append(Utterance(voice, vowel, word, audio, frame_labels(audio, vowel)))
    return items
