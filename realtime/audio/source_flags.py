"""CLI glue for audio: ``gesturecast devices`` and the shared source flags for live/file input.

Other commands call :func:`add_source_arguments` on their parser and :func:`open_source` on the
parsed arguments, so every command takes the same ``--input/--device/--sample-rate/--block-size``,
``--stall-timeout`` and ``--pace`` flags.
"""

from __future__ import annotations

import argparse
import sys

from gesturecast.arguments import finite_float, int_at_least
from gesturecast.realtime.audio.portaudio import NO_DEVICE_HINT, list_input_devices
from gesturecast.realtime.audio.sources import (
    DEFAULT_CHUNK,
    AudioSource,
    FastFileSource,
    MicConfig,
    MicSource,
    PacedFileSource,
)
from gesturecast.realtime.audio.watchdog import DEFAULT_STALL_TIMEOUT_S, STALL_WARN_S
from gesturecast.realtime.timing.clock import Clock

PACES = ("realtime", "fast")


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("devices", help="list audio input devices (microphones)")
    parser.set_defaults(func=run_devices)


def run_devices(args: argparse.Namespace) -> int:
    devices = list_input_devices()
    if not devices:
        sys.stdout.write(NO_DEVICE_HINT + "\n")
        return 1
    for device in devices:
        sys.stdout.write(
            f"{device.index:3d}  {device.name}  ({device.host_api}, {device.channels} ch, "
            f"default {device.default_rate:.0f} Hz)\n"
        )
    return 0


def add_source_arguments(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("audio input")
    group.add_argument("--input", metavar="FILE", help="read speech from an audio file instead of the microphone")
    group.add_argument(
        "--pace", choices=PACES, default="realtime", help="with --input: real-time pace or as fast as possible"
    )
    group.add_argument("--device", help="microphone: index or name substring (see `gesturecast devices`)")
    group.add_argument("--sample-rate", type=int_at_least(1), help="microphone rate in Hz (default: the device's own)")
    group.add_argument("--block-size", type=int_at_least(1), default=DEFAULT_CHUNK, help="samples per audio chunk")
    group.add_argument("--stall-timeout", type=finite_float(minimum=0.0, exclusive_minimum=True),
                       default=DEFAULT_STALL_TIMEOUT_S, metavar="SECONDS",
                       help=f"microphone: end the run when the device delivers no samples for this long "
                            f"(a warning comes after {STALL_WARN_S:.0f} s)")


def open_source(args: argparse.Namespace, clock: Clock | None = None) -> AudioSource:
    if args.input:
        if args.pace == "fast":
            return FastFileSource(args.input, chunk_samples=args.block_size)
        return PacedFileSource(args.input, chunk_samples=args.block_size, clock=clock)
    config = MicConfig(device=args.device, sample_rate=args.sample_rate, block_size=args.block_size,
                       stall_timeout_s=args.stall_timeout)
    return MicSource(config, clock=clock)
