"""How ``bench gestures`` gives a story's words to the session (``--words``), and the voices held out for it.

- ``timed``: every word with the synthesiser's own times (the reference);
- ``text``: the story as a plain-text script placed on its audio, as ``generate --transcript script.txt`` does
  (:meth:`gesturecast.realtime.gestures.director.GestureDirector.hear_script`: only the sentences that cue something
  are aligned); the aligner's word start error is measured apart, on every sentence;
- ``unpunctuated``: the timed words with their punctuation removed, as many recognisers give them, each ending
  where its voiced audio ends (a recogniser's word end: the pauses between words show).

:data:`HELD_OUT_VOICES` were chosen before the aligner or the speech acts were tuned on words without times: that
tuning used espeak-ng's default voice only, so these voices (``--voice``) measure it on speech it never saw. Then
``en-gb-x-rp+f2``'s unpunctuated narration showed comma pauses shorter than the clause pause of the time (0.14 s),
and it was lowered to 0.10 s (:mod:`gesturecast.realtime.words.punctuation`); :data:`LATER_HELD_OUT_VOICES` were
written down then, before anything was measured on them.
"""

from __future__ import annotations

import re
from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from gesturecast.controls import Word
from gesturecast.realtime.gestures.director import GestureDirector, in_order
from gesturecast.realtime.gestures.transcripts import Transcript
from gesturecast.realtime.words.aligner import SentenceAligner
from gesturecast.realtime.words.script import script_sentences
from gesturecast.realtime.words.voicing import SAMPLE_RATE, voiced_span
from gesturecast.tools.bench.gesture_set.stories import Story

WORD_MODES = ("timed", "text", "unpunctuated")
HELD_OUT_VOICES = ("en-us+f3", "en-gb-scotland+m3", "en-gb-x-rp+f2")  # never used while tuning (module docstring)
LATER_HELD_OUT_VOICES = ("en-029+f3", "en-gb-x-gbcwmd+m2")  # written when the clause pause was lowered (below)
PUNCTUATION = re.compile(r"[^\w'’-]|(?<!\w)['’-]|['’-](?!\w)")  # all but letters, digits and inner ' or -


@dataclass
class WordsGiven:
    """What the stories' words cost and how far the aligner moved them: the sessions' alignment CPU seconds and
    sentence outcomes, and the start errors (s) of every sentence aligned apart."""

    cpu_s: float = 0.0
    counts: Counter = field(default_factory=Counter)
    start_errors: list[float] = field(default_factory=list)
    aligner: SentenceAligner = field(default_factory=SentenceAligner)  # the measurement's own, not a session's

    def add_session(self, gestures: GestureDirector) -> None:
        """What placing one story's words cost its session."""
        self.cpu_s += gestures.aligner.cpu_s
        self.counts.update(gestures.alignments.to_dict())

    def add_errors(self, story: Story) -> None:
        """The start error of every word of ``story``, its script's sentences all aligned on its audio."""
        text = " ".join(word.text for word in story.words)
        placed = [word for sentence in script_sentences(text, story.audio)
                  for word in self.aligner.align(sentence).words]
        self.start_errors += [abs(word.start - own.start) for word, own in zip(placed, story.words, strict=True)]


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


def story_transcript(story: Story, mode: str) -> Transcript:
    """The words of ``story`` as ``mode`` gives them (module docstring)."""
    if mode == "timed":
        return Transcript(tuple(story.words))
    if mode == "unpunctuated":
        ends = voiced_ends(story)
        return Transcript(tuple(Word(unpunctuated(w.text), w.start, end)
                                for w, end in zip(story.words, ends, strict=True)))
    return Transcript(script=" ".join(word.text for word in story.words), samples=story.audio)


def decision_words(transcript: Transcript) -> tuple[Word, ...]:
    """The words a transcript's speech acts are decided on: its words, or a script's in their order."""
    return transcript.words or in_order(transcript.script.split())


def words_summary(given: WordsGiven, generate_cpu_s: float) -> dict:
    """The aligner's measures for the JSON: outcomes, word start error p50/p95 (ms), CPU against generation's."""
    errors = np.array(given.start_errors) * 1e3
    return {"alignment": dict(given.counts),
            "start_error_ms": {"p50": round(float(np.percentile(errors, 50)), 1),
                               "p95": round(float(np.percentile(errors, 95)), 1)} if errors.size else None,
            "alignment_cpu_s": round(given.cpu_s, 3), "generate_cpu_s": round(generate_cpu_s, 3),
            "alignment_cpu_fraction": round(given.cpu_s / generate_cpu_s, 4) if generate_cpu_s else None}
