"""``gesturecast bench lipsync --json``: how right, how loud-following and how cheap the viseme weights are.

- **Vowel accuracy** on the espeak-ng set (:mod:`gesturecast.tools.bench.speech.lipsync_set`): per labelled frame,
  the class of :func:`mouth_class` (argmax vowel, or closed when the opening is below ``SILENT_MOUTH``) vs
  the label (5 vowels + silence); per voice, overall, vowels only, and the 6 × 6 confusion matrix.
- **Mouth opening vs loudness** on real speech: Pearson r between the opening (sum of the weights) and the
  frame's RMS level in dBFS, over all frames and over the speaking ones; and the share of non-speaking frames
  whose mouth is closed (opening < ``SILENT_MOUTH``).
- **Cost**: feature extraction with and without lip sync on the same speech, pushed as the session pushes
  (one latent's audio per burst: ``SESSION_BURST_FRAMES`` frames) and as a microphone delivers it (512-sample
  chunks); the difference per frame and as real-time factor (compute s / audio s).
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np

from gesturecast.frames import VISEME_VOWELS
from gesturecast.models.audio.dsp import frame_boundary
from gesturecast.models.audio.files import load_audio
from gesturecast.models.audio.lipsync import SILENT_MOUTH, LipSyncConfig, mouth_class
from gesturecast.models.audio.streaming import FeatureConfig, StreamingFeatureExtractor, speaking_flags
from gesturecast.realtime.audio.sources import DEFAULT_CHUNK
from gesturecast.tools.bench.speech.lipsync_set import SET_DIR, SILENCE, UNLABELLED, VOICES, WORDS, Utterance, vowel_set

SHARED_DATA = Path("/work/shared/data")
DEFAULT_SPEECH = ("zeggs/067_Speech_2_x_1_0.wav", "beat2/2_scott_0_1_1.wav", "show/*.wav")
CLASSES = (*VISEME_VOWELS, "silence")
MS_PER_S = 1000.0
SESSION_BURST_FRAMES = 4  # the default model's frames per latent: the session extracts features per latent


def register_bench(bench_subparsers: argparse._SubParsersAction) -> None:
    parser = bench_subparsers.add_parser("lipsync", help="viseme accuracy (espeak-ng vowels), loudness "
                                         "correlation on real speech, cost")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--voices", default=",".join(VOICES), help="comma list of espeak-ng voices")
    parser.add_argument("--words", type=int, default=len(WORDS["a"]), help="utterances per vowel and voice")
    parser.add_argument("--speech", type=Path, nargs="*", help="real speech files (default: zeggs, beat2 and "
                        f"show/ clips under {SHARED_DATA})")
    parser.add_argument("--repeats", type=int, default=3, help="timing runs; the cost is their median")
    parser.add_argument("--set-dir", type=Path, default=SET_DIR, help="where espeak-ng's WAVs are cached")
    parser.set_defaults(func=run)


def lipsync_frames(audio: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(N,) audio → (T, F) raw features and (T, 5) viseme weights, one streaming pass."""
    extractor = StreamingFeatureExtractor(FeatureConfig(), LipSyncConfig())
    features = extractor.push(audio)
    return features, extractor.take_visemes()


def vowel_accuracy(items: list[Utterance]) -> dict:
    """Accuracy per voice and overall, and the confusion matrix (rows: label, columns: prediction)."""
    confusion = np.zeros((len(CLASSES), len(CLASSES)), int)
    per_voice: dict[str, np.ndarray] = {}
    for item in items:
        predicted = mouth_class(lipsync_frames(item.audio)[1])  # (T,)
        labelled = item.labels != UNLABELLED
        counts = np.zeros_like(confusion)
        np.add.at(counts, (item.labels[labelled], predicted[labelled]), 1)
        confusion += counts
        per_voice[item.voice] = per_voice.get(item.voice, 0) + counts
    vowels = confusion[:SILENCE, :]
    return {
        "frames": int(confusion.sum()),
        "accuracy": float(np.trace(confusion) / confusion.sum()),
        "vowel_accuracy": float(np.trace(vowels[:, :SILENCE]) / vowels.sum()),
        "silence_accuracy": float(confusion[SILENCE, SILENCE] / confusion[SILENCE].sum()),
        "per_voice": {voice: {"all": round(float(np.trace(c) / c.sum()), 3),
                              "vowels": round(float(np.trace(c[:SILENCE, :SILENCE]) / c[:SILENCE].sum()), 3)}
                      for voice, c in per_voice.items()},
        "confusion": {"classes": list(CLASSES), "rows_label_columns_predicted": confusion.tolist()},
    }


