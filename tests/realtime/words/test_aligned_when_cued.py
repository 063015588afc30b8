"""A sentence without word times is aligned on its speech only when its words cue something: with a sentence mark
its speech acts are decided on the text first (narration costs no alignment), a cue on its first word takes the
voiced onset, a later one is aligned; without a mark, its pauses give its punctuation, so it is aligned first."""

import pytest

from gesturecast.realtime.run.engine_setup import build_session
from gesturecast.realtime.timing.clock import MonotonicClock
from gesturecast.settings import Settings
from gesturecast.tools.bench.speech.espeak_words import spoken

SCRIPT = "The museum opened in the spring. Thank you so much for coming! The rooms are upstairs."
LATER_CUE = "We made it to the top, and thank you so much for walking with me."
NARRATION = "The museum opened in the spring. The rooms are upstairs."


@pytest.fixture
def gestures():
    return build_session(Settings(), MonotonicClock()).gestures


def test_only_the_sentence_that_cues_is_placed_and_its_cue_sits_on_its_word(gestures, tmp_path):
    audio, timed = spoken(SCRIPT, tmp_path)
    outcomes = gestures.hear_script(SCRIPT, audio)
    counts = gestures.alignments.to_dict()
    assert counts["uncued"] == 2 and counts["onset"] == 1 and gestures.aligner.cpu_s == 0.0  # "Thank" opens it
    assert counts["words"] == len(SCRIPT.split())
    [thanks] = [outcome.cue for outcome in outcomes]
    own = next(word for word in timed if word.text == "Thank")
    assert thanks.source == "Thank you so much" and thanks.time == pytest.approx(own.start, abs=0.1)


def test_a_cue_later_in_its_sentence_is_aligned(gestures, tmp_path):
    audio, timed = spoken(LATER_CUE, tmp_path)
    outcomes = gestures.hear_script(LATER_CUE, audio)
    counts = gestures.alignments.to_dict()
    assert counts["aligned"] + counts["partly"] == 1 and gestures.aligner.cpu_s > 0
    [thanks] = [outcome.cue for outcome in outcomes if outcome.cue.source.startswith("thank you")]
    own = next(word for word in timed if word.text == "thank")
    assert thanks.time == pytest.approx(own.start, abs=0.1)


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
