"""Forced alignment of one sentence to its own speech (pocketsphinx, its shipped US-English acoustic model and
dictionary), with a fallback that never loses the sentence.

:meth:`SentenceAligner.align` gives every whitespace-separated token of the sentence stream times (a sentence the
alignment does not finish is aligned again in two parts, cut at a pause), by one of:

- ``aligned``: every token's start and end come from the alignment;
- ``partly``: the alignment placed some tokens (those in the dictionary, up to where it stopped); the others are
  spread by their letters between their placed neighbours (or over the voiced audio after the last placed one). A
  hyphenated token the dictionary lacks ("bye-bye") is aligned as its parts when it has them all;
- ``spread``: nothing aligned (no token in the dictionary, the search did not reach the sentence's end): every token
  is spread by its letters over the voiced part of the audio;
- ``failed``: the span has no voiced audio: the tokens are spread over the whole span, at least as long as
  :data:`NOMINAL_WORD_S` a word;
- ``onset`` (:meth:`SentenceAligner.at_onset`, no alignment asked): the tokens are spread over the voiced audio, so
  the first word starts at the voiced onset, where an alignment starts it too.

``confidence`` is the share of tokens whose times the alignment gave (1.0 aligned, 0.0 spread or failed). The
words keep the sentence's spelling and punctuation (the speech acts read them); only the alignment sees them
normalised (lower case, letters and apostrophes).
"""

from __future__ import annotations

import re
import threading
import time
from collections import Counter
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, replace

import numpy as np

from gesturecast.controls import Word
from gesturecast.realtime.words.voicing import (
    FRAME_S,
    SAMPLE_RATE,
    end_by_letters,
    letters,
    pause_runs,
    pauses,
    spread,
    voiced_frames,
    voiced_span,
)

PAD_S = 0.2  # silence around the span: the alignment starts and ends in silence
NOMINAL_WORD_S = 0.3  # a word's share of a span without voiced audio
MIN_GAP_SHARE = 0.5  # unplaced words given less than this share of NOMINAL_WORD_S each share the word before's span
MIN_SPLIT_WORDS = 4  # a sentence the alignment did not finish is aligned again in two parts from this length
MAX_CUT_SHIFT_S = 1.0  # the cut between the parts moves at most this far to a pause
CLAUSE_MARKS = frozenset(",;:")
FILLERS = frozenset(["<s>", "</s>", "<sil>", "(NULL)", "[NOISE]"])
METHODS = ("aligned", "onset", "partly", "spread", "failed")
FALLBACKS = ("partly", "spread", "failed")  # the outcomes of an alignment that did not place every word
ALTERNATE = re.compile(r"\(\d+\)$")  # "the(2)": the dictionary's second pronunciation
HYPHENS = re.compile(r"[-‐‑–—]")
# The search's beams, wider than pocketsphinx's defaults (1e-48, 7e-29, 1e-48): with those, an accent the US-English
# model knows less well (espeak-ng's Scottish voice) left a quarter of the sentences part-aligned (word start error
# p95 203 ms); with these, 3 of 57 (41 ms), at the same CPU time (docs/results.md).
BEAMS = {"beam": 1e-80, "wbeam": 1e-60, "pbeam": 1e-80}
MAX_ONSET_SHIFT_S = 0.5  # the first word's start moves at most this far back to the voiced onset
PREFIX_MARGIN_S = 0.3  # a prefix's audio runs to the first gap this long after its estimated end
PREFIX_GAP_S = 0.05  # the least unvoiced run a prefix's audio is cut at
LOST_SPEECH_S = 0.3  # an aligned silence over this much voiced audio lost the words spoken there (_trusted)


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

    def prefix(self, count: int) -> SentenceAudio:
        """The sentence's first ``count`` tokens with the audio they are spoken in: up to the first gap
        (:data:`PREFIX_GAP_S` unvoiced) after their share of the voiced audio by letters plus
        :data:`PREFIX_MARGIN_S`; the whole sentence when it has no more tokens or no such gap."""
        tokens = self.text.split()
        span = voiced_span(self.samples)
        if count >= len(tokens) or span is None:
            return self
        estimate = end_by_letters(tokens, count, span) + PREFIX_MARGIN_S
        cut = next((middle for middle, _ in pause_runs(self.samples, PREFIX_GAP_S) if estimate <= middle < span[1]),
                   None)
        if cut is None:
            return self
        return SentenceAudio(" ".join(tokens[:count]), self.samples[: int(cut * SAMPLE_RATE)], self.start)


