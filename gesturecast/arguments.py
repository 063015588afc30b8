"""Number types for command-line flags: a value outside its range is one line from argparse, never a traceback.

``parser.add_argument("--steps", type=int_at_least(1))`` refuses ``--steps 0`` with
``argument --steps: must be an integer ≥ 1, got '0'``; :func:`finite_float` refuses ``nan``, ``inf``
and values outside its bounds (non-finite numbers would otherwise turn every pose into NaN).
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from dataclasses import dataclass

from gesturecast.errors import USER_ERROR_EXIT_CODE, UserError

MAX_PORT = 65535


def int_at_least(minimum: int, maximum: int | None = None) -> Callable[[str], int]:
    """An argparse type: an integer in ``[minimum, maximum]`` (no upper bound when ``maximum`` is None)."""
    wanted = f"an integer ≥ {minimum}" if maximum is None else f"an integer from {minimum} to {maximum}"

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be {wanted}, got {text!r}") from None
        if value < minimum or (maximum is not None and value > maximum):
            raise argparse.ArgumentTypeError(f"must be {wanted}, got {text!r}")
        return value

    return parse


def finite_float(minimum: float | None = None, maximum: float | None = None,
                 exclusive_minimum: bool = False) -> Callable[[str], float]:
    """An argparse type: a finite float, optionally bounded (``exclusive_minimum``: strictly above ``minimum``)."""
    wanted = _float_range(minimum, maximum, exclusive_minimum)

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be {wanted}, got {text!r}") from None
        below = minimum is not None and (value <= minimum if exclusive_minimum else value < minimum)
        above = maximum is not None and value > maximum
        if not math.isfinite(value) or below or above:
            raise argparse.ArgumentTypeError(f"must be {wanted}, got {text!r}")
        return value

    return parse


def _float_range(minimum: float | None, maximum: float | None, exclusive_minimum: bool) -> str:
    """Words for a finite-float range, e.g. ``a finite number > 0``."""
    parts = []
    if minimum is not None:
        parts.append(f"{'>' if exclusive_minimum else '≥'} {minimum:g}")
    if maximum is not None:
        parts.append(f"≤ {maximum:g}")
    return "a finite number" + (" " + " and ".join(parts) if parts else "")


def port_number(allow_any: bool = False) -> Callable[[str], int]:
    """An argparse type: a TCP/UDP port 1..65535 (0 too with ``allow_any``: the system picks a free one)."""
    return int_at_least(0 if allow_any else 1, MAX_PORT)


class OneLineParser(argparse.ArgumentParser):
    """An ArgumentParser whose errors are one line on stderr (``gesturecast live: error: ...``), exit code 2."""

    def error(self, message: str) -> None:  # type: ignore[override]  # argparse's contract: never returns
        self.exit(USER_ERROR_EXIT_CODE, f"{self.prog}: error: {message} (see `{self.prog} --help`)\n")


@dataclass(frozen=True)
class NumberLimit:
    """The range of a numeric setting, shared by its command-line flag and :class:`gesturecast.Settings`."""

    minimum: float
    maximum: float
    integer: bool = False

    def words(self) -> str:
        """e.g. ``an integer from 1 to 1000`` or ``a finite number ≥ 0 and ≤ 10``."""
        if self.integer:
            return f"an integer from {self.minimum} to {self.maximum}"
        return _float_range(self.minimum, self.maximum, exclusive_minimum=False)

    def flag_type(self) -> Callable[[str], float]:
        """The argparse type of the flag."""
        if self.integer:
            return int_at_least(self.minimum, self.maximum)
        return finite_float(self.minimum, self.maximum)

    def check(self, name: str, value: object) -> float:
        """``value`` as an int or float when inside the range; UserError naming ``name`` otherwise."""
        wrong_type = isinstance(value, bool) or not isinstance(value, (int, float)) or (
            self.integer and not float(value).is_integer())
        if wrong_type or not math.isfinite(value) or not self.minimum <= value <= self.maximum:
            raise UserError(f"{name} must be {self.words()}, got {value!r}")
        return int(value) if self.integer else float(value)
