"""`gesturecast data build`: build the training-set cache from the shared data and user datasets.

Shared data (default ``../shared/data``): the ZeroEGGS take + audio, the BEAT2 take + audio, the two
``zeggs_upper`` world-pose takes (arms only, solved against the ZeroEGGS take's skeleton), the SHOW clips (arms
only; two speakers held out as unseen voices), and Bandai Namco dataset-1 and the dataset-2 gesture subset
(unpacked once into ``.cache/raw``). User folders are added with ``--zeggs``, ``--beat``, ``--smplx``,
``--show``, ``--bandai`` (repeatable); see docs/dataset.md.
"""

from __future__ import annotations

import argparse
import json
import logging
import time
from collections.abc import Callable
from pathlib import Path

from gesturecast.errors import UserError
from gesturecast.models.dataset.cache import build_dataset, summary_table
from gesturecast.models.dataset.sources import (
    TakeSource,
    bandai_takes,
    beat_takes,
    show_takes,
    smplx_takes,
    unpack_archive,
    zeggs_takes,
    zeggs_upper_takes,
)

LOGGER = logging.getLogger(__name__)
DEFAULT_SHARED = Path("../shared/data")
DEFAULT_CACHE = Path(".cache/dataset")
DEFAULT_RAW = Path(".cache/raw")
BANDAI_ARCHIVES = ("dataset-1.tar.xz", "dataset-2-gestures.tar.xz")
USER_LAYOUTS: dict[str, Callable[[Path], list[TakeSource]]] = {
    "zeggs": zeggs_takes,
    "beat": beat_takes,
    "smplx": smplx_takes,
    "show": show_takes,
    "bandai": bandai_takes,
}


def register(subparsers: argparse._SubParsersAction) -> None:
    data = subparsers.add_parser("data", help="training data: build the dataset cache")
    commands = data.add_subparsers(dest="data_command", required=True)
    build = commands.add_parser("build", help="retarget every take, write .cache/dataset (+ index.json)")
    build.add_argument("--shared", type=Path, default=DEFAULT_SHARED, help="shared data folder (default %(default)s)")
    build.add_argument("--no-shared", action="store_true", help="read only the folders given below")
    for layout in USER_LAYOUTS:
        build.add_argument(f"--{layout}", type=Path, action="append", default=[], metavar="DIR",
                           help=f"a {layout} dataset folder (repeatable); see docs/dataset.md")
    build.add_argument("--cache", type=Path, default=DEFAULT_CACHE, help="output folder (default %(default)s)")
    build.add_argument("--raw-cache", type=Path, default=DEFAULT_RAW, help="where archives are unpacked")
    build.add_argument("--limit", type=int, default=None, help="at most N takes per dataset (quick builds)")
    build.set_defaults(func=run_build)


def shared_takes(shared: Path, raw_cache: Path) -> list[TakeSource]:
    """The takes of the shared data folder (ZeroEGGS, BEAT2, zeggs_upper, SHOW, both Bandai archives)."""
    if not shared.is_dir():
        raise UserError(f"shared data folder not found: {shared} (pass --shared DIR or --no-shared)")
    zeggs = zeggs_takes(shared / "zeggs")
    takes = zeggs + smplx_takes(shared / "beat2", dataset="beat2")
    takes += zeggs_upper_takes(shared / "zeggs_upper", zeggs[0].motion_path) + show_takes(shared / "show")
    for archive in BANDAI_ARCHIVES:
        takes += bandai_takes(unpack_archive(shared / "bandai" / archive, raw_cache / "bandai"))
    return takes


def limit_per_dataset(takes: list[TakeSource], limit: int | None) -> list[TakeSource]:
    if limit is None:
        return takes
    kept: dict[str, int] = {}
    selected = []
    for take in takes:
        if kept.get(take.dataset, 0) < limit:
            kept[take.dataset] = kept.get(take.dataset, 0) + 1
            selected.append(take)
    return selected


def collect_takes(args: argparse.Namespace) -> list[TakeSource]:
    takes = [] if args.no_shared else shared_takes(args.shared, args.raw_cache)
    for layout, discover in USER_LAYOUTS.items():
        for folder in getattr(args, layout):
            if not folder.is_dir():
                raise UserError(f"--{layout} {folder}: not a folder")
            takes += discover(folder)
    if not takes:
        raise UserError("no takes to build from; drop --no-shared or pass a dataset folder")
    return limit_per_dataset(takes, args.limit)


def run_build(args: argparse.Namespace) -> int:
    started = time.perf_counter()
    takes = collect_takes(args)
    index = build_dataset(takes, args.cache)
    seconds = time.perf_counter() - started
    size = sum(p.stat().st_size for p in args.cache.rglob("*") if p.is_file())
    print(summary_table(index))
    print(json.dumps({"takes": len(index["takes"]), "build_seconds": round(seconds, 1),
                      "cache_megabytes": round(size / 2**20, 1), "cache": str(args.cache)}))
    return 0