def dictionary_form(token: str) -> str:
    """How the dictionary spells ``token``: lower case, letters and inner apostrophes only ("Hello," → "hello")."""
    return re.sub(r"[^a-z']", "", token.lower()).strip("'")


class DecoderPool:
    """The process's loaded decoders: one is lent to each alignment and given back after it, so a process loads only
    as many as align at once (a load costs about 0.09 CPU-s; streams come and go)."""

    def __init__(self) -> None:
        self._free: list = []
        self._lock = threading.Lock()

    @contextmanager
    def lend(self) -> Iterator:
        with self._lock:
            decoder = self._free.pop() if self._free else None
        if decoder is None:
            from pocketsphinx import Decoder  # the C decoder and its model: loaded when first needed

            decoder = Decoder(lm=None, loglevel="FATAL", samprate=SAMPLE_RATE, bestpath=False, **BEAMS)
        try:
            yield decoder
        finally:
            with self._lock:
                self._free.append(decoder)


DECODERS = DecoderPool()


class SentenceAligner:
    """Aligns sentences to 16 kHz mono float32 audio on a decoder lent by :data:`DECODERS` for each alignment. One
    aligner serves one thread; ``cpu_s`` is the thread CPU time its alignments took (a decoder's load included)."""

    def __init__(self) -> None:
        self.decoder = None  # the lent decoder, during an alignment
        self.cepstral_mean: str | None = None  # this aligner's voice so far (the decoder's start when None)
        self.cpu_s = 0.0

    def pronounced(self, token: str) -> list[str]:
        """The dictionary words ``token`` is spoken as: its :func:`dictionary_form`, or the forms of its hyphenated
        parts when the dictionary has them all; [] when it has neither."""
        for forms in ([dictionary_form(token)], [dictionary_form(part) for part in HYPHENS.split(token)]):
            if all(forms) and all(self.decoder.lookup_word(form) is not None for form in forms):
                return forms
        return []

    def align(self, sentence: SentenceAudio) -> Alignment:
        """The sentence's tokens placed on its audio (module docstring)."""
        started = time.thread_time()
        try:
            with DECODERS.lend() as self.decoder, self._own_voice():
                return self._aligned(sentence.text.split(), sentence.samples, sentence.start)
        finally:
            self.decoder = None
            self.cpu_s += time.thread_time() - started

    @contextmanager
    def _own_voice(self) -> Iterator[None]:
        """The lent decoder with this aligner's cepstral mean, kept for its next sentence: the decoder adapts to the
        voice sentence by sentence, and a sentence's alignment depends only on this aligner's own earlier sentences,
        whichever decoder is lent."""
        initial = self.decoder.get_cmn(False)
        if self.cepstral_mean is not None:
            self.decoder.set_cmn(self.cepstral_mean)
        try:
            yield
        finally:
            self.cepstral_mean = self.decoder.get_cmn(False)
            self.decoder.set_cmn(initial)

    @staticmethod
    def at_onset(sentence: SentenceAudio) -> Alignment:
        """The sentence's tokens spread by letters over its voiced audio, without aligning them (``onset``; ``failed``
        without voiced audio): enough when only its first word's start is needed."""
        tokens, span = sentence.text.split(), voiced_span(sentence.samples)
        if span is None:
            return _failed(tokens, sentence.samples, sentence.start)
        return Alignment(tuple(spread(tokens, sentence.start + span[0], sentence.start + span[1])), "onset", 0.0)

    def _aligned(self, tokens: list[str], samples: np.ndarray, start: float) -> Alignment:
        span = voiced_span(samples)
        if span is None:
            return _failed(tokens, samples, start)
        voiced = (start + span[0], start + span[1])
        placed = self._aligned_starts(tokens, samples, start) or self._aligned_in_two(tokens, samples, start, span)
        if not placed:
            return Alignment(tuple(spread(tokens, *voiced)), "spread", 0.0)
        words = _from_onset(_fill(tokens, placed, voiced), voiced[0])
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
        estimate = end_by_letters(tokens, cut, span)
        at = min(pauses(samples), key=lambda pause: abs(pause - estimate), default=estimate)
        at = at if abs(at - estimate) <= MAX_CUT_SHIFT_S else estimate
        middle = int(at * SAMPLE_RATE)
        first = self._aligned_starts(tokens[:cut], samples[:middle], start)
        second = self._aligned_starts(tokens[cut:], samples[middle:], start + middle / SAMPLE_RATE)
        return {**first, **{cut + index: times for index, times in second.items()}}

    def _aligned_starts(self, tokens: list[str], samples: np.ndarray, start: float) -> dict[int, tuple[float, float]]:
        """{token index: (start, end)} of the dictionary's tokens the alignment placed, in order (it may stop short
        of the sentence's end); {} when it placed none."""
        spoken = [(i, form) for i, token in enumerate(tokens) for form in self.pronounced(token)]  # (token, word)
        if not spoken:
            return {}
        pad = np.zeros(int(PAD_S * SAMPLE_RATE), np.float32)
        pcm = (np.clip(np.concatenate([pad, samples, pad]), -1, 1) * 32767).astype("<i2").tobytes()
        decoder = self.decoder
        try:
            decoder.set_align_text(" ".join(form for _, form in spoken))
            decoder.start_utt()
            decoder.process_raw(pcm)
            decoder.end_utt()
        except RuntimeError:  # pocketsphinx refused the text or the audio: nothing aligned
            _close_utterance(decoder)  # an utterance left open would refuse the next sentence
            return {}
        segments = [segment for segment in _trusted(list(decoder.seg() or ()), voiced_frames(samples))
                    if segment.word not in FILLERS]
        offset = start - PAD_S
        placed, parts = {}, Counter()  # token index → (start, end), its parts placed
        for (index, form), segment in zip(spoken, segments, strict=False):
            if ALTERNATE.sub("", segment.word) != form:
                break
            times = offset + np.array([segment.start_frame, segment.end_frame + 1]) * FRAME_S
            begin, end = (float(t) for t in np.clip(times, start, start + len(samples) / SAMPLE_RATE))
            placed[index] = (placed.get(index, (begin, end))[0], end)
            parts[index] += 1
        expected = Counter(index for index, _ in spoken)  # a hyphenated token is placed once all its parts are
        return {index: times for index, times in placed.items() if parts[index] == expected[index]}


