"""``gesturecast bench generator``: per-latent-step latency of the live generator on this CPU.

For each DDIM step count K (and the full 1000-step DDPM path) a fresh :class:`Generator` streams
``--latents`` latent frames (each d motion frames) with classifier-free guidance (a null-style row)
unless ``--no-guidance`` and audio guidance (an audio-null row) unless ``--audio-guidance 1``.
Reported per sampler: p50 / p95 / max milliseconds per latent step, the real-time budget of one
latent (d / fps seconds) and the real-time factor (compute per second of motion). One JSON object; nothing is asserted.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from gesturecast.models.generator.diffusion import DEFAULT_NUM_TIMESTEPS, SamplerConfig
from gesturecast.models.runtime.bundle import ModelBundle
from gesturecast.realtime.generation.generator import Generator, GeneratorSettings
from gesturecast.settings import DEFAULT_AUDIO_GUIDANCE

DEFAULT_BUNDLE = Path("models/weights/default")
TIMED_DDIM_STEPS = "1,2,4,8"  # the K values timed unless told
WARMUP_LATENTS = 2
MS_PER_S = 1000.0
PERCENTILES = (50, 95)


def register_bench(bench_subparsers: argparse._SubParsersAction) -> None:
    parser = bench_subparsers.add_parser("generator", help="per-latent-step generator latency (DDIM K, DDPM 1000)")
    parser.add_argument("--bundle", type=Path, default=DEFAULT_BUNDLE, help="model bundle (default %(default)s)")
    parser.add_argument("--ddim-steps", default=TIMED_DDIM_STEPS, help="comma-separated K values")
    parser.add_argument("--latents", type=int, default=40, help="timed latent steps per DDIM setting")
    parser.add_argument("--ddpm-latents", type=int, default=3, help="timed 1000-step latents (0: skip)")
    parser.add_argument("--guidance", type=float, default=None, help="guidance scale s (default: the bundle's)")
    parser.add_argument("--no-guidance", action="store_true", help="s = 1: one row per denoiser call")
    parser.add_argument("--audio-guidance", type=float, default=DEFAULT_AUDIO_GUIDANCE,
                        help="audio guidance s_a (1: off, one row less)")
    parser.add_argument("--threads", type=int, default=1, help="onnxruntime intra-op threads")
    parser.set_defaults(func=run_bench)


def time_sampler(bundle: ModelBundle, sampler: SamplerConfig, guidance: float | None, threads: int,
                 latents: int, audio_guidance: float) -> dict:
    settings = GeneratorSettings(sampler=sampler, guidance=guidance, threads=threads, audio_guidance=audio_guidance)
    generator = Generator(bundle, settings)
    rng = np.random.default_rng(0)
    windows = rng.standard_normal((WARMUP_LATENTS + latents, bundle.audio_window, bundle.denoiser_config.audio_dim))
    durations = []
    for index, window in enumerate(windows.astype(np.float32)):
        started = time.perf_counter()
        generator.step(window, True)
        if index >= WARMUP_LATENTS:
            durations.append(time.perf_counter() - started)
    seconds_of_motion = bundle.frames_per_latent / bundle.manifest["fps"]
    values = np.asarray(durations) * MS_PER_S
    return {
        "sampler": sampler.kind,
        "steps": sampler.steps,
        "rows_per_call": generator.layout.batch,
        "latents_timed": latents,
        **{f"p{p}_ms": round(float(np.percentile(values, p)), 3) for p in PERCENTILES},
        "max_ms": round(float(values.max()), 3),
        "budget_ms": round(seconds_of_motion * MS_PER_S, 3),
        "rtf": round(float(np.mean(durations)) / seconds_of_motion, 4),
    }


def run_bench(args: argparse.Namespace) -> int:
    bundle = ModelBundle.load(args.bundle)
    guidance = 1.0 if args.no_guidance else args.guidance
    samplers = [SamplerConfig("ddim", int(k)) for k in args.ddim_steps.split(",")]
    runs = [time_sampler(bundle, sampler, guidance, args.threads, args.latents, args.audio_guidance)
            for sampler in samplers]
    if args.ddpm_latents > 0:
        ddpm = SamplerConfig("ddpm", DEFAULT_NUM_TIMESTEPS)
        runs.append(time_sampler(bundle, ddpm, guidance, args.threads, args.ddpm_latents, args.audio_guidance))
    report = {
        "bundle": str(args.bundle),
        "guidance": bundle.default_guidance if guidance is None else guidance,
        "audio_guidance": args.audio_guidance,
        "threads": args.threads,
        "frames_per_latent": bundle.frames_per_latent,
        "runs": runs,
    }
    print(json.dumps(report, indent=1))
    return 0