def loudness_correlation(path: Path) -> dict:
    """Pearson r of mouth opening vs frame RMS (dBFS) on one speech file, all frames and speaking frames."""
    config = FeatureConfig()
    features, weights = lipsync_frames(load_audio(path))
    level = features[:, config.layout["energy"]][:, 0]  # (T,) dBFS
    opening = weights.sum(axis=1)  # (T,)
    speaking = speaking_flags(features, config)
    silent = ~speaking
    return {
        "file": path.name,
        "frames": len(level),
        "speaking_fraction": round(float(speaking.mean()), 3),
        "r_all": round(float(np.corrcoef(opening, level)[0, 1]), 3),
        "r_speaking": round(float(np.corrcoef(opening[speaking], level[speaking])[0, 1]), 3),
        "closed_when_silent": round(float((opening[silent] < SILENT_MOUTH).mean()), 3) if silent.any() else None,
    }


def push_time(audio: np.ndarray, lipsync: LipSyncConfig | None, chunk: int) -> float:
    """Seconds spent in ``push`` streaming ``audio`` in chunks of ``chunk`` samples."""
    extractor = StreamingFeatureExtractor(FeatureConfig(), lipsync)
    started = time.perf_counter()
    for start in range(0, len(audio), chunk):
        extractor.push(audio[start:start + chunk])
    return time.perf_counter() - started


def cost_at_chunk(audio: np.ndarray, chunk: int, repeats: int) -> dict:
    """Median compute time with and without lip sync, per frame and as real-time factor."""
    config = FeatureConfig()
    seconds = len(audio) / config.sample_rate
    frames = seconds * config.fps
    plain = statistics.median(push_time(audio, None, chunk) for _ in range(repeats))
    with_lipsync = statistics.median(push_time(audio, LipSyncConfig(), chunk) for _ in range(repeats))
    return {
        "chunk_samples": chunk,
        "features_ms_per_frame": round(plain / frames * MS_PER_S, 4),
        "lipsync_ms_per_frame": round((with_lipsync - plain) / frames * MS_PER_S, 4),
        "lipsync_rtf": round((with_lipsync - plain) / seconds, 5),
    }


def cost(path: Path, repeats: int) -> dict:
    """The lip sync's cost in the session's bursts and in microphone-sized pushes."""
    audio = load_audio(path)
    config = FeatureConfig()
    burst = int(frame_boundary(SESSION_BURST_FRAMES, config.sample_rate, config.fps))
    return {
        "file": path.name,
        "audio_s": round(len(audio) / config.sample_rate, 2),
        "session_burst": cost_at_chunk(audio, burst, repeats),
        "microphone_chunk": cost_at_chunk(audio, DEFAULT_CHUNK, repeats),
    }


def speech_files(given: list[Path] | None) -> list[Path]:
    if given:
        return given
    return sorted(path for pattern in DEFAULT_SPEECH for path in SHARED_DATA.glob(pattern))


def benchmark(voices: tuple[str, ...], words: int, speech: list[Path], repeats: int, set_dir: Path) -> dict:
    return {
        "voices": list(voices),
        "utterances_per_vowel_and_voice": words,
        "vowels": vowel_accuracy(vowel_set(voices, words, set_dir)),
        "loudness": [loudness_correlation(path) for path in speech],
        "cost": cost(speech[0], repeats) if speech else None,
    }


def run(args: argparse.Namespace) -> int:
    voices = tuple(v.strip() for v in args.voices.split(",") if v.strip())
    result = benchmark(voices, args.words, speech_files(args.speech), args.repeats, args.set_dir)
    sys.stdout.write((json.dumps(result) if args.json else json.dumps(result, indent=2)) + "\n")
    return 0
