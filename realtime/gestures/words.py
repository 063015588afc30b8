"""Words with times → gesture cues: transcripts (JSON word lists, SRT, WebVTT) and the trigger vocabulary.

A word list is what word-timestamp speech recognisers and TTS services give: ``[{"word": "Hello", "start": 0.42,
"end": 0.71}, ...]`` in seconds (also as ``{"words": [...]}``). SRT and WebVTT cues carry a span per line of text;
their words are spread evenly over it. :class:`TriggerVocabulary` turns words into :class:`Cue` s: each trigger
phrase (case-insensitive, punctuation ignored, the longest match first: "come here" is a call, "here" alone points)
cues its gesture with the stroke at the phrase's first word's start.
"""

from __future__ import annotations

import json
import re
from collections import deque
from collections.abc import Iterable, Mapping
from pathlib import Path

from gesturecast.controls import Word  # the words of transcripts and of ``words`` controls are one type
from gesturecast.errors import UserError
from gesturecast.input_files import read_bounded
from gesturecast.realtime.gestures.cues import Cue

MAX_TRANSCRIPT_BYTES = 16 << 20  # a day of speech is a few MB of word JSON
MAX_WORDS = 200_000  # of a transcript (JSON or subtitles) or a word list
MAX_WORD_SECONDS = 1e6  # word times beyond this are not stream times (11 days)
SUBTITLE_SUFFIXES = (".srt", ".vtt")
TIMESTAMP = re.compile(r"(?:(\d{1,5}):)?(\d{1,2}):(\d{2})[.,](\d{1,3})")
SPAN = re.compile(rf"{TIMESTAMP.pattern}\s*-->\s*{TIMESTAMP.pattern}")
NOT_A_LETTER = re.compile(r"[^\w']+")
DEFAULT_TRIGGERS: dict[str, tuple[str, ...]] = {  # gesture -> English trigger phrases
    "wave": ("hello", "hi", "hey", "welcome"),
    "wave-right": ("bye", "goodbye", "see you"),
    "bow": ("thank you", "thanks"),
    "raise-both": ("hooray", "yay", "congratulations"),
    "guide": ("here", "there", "look at", "this"),
    "call": ("come on", "come here"),
}


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
    start, end = (_time(value, where) for value in times)
    if end < start:
        raise UserError(f"{where}: \"end\" {times[1]} is before \"start\" {times[0]}")
    return Word(item["word"], start, end)


def _time(value: object, where: str) -> float:
    """A word time in seconds: a JSON number within [0, MAX_WORD_SECONDS] (no huge integer reaches float())."""
    if isinstance(value, (int, float)) and not isinstance(value, bool) and 0 <= value <= MAX_WORD_SECONDS:
        return float(value)
    raise UserError(f"{where}: \"start\" and \"end\" must be seconds ≥ 0 and at most {MAX_WORD_SECONDS:g}")


def read_transcript(path: Path) -> list[Word]:
    """The words of a ``.json`` word list or an ``.srt`` / ``.vtt`` subtitle file (a regular file of at most
    MAX_TRANSCRIPT_BYTES)."""
    data = read_bounded(path, MAX_TRANSCRIPT_BYTES, "the transcript", regular_only=True)
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        raise UserError(f"{path}: cannot read the transcript (not UTF-8 at byte {error.start})") from None
    if path.suffix.lower() in SUBTITLE_SUFFIXES:
        return subtitle_words(text, str(path))
    try:
        return words_from_list(json.loads(text), str(path))
    except json.JSONDecodeError as error:
        raise UserError(f"{path}: not a JSON word list ({error.msg} at line {error.lineno}); subtitles need a "
                        f"{' or '.join(SUBTITLE_SUFFIXES)} suffix") from None
    except (ValueError, RecursionError) as error:  # an integer of thousands of digits, nesting thousands deep
        raise UserError(f"{path}: not a JSON word list ({type(error).__name__}: {str(error)[:80]})") from None


def _seconds(hours: str | None, minutes: str, seconds: str, fraction: str) -> float:
    return int(hours or 0) * 3600 + int(minutes) * 60 + int(seconds) + int(fraction.ljust(3, "0")) / 1000


def _span(line: str, where: str) -> tuple[float, float]:
    """(start, end) seconds of a cue's ``00:00:01,000 --> 00:00:02,500`` line; UserError for minutes or seconds
    beyond 59 or an end before the start."""
    times = SPAN.search(line).groups()
    if any(int(field) > 59 for field in (*times[1:3], *times[5:7])):
        raise UserError(f"{where}: {line.strip()!r} has minutes or seconds beyond 59")
    start, end = _seconds(*times[:4]), _seconds(*times[4:])
    if end < start:
        raise UserError(f"{where}: {line.strip()!r} ends before it starts")
    if end > MAX_WORD_SECONDS:
        raise UserError(f"{where}: {line.strip()!r} is beyond {MAX_WORD_SECONDS:g} s")
    return start, end


def subtitle_words(text: str, source: str = "subtitles") -> list[Word]:
    """SRT / WebVTT cues → words spread evenly over each cue's span (at most MAX_WORDS)."""
    words: list[Word] = []
    for number, block in enumerate(re.split(r"\n\s*\n", text.replace("\r\n", "\n")), 1):
        lines = block.strip().split("\n")
        span_line = next((i for i, line in enumerate(lines) if SPAN.search(line)), None)
        if span_line is None:
            continue
        start, end = _span(lines[span_line], f"{source} block {number}")
        tokens = " ".join(lines[span_line + 1 :]).split()
        if len(words) + len(tokens) > MAX_WORDS:
            raise UserError(f"{source}: more than {MAX_WORDS} words; split the transcript")
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
