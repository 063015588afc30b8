"""``gesturecast bench voices``: does the motion follow the speech whoever speaks, and through any channel?

``--set held-out`` (the default) scores the held-out unseen voices of
:mod:`gesturecast.tools.bench.speech.voice_set` per voice group, ``--set dev`` the voices that may be chosen on,
``--set transforms`` the held-out paired segments and nine voice/channel transforms of them
(:mod:`gesturecast.tools.bench.speech.voice_conditions`). For every case and every seed, motion is generated
through the product's offline path (``run_offline``, DDIM K, the bundle's guidance) at the product's default
settings (``Settings()``: the style ``neutral`` given by the stylizer, the generator hearing ``speech``) unless
``--style`` / ``--generator-style`` ask for another condition, and scored:

- ``r``: the speech-following measure (:mod:`gesturecast.models.evaluation.speech_following`: Pearson r of
  smoothed upper-body speed vs the reference speech's loudness, best lag within ±0.5 s);
- ``chance``: the same measure of the same generated motion against the reference audio of every *other*
  recording of the run (both cropped to the shorter), averaged: what r is when the motion has nothing to do
  with the speech; ``margin`` = r − chance;
- ``ratio``: a transform's r over the original's r on the same held-out segments (target ≥ 0.9);
- ``bc``: BEAT beat consistency against the reference speech's onsets;
- ``rest``: mean upper-body speed in the reference's pauses (the runtime's speaking flag off) over its
  mean speed while speaking (< 1: the avatar calms down in pauses); only where ≥ 1 s of pause exists.
Each group's (condition's) numbers are means over its recordings and seeds; ``overall`` weighs every voice group
equally. One JSON object (``--json``) and a picture (``--plot``); nothing is asserted. Definitions: docs/voices.md.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from gesturecast.files import write_text_atomic
from gesturecast.models.audio.files import SAMPLE_RATE
from gesturecast.models.audio.streaming import extract_features, speaking_flags
from gesturecast.models.dataset.augment import audio_samples_for_frames
from gesturecast.models.evaluation.beat_consistency import beat_consistency, speech_onsets
from gesturecast.models.evaluation.speech_following import (
    FollowingConfig,
    frame_energy_db,
    moving_average,
    speech_following,
    upper_body_speed,
)
from gesturecast.models.generator.diffusion import SamplerConfig
from gesturecast.models.motion.motion import MOTION_FPS
from gesturecast.realtime.run.engine_setup import load_bundle
from gesturecast.settings import DEFAULT_AUDIO_GUIDANCE, DEFAULT_MODEL_DIR
from gesturecast.tools.bench.speech.voice_conditions import (
    ORIGINAL,
    TRANSFORMS,
    VoiceCase,
    transformed_cases,
    voice_set_cases,
)
from gesturecast.tools.bench.speech.voice_set import HELD_OUT, SPLITS
from gesturecast.tools.data_cli import DEFAULT_CACHE, DEFAULT_SHARED
from gesturecast.tools.eval.clips import EvalClip
from gesturecast.tools.eval.condition import DEFAULT_CONDITION, Condition, add_condition_arguments
from gesturecast.tools.eval.generate import generate_offline
from gesturecast.tools.render.plot_voices import VoiceTrace, plot_voice_traces

DEFAULT_SEEDS = "0,1,2"
MIN_PAUSE_S = 1.0
PLOT_SECONDS = 20.0
PLOT_ROWS = 3  # the first case of the first three conditions
TRANSFORMS_SET = "transforms"
FOLLOWING = FollowingConfig()


def register_bench(bench_subparsers: argparse._SubParsersAction) -> None:
    parser = bench_subparsers.add_parser("voices", help="speech following under voice and channel changes (JSON)")
    parser.add_argument("--bundle", type=Path, default=DEFAULT_MODEL_DIR, help="model bundle (default: bundled)")
    parser.add_argument("--cache", type=Path, default=DEFAULT_CACHE, help="dataset cache (held-out segments)")
    parser.add_argument("--shared", type=Path, default=DEFAULT_SHARED, help="shared data folder (unseen voices)")
    parser.add_argument("--set", dest="voice_set", choices=[*SPLITS, TRANSFORMS_SET], default=HELD_OUT,
                        help="held-out unseen voices per group (default), the dev voices, or the paired held-out "
                             "segments under nine voice/channel transforms")
    parser.add_argument("--seeds", default=DEFAULT_SEEDS, help="comma-separated generation seeds")
    parser.add_argument("--steps", type=int, default=None, help="DDIM steps K (default: the model's)")
    parser.add_argument("--audio-guidance", type=float, default=DEFAULT_AUDIO_GUIDANCE,
                        help="audio guidance scale s_a (1: off)")
    parser.add_argument("--guidance", type=float, help="style guidance scale s (default: the bundle's)")
    add_condition_arguments(parser)
    parser.add_argument("--json", type=Path, help="also write the result here")
    parser.add_argument("--plot", type=Path, help="PNG: loudness and generated speed for three voices")
    parser.set_defaults(func=run_bench)


def crop_audio(audio: np.ndarray, frames: int) -> np.ndarray:
    return audio[: audio_samples_for_frames(frames, MOTION_FPS, SAMPLE_RATE)]


def following_r(positions: np.ndarray, reference: np.ndarray) -> float:
    """r_best of motion against speech, both cropped to the shorter of the two."""
    frames = min(len(positions), int(len(reference) * MOTION_FPS // SAMPLE_RATE))
    return speech_following(positions[:frames], crop_audio(reference, frames), SAMPLE_RATE, MOTION_FPS,
                            FOLLOWING).best_correlation


def chance_r(positions: np.ndarray, own_file: str, references: dict[str, np.ndarray]) -> float:
    values = [following_r(positions, audio) for name, audio in references.items() if name != own_file]
    finite = [v for v in values if np.isfinite(v)]
    return float(np.mean(finite)) if finite else float("nan")


def rest_ratio(positions: np.ndarray, reference: np.ndarray) -> float:
    """Mean upper-body speed in pauses / while speaking (NaN with < MIN_PAUSE_S of pause)."""
    return rest_ratio_of_flags(positions, speaking_flags(extract_features(reference)))


def rest_ratio_of_flags(positions: np.ndarray, speaking: np.ndarray) -> float:
    """:func:`rest_ratio` with the reference's speaking flags (T',) already read."""
    speaking = speaking[: len(positions)]  # (T',)
    speed = upper_body_speed(positions[: len(speaking)], MOTION_FPS)
    if (~speaking).sum() < MIN_PAUSE_S * MOTION_FPS or not speaking.any():
        return float("nan")
    return float(speed[~speaking].mean() / speed[speaking].mean())


def score_case(positions: np.ndarray, case: VoiceCase, onsets: np.ndarray, references: dict[str, np.ndarray]) -> dict:
    values = {"r": following_r(positions, case.reference), "chance": chance_r(positions, case.file, references),
              "bc": beat_consistency(positions, MOTION_FPS, onsets), "rest": rest_ratio(positions, case.reference)}
    return {key: None if not np.isfinite(value) else round(float(value), 4) for key, value in values.items()}


def _mean(rows: list[dict], key: str) -> float | None:
    values = [row[key] for row in rows if row[key] is not None]
    return round(float(np.mean(values)), 4) if values else None


def _seed_sd(rows: list[dict], key: str) -> float | None:
    """The s.d. over seeds of the per-seed means of ``key``."""
    per_seed = [_mean([row for row in rows if row["seed"] == seed], key) for seed in sorted({r["seed"] for r in rows})]
    per_seed = [value for value in per_seed if value is not None]
    return round(float(np.std(per_seed)), 4) if per_seed else None


def condition_summary(rows: list[dict], original_r: dict[str, float]) -> dict:
    """One condition's means; the seed spreads are the s.d. of the per-seed means of r and of the margin."""
    r, chance = _mean(rows, "r"), _mean(rows, "chance")
    originals = [original_r[row["file"]] for row in rows if row["file"] in original_r]
    ratio = None if r is None or not originals or np.mean(originals) <= 0 else round(r / float(np.mean(originals)), 3)
    margins = [{**row, "margin": row["r"] - row["chance"]} for row in rows
               if row["r"] is not None and row["chance"] is not None]
    return {"r": r, "r_seed_sd": _seed_sd(rows, "r"), "chance": chance,
            "margin": None if r is None or chance is None else round(r - chance, 4),
            "margin_seed_sd": _seed_sd(margins, "margin"), "ratio_to_original": ratio,
            "bc": _mean(rows, "bc"), "rest": _mean(rows, "rest"), "files": len({row["file"] for row in rows}),
            "rows": len(rows)}


