"""The JSON files ``gesturecast style-fit`` writes (the stylizer's styles, the style judge): read bounded and
checked for their format and the names their numbers are laid out by, written atomically."""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

from gesturecast.errors import UserError
from gesturecast.files import write_text_atomic
from gesturecast.input_files import read_bounded

MAX_FITTED_BYTES = 4 << 20  # the shipped files are 16-40 KB


def read_fitted(path: Path, what: str, file_format: str, key: str, names: Sequence[str]) -> dict:
    """The JSON object at ``path``, whose ``format`` is ``file_format`` and whose ``key`` lists ``names`` in order;
    a one-line UserError otherwise."""
    try:
        data = json.loads(read_bounded(path, MAX_FITTED_BYTES, what).decode("utf-8"))
    except (UserError, ValueError) as error:  # JSONDecodeError and UnicodeDecodeError are ValueErrors
        raise UserError(f"{path}: not a readable {what} ({error})") from None
    if not isinstance(data, dict) or data.get("format") != file_format or data.get(key) != list(names):
        raise UserError(f"{path}: not a {file_format} file with {key} {', '.join(names)}")
    return data


def write_fitted(path: Path, data: dict) -> None:
    write_text_atomic(path, json.dumps(data, indent=1) + "\n")
