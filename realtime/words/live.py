"""Sentences without word times placed as a live stream's audio arrives.

The stream's last :data:`HISTORY_S` seconds of 16 kHz audio are kept, so a sentence whose text comes after its
speech (a recogniser's transcript, a TTS service reporting what it said) is aligned on audio already heard, and one
whose text comes first (a TTS service's sentence before its audio) waits for its audio. Sentences are placed in the
order they were given:

- its speech begins at ``start`` when given; else at the first voiced audio after the end of the sentence placed
  before it (the stream's start for the first);
- it ends at ``end`` when given; else at the first pause (:data:`~.voicing.MIN_PAUSE_S` unvoiced) after half its
  expected length (:data:`LETTER_S` a letter), or at twice its expected length without one;
- it is placed (handed over with its audio, :class:`~gesturecast.realtime.words.aligner.SentenceAudio`) once the
  audio up to its end has arrived, or at the end of the words (:meth:`LiveSentences.ready` with ``final``), on what
  has arrived.
"""

from __future__ import annotations

import threading
from collections import deque
from dataclasses import dataclass

import numpy as np

from gesturecast.realtime.words.aligner import NOMINAL_WORD_S, SentenceAudio
from gesturecast.realtime.words.voicing import FRAME_S, SAMPLE_RATE, letters, pause_runs, voiced_frames

HISTORY_S = 30.0  # the audio kept for sentences given after their speech
LETTER_S = 0.06  # expected speaking time per letter (about 170 words a minute)
ONSET_LEAD_S = 0.1  # a sentence's window starts this long before its first voiced frame
VOICING_CONTEXT_S = 10.0  # the audio whose quiet frames set what counts as voiced
MAX_PENDING_SENTENCES = 64  # sentences waiting for their audio; an older one is placed at once when more come


@dataclass(frozen=True)
class PendingSentence:
    text: str
    start: float | None  # stream seconds its speech begins at (None: after the sentence before it)
    end: float | None  # stream seconds its speech ends by (None: found in the audio)

    @property
    def expected_s(self) -> float:
        return LETTER_S * sum(letters(token) for token in self.text.split())


class AudioHistory:
    """The last ``seconds`` of a stream's 16 kHz audio in a ring (no copy of the whole history per chunk), written by
    the stream's thread and read by the words worker (a lock keeps each read whole)."""

    def __init__(self, seconds: float = HISTORY_S) -> None:
        self.ring = np.zeros(int(seconds * SAMPLE_RATE), np.float32)  # (H,)
        self.samples = 0  # stream samples heard
        self._lock = threading.Lock()

    @property
    def heard_s(self) -> float:
        return self.samples / SAMPLE_RATE

    @property
    def oldest_s(self) -> float:
        return max(0, self.samples - len(self.ring)) / SAMPLE_RATE

    def append(self, samples: np.ndarray) -> None:
        """The stream's next (n,) samples, copied into the ring."""
        kept = samples[-len(self.ring) :]
        with self._lock:
            at = (self.samples + len(samples) - len(kept)) % len(self.ring)
            first = min(len(kept), len(self.ring) - at)
            self.ring[at : at + first] = kept[:first]
            self.ring[: len(kept) - first] = kept[first:]
            self.samples += len(samples)

    def span(self, start: float, end: float) -> tuple[np.ndarray, float]:
        """(the kept samples from ``start`` to ``end`` seconds, the stream time of the first), clipped to what is
        kept."""
        with self._lock:
            first = max(int(start * SAMPLE_RATE), self.samples - len(self.ring), 0)
            last = max(min(int(end * SAMPLE_RATE), self.samples), first)
            indices = np.arange(first, last) % len(self.ring)
            return self.ring[indices], first / SAMPLE_RATE


class LiveSentences:
    """The sentences of one live stream waiting for their audio (module docstring)."""

    def __init__(self) -> None:
        self.audio = AudioHistory()
        self.pending: deque[PendingSentence] = deque()
        self.cursor = 0.0  # stream seconds where the last placed sentence ended

    def hear(self, samples: np.ndarray) -> None:
        """The stream's next audio ((n,) float32, 16 kHz)."""
        self.audio.append(samples)

    def add(self, text: str, start: float | None = None, end: float | None = None) -> list[SentenceAudio]:
        """Queue a sentence (at least one token); returns the sentences placed now (:meth:`ready`, and the oldest when
        too many wait)."""
        self.pending.append(PendingSentence(text, start, end))
        return self.ready(final=False) + ([self._place(self.pending.popleft(), True)]
                                          if len(self.pending) > MAX_PENDING_SENTENCES else [])

    def place_with_audio(self, sentence: SentenceAudio) -> SentenceAudio:
        """A sentence given with its own speech, before that speech reaches :meth:`hear`: placed on it at once; the
        sentences after it look for their speech after its end."""
        self.cursor = max(self.cursor, sentence.start + len(sentence.samples) / SAMPLE_RATE)
        return sentence

    def ready(self, final: bool = False) -> list[SentenceAudio]:
        """The waiting sentences whose audio has arrived, in order, with that audio (all of them when ``final``: the
        speech ended)."""
        placed = []
        while self.pending:
            sentence = self._place(self.pending[0], final)
            if sentence is None:
                break
            self.pending.popleft()
            placed.append(sentence)
        return placed

    def _place(self, sentence: PendingSentence, final: bool) -> SentenceAudio | None:
        bounded = sentence.start is not None and sentence.end is not None
        context = None if bounded else self._context()  # what voicing is judged against, read once
        begin = self._begin(sentence, final, context)
        if begin is None:
            return None
        end = self._end(sentence, begin, final, context)
        if end is None:
            return None
        samples, first_s = self.audio.span(begin, end)
        heard_end = end if len(samples) else first_s + NOMINAL_WORD_S * len(sentence.text.split())  # none: nominal
        self.cursor = max(self.cursor, heard_end)
        return SentenceAudio(sentence.text, samples, first_s)

    def _begin(self, sentence: PendingSentence, final: bool, context: np.ndarray | None) -> float | None:
        """Where the sentence's window starts: its start, else just before the first voiced audio after the cursor
        (None while none has arrived; the cursor itself at the end of the words)."""
        if sentence.start is not None:
            return sentence.start
        after = max(self.cursor, self.audio.oldest_s)
        samples, first_s = self.audio.span(after, self.audio.heard_s)
        voiced = np.flatnonzero(voiced_frames(samples, context))
        if not len(voiced):
            return after if final else None
        return max(after, first_s + voiced[0] * FRAME_S - ONSET_LEAD_S)

    def _context(self) -> np.ndarray:
        """The last :data:`VOICING_CONTEXT_S` of audio: what voicing is judged against (a window that is all speech
        has no quiet frames of its own)."""
        return self.audio.span(self.audio.heard_s - VOICING_CONTEXT_S, self.audio.heard_s)[0]

    def _end(self, sentence: PendingSentence, begin: float, final: bool, context: np.ndarray | None) -> float | None:
        """Where the sentence's window ends (module docstring); None while its audio is still to come."""
        heard = self.audio.heard_s
        if sentence.end is not None:
            return sentence.end if final or heard >= sentence.end else None
        expected = sentence.expected_s
        samples, first_s = self.audio.span(begin, heard)
        breaks = [first_s + middle for middle, _ in pause_runs(samples, context=context)
                  if first_s + middle >= begin + expected / 2]
        if breaks:
            return breaks[0]
        if heard >= begin + 2 * expected:
            return begin + 2 * expected
        return heard if final else None
