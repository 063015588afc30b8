"""A sentence without word times is aligned on its speech only when its words cue something: with a sentence mark
its speech acts are decided on the text first (narration costs no alignment); without one, its pauses give its
punctuation, so it is aligned first."""

import pytest

from gesturecast.realtime.run.engine_setup import build_session
from gesturecast.realtime.timing.clock import MonotonicClock
from gesturecast.settings import Settings
from gesturecast.tools.bench.speech.espeak_words import spoken

SCRIPT = "The museum opened in the spring. Hello everyone, welcome to the tour! The rooms are upstairs."
NARRATION = "The museum opened in the spring. The rooms are upstairs."


@pytest.fixture
def gestures():
    return build_session(Settings(), MonotonicClock()).gestures


def test_only_the_sentence_that_cues_is_aligned_and_its_cue_sits_on_its_word(gestures, tmp_path):
    audio, timed = spoken(SCRIPT, tmp_path)
    outcomes = gestures.hear_script(SCRIPT, audio)
    counts = gestures.alignments.to_dict()
    assert counts["uncued"] == 2 and counts["aligned"] + counts["partly"] == 1
    assert counts["words"] == len(SCRIPT.split())
    [greeting] = [outcome.cue for outcome in outcomes if outcome.cue.source == "Hello"]
    hello = next(word for word in timed if word.text == "Hello")
    assert greeting.time == pytest.approx(hello.start, abs=0.1)


def test_narration_costs_no_alignment(gestures, tmp_path):
    audio, _ = spoken(NARRATION, tmp_path)
    assert gestures.hear_script(NARRATION, audio) == []
    assert gestures.aligner.cpu_s == 0.0 and gestures.alignments.to_dict()["uncued"] == 2


def test_a_sentence_without_marks_is_aligned_before_it_is_decided(gestures, tmp_path):
    text = "the rooms are upstairs"
    audio, _ = spoken(text, tmp_path)
    gestures.hear_script(text, audio)
    counts = gestures.alignments.to_dict()
    assert counts["uncued"] == 0 and counts["aligned"] + counts["partly"] == 1 and gestures.aligner.cpu_s > 0
