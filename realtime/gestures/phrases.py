"""Words → the cues of their speech acts (:mod:`gesturecast.realtime.gestures.speech_acts`), for a transcript
given at once (:meth:`PhraseCues.cues`) and for words reported one at a time (:class:`PhraseListener`).

A cue's stroke is at the start of its phrase's first word, its source the phrase as spoken ("Bye-bye"). Only the
gestures the session's lexicon has are cued. The listener holds the words of the sentence being spoken (at most
:data:`MAX_HELD_WORDS`) and decides a phrase once the words after it that the decision reads have arrived or its
sentence has ended; :meth:`PhraseListener.flush` decides what is left when the speech ends. Of earlier sentences
both keep only how many have ended since the last act that opens a talk (a deictic "this is" presents only soon
after one: :func:`gesturecast.realtime.gestures.speech_acts.addressed`).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from functools import cache
from pathlib import Path

from gesturecast.controls import Word
from gesturecast.realtime.gestures.cues import Cue
from gesturecast.realtime.gestures.speech_acts import (
    INTENT_GESTURES,
    SpeechActClassifier,
    SpeechActModel,
    Token,
    candidates,
    decidable,
    default_weights,
    opens_talk,
    tokenize,
)

MAX_HELD_WORDS = 24  # a sentence longer than this is read from its last 24 words


@cache
def shared_classifier(weights: Path | None = None) -> SpeechActClassifier:
    """One classifier per process and weights file (read-only; loading wordllama takes about a second)."""
    return SpeechActClassifier(SpeechActModel.load(weights or default_weights()))


class PhraseCues:
    """The speech acts of words, as cues of the ``gestures`` available (the default classifier when None)."""

    def __init__(self, gestures: Iterable[str], classifier: SpeechActClassifier | None = None) -> None:
        self.gestures = frozenset(gestures)
        self._classifier = classifier

    @property
    def classifier(self) -> SpeechActClassifier:
        """The classifier, loaded when the first words come (a stream that gets none never loads wordllama)."""
        if self._classifier is None:
            self._classifier = shared_classifier()
        return self._classifier

    def warm(self) -> None:
        """Load the classifier now (a live stream's warm-up), not when the first words come."""
        self.classifier.decide([], [], [])

    def gesture_of(self, intent: str) -> str | None:
        """The gesture that performs ``intent`` in this lexicon (None for "none" or when it has none)."""
        return next((g for g in INTENT_GESTURES.get(intent, ()) if g in self.gestures), None)

    def cues(self, words: Sequence[Word], paused: frozenset[int] = frozenset()) -> list[Cue]:
        """One cue per speech act in ``words`` (a whole transcript or a stretch of it); ``paused``: the words whose
        marks were read from their pauses (:func:`gesturecast.realtime.words.punctuation.punctuated_by_pauses`)."""
        tokens = tokenize([w.text for w in words], paused)
        return [cue for cue, _, _ in self.decided(words, tokens, lambda _: True, None) if cue]

    def decided(self, words: Sequence[Word], tokens: list[Token], ready, since: int | None
                ) -> list[tuple[Cue | None, int, bool]]:
        """(cue or None for no gesture, the candidate's first token, whether its act opens a talk) of each candidate
        that ``ready(candidate)`` accepts, in order; ``since``: sentence ends between the last act that opens a talk
        and ``tokens``."""
        found = [c for c in candidates(tokens) if ready(c)]
        if not found:  # no speech act possible: a stream without words never loads wordllama
            return []
        intents = self.classifier.decide(tokens, [w.text for w in words], found, since)
        out = []
        for candidate, intent in zip(found, intents, strict=True):
            gesture = self.gesture_of(intent)
            first = tokens[candidate.start].word
            phrase = " ".join(w.text for w in words[first: tokens[candidate.stop - 1].word + 1])
            cue = Cue(gesture, words[first].start, phrase) if gesture else None
            out.append((cue, candidate.start, opens_talk(tokens, candidate, intent)))
        return out


class PhraseStream:
    """A stream's word messages, each a stretch of its transcript in order (a live ``words`` message) → cues; the
    sentences since the last act that opens a talk carry over from one message to the next, so "Hello, everyone."
    and then "This is our new coffee machine." cue as they would in one transcript."""

    def __init__(self, phrases: PhraseCues) -> None:
        self.phrases = phrases
        self.since: int | None = None  # sentence ends since the last act opening a talk (None: none yet)

    def cues(self, words: Sequence[Word], paused: frozenset[int] = frozenset()) -> list[Cue]:
        """The cues of ``words``, the message after those before (``paused`` as :meth:`PhraseCues.cues`)."""
        tokens = tokenize([w.text for w in words], paused)
        decided = self.phrases.decided(words, tokens, lambda _: True, self.since)
        opened = [start for _, start, opens in decided if opens]
        if opened or self.since is not None:
            start = opened[-1] if opened else 0
            self.since = (0 if opened else self.since) + sum(t.sentence_end for t in tokens[start:])
        return [cue for cue, _, _ in decided if cue]


class PhraseListener:
    """Words one at a time (a TTS reporting what it speaks) → the cues decided by each new word."""

    def __init__(self, phrases: PhraseCues) -> None:
        self.phrases = phrases
        self.held: list[Word] = []  # the words of the sentence being spoken
        self.decided_upto = 0  # tokens of ``held`` before this are decided
        self.since: int | None = None  # sentence ends since the last act opening a talk (0: in this sentence)

    def hear(self, word: Word) -> list[Cue]:
        """The cues that ``word`` lets the listener decide."""
        self.held.append(word)
        cues = self._decide(lambda tokens, c: decidable(tokens, c))
        tokens = tokenize([w.text for w in self.held])
        if tokens:
            self._forget(tokens)
        return cues

    def flush(self) -> list[Cue]:
        """The speech ended: decide what is left and forget the sentence."""
        cues = self._decide(lambda tokens, c: True)
        self._end_sentence()
        return cues

    def _decide(self, ready) -> list[Cue]:
        tokens = tokenize([w.text for w in self.held])
        decided = self.phrases.decided(self.held, tokens,
                                       lambda c: c.start >= self.decided_upto and ready(tokens, c), self.since)
        if decided:
            self.decided_upto = max(start for _, start, _ in decided) + 1
        if any(opens for _, _, opens in decided):
            self.since = 0
        return [cue for cue, _, _ in decided if cue is not None]

    def _end_sentence(self) -> None:
        self.held, self.decided_upto = [], 0
        self.since = None if self.since is None else self.since + 1

    def _forget(self, tokens: list[Token]) -> None:
        """Forget an ended sentence (all its phrases are decided), or the oldest word beyond the bound."""
        if tokens[-1].sentence_end:
            self._end_sentence()
        elif len(self.held) > MAX_HELD_WORDS:
            self.held.pop(0)
            self.decided_upto = max(0, self.decided_upto - sum(1 for t in tokens if t.word == 0))
