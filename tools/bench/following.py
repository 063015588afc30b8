"""``gesturecast bench following``: does a model's motion follow the speech of voices it never heard?

For a bundle, motion is generated through the product's offline path (``run_offline``, DDIM K,
the bundle's guidance) at the product's default settings unless ``--style`` / ``--generator-style`` ask for another
condition (:mod:`gesturecast.tools.eval.condition`), for: the held-out test segments of the paired takes (seen speakers,
unseen sentences; their real motion is scored too), the unseen ZeroEGGS Flirty recording and the
synthetic espeak voices (the shared data folder, ``--shared``), each alone and all six joined into one stream
with 1.5 s pauses (does the motion rest in the pauses?). Per file and seed: the energy–speed correlation
of :mod:`gesturecast.models.evaluation.speech_following` (lag searched within ±0.5 s) and BEAT beat
consistency. Groups report the mean over files and seeds. One JSON object; nothing is asserted.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from gesturecast.files import write_text_atomic
from gesturecast.models.audio.files import SAMPLE_RATE
from gesturecast.models.evaluation.beat_consistency import beat_consistency, speech_onsets
from gesturecast.models.evaluation.speech_following import FollowingConfig, speech_following
from gesturecast.models.generator.diffusion import SamplerConfig
from gesturecast.models.motion.motion import MOTION_FPS
from gesturecast.realtime.generation.generator import check_lookahead
from gesturecast.realtime.run.engine_setup import load_bundle
from gesturecast.settings import DEFAULT_AUDIO_GUIDANCE, DEFAULT_MODEL_DIR, LATENCY_SETTINGS, QUALITY
from gesturecast.tools.data_cli import DEFAULT_CACHE, DEFAULT_SHARED
from gesturecast.tools.eval.clips import EvalClip, default_unseen_paths, held_out_clips, unseen_clips
from gesturecast.tools.eval.condition import DEFAULT_CONDITION, Condition, add_condition_arguments
from gesturecast.tools.eval.generate import generate_offline

DEFAULT_SEEDS = "0,1,2"
JOIN_GAP_S = 1.5  # silence between the espeak sentences of the joined stream


def register_bench(bench_subparsers: argparse._SubParsersAction) -> None:
    parser = bench_subparsers.add_parser("following", help="speech following on held-out and unseen voices (JSON)")
    parser.add_argument("--bundle", type=Path, default=DEFAULT_MODEL_DIR, help="model bundle (default: bundled)")
    parser.add_argument("--cache", type=Path, default=DEFAULT_CACHE, help="dataset cache (held-out segments)")
    parser.add_argument("--shared", type=Path, default=DEFAULT_SHARED, help="shared data folder (unseen speech)")
    parser.add_argument("--seeds", default=DEFAULT_SEEDS, help="comma-separated generation seeds")
    parser.add_argument("--steps", type=int, default=None, help="DDIM steps K (default: the model's)")
    parser.add_argument("--audio-guidance", type=float, default=DEFAULT_AUDIO_GUIDANCE,
                        help="audio guidance scale s_a (1: off)")
    parser.add_argument("--guidance", type=float, help="style guidance scale s (default: the model's)")
    parser.add_argument("--latency", choices=tuple(LATENCY_SETTINGS), default=QUALITY.name,
                        help="latency setting whose look-ahead the motion is generated with (docs/latency.md)")
    add_condition_arguments(parser)
    parser.add_argument("--json", type=Path, help="also write the result here")
    parser.set_defaults(func=run_bench)


def joined_clip(clips: list[EvalClip], name: str, gap_s: float) -> EvalClip:
    """One stream of the clips' audio with ``gap_s`` of silence after each."""
    gap = np.zeros(int(round(gap_s * SAMPLE_RATE)), np.float32)
    return EvalClip(name, np.concatenate([part for clip in clips for part in (clip.audio, gap)]), clips[0].style)


