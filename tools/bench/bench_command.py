"""``gesturecast bench <what>``: one parser, sub-benchmarks contributed by modules in BENCH_MODULES.

Each bench module exposes ``register_bench(bench_subparsers)``, adding its own sub-command with
``set_defaults(func=...)``. Benchmarks print one JSON object (with ``--json``) and never assert.
"""

from __future__ import annotations

import argparse
import importlib

BENCH_MODULES: tuple[str, ...] = (
    "gesturecast.tools.bench.features",
    "gesturecast.tools.bench.vad",
    "gesturecast.tools.bench.bridges",
    "gesturecast.tools.bench.denoiser",
    "gesturecast.tools.bench.vq",
    "gesturecast.tools.bench.latency",
    "gesturecast.tools.bench.generator",
    "gesturecast.tools.bench.serve",
    "gesturecast.tools.bench.memory",
    "gesturecast.tools.bench.following",
    "gesturecast.tools.bench.speech.voices",
    "gesturecast.tools.bench.denoising",
    "gesturecast.tools.bench.root",
    "gesturecast.tools.bench.speech.lipsync",
    "gesturecast.tools.bench.styles.study",
    "gesturecast.tools.bench.gestures",
    "gesturecast.tools.bench.cues",
    "gesturecast.tools.bench.worker_kill",
    "gesturecast.tools.bench.styles.face",
)


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("bench", help="speed benchmarks (print JSON)")
    bench_subparsers = parser.add_subparsers(dest="bench", required=True)
    for module_name in BENCH_MODULES:
        importlib.import_module(module_name).register_bench(bench_subparsers)
