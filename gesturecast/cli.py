"""The ``gesturecast`` console script: sub-commands contributed by the modules of :data:`COMMANDS`.

Each command module exposes ``register(subparsers)``, which adds its parser and sets
``func`` (``args -> exit code``). Errors meant for the user raise :class:`UserError` and are
printed as one line, without a traceback. SIGTERM and SIGHUP end a command as Ctrl-C does
(:mod:`gesturecast.stop_signals`).
"""

from __future__ import annotations

import argparse
import importlib
import logging
import sys

from gesturecast import __version__, stop_signals
from gesturecast.arguments import OneLineParser
from gesturecast.cli_help import describe
from gesturecast.errors import INTERRUPTED_EXIT, USER_ERROR_EXIT_CODE, UserError
from gesturecast.extras import missing_extra

DESCRIPTION = ("Real-time avatar driver: speech from a microphone or a recording in, stylized full-body gestures "
               "out over VMC, OSC, WebSocket and BVH.")

EPILOG = """examples:
  gesturecast demo                                   the bundled sample, live, with no set-up
  gesturecast live --vmc 127.0.0.1:39539             your microphone to VSeeFace / Warudo / VNyan
  gesturecast generate talk.wav -o talk.bvh          a recording to a BVH file
  gesturecast COMMAND --help                         what a command does, its options and examples"""

# command -> (the module whose ``register(subparsers)`` adds it, its line in ``gesturecast --help``), in listing
# order. Only the module of the command being run is imported: the others would cost seconds of imports
# (scipy, matplotlib, torch) that the command never uses. tests/test_cli_help.py checks the lines match.
COMMANDS: dict[str, tuple[str, str]] = {
    "render": ("gesturecast.tools.render.render_command",
               "draw a .bvh or SMPL-X .npz as a stick figure (front + side)"),
    "data": ("gesturecast.tools.data_cli", "training data: build the dataset cache"),
    "gestures": ("gesturecast.tools.gestures.gestures_command",
                 "the gesture lexicon: build it from the Bandai takes, list it"),
    "devices": ("gesturecast.realtime.audio.source_flags", "list audio input devices (microphones)"),
    "bench": ("gesturecast.tools.bench.bench_command", "speed benchmarks (print JSON)"),
    "train": ("gesturecast.tools.train_cli", "train the gesture generator from the dataset cache"),
    "export": ("gesturecast.tools.export_cli", "export a training checkpoint as a model bundle (ONNX + JSON)"),
    "live": ("gesturecast.realtime.engine_cli", "speech in (microphone or --input FILE), gestures out, live"),
    "generate": ("gesturecast.realtime.engine_cli", "offline: audio file → BVH (same session code as live); "
                 "--batch: a folder or CSV of files → a folder of BVHs"),
    "demo": ("gesturecast.tools.demo_cli", "the bundled sample through the live engine (no arguments needed)"),
    "serve": ("gesturecast.realtime.serve.serve_command", "many avatars: audio in / poses out over WebSocket, batched"),
    "eval": ("gesturecast.tools.eval.eval_command", "objective evaluation suite (JSON + plots + table)"),
    "eval-train": ("gesturecast.tools.eval.train_cli", "train the frozen FGD encoder and style classifier"),
    "style-fit": ("gesturecast.tools.style.style_fit_command",
                  "fit the stylizer's styles and the style judge (Bandai takes)"),
}
NO_COMMAND = ""  # ``build_parser(only=NO_COMMAND)``: the parser of a command line naming no command imports none


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """Every command's parser; with ``only`` (the command line's first word that is not an option), only that
    command's module is imported, none when it names no command (``""``: ``--help``, ``--version``), and the
    others are listed by name and help line."""
    parser = OneLineParser(prog="gesturecast", description=DESCRIPTION, epilog=EPILOG,
                           formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("-v", "--verbose", action="store_true", help="debug logging")
    parser.add_argument("--version", action="version", version=f"gesturecast {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    wanted = None if only is None else COMMANDS.get(only, (NO_COMMAND,))[0]
    for module_name in dict.fromkeys(module for module, _ in COMMANDS.values()):
        if wanted in (None, module_name):
            importlib.import_module(module_name).register(sub)
            continue
        for name, (owner, help_line) in COMMANDS.items():
            if owner == module_name:
                sub.add_parser(name, help=help_line)
    for name, command_parser in sub.choices.items():
        describe(name, command_parser)
    return parser


def command_in(argv: list[str]) -> str | None:
    """The sub-command named on a command line (the first word that is not an option)."""
    return next((word for word in argv if not word.startswith("-")), None)


def tolerate_narrow_encodings() -> None:
    """Write characters the output's encoding lacks as escapes instead of failing: Windows writes redirected output
    in its ANSI code page (e.g. cp1252), which has no "→", "γ" or "≥" (help texts, style names)."""
    for stream in (sys.stdout, sys.stderr):
        if hasattr(stream, "reconfigure"):
            stream.reconfigure(errors="backslashreplace")


def main(argv: list[str] | None = None) -> int:
    tolerate_narrow_encodings()
    argv = sys.argv[1:] if argv is None else argv
    args = build_parser(only=command_in(argv) or NO_COMMAND).parse_args(argv)
    level = logging.DEBUG if getattr(args, "verbose", False) else logging.INFO  # -v before or after the command
    logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s")
    with stop_signals.handled():  # SIGTERM / SIGHUP end the command as Ctrl-C does
        return stop_signals.exit_status(run_command(args))


def run_command(args: argparse.Namespace) -> int:
    """The command's exit status; a :class:`UserError` is printed as one line, Ctrl-C ends with 130."""
    try:
        return int(args.func(args) or 0)
    except UserError as error:
        print(f"gesturecast {args.command}: error: {error}", file=sys.stderr)
        return USER_ERROR_EXIT_CODE
    except ModuleNotFoundError as error:  # an optional extra that is not installed (torch, Ray, Pipecat)
        message = missing_extra(error)
        if message is None:
            raise
        print(f"gesturecast {args.command}: error: {message}", file=sys.stderr)
        return USER_ERROR_EXIT_CODE
    except KeyboardInterrupt:
        return INTERRUPTED_EXIT


if __name__ == "__main__":
    sys.exit(main())
