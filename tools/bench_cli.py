"""``gesturecast bench <what>``: one parser, sub-benchmarks contributed by modules in BENCH_MODULES.

Each bench module exposes ``register_bench(bench_subparsers)``, adding its own sub-command with
``set_defaults(func=...)``. Benchmarks print one JSON object (with ``--json``) and never assert.
"""

from __future__ import annotations

import argparse
import importlib

BENCH_MODULES: tuple[str, ...] = (
    "gesturecast.tools.bench_features",
    "gesturecast.tools.bench_vad",
    "gesturecast.tools.bench_bridges",
    "gesturecast.tools.bench_denoiser",
    "gesturecast.tools.bench_vq",
    "gesturecast.tools.bench_latency",
    "gesturecast.tools.bench_generator",
    "gesturecast.tools.bench_serve",
    "gesturecast.tools.bench_memory",
    "gesturecast.tools.bench_following",
    "gesturecast.tools.bench_denoising",
)


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("bench", help="speed benchmarks (print JSON)")
    bench_subparsers = parser.add_subparsers(dest="bench", required=True)
    for module_name in BENCH_MODULES:
        importlib.import_module(module_name).register_bench(bench_subparsers)
