"""``gesturecast bench denoising CHECKPOINT...``: held-out denoising error of trained denoisers (JSON).

For each training checkpoint (``.cache/train/<run>/checkpoint.pt``):
:func:`gesturecast.models.evaluation.denoising.held_out_denoising_error` on the paired takes' test
segments — x0 Huber error with the speech, without it, and with another window's speech, under
the same fixed noise draws — plus the run's look-ahead δa and training steps. Nothing is asserted.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from gesturecast.tools.data_cli import DEFAULT_CACHE


def register_bench(bench_subparsers: argparse._SubParsersAction) -> None:
    parser = bench_subparsers.add_parser("denoising", help="held-out denoising error of training checkpoints")
    parser.add_argument("checkpoints", type=Path, nargs="+", help="training checkpoint files")
    parser.add_argument("--cache", type=Path, default=DEFAULT_CACHE, help="dataset cache (default %(default)s)")
    parser.add_argument("--draws", type=int, default=32, help="fixed noise draws per window")
    parser.set_defaults(func=run_bench)


def run_bench(args: argparse.Namespace) -> int:
    from gesturecast.models.evaluation.denoising import HeldOutConfig, held_out_denoising_error
    from gesturecast.models.training.pipeline import load_checkpoint

    results = {}
    for path in args.checkpoints:
        checkpoint = load_checkpoint(path)
        preset = checkpoint["preset"]
        error = held_out_denoising_error(checkpoint, args.cache, HeldOutConfig(draws=args.draws))
        rounded = {key: round(value, 5) if isinstance(value, float) else value for key, value in error.items()}
        results[str(path)] = {"audio_lookahead": preset["audio_lookahead"],
                              "denoiser_steps": preset["denoiser"]["steps"],
                              "audio_augmentation": preset.get("audio_augmentation", False), **rounded}
    print(json.dumps(results, indent=1))
    return 0
