"""Trigger phrases → gesture cues: a user's lexicon names the phrases that always cue its gestures.

:class:`TriggerVocabulary` turns words into :class:`Cue` s: each trigger phrase (case-insensitive, punctuation
ignored, the longest match first: "come here" is a call, "here" alone points) cues its gesture with the stroke at the
phrase's first word's start; :class:`WordListener` does it for words heard one at a time.
"""

from __future__ import annotations

import re
from collections import deque
from collections.abc import Iterable, Mapping

from gesturecast.controls import Word
from gesturecast.realtime.gestures.cues import Cue

NOT_A_LETTER = re.compile(r"[^\w']+")
DEFAULT_TRIGGERS: dict[str, tuple[str, ...]] = {  # gesture -> English trigger phrases
    "wave": ("hello", "hi", "hey", "welcome"),
    "wave-right": ("bye", "goodbye", "see you"),
    "bow": ("thank you", "thanks"),
    "raise-both": ("hooray", "yay", "congratulations"),
    "guide": ("here", "there", "look at", "this"),
    "call": ("come on", "come here"),
}


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
