"""Sentences given without times to a live stream: placed on audio already heard, or waiting for audio to come."""

import numpy as np
import pytest

from gesturecast.controls import ControlError, Sentence, parse_controls
from gesturecast.realtime.words.aligner import SentenceAligner
from gesturecast.realtime.words.live import AudioHistory, LiveSentences
from gesturecast.realtime.words.voicing import SAMPLE_RATE
from gesturecast.tools.bench.speech.espeak_words import spoken

FIRST, SECOND = "Now let me show you the map of the old city.", "Thank you so much for watching."
GAP = np.zeros(SAMPLE_RATE // 2, np.float32)  # (8000,) half a second of silence


@pytest.fixture(scope="module")
def speech(tmp_path_factory):
    cache = tmp_path_factory.mktemp("espeak")
    return spoken(FIRST, cache), spoken(SECOND, cache)


def in_chunks(sentences: LiveSentences, audio: np.ndarray) -> list:
    """Push ``audio`` in 20 ms chunks as a stream does; the sentences placed on the way."""
    placed = []
    for at in range(0, len(audio), 320):
        sentences.hear(audio[at : at + 320])
        placed += sentences.ready()
    return placed


def test_text_after_its_audio_is_placed_at_once_and_text_before_waits(speech):
    (first, first_timed), (second, second_timed) = speech
    sentences, aligner = LiveSentences(), SentenceAligner()
    in_chunks(sentences, np.concatenate([GAP, first, GAP]))
    [placed] = map(aligner.align, sentences.add(FIRST))  # a transcript of what was just said
    assert placed.method == "aligned"
    assert abs(placed.words[3].start - (0.5 + first_timed[3].start)) < 0.05
    assert sentences.add(SECOND) == []  # a TTS sentence before its audio
    [later] = map(aligner.align, in_chunks(sentences, np.concatenate([second, GAP])))
    offset = 0.5 + len(first) / SAMPLE_RATE + 0.5
    assert later.method == "aligned" and abs(later.words[0].start - (offset + second_timed[0].start)) < 0.05


def test_the_end_of_words_places_a_sentence_whose_audio_never_came():
    sentences = LiveSentences()
    sentences.hear(GAP)
    assert sentences.add("Hello there.", start=0.2) == []
    [placed] = sentences.ready(final=True)
    assert placed.text == "Hello there." and placed.start == pytest.approx(0.2) and not placed.samples.any()  # silence
    alignment = SentenceAligner().align(placed)
    assert alignment.method == "failed" and [word.text for word in alignment.words] == ["Hello", "there."]


def test_the_history_keeps_the_last_seconds_in_order():
    history = AudioHistory(seconds=1.0)
    ramp = np.arange(3 * SAMPLE_RATE // 2, dtype=np.float32)  # (24000,) 1.5 s
    for at in range(0, len(ramp), 700):
        history.append(ramp[at : at + 700])
    kept, first_s = history.span(0.0, 2.0)
    assert first_s == 0.5 and np.array_equal(kept, ramp[SAMPLE_RATE // 2 :])


def test_a_text_control_carries_optional_bounds():
    assert parse_controls({"text": "Hello everyone!", "start": 1.5}) == (Sentence("Hello everyone!", 1.5, None),)
    with pytest.raises(ControlError, match="need a text field"):
        parse_controls({"start": 1.0})
    with pytest.raises(ControlError, match="text must not be blank"):
        parse_controls({"text": "  "})
