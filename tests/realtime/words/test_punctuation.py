"""Words without punctuation get the marks their pauses show, so the speech acts read them as punctuated words."""

from gesturecast.controls import Word
from gesturecast.realtime.gestures.phrases import PhraseCues, PhraseStream
from gesturecast.realtime.words.punctuation import punctuated_by_pauses

GESTURES = ("wave", "wave-right", "raise-both", "bow", "guide", "call")


def timed(text: str, pauses: dict[int, float]) -> tuple[Word, ...]:
    """The tokens of ``text`` 0.3 s each, with ``pauses`` (seconds) after the tokens they index."""
    words, at = [], 0.0
    for index, token in enumerate(text.split()):
        words.append(Word(token, at, at + 0.3))
        at += 0.3 + pauses.get(index, 0.0)
    return tuple(words)


def test_pauses_become_sentence_ends_and_clause_marks():
    words = timed("well done everyone hooray we did it", {2: 0.6, 3: 0.2})  # a clause pause of 0.2 s
    assert [w.text for w in punctuated_by_pauses(words, ended=True)] == \
        ["well", "done", "everyone.", "hooray,", "we", "did", "it."]


def test_punctuated_words_are_left_as_written():
    words = timed("Hello there. We did it", {1: 0.6, 2: 0.6})
    assert punctuated_by_pauses(words, ended=True) == words


def test_a_farewell_at_the_end_of_an_unpunctuated_transcript_is_decided():
    words = timed("thanks for watching see you next time", {2: 0.5})
    plain = PhraseStream(PhraseCues(GESTURES)).cues(list(words))
    marked = PhraseStream(PhraseCues(GESTURES)).cues(list(punctuated_by_pauses(words, ended=True)))
    assert "wave-right" not in [cue.gesture for cue in plain]
    assert [cue.gesture for cue in marked] == ["bow", "wave-right"]
