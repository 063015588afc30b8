"""What ``generate --batch`` has to do: the audio files of a folder or a CSV, each with its outputs and style.

A **folder** gives every audio file under it (any depth, by extension, sorted), with the command's
style flags. A **CSV** gives one file per row; ``path`` (relative to the CSV's folder) is required,
the other columns (:data:`CSV_COLUMNS`) set that file's style options, and ``transcript`` names the file's words
(a JSON word list, ``.srt`` or ``.vtt``, relative to the CSV's folder) whose trigger words cue gestures; an empty
cell keeps the
flag's value (a row with fewer cells leaves the rest empty; one with more cells than the header,
a header naming a column twice, or a ``path`` that names no file such as ``.`` is refused). Outputs
mirror the input's relative path under the output folder with ``.bvh`` (and ``.json`` / ``.vrma``) in
place of the audio suffix. Everything here is checked before any file is generated:
an unknown column, a bad value, two inputs with the same output, or an output that is an input is one
:class:`UserError` line. A missing or broken audio file is not: it fails only its own job (a missing one,
or one that is not a regular file, before any worker sees it: :meth:`BatchJob.missing_reason`).
"""

from __future__ import annotations

import argparse
import csv
import io
import os
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

from gesturecast.errors import UserError
from gesturecast.files import check_distinct
from gesturecast.input_files import read_bounded
from gesturecast.settings import NUMBER_LIMITS, Settings

AUDIO_SUFFIXES = (".wav", ".flac", ".ogg", ".oga", ".opus", ".mp3", ".aiff", ".aif", ".au", ".caf", ".w64")
BVH_SUFFIX = ".bvh"
JSON_SUFFIX = ".json"
VRMA_SUFFIX = ".vrma"
PATH_COLUMN = "path"
TRANSCRIPT_COLUMN = "transcript"
MAX_CSV_BYTES = 64 << 20  # about a million rows; the whole table is read and checked before any work
# CSV column -> (the Settings field it overrides, parser of its text: the flag's own type)
CSV_COLUMNS: dict[str, tuple[str, Callable[[str], object]]] = {
    "style": ("style", str),
    "prompt": ("prompt", str),
    "style2": ("style2", str),
    "part_style": ("part_styles", str.split),  # space-separated PART=STYLE pairs, as --part-style takes them
    "gamma": ("gamma", NUMBER_LIMITS["gamma"].flag_type()),
    "style_strength": ("style_strength", NUMBER_LIMITS["style_strength"].flag_type()),
    "guidance": ("guidance", NUMBER_LIMITS["guidance"].flag_type()),
    "audio_guidance": ("audio_guidance", NUMBER_LIMITS["audio_guidance"].flag_type()),
    "seed": ("seed", NUMBER_LIMITS["seed"].flag_type()),
}


@dataclass(frozen=True)
class BatchJob:
    """One audio file, where its outputs go, and the flag values its CSV row overrides."""

    audio: Path
    bvh: Path
    json: Path | None = None
    overrides: dict = field(default_factory=dict)  # Settings field -> value
    vrma: Path | None = None
    transcript: Path | None = None  # the audio's words (gesture cues); read by the worker: a bad one fails this job

    def motion_paths(self) -> list[Path]:
        """The motion files: the BVH, and the VRM Animation when asked for."""
        return [self.bvh] if self.vrma is None else [self.bvh, self.vrma]

    def outputs(self) -> list[Path]:
        """Every file this job writes: the BVH, then the JSON and the VRM Animation when asked for."""
        return [path for path in (self.bvh, self.json, self.vrma) if path is not None]

    def finished(self) -> bool:
        """Every output exists; they are written atomically, so existing means complete (resumable)."""
        return all(path.is_file() for path in self.outputs())

    def missing_reason(self) -> str | None:
        """Why the audio file cannot be read at all (missing, or a folder or device), as a failure line; None when
        it is a regular file. Checked before dispatching, so a CSV of missing files fails in a stat each."""
        if not self.audio.exists():
            return f"{self.audio}: no such audio file"
        if not self.audio.is_file():
            return f"{self.audio}: not a regular file (a folder or a device), not an audio file"
        return None

    def settings(self, base: Settings) -> Settings:
        """The settings for this file: ``base`` with this row's overrides."""
        return base.replace(**self.overrides)


def find_jobs(source: Path, output_dir: Path, with_json: bool, with_vrma: bool = False) -> list[BatchJob]:
    """The jobs of a folder or a CSV file (see the module docstring), checked for clashing outputs."""
    if source.is_dir():
        extras = (with_json, with_vrma)
        jobs = [_job(path, path.relative_to(source), output_dir, extras, {}) for path in _audio_files(source)]
        if not jobs:
            raise UserError(f"no audio files ({', '.join(AUDIO_SUFFIXES)}) under {source}")
    elif source.is_file():
        jobs = _csv_jobs(source, output_dir, (with_json, with_vrma))
    else:
        raise UserError(f"--batch {source}: no such folder or CSV file")
    _check_outputs(jobs)
    return jobs


