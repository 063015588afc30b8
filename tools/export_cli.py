"""`gesturecast export CHECKPOINT -o DIR`: a training checkpoint → a model bundle (ONNX + model.json)."""

from __future__ import annotations

import argparse
from pathlib import Path


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("export", help="export a training checkpoint as a model bundle (ONNX + JSON)")
    parser.add_argument("checkpoint", type=Path, help="checkpoint.pt or the training work folder holding it")
    parser.add_argument("-o", "--out", type=Path, required=True, help="bundle folder, e.g. models/weights/default")
    parser.set_defaults(func=run_export)


def run_export(args: argparse.Namespace) -> int:
    from gesturecast.models.export.bundle import export_bundle
    from gesturecast.models.training.pipeline import CHECKPOINT_FILE, load_checkpoint

    path = args.checkpoint / CHECKPOINT_FILE if args.checkpoint.is_dir() else args.checkpoint
    export_bundle(load_checkpoint(path), args.out)
    print(f"bundle written to {args.out}")
    return 0
