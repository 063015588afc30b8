"""``gesturecast bench gestures --decisions-only``: which speech acts the phrase classifier decides on a text set,
without speech or generation (a second, not minutes).

Each cued story and each narration is read as one transcript: its marked sentences' words, one made-up second
apiece (the decisions read only the words), through the session's :class:`~gesturecast.realtime.gestures.phrases.
PhraseCues`. An intended cue is *decided* when a cue of its intent's gesture falls on its marked word; every other
cue in a story is *unintended*, every cue on a narration a *narration cue*. The timing, the scheduler (merged or
dropped cues) and the detector are the full benchmark's.
"""

from __future__ import annotations

from gesturecast.controls import Word
from gesturecast.realtime.gestures.phrases import PhraseCues
from gesturecast.realtime.gestures.speech_acts import MARKS
from gesturecast.tools.gestures.speech_act_training import parse_marked


def transcript(sentences: tuple[str, ...]) -> tuple[list[Word], dict[int, str], list[int]]:
    """(words, {word index: mark}, the sentence index of each word) of marked sentences read as one transcript."""
    words, marks, owner = [], {}, []
    for k, sentence in enumerate(sentences):
        texts, marked = parse_marked(sentence)
        marks.update({len(words) + index: mark for index, mark in marked.items()})
        words += [Word(text, float(len(words) + i), float(len(words) + i + 1)) for i, text in enumerate(texts)]
        owner += [k] * len(texts)
    return words, marks, owner


def decided_cues(phrases: PhraseCues, sentences: tuple[str, ...]) -> tuple[dict[int, str], list[dict]]:
    """({marked word: mark}, one row per cue: word index, gesture, phrase, sentence)."""
    words, marks, owner = transcript(sentences)
    rows = [{"word": int(cue.time), "gesture": cue.gesture, "phrase": cue.source,
             "sentence": sentences[owner[int(cue.time)]]} for cue in phrases.cues(words)]
    return marks, rows


def decisions(phrases: PhraseCues, stories: dict[str, tuple[str, ...]],
              narrations: tuple[tuple[str, tuple[str, ...]], ...]) -> dict:
    """The decisions on a text set (module docstring): counts, then each miss, unintended and narration cue."""
    intended = decided = 0
    misses, unintended, fired = [], [], []
    for sentences in stories.values():
        marks, rows = decided_cues(phrases, sentences)
        at = {row["word"]: row for row in rows}
        for index, mark in marks.items():
            intended += 1
            row = at.get(index)
            if row is not None and row["gesture"] == phrases.gesture_of(MARKS[mark]):
                decided += 1
            else:
                misses.append({"mark": mark, "decided": row and row["gesture"],
                               "sentence": _sentence_of(sentences, index)})
        unintended += [row for row in rows if row["word"] not in marks]
    for _, sentences in narrations:
        fired += decided_cues(phrases, sentences)[1]
    return {"intended": intended, "decided": decided, "unintended_in_stories": len(unintended),
            "narration_sentences": sum(len(sentences) for _, sentences in narrations), "narration_cues": len(fired),
            "misses": misses, "unintended": unintended, "narration": fired}


def _sentence_of(sentences: tuple[str, ...], index: int) -> str:
    return sentences[transcript(sentences)[2][index]]
