"""``gesturecast bench vq``: VQ-VAE size and the onnxruntime cost of one streaming decoder step.

Builds a VQ-VAE with random weights (the cost does not depend on the weights), exports the decoder
step to ONNX and times :class:`StreamingVQDecoder.step` on this CPU. Reported: parameter counts,
ONNX size, per-step p50/p95/p99/max milliseconds, and the real-time budget of one step (the
duration of the d motion frames it produces). torch is imported only when this benchmark runs, so
``gesturecast bench`` keeps working on a runtime-only install.
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

from gesturecast.models.runtime.vq import StreamingVQDecoder

MOTION_FPS = 30.0
MS_PER_S = 1000.0
PERCENTILES = (50, 95, 99)
WARMUP_STEPS = 20


def _parameter_count(module) -> int:
    return sum(p.numel() for p in module.parameters())


def benchmark_vq_decoder(config, threads: int = 1, steps: int = 500, seed: int = 0) -> dict:
    """Sizes of a VQ-VAE of this :class:`VQVAEConfig` and its decoder-step latency in onnxruntime (JSON-ready)."""
    import torch

    from gesturecast.models.export.vq import export_vq_decoder_step
    from gesturecast.models.networks.vqvae import MotionVQVAE

    torch.manual_seed(seed)
    model = MotionVQVAE(config).eval()
    data = export_vq_decoder_step(model)
    decoder = StreamingVQDecoder(data, threads=threads)
    latents = np.random.default_rng(seed).standard_normal((WARMUP_STEPS + steps, config.latent_dim)).astype(np.float32)
    timings = []
    for index, latent in enumerate(latents):
        started = time.perf_counter()
        decoder.step(latent)
        if index >= WARMUP_STEPS:
            timings.append((time.perf_counter() - started) * MS_PER_S)
    step_ms = {f"p{q}": float(np.percentile(timings, q)) for q in PERCENTILES} | {"max": float(np.max(timings))}
    return {
        "config": config.to_dict(),
        "parameters": {
            "total": _parameter_count(model),
            "encoder": _parameter_count(model.encoder),
            "decoder": _parameter_count(model.decoder),
            "codebook": model.quantizer.codebook.numel(),
        },
        "onnx_decoder_step_bytes": len(data),
        "threads": threads,
        "steps_timed": steps,
        "decoder_step_ms": step_ms,
        "realtime_budget_ms": config.downsample / MOTION_FPS * MS_PER_S,
    }


def register_bench(bench_subparsers: argparse._SubParsersAction) -> None:
    parser = bench_subparsers.add_parser("vq", help="VQ-VAE parameters and ONNX decoder-step latency")
    parser.add_argument("--json", action="store_true", help="print one JSON object (the only output format)")
    parser.add_argument("--downsample", type=int, default=4, help="motion frames per latent (power of two)")
    parser.add_argument("--hidden-dim", type=int, default=128)
    parser.add_argument("--latent-dim", type=int, default=32)
    parser.add_argument("--feature-dim", type=int, default=136)
    parser.add_argument("--threads", type=int, default=1, help="onnxruntime intra-op threads")
    parser.add_argument("--steps", type=int, default=500, help="decoder steps timed")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from gesturecast.models.networks.vqvae import VQVAEConfig

    config = VQVAEConfig(
        feature_dim=args.feature_dim, hidden_dim=args.hidden_dim, latent_dim=args.latent_dim, downsample=args.downsample
    )
    print(json.dumps(benchmark_vq_decoder(config, threads=args.threads, steps=args.steps), indent=2))
    return 0
