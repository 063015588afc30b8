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
