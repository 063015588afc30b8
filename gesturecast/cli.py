"""The ``gesturecast`` console script: one sub-command per module, registered below.

Each command module exposes ``register(subparsers)``, which adds its parser and sets
``func`` (``args -> exit code``). Errors meant for the user raise :class:`UserError` and are
printed as one line, without a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import sys

from gesturecast.arguments import OneLineParser
from gesturecast.errors import INTERRUPTED_EXIT, USER_ERROR_EXIT_CODE, UserError

DESCRIPTION = ("Real-time avatar driver: speech from a microphone or a recording in, stylized full-body gestures "
               "out over VMC, OSC, WebSocket and BVH.")

# module paths that provide ``register(subparsers)``; imported lazily so that `--help` is fast
COMMAND_MODULES: tuple[str, ...] = (
    "gesturecast.tools.render.cli",
    "gesturecast.tools.data_cli",
    "gesturecast.realtime.audio.cli",
    "gesturecast.tools.bench.cli",
    "gesturecast.tools.train_cli",
    "gesturecast.tools.export_cli",
    "gesturecast.realtime.engine_cli",
    "gesturecast.tools.demo_cli",
    "gesturecast.realtime.serve.cli",
    "gesturecast.tools.eval.cli",
    "gesturecast.tools.eval.train_cli",
)


def build_parser() -> argparse.ArgumentParser:
    parser = OneLineParser(prog="gesturecast", description=DESCRIPTION)
    parser.add_argument("-v", "--verbose", action="store_true", help="debug logging")
    sub = parser.add_subparsers(dest="command", required=True)
    for module_name in COMMAND_MODULES:
        importlib.import_module(module_name).register(sub)
    return parser


def tolerate_narrow_encodings() -> None:
    """Write characters the output's encoding lacks as escapes instead of failing: Windows writes redirected output
    in its ANSI code page (e.g. cp1252), which has no "→", "γ" or "≥" (help texts, style names)."""
    for stream in (sys.stdout, sys.stderr):
        if hasattr(stream, "reconfigure"):
            stream.reconfigure(errors="backslashreplace")


def main(argv: list[str] | None = None) -> int:
    tolerate_narrow_encodings()
    args = build_parser().parse_args(argv)
    logging.basicConfig(
        level=logging.DEBUG if args.verbose else logging.INFO, format="%(levelname)s %(name)s: %(message)s"
    )
    try:
        return int(args.func(args) or 0)
    except UserError as error:
        print(f"gesturecast {args.command}: error: {error}", file=sys.stderr)
        return USER_ERROR_EXIT_CODE
    except KeyboardInterrupt:
        return INTERRUPTED_EXIT


if __name__ == "__main__":
    sys.exit(main())