def _trusted(segments: list, voiced: np.ndarray) -> list:
    """The segments up to the first silence the alignment laid over at least :data:`LOST_SPEECH_S` of ``voiced``
    audio (F,) frames: the words after it were pushed past speech it could not match (an accent the model knows
    less well: "and welcome" put 0.7 s late, after a "silence" over them) and are left to the fallback."""
    pad = round(PAD_S / FRAME_S)
    for index, segment in enumerate(segments):
        if segment.word in FILLERS:
            first, last = max(0, segment.start_frame - pad), max(0, segment.end_frame + 1 - pad)
            if voiced[first:last].sum() * FRAME_S >= LOST_SPEECH_S:
                return segments[:index]
    return segments


def _failed(tokens: list[str], samples: np.ndarray, start: float) -> Alignment:
    """Tokens spread over audio without voiced speech: over all of it, at least :data:`NOMINAL_WORD_S` a word."""
    length = max(len(samples) / SAMPLE_RATE, NOMINAL_WORD_S * len(tokens))
    return Alignment(tuple(spread(tokens, start, start + length)), "failed", 0.0)


def _from_onset(words: list[Word], onset: float) -> list[Word]:
    """The first word starting at the sentence's voiced onset (at most :data:`MAX_ONSET_SHIFT_S` before where it was
    aligned): the alignment starts a sentence late when its first sound is weak (the /h/ of "Hello", the /w/ of
    "Welcome": 0.15-0.35 s late in some voices), and the speech begins with its first word."""
    first = words[0]
    if first.start <= onset:
        return words
    return [replace(first, start=max(onset, first.start - MAX_ONSET_SHIFT_S)), *words[1:]]


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