def overall(groups: dict[str, dict]) -> dict:
    """Every group weighed equally: the mean of the groups' r, chance, margin, bc and rest."""
    return {key: _mean(list(groups.values()), key) for key in ("r", "chance", "margin", "bc", "rest")}


def summarise(rows: list[dict]) -> dict:
    by_condition: dict[str, list[dict]] = {}
    for row in rows:
        by_condition.setdefault(row["condition"], []).append(row)
    originals = by_condition.get(ORIGINAL, [])
    original_r = {name: _mean([row for row in originals if row["file"] == name], "r")
                  for name in {row["file"] for row in originals}}
    original_r = {name: value for name, value in original_r.items() if value is not None}
    order = [ORIGINAL, *TRANSFORMS, *sorted(set(by_condition) - {ORIGINAL, *TRANSFORMS})]
    return {name: condition_summary(by_condition[name], original_r) for name in order if name in by_condition}


def trace(title: str, audio: np.ndarray, positions: np.ndarray) -> VoiceTrace:
    frames = min(len(positions), int(PLOT_SECONDS * MOTION_FPS))
    width = int(round(FOLLOWING.smooth_s * MOTION_FPS)) | 1
    loudness = frame_energy_db(audio, SAMPLE_RATE, MOTION_FPS, frames, FOLLOWING.floor_db)
    speed = upper_body_speed(positions[:frames], MOTION_FPS)
    return VoiceTrace(title, moving_average(loudness, width), moving_average(speed, width), MOTION_FPS)


