"""``gesturecast bench cues``: what far-future words cost a stream, per latent, against a few.

For each word count, a fresh session (the model and lexicon of the settings) hears :data:`LEAD_S` of the bundled
sample, is given that many words starting a minute ahead (two a second, every :data:`TRIGGER_EVERY`-th a trigger
word, each far enough from the last to be placed), then hears :data:`TIMED_S` more seconds, one latent's audio per
push. Reported per count: the cues placed, the microseconds placing took per word, each push's milliseconds
(p50 / p95: the denoiser and decoder dominate them) and the cue plan's own microseconds per latent (the imposition
look-up the session makes for every latent), p50 / p95 over :data:`PLAN_LATENTS` latents.
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

from gesturecast.controls import Word
from gesturecast.models.audio.files import PACKAGED_SAMPLE, SAMPLE_RATE, load_audio
from gesturecast.realtime.audio.sources import AudioChunk
from gesturecast.realtime.cli_flags import add_generation_arguments, settings_from_args
from gesturecast.realtime.run.engine_setup import build_session
from gesturecast.realtime.timing.clock import MonotonicClock

LEAD_S = 2.0  # audio before the words arrive
TIMED_S = 6.0  # audio timed after them
AHEAD_S = 60.0  # the first word's distance ahead of the stream
WORD_S = 0.5  # two words a second
TRIGGER_EVERY = 10  # one "hello" every 5 s: beyond the refractory time, so each is placed
PLAN_LATENTS = 500
DEFAULT_COUNTS = (10, 100_000)


def register_bench(bench_subparsers: argparse._SubParsersAction) -> None:
    parser = bench_subparsers.add_parser("cues", help="far-future words: a stream's cost per latent against a few "
                                         "(JSON)")
    add_generation_arguments(parser)
    parser.add_argument("--words", type=int, nargs="+", default=list(DEFAULT_COUNTS), metavar="N",
                        help="word counts to compare (default: 10 100000)")
    parser.set_defaults(func=run)


def far_words(count: int, start: float) -> list[Word]:
    """``count`` words two a second from ``start`` (stream s), every TRIGGER_EVERY-th of them "hello"."""
    return [Word("hello" if index % TRIGGER_EVERY == 0 else "and", start + index * WORD_S,
                 start + (index + 1) * WORD_S) for index in range(count)]


def percentiles(values: list[float]) -> dict[str, float]:
    return {"p50": float(np.percentile(values, 50)), "p95": float(np.percentile(values, 95))}


def measure(settings, audio: np.ndarray, count: int) -> dict:
    """One session given ``count`` far-future words (see the module docstring)."""
    session = build_session(settings, MonotonicClock())
    per_latent = int(SAMPLE_RATE * session.denoiser_config.frames_per_latent / session.fps)
    lead = int(LEAD_S * SAMPLE_RATE)
    session.push(AudioChunk(audio[:lead], 0, 0.0))
    words = far_words(count, lead / SAMPLE_RATE + AHEAD_S)
    started = time.perf_counter()
    placed = len(session.gestures.hear_words(tuple(words)))
    place_s = time.perf_counter() - started
    push_ms = []
    for offset in range(lead, lead + int(TIMED_S * SAMPLE_RATE), per_latent):
        started = time.perf_counter()
        session.push(AudioChunk(audio[offset : offset + per_latent], offset, offset / SAMPLE_RATE))
        push_ms.append((time.perf_counter() - started) * 1e3)
    plan_us = []
    for latent in range(session.next_latent, session.next_latent + PLAN_LATENTS):
        started = time.perf_counter()
        session.gestures.cues.imposition(latent)
        plan_us.append((time.perf_counter() - started) * 1e6)
    return {"words": count, "placed": placed, "place_us_per_word": place_s / count * 1e6,
            "push_ms_per_latent": percentiles(push_ms), "plan_us_per_latent": percentiles(plan_us)}


def run(args: argparse.Namespace) -> int:
    settings = settings_from_args(args)
    audio = load_audio(PACKAGED_SAMPLE)  # (n,)
    results = [measure(settings, audio, count) for count in args.words]
    print(json.dumps({"bench": "cues", "ahead_s": AHEAD_S, "timed_s": TIMED_S, "results": results}, indent=2))
    return 0
