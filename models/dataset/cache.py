"""The training-set cache: build it from dataset takes, read it back for training.

Cache layout (default ``.cache/dataset/``), written atomically (a staging folder renamed into
place; an error leaves the previous cache untouched and no partial folder behind):

- ``takes/<dataset>/<name>.npz`` (compressed), one per take: ``rotations`` (T, J, 4) float32
  canonical local XYZW, ``root_position`` (T, 3) float32 metres, faced forward (the first frame
  faces +Z at the planar origin); ``audio`` (N,) float32 16 kHz mono, frame-aligned, N =
  round(T * 16000 / 30), empty when the take has none; ``fps``, ``style``, ``dataset``, ``source``.
- ``index.json``: ``format_version``, fps, sample rate, the style vocabulary and synonyms, the
  split rule, and one record per take (name, dataset, style, source, frames, seconds, audio
  flag, file, segments, ``parts``: the body parts whose motion is reliable, all three for a full-body take).

Split (deterministic, by take): a take with speech audio is cut by time — its first 75 % trains,
the next 10 % validates, the final 15 % is held out for testing, so every paired speaker/style
has unseen test speech. A held-out take (an unseen voice, :class:`TakeSource`) is test data whole.
A motion-only take goes whole to train / val / test by a hash of its name (90 / 5 / 5 %).

Augmentation (mirror, speed 0.9 / 1.1 with the audio) is applied at load time, to the train
split only: the cache stays one copy of the data and the augmentation can change without a rebuild.
"""

from __future__ import annotations

import hashlib
import json
import logging
import shutil
import tempfile
from collections import defaultdict
from collections.abc import Iterable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
from tqdm import tqdm

from gesturecast.errors import UserError
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.models.dataset.augment import AugmentConfig, augmented_variants, fit_audio, slice_audio
from gesturecast.models.dataset.sources import TakeSource
from gesturecast.models.generator.styles import STYLE_SYNONYMS, STYLES
from gesturecast.models.motion.body_parts import PART_NAMES, holds_every_part
from gesturecast.models.motion.motion import MOTION_FPS, SkeletonMotion
from gesturecast.models.motion.motion_features import face_forward, motion_to_features
from gesturecast.models.motion.retarget import load_motion_file, upright_from_camera
from gesturecast.models.motion.world_poses import load_world_pose_motion

LOGGER = logging.getLogger(__name__)
FORMAT_VERSION = 2  # 2: per-take body parts and held-out takes
INDEX_FILE = "index.json"
TAKES_FOLDER = "takes"
SPLITS = ("train", "val", "test")
_HASH_SCALE = float(16**8)
_SECONDS_PER_MINUTE = 60.0


@dataclass(frozen=True)
class SplitConfig:
    """Split rule: time fractions for paired takes, hash fractions for motion-only takes."""

    paired_val_fraction: float = 0.10
    paired_test_fraction: float = 0.15
    motion_val_fraction: float = 0.05
    motion_test_fraction: float = 0.05


@dataclass
class DatasetTake:
    """One training/evaluation clip: a split segment of a cached take, possibly augmented."""

    name: str
    dataset: str
    style: str
    split: str
    variant: str
    start_frame: int
    features: np.ndarray  # (T, FEATURE_DIM) float32
    audio: np.ndarray | None  # (round(T * 16000 / 30),) float32 or None
    fps: float = MOTION_FPS
    parts: tuple[str, ...] = PART_NAMES  # the body parts whose motion is reliable


DEFAULT_SPLIT = SplitConfig()
DEFAULT_AUGMENT = AugmentConfig()


def _hash_fraction(key: str) -> float:
    return int(hashlib.sha1(key.encode()).hexdigest()[:8], 16) / _HASH_SCALE


