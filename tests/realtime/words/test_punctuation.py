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
    marked, paused = punctuated_by_pauses(words, ended=True)
    assert [w.text for w in marked] == ["well", "done", "everyone.", "hooray,", "we", "did", "it."]
    assert paused == {2, 3, 6}


def test_punctuated_words_are_left_as_written():
    words = timed("Hello there. We did it", {1: 0.6, 2: 0.6})
    assert punctuated_by_pauses(words, ended=True) == (words, frozenset())


def test_a_farewell_at_the_end_of_an_unpunctuated_transcript_is_decided():
    words = timed("thanks for watching see you next time", {2: 0.5})
    plain = PhraseStream(PhraseCues(GESTURES)).cues(list(words))
    marked = PhraseStream(PhraseCues(GESTURES)).cues(*punctuated_by_pauses(words, ended=True))
    assert "wave-right" not in [cue.gesture for cue in plain]
    assert [cue.gesture for cue in marked] == ["bow", "wave-right"]


def test_a_mark_read_from_a_pause_does_not_end_the_grammar_a_written_one_does():
    """A voice that keeps an unvoiced "-ks" after "Thanks" (a recogniser ending the word at its voicing) leaves a
    pause there: "thanks to the rain" stays causal, "hello was" a mention, while "hooray (pause) we did it" cheers."""
    phrases = PhraseStream(PhraseCues(GESTURES))
    heard = {text: [cue.gesture for cue in phrases.cues(*punctuated_by_pauses(timed(text, {0: 0.17}), ended=True))]
             for text in ("thanks to the rain in april the fields are greener", "hello was once a rude word",
                          "hooray we did it", "thanks for coming everyone")}
    assert heard == {"thanks to the rain in april the fields are greener": [], "hello was once a rude word": [],
                     "hooray we did it": ["raise-both"], "thanks for coming everyone": ["bow"]}
    written = PhraseStream(PhraseCues(GESTURES)).cues(list(timed("Thanks, to the rain in April.", {})))
    assert [cue.gesture for cue in written] == ["bow"]
