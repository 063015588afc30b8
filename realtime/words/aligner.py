"""Forced alignment of one sentence to its own speech (pocketsphinx, its shipped US-English acoustic model and
dictionary), with a fallback that never loses the sentence.

:meth:`SentenceAligner.align` gives every whitespace-separated token of the sentence stream times (a sentence the
alignment does not finish is aligned again in two parts, cut at a pause), by one of:

- ``aligned``: every token's start and end come from the alignment;
- ``partly``: the alignment placed some tokens (those in the dictionary, up to where it stopped); the others are
  spread by their letters between their placed neighbours (or over the voiced audio after the last placed one);
- ``spread``: nothing aligned (no token in the dictionary, the search did not reach the sentence's end): every token
  is spread by its letters over the voiced part of the audio;
- ``failed``: the span has no voiced audio: the tokens are spread over the whole span, at least as long as
  :data:`NOMINAL_WORD_S` a word.

``confidence`` is the share of tokens whose times the alignment gave (1.0 aligned, 0.0 spread or failed). The
words keep the sentence's spelling and punctuation (the speech acts read them); only the alignment sees them
normalised (lower case, letters and apostrophes).
"""

from __future__ import annotations

import re
import time
from dataclasses import dataclass

import numpy as np

from gesturecast.controls import Word
from gesturecast.realtime.words.voicing import FRAME_S, SAMPLE_RATE, letters, pauses, spread, voiced_span

PAD_S = 0.2  # silence around the span: the alignment starts and ends in silence
NOMINAL_WORD_S = 0.3  # a word's share of a span without voiced audio
MIN_GAP_SHARE = 0.5  # unplaced words given less than this share of NOMINAL_WORD_S each share the word before's span
MIN_SPLIT_WORDS = 4  # a sentence the alignment did not finish is aligned again in two parts from this length
MAX_CUT_SHIFT_S = 1.0  # the cut between the parts moves at most this far to a pause
CLAUSE_MARKS = frozenset(",;:")
FILLERS = frozenset(["<s>", "</s>", "<sil>", "(NULL)", "[NOISE]"])
METHODS = ("aligned", "partly", "spread", "failed")
ALTERNATE = re.compile(r"\(\d+\)$")  # "the(2)": the dictionary's second pronunciation


@dataclass(frozen=True)
class Alignment:
    """One sentence's words with stream times, how they were placed (:data:`METHODS`) and the share aligned."""

    words: tuple[Word, ...]
    method: str
    confidence: float


@dataclass(frozen=True, eq=False)
class SentenceAudio:
    """A sentence (at least one token) and the audio its speech is in: ``samples`` (n,) float32 at 16 kHz, whose first
    sample is at stream time ``start``."""

    text: str
    samples: np.ndarray
    start: float


def dictionary_form(token: str) -> str:
    """How the dictionary spells ``token``: lower case, letters and inner apostrophes only ("Hello," → "hello")."""
    return re.sub(r"[^a-z']", "", token.lower()).strip("'")


