"""One style vocabulary across ZeroEGGS, Bandai Namco dataset-1/-2 and BEAT/BEAT2.

Labels are normalised (lower case, ``_`` and spaces become ``-``, a ``dataset-N_`` prefix as in
Bandai's ``cfg/style_label.txt`` is dropped) and then mapped to a canonical name. Merges, each
with its reason:

- ``neutral`` <- ZeroEGGS "Neutral", Bandai "normal" (both datasets), BEAT/BEAT2 conversation
  takes ("conversation"): the unmarked, everyday way of moving in each dataset.
- ``old`` <- Bandai-1 "old", Bandai-2 "elderly", ZeroEGGS "Old": same acted trait.
- ``tired`` <- "tired" (ZeroEGGS, Bandai-1), Bandai-2 "exhausted": same acted state; Bandai-2
  renamed the styles it re-recorded from dataset-1.
- ``masculine`` <- Bandai-1 "masculinity", Bandai-2 "masculine": noun vs adjective.
- ``childish`` <- Bandai-1 "childish" (its README says "children"), Bandai-2 "youthful". Bandai-2's
  seven styles are dataset-1 styles under new names (active, feminine, normal unchanged;
  old/elderly, tired/exhausted, masculinity/masculine); youthful is the seventh. In plain English
  "youthful" is milder than "childish" — a judgement call, kept because the recordings were
  designed as the same style.

Not merged (different acting): ZeroEGGS "Speech" (oration) is not neutral; "threatening" is not
Bandai's "chimpira" (a street-punk swagger); "still" and "relaxed" are not neutral; "giant",
"musical", "proud", "not-confident" have no counterpart.
"""

from __future__ import annotations

import re

from gesturecast.errors import UserError

# canonical name -> every accepted spelling (after normalisation), the canonical name included
STYLE_SYNONYMS: dict[str, tuple[str, ...]] = {
    "neutral": ("neutral", "normal", "conversation"),
    "old": ("old", "elderly"),
    "tired": ("tired", "exhausted"),
    "masculine": ("masculine", "masculinity"),
    "childish": ("childish", "children", "youthful"),
    "feminine": ("feminine",),
    "active": ("active",),
    "happy": ("happy",),
    "sad": ("sad",),
    "angry": ("angry",),
    "proud": ("proud",),
    "not-confident": ("not-confident",),
    "musical": ("musical",),
    "giant": ("giant",),
    "chimpira": ("chimpira",),
    "laughing": ("laughing",),
    "agreement": ("agreement",),
    "disagreement": ("disagreement",),
    "distracted": ("distracted",),
    "speech": ("speech",),
    "still": ("still",),
    "scared": ("scared",),
    "flirty": ("flirty",),
    "sneaky": ("sneaky",),
    "threatening": ("threatening",),
    "relaxed": ("relaxed",),
    "pensive": ("pensive",),
    "sarcastic": ("sarcastic",),
}

STYLES: tuple[str, ...] = tuple(sorted(STYLE_SYNONYMS))
_LOOKUP: dict[str, str] = {spelling: name for name, spellings in STYLE_SYNONYMS.items() for spelling in spellings}
_DATASET_PREFIX = re.compile(r"^dataset-\d+_")


def normalise_label(label: str) -> str:
    """Lower case, ``_``/spaces to ``-``, no Bandai ``dataset-N_`` prefix."""
    text = _DATASET_PREFIX.sub("", label.strip().lower())
    return re.sub(r"[\s_]+", "-", text)


def canonical_style(label: str) -> str:
    """The canonical style name for any dataset's label; unknown labels raise :class:`UserError`."""
    name = _LOOKUP.get(normalise_label(label))
    if name is None:
        raise UserError(f"unknown style {label!r}; known styles: {', '.join(STYLES)}")
    return name


def style_index(label: str) -> int:
    """Position of the label's canonical style in :data:`STYLES` (the model's label id)."""
    return STYLES.index(canonical_style(label))