def take_segments(dataset: str, name: str, num_frames: int, has_audio: bool, split: SplitConfig,
                  held_out: bool = False) -> list[dict]:
    """Split segments ``{"split", "start", "stop"}`` of one take (rule: module docstring)."""
    if held_out:
        return [{"split": "test", "start": 0, "stop": num_frames}]
    if has_audio:
        test_start = int(round(num_frames * (1.0 - split.paired_test_fraction)))
        val_start = int(round(num_frames * (1.0 - split.paired_test_fraction - split.paired_val_fraction)))
        bounds = [("train", 0, val_start), ("val", val_start, test_start), ("test", test_start, num_frames)]
        return [{"split": s, "start": a, "stop": b} for s, a, b in bounds if b > a]
    fraction = _hash_fraction(f"{dataset}/{name}")
    which = "val" if fraction < split.motion_val_fraction else "train"
    if split.motion_val_fraction <= fraction < split.motion_val_fraction + split.motion_test_fraction:
        which = "test"
    return [{"split": which, "start": 0, "stop": num_frames}]


def read_take(source: TakeSource) -> tuple[SkeletonMotion, np.ndarray | None]:
    """Canonical motion faced forward, and its frame-aligned 16 kHz audio (None without audio)."""
    try:
        motion = (load_world_pose_motion(source.motion_path, source.reference_path) if source.reference_path
                  else load_motion_file(source.motion_path))
        motion = face_forward(upright_from_camera(motion) if source.root_in_camera_frame else motion)
    except UserError as error:
        message = str(error)
        raise UserError(message if str(source.motion_path) in message else f"{source.motion_path}: {message}") from None
    if source.audio_path is None:
        return motion, None
    return motion, fit_audio(load_audio(source.audio_path), motion.num_frames, motion.fps, SAMPLE_RATE)


def _write_take(path: Path, motion: SkeletonMotion, audio: np.ndarray | None, source: TakeSource) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(
        path,
        rotations=motion.rotations.astype(np.float32),
        root_position=motion.root_position.astype(np.float32),
        audio=np.zeros(0, np.float32) if audio is None else audio,
        fps=np.float64(motion.fps),
        style=np.str_(source.style),
        dataset=np.str_(source.dataset),
        source=np.str_(str(source.motion_path)),
    )


def _take_record(source: TakeSource, motion: SkeletonMotion, has_audio: bool, split: SplitConfig) -> dict:
    return {
        "name": source.name,
        "dataset": source.dataset,
        "style": source.style,
        "source": str(source.motion_path),
        "audio_source": None if source.audio_path is None else str(source.audio_path),
        "file": f"{TAKES_FOLDER}/{source.dataset}/{source.name}.npz",
        "num_frames": motion.num_frames,
        "seconds": motion.duration,
        "has_audio": has_audio,
        "parts": list(source.parts),
        "segments": take_segments(source.dataset, source.name, motion.num_frames, has_audio, split, source.held_out),
    }


def _replace_folder(staging: Path, target: Path) -> None:
    """Move ``staging`` to ``target``, replacing an existing ``target`` only once the new one is complete."""
    backup = target.with_name(f".{target.name}.old")
    shutil.rmtree(backup, ignore_errors=True)
    if target.exists():
        target.rename(backup)
    staging.rename(target)
    shutil.rmtree(backup, ignore_errors=True)


def build_dataset(
    sources: Sequence[TakeSource], cache_dir: Path, split: SplitConfig = DEFAULT_SPLIT, progress: bool = True
) -> dict:
    """Read every take, write the cache atomically, return the index (also saved as index.json)."""
    names = [(s.dataset, s.name) for s in sources]
    if len(set(names)) != len(names):
        raise UserError("two takes share a dataset and name; pass each dataset folder once")
    cache_dir.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(dir=cache_dir.parent, prefix=f".{cache_dir.name}-building-"))
    try:
        records = []
        for source in tqdm(sources, desc="takes", unit="take", disable=not progress):
            motion, audio = read_take(source)
            record = _take_record(source, motion, audio is not None, split)
            _write_take(staging / record["file"], motion, audio, source)
            records.append(record)
        index = {
            "format_version": FORMAT_VERSION,
            "fps": MOTION_FPS,
            "sample_rate": SAMPLE_RATE,
            "styles": list(STYLES),
            "style_synonyms": {name: list(spellings) for name, spellings in STYLE_SYNONYMS.items()},
            "split": asdict(split),
            "takes": records,
        }
        (staging / INDEX_FILE).write_text(json.dumps(index, indent=1))
        _replace_folder(staging, cache_dir)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return index


