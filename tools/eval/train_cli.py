"""`gesturecast eval-train`: train, freeze and stamp the evaluation networks (FGD encoder, style classifier).

Run once by a maintainer; the weights are committed under models/weights/eval/ and replaced only
with a version bump (see gesturecast.models.evaluation.build).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from gesturecast.models.evaluation.fgd_encoder import EVAL_WEIGHTS_DIR
from gesturecast.tools.data_cli import DEFAULT_CACHE


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("eval-train", help="train the frozen FGD encoder and style classifier")
    parser.add_argument("--cache", type=Path, default=DEFAULT_CACHE, help="dataset cache (default %(default)s)")
    parser.add_argument("--out", type=Path, default=EVAL_WEIGHTS_DIR, help="output folder (default: the bundled one)")
    parser.add_argument("--steps", type=int, help="optimiser steps per network (default: EvalTrainConfig's)")
    parser.add_argument("--seed", type=int, default=0, help="random seed (default %(default)s)")
    parser.set_defaults(func=run_eval_train)


def run_eval_train(args: argparse.Namespace) -> int:
    from gesturecast.models.evaluation.build import build_eval_models  # needs torch (the `train` extra)
    from gesturecast.models.evaluation.train_networks import EvalTrainConfig

    steps = {} if args.steps is None else {"steps": args.steps}
    config = EvalTrainConfig(seed=args.seed, **steps)
    for path in build_eval_models(args.cache, args.out, config):
        print(f"wrote {path} and {path.with_suffix('.json').name}")
    return 0