def parse_seeds(text: str) -> list[int]:
    """``--seeds``' comma-separated generation seeds ("" or spaces: none)."""
    return [int(value) for value in text.split(",") if value.strip()]


def case_key(case: VoiceCase) -> tuple[str, str, str]:
    return case.condition, case.file, case.voice


def picture(cases: list[VoiceCase], motion: dict[tuple[str, str, str], np.ndarray], out: Path, bundle: Path) -> Path:
    """The first case of each of the first PLOT_ROWS conditions (the first seed's motion)."""
    conditions = list(dict.fromkeys(case.condition for case in cases))[:PLOT_ROWS]
    chosen = [next(case for case in cases if case.condition == condition) for condition in conditions]
    traces = [trace(f"{case.condition}: {case.voice or case.file}", case.heard, motion[case_key(case)])
              for case in chosen]
    return plot_voice_traces(traces, out, f"bench voices: {bundle}")


def bench_cases(voice_set: str, cache: Path, shared: Path) -> list[VoiceCase]:
    """The cases of ``--set``."""
    if voice_set == TRANSFORMS_SET:
        return transformed_cases(cache, shared, TRANSFORMS)
    return voice_set_cases(voice_set, shared, cache)


def voices_report(bundle_dir: Path, cache: Path, shared: Path, seeds: list[int], steps: int | None,
                  audio_guidance: float = DEFAULT_AUDIO_GUIDANCE, plot: Path | None = None,
                  voice_set: str = HELD_OUT, guidance: float | None = None,
                  condition: Condition = DEFAULT_CONDITION) -> dict:
    bundle = load_bundle(bundle_dir)
    sampler = SamplerConfig("ddim", steps or bundle.default_steps)
    started = time.perf_counter()
    cases = bench_cases(voice_set, cache, shared)
    references = {case.file: case.reference for case in cases}
    rows, real, first_motion = [], [], {}
    for case in cases:
        onsets = speech_onsets(case.reference, SAMPLE_RATE)
        if case.positions is not None:
            real.append({"condition": case.condition, "file": case.file, "voice": case.voice, "seed": -1,
                         **score_case(case.positions, case, onsets, references)})
        for seed in seeds:
            clip = EvalClip(case.file, case.heard, condition.style)
            positions = generate_offline(bundle, sampler, clip, condition.style, seed, audio_guidance,
                                         guidance=guidance, generator_style=condition.generator_style).positions
            first_motion.setdefault(case_key(case), positions)
            rows.append({"condition": case.condition, "file": case.file, "voice": case.voice, "seed": seed,
                         **score_case(positions, case, onsets, references)})
    conditions = summarise(rows)
    report = {
        "bundle": str(bundle_dir), "set": voice_set, "sampler": f"ddim K={sampler.steps}",
        "audio_guidance": audio_guidance, "guidance": guidance, "seeds": seeds, "condition": condition.describe(),
        "metric": "r: Pearson r of smoothed upper-body speed vs the clean reference speech's RMS dB, best lag "
                  "within ±0.5 s; chance: the same motion against the other recordings; ratio: r / r(original) "
                  "on the same files; rest: speed in pauses / while speaking; bc: BEAT beat consistency",
        "conditions": conditions,
        "overall": overall({name: row for name, row in conditions.items()
                            if name != ORIGINAL and name not in TRANSFORMS}),
        "real_motion": summarise(real),
        "per_file": rows,
        "seconds": round(time.perf_counter() - started, 1),
    }
    if plot is not None:
        report["plot"] = str(picture(cases, first_motion, plot, bundle_dir))
    return report


def run_bench(args: argparse.Namespace) -> int:
    seeds = parse_seeds(args.seeds)
    report = voices_report(args.bundle, args.cache, args.shared, seeds, args.steps, args.audio_guidance, args.plot,
                           args.voice_set, args.guidance, Condition.from_args(args))
    text = json.dumps(report, indent=1)
    if args.json is not None:
        write_text_atomic(args.json, text + "\n")
    print(text)
    return 0
