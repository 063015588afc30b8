"""Punctuation from pauses, for words that come without any (as many recognisers give them): the speech acts read
sentence ends and clause marks ("Hooray, we did it!"), and a speaker's pauses show where they are.

A word followed by at least :data:`SENTENCE_PAUSE_S` of silence before the next ends its sentence (``.``), by at
least :data:`CLAUSE_PAUSE_S` its clause (``,``); the last word of a transcript ends its sentence. Words that carry
any sentence mark are left as they are: their punctuation is the writer's.
"""

from __future__ import annotations

from dataclasses import replace

from gesturecast.controls import Word

SENTENCE_PAUSE_S = 0.3  # silence after a word that ends its sentence
# silence after a word that ends its clause: espeak-ng's voices pause 0.10-0.15 s at a comma; on the default voice's
# narration every comma is this long and 10 % of the other gaps between words are (a stray comma cues nothing; a
# missed one turned "Thanks to the rain, the fields…" into thanks)
CLAUSE_PAUSE_S = 0.10
SENTENCE_MARKS = frozenset(".!?…")
MARKS = frozenset(".!?…,;:")


def has_sentence_mark(texts: list[str]) -> bool:
    """Whether any of the words ends a sentence by its punctuation (closing quotes and brackets aside)."""
    return any(text.rstrip("\"')]")[-1:] in SENTENCE_MARKS for text in texts)


def punctuated_by_pauses(words: tuple[Word, ...], ended: bool = False) -> tuple[tuple[Word, ...], frozenset[int]]:
    """(``words`` with the marks their pauses show, the indices of the words given a mark): the last one ends its
    sentence when the speech ``ended`` with it (a transcript's words); unchanged when any word ends a sentence, and a
    word that carries a mark keeps its own."""
    if has_sentence_mark([word.text for word in words]):
        return words, frozenset()
    marks = {}
    for index, (word, following) in enumerate(zip(words, words[1:], strict=False)):
        pause = following.start - word.end
        marks[index] = "." if pause >= SENTENCE_PAUSE_S else "," if pause >= CLAUSE_PAUSE_S else ""
    if ended and words:
        marks[len(words) - 1] = "."
    marks = {index: mark for index, mark in marks.items() if mark and words[index].text[-1] not in MARKS}
    return (tuple(replace(word, text=word.text + marks[index]) if index in marks else word
                  for index, word in enumerate(words)), frozenset(marks))
