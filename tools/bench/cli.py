"""``gesturecast bench <what>``: one parser, sub-benchmarks contributed by modules in BENCH_MODULES.

Each bench module exposes ``register_bench(bench_subparsers)``, adding its own sub-command with
``set_defaults(func=...)``. Benchmarks print one JSON object (with ``--json``) and never assert.

``gesturecast bench startup`` lives here, beside the dispatcher: how long the command line takes to answer
``--help`` and ``--version``. Each command line (``gesturecast --help``, ``gesturecast --version`` and every
command's ``--help``) runs as its own process, as a person at the terminal runs it, ``--repeats`` times; the median
and the slowest wall time are reported. What a command imports at start shows here: a command's help should not
wait for the modules only its run needs (scipy, onnxruntime, torch).
"""

from __future__ import annotations

import argparse
import importlib
import json
import re
import statistics
import subprocess
import sys
import time

from gesturecast.arguments import int_at_least

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
    register_startup(bench_subparsers)


CLI = (sys.executable, "-m", "gesturecast.cli")
MAX_REPEATS = 50
COMMAND_LINE = re.compile(r"^ {4}(\S+)")  # a command's line under COMMAND in `gesturecast --help` (argparse's layout)


def register_startup(bench_subparsers: argparse._SubParsersAction) -> None:
    parser = bench_subparsers.add_parser("startup", help="seconds until --help and --version answer, per command")
    parser.add_argument("--repeats", type=int_at_least(1, MAX_REPEATS), default=3,
                        help="runs of each command line (default %(default)s)")
    parser.set_defaults(func=run_startup)


def command_names(help_text: str) -> list[str]:
    """The commands ``gesturecast --help`` lists (the console script sits above the benchmarks: its table is read
    from its help, not imported)."""
    listing = help_text.split("\n  COMMAND\n", 1)[1].split("\n\n", 1)[0]
    return [match.group(1) for line in listing.splitlines() if (match := COMMAND_LINE.match(line))]


def command_lines() -> list[tuple[str, ...]]:
    """``--help``, ``--version`` and each command's ``--help``."""
    help_text = subprocess.run([*CLI, "--help"], capture_output=True, text=True, check=True).stdout
    return [("--help",), ("--version",), *((name, "--help") for name in command_names(help_text))]


def wall_seconds(arguments: tuple[str, ...]) -> float:
    """Wall time of one run of ``gesturecast ARGUMENTS`` (its output discarded)."""
    start = time.perf_counter()
    subprocess.run([*CLI, *arguments], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    return time.perf_counter() - start


def timing(arguments: tuple[str, ...], repeats: int) -> dict:
    seconds = [wall_seconds(arguments) for _ in range(repeats)]
    return {"command": " ".join(("gesturecast", *arguments)), "median_s": round(statistics.median(seconds), 3),
            "max_s": round(max(seconds), 3)}


def run_startup(args: argparse.Namespace) -> int:
    results = [timing(arguments, args.repeats) for arguments in command_lines()]
    slowest = max(results, key=lambda result: result["median_s"])
    print(json.dumps({"repeats": args.repeats, "results": results, "slowest": slowest}, indent=2))
    return 0

