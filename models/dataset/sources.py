"""Finding the takes of each supported dataset layout on disk.

Layouts:

- ZeroEGGS: ``info.csv`` (columns ``anim_bvh``, ``audio_filename``, ``style``) with the BVH and
  WAV files anywhere below the folder. File stems may carry a suffix (``067_Speech_2_x_1_0.bvh``
  for the row ``067_Speech_2.bvh``). The dataset's own ``*_mirror`` takes are skipped: mirroring
  is this project's augmentation, applied to every take alike.
- BEAT: ``*.bvh`` with a ``*.wav`` of the same stem (BEAT's conversation and self-talk takes are
  both labelled "conversation", i.e. neutral; BEAT's per-sentence emotion labels are not read).
- SMPL-X NPZ (BEAT2, AMASS, TalkSHOW): ``*.npz`` with ``poses``; a ``*.wav`` of the same stem
  is its audio when present.
- Bandai Namco dataset-1/-2: ``dataset-N_{content}_{style}_{id}.bvh`` with a ``.json`` label file
  beside it; the style is the label index into ``cfg/style_label.txt`` (else the file name's).
- SHOW (TalkSHOW clips fitted from video): SMPL-X ``*.npz`` + same-stem ``*.wav``, the root in the video
  camera's frame. Only the arms are kept as training targets (:data:`SHOW_PARTS`); the speakers in
  :data:`SHOW_HELD_OUT_SPEAKERS` are test data as a whole (unseen voices).
- ZeroEGGS upper-body world poses (``zeggs_upper``): ``*.npy`` (frames, 9, 7) at 60 fps + same-stem ``*.wav``;
  the style is the name's second field (``001_Neutral_0_x_1_0``). Only the arms are kept
  (:mod:`gesturecast.models.motion.world_poses`, solved against a full-body ZeroEGGS BVH of the same skeleton).
"""

from __future__ import annotations

import csv
import json
import logging
import re
import shutil
import tarfile
import tempfile
from dataclasses import dataclass
from pathlib import Path

from gesturecast.errors import UserError
from gesturecast.models.generator.styles import canonical_style
from gesturecast.models.motion.body_parts import PART_NAMES, holds_every_part

LOGGER = logging.getLogger(__name__)
ZEGGS_INFO = "info.csv"
BEAT_STYLE = "conversation"
_BANDAI_NAME = re.compile(r"^dataset-(\d+)_(?P<content>[^_]+)_(?P<style>[^_]+)_\d+$")
# SHOW (TalkSHOW) clips are split by speaker (the file-name prefix): these voices are never trained on
SHOW_HELD_OUT_SPEAKERS = ("seth", "chemistry")
# The speakers sit behind desks: legs and root are occluded guesses, and the spine's rotation is relative to a
# pelvis tilted back in the chair (mean Spine rotation 30-35 deg on oliver's clips vs 7-15 deg in the standing
# mocap), so the torso would teach a forward lean. The arms hang from the upper chest and are kept.
SHOW_PARTS = ("arms",)
WORLD_POSE_PARTS = ("arms",)  # 9 world joints: no head, neck, legs or fingers, and the clavicles are solved


def show_speaker(stem: str) -> str:
    """The speaker of a SHOW clip: its file-name prefix (``seth_98201-00_04_32-00_04_42`` → ``seth``)."""
    return stem.split("_", 1)[0]


@dataclass(frozen=True)
class TakeSource:
    """One take to read: ``name`` is unique within its ``dataset``; ``style`` is canonical.

    ``parts``: the body parts (:mod:`gesturecast.models.motion.body_parts`) whose motion is reliable; the others
    are masked in every training loss. ``held_out``: the whole take is test data. ``root_in_camera_frame``: the
    motion's root is in an OpenCV camera frame (y down, z away), turned upright when read. ``reference_path``: for
    world-pose takes, the full-body BVH of the same skeleton (:mod:`gesturecast.models.motion.world_poses`)."""

    dataset: str
    name: str
    motion_path: Path
    audio_path: Path | None
    style: str
    parts: tuple[str, ...] = PART_NAMES
    held_out: bool = False
    root_in_camera_frame: bool = False
    reference_path: Path | None = None  # world-pose takes: the full-body BVH their rest frames are solved against

    @property
    def full_body(self) -> bool:
        return holds_every_part(self.parts)


def _files_by_stem(folder: Path, suffix: str) -> dict[str, Path]:
    return {path.stem: path for path in sorted(folder.rglob(f"*{suffix}"))}


def _match_stem(stem: str, files: dict[str, Path]) -> Path | None:
    """The file named ``stem`` or ``stem_<suffix>`` (not a mirror take)."""
    if stem in files:
        return files[stem]
    candidates = [s for s in files if s.startswith(f"{stem}_") and "mirror" not in s]
    return files[min(candidates)] if candidates else None


def zeggs_takes(folder: Path) -> list[TakeSource]:
    """Takes of a ZeroEGGS folder (``info.csv`` + BVH + WAV)."""
    info = folder / ZEGGS_INFO
    if not info.is_file():
        raise UserError(f"{folder} is not a ZeroEGGS folder: no {ZEGGS_INFO} (expected info.csv + *.bvh + *.wav)")
    bvh_files, wav_files = _files_by_stem(folder, ".bvh"), _files_by_stem(folder, ".wav")
    takes = []
    with info.open(newline="") as handle:
        for row in csv.DictReader(handle):
            stem = Path(row["anim_bvh"]).stem
            motion_path = None if "mirror" in stem else _match_stem(stem, bvh_files)
            if motion_path is None:
                continue
            audio_path = wav_files.get(motion_path.stem) or _match_stem(Path(row["audio_filename"]).stem, wav_files)
            takes.append(TakeSource("zeggs", stem, motion_path, audio_path, canonical_style(row["style"])))
    LOGGER.info("ZeroEGGS %s: %d takes with motion", folder, len(takes))
    return takes


