"""One stream's gestures: the one place every door's words and gesture controls reach the cue plan.

:class:`GestureDirector` owns the stream's :class:`~gesturecast.realtime.gestures.cues.CuePlan`, the trigger
phrases that always cue their gesture (:class:`~gesturecast.realtime.gestures.triggers.TriggerVocabulary`) and the
speech-act decisions (:mod:`gesturecast.realtime.gestures.phrases`). The session factory builds one per session from
the factory's :class:`~gesturecast.realtime.gestures.repertoire.GestureRepertoire`; the session tells it which
latent is generated next and how much audio has arrived, and every door calls it: the session's controls (WebSocket,
``serve``, OSC input, ``Stream.control``), ``Stream.words``, ``Stream.spoken`` (and through it the Pipecat
processor) and the transcripts of ``generate``, ``live`` and batches.

Every word has been checked by :func:`gesturecast.controls.parse_words` before it comes here; the cues its words
decide reach the plan through :meth:`GestureDirector.place_word_cues`, whichever door they came through.
"""

from __future__ import annotations

import numpy as np

from gesturecast.controls import Word, parse_words
from gesturecast.errors import UserError
from gesturecast.realtime.gestures.cues import BLEND_LATENTS, CONTROL_SOURCE, Cue, CueOutcome, CuePlan, Imposition
from gesturecast.realtime.gestures.phrases import PhraseCues, PhraseListener, PhraseStream
from gesturecast.realtime.gestures.repertoire import GestureRepertoire
from gesturecast.realtime.gestures.triggers import TriggerVocabulary, WordListener
from gesturecast.realtime.words.aligner import Alignment, SentenceAligner
from gesturecast.realtime.words.live import LiveSentences
from gesturecast.realtime.words.outcomes import AlignmentCounts


