"""``gesturecast bench <what>``: one parser, sub-benchmarks contributed by the modules of :data:`BENCHES`.

Each bench module exposes ``register_bench(bench_subparsers)``, adding its own sub-command with
``set_defaults(func=...)``; it is imported only when its bench is named. Benchmarks print one JSON object (with
``--json``) and never assert.

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

# bench -> (the module whose ``register_bench`` adds it, its line in ``gesturecast bench --help``), in listing order.
# Only the module of the bench being run is imported (:class:`LazyBenches`): the others would cost a second of imports
# (the engine, onnxruntime, matplotlib) that ``bench --help`` never uses. tests/test_cli_help.py checks the lines match.
BENCHES: dict[str, tuple[str, str]] = {
    "features": ("gesturecast.tools.bench.features", "streaming speech-feature cost (rtf, per-chunk ms, memory)"),
    "vad": ("gesturecast.tools.bench.vad", "speaking-flag accuracy: energy vs Silero"),
    "bridges": ("gesturecast.tools.bench.bridges", "bytes per frame and send cost per bridge"),
    "denoiser": ("gesturecast.tools.bench.denoiser", "denoiser parameters and ONNX per-latent latency"),
    "vq": ("gesturecast.tools.bench.vq", "VQ-VAE parameters and ONNX decoder-step latency"),
    "latency": ("gesturecast.tools.bench.timing.latency", "end-to-end latency of the live engine (file or microphone)"),
    "generator": ("gesturecast.tools.bench.generator", "per-latent-step generator latency (DDIM K, DDPM 1000)"),
    "serve": ("gesturecast.tools.bench.serve", "streams per core of `gesturecast serve` (JSON)"),
    "memory": ("gesturecast.tools.bench.memory", "RSS of one session over hours of audio (JSON + plot)"),
    "following": ("gesturecast.tools.bench.following", "speech following on held-out and unseen voices (JSON)"),
    "voices": ("gesturecast.tools.bench.speech.voices", "speech following under voice and channel changes (JSON)"),
    "denoising": ("gesturecast.tools.bench.denoising", "held-out denoising error of training checkpoints"),
    "root": ("gesturecast.tools.bench.root", "root drift (distance, travel, facing) per style and mode"),
    "lipsync": ("gesturecast.tools.bench.speech.lipsync",
                "viseme accuracy (espeak-ng vowels), loudness correlation on real speech, cost"),
    "styles": ("gesturecast.tools.bench.styles.study",
               "style visibility: accuracy vs guidance, motion prompts, per-part styles (JSON)"),
    "gestures": ("gesturecast.tools.bench.gestures", "intended gestures on their words, none on ordinary narration, "
                 "no silent drops (espeak-ng texts; JSON + PNG)"),
    "pipecat": ("gesturecast.tools.bench.agents.pipecat_orders", "a voice agent's gestures on their words, text "
                "after, before or with its audio (Pipecat; JSON)"),
    "cues": ("gesturecast.tools.bench.cues", "far-future words: a stream's cost per latent against a few (JSON)"),
    "worker-kill": ("gesturecast.tools.bench.worker_kill", "serve --workers under churn, one worker SIGKILLed at a "
                    "time: who is served, how the stop ends (JSON)"),
    "idle": ("gesturecast.tools.bench.idle", "motion in settled pauses: real takes against the idle (JSON)"),
    "face": ("gesturecast.tools.bench.styles.face", "blinks and expressions on minutes of speech (JSON + PNG)"),
}


class LazyBenches(argparse._SubParsersAction):
    """The bench sub-commands, each listed by name and help line until it is named: then its module is imported and
    registers its real parser in place of the listing (argparse's sub-parser action, told where the modules are)."""

    def __call__(self, parser: argparse.ArgumentParser, namespace: argparse.Namespace, values: list[str],
                 option_string: str | None = None) -> None:
        name = values[0]
        if name in BENCHES and name in self._listed:
            self._listed.discard(name)
            del self._name_parser_map[name]
            self._choices_actions = [action for action in self._choices_actions if action.dest != name]
            importlib.import_module(BENCHES[name][0]).register_bench(self)
        super().__call__(parser, namespace, values, option_string)

    def list_benches(self) -> None:
        """Add every bench of :data:`BENCHES` by name and help line."""
        self._listed = set(BENCHES)
        for name, (_, help_line) in BENCHES.items():
            self.add_parser(name, help=help_line)


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("bench", help="speed benchmarks (print JSON)")
    bench_subparsers = parser.add_subparsers(dest="bench", required=True, action=LazyBenches)
    bench_subparsers.list_benches()
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