def group_of(clip: EvalClip) -> str:
    if clip.name == "espeak_joined":
        return clip.name
    if clip.name.endswith("[test]"):
        return f"heldout_{clip.name.split('/')[0]}"
    return "espeak" if clip.name.startswith("tts_") else Path(clip.name).stem.split("_")[1].lower()


def score(positions: np.ndarray, audio: np.ndarray, onsets: np.ndarray) -> dict:
    """Following and beat consistency of motion for ``audio`` (``onsets``: its speech onsets, seconds)."""
    following = speech_following(positions, audio, SAMPLE_RATE, MOTION_FPS, FollowingConfig())
    bc = beat_consistency(positions, MOTION_FPS, onsets)
    return {**following.to_dict(), "bc": None if not np.isfinite(bc) else round(bc, 4)}


def _mean(rows: list[dict], key: str) -> float | None:
    values = [row[key] for row in rows if row[key] is not None and np.isfinite(row[key])]
    return round(float(np.mean(values)), 4) if values else None


def summarise(rows: list[dict]) -> dict:
    groups: dict[str, list[dict]] = {}
    for row in rows:
        groups.setdefault(row["group"], []).append(row)
    return {name: {"r_best": _mean(g, "r_best"), "r_lag0": _mean(g, "r_lag0"), "bc": _mean(g, "bc"),
                   "files": len({row["file"] for row in g})} for name, g in sorted(groups.items())}


def following_report(bundle_dir: Path, cache: Path, shared: Path, seeds: list[int], steps: int | None,
                     audio_guidance: float = DEFAULT_AUDIO_GUIDANCE, latency: str = QUALITY.name,
                     guidance: float | None = None, condition: Condition = DEFAULT_CONDITION) -> dict:
    bundle = load_bundle(bundle_dir)
    lookahead = LATENCY_SETTINGS[latency].lookahead_for(bundle.audio_lookahead)
    check_lookahead(bundle.denoiser_config, lookahead)
    sampler = SamplerConfig("ddim", steps or bundle.default_steps)
    unseen = unseen_clips(default_unseen_paths(shared), condition.style, None)
    espeak = [clip for clip in unseen if clip.name.startswith("tts_")]
    joined = [joined_clip(espeak, "espeak_joined", JOIN_GAP_S)] if espeak else []
    clips = [*held_out_clips(cache), *unseen, *joined]
    rows, real = [], []
    started = time.perf_counter()
    for clip in clips:
        onsets = speech_onsets(clip.audio, SAMPLE_RATE)  # the same for the real motion and every seed
        if clip.positions is not None:
            real.append({"file": clip.name, "group": group_of(clip), **score(clip.positions, clip.audio, onsets)})
        for seed in seeds:
            generated = generate_offline(bundle, sampler, clip, condition.style, seed, audio_guidance, lookahead,
                                         guidance, generator_style=condition.generator_style)
            rows.append({"file": clip.name, "group": group_of(clip), "seed": seed,
                         **score(generated.positions, clip.audio, onsets)})
    return {
        "bundle": str(bundle_dir),
        "sampler": f"ddim K={sampler.steps}",
        "audio_guidance": audio_guidance,
        "guidance": bundle.default_guidance if guidance is None else guidance,
        "latency": latency,
        "lookahead_frames": lookahead,
        "seeds": seeds,
        "condition": condition.describe(),
        "metric": "Pearson r of smoothed upper-body joint speed vs frame RMS dB, best lag within ±0.5 s; "
                  "BC = BEAT beat consistency",
        "generated": summarise(rows),
        "real_motion": summarise(real),
        "per_file": rows,
        "seconds": round(time.perf_counter() - started, 1),
    }


def run_bench(args: argparse.Namespace) -> int:
    seeds = [int(value) for value in args.seeds.split(",")]
    report = following_report(args.bundle, args.cache, args.shared, seeds, args.steps, args.audio_guidance,
                              args.latency, args.guidance, Condition.from_args(args))
    text = json.dumps(report, indent=1)
    if args.json is not None:
        write_text_atomic(args.json, text + "\n")
    print(text)
    return 0
