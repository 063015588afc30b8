"""A tiny real training set (cuts of the shared ZeroEGGS take) and a tiny trained model bundle."""

from __future__ import annotations

from pathlib import Path

from dataset_fixtures import FIRST_FRAME, TAKE, cut_bvh, make_zeggs_folder

from gesturecast.models.dataset.cache import build_dataset, read_index
from gesturecast.models.dataset.sources import TakeSource, zeggs_takes
from gesturecast.models.export.bundle import export_bundle
from gesturecast.models.training.pipeline import run_training
from gesturecast.models.training.presets import get_preset

PAIRED_FRAMES = 96  # 3.2 s per paired take: its first 75 % (72 frames) trains
MOTION_ONLY_FRAMES = 72
MOTION_ONLY_OFFSET = 700  # frames into the take, away from the paired cuts
MOTION_ONLY_NAME = "happy_walk_000"  # a name whose hash puts it in the train split


def build_tiny_cache(root: Path, shared_zeggs: Path, extra_takes: tuple[TakeSource, ...] = ()) -> Path:
    """Two paired takes (styles neutral, old) and one motion-only take (happy), plus ``extra_takes``, as a cache."""
    folder = make_zeggs_folder(root / "zeggs", shared_zeggs, {"001_Neutral_0": "Neutral", "002_Old_0": "Old"},
                               PAIRED_FRAMES)
    motion_only = root / f"{MOTION_ONLY_NAME}.bvh"
    cut_bvh(shared_zeggs / f"{TAKE}.bvh", motion_only, MOTION_ONLY_FRAMES, FIRST_FRAME + MOTION_ONLY_OFFSET)
    takes = [*zeggs_takes(folder), TakeSource("bandai-1", MOTION_ONLY_NAME, motion_only, None, "happy"), *extra_takes]
    cache = root / "dataset"
    build_dataset(takes, cache, progress=False)
    motion_only_record = next(t for t in read_index(cache)["takes"] if t["name"] == MOTION_ONLY_NAME)
    assert motion_only_record["segments"][0]["split"] == "train"
    return cache


def train_tiny_bundle(root: Path, shared_zeggs: Path, seed: int = 0, **preset_overrides) -> tuple[dict, Path]:
    """(training checkpoint, bundle directory) of the tiny preset (with ``preset_overrides``) on the tiny cache."""
    cache = build_tiny_cache(root, shared_zeggs)
    checkpoint = run_training(get_preset("tiny", seed=seed, **preset_overrides), cache, root / "work", progress=False)
    return checkpoint, export_bundle(checkpoint, root / "bundle")
