"""Transcripts: the words of a whole recording with their times, from a file (JSON word list, SRT, WebVTT, or a
plain-text script placed on its audio) or a list.

A word list is what word-timestamp speech recognisers and TTS services give: ``[{"word": "Hello", "start": 0.42,
"end": 0.71}, ...]`` in seconds (also as ``{"words": [...]}``). SRT and WebVTT cues carry a span per line of text;
their words are spread evenly over it. Either way the items are checked by :func:`gesturecast.controls.parse_words`,
the one check of every word whichever door it comes through (at most
:data:`~gesturecast.controls.MAX_TRANSCRIPT_WORDS` of them), and refused by the same one-line ``ControlError``.
"""

from __future__ import annotations

import json
import logging
import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from gesturecast.controls import MAX_TRANSCRIPT_WORDS, Word, parse_words
from gesturecast.errors import UserError
from gesturecast.input_files import read_bounded
from gesturecast.settings import Settings

if TYPE_CHECKING:
    from gesturecast.realtime.gestures.cues import CueOutcome
    from gesturecast.realtime.gestures.director import GestureDirector

logger = logging.getLogger(__name__)
MAX_TRANSCRIPT_BYTES = 16 << 20  # a day of speech is a few MB of word JSON
SUBTITLE_SUFFIXES = (".srt", ".vtt")
SCRIPT_SUFFIX = ".txt"  # plain text without times: placed on its audio
TIMESTAMP = re.compile(r"(?:(\d{1,5}):)?(\d{1,2}):(\d{2})[.,](\d{1,3})")
SPAN = re.compile(rf"{TIMESTAMP.pattern}\s*-->\s*{TIMESTAMP.pattern}")


@dataclass(frozen=True, eq=False)
class Transcript:
    """A recording's words: timed ``words`` (a word list, subtitles), or a plain-text ``script`` with the recording's
    ``samples`` ((n,) float32, 16 kHz) it is placed on. Empty (false) without either."""

    words: tuple[Word, ...] = ()
    script: str = ""
    samples: np.ndarray | None = None

    def __bool__(self) -> bool:
        return bool(self.words or self.script)

    def cue(self, gestures: GestureDirector) -> list[CueOutcome]:
        """Cue the gestures the words decide (a script's sentences placed on its recording first)."""
        if not self.script:
            return gestures.hear_transcript(self.words)
        outcomes = gestures.hear_script(self.script, self.samples)
        logger.info("the script placed on its audio: sentences %s; %.2f CPU-s aligning", gestures.alignments.describe(),
                    gestures.aligner.cpu_s)
        return outcomes


def transcript_file(path: Path | None, settings: Settings, audio: Path | str | None = None) -> Transcript:
    """The transcript in a file (empty without one); refused when gestures are off (nothing to cue). A plain-text
    script (``.txt``) is placed on ``audio``, the recording it was read in."""
    if path is None:
        return Transcript()
    if settings.gestures is None:
        raise UserError(f"the transcript {path} cues gestures, and --gestures is off")
    if path.suffix.lower() == SCRIPT_SUFFIX:
        if audio is None:
            raise UserError(f"the script {path} has no times: it is placed on an audio file (--input / the audio)")
        from gesturecast.models.audio.files import load_audio

        return script_transcript(path, load_audio(audio))
    return Transcript(read_transcript(path))


def transcript_beside(audio: Path | str | None) -> Path | None:
    """The plain-text script beside an audio file (``talk.wav`` → ``talk.txt``), when there is one."""
    script = None if audio is None else Path(audio).with_suffix(SCRIPT_SUFFIX)
    if script is None or not script.is_file():
        return None
    logger.info("gesture cues from the script beside the audio: %s", script)
    return script


def script_transcript(path: Path, samples: np.ndarray) -> Transcript:
    """The plain-text script ``path`` (a regular file of at most MAX_TRANSCRIPT_BYTES) of the recording ``samples``
    ((n,) float32, 16 kHz)."""
    text = _text(read_bounded(path, MAX_TRANSCRIPT_BYTES, "the script", regular_only=True), path)
    if not text.split():
        raise UserError(f"{path}: the script has no words")
    words_from_list([{"word": token, "start": 0.0} for token in text.split()], str(path))  # every door's limits
    return Transcript(script=text, samples=samples)


def _text(data: bytes, path: Path) -> str:
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        raise UserError(f"{path}: cannot read the transcript (not UTF-8 at byte {error.start})") from None


def words_from_list(items: object, source: str) -> tuple[Word, ...]:
    """``[{"word", "start", "end"}, ...]`` (or ``{"words": [...]}``) → words; one-line ControlError naming ``source``
    and the item for anything else."""
    return parse_words(items.get("words") if isinstance(items, Mapping) else items, source, MAX_TRANSCRIPT_WORDS)


def read_transcript(path: Path) -> tuple[Word, ...]:
    """The words of a ``.json`` word list or an ``.srt`` / ``.vtt`` subtitle file (a regular file of at most
    MAX_TRANSCRIPT_BYTES)."""
    text = _text(read_bounded(path, MAX_TRANSCRIPT_BYTES, "the transcript", regular_only=True), path)
    if path.suffix.lower() in SUBTITLE_SUFFIXES:
        return words_from_list(subtitle_items(text, str(path)), str(path))
    try:
        items = json.loads(text)
    except json.JSONDecodeError as error:
        raise UserError(f"{path}: not a JSON word list ({error.msg} at line {error.lineno}); subtitles need a "
                        f"{' or '.join(SUBTITLE_SUFFIXES)} suffix") from None
    except (ValueError, RecursionError) as error:  # an integer of thousands of digits, nesting thousands deep
        raise UserError(f"{path}: not a JSON word list ({type(error).__name__}: {str(error)[:80]})") from None
    return words_from_list(items, str(path))


def _seconds(hours: str | None, minutes: str, seconds: str, fraction: str) -> float:
    return int(hours or 0) * 3600 + int(minutes) * 60 + int(seconds) + int(fraction.ljust(3, "0")) / 1000


def _span(line: str, where: str) -> tuple[float, float]:
    """(start, end) seconds of a cue's ``00:00:01,000 --> 00:00:02,500`` line; UserError for minutes or seconds
    beyond 59."""
    times = SPAN.search(line).groups()
    if any(int(field) > 59 for field in (*times[1:3], *times[5:7])):
        raise UserError(f"{where}: {line.strip()!r} has minutes or seconds beyond 59")
    return _seconds(*times[:4]), _seconds(*times[4:])


def subtitle_items(text: str, source: str = "subtitles") -> list[dict]:
    """SRT / WebVTT cues → word items (``{"word", "start", "end"}``) spread evenly over each cue's span."""
    items: list[dict] = []
    for number, block in enumerate(re.split(r"\n\s*\n", text.replace("\r\n", "\n")), 1):
        lines = block.strip().split("\n")
        span_line = next((i for i, line in enumerate(lines) if SPAN.search(line)), None)
        if span_line is None:
            continue
        start, end = _span(lines[span_line], f"{source} block {number}")
        tokens = " ".join(lines[span_line + 1 :]).split()
        step = (end - start) / max(len(tokens), 1)
        items += [{"word": token, "start": start + i * step, "end": start + (i + 1) * step}
                  for i, token in enumerate(tokens)]
    return items
