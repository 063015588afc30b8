"""`gesturecast style-fit`: fit the stylizer's styles and the style judge from the Bandai dataset-1 takes.

Reads ``dataset-1.tar.xz`` (or its unpacked folder), unpacked once under ``--raw-cache``; writes the stylizer's
parameters (``styles.json``) and the style judge (``judge.json``) into ``--out`` (default: the folder that ships,
``models/weights/stylizer``) and prints what it measured as JSON: per style and body part the amplitude and tempo
ratios against neutral and the posture's calibration (``calibrate``), the judge's held-out-content accuracy, per
action the closest pair of the judged styles' real takes on the FK measure of ``bench styles``, and the stylizer
judged on actions neither it nor the judge saw (``held_out``). numpy only; well under a minute.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from gesturecast.tools.data_cli import DEFAULT_SHARED

DEFAULT_TAKES = DEFAULT_SHARED / "bandai" / "dataset-1.tar.xz"
DEFAULT_OUT = Path("models/weights/stylizer")
DEFAULT_RAW = Path(".cache/style")
LICENSE_NOTE = ("Fitted from the Bandai Namco Research Motion Dataset (CC BY-NC 4.0): non-commercial use only "
                "(models/weights/LICENSE.md).")


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("style-fit", help="fit the stylizer's styles and the style judge (Bandai takes)")
    parser.add_argument("--takes", type=Path, default=DEFAULT_TAKES,
                        help="Bandai dataset-1 archive or unpacked folder (default %(default)s)")
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT, help="output folder (default %(default)s)")
    parser.add_argument("--raw-cache", type=Path, default=DEFAULT_RAW,
                        help="where the archive is unpacked (default %(default)s)")
    parser.add_argument("--contents", nargs="+", metavar="ACTION",
                        help="fit the styles from these actions only (e.g. bye byebye guide bow; default: every "
                             "action with a neutral take); the judge always uses every action")
    parser.add_argument("--compare-learned", action="store_true",
                        help="also measure the fitted stylizer against a small learned one on held-out actions "
                             "(torch; about 8 minutes on 2 cores)")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from gesturecast.models.style.params import StyleBook
    from gesturecast.tools.style.calibrate import fit_calibrated
    from gesturecast.tools.style.held_out import held_out_actions
    from gesturecast.tools.style.judge_fit import fit_judge
    from gesturecast.tools.style.takes import load_paired_takes, take_folder

    takes = load_paired_takes(take_folder(args.takes, args.raw_cache))
    styles, report = fit_calibrated(takes if not args.contents else [take for take in takes
                                                                  if take.content in args.contents])
    args.out.mkdir(parents=True, exist_ok=True)
    StyleBook(styles, {"license": LICENSE_NOTE, "fitted_from": "Bandai Namco Research Motion Dataset, dataset-1",
                       "takes": len(takes)}).save(args.out / "styles.json")
    judge, judge_report = fit_judge(takes)
    fk = real_style_distances(takes)
    judge.save(args.out / "judge.json", {"license": LICENSE_NOTE, "held_out_content_accuracy": judge_report["mean"]})
    result = {"styles": report, "judge_held_out_content": judge_report, "fk_real_takes": fk,
              "held_out_actions": held_out_actions(takes)}
    if args.compare_learned:
        from gesturecast.tools.style.compare import compare_stylizers

        result["learned_vs_fitted"] = compare_stylizers(takes)
    print(json.dumps(result, indent=1))
    return 0


def real_style_distances(takes: list) -> dict:
    """Per action, the closest pair of the judged styles' takes on the FK measure of ``bench styles`` (the distance
    real styles keep between them)."""
    import itertools

    from gesturecast.models.style.descriptors import clip_descriptor, style_distance
    from gesturecast.models.style.judge import JUDGED_STYLES

    out = {}
    for content in sorted({take.content for take in takes}):
        clips = {take.style: clip_descriptor(take.motion.rotations, take.motion.root_position, take.motion.fps)
                 for take in takes if take.content == content and take.style in JUDGED_STYLES}
        pairs = {f"{a}-{b}": style_distance(clips[a], clips[b]) for a, b in itertools.combinations(sorted(clips), 2)}
        if pairs:
            closest = min(pairs, key=pairs.get)
            out[content] = {"closest_pair": closest, "closest": round(pairs[closest], 3), "styles": len(clips)}
    return out
