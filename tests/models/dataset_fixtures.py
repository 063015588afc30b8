"""Small real dataset folders for dataset tests, cut from the shared ZeroEGGS take."""

from __future__ import annotations

import csv
from pathlib import Path

import soundfile

TAKE = "067_Speech_2_x_1_0"
FPS = 30
FIRST_FRAME = 90  # the take is silent for its first 2 s
INFO_COLUMNS = ("audio_filename", "anim_bvh", "style", "validation")


def cut_bvh(source: Path, target: Path, num_frames: int, first_frame: int = 0) -> None:
    """Copy a BVH keeping only frames [first_frame, first_frame + num_frames)."""
    lines = source.read_text().splitlines()
    motion_at = lines.index("MOTION")
    header = lines[: motion_at + 1] + [f"Frames: {num_frames}", lines[motion_at + 2]]
    frames = lines[motion_at + 3 + first_frame : motion_at + 3 + first_frame + num_frames]
    target.write_text("\n".join(header + frames) + "\n")


def cut_wav(source: Path, target: Path, num_frames: int, first_frame: int = 0) -> None:
    audio, rate = soundfile.read(source, dtype="float32")
    start = int(round(first_frame * rate / FPS))
    soundfile.write(target, audio[start : start + int(round(num_frames * rate / FPS))], rate)


def make_zeggs_folder(folder: Path, shared_zeggs: Path, takes: dict[str, str], num_frames: int = 60) -> Path:
    """A ZeroEGGS-layout folder: ``takes`` maps a take stem to its style; each gets a BVH + WAV.

    Files carry the release's ``_x_1_0`` suffix; info.csv also lists a mirror row and a row
    without files, both of which must be skipped.
    """
    folder.mkdir(parents=True, exist_ok=True)
    rows = []
    for offset, (stem, style) in enumerate(takes.items()):
        cut_bvh(shared_zeggs / f"{TAKE}.bvh", folder / f"{stem}_x_1_0.bvh", num_frames, FIRST_FRAME + 100 * offset)
        cut_wav(shared_zeggs / f"{TAKE}.wav", folder / f"{stem}_x_1_0.wav", num_frames, FIRST_FRAME + 100 * offset)
        rows.append((f"{stem}.wav", f"{stem}.bvh", style, "FALSE"))
        rows.append((f"{stem}.wav", f"{stem}_mirror.bvh", style, "FALSE"))
    rows.append(("099_Sad_9.wav", "099_Sad_9.bvh", "Sad", "FALSE"))
    with (folder / "info.csv").open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(INFO_COLUMNS)
        writer.writerows(rows)
    return folder
