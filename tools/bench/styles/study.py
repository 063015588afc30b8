"""``gesturecast bench styles``: how visible the styles are (docs/style-study.md). Prints one JSON object.

1. ``guidance``: per guidance scale s, style accuracy and the confusion matrix of the frozen style
   classifier over every style both the model and the classifier know (:mod:`.guidance_sweep`), and the
   neutral style's motion metrics on the held-out clips;
2. ``motion_prompts``: two real styled takes written as 120 fps CMU-style BVH drive generation as
   motion prompts; how far apart the results' mean upper-body poses are, vs the label prompts
   (:mod:`.motion_prompts`);
3. ``part_styles``: per-part prompts at the bundle's s — signatures, seams, metrics and compute vs
   single-style generation (:mod:`.part_styles`);
4. ``stylizer``: the seven judged styles on held-out speech at the default settings with and without the stylizer
   after the generator: FK distances and seed floor, the style judge beside the old classifier, speech following,
   jerk, the face, the stylizer's cost (:mod:`.stylizer_study`). ``--stylizer-only`` runs this part alone (it
   needs no dataset cache, only the shared data folder).

Everything runs on the same speech (the first held-out clip at least ``--seconds`` long) through the
product's offline session, DDIM at the model's K, with every ``--seeds`` (default 0; the per-part study uses the first).
Nothing is asserted. Definitions: docs/style-study.md.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from dataclasses import asdict, dataclass, replace
from pathlib import Path

from gesturecast.errors import UserError
from gesturecast.files import write_text_atomic
from gesturecast.models.evaluation.fgd_encoder import FGDEncoder
from gesturecast.models.evaluation.style_classifier import StyleClassifier
from gesturecast.models.generator.diffusion import SamplerConfig
from gesturecast.models.runtime.bundle import ModelBundle
from gesturecast.realtime.run.engine_setup import load_bundle
from gesturecast.settings import DEFAULT_AUDIO_GUIDANCE, DEFAULT_MODEL_DIR
from gesturecast.tools.bench.styles.guidance_sweep import guidance_entry
from gesturecast.tools.bench.styles.motion_prompts import prompt_comparison, write_prompt_clip
from gesturecast.tools.bench.styles.part_styles import DEFAULT_PAIRS, TIMING_REPEATS, PartPair, part_study
from gesturecast.tools.bench.styles.runs import StudyRuns
from gesturecast.tools.bench.styles.sheet import SHEET_STYLES, style_sheet
from gesturecast.tools.bench.styles.stylizer_study import stylizer_report
from gesturecast.tools.data_cli import DEFAULT_CACHE, DEFAULT_SHARED
from gesturecast.tools.eval.clips import EvalClip, held_out_clips, reference_positions
from gesturecast.tools.eval.metrics import EvalNetworks

STYLIZER_SEEDS = (0, 1, 2)  # the stylizer part's seeds: two can agree by chance and hide the floor (style-study.md)


@dataclass(frozen=True)
class StudyConfig:
    guidance: tuple[float, ...] = (1.5, 2.5, 4.0, 6.0)  # classifier-free guidance scales s
    seconds: float = 8.0  # speech generated per style request
    max_styles: int | None = None  # only the first N styles of the model ∩ classifier (None: all)
    prompt_styles: tuple[str, str] = ("old", "angry")  # the two motion prompts' styles
    pairs: tuple[PartPair, ...] = DEFAULT_PAIRS
    steps: int | None = None  # DDIM K (None: the model's)
    seeds: tuple[int, ...] = (0,)  # generation seeds (confusion counts pooled; per-part study: the first)
    timing_repeats: int = TIMING_REPEATS  # fresh generations per request timed for the per-part compute cost
    audio_guidance: float = DEFAULT_AUDIO_GUIDANCE  # s_a: < 1 weakens the speech's pull toward the paired takes' style


QUICK = StudyConfig(guidance=(1.5,), seconds=2.5, max_styles=2, timing_repeats=1)
STYLIZER_S, QUICK_STYLIZER_S = 60.0, 10.0  # held-out speech per style in the stylizer part


def register_bench(bench_subparsers: argparse._SubParsersAction) -> None:
    parser = bench_subparsers.add_parser("styles", help="style visibility: accuracy vs guidance, motion prompts, "
                                         "per-part styles (JSON)")
    parser.add_argument("--model", type=Path, default=DEFAULT_MODEL_DIR, help="model bundle (default: bundled)")
    parser.add_argument("--cache", type=Path, default=DEFAULT_CACHE, help="dataset cache (default %(default)s)")
    parser.add_argument("--guidance", type=float, nargs="+", help="guidance scales s (default 1.5 2.5 4 6)")
    parser.add_argument("--seconds", type=float, help="seconds of speech per style request (default 8)")
    parser.add_argument("--prompt-styles", nargs=2, metavar=("A", "B"), help="styles of the two motion-prompt "
                        "takes (default: old angry)")
    parser.add_argument("--seeds", type=int, nargs="+", help="generation seeds (default: 0)")
    parser.add_argument("--audio-guidance", type=float, help=f"audio guidance s_a of every generation (default "
                        f"{DEFAULT_AUDIO_GUIDANCE}; docs/style-study.md: styles vs speech following)")
    parser.add_argument("--prompt-dir", type=Path, help="keep the CMU BVH prompts here (default: a temporary folder)")
    parser.add_argument("--quick", action="store_true", help="2 styles, s = 1.5 only, 2.5 s (for tests)")
    parser.add_argument("--data", type=Path, default=DEFAULT_SHARED,
                        help="shared data folder: held-out speech and real motion for the stylizer part "
                             "(default %(default)s)")
    parser.add_argument("--stylizer-seconds", type=float,
                        help="seconds of held-out speech per style in the stylizer part (default 60; --quick: 10)")
    parser.add_argument("--grid", type=Path, help="PNG: the stylizer part's styles (rows) at 8, 20, 32, 44, 56 s "
                        "(columns), front and side; OUT_generator.png: the same without the stylizer")
    parser.add_argument("--stylizer-only", action="store_true",
                        help="only the stylizer part (seeds: --seeds, default 0 1 2)")
    parser.add_argument("--json", type=Path, help="also write the result here")
    parser.add_argument("--plot", type=Path, help="PNG: confusion matrix and accuracy vs s (and OUT_parts.png)")
    parser.add_argument("--sheet", type=Path, help="PNG: the speech in neutral, happy, old and angry at the default "
                        "settings, body and face")
    parser.set_defaults(func=run_bench)


def study_config(args: argparse.Namespace) -> StudyConfig:
    config = QUICK if args.quick else StudyConfig()
    if args.guidance:
        config = replace(config, guidance=tuple(args.guidance))
    if args.seconds is not None:
        config = replace(config, seconds=args.seconds)
    if args.seeds:
        config = replace(config, seeds=tuple(args.seeds))
    if args.audio_guidance is not None:
        config = replace(config, audio_guidance=args.audio_guidance)
    if args.prompt_styles:
        config = replace(config, prompt_styles=tuple(args.prompt_styles))
    return config


def study_styles(bundle: ModelBundle, classifier: StyleClassifier, config: StudyConfig) -> tuple[str, ...]:
    styles = tuple(style for style in bundle.styles.labels if style in classifier.labels)
    if not styles:
        raise UserError("the model and the style classifier share no style label")
    return styles[: config.max_styles]


def speech_clip(held_out: list[EvalClip], seconds: float) -> EvalClip:
    """The first held-out clip at least ``seconds`` long (else the longest), cropped to ``seconds``."""
    long_enough = [clip for clip in held_out if clip.seconds >= seconds]
    return (long_enough[0] if long_enough else max(held_out, key=lambda clip: clip.seconds)).crop(seconds)


def classifier_summary(classifier: StyleClassifier) -> dict:
    held_out = classifier.stamp.get("held_out", {})
    return {"version": classifier.version, "labels": list(classifier.labels),
            "held_out_window_accuracy": held_out.get("window_accuracy"),
            "held_out_balanced_accuracy": held_out.get("balanced_accuracy")}


def study_report(model: Path, cache: Path, config: StudyConfig, prompt_dir: Path, sheet: Path | None = None) -> dict:
    started = time.perf_counter()
    bundle = load_bundle(model)
    networks = EvalNetworks(FGDEncoder.load(), StyleClassifier.load(), reference_positions(cache))
    held_out = [clip.crop(config.seconds) for clip in held_out_clips(cache)]
    sampler = SamplerConfig("ddim", config.steps or bundle.default_steps)
    runs = StudyRuns(bundle, speech_clip(held_out, config.seconds), sampler, config.audio_guidance)
    styles, seeds = study_styles(bundle, networks.classifier, config), config.seeds
    guidance = {f"{s:g}": guidance_entry(runs, networks, styles, held_out, s, seeds) for s in config.guidance}
    prompts = tuple(write_prompt_clip(cache, style, prompt_dir) for style in config.prompt_styles)
    motion_prompts = {f"{s:g}": prompt_comparison(runs, networks.classifier, prompts, s, seeds)
                      for s in config.guidance}
    return {
        "model": str(model),
        "config": {**asdict(config), "pairs": [pair.name for pair in config.pairs]},
        "speech": {"clip": runs.clip.name, "seconds": runs.clip.seconds, "sampler": f"ddim K={runs.sampler.steps}",
                   "seeds": list(seeds)},
        "styles": list(styles),
        "classifier": classifier_summary(networks.classifier),
        "guidance": guidance,
        "motion_prompts": {"clips": [{**asdict(p), "path": p.path.name} for p in prompts],
                           "by_guidance": motion_prompts},
        "part_styles": part_study(runs, networks, config.pairs, bundle.default_guidance, seeds[0],
                                  config.timing_repeats),
        "sheet": None if sheet is None else str(style_sheet(runs, SHEET_STYLES, seeds[0], sheet)),
        "generations": len(runs.results),
        "seconds": round(time.perf_counter() - started, 1),
    }


def run_bench(args: argparse.Namespace) -> int:
    config = study_config(args)
    seconds = args.stylizer_seconds or (QUICK_STYLIZER_S if args.quick else STYLIZER_S)
    seeds = tuple(args.seeds or STYLIZER_SEEDS)
    stylizer = stylizer_report(load_bundle(args.model), args.data, seconds, seeds, args.grid, voices=not args.quick)
    if args.stylizer_only:
        return _print_report({"model": str(args.model), "stylizer": stylizer}, args)
    if args.prompt_dir is not None:
        args.prompt_dir.mkdir(parents=True, exist_ok=True)
        report = study_report(args.model, args.cache, config, args.prompt_dir, args.sheet)
    else:
        with tempfile.TemporaryDirectory(prefix="gesturecast-style-prompts-") as folder:
            report = study_report(args.model, args.cache, config, Path(folder), args.sheet)
    report["stylizer"] = stylizer
    if args.plot is not None:
        from gesturecast.tools.render.plot_styles import plot_style_study

        report["plots"] = [str(path) for path in plot_style_study(report, args.plot)]
    return _print_report(report, args)


def _print_report(report: dict, args: argparse.Namespace) -> int:
    text = json.dumps(report, indent=1)
    if args.json is not None:
        write_text_atomic(args.json, text + "\n")
    print(text)
    return 0
