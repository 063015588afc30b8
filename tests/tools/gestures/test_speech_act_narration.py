"""The generated training sentences: narration that uses the candidate phrases without an act, presenting that
names a thing there to see, both seeded, and the head word the classifier reads after a phrase."""

import random

from gesturecast.realtime.gestures.speech_acts import candidates, context_texts, rule, tokenize
from gesturecast.tools.gestures.speech_act_narration import (
    advice_sentences,
    narration_sentences,
    presenting_sentences,
)
from gesturecast.tools.gestures.speech_act_training import parse_marked


def open_candidates(sentence: str) -> list[str]:
    """The candidate phrases of a sentence that no rule decides (those the classifier learns from)."""
    words, _ = parse_marked(sentence)
    tokens = tokenize(words)
    return [" ".join(t.text for t in tokens[c.start:c.stop]) for c in candidates(tokens) if rule(tokens, c) is None]


def test_generated_narration_has_no_marks_and_mostly_open_candidates():
    sentences = narration_sentences(random.Random(0), 200)
    assert not any("[" in s for s in sentences)
    assert sum(bool(open_candidates(s)) for s in sentences) >= 0.8 * len(sentences)


def test_generated_presenting_is_marked_on_a_presenting_phrase():
    for sentence in presenting_sentences(random.Random(0), 100):
        words, marks = parse_marked(sentence)
        assert list(marks.values()) == ["guide"] and 0 in marks
        tokens = tokenize(words)
        assert "presenting" in candidates(tokens)[0].intents


def test_generation_is_seeded():
    assert narration_sentences(random.Random(3), 50) == narration_sentences(random.Random(3), 50)


def test_the_head_word_skips_determiners():
    words = ["This", "is", "the", "part", "that", "matters."]
    tokens = tokenize(words)
    assert context_texts(tokens, words, candidates(tokens)[0])[-2:] == ("the", "part")


def test_advice_sentences_leave_welcome_and_bye_to_the_classifier_as_no_act():
    sentences = advice_sentences(random.Random(0), 30)
    assert not any("[" in s for s in sentences)
    assert {" ".join(open_candidates(s)) for s in sentences} == {"welcome", "bye"}


def test_every_phrasebook_phrase_opens_a_generated_act_of_its_intent():
    from gesturecast.realtime.gestures.phrasebook import PHRASEBOOK
    from gesturecast.realtime.gestures.speech_acts import MARKS
    from gesturecast.tools.gestures.speech_act_phrasebook import phrasebook_acts

    opened = set()
    for sentence in phrasebook_acts(random.Random(0)):
        words, marks = parse_marked(sentence)
        tokens = tokenize(words)
        first = candidates(tokens)[0]
        assert list(marks) == [0] and first.start == 0 and MARKS[marks[0]] in first.intents
        opened.add(" ".join(t.text for t in tokens[first.start:first.stop]))
    assert opened == {phrase for phrases in PHRASEBOOK.values() for phrase in phrases}


def test_the_ordinary_phrasebook_sentences_are_unmarked_and_hold_a_candidate():
    from gesturecast.tools.gestures.speech_act_phrasebook import ORDINARY, phrasebook_ordinary

    assert len(phrasebook_ordinary()) == 3 * len(ORDINARY)
    for sentence in ORDINARY:
        words, marks = parse_marked(sentence)
        assert not marks and candidates(tokenize(words)), sentence
