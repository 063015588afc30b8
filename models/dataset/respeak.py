"""A paired take's words re-spoken by a TTS voice, in time with the take, for denoiser training.

Two speakers have paired speech + motion here, so the model hears two voices; voice agents speak with TTS
voices. A re-spoken copy keeps the take's motion and replaces its speech: every word of the take's transcript
(models/dataset/transcripts.py) is synthesised alone by espeak-ng in one of :data:`TRAINING_VOICES` at the
speaking rate that brings it closest to the word's duration, its silent edges trimmed, time-stretched the rest of
the way (librosa's phase vocoder, pitch kept) and scaled to the RMS of the original word, so the copy speaks where
the take speaks, pauses where it pauses and stresses the words the speaker stressed; the voice, its timbre and its
intonation are the TTS engine's. The copy has the take's length.

The training voices share no espeak-ng voice variant with ``gesturecast bench voices`` (its held-out and dev
voices, tools/bench/speech/voice_set.py); its Flite voices are another engine, heard in no training.
"""

from __future__ import annotations

import io
import subprocess
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import soundfile
import soxr

from gesturecast.models.audio.files import SAMPLE_RATE
from gesturecast.models.dataset.transcripts import RecognisedWord
from gesturecast.programs import espeak

TRIM_DB = 40.0  # a synthesised word's edges quieter than its peak by this much are cut
BASE_WPM = 175  # espeak-ng's default speaking rate
WPM_RANGE = (80, 450)  # the rates espeak-ng takes (-s)
WPM_STEP = 5  # rates are rounded to this, so that a word's syntheses are reused
FADE_S = 0.015  # linear fade at both ends of each placed word (no clicks)
MIN_WORD_S = 0.04
STRETCH_N_FFT = 512  # 32 ms: short words still span several frames
SILENT_RMS = 1e-4


@dataclass(frozen=True)
class TtsVoice:
    voice: str  # espeak-ng -v (language + variant)
    pitch: int  # 0-99 (-p)


TRAINING_VOICES: tuple[TtsVoice, ...] = (
    TtsVoice("en-us+m1", 40), TtsVoice("en-gb+m4", 35), TtsVoice("en-gb-x-gbclan+m6", 50),
    TtsVoice("en-us+klatt4", 55), TtsVoice("en-gb-x-rp+klatt6", 45), TtsVoice("en-us+linda", 65),
    TtsVoice("en-gb+belinda", 70), TtsVoice("en-us+Andrea", 60),
)


@lru_cache(maxsize=16384)
def synthesize_word(voice: TtsVoice, text: str, wpm: int = BASE_WPM) -> np.ndarray:
    """One word by espeak-ng at ``wpm`` words a minute, 16 kHz, silent edges trimmed (F,) float32."""
    argv = [espeak(), "-v", voice.voice, "-p", str(voice.pitch), "-s", str(wpm), "--stdout", text]
    wav = subprocess.run(argv, check=True, capture_output=True).stdout
    audio, rate = soundfile.read(io.BytesIO(wav), dtype="float32")
    import librosa  # a train extra: the voice table above is read where librosa may be absent

    audio = soxr.resample(audio, rate, SAMPLE_RATE).astype(np.float32)
    trimmed, _ = librosa.effects.trim(audio, top_db=TRIM_DB)
    return trimmed


def fit_length(audio: np.ndarray, length: int) -> np.ndarray:
    """(F,) → (length,): time-stretched to ``length`` samples (pitch kept), then cut or padded to it exactly."""
    import librosa

    rate = len(audio) / length
    stretched = librosa.effects.time_stretch(audio, rate=rate, n_fft=STRETCH_N_FFT, hop_length=STRETCH_N_FFT // 4)
    return np.pad(stretched[:length], (0, max(0, length - len(stretched))))


def spoken_word(voice: TtsVoice, text: str, length: int) -> np.ndarray:
    """``text`` said in ``length`` samples: synthesised at the speaking rate closest to that duration (a slower
    voice, not a smeared one), then stretched the rest of the way (F,) → (length,)."""
    natural = synthesize_word(voice, text)
    if len(natural) == 0:
        return np.zeros(length, np.float32)
    wpm = int(np.clip(round(BASE_WPM * len(natural) / length / WPM_STEP) * WPM_STEP, *WPM_RANGE))
    closer = natural if wpm == BASE_WPM else synthesize_word(voice, text, wpm)
    return fit_length(closer if len(closer) else natural, length)


def _faded(audio: np.ndarray) -> np.ndarray:
    fade = min(int(FADE_S * SAMPLE_RATE), len(audio) // 2)
    ramp = np.linspace(0.0, 1.0, fade, dtype=np.float32)
    audio = audio.copy()
    audio[:fade] *= ramp
    audio[len(audio) - fade:] *= ramp[::-1]
    return audio


def _rms(audio: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(audio, dtype=np.float64)))) if len(audio) else 0.0


def respeak(audio: np.ndarray, words: list[RecognisedWord], voice: TtsVoice) -> np.ndarray:
    """(N,) 16 kHz take audio + its words → (N,) the same words in ``voice``, each on its own time and level."""
    out = np.zeros(len(audio), np.float32)
    for word in words:
        start, stop = int(word.start_s * SAMPLE_RATE), min(int(word.end_s * SAMPLE_RATE), len(audio))
        level = _rms(audio[start:stop])
        if stop - start < MIN_WORD_S * SAMPLE_RATE or level < SILENT_RMS:
            continue
        placed = _faded(spoken_word(voice, word.text, stop - start))
        if _rms(placed) < SILENT_RMS:
            continue
        out[start:stop] += placed * (level / max(_rms(placed), SILENT_RMS))
    return out
