"""``gesturecast bench vad``: frame accuracy of the speaking flag (energy vs Silero) with known truth.

Ground truth comes from synthetic speech whose silences are exact: the shared espeak sentences
(``speech/*.wav``) are joined with seeded random pauses; a frame is "speaking" when it lies
inside a sentence (between its first and last sample above −60 dBFS), so short pauses between
words count as speaking, as they should for the avatar's idle behaviour. The mix is scored
clean, with white noise at several SNRs, and 20 dB quieter (a distant microphone). On real
speech (a ZeroEGGS take, no labels) the two detectors' agreement is reported.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from gesturecast.models.audio.dsp import frame_boundary
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.models.audio.streaming import FeatureConfig, extract_features, speaking_flags
from gesturecast.models.audio.vad import VadConfig

DEFAULT_SPEECH_DIR = Path("/work/shared/data/speech")
DEFAULT_REAL = Path("/work/shared/data/zeggs/067_Speech_2_x_1_0.wav")
SENTENCE_LEVEL = 1e-3  # −60 dBFS: sentence start/end detection on clean synthetic speech
PAUSE_RANGE_S = (0.6, 2.5)
NOISE_SNRS_DB = (20.0, 10.0, 5.0)
QUIET_GAIN = 0.1  # −20 dB
METHODS = ("energy", "silero")
SEED = 0


def register_bench(bench_subparsers: argparse._SubParsersAction) -> None:
    parser = bench_subparsers.add_parser("vad", help="speaking-flag accuracy: energy vs Silero")
    parser.add_argument("--speech-dir", type=Path, default=DEFAULT_SPEECH_DIR, help="clean synthetic sentences")
    parser.add_argument("--real", type=Path, default=DEFAULT_REAL, help="real speech for the agreement check")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.set_defaults(func=run)


def labelled_mix(paths: list[Path], rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Sentences joined by random pauses → (audio (N,), per-sample truth (N,) bool)."""
    pieces, truth = [], []
    for path in paths:
        pause = np.zeros(int(rng.uniform(*PAUSE_RANGE_S) * SAMPLE_RATE), np.float32)
        sentence = load_audio(path)
        loud = np.flatnonzero(np.abs(sentence) > SENTENCE_LEVEL)
        label = np.zeros(sentence.shape[0], bool)
        label[loud[0] : loud[-1] + 1] = True
        pieces += [pause, sentence]
        truth += [np.zeros(pause.shape[0], bool), label]
    pieces.append(np.zeros(int(PAUSE_RANGE_S[1] * SAMPLE_RATE), np.float32))
    truth.append(np.zeros(pieces[-1].shape[0], bool))
    return np.concatenate(pieces), np.concatenate(truth)


def frame_truth(sample_truth: np.ndarray, config: FeatureConfig) -> np.ndarray:
    """Per-sample truth → per-frame truth (majority of the frame's samples)."""
    frames = np.arange(sample_truth.shape[0] * config.fps // config.sample_rate)
    starts = frame_boundary(frames, config.sample_rate, config.fps)
    ends = frame_boundary(frames + 1, config.sample_rate, config.fps)
    cumulative = np.concatenate([[0], np.cumsum(sample_truth)])
    return (cumulative[ends] - cumulative[starts]) * 2 > (ends - starts)


def with_noise(audio: np.ndarray, truth: np.ndarray, snr_db: float, rng: np.random.Generator) -> np.ndarray:
    speech_power = float(np.mean(audio[truth] ** 2))
    noise = rng.standard_normal(audio.shape[0]) * np.sqrt(speech_power / 10 ** (snr_db / 10))
    return (audio + noise).astype(np.float32)


def score(audio: np.ndarray, truth: np.ndarray, method: str) -> dict:
    config = FeatureConfig(vad=VadConfig(method=method))
    flags = speaking_flags(extract_features(audio, config), config)
    expected = frame_truth(truth, config)[: flags.shape[0]]
    return {
        "accuracy": round(float(np.mean(flags == expected)), 4),
        "missed_speech": round(float(np.mean(~flags[expected])), 4),
        "false_speech": round(float(np.mean(flags[~expected])), 4),
    }


def evaluate(speech_dir: Path, real: Path) -> dict:
    rng = np.random.default_rng(SEED)
    audio, truth = labelled_mix(sorted(speech_dir.glob("*.wav")), rng)
    conditions = {"clean": audio, "quiet_-20dB": audio * QUIET_GAIN}
    conditions |= {f"white_noise_snr_{snr:g}dB": with_noise(audio, truth, snr, rng) for snr in NOISE_SNRS_DB}
    conditions["quiet_-20dB_snr_10dB"] = with_noise(audio * QUIET_GAIN, truth, NOISE_SNRS_DB[1], rng)
    result: dict = {"audio_s": round(audio.shape[0] / SAMPLE_RATE, 2), "speaking_fraction": float(truth.mean())}
    result["synthetic"] = {name: {m: score(mix, truth, m) for m in METHODS} for name, mix in conditions.items()}
    speech = load_audio(real)
    flags = {m: speaking_flags(extract_features(speech, FeatureConfig(vad=VadConfig(method=m)))) for m in METHODS}
    result["real_speech"] = {
        "file": str(real),
        "agreement": round(float(np.mean(flags["energy"] == flags["silero"])), 4),
        "speaking_fraction": {m: round(float(f.mean()), 4) for m, f in flags.items()},
    }
    return result


def run(args: argparse.Namespace) -> int:
    result = evaluate(args.speech_dir, args.real)
    if args.json:
        sys.stdout.write(json.dumps(result) + "\n")
    else:
        for condition, by_method in result["synthetic"].items():
            line = "  ".join(f"{m} acc {s['accuracy']:.3f}" for m, s in by_method.items())
            sys.stdout.write(f"{condition:28s} {line}\n")
        sys.stdout.write(f"real speech agreement {result['real_speech']['agreement']:.3f}\n")
    return 0
