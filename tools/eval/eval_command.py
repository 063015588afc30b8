"""`gesturecast eval --json OUT.json`: the objective evaluation suite (docs/evaluation.md).

Runs ground truth, mismatched ground truth, DDPM (limited duration) and DDIM K = 1, 2, 4, 8 on the
held-out test segments of the paired takes and on unseen speech; checks the live path against the
offline one; optionally compares models trained with other audio look-aheads. Writes the JSON, two
plots beside it, and prints a Markdown table.
"""

from __future__ import annotations

import argparse
import logging
import time
from dataclasses import asdict, replace
from pathlib import Path

from gesturecast.errors import UserError
from gesturecast.models.evaluation.fgd_encoder import DEFAULT_FGD_ENCODER, FGDEncoder
from gesturecast.models.evaluation.style_classifier import DEFAULT_STYLE_CLASSIFIER, StyleClassifier
from gesturecast.realtime.run.engine_setup import load_bundle
from gesturecast.settings import DEFAULT_MODEL_DIR
from gesturecast.tools.data_cli import DEFAULT_CACHE, DEFAULT_SHARED
from gesturecast.tools.eval.clips import default_unseen_paths, held_out_clips, reference_positions, unseen_clips
from gesturecast.tools.eval.condition import Condition, add_condition_arguments
from gesturecast.tools.eval.metrics import EvalNetworks
from gesturecast.tools.eval.report import ddim_vs_ddpm, format_table, git_commit, plot_curves, write_json
from gesturecast.tools.eval.suite import QUICK, SYSTEM_NAMES, EvalConfig, EvalSets, SuiteRunner

LOGGER = logging.getLogger(__name__)


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("eval", help="objective evaluation suite (JSON + plots + table)")
    parser.add_argument("--json", type=Path, required=True, metavar="OUT.json", help="results file")
    parser.add_argument("--model", type=Path, default=DEFAULT_MODEL_DIR, help="model bundle (default: bundled)")
    parser.add_argument("--quick", action="store_true", help="short crops everywhere (about a minute)")
    parser.add_argument("--cache", type=Path, default=DEFAULT_CACHE, help="dataset cache (default %(default)s)")
    parser.add_argument("--unseen", type=Path, nargs="*", help="unseen speech files (default: the shared "
                        "Flirty take and synthetic speech, else the packaged sample)")
    parser.add_argument("--shared", type=Path, default=DEFAULT_SHARED, help="shared data folder (default %(default)s)")
    parser.add_argument("--systems", nargs="+", choices=SYSTEM_NAMES, help="systems to run (default: all)")
    parser.add_argument("--styles", nargs="+", help="styles requested for style accuracy (default: the model's "
                        "trained styles the classifier knows)")
    parser.add_argument("--ddpm-seconds", type=float, help="crop of every clip DDPM runs on (costly: "
                        "~5 s of compute per second of motion)")
    parser.add_argument("--seed", type=int, default=0,
                        help="generation seed of every system (default 0); compare models over several")
    add_condition_arguments(parser)
    parser.add_argument("--lookahead-models", type=Path, nargs="*", default=[], metavar="DIR",
                        help="bundles trained with another look-ahead, compared at K = 4 on the held-out set")
    parser.add_argument("--fgd-encoder", type=Path, default=DEFAULT_FGD_ENCODER, help=argparse.SUPPRESS)
    parser.add_argument("--style-classifier", type=Path, default=DEFAULT_STYLE_CLASSIFIER, help=argparse.SUPPRESS)
    parser.set_defaults(func=run_eval)


def eval_config(args: argparse.Namespace) -> EvalConfig:
    config = replace(QUICK if args.quick else EvalConfig(), seed=args.seed, condition=Condition.from_args(args))
    if args.systems:
        config = replace(config, systems=tuple(n for n in SYSTEM_NAMES if n in args.systems))
    if args.styles:
        config = replace(config, styles=tuple(args.styles))
    if args.ddpm_seconds is not None:
        config = replace(config, ddpm_seconds=args.ddpm_seconds)
    return config


def requested_styles(config: EvalConfig, model_styles: tuple[str, ...], classifier: StyleClassifier) -> tuple:
    styles = config.styles or tuple(s for s in model_styles if s in classifier.labels)
    unknown = [s for s in styles if s not in model_styles]
    if unknown:
        raise UserError(f"the model has no style {', '.join(unknown)}; it knows: {', '.join(model_styles)}")
    return styles


def run_eval(args: argparse.Namespace) -> int:
    started = time.perf_counter()
    config = eval_config(args)
    bundle = load_bundle(args.model)
    networks = EvalNetworks(FGDEncoder.load(args.fgd_encoder), StyleClassifier.load(args.style_classifier),
                            reference_positions(args.cache))
    unseen_paths = args.unseen if args.unseen else default_unseen_paths(args.shared)
    sets = EvalSets(
        held_out=[c.crop(config.held_out_seconds) for c in held_out_clips(args.cache)],
        unseen=unseen_clips(unseen_paths, config.condition.style, config.unseen_seconds),
        styles=requested_styles(config, bundle.styles.trained, networks.classifier),
    )
    runner = SuiteRunner(bundle, networks, sets, config)
    systems = {name: runner.run_system(name) for name in config.systems}
    live = runner.live_vs_offline()
    live_system = f"ddim_k{bundle.default_steps}"  # the model's own K
    lookahead = {str(bundle.audio_lookahead): systems.get(live_system)} if args.lookahead_models else {}
    for path in args.lookahead_models:
        other = load_bundle(path)
        other_runner = SuiteRunner(other, networks, sets, replace(config, systems=()), progress=False)
        lookahead[str(other.audio_lookahead)] = other_runner.held_out_only(live_system)
    runner.bar.close()
    report = {
        **git_commit(),
        "model": {"path": str(args.model), "audio_lookahead": bundle.audio_lookahead,
                  "frames_per_latent": bundle.frames_per_latent},
        "eval_networks": {"fgd_encoder_version": networks.encoder.version,
                          "style_classifier_version": networks.classifier.version,
                          "style_classifier_held_out": networks.classifier.stamp.get("held_out")},
        "config": {**asdict(config), "quick": args.quick},
        "sets": {"held_out": [[c.name, c.seconds] for c in sets.held_out],
                 "unseen": [[c.name, c.seconds] for c in sets.unseen], "styles": list(sets.styles)},
        "systems": systems,
        "deltas": {"live_vs_offline": live, "ddim_minus_ddpm": ddim_vs_ddpm(systems), "lookahead": lookahead},
        "runtime_s": time.perf_counter() - started,
    }
    write_json(report, args.json)
    plots = plot_curves(systems, lookahead, args.json)
    print(format_table(systems))
    print(f"live vs offline ({live['sampler']}): max |Δ position| = {live['max_abs_position_difference_m']:.2e} m")
    print(f"wrote {args.json} and {', '.join(p.name for p in plots)} in {report['runtime_s']:.0f} s")
    return 0