def _audio_files(folder: Path) -> list[Path]:
    return sorted(p for p in folder.rglob("*") if p.suffix.lower() in AUDIO_SUFFIXES and p.is_file())


def _job(audio: Path, relative: Path, output_dir: Path, extras: tuple[bool, bool], overrides: dict) -> BatchJob:
    """``extras``: whether the job also writes NAME.json and NAME.vrma beside NAME.bvh."""
    with_json, with_vrma = extras
    bvh = output_dir / relative.with_suffix(BVH_SUFFIX)
    return BatchJob(audio, bvh, bvh.with_suffix(JSON_SUFFIX) if with_json else None, overrides,
                    bvh.with_suffix(VRMA_SUFFIX) if with_vrma else None)


def _csv_jobs(table: Path, output_dir: Path, extras: tuple[bool, bool]) -> list[BatchJob]:
    columns, rows = _read_csv(table)
    if PATH_COLUMN not in columns or not rows:
        raise UserError(f"--batch {table}: needs a header row with a '{PATH_COLUMN}' column and at least one row")
    _check_header(table, columns)
    return [_csv_job(table, line, row, output_dir, extras) for line, row in rows]


def _read_csv(table: Path) -> tuple[list[str], list[tuple[int, dict]]]:
    """The header's column names and each data row with the file line it ends on (blank lines are skipped)."""
    data = read_bounded(table, MAX_CSV_BYTES, "--batch CSV")
    try:
        reader = csv.DictReader(io.StringIO(data.decode("utf-8-sig"), newline=""))
        rows = [(reader.line_num, row) for row in reader]
        return list(reader.fieldnames or []), rows
    except (UnicodeDecodeError, csv.Error) as error:
        raise UserError(f"--batch {table}: cannot read it as a UTF-8 CSV file ({error})") from None


def _check_header(table: Path, columns: list[str]) -> None:
    """Refuse unknown columns and a column named twice (csv.DictReader would keep only its last cell)."""
    twice = sorted({column for column in columns if columns.count(column) > 1})
    if twice:
        raise UserError(f"--batch {table} line 1: column(s) {', '.join(twice)} appear more than once in the header")
    unknown = sorted(set(columns) - {PATH_COLUMN, TRANSCRIPT_COLUMN, *CSV_COLUMNS})
    if unknown:
        raise UserError(f"--batch {table} line 1: unknown column(s) {', '.join(unknown)}; "
                        f"known: {PATH_COLUMN}, {TRANSCRIPT_COLUMN}, {', '.join(CSV_COLUMNS)}")


def _csv_job(table: Path, line: int, row: dict, output_dir: Path, extras: tuple[bool, bool]) -> BatchJob:
    if None in row:  # csv.DictReader puts the cells beyond the header under the key None
        raise UserError(f"--batch {table} line {line}: {len(row) - 1 + len(row[None])} cells, "
                        f"the header has {len(row) - 1} columns")
    written = (row.get(PATH_COLUMN) or "").strip()
    if not written:
        raise UserError(f"--batch {table} line {line}: empty '{PATH_COLUMN}'")
    audio = table.parent / written
    name = _output_name(table.parent, audio)
    if name is None:
        raise UserError(f"--batch {table} line {line}: '{PATH_COLUMN}' {written} names a folder, not an audio file")
    job = _job(audio, name, output_dir, extras, _overrides(table, line, row))
    transcript = (row.get(TRANSCRIPT_COLUMN) or "").strip()
    return replace(job, transcript=table.parent / transcript) if transcript else job


def _output_name(base: Path, audio: Path) -> Path | None:
    """The output's path relative to the output folder: the audio's path relative to the CSV's folder when it
    lies inside it, else the audio's file name; None when the path names no file (``.``, the CSV's folder)."""
    absolute = os.path.abspath(audio)
    relative = Path(os.path.relpath(absolute, os.path.abspath(base)))
    if not relative.parts or not os.path.basename(absolute):
        return None
    return Path(os.path.basename(absolute)) if relative.parts[0] == os.pardir else relative


def _overrides(table: Path, line: int, row: dict) -> dict:
    overrides = {}
    for column, (attribute, parse) in CSV_COLUMNS.items():
        text = (row.get(column) or "").strip()
        if not text:
            continue
        try:
            overrides[attribute] = parse(text)
        except argparse.ArgumentTypeError as error:
            raise UserError(f"--batch {table} line {line}: column {column} {error}") from None
    return overrides


def _check_outputs(jobs: list[BatchJob]) -> None:
    """Two jobs writing the same file, or an output that is an input, is refused before any work."""
    owners: dict[str, Path] = {}
    for job in jobs:
        check_distinct([("audio", job.audio)], [("output", output) for output in job.outputs()])
        for output in job.outputs():
            key = os.path.realpath(output)
            if key in owners:
                raise UserError(f"{owners[key]} and {job.audio} would both write {output}; rename one of them")
            owners[key] = job.audio
    inputs = {os.path.realpath(job.audio): job.audio for job in jobs}
    for key, audio in owners.items():
        if key in inputs:
            raise UserError(f"the output of {audio} would overwrite the input {inputs[key]}")