class SentenceAligner:
    """Aligns sentences to 16 kHz mono float32 audio; the decoder is loaded on the first alignment (about 0.1 CPU-s)
    and reused. One aligner serves one thread; ``cpu_s`` is the thread CPU time its alignments took."""

    def __init__(self) -> None:
        self._decoder = None
        self.cpu_s = 0.0

    @property
    def decoder(self):
        if self._decoder is None:
            from pocketsphinx import Decoder  # the C decoder and its model: loaded when first needed

            self._decoder = Decoder(lm=None, loglevel="FATAL", samprate=SAMPLE_RATE, bestpath=False)
        return self._decoder

    def known(self, token: str) -> bool:
        """Whether the dictionary has ``token`` (in its :func:`dictionary_form`)."""
        form = dictionary_form(token)
        return bool(form) and self.decoder.lookup_word(form) is not None

    def align(self, sentence: SentenceAudio) -> Alignment:
        """The sentence's tokens placed on its audio (module docstring)."""
        started = time.thread_time()
        try:
            return self._aligned(sentence.text.split(), sentence.samples, sentence.start)
        finally:
            self.cpu_s += time.thread_time() - started

    def _aligned(self, tokens: list[str], samples: np.ndarray, start: float) -> Alignment:
        span = voiced_span(samples)
        if span is None:
            length = max(len(samples) / SAMPLE_RATE, NOMINAL_WORD_S * len(tokens))
            return Alignment(tuple(spread(tokens, start, start + length)), "failed", 0.0)
        voiced = (start + span[0], start + span[1])
        placed = self._aligned_starts(tokens, samples, start) or self._aligned_in_two(tokens, samples, start, span)
        if not placed:
            return Alignment(tuple(spread(tokens, *voiced)), "spread", 0.0)
        words = _fill(tokens, placed, voiced)
        method = "aligned" if len(placed) == len(tokens) else "partly"
        return Alignment(tuple(words), method, len(placed) / len(tokens))

    def _aligned_in_two(self, tokens: list[str], samples: np.ndarray, start: float, span: tuple[float, float]
                        ) -> dict[int, tuple[float, float]]:
        """A sentence the alignment did not finish, aligned again as two parts (:func:`_split`), the audio cut at
        the pause nearest the first part's share of the voiced span (at that share without a pause); {} for a
        sentence too short to split."""
        if len(tokens) < MIN_SPLIT_WORDS:
            return {}
        cut = _split(tokens)
        share = sum(letters(token) for token in tokens[:cut]) / sum(letters(token) for token in tokens)
        estimate = span[0] + share * (span[1] - span[0])
        at = min(pauses(samples), key=lambda pause: abs(pause - estimate), default=estimate)
        at = at if abs(at - estimate) <= MAX_CUT_SHIFT_S else estimate
        middle = int(at * SAMPLE_RATE)
        first = self._aligned_starts(tokens[:cut], samples[:middle], start)
        second = self._aligned_starts(tokens[cut:], samples[middle:], start + middle / SAMPLE_RATE)
        return {**first, **{cut + index: times for index, times in second.items()}}

    def _aligned_starts(self, tokens: list[str], samples: np.ndarray, start: float) -> dict[int, tuple[float, float]]:
        """{token index: (start, end)} of the dictionary's tokens the alignment placed, in order (it may stop short
        of the sentence's end); {} when it placed none."""
        indices = [i for i, token in enumerate(tokens) if self.known(token)]
        if not indices:
            return {}
        pad = np.zeros(int(PAD_S * SAMPLE_RATE), np.float32)
        pcm = (np.clip(np.concatenate([pad, samples, pad]), -1, 1) * 32767).astype("<i2").tobytes()
        decoder = self.decoder
        try:
            decoder.set_align_text(" ".join(dictionary_form(tokens[i]) for i in indices))
            decoder.start_utt()
            decoder.process_raw(pcm)
            decoder.end_utt()
        except RuntimeError:  # pocketsphinx refused the text or the audio: nothing aligned
            _close_utterance(decoder)  # an utterance left open would refuse the next sentence
            return {}
        segments = [segment for segment in decoder.seg() or () if segment.word not in FILLERS]
        offset = start - PAD_S
        placed = {}
        for index, segment in zip(indices, segments, strict=False):
            if ALTERNATE.sub("", segment.word) != dictionary_form(tokens[index]):
                break
            times = offset + np.array([segment.start_frame, segment.end_frame + 1]) * FRAME_S
            placed[index] = tuple(float(t) for t in np.clip(times, start, start + len(samples) / SAMPLE_RATE))
        return placed


def _close_utterance(decoder) -> None:
    """End the decoder's utterance if one is open (ending none raises; nothing else is wrong then)."""
    try:
        decoder.end_utt()
    except RuntimeError:
        return


def _split(tokens: list[str]) -> int:
    """Where a sentence splits in two: after the clause mark (, ; :) nearest its middle by letters, else at the
    middle."""
    shares = np.cumsum([letters(token) for token in tokens]) / sum(letters(token) for token in tokens)
    marks = [i + 1 for i, token in enumerate(tokens[:-1]) if token[-1] in CLAUSE_MARKS]
    candidates = marks or list(range(1, len(tokens)))
    return min(candidates, key=lambda cut: abs(shares[cut - 1] - 0.5))


def _fill(tokens: list[str], placed: dict[int, tuple[float, float]], voiced: tuple[float, float]) -> list[Word]:
    """Every token with times: the placed ones as aligned, each run of others spread by letters between the end of
    the placed token before it (the voiced start before the first) and the start of the one after (the voiced end
    after the last); when that gap is too
    short for them, the word before took their speech, and shares its span with them."""
    words: list[Word] = []
    index = 0
    while index < len(tokens):
        if index in placed:
            words.append(Word(tokens[index], *placed[index]))
            index += 1
            continue
        run_end = next((i for i in range(index, len(tokens)) if i in placed), len(tokens))
        run = tokens[index:run_end]
        before = words[-1].end if words else min(voiced[0], placed[run_end][0])
        after = placed[run_end][0] if run_end < len(tokens) else max(voiced[1], before + NOMINAL_WORD_S)
        if words and after - before < MIN_GAP_SHARE * NOMINAL_WORD_S * len(run):  # the word before took their speech
            absorbing = words.pop()  # tokens[index - 1], placed
            run, before = [absorbing.text, *run], absorbing.start
        words += spread(run, before, max(after, before))
        index = run_end
    return words
