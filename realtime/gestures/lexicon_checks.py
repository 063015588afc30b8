"""The checks a gesture lexicon's files pass before anything is built from them (:mod:`.lexicon`).

A built lexicon (``lexicon.json`` + ``clips.npz``) and a user's folder (``gestures.json`` + clip files) come from
anywhere, so every field is checked for its type and range (a one-line :class:`UserError` naming the file and the
field), each clip array is read only after its header says it fits (:class:`ClipArchive`: a 6 MB archive can hold
a header asking for 5 GiB), and a user's clip must be a regular file inside the folder, of at most
:data:`MAX_CLIP_FILE_BYTES`.
"""

from __future__ import annotations

import json
import math
import zipfile
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.input_files import MIB, format_size, read_bounded

MAX_CLIPS_VALUES = 64 * MIB  # array values of all a built lexicon's clips together (the shipped one: about 1 M)
MAX_CLIP_FILE_BYTES = 16 * MIB  # a user's clip is seconds of motion: a 10 s BVH of 70 joints at 120 fps is ~5 MB
MAX_FPS = 1000.0
MIN_CLIP_S = 0.25  # a user's clip shorter than this is not a gesture (the model needs a latent's frames at least)


def read_json(path: Path, limit: int, what: str) -> object:
    """The JSON of ``path`` (at most ``limit`` bytes); integers of more digits than a float holds exactly come as
    floats (a 400-digit one as inf, which every numeric field refuses), and nesting too deep for the parser is one
    line."""
    try:
        return json.loads(read_bounded(path, limit, what).decode("utf-8"), parse_int=_json_int)
    except UnicodeDecodeError as error:
        raise UserError(f"{path}: not UTF-8 text ({error.reason})") from None
    except json.JSONDecodeError as error:
        raise UserError(f"{path}: not valid JSON: {error.msg} (line {error.lineno})") from None
    except RecursionError:
        raise UserError(f"{path}: not valid JSON: nested too deep") from None


def _json_int(digits: str) -> int | float:
    return int(digits) if len(digits) <= 15 else float(digits)


def built_fps(value: object, path: Path) -> float:
    """A built lexicon's frame rate: a number in (0, MAX_FPS]."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 < value <= MAX_FPS:
        raise UserError(f"{path}: 'fps' must be a number of frames per second in (0, {MAX_FPS:g}], got {value!r:.40}")
    return float(value)


def check_built_item(item: object, index: int, path: Path) -> None:
    """One entry of a built lexicon's ``gestures`` list: a name, a non-empty list of part strings, a list of trigger
    strings and a non-empty list of variant objects, each naming its clip and style with a whole stroke frame (and
    take number, when it gives one)."""
    where = f"{path}: gestures[{index}]"
    if not isinstance(item, dict) or not isinstance(item.get("name"), str):
        raise UserError(f"{where} must be an object with a string 'name'")
    parts, triggers = item.get("parts"), item.get("triggers")
    if not _strings(parts) or not parts:
        raise UserError(f"{where} ({item['name']}): 'parts' must be a non-empty list of strings")
    if not _strings(triggers):  # empty for a gesture only a control cues
        raise UserError(f"{where} ({item['name']}): 'triggers' must be a list of strings")
    variants = item.get("variants")
    if not isinstance(variants, list) or not variants:
        raise UserError(f"{where} ({item['name']}): 'variants' must be a non-empty list")
    for number, variant in enumerate(variants):
        if (not isinstance(variant, dict) or not isinstance(variant.get("clip"), str)
                or not isinstance(variant.get("style"), str) or not _whole(variant.get("stroke_frame"))
                or not _whole(variant.get("take", 0))):
            raise UserError(f"{where} ({item['name']}): variants[{number}] needs a string 'clip' and 'style', a "
                            "whole 'stroke_frame' ≥ 0 and, if given, a whole 'take' ≥ 0")


def _strings(values: object) -> bool:
    return isinstance(values, list) and all(isinstance(v, str) and v for v in values)


def _whole(value: object) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and value >= 0


class ClipArchive:
    """A built lexicon's ``clips.npz``, each array read only once its header says the archive's arrays together
    stay within :data:`MAX_CLIPS_VALUES` values."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.values_left = MAX_CLIPS_VALUES
        self._archive = zipfile.ZipFile(path)

    def __enter__(self) -> ClipArchive:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self._archive.close()

    def __getitem__(self, key: str) -> np.ndarray:
        """The array ``key`` (KeyError when the archive has none)."""
        with self._archive.open(f"{key}.npy") as member:
            version = np.lib.format.read_magic(member)
            shape, _, dtype = (np.lib.format.read_array_header_1_0 if version == (1, 0)
                               else np.lib.format.read_array_header_2_0)(member)
            values = math.prod(shape)
            if dtype.hasobject or values > self.values_left:
                raise UserError(f"{self.path}: clip {key} claims shape {shape} of {dtype}: more than a gesture "
                                f"lexicon holds ({MAX_CLIPS_VALUES} values in all)")
            self.values_left -= values
        with self._archive.open(f"{key}.npy") as member:
            return np.lib.format.read_array(member, allow_pickle=False)


def inside(folder: Path, name: str) -> Path | None:
    """``folder / name`` resolved when it stays inside ``folder`` (no ``..``, absolute path or symlink out of it)."""
    root = folder.resolve()
    path = (folder / name).resolve()
    return path if root in path.parents else None


def user_clip_path(folder: Path, clip: str, where: str, mapping: Path) -> Path:
    """The path of a user's clip file: a regular file inside ``folder`` of at most MAX_CLIP_FILE_BYTES."""
    path = inside(folder, clip)
    if path is None:
        raise UserError(f"{mapping}: {where}: 'clip' {clip!r} is not inside {folder}")
    if not path.is_file():
        raise UserError(f"{mapping}: {where}: 'clip' file not found: {folder / clip}")
    size = path.stat().st_size
    if size > MAX_CLIP_FILE_BYTES:
        raise UserError(f"{mapping}: {where}: 'clip' {clip} is {format_size(size)}; a gesture clip is at most "
                        f"{format_size(MAX_CLIP_FILE_BYTES)} (seconds of motion)")
    return path
