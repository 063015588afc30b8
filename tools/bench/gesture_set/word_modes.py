"""How ``bench gestures`` gives a story's words to the session (``--words``), and the voices held out for it.

- ``timed``: every word with the synthesiser's own times (the reference);
- ``text``: the story as a plain-text script, placed on its audio by the sentence aligner
  (:func:`gesturecast.realtime.words.script.place_script`), as ``generate --transcript script.txt`` does;
- ``unpunctuated``: the timed words with their punctuation removed, as many recognisers give them, each ending
  where its voiced audio ends (a recogniser's word end: the pauses between words show).

:data:`HELD_OUT_VOICES` were chosen before the aligner or the speech acts were tuned on words without times: that
tuning used espeak-ng's default voice only, so these voices (``--voice``) measure it on speech it never saw.
"""

from __future__ import annotations

import re
import time
from dataclasses import dataclass, field

import numpy as np

from gesturecast.controls import Word
from gesturecast.realtime.words.aligner import SentenceAligner
from gesturecast.realtime.words.outcomes import AlignmentCounts
from gesturecast.realtime.words.script import place_script
from gesturecast.realtime.words.voicing import SAMPLE_RATE, voiced_span
from gesturecast.tools.bench.gesture_set.stories import Story

WORD_MODES = ("timed", "text", "unpunctuated")
HELD_OUT_VOICES = ("en-us+f3", "en-gb-scotland+m3", "en-gb-x-rp+f2")  # never used while tuning (module docstring)
PUNCTUATION = re.compile(r"[^\w'’-]|(?<!\w)['’-]|['’-](?!\w)")  # all but letters, digits and inner ' or -


@dataclass
class WordsGiven:
    """What a story's words cost and how far they moved: alignment CPU seconds, counts, start errors (s)."""

    cpu_s: float = 0.0
    counts: AlignmentCounts = field(default_factory=AlignmentCounts)
    start_errors: list[float] = field(default_factory=list)


def unpunctuated(token: str) -> str:
    """``token`` without punctuation ("everyone," → "everyone"; "don't" stays); a bare mark stays as it is."""
    return PUNCTUATION.sub("", token) or token


def voiced_ends(story: Story) -> list[float]:
    """Each word's end where its voiced audio ends before the next word starts (a recogniser's word end; the
    synthesiser reports only starts)."""
    ends = []
    for word in story.words:
        first, last = int(word.start * SAMPLE_RATE), int(word.end * SAMPLE_RATE)
        span = voiced_span(story.audio[first:last]) if last > first else None
        ends.append(word.end if span is None else word.start + span[1])
    return ends


def story_words(story: Story, mode: str, aligner: SentenceAligner, given: WordsGiven) -> tuple[Word, ...]:
    """The words of ``story`` as ``mode`` gives them (module docstring); the cost and errors added to ``given``."""
    if mode == "timed":
        return tuple(story.words)
    if mode == "unpunctuated":
        ends = voiced_ends(story)
        return tuple(Word(unpunctuated(w.text), w.start, end) for w, end in zip(story.words, ends, strict=True))
    started = time.process_time()
    words = place_script(" ".join(word.text for word in story.words), story.audio, aligner, given.counts)
    given.cpu_s += time.process_time() - started
    given.start_errors += [abs(placed.start - word.start) for placed, word in zip(words, story.words, strict=True)]
    return words


def words_summary(given: WordsGiven, generate_cpu_s: float) -> dict:
    """The aligner's measures for the JSON: outcomes, word start error p50/p95 (ms), CPU against generation's."""
    errors = np.array(given.start_errors) * 1e3
    return {"alignment": given.counts.to_dict(),
            "start_error_ms": {"p50": round(float(np.percentile(errors, 50)), 1),
                               "p95": round(float(np.percentile(errors, 95)), 1)} if errors.size else None,
            "alignment_cpu_s": round(given.cpu_s, 3), "generate_cpu_s": round(generate_cpu_s, 3),
            "alignment_cpu_fraction": round(given.cpu_s / generate_cpu_s, 4) if generate_cpu_s else None}
