"""``gesturecast bench denoiser``: size and onnxruntime cost of the causal latent denoiser (prints JSON).

A default-config denoiser with random weights is exported to ONNX and run through the live loop:
per latent frame, K DDIM steps (Song et al. 2021) with classifier-free guidance as one batch-2 call
each (cond + uncond rows), the previous latent's commit folded into the first call. Reported per K:
median / p95 ms per latent frame and the real-time factor against the latent period d/30 s.
The 1000-step DDPM path is estimated from the marginal cost of one more call, (t(K=8) − t(K=1)) / 7,
times 1000 calls per latent.

    python -m gesturecast.tools.bench.denoiser --latents 60 --threads 1
"""

from __future__ import annotations

import argparse
import json
import platform
import time
from pathlib import Path

import numpy as np

from gesturecast.models.generator.denoiser_config import DenoiserConfig
from gesturecast.models.generator.diffusion import SamplerConfig, classifier_free_guidance, get_schedule, sampler_step
from gesturecast.models.generator.diffusion import sampling_plan as make_plan
from gesturecast.models.runtime.denoiser_runtime import DenoiserRuntime, condition_path

BENCH_DIR = Path(".cache/bench")
DDIM_STEPS = (1, 2, 4, 8)
DDPM_STEPS = 1000
GUIDANCE_SCALE = 2.0
CFG_BATCH = 2  # cond + uncond rows
MOTION_FPS = 30.0
MS_PER_S = 1000.0
P95 = 95
WARMUP_LATENTS = 3


def register_bench(bench_subparsers: argparse._SubParsersAction) -> None:
    parser = bench_subparsers.add_parser("denoiser", help="denoiser parameters and ONNX per-latent latency")
    add_arguments(parser)
    parser.set_defaults(func=run)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--latents", type=int, default=60, help="latent frames timed per K")
    parser.add_argument("--threads", type=int, default=1, help="onnxruntime intra-op threads")
    parser.add_argument("--json", action="store_true", help="print one JSON object (always JSON)")


def export_default(config: DenoiserConfig, out_dir: Path = BENCH_DIR) -> tuple[Path, int]:
    """Random-weight default model → ONNX; returns (path, parameter count). Needs torch (training extra)."""
    import torch

    from gesturecast.models.export.denoiser_onnx import export_denoiser
    from gesturecast.models.networks.denoiser_network import CausalDenoiser

    torch.manual_seed(0)
    model = CausalDenoiser(config)
    out_dir.mkdir(parents=True, exist_ok=True)
    return export_denoiser(model, out_dir / "denoiser_default.onnx"), sum(p.numel() for p in model.parameters())


def time_stream(runtime: DenoiserRuntime, steps: int, num_latents: int, rng: np.random.Generator) -> list[float]:
    """Seconds per latent frame of the live loop with K = ``steps`` DDIM steps and guidance."""
    cfg = runtime.config
    schedule = get_schedule()
    plan = make_plan(schedule.num_timesteps, SamplerConfig("ddim", steps))
    style = np.repeat(rng.standard_normal((1, cfg.style_dim)).astype(np.float32), CFG_BATCH, axis=0)  # (2, S)
    style_present = np.array([1.0, 0.0], np.float32)  # cond, uncond
    runtime.reset(CFG_BATCH)
    durations = []
    for _ in range(num_latents + WARMUP_LATENTS):
        audio = rng.standard_normal((CFG_BATCH, cfg.audio_window, cfg.audio_dim)).astype(np.float32)  # (2, A, F)
        start = time.perf_counter()
        condition = runtime.frame_condition(audio, style, style_present=style_present)  # (2, Dc)
        x = rng.standard_normal((1, cfg.latent_dim))  # (1, C)
        for t, t_prev in plan:
            both = np.repeat(x, CFG_BATCH, axis=0)  # (2, C)
            x0 = runtime.step(both, t, condition)  # (2, C)
            guided = classifier_free_guidance(x0[1:], x0[:1], GUIDANCE_SCALE)  # (1, C)
            x = sampler_step(schedule, SamplerConfig("ddim", steps), guided, t, t_prev, x)
        runtime.commit(np.repeat(x, CFG_BATCH, axis=0), condition)
        durations.append(time.perf_counter() - start)
    return durations[WARMUP_LATENTS:]


def summarize(durations: list[float], latent_period_s: float) -> dict:
    median = float(np.median(durations))
    return {
        "ms_per_latent_p50": round(median * MS_PER_S, 3),
        "ms_per_latent_p95": round(float(np.percentile(durations, P95)) * MS_PER_S, 3),
        "real_time_factor": round(median / latent_period_s, 4),
    }


def measure(args: argparse.Namespace) -> dict:
    config = DenoiserConfig()
    path, parameters = export_default(config)
    runtime = DenoiserRuntime(path, threads=args.threads)
    rng = np.random.default_rng(0)
    latent_period_s = config.frames_per_latent / MOTION_FPS
    per_k = {k: summarize(time_stream(runtime, k, args.latents, rng), latent_period_s) for k in DDIM_STEPS}
    low, high = min(DDIM_STEPS), max(DDIM_STEPS)
    call_ms = (per_k[high]["ms_per_latent_p50"] - per_k[low]["ms_per_latent_p50"]) / (high - low)
    ddpm_ms = DDPM_STEPS * call_ms
    return {
        "config": config.to_dict(),
        "parameters": parameters,
        "onnx_bytes": path.stat().st_size + condition_path(path).stat().st_size,
        "threads": args.threads,
        "cfg_batch": CFG_BATCH,
        "latent_period_ms": round(latent_period_s * MS_PER_S, 3),
        "ddim": {str(k): v for k, v in per_k.items()},
        "ddpm_1000_estimate": {
            "ms_per_call": round(call_ms, 3),
            "ms_per_latent": round(ddpm_ms, 1),
            "real_time_factor": round(ddpm_ms / MS_PER_S / latent_period_s, 2),
            "seconds_per_second_of_motion": round(ddpm_ms / MS_PER_S * MOTION_FPS / config.frames_per_latent, 2),
        },
        "machine": platform.processor() or platform.machine(),
    }


def run(args: argparse.Namespace) -> int:
    print(json.dumps(measure(args), indent=2))
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_arguments(parser)
    return run(parser.parse_args(argv))


if __name__ == "__main__":
    raise SystemExit(main())