def read_index(cache_dir: Path) -> dict:
    """The cache's index.json; a missing or foreign cache raises a one-line UserError."""
    path = cache_dir / INDEX_FILE
    if not path.is_file():
        raise UserError(f"no dataset cache at {cache_dir}; build it with `gesturecast data build`")
    index = json.loads(path.read_text())
    if index.get("format_version") != FORMAT_VERSION:
        raise UserError(f"{path} has format {index.get('format_version')}, expected {FORMAT_VERSION}; rebuild it")
    return index


def is_full_body(record: dict) -> bool:
    """Whether an index record's take holds reliable motion of every body part (evaluation uses only these)."""
    return holds_every_part(record["parts"])


def load_take(cache_dir: Path, record: dict) -> tuple[SkeletonMotion, np.ndarray | None]:
    """The cached motion (float64) and audio (None when the take has none) of one index record."""
    with np.load(cache_dir / record["file"]) as data:
        motion = SkeletonMotion(
            data["rotations"].astype(np.float64), data["root_position"].astype(np.float64), float(data["fps"])
        )
        audio = data["audio"] if record["has_audio"] else None
    return motion, audio


def load_dataset(
    cache_dir: Path, splits: Iterable[str] = SPLITS, augment: AugmentConfig | None = DEFAULT_AUGMENT
) -> list[DatasetTake]:
    """Clips for training/evaluation: one per take segment in ``splits`` (train ones augmented)."""
    wanted = set(splits)
    clips = []
    for record in read_index(cache_dir)["takes"]:
        segments = [s for s in record["segments"] if s["split"] in wanted]
        if not segments:
            continue
        motion, audio = load_take(cache_dir, record)
        for segment in segments:
            clips.extend(_segment_clips(record, segment, motion, audio, augment))
    return clips


def _segment_clips(
    record: dict, segment: dict, motion: SkeletonMotion, audio: np.ndarray | None, augment: AugmentConfig | None
) -> list[DatasetTake]:
    start, stop = segment["start"], segment["stop"]
    part = motion.slice(start, stop)
    part_audio = None if audio is None else slice_audio(audio, start, stop, motion.fps, SAMPLE_RATE)
    config = augment if segment["split"] == "train" and augment is not None else AugmentConfig(False, ())
    return [
        DatasetTake(
            record["name"], record["dataset"], record["style"], segment["split"], tag, start,
            motion_to_features(variant), variant_audio, variant.fps, tuple(record["parts"]),
        )
        for tag, variant, variant_audio in augmented_variants(part, part_audio, config, SAMPLE_RATE)
    ]


def summary_rows(index: dict) -> tuple[dict[str, float], dict[str, float]]:
    """Minutes per dataset and per style."""
    per_dataset: dict[str, float] = defaultdict(float)
    per_style: dict[str, float] = defaultdict(float)
    for record in index["takes"]:
        per_dataset[record["dataset"]] += record["seconds"] / _SECONDS_PER_MINUTE
        per_style[record["style"]] += record["seconds"] / _SECONDS_PER_MINUTE
    return dict(per_dataset), dict(per_style)


def summary_table(index: dict) -> str:
    """A plain-text table: takes and minutes per dataset, then minutes per style."""
    per_dataset, per_style = summary_rows(index)
    counts = defaultdict(int)
    for record in index["takes"]:
        counts[record["dataset"]] += 1
    lines = [f"{'dataset':<12} {'takes':>6} {'minutes':>8}"]
    lines += [f"{name:<12} {counts[name]:>6} {minutes:>8.2f}" for name, minutes in sorted(per_dataset.items())]
    lines.append(f"{'total':<12} {len(index['takes']):>6} {sum(per_dataset.values()):>8.2f}")
    lines += ["", f"{'style':<14} {'minutes':>8}"]
    lines += [f"{name:<14} {minutes:>8.2f}" for name, minutes in sorted(per_style.items(), key=lambda kv: -kv[1])]
    return "\n".join(lines)
