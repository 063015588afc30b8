"""Words with times → gesture cues: transcripts (JSON word lists, SRT, WebVTT) and the trigger vocabulary.

A word list is what word-timestamp speech recognisers and TTS services give: ``[{"word": "Hello", "start": 0.42,
"end": 0.71}, ...]`` in seconds (also as ``{"words": [...]}``). SRT and WebVTT cues carry a span per line of text;
their words are spread evenly over it. :class:`TriggerVocabulary` turns words into :class:`Cue` s: each trigger
phrase (case-insensitive, punctuation ignored, the longest match first: "come here" is a call, "here" alone points)
cues its gesture with the stroke at the phrase's first word's start.
"""

from __future__ import annotations

import json
import math
import re
from collections import deque
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path

from gesturecast.errors import UserError
from gesturecast.realtime.generation.gesture_cues import Cue

MAX_TRANSCRIPT_BYTES = 16 << 20  # a day of speech is a few MB of word JSON
MAX_WORDS = 200_000
SUBTITLE_SUFFIXES = (".srt", ".vtt")
TIMESTAMP = re.compile(r"(?:(\d+):)?(\d{1,2}):(\d{2})[.,](\d{1,3})")
SPAN = re.compile(rf"{TIMESTAMP.pattern}\s*-->\s*{TIMESTAMP.pattern}")
NOT_A_LETTER = re.compile(r"[^\w']+")
DEFAULT_TRIGGERS: dict[str, tuple[str, ...]] = {  # gesture -> English trigger phrases
    "wave": ("hello", "hi", "hey", "welcome"),
    "bye": ("bye", "goodbye", "see you"),
    "bow": ("thank you", "thanks"),
    "raise-both": ("hooray", "yay", "congratulations"),
    "guide": ("here", "there", "look at", "this"),
    "call": ("come on", "come here"),
}


@dataclass(frozen=True)
class Word:
    text: str
    start: float  # seconds from the start of the audio
    end: float


def words_from_list(items: object, source: str) -> list[Word]:
    """``[{"word", "start", "end"}, ...]`` (or ``{"words": [...]}``) → words; one-line UserError naming ``source``
    and the item for anything else."""
    if isinstance(items, Mapping):
        items = items.get("words")
    if not isinstance(items, list) or len(items) > MAX_WORDS:
        raise UserError(f"{source}: expected a list of at most {MAX_WORDS} {{\"word\", \"start\", \"end\"}} items")
    return [_word(item, f"{source} item {index}") for index, item in enumerate(items)]


def _word(item: object, where: str) -> Word:
    if not isinstance(item, Mapping) or not isinstance(item.get("word"), str):
        raise UserError(f"{where}: needs a string \"word\"")
    times = [item.get("start"), item.get("end", item.get("start"))]
    if not all(isinstance(t, (int, float)) and not isinstance(t, bool) and math.isfinite(t) and t >= 0 for t in times):
        raise UserError(f"{where}: \"start\" and \"end\" must be seconds ≥ 0")
    if times[1] < times[0]:
        raise UserError(f"{where}: \"end\" {times[1]} is before \"start\" {times[0]}")
    return Word(item["word"], float(times[0]), float(times[1]))


def read_transcript(path: Path) -> list[Word]:
    """The words of a ``.json`` word list or an ``.srt`` / ``.vtt`` subtitle file."""
    try:
        size = path.stat().st_size
        if size > MAX_TRANSCRIPT_BYTES:
            raise UserError(f"{path}: {size} bytes is more than a transcript holds ({MAX_TRANSCRIPT_BYTES} at most)")
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as error:
        raise UserError(f"{path}: cannot read the transcript ({error})") from None
    if path.suffix.lower() in SUBTITLE_SUFFIXES:
        return subtitle_words(text)
    try:
        return words_from_list(json.loads(text), str(path))
    except json.JSONDecodeError as error:
        raise UserError(f"{path}: not a JSON word list ({error.msg} at line {error.lineno}); subtitles need a "
                        f"{' or '.join(SUBTITLE_SUFFIXES)} suffix") from None


def _seconds(hours: str | None, minutes: str, seconds: str, fraction: str) -> float:
    return int(hours or 0) * 3600 + int(minutes) * 60 + int(seconds) + int(fraction.ljust(3, "0")) / 1000


def subtitle_words(text: str) -> list[Word]:
    """SRT / WebVTT cues → words spread evenly over each cue's span."""
    words: list[Word] = []
    for block in re.split(r"\n\s*\n", text.replace("\r\n", "\n")):
        lines = block.strip().split("\n")
        span_line = next((i for i, line in enumerate(lines) if SPAN.search(line)), None)
        if span_line is None:
            continue
        times = SPAN.search(lines[span_line]).groups()
        start, end = _seconds(*times[:4]), _seconds(*times[4:])
        tokens = " ".join(lines[span_line + 1 :]).split()
        step = (end - start) / max(len(tokens), 1)
        words += [Word(token, start + i * step, start + (i + 1) * step) for i, token in enumerate(tokens)]
    return words


def normalise(text: str) -> str:
    return NOT_A_LETTER.sub(" ", text.lower()).strip()


class TriggerVocabulary:
    """Trigger phrases → gestures; ``triggers`` maps a gesture to its phrases (default: :data:`DEFAULT_TRIGGERS`)."""

    def __init__(self, triggers: Mapping[str, Iterable[str]] | None = None) -> None:
        chosen = DEFAULT_TRIGGERS if triggers is None else triggers
        phrases = {normalise(p): gesture for gesture, ps in chosen.items() for p in ps}
        self.phrases = {tuple(phrase.split()): gesture for phrase, gesture in phrases.items() if phrase}
        self.longest = max((len(p) for p in self.phrases), default=0)

    def cues(self, words: list[Word]) -> list[Cue]:
        """One cue per trigger phrase in ``words`` (the longest phrase wins where several start at a word)."""
        return [cue for cue, _ in self.phrases_in(words)]

    def phrases_in(self, words: list[Word]) -> list[tuple[Cue, int]]:
        """(cue, index just past the phrase's last word) of each trigger phrase in ``words``, in order."""
        tokens = [normalise(word.text) for word in words]
        found, index = [], 0
        while index < len(tokens):
            match = self._match(tokens, index) if tokens[index] else None
            if match is None:
                index += 1
                continue
            length, gesture = match
            phrase = " ".join(w.text for w in words[index : index + length])
            found.append((Cue(gesture, words[index].start, phrase), index + length))
            index += length
        return found

    def _match(self, tokens: list[str], index: int) -> tuple[int, str] | None:
        for length in range(min(self.longest, len(tokens) - index), 0, -1):
            phrase = tuple(" ".join(tokens[index : index + length]).split())
            if phrase in self.phrases:
                return length, self.phrases[phrase]
        return None


class WordListener:
    """Words one at a time, as a TTS service reports them while it speaks → the cues of the trigger phrases that
    end at each new word ("thank" cues nothing; "you" after it cues the bow, stroke on "thank")."""

    def __init__(self, vocabulary: TriggerVocabulary) -> None:
        self.vocabulary = vocabulary
        self.recent: deque[Word] = deque(maxlen=max(vocabulary.longest, 1))

    def hear(self, word: Word) -> list[Cue]:
        self.recent.append(word)
        return [cue for cue, end in self.vocabulary.phrases_in(list(self.recent)) if end == len(self.recent)]