class GestureDirector:
    """The gestures of one stream (module docstring). ``seconds_per_latent``: d / fps of the model; ``latency_s``:
    L, how long after its audio arrived a stream instant shows."""

    def __init__(self, repertoire: GestureRepertoire, seconds_per_latent: float, latency_s: float) -> None:
        self.repertoire = repertoire
        self.seconds_per_latent = seconds_per_latent
        self.latency_s = latency_s
        self.vocabulary = TriggerVocabulary(dict(repertoire.triggers))
        self.phrases = PhraseCues(repertoire.names) if repertoire.speech_acts else None
        self.aligner = SentenceAligner()  # sentences without word times, placed on their own speech
        self.reset()

    def reset(self) -> None:
        """A new stream: no cue placed, no word heard, latent 0 next."""
        self.cues = CuePlan(self.repertoire.first_performances(), self.seconds_per_latent,
                            self.repertoire.performances())
        self.listener = WordListener(self.vocabulary)  # words reported one at a time (a TTS speaking)
        self.phrase_listener = None if self.phrases is None else PhraseListener(self.phrases)
        self.phrase_stream = None if self.phrases is None else PhraseStream(self.phrases)  # word messages
        self.next_latent = 0  # the first latent not generated yet
        self.heard_s = 0.0  # stream seconds of audio arrived
        self.alignments = AlignmentCounts()
        self.sentences = LiveSentences(self.aligner, self.alignments)  # sentences waiting for their audio

    @property
    def names(self) -> tuple[str, ...]:
        """The gestures this stream can perform."""
        return tuple(self.cues.clips)

    def warm(self) -> None:
        """Load the speech-act classifier now (a live stream's warm-up), not when the first words come."""
        if self.phrases is not None:
            self.phrases.warm()

    # ---- what the session tells ----
    def heard(self, seconds: float, samples: np.ndarray | None = None) -> list[CueOutcome]:
        """The stream's audio has arrived up to ``seconds`` (stream time), ``samples`` ((n,) float32, 16 kHz) the
        audio that arrived since the last call; the sentences waiting for it are placed (their cues returned)."""
        self.heard_s = seconds
        if samples is None:
            return []
        self.sentences.hear(samples)
        return self._hear_aligned(self.sentences.ready() if self.sentences.pending else [])

    def play(self, latent: int) -> Imposition | None:
        """What the placed clips impose on ``latent``, generated now (None when none does); the placements that
        ended before it are forgotten, and cues from now on are placed from the next latent."""
        imposed = self.cues.imposition(latent)
        self.cues.forget_before(latent)
        self.next_latent = latent + 1
        return imposed

    # ---- doors ----
    def check_lexicon(self, name: str | None = None) -> None:
        """UserError unless the stream has a lexicon (and ``name``, when given, is in it)."""
        if not self.cues.clips:
            raise UserError("this stream has no gesture lexicon")
        if name is not None:
            self.cues.check(name)

    def check_gesture(self, name: str) -> None:
        """What a gesture control checks when it is submitted: the gesture is in the lexicon, the plan has room."""
        self.check_lexicon(name)
        self.cues.check_ahead([], self.next_latent)

    def check_live_words(self, words: tuple[Word, ...]) -> None:
        """CueRefused (one line) for a word too far ahead of the stream, or while the plan is full: what a live door
        (a words message, :meth:`gesturecast.Stream.words`) checks before it hands words over."""
        self.cues.check_ahead([word.start for word in words], self.next_latent)

    def cue_gesture(self, name: str, t: float) -> CueOutcome:
        """A gesture control: ``name`` with its stroke as early as it can be from stream time ``t``."""
        return self.cue(Cue(name, t, CONTROL_SOURCE))

    def cue(self, cue: Cue) -> CueOutcome:
        """Place ``cue`` from the next latent on (:meth:`CuePlan.place`): on time, late, blended, merged or
        dropped."""
        return self.cues.place(cue, self.next_latent)

    def stroke_lead_s(self) -> float:
        """About how long from now until the stroke of a gesture control submitted now shows: it starts at the next
        latent and approaches over :data:`BLEND_LATENTS`; a stream instant shows L after its audio arrived."""
        stroke_s = (self.next_latent + BLEND_LATENTS) * self.seconds_per_latent
        return max(0.0, self.latency_s + stroke_s - self.heard_s)

    def hear_words(self, words: tuple[Word, ...]) -> list[CueOutcome]:
        """Cue the gestures of the speech acts and forced trigger phrases in ``words`` (stream-time stamps, a
        transcript or a words message), the words after those of earlier calls
        (:class:`~gesturecast.realtime.gestures.phrases.PhraseStream`)."""
        acts = [] if self.phrase_stream is None else self.phrase_stream.cues(list(words))
        return self.place_word_cues(self.vocabulary.cues(list(words)), acts)

    def hear_spoken(self, word: Word) -> list[CueOutcome]:
        """Cue what ``word`` completes, one of the words a TTS service reports as it speaks them (earlier words of
        the phrase came in earlier calls; a speech act is decided once the words after it that tell arrive)."""
        acts = [] if self.phrase_listener is None else self.phrase_listener.hear(word)
        return self.place_word_cues(self.listener.hear(word), acts)

    def hear_sentence(self, text: str, start: float | None = None, end: float | None = None) -> list[CueOutcome]:
        """A sentence without word times (at least one token): its words get times from its own speech once that has
        arrived (:mod:`gesturecast.realtime.words.live`: ``start`` / ``end`` bound it when known), then are heard as
        :meth:`hear_words` hears words. Returns the cues of the sentences placed now (this one, if its audio is
        already here)."""
        return self._hear_aligned(self.sentences.add(text, start, end))

    def end_of_words(self) -> list[CueOutcome]:
        """The words stopped (the speech ended): the sentences still waiting are placed on the audio that arrived,
        and the phrases still waiting for the words after them are decided."""
        outcomes = self._hear_aligned(self.sentences.ready(final=True))
        return outcomes + self.place_word_cues([], [] if self.phrase_listener is None else self.phrase_listener.flush())

    def _hear_aligned(self, alignments: list[Alignment]) -> list[CueOutcome]:
        """Hear the words of placed sentences, checked as every door's words are."""
        outcomes = []
        for alignment in alignments:
            items = [{"word": w.text, "start": w.start, "end": w.end} for w in alignment.words]
            outcomes += self.hear_words(parse_words(items, "sentence words"))
        return outcomes

    def place_word_cues(self, forced: list[Cue], acts: list[Cue]) -> list[CueOutcome]:
        """The cues that words decided, placed in time order: a forced trigger wins over a speech act on the same
        word; a gesture this stream does not have is not cued."""
        taken = {cue.time for cue in forced}
        cues = sorted(forced + [cue for cue in acts if cue.time not in taken], key=lambda cue: cue.time)
        return [self.cue(cue) for cue in cues if cue.gesture in self.cues.clips]
