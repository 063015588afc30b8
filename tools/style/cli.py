"""`gesturecast style-fit`: fit the stylizer's styles and the style judge from the Bandai dataset-1 takes.

Reads ``dataset-1.tar.xz`` (or its unpacked folder), unpacked once under ``--raw-cache``; writes the stylizer's
parameters (``styles.json``) and the style judge (``judge.json``) into ``--out`` (default: the folder that ships,
``models/weights/stylizer``) and prints what it measured as JSON: per style and body part the amplitude and tempo
ratios against neutral, and the judge's held-out-content accuracy. numpy only; about half a minute.
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
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from gesturecast.models.style.params import StyleBook
    from gesturecast.tools.style.fit import fit_styles
    from gesturecast.tools.style.judge_fit import fit_judge
    from gesturecast.tools.style.takes import load_paired_takes, take_folder

    takes = load_paired_takes(take_folder(args.takes, args.raw_cache))
    styles, report = fit_styles(takes if not args.contents else [take for take in takes
                                                                  if take.content in args.contents])
    args.out.mkdir(parents=True, exist_ok=True)
    StyleBook(styles, {"license": LICENSE_NOTE, "fitted_from": "Bandai Namco Research Motion Dataset, dataset-1",
                       "takes": len(takes)}).save(args.out / "styles.json")
    judge, judge_report = fit_judge(takes)
    judge.save(args.out / "judge.json", {"license": LICENSE_NOTE, "held_out_content_accuracy": judge_report["mean"]})
    print(json.dumps({"styles": report, "judge_held_out_content": judge_report}, indent=1))
    return 0
