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

A sentence without word times (a script's, a TTS service's, a recogniser's) is aligned on its own speech only when
its words cue something: with a sentence mark, its speech acts and trigger phrases read only its text, so they are
decided on the words' order first, and a sentence that cues nothing (most narration) costs no alignment; one whose
cues all sit on its first word takes that word's start from its voiced onset, and any other is aligned only as far as
its last cue's word and :data:`CONTEXT_WORDS` after it. Without a
sentence mark, its pauses give its punctuation (:mod:`gesturecast.realtime.words.punctuation`), so it is aligned
first.
"""

from __future__ import annotations

import logging
from collections import deque
from collections.abc import Callable
from concurrent.futures import Future
from dataclasses import replace

import numpy as np

from gesturecast.controls import Word, parse_words
from gesturecast.errors import UserError
from gesturecast.realtime.gestures.cues import BLEND_LATENTS, CONTROL_SOURCE, Cue, CueOutcome, CuePlan, Imposition
from gesturecast.realtime.gestures.phrases import PhraseCues, PhraseListener, PhraseStream
from gesturecast.realtime.gestures.repertoire import GestureRepertoire
from gesturecast.realtime.gestures.triggers import TriggerVocabulary, WordListener
from gesturecast.realtime.words.aligner import SentenceAligner, SentenceAudio
from gesturecast.realtime.words.live import LiveSentences
from gesturecast.realtime.words.outcomes import AlignmentCounts
from gesturecast.realtime.words.punctuation import has_sentence_mark, punctuated_by_pauses
from gesturecast.realtime.words.script import script_sentences
from gesturecast.realtime.words.worker import WordsWorker

logger = logging.getLogger(__name__)
Decision = tuple[list[Cue], list[Cue]]  # (forced trigger cues, speech-act cues) of some words
CONTEXT_WORDS = 2  # words after a cue's first word aligned with it (they take any speech the prefix's audio overruns)


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
        self.worker: WordsWorker | None = None  # None: words decided on the caller's thread (offline: always)
        self._decided: deque[Future] = deque()  # handed-over decisions not placed yet, in order
        self.reset()

    def reset(self) -> None:
        """A new stream: no cue placed, no word heard, latent 0 next (the words worker's last jobs finished first)."""
        if self.worker is not None:
            self.worker.submit(lambda: None).result()
        self._decided.clear()
        self.cues = CuePlan(self.repertoire.first_performances(), self.seconds_per_latent,
                            self.repertoire.performances())
        self.listener = WordListener(self.vocabulary)  # words reported one at a time (a TTS speaking)
        self.phrase_listener = None if self.phrases is None else PhraseListener(self.phrases)
        self.phrase_stream = None if self.phrases is None else PhraseStream(self.phrases)  # word messages
        self.next_latent = 0  # the first latent not generated yet
        self.heard_s = 0.0  # stream seconds of audio arrived
        self.alignments = AlignmentCounts()
        self.sentences = LiveSentences()  # sentences waiting for their audio

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
        """The stream's audio has arrived up to ``seconds`` (stream time), ``samples`` ((n,) float32, 16 kHz) the audio
        that arrived since the last call: kept for sentences whose text comes after it, and the sentences waiting
        for it placed (their cues returned; with the words worker, at a later latent)."""
        self.heard_s = seconds
        if samples is None:
            return []
        self.sentences.hear(samples)
        if not self.sentences.pending:  # most chunks: nothing waits for audio, no work handed over
            return []
        return self._decided_now(lambda: self._sentence_decisions(self.sentences.ready()), wait=False)

    def play(self, latent: int) -> Imposition | None:
        """What the placed clips impose on ``latent``, generated now (None when none does); the placements that
        ended before it are forgotten, and cues from now on are placed from the next latent."""
        self._place_decided()
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

    def hear_words(self, words: tuple[Word, ...], wait: bool = True) -> list[CueOutcome]:
        """Cue the gestures of the speech acts and forced trigger phrases in ``words`` (stream-time stamps, a
        transcript or a words message), the words after those of earlier calls
        (:class:`~gesturecast.realtime.gestures.phrases.PhraseStream`). With the words worker and ``wait`` False (the
        stream's own thread), they are decided there and placed at a later latent; returns the cues placed now."""
        return self._decided_now(lambda: [self._decide(words)], wait)

    def hear_transcript(self, words: tuple[Word, ...]) -> list[CueOutcome]:
        """:meth:`hear_words` for the words of a whole recording (a transcript): its last word ends the speech."""
        return self._decided_now(lambda: [self._decide(words, ended=True)], wait=True)

    def hear_spoken(self, word: Word, wait: bool = True) -> list[CueOutcome]:
        """Cue what ``word`` completes, one of the words a TTS service reports as it speaks them (earlier words of
        the phrase came in earlier calls; a speech act is decided once the words after it that tell arrive)."""
        def decide() -> list[Decision]:
            acts = [] if self.phrase_listener is None else self.phrase_listener.hear(word)
            return [(self.listener.hear(word), acts)]

        return self._decided_now(decide, wait)

    def hear_script(self, text: str, samples: np.ndarray) -> list[CueOutcome]:
        """A plain-text script of the recording ``samples`` ((n,) float32, 16 kHz, from stream time 0), placed on it
        sentence by sentence (:func:`~gesturecast.realtime.words.script.script_sentences`); its last sentence ends the
        speech."""
        def decide() -> list[Decision]:
            placed = script_sentences(text, samples)
            return [self._sentence_decision(sentence, ended=index == len(placed) - 1)
                    for index, sentence in enumerate(placed)]

        return self._decided_now(decide, wait=True)

    def hear_sentence(self, text: str, start: float | None = None, end: float | None = None, wait: bool = True
                      ) -> list[CueOutcome]:
        """A sentence without word times (at least one token): its words get times from its own speech once that has
        arrived (:mod:`gesturecast.realtime.words.live`: ``start`` / ``end`` bound it when known), then are heard as
        :meth:`hear_words` hears words. Returns the cues of the sentences placed now (this one, if its audio is
        already here)."""
        return self._decided_now(lambda: self._sentence_decisions(self.sentences.add(text, start, end)), wait)

    def hear_sentence_with_audio(self, text: str, samples: np.ndarray, start: float) -> list[CueOutcome]:
        """A sentence (at least one token) and its own speech ((n,) float32, 16 kHz, from stream time ``start``),
        given before that speech is pushed: aligned on it and its cues placed now (waiting for the words worker), so
        they are known before the speech's latents are generated."""
        sentence = SentenceAudio(text, samples, start)
        return self._decided_now(lambda: self._sentence_decisions([self.sentences.place_with_audio(sentence)]),
                                 wait=True)

    def end_of_words(self) -> list[CueOutcome]:
        """The words stopped (the speech ended): the sentences still waiting are placed on the audio that arrived,
        and the phrases still waiting for the words after them are decided (waiting for the words worker)."""
        def decide() -> list[Decision]:
            acts = [] if self.phrase_listener is None else self.phrase_listener.flush()
            return [*self._sentence_decisions(self.sentences.ready(final=True)), ([], acts)]

        return self._decided_now(decide, wait=True)

    # ---- the words worker ----
    def start_worker(self) -> None:
        """Decide words and align sentences on a worker thread from now on: a live stream's thread never waits for
        them (:mod:`gesturecast.realtime.words.worker`)."""
        if self.worker is None:
            self.worker = WordsWorker()

    def stop_worker(self) -> None:
        """Finish the handed-over work, place it, and decide on the caller's thread again."""
        if self.worker is not None:
            self.worker.close()
            self.worker = None
            self._place_decided()

    def _decide(self, words: tuple[Word, ...], ended: bool = False) -> Decision:
        """The forced trigger cues and the speech acts of ``words`` (the decision state moves on); words without
        punctuation are read with the marks their pauses show (:mod:`gesturecast.realtime.words.punctuation`)."""
        words, paused = punctuated_by_pauses(words, ended)
        acts = [] if self.phrase_stream is None else self.phrase_stream.cues(words, paused)
        return self.vocabulary.cues(list(words)), acts

    def _sentence_decisions(self, sentences: list[SentenceAudio]) -> list[Decision]:
        return [self._sentence_decision(sentence) for sentence in sentences]

    def _sentence_decision(self, sentence: SentenceAudio, ended: bool = False) -> Decision:
        """The cues of a sentence without word times, aligned on its audio only when they need it (module
        docstring); ``ended``: the speech ends with it."""
        tokens = sentence.text.split()
        if not has_sentence_mark(tokens):
            return self._decide(self._aligned_words(sentence), ended)
        forced, acts = self._decide(in_order(tokens))
        cued = [round(cue.time) for cue in forced + acts if cue.gesture in self.cues.clips]  # their first words
        if not cued:
            self.alignments.count_uncued(len(tokens))
            return [], []
        words = self._aligned_words(sentence, max(cued))
        return timed_by_words(forced, words), timed_by_words(acts, words)

    def _aligned_words(self, sentence: SentenceAudio, last_cued: int | None = None) -> tuple[Word, ...]:
        """The sentence's words with times from its speech (counted), checked as every door's words are; with the
        index of its last cued word, only as far as the cues need: the first word starts at the voiced onset (no
        alignment), a later one is aligned with :data:`CONTEXT_WORDS` after it (:meth:`SentenceAudio.prefix`)."""
        if last_cued == 0:
            alignment = self.aligner.at_onset(sentence)
        elif last_cued is None:
            alignment = self.aligner.align(sentence)
        else:
            alignment = self.aligner.align(sentence.prefix(last_cued + 1 + CONTEXT_WORDS))
        self.alignments.count(alignment, sentence.text)
        return parse_words([{"word": w.text, "start": w.start, "end": w.end} for w in alignment.words],
                           "sentence words")

    def _decided_now(self, decide: Callable[[], list[Decision]], wait: bool) -> list[CueOutcome]:
        """Run ``decide`` here (no worker), or on the worker: waited for and placed now when ``wait``, else placed
        at a later latent. Returns the cues placed now."""
        if self.worker is None:
            return self._place(decide())
        future = self.worker.submit(decide)
        if not wait:
            self._decided.append(future)
            return []
        outcomes = self._place_decided()  # what was handed over before it is decided by now: placed first
        return outcomes + self._place(future.result())

    def _place_decided(self) -> list[CueOutcome]:
        """Place the handed-over decisions that are ready, in order (one that failed is logged, not placed)."""
        outcomes = []
        while self._decided and (self.worker is None or self._decided[0].done()):
            future = self._decided.popleft()
            if future.exception() is not None:
                logger.warning("words not decided: %s", future.exception())
                continue
            outcomes += self._place(future.result())
        return outcomes

    def _place(self, decisions: list[Decision]) -> list[CueOutcome]:
        return [outcome for forced, acts in decisions for outcome in self.place_word_cues(forced, acts)]

    def place_word_cues(self, forced: list[Cue], acts: list[Cue]) -> list[CueOutcome]:
        """The cues that words decided, placed in time order: a forced trigger wins over a speech act on the same
        word; a gesture this stream does not have is not cued."""
        taken = {cue.time for cue in forced}
        cues = sorted(forced + [cue for cue in acts if cue.time not in taken], key=lambda cue: cue.time)
        return [self.cue(cue) for cue in cues if cue.gesture in self.cues.clips]


def in_order(tokens: list[str]) -> tuple[Word, ...]:
    """The tokens as words timed by their order (word i at i seconds), for decisions that read only the text."""
    return tuple(Word(token, float(index), float(index)) for index, token in enumerate(tokens))


def timed_by_words(cues: list[Cue], words: tuple[Word, ...]) -> list[Cue]:
    """Cues decided on :func:`in_order` words, at the start of their word in ``words`` (the same tokens, timed)."""
    return [replace(cue, time=words[round(cue.time)].start) for cue in cues]
