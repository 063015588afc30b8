"""The condition a benchmark generates in: the style asked for and the label the generator hears under the
stylizer, by default the product's own (``Settings()``), so that every headline measures what a user runs.

Another condition (``--style speech``, ``--generator-style neutral``) is an extra row, reported as such.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass

from gesturecast.settings import Settings

_DEFAULTS = Settings()


@dataclass(frozen=True)
class Condition:
    style: str = _DEFAULTS.style  # the style asked for (a label, text:… or motion:…)
    generator_style: str = _DEFAULTS.generator_style  # what the generator hears under the stylizer's styles

    @property
    def is_default(self) -> bool:
        return self == DEFAULT_CONDITION

    def describe(self) -> dict:
        """The condition as a report states it."""
        return {"style": self.style, "generator_style": self.generator_style, "default_settings": self.is_default}

    @staticmethod
    def from_args(args: argparse.Namespace) -> Condition:
        return Condition(args.style, Settings(generator_style=args.generator_style).generator_style)


DEFAULT_CONDITION = Condition()


def add_condition_arguments(parser: argparse.ArgumentParser) -> None:
    """``--style`` and ``--generator-style``, defaulting to the product's settings."""
    parser.add_argument("--style", default=_DEFAULTS.style,
                        help="style asked for (default: the product's, %(default)s); other styles are extra rows")
    parser.add_argument("--generator-style", default=_DEFAULTS.generator_style, metavar="LABEL",
                        help="the label the generator hears under the stylizer's styles (default: the product's, "
                             "%(default)s)")
