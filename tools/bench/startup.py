"""``gesturecast bench startup``: how long the command line takes to answer ``--help`` and ``--version``.

Each command line (``gesturecast --help``, ``gesturecast --version`` and every command's ``--help``) runs as its own
process, as a person at the terminal runs it, ``--repeats`` times; the median and the slowest wall time are
reported. What a command imports at start shows here: a command's help should not wait for the modules only its
run needs (scipy, onnxruntime, torch). One JSON object; nothing is asserted.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time

from gesturecast.arguments import int_at_least
from gesturecast.cli import COMMANDS

CLI = (sys.executable, "-m", "gesturecast.cli")
MAX_REPEATS = 50


def register_bench(bench_subparsers: argparse._SubParsersAction) -> None:
    parser = bench_subparsers.add_parser("startup", help="seconds until --help and --version answer, per command")
    parser.add_argument("--repeats", type=int_at_least(1, MAX_REPEATS), default=3,
                        help="runs of each command line (default %(default)s)")
    parser.set_defaults(func=run)


def command_lines() -> list[tuple[str, ...]]:
    """``--help``, ``--version`` and each command's ``--help``."""
    return [("--help",), ("--version",), *((name, "--help") for name in COMMANDS)]


def wall_seconds(arguments: tuple[str, ...]) -> float:
    """Wall time of one run of ``gesturecast ARGUMENTS`` (its output discarded)."""
    start = time.perf_counter()
    subprocess.run([*CLI, *arguments], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    return time.perf_counter() - start


def timing(arguments: tuple[str, ...], repeats: int) -> dict:
    seconds = [wall_seconds(arguments) for _ in range(repeats)]
    return {"command": " ".join(("gesturecast", *arguments)), "median_s": round(statistics.median(seconds), 3),
            "max_s": round(max(seconds), 3)}


def run(args: argparse.Namespace) -> int:
    results = [timing(arguments, args.repeats) for arguments in command_lines()]
    slowest = max(results, key=lambda result: result["median_s"])
    print(json.dumps({"repeats": args.repeats, "results": results, "slowest": slowest}, indent=2))
    return 0
