"""``gesturecast bench face``: blinks and expressions on minutes of speech (JSON + PNG).

The packaged sample is tiled to ``--minutes`` and generated offline with the default settings in one style
(``--style``, default happy). From the frames' face weights and voice-activity flags:

- blinks: count, rate per minute over all frames, while speaking and in silence (each over the time spent in
  that state), duration (frames with the lid more than 5 % closed) p5 / p50 / p95 ms, the share of double blinks
  (a blink starting within 300 ms of the previous one's end), and the share starting within 0.5 s after the
  voice stops (a pause) against the share of time that is;
- expression: the mean weight of each emotion preset while speaking and in silence, and the weights every style
  label of the model (and a few free-text prompts) gets, as :class:`gesturecast.realtime.pose.face.Expressions`
  gives them to the session;
- a PNG: the lid and the style's preset over the first 30 s, speech shaded.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from gesturecast.files import write_text_atomic
from gesturecast.frames import EXPRESSION_PRESETS
from gesturecast.models.audio.files import PACKAGED_SAMPLE, SAMPLE_RATE, load_audio
from gesturecast.models.generator.style_prompt import StylePrompt
from gesturecast.models.motion.motion import MOTION_FPS
from gesturecast.realtime.audio.sources import ArraySource
from gesturecast.realtime.cli_flags import add_generation_arguments, settings_from_args
from gesturecast.realtime.pose.face import BLINK_SHAPES
from gesturecast.realtime.run.engine import run_offline
from gesturecast.realtime.run.engine_setup import build_session
from gesturecast.realtime.timing.clock import MonotonicClock

CLOSED = 0.05  # lid closure that counts as blinking
DOUBLE_GAP_S = 0.3
PAUSE_WINDOW_S = 0.5
FREE_TEXT = ("cheerful", "furious", "shocked", "gloomy", "calm and slow")
PLOT_S = 30.0


def register_bench(bench_subparsers: argparse._SubParsersAction) -> None:
    parser = bench_subparsers.add_parser("face", help="blinks and expressions on minutes of speech (JSON + PNG)")
    add_generation_arguments(parser)
    parser.set_defaults(style="happy")
    parser.add_argument("--minutes", type=float, default=10.0, help="minutes of speech (the sample, tiled)")
    parser.add_argument("--json", action="store_true", help="print the JSON result")
    parser.add_argument("--out", type=Path, default=Path("out/bench/face"), help="folder for JSON and PNG")
    parser.set_defaults(func=run)


def blink_spans(lid: np.ndarray) -> np.ndarray:
    """(N, 2) first and one-past-last frame of each blink in a (T,) lid closure track."""
    edges = np.diff(np.r_[0, (lid > CLOSED).astype(int), 0])
    return np.stack([np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)], axis=1)


def blink_stats(lid: np.ndarray, speaking: np.ndarray) -> dict:
    spans = blink_spans(lid)
    starts = spans[:, 0]
    minutes = len(lid) / MOTION_FPS / 60.0
    talk_minutes = speaking.sum() / MOTION_FPS / 60.0
    durations_ms = (spans[:, 1] - spans[:, 0]) / MOTION_FPS * 1e3
    gaps_s = (spans[1:, 0] - spans[:-1, 1]) / MOTION_FPS
    pause_onsets = np.flatnonzero(np.diff(speaking.astype(int)) == -1) + 1  # first silent frame after speech
    after_pause = np.zeros(len(lid), bool)
    for onset in pause_onsets:
        after_pause[onset : onset + int(PAUSE_WINDOW_S * MOTION_FPS)] = True
    return {
        "blinks": int(len(spans)),
        "per_minute": len(spans) / minutes,
        "per_minute_speaking": float(speaking[starts].sum() / talk_minutes) if talk_minutes else None,
        "per_minute_silent": float((~speaking[starts]).sum() / (minutes - talk_minutes)) if minutes > talk_minutes
        else None,
        "duration_ms": {f"p{q}": float(np.percentile(durations_ms, q)) for q in (5, 50, 95)} if len(spans) else None,
        "double_share": float(np.mean(gaps_s < DOUBLE_GAP_S)) if len(gaps_s) else 0.0,
        "share_after_pause": float(after_pause[starts].mean()) if len(spans) else None,
        "time_share_after_pause": float(after_pause.mean()),
        "speaking_share": float(speaking.mean()),
    }


def expression_table(session) -> dict:
    """{prompt: {preset: weight}} for every style label of the model and a few free-text prompts."""
    prompts = [StylePrompt("label", label) for label in session.bundle.styles.labels]
    prompts += [StylePrompt("text", text) for text in FREE_TEXT]
    weights = {prompt.value: np.round(session.face.expressions.of(prompt).astype(float), 3) for prompt in prompts}
    return {name: dict(zip(EXPRESSION_PRESETS, values.tolist(), strict=True)) for name, values in weights.items()}


def run(args: argparse.Namespace) -> int:
    settings = settings_from_args(args, face="full")
    sample = load_audio(PACKAGED_SAMPLE)
    audio = np.resize(sample, int(args.minutes * 60 * SAMPLE_RATE))  # (n,) the sample, tiled
    session = build_session(settings, MonotonicClock())
    frames, _ = run_offline(session, ArraySource(audio, SAMPLE_RATE))
    face = np.stack([frame.face for frame in frames])  # (T, 8)
    speaking = np.array([frame.speaking for frame in frames])  # (T,)
    presets = face[:, BLINK_SHAPES:]
    result = {
        "style": settings.style, "minutes": len(frames) / MOTION_FPS / 60.0,
        "blinks": blink_stats(face[:, 0], speaking),
        "expression_mean": {"speaking": dict(zip(EXPRESSION_PRESETS, presets[speaking].mean(0).round(3).tolist(),
                                                 strict=True)),
                            "silent": dict(zip(EXPRESSION_PRESETS, presets[~speaking].mean(0).round(3).tolist(),
                                               strict=True))},
        "expression_by_style": expression_table(session),
    }
    args.out.mkdir(parents=True, exist_ok=True)
    result["picture"] = str(plot_face(face, speaking, settings.style, args.out / "face.png"))
    text = json.dumps(result, indent=2) + "\n"
    write_text_atomic(args.out / "face.json", text)
    print(text if args.json else f"wrote {args.out / 'face.json'}", end="")
    return 0


def plot_face(face: np.ndarray, speaking: np.ndarray, style: str, path: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    shown = int(PLOT_S * MOTION_FPS)
    t = np.arange(min(shown, len(face))) / MOTION_FPS
    figure, axis = plt.subplots(figsize=(12, 3))
    axis.fill_between(t, 0, 1, where=speaking[: len(t)], color="0.9", label="speaking", step="post")
    axis.plot(t, face[: len(t), 0], color="tab:blue", label="blink (lid closed)")
    strongest = int(np.argmax(face[:, BLINK_SHAPES:].mean(0)))
    axis.plot(t, face[: len(t), BLINK_SHAPES + strongest], color="tab:orange",
              label=f"{EXPRESSION_PRESETS[strongest]} ({style})")
    axis.set(xlabel="seconds", ylabel="weight", ylim=(0, 1.05), xlim=(0, t[-1]))
    axis.legend(loc="upper right", ncol=3)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)
    return path