def _paired_files(folder: Path, motion_suffix: str, layout: str) -> list[tuple[str, Path, Path]]:
    """(stem, motion file, WAV) of every motion file with a WAV of the same stem; UserError when there is none."""
    motion_files, wav_files = _files_by_stem(folder, motion_suffix), _files_by_stem(folder, ".wav")
    paired = sorted(set(motion_files) & set(wav_files))
    if not paired:
        raise UserError(f"{folder} is not a {layout} folder: no *{motion_suffix} with a *.wav of the same name")
    return [(stem, motion_files[stem], wav_files[stem]) for stem in paired]


def beat_takes(folder: Path) -> list[TakeSource]:
    """Takes of a BEAT folder: BVH + WAV pairs with the same stem."""
    style = canonical_style(BEAT_STYLE)
    return [TakeSource("beat", stem, bvh, wav, style) for stem, bvh, wav in _paired_files(folder, ".bvh", "BEAT")]


def smplx_takes(folder: Path, dataset: str = "smplx") -> list[TakeSource]:
    """SMPL-X NPZ takes (BEAT2/AMASS layout); a same-stem WAV is the take's audio."""
    npz_files, wav_files = _files_by_stem(folder, ".npz"), _files_by_stem(folder, ".wav")
    if not npz_files:
        raise UserError(f"{folder} is not an SMPL-X folder: no *.npz files (expected BEAT2/AMASS-style NPZ)")
    style = canonical_style(BEAT_STYLE)
    return [TakeSource(dataset, stem, path, wav_files.get(stem), style) for stem, path in npz_files.items()]


def show_takes(folder: Path) -> list[TakeSource]:
    """SHOW clips (SMPL-X NPZ + WAV of the same stem): arms only, held-out speakers whole in the test split."""
    style = canonical_style(BEAT_STYLE)
    return [TakeSource("show", stem, npz, wav, style, SHOW_PARTS, show_speaker(stem) in SHOW_HELD_OUT_SPEAKERS,
                       root_in_camera_frame=True) for stem, npz, wav in _paired_files(folder, ".npz", "SHOW")]


def _zeggs_name_style(stem: str) -> str:
    """The style field of a ZeroEGGS file name (``001_Neutral_0_x_1_0`` → neutral); neutral when there is none."""
    fields = stem.split("_")
    return canonical_style(fields[1] if len(fields) > 1 else "neutral")


def zeggs_upper_takes(folder: Path, reference_bvh: Path) -> list[TakeSource]:
    """ZeroEGGS upper-body world-pose takes (``*.npy`` + same-stem ``*.wav``): arms only, solved on a full-body BVH."""
    if not reference_bvh.is_file():
        raise UserError(f"{folder}: world-pose takes need a full-body ZeroEGGS BVH as reference; {reference_bvh} "
                        "is not a file")
    pairs = _paired_files(folder, ".npy", "ZeroEGGS upper-body")
    return [TakeSource("zeggs_upper", stem, npy, wav, _zeggs_name_style(stem), WORLD_POSE_PARTS,
                       reference_path=reference_bvh) for stem, npy, wav in pairs]


def _bandai_style_labels(bvh_path: Path) -> list[str] | None:
    for parent in bvh_path.parents:
        labels = parent / "cfg" / "style_label.txt"
        if labels.is_file():
            return [line.strip() for line in labels.read_text().splitlines() if line.strip()]
    return None


def _bandai_style(bvh_path: Path, file_style: str, labels: list[str] | None) -> str:
    label_file = bvh_path.with_suffix(".json")
    if labels is not None and label_file.is_file():
        return canonical_style(labels[json.loads(label_file.read_text())["style"]])
    return canonical_style(file_style)


def bandai_takes(folder: Path) -> list[TakeSource]:
    """Bandai Namco dataset-1/-2 takes (``dataset-N_{content}_{style}_{id}.bvh`` + ``.json``)."""
    takes = []
    labels_by_folder: dict[Path, list[str] | None] = {}
    for path in sorted(folder.rglob("dataset-*.bvh")):
        match = _BANDAI_NAME.match(path.stem)
        if match is None:
            continue
        if path.parent not in labels_by_folder:
            labels_by_folder[path.parent] = _bandai_style_labels(path)
        style = _bandai_style(path, match["style"], labels_by_folder[path.parent])
        takes.append(TakeSource(f"bandai-{match[1]}", path.stem, path, None, style))
    if not takes:
        raise UserError(f"{folder} is not a Bandai Namco folder: no dataset-N_content_style_id.bvh files")
    return takes


def unpack_archive(archive: Path, raw_cache: Path) -> Path:
    """Unpack a ``.tar.xz`` once into ``raw_cache/<archive name>/`` (atomically) and return that folder."""
    target = raw_cache / archive.name.removesuffix(".tar.xz")
    if target.is_dir():
        return target
    if not archive.is_file():
        raise UserError(f"archive not found: {archive}")
    raw_cache.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(dir=raw_cache, prefix=f".{target.name}-"))
    try:
        LOGGER.info("unpacking %s into %s", archive, target)
        with tarfile.open(archive, "r:xz") as tar:
            tar.extractall(staging, filter="data")
        staging.rename(target)
    except OSError:
        if not target.is_dir():  # else another process unpacked it first
            raise
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return target
