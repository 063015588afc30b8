"""Content-paired styled takes: the Bandai Namco dataset-1 actions, each in ``neutral`` and up to 14 styles.

A take is named ``dataset-1_{content}_{style}_{id}.bvh``; :func:`load_paired_takes` reads every take of a folder
(the unpacked archive), retargets it to the canonical skeleton and groups it by content and canonical style.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from gesturecast.errors import UserError
from gesturecast.models.dataset.cache import read_take
from gesturecast.models.dataset.sources import bandai_takes, unpack_archive
from gesturecast.models.motion.motion import SkeletonMotion

NEUTRAL = "neutral"


@dataclass(frozen=True)
class Take:
    """One take: its action (content), canonical style and canonical motion."""

    name: str
    content: str
    style: str
    motion: SkeletonMotion


def content_of(name: str) -> str:
    """The action of a Bandai take name (``dataset-1_walk-left_happy_001`` → ``walk-left``)."""
    parts = name.split("_")
    if len(parts) < 4:
        raise UserError(f"{name}: not a dataset-N_content_style_id take name")
    return parts[1]


def take_folder(source: Path, unpack_to: Path) -> Path:
    """A folder of takes: ``source`` itself, or the archive ``source`` (``.tar.xz``) unpacked under ``unpack_to``."""
    if source.is_dir():
        return source
    return unpack_archive(source, unpack_to)


def load_paired_takes(folder: Path) -> list[Take]:
    """Every dataset-1 take under ``folder`` whose content also has a ``neutral`` take, in name order."""
    takes = [Take(source.name, content_of(source.name), source.style, read_take(source)[0])
             for source in bandai_takes(folder) if source.dataset == "bandai-1"]
    neutral_contents = {take.content for take in takes if take.style == NEUTRAL}
    paired = [take for take in takes if take.content in neutral_contents]
    if not paired:
        raise UserError(f"{folder}: no dataset-1 content has both a neutral and a styled take")
    return paired
